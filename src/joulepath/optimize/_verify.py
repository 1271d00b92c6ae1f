"""Verification of a move: limits on a fine grid, energies on physics and on the lab plant.

Everything a result claims is measured here, independently of the search that found
it: the physics energy ``Σ |tau qd| dt`` on the samples (the reported metric) and on
a grid ``FINE_FACTOR`` times finer (the integral it approximates, which a path
cannot game by moving between samples), the joint ranges, speed, acceleration, jerk and
effort limits on the fine grid, and the TCP's largest distance from the default move's.

Jerk is the difference of consecutive accelerations over the grid step
(:func:`path_jerk`): the exact mean jerk over each step of the fine grid, for any
path whatever its representation; the gradient search constrains the same quantity.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Friction, Robot
from joulepath.energy import DEFAULT_MEASURE, MeasuredEnergy, measure_energy
from joulepath.optimize._problem import FINE_FACTOR, physics_energy
from joulepath.trajectory import Trajectory, minimum_jerk, sample_times

TOLERANCE = 1e-7
"""Relative (speed, effort) or absolute (rad) excess below which a limit counts as held."""


@dataclass(frozen=True, slots=True)
class LimitExcess:
    """The worst excess of one kind of limit: which joint, where, by how much."""

    kind: str  # "range", "speed", "acceleration", "jerk" or "effort"
    joint: int  # 1-based
    t_s: float
    value: float  # SI: rad, rad/s, rad/s², rad/s³ or N·m
    limit: float
    excess: float  # relative for speed and effort (0.19 = 19 % over), rad for range

    def describe(self) -> str:
        unit = {
            "range": "deg",
            "speed": "deg/s",
            "acceleration": "deg/s²",
            "jerk": "deg/s³",
            "effort": "N·m",
        }[self.kind]
        conv = np.degrees if self.kind != "effort" else (lambda v: v)
        over = (
            f"{np.degrees(self.excess):.2f} deg past it"
            if self.kind == "range"
            else f"{100 * self.excess:.1f} % over"
        )
        return (
            f"joint {self.joint} {self.kind} {float(conv(self.value)):.2f} {unit} at t = {self.t_s:.3f} s "
            f"against its limit {float(conv(self.limit)):.2f} {unit} ({over})"
        )


@dataclass(frozen=True, slots=True)
class LimitReport:
    """Limit check of one path on the fine grid; ``worst`` holds one entry per violated kind."""

    range_rad: float
    overspeed: float
    overtorque: float
    worst: tuple[LimitExcess, ...]

    @property
    def ok(self) -> bool:
        return not self.worst


def path_jerk(path: Trajectory) -> tuple[FloatArray, FloatArray]:
    """Jerk of a path on its grid: ``(qdd[k+1] - qdd[k]) / dt`` at the midpoints of its steps.

    The exact mean jerk over each step (rad/s³), for any path whose acceleration is
    continuous. Returns the midpoint times (n_steps - 1,) and the jerk (..., n_steps - 1, n).

    Examples
    --------
    >>> from joulepath.trajectory import minimum_jerk
    >>> t, jerk = path_jerk(minimum_jerk([0.0], [1.0], 1.0, dt=0.001))
    >>> round(float(abs(jerk).max()), 1)  # 60 |dq| / T³ at the ends, less a sliver
    59.8
    """
    out: FloatArray = np.diff(path.qdd, axis=-2) / path.dt
    return 0.5 * (path.t[1:] + path.t[:-1]), out


def check_limits(
    robot: Robot,
    fine: Trajectory,
    *,
    friction: Friction | None,
    acceleration_limit: FloatArray | None = None,
    jerk_limit: FloatArray | None = None,
) -> LimitReport:
    """Ranges, speed, acceleration and jerk (if given) and effort limits (if stated) of a path, on its grid.

    The jerk is :func:`path_jerk` on the path's grid; its relative excess counts, like the
    acceleration's, in ``overspeed``.
    """
    lo, hi = robot.joint_ranges()
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    emax = np.asarray(robot.effort_limit, dtype=float)
    q, qd = fine.q, fine.qd
    over_q = np.maximum(q - hi, 0.0) + np.maximum(lo - q, 0.0)
    worst: list[LimitExcess] = []

    def note(
        kind: str,
        excess: FloatArray,
        value: FloatArray,
        limit: FloatArray,
        tol: float,
        t: FloatArray = fine.t,
    ) -> float:
        if not excess.size:
            return 0.0
        k, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
        if excess[k, j] > tol:
            worst.append(
                LimitExcess(
                    kind=kind,
                    joint=int(j) + 1,
                    t_s=float(t[k]),
                    value=float(value[k, j]),
                    limit=float(np.broadcast_to(limit, excess.shape)[k, j]),
                    excess=float(excess[k, j]),
                )
            )
        return float(max(excess.max(axis=0).sum(), 0.0)) if excess[k, j] > tol else 0.0

    r = note("range", over_q, q, np.where(q > hi, hi, lo), TOLERANCE)
    rng = robot.axis3_range
    if rng is not None and q.shape[-1] >= 3:  # the controller's coupled axis 3 (joint 2 + joint 3)
        a3 = robot.joints_to_axes(q)[..., 2:3]
        over3 = np.maximum(a3 - rng[1], 0.0) + np.maximum(rng[0] - a3, 0.0)
        r += note(
            "axis-3 range",
            over3 * np.eye(q.shape[-1])[2],
            a3 * np.eye(q.shape[-1])[2],
            np.where(a3 > rng[1], rng[1], rng[0]),
            TOLERANCE,
        )
    v_lim = np.where(np.isfinite(vmax) & (vmax > 0), vmax, np.inf)
    s = note("speed", np.abs(qd) / v_lim - 1.0, qd, v_lim, TOLERANCE)
    if acceleration_limit is not None:
        a_lim = np.where(np.isfinite(acceleration_limit), acceleration_limit, np.inf)
        s += note("acceleration", np.abs(fine.qdd) / a_lim - 1.0, fine.qdd, a_lim, TOLERANCE)
    if jerk_limit is not None:
        j_lim = np.where(np.isfinite(jerk_limit), jerk_limit, np.inf)
        t_mid, jerk = path_jerk(fine)
        s += note("jerk", np.abs(jerk) / j_lim - 1.0, jerk, j_lim, TOLERANCE, t_mid)
    e = 0.0
    if np.any(np.isfinite(emax)):
        tau = robot.inverse_dynamics(q, qd, fine.qdd, friction=friction)
        e_lim = np.where(np.isfinite(emax) & (emax > 0), emax, np.inf)
        e = note("effort", np.abs(tau) / e_lim - 1.0, tau, e_lim, TOLERANCE)
    return LimitReport(range_rad=r, overspeed=s, overtorque=e, worst=tuple(worst))


def energy_on_samples(
    robot: Robot, path: Trajectory, *, friction: Friction | None, measure: str = DEFAULT_MEASURE
) -> float:
    """The reported metric over the path's samples (J): ``Σ |tau qd| dt``, or another measure's motion energy.

    The standby power of ``measure`` is not included (:func:`measured_energy` adds it).
    """
    energy, _ = physics_energy(robot, path, friction=friction, measure=measure)
    return float(energy[0])


def measured_energy(
    robot: Robot, path: Trajectory, *, friction: Friction | None, measure: str = DEFAULT_MEASURE
) -> MeasuredEnergy:
    """A path's energy on ``measure`` over its samples, on the robot's model, standby over its duration."""
    tau = robot.inverse_dynamics(path.q, path.qd, path.qdd, friction=friction)
    return measure_energy(
        measure, tau, path.qd, path.dt, robot.drivetrain, duration=float(path.t[-1] - path.t[0])
    )


def plant_energy(plant: Any, path: Trajectory, *, measure: str = "mechanical") -> float:
    """A plant's energy over the path's samples (J), standby included where the measure counts it.

    The default ``"mechanical"`` is ``Σ |tau qd| dt`` of the plant's drive torque
    (``plant.drive_torque``, the logged torque: its gears included), what a log of the
    plant integrates to.
    """
    return plant_measured(plant, path, measure=measure).total_J


def plant_measured(plant: Any, path: Trajectory, *, measure: str) -> MeasuredEnergy:
    """A plant's energy on ``measure`` over the path's samples: its joint torque through its own gears."""
    tau = plant.joint_torque(path.q, path.qd, path.qdd)
    return measure_energy(
        measure, tau, path.qd, path.dt, plant.drivetrain, duration=float(path.t[-1] - path.t[0])
    )


def tcp_deviation_mm(robot: Robot, path: Trajectory, reference: Trajectory) -> float:
    """Largest distance (mm) between the TCPs of two paths sampled on the same grid."""
    a = robot.fk(path.q).position_m
    b = robot.fk(reference.q).position_m
    return float(1000.0 * np.linalg.norm(a - b, axis=-1).max())


def default_fine(q_start: FloatArray, q_end: FloatArray, duration: float, dt: float) -> Trajectory:
    """The minimum-jerk move on the fine verification grid."""
    return minimum_jerk(q_start, q_end, duration, dt=dt / FINE_FACTOR)


def shortest_feasible_duration(
    robot: Robot,
    q_start: FloatArray,
    q_end: FloatArray,
    *,
    dt: float,
    friction: Friction | None,
    acceleration_limit: FloatArray | None = None,
    jerk_limit: FloatArray | None = None,
    longest: float = 60.0,
) -> float | None:
    """Shortest whole-sample duration whose minimum-jerk move respects every limit (None: none ≤ ``longest``).

    Starts at the speed bound (``1.875 |Δq| / v_max``, the minimum-jerk peak), the
    acceleration bound (``10/sqrt(3) |Δq| / T²``) and the jerk bound (``60 |Δq| / T³``)
    and steps up one sample at a time while a limit is exceeded on the fine grid.
    """
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    v_lim = np.where(np.isfinite(vmax) & (vmax > 0), vmax, np.inf)
    travel = np.abs(np.asarray(q_end) - np.asarray(q_start))
    need = float(np.max(1.875 * travel / v_lim))
    if acceleration_limit is not None:  # minimum-jerk peak acceleration 10/sqrt(3) |Δq| / T²
        a_lim = np.where(np.isfinite(acceleration_limit), acceleration_limit, np.inf)
        need = max(need, float(np.max(np.sqrt(10 / np.sqrt(3) * travel / a_lim))))
    if jerk_limit is not None:  # minimum-jerk peak jerk 60 |Δq| / T³ (at the ends), less a
        # margin: the checked jerk is the mean over the fine grid's first step, a little lower
        j_lim = np.where(np.isfinite(jerk_limit), jerk_limit, np.inf)
        need = max(need, 0.95 * float(np.max(np.cbrt(60 * travel / j_lim))))
    steps = max(1, int(np.ceil(need / dt - 1e-9)))
    while steps * dt <= longest + 1e-9:
        T = steps * dt
        sample_times(T, dt)
        fine = default_fine(q_start, q_end, T, dt)
        report = check_limits(
            robot, fine, friction=friction, acceleration_limit=acceleration_limit, jerk_limit=jerk_limit
        )
        if report.ok:
            return round(T, 9)
        steps += 1 if steps < 400 else steps // 50
    return None
