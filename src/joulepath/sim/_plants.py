"""Two plants that turn commanded motion into a controller log.

* ``sim`` — the nominal twin (what RobotStudio gives): the robot's nominal rigid-body
  model, nominal Coulomb + viscous friction, motion exactly as commanded, no noise.
* ``lab`` — the real robot the twin never matches: link masses, centres of mass and
  inertias perturbed (one fixed "robot instance" per ``instance_seed``), a 0.35 kg
  flange adapter, stronger friction with a Stribeck bump and a direction asymmetry,
  gear losses in the measured motor torque (``tau/eta`` when driving, ``tau*eta``
  when braking), torque and speed sensor noise, and a servo tracking lag (the
  actual motion is the command through a critically damped 2nd-order filter).

Both are printed the same way: the controller's units with 5 decimals of
single-precision ``num`` values (``NumToStr(value, 5)``).

The friction values are assumptions (no identified friction of the IRB 120 is
public); they are of the size reported for robots of this class.

For any other arm the ``lab`` plant is a *generic perturbation* of its model (the
same recipe: perturbed links, the flange adapter, the robot's own friction made
stronger, gear losses, noise scaled to its torque limits, the tracking lag). It is
a test of robustness to model error, not an estimate of what the real arm would
measure: :attr:`Plant.note` says so, and the outputs repeat it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Protocol

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Friction, Robot
from joulepath.energy import DriveModel, Drivetrain, motor_side_torque
from joulepath.errors import InvalidInput
from joulepath.sim._controller import MotionPlan, evaluate_plan

PLANTS = ("sim", "lab")

NOMINAL_COULOMB = np.atleast_1d(np.asarray(NOMINAL_FRICTION.coulomb, dtype=float))
NOMINAL_VISCOUS = np.atleast_1d(np.asarray(NOMINAL_FRICTION.viscous, dtype=float))


@dataclass(frozen=True, slots=True, kw_only=True)
class LabFriction:
    """Coulomb + viscous + Stribeck friction with different levels per direction."""

    coulomb: FloatArray
    viscous: FloatArray
    stribeck: FloatArray
    stribeck_speed: float = 0.05
    asymmetry: float = 0.1

    def torque(self, qd: FloatArray) -> FloatArray:
        sgn = np.tanh(qd / 0.005)
        level = self.coulomb * (1.0 + self.asymmetry * np.sign(qd))
        bump = self.stribeck * np.exp(-((qd / self.stribeck_speed) ** 2))
        out: FloatArray = (level + bump) * sgn + self.viscous * qd
        return out


@dataclass(frozen=True, slots=True, eq=False)
class Plant:
    """How a robot turns commanded motion into logged signals."""

    name: str
    robot: Robot
    friction: Friction | None
    gear_efficiency: float = 1.0
    torque_noise: tuple[float, ...] = ()
    speed_noise_deg_s: float = 0.0
    tracking_hz: float | None = None
    note: str = ""
    drives: DriveModel | None = None
    """The drive data of the robot this plant emulates (None: none known)."""
    drives_note: str = "none"

    def joint_torque(self, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
        """Noise-free joint torque (N·m, friction included, before the gears) of a motion."""
        tau = self.robot.inverse_dynamics(q, qd, qdd)
        if self.friction is not None:
            tau = tau + self.friction.torque(qd)
        out: FloatArray = tau
        return out

    def drive_torque(self, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
        """Noise-free motor torque (joint side, N·m) the plant needs for a motion: :meth:`joint_torque`
        through the gears (:func:`joulepath.energy.motor_side_torque`)."""
        tau = self.joint_torque(q, qd, qdd)
        if self.gear_efficiency != 1.0:
            tau = motor_side_torque(tau, qd, self.gear_efficiency)
        return tau

    @property
    def drivetrain(self) -> Drivetrain:
        """The plant's gears and its robot's drive data, for the energy measures (:mod:`joulepath.energy`)."""
        drives = self.drives
        return Drivetrain(
            gear_efficiency=(float(self.gear_efficiency),) * self.robot.n_joints,
            gear_source=f"the {self.name} plant's ({self.gear_efficiency:g})",
            drives=drives,
            drives_source=self.drives_note if drives is None else drives.describe(),
        )


def perturbed_robot(robot: Robot, rng: np.random.Generator) -> Robot:
    """The robot with its link mass properties perturbed (masses ±8 %, COM ±4 mm, inertia ±10 %)."""
    chain = robot.chain
    n = chain.n_joints
    ratio = 1.0 + 0.08 * rng.standard_normal(n)
    ratio = np.clip(ratio, 0.8, 1.2)
    masses = chain.masses * ratio
    coms = chain.coms + 0.004 * rng.standard_normal((n, 3))
    scale = ratio * np.clip(1.0 + 0.1 * rng.standard_normal(n), 0.75, 1.25)
    inertias = chain.inertias * scale[:, None, None]
    new = replace(chain, masses=masses, coms=coms, inertias=inertias)
    return Robot(new, description=None, source=f"{robot.source} (perturbed)")


_IRB120 = re.compile(r"irb[ _-]?120", re.I)
IRB120_TORQUE_NOISE = (0.15, 0.15, 0.10, 0.03, 0.03, 0.02)
"""N·m, the IRB 120 lab plant's torque sensor noise per joint."""
GENERIC_NOISE_SHARE = 1e-3
"""Another arm's lab-plant torque noise: this share of each joint's torque limit (0.05 N·m where unknown)."""


def is_irb120(robot: Robot) -> bool:
    """Whether the lab plant of this robot is the emulated IRB 120 (else a generic perturbation)."""
    return bool(_IRB120.search(robot.name)) and robot.n_joints == 6


def _coulomb_viscous(friction: Friction | None, n: int) -> tuple[FloatArray, FloatArray]:
    fc = np.broadcast_to(np.atleast_1d(np.asarray(getattr(friction, "coulomb", 0.0), float)), (n,))
    fv = np.broadcast_to(np.atleast_1d(np.asarray(getattr(friction, "viscous", 0.0), float)), (n,))
    return np.array(fc), np.array(fv)


def twin_plant(folder: str, robot: Robot) -> Plant:
    """A twin folder (``joulepath identify --out``) as a plant: its identified physics, no noise.

    The twin's identified rigid body, friction and gear efficiency turn the motion of
    ``robot`` (the planned kinematics) into motor torque; nothing else is added.
    """
    from joulepath.dynamics import load_robot

    twin = load_robot(folder)
    if twin.calibration is None or twin.n_joints != robot.n_joints:
        raise InvalidInput(f"{folder}: not a twin of a {robot.n_joints}-joint robot; give a twin folder")
    return Plant(
        name="twin",
        robot=twin,
        friction=twin.friction,
        gear_efficiency=twin.calibration.gear_efficiency,
        torque_noise=(0.0,) * robot.n_joints,
        drives=twin.drives,
        drives_note=twin.drives_note,
    )


def make_plant(name: str, robot: Robot, *, instance_seed: int = 120) -> Plant:
    """The ``sim`` or ``lab`` plant of a robot (``instance_seed`` fixes the lab robot), or a twin folder.

    ``sim`` uses the robot's own friction (:attr:`Robot.friction`, none: rigid body
    only). ``lab`` is the emulated IRB 120 for the IRB 120, and the same recipe as a
    generic perturbation for any other arm (see the module's description). For a twin
    (``robot.calibration``), ``sim`` is the twin's own identified physics and ``lab``
    the lab plant of the robot it is a twin of.
    """
    if name not in PLANTS and Path(name).is_dir():
        return twin_plant(name, robot)
    calibration = robot.calibration
    if calibration is not None and name == "sim":  # a twin's nominal physics are its identified ones
        return Plant(
            name="sim",
            robot=robot,
            friction=robot.friction,
            gear_efficiency=calibration.gear_efficiency,
            note=f"identified twin {robot.source}",
            drives=robot.drives,
            drives_note=robot.drives_note,
        )
    if calibration is not None and calibration.twin_of is not None:
        # a twin is measured on the lab robot it is a twin of, never on a perturbed copy of itself
        from joulepath.dynamics import load_robot

        robot = load_robot(calibration.twin_of)
    if name == "sim":
        return Plant(
            name="sim",
            robot=robot,
            friction=robot.friction,
            note=f"nominal {robot.name} model",
            drives=robot.drives,
            drives_note=robot.drives_note,
        )
    if name == "lab":
        n = robot.n_joints
        rng = np.random.default_rng(instance_seed)
        real = perturbed_robot(robot, rng).with_payload(0.35, com=(0.0, 0.0, 0.025))
        noise: tuple[float, ...]
        if is_irb120(robot):
            fc, fv = NOMINAL_COULOMB, NOMINAL_VISCOUS
            noise = IRB120_TORQUE_NOISE
            note = "emulated IRB 120 lab robot (assumed perturbations, friction and noise)"
        else:
            fc, fv = _coulomb_viscous(robot.friction, n)
            effort = robot.effort_limit
            noise = tuple(float(v) for v in np.where(np.isfinite(effort), GENERIC_NOISE_SHARE * effort, 0.05))
            note = (
                f"generic perturbation of the {robot.name} model (links, flange adapter, "
                + ("its friction made stronger" if robot.friction is not None else "no friction: none known")
                + ", "
                "gear losses, noise, tracking lag); not an estimate of a real robot"
            )
        friction = LabFriction(coulomb=1.35 * fc, viscous=1.25 * fv, stribeck=0.4 * fc)
        return Plant(
            name="lab",
            robot=real,
            friction=friction,
            gear_efficiency=0.88,
            torque_noise=noise,
            speed_noise_deg_s=0.05,
            tracking_hz=12.0,
            note=note,
            drives=robot.drives,
            drives_note=robot.drives_note,
        )
    raise InvalidInput(
        f"unknown plant {name!r}; use one of {', '.join(PLANTS)}, or a twin folder (`joulepath identify`)"
    )


class Commanded(Protocol):
    """Any commanded motion besides a :class:`MotionPlan`: ``q, qd, qdd`` at times ``t`` (s)."""

    def evaluate(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]: ...


def _commanded(plan: MotionPlan | Commanded, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    if isinstance(plan, MotionPlan):
        return evaluate_plan(plan, t)
    return plan.evaluate(t)


def _track(
    plan: MotionPlan | Commanded, t: FloatArray, hz: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Actual motion: the command through ``w²/(s² + 2ws + w²)``, sampled at ``t``."""
    from scipy import signal  # here: SciPy's signal package costs 0.3 s to import, needed only here

    step = 0.002
    grid = np.arange(0.0, t[-1] + 2 * step, step)
    q_c, qd_c, qdd_c = _commanded(plan, grid)
    w = 2 * np.pi * hz
    b, a, _ = signal.cont2discrete(([w * w], [1.0, 2 * w, w * w]), step, method="bilinear")
    b = np.ravel(b)
    zi = signal.lfilter_zi(b, a)[:, None]
    q = signal.lfilter(b, a, q_c, axis=0, zi=zi * q_c[:1])[0]
    qd = signal.lfilter(b, a, qd_c, axis=0, zi=zi * 0.0)[0]
    qdd = signal.lfilter(b, a, qdd_c, axis=0, zi=zi * 0.0)[0]

    def at(x: FloatArray) -> FloatArray:
        return np.column_stack([np.interp(t, grid, x[:, j]) for j in range(x.shape[1])])

    return at(q), at(qd), at(qdd)


@dataclass(frozen=True, slots=True)
class Measured:
    """Signals as the controller reports them, in SI units (before printing)."""

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    tau: FloatArray


def run_plant(
    plant: Plant, plan: MotionPlan | Commanded, t: FloatArray, *, rng: np.random.Generator
) -> Measured:
    """Drive the plant along a plan (or any :class:`Commanded` motion) and measure at times ``t``."""
    if plant.tracking_hz is None:
        q, qd, qdd = _commanded(plan, t)
    else:
        q, qd, qdd = _track(plan, t, plant.tracking_hz)
    tau = plant.drive_torque(q, qd, qdd)
    noise = np.asarray(plant.torque_noise)
    if np.any(noise > 0):
        tau = tau + rng.standard_normal(tau.shape) * noise
    qd_meas = qd
    if plant.speed_noise_deg_s > 0:
        qd_meas = qd + rng.standard_normal(qd.shape) * np.radians(plant.speed_noise_deg_s)
    return Measured(t=t, q=q, qd=qd_meas, qdd=qdd, tau=tau)
