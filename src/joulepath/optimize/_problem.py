"""The energy-optimal trajectory problem: chromosomes -> paths -> fitness, with limits.

Fitness kinds (each one call for the whole population):

* ``"surrogate"`` — a learned model of the total energy ``E`` summed over the path's rows;
* ``"surrogate-joints"`` — the sum of per-joint models ``E1..En``, one per joint (the
  thesis' multi-objective variant);
* ``"physics"`` — the dynamics model (nominal parameters and friction) on an
  energy measure (:data:`joulepath.energy.MEASURES`; default the thesis'
  ``Σ |tau_i qd_i| dt``).

Limits: every candidate's joint positions are checked against the robot's ranges
and its joint speeds against the speed limits (and, for the physics fitness, its
torques against the effort limits where the robot states them). Penalty rule: the
fitness becomes ``E + PENALTY * v`` with ``v`` the sum over joints of the largest
excursion beyond the range (rad) plus the largest relative overspeed
(``max(|qd| / v_max) - 1``) plus the relative overtorque: any violating path is
worse than every feasible path of reasonable energy, and less violation ranks better.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.energy import DEFAULT_MEASURE, measure_power, path_energy
from joulepath.errors import InvalidInput
from joulepath.optimize._features import path_features
from joulepath.trajectory import GRID_HIGH, GRID_LOW, N_COEFFICIENTS, Trajectory, rest_to_rest, thesis_quintic

PARAMETRIZATIONS = ("rest_to_rest", "thesis")


@dataclass(frozen=True, slots=True)
class FitnessKind:
    """What a ``--fitness`` name means: the learned models it needs (none: the physics model)."""

    name: str
    description: str
    targets: Callable[[int], tuple[str, ...]]
    """Model targets for an arm of ``n`` joints (``()``: no learned model)."""

    def model_targets(self, n_joints: int) -> tuple[str, ...]:
        return self.targets(n_joints)

    @property
    def needs_models(self) -> bool:
        return bool(self.targets(1))


FITNESS_KINDS: dict[str, FitnessKind] = {}
"""The fitness registry; adding a kind is :func:`register_fitness` plus what evaluates it."""


def register_fitness(kind: FitnessKind) -> FitnessKind:
    FITNESS_KINDS[kind.name] = kind
    return kind


register_fitness(
    FitnessKind("surrogate", "one learned model of the path energy (target E)", lambda n: ("E",))
)
register_fitness(
    FitnessKind(
        "surrogate-joints",
        "one learned model per joint (targets E1..En), summed: the thesis' multi-objective fitness",
        lambda n: tuple(f"E{i}" for i in range(1, n + 1)),
    )
)
register_fitness(
    FitnessKind("physics", "the physics model: rigid body and the robot's friction", lambda n: ())
)
FITNESS = tuple(FITNESS_KINDS)


def fitness_kind(name: str) -> FitnessKind:
    """The registered fitness ``name``; InvalidInput naming the choices otherwise."""
    try:
        return FITNESS_KINDS[name]
    except KeyError:
        raise InvalidInput(f"fitness must be one of {', '.join(FITNESS_KINDS)}, got {name!r}") from None


PENALTY = 1000.0
"""J per unit of limit violation (see the module docstring)."""
FINE_FACTOR = 10
"""Limits and the energy integral are checked on a grid this many times finer than the samples.

The one definition of the fine grid: the jerk penalty here, the searches and the
verification (:mod:`joulepath.optimize._verify`) all measure on it.
"""


@dataclass(frozen=True, slots=True)
class Violation:
    """Limit violations of each path: range (rad), overspeed and overtorque (relative)."""

    range: FloatArray
    speed: FloatArray
    torque: FloatArray

    @property
    def total(self) -> FloatArray:
        out: FloatArray = self.range + self.speed + self.torque
        return out


def limit_violation(
    robot: Robot,
    traj: Trajectory,
    tau: FloatArray | None = None,
    *,
    acceleration_limit: FloatArray | None = None,
    jerk_limit: FloatArray | None = None,
) -> Violation:
    """Violations of paths q, qd (and torques tau) of shape (P, n_steps, n).

    With ``acceleration_limit`` (rad/s², one per joint) the relative over-acceleration
    counts with the overspeed, and so does with ``jerk_limit`` (rad/s³) the relative
    over-jerk, the jerk being the difference of consecutive accelerations over the
    sample period (as the limit check measures it, on its grid).
    """
    q = traj.q if traj.q.ndim == 3 else traj.q[None]
    qd = traj.qd if traj.qd.ndim == 3 else traj.qd[None]
    lo, hi = robot.joint_ranges()
    lo = np.where(np.isfinite(lo), lo, -np.inf)
    hi = np.where(np.isfinite(hi), hi, np.inf)
    over = np.maximum(q - hi, 0.0) + np.maximum(lo - q, 0.0)
    rng_v = over.max(axis=1).sum(axis=1)
    vmax = robot.velocity_limit
    ratio = np.abs(qd) / np.where(np.isfinite(vmax), vmax, np.inf)
    spd_v = np.maximum(ratio.max(axis=1) - 1.0, 0.0).sum(axis=1)
    if acceleration_limit is not None:
        qdd = traj.qdd if traj.qdd.ndim == 3 else traj.qdd[None]
        amax = np.asarray(acceleration_limit, dtype=float)
        acc = np.abs(qdd) / np.where(np.isfinite(amax) & (amax > 0), amax, np.inf)
        spd_v = spd_v + np.maximum(acc.max(axis=1) - 1.0, 0.0).sum(axis=1)
    if jerk_limit is not None and traj.t.size > 1:
        qdd = traj.qdd if traj.qdd.ndim == 3 else traj.qdd[None]
        jmax = np.asarray(jerk_limit, dtype=float)
        jerk = np.abs(np.diff(qdd, axis=1)) / traj.dt
        jer = jerk / np.where(np.isfinite(jmax) & (jmax > 0), jmax, np.inf)
        spd_v = spd_v + np.maximum(jer.max(axis=1) - 1.0, 0.0).sum(axis=1)
    trq_v = np.zeros_like(rng_v)
    emax = robot.effort_limit
    if tau is not None and np.any(np.isfinite(emax)):
        t = tau if tau.ndim == 3 else tau[None]
        r = np.abs(t) / np.where(np.isfinite(emax), emax, np.inf)
        trq_v = np.maximum(r.max(axis=1) - 1.0, 0.0).sum(axis=1)
    return Violation(range=rng_v, speed=spd_v, torque=trq_v)


ROBOT_FRICTION = "robot"
"""``friction=ROBOT_FRICTION``: the robot's own friction (:attr:`Robot.friction`)."""


def physics_energy(
    robot: Robot, traj: Trajectory, *, friction: Any = ROBOT_FRICTION, measure: str = DEFAULT_MEASURE
) -> tuple[FloatArray, FloatArray]:
    """Per-path motion energy ``Σ_k P_k dt`` (J) on a measure, and the torques, of paths (P, n_steps, n).

    ``friction``: the robot's own by default; None for the rigid body only. ``measure``:
    a name of :data:`joulepath.energy.MEASURES` (default the thesis' ``Σ |tau qd| dt``);
    its data come from :attr:`Robot.drivetrain`. The standby power, the same for every
    path of a duration, is not included.
    """
    if isinstance(friction, str) and friction == ROBOT_FRICTION:
        friction = robot.friction
    tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=friction)
    if measure == DEFAULT_MEASURE:
        e = path_energy(tau, traj.qd, traj.dt).total
    else:
        e = measure_power(measure, tau, traj.qd, robot.drivetrain).value.sum(axis=-1) * traj.dt
    return np.atleast_1d(e), tau


@dataclass(eq=False)
class TrajectoryProblem:
    """Chromosomes (flattened (n, 6) coefficient matrices: 6 per joint) to penalized path energy.

    Implements :class:`joulepath.evolve.Problem`.
    """

    robot: Robot
    q_start: FloatArray
    q_end: FloatArray
    duration: float
    fitness: str = "physics"
    models: tuple[Any, ...] = ()
    parametrization: str = "rest_to_rest"
    dt: float = 0.025
    acceleration_limit: FloatArray | None = None
    jerk_limit: FloatArray | None = None
    energy_measure: str = DEFAULT_MEASURE
    n_evaluated: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        if self.parametrization not in PARAMETRIZATIONS:
            raise InvalidInput(
                f"parametrization must be one of {PARAMETRIZATIONS}, got {self.parametrization!r}"
            )
        need = len(fitness_kind(self.fitness).model_targets(self.robot.n_joints))
        if len(self.models) != need:
            raise InvalidInput(f"fitness {self.fitness!r} needs {need} model(s), got {len(self.models)}")
        self.q_start = np.asarray(self.q_start, dtype=float)
        self.q_end = np.asarray(self.q_end, dtype=float)

    @property
    def n_var(self) -> int:
        """``6·n``: six polynomial coefficients per joint (36 for a 6-joint arm)."""
        return N_COEFFICIENTS * self.robot.n_joints

    @property
    def xl(self) -> FloatArray:
        return np.full(self.n_var, GRID_LOW)

    @property
    def xu(self) -> FloatArray:
        return np.full(self.n_var, GRID_HIGH)

    def trajectory(self, X: FloatArray, *, dt: float | None = None) -> Trajectory:
        """Paths of chromosomes X (P, 6·n) or (6·n,), on the samples (or every ``dt`` s)."""
        chrom = np.asarray(X, dtype=float).reshape(-1, self.robot.n_joints, N_COEFFICIENTS)
        build = rest_to_rest if self.parametrization == "rest_to_rest" else thesis_quintic
        return build(chrom, self.q_start, self.q_end, self.duration, dt=self.dt if dt is None else dt)

    def energy(self, traj: Trajectory) -> tuple[FloatArray, FloatArray | None]:
        """Unpenalized fitness energy of paths (J) and torques where computed."""
        if not fitness_kind(self.fitness).needs_models:
            return physics_energy(self.robot, traj, friction=self.robot.friction, measure=self.energy_measure)
        P, n = traj.q.shape[0], traj.q.shape[1]
        total = np.zeros(P)
        cache: dict[tuple[str, ...], FloatArray] = {}
        for model in self.models:
            cols = model.input_columns
            if cols not in cache:
                cache[cols] = path_features(self.robot, traj, cols)
            total += model.predict_rows(cache[cols]).reshape(P, n).sum(axis=1)
        return total, None

    def evaluate(self, X: FloatArray) -> FloatArray:
        """Penalized energy; with a jerk limit the kinematic limits are penalized on the fine grid.

        A jerk that peaks between samples (at the ends of a polynomial path) is averaged
        away by the samples' differences, so with ``jerk_limit`` the ranges, speeds,
        accelerations and jerks are measured on the grid results are checked on
        (``FINE_FACTOR`` times finer), the efforts on the samples.
        """
        traj = self.trajectory(X)
        energy, tau = self.energy(traj)
        self.n_evaluated += energy.size
        amax, jmax = self.acceleration_limit, self.jerk_limit
        if jmax is None:
            viol = limit_violation(self.robot, traj, tau, acceleration_limit=amax)
            total = viol.total
        else:
            fine = self.trajectory(X, dt=self.dt / FINE_FACTOR)
            kin = limit_violation(self.robot, fine, None, acceleration_limit=amax, jerk_limit=jmax)
            total = kin.range + kin.speed + limit_violation(self.robot, traj, tau).torque
        out: FloatArray = energy + PENALTY * total
        return out
