"""Zone and limit geometry of a cycle's units: pure functions of the robot, the taught moves and the
settings (the controller's zones at fly-by targets, the joint boxes that keep the TCP within them,
the limits an optimized move keeps, the distance to the cell)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.optimize import acceleration_limit, jerk_limit
from joulepath.program._cell import Cell, clearance
from joulepath.program._cycle_model import STEP, CycleSettings
from joulepath.program._resolve import Step
from joulepath.sim import FINE_DT, RAPID_ACCEL_SHARE, PlannedCycle, PlannedMove, evaluate_cycle
from joulepath.sim import tcp_pose as _tcp
from joulepath.trajectory import Trajectory

Passes = tuple[tuple[float, FloatArray], ...]
"""When a unit passes its inner targets (s from its start) and the targets (joint positions)."""


# ------------------------------------------------------------ limits
def move_robot(m: PlannedMove) -> Robot:
    """The robot that runs move ``m``."""
    assert m.step.robot is not None
    return m.step.robot


def acceleration_bound(robot: Robot, settings: CycleSettings) -> FloatArray | None:
    """The joints' acceleration limit (rad/s²) of an optimized move (None: none), within
    :data:`joulepath.sim.RAPID_ACCEL_SHARE` of it for via points."""
    a = acceleration_limit(robot, settings.accel_time)
    if a is not None and settings.follow == "via-points":
        a = a * RAPID_ACCEL_SHARE
    return a


def acceleration_bound_array(robot: Robot, settings: CycleSettings) -> FloatArray:
    """:func:`acceleration_bound`, infinite where there is none."""
    a = acceleration_bound(robot, settings)
    return np.full(robot.n_joints, np.inf) if a is None else a


def jerk_bound(robot: Robot, settings: CycleSettings) -> FloatArray | None:
    """The joints' jerk limit (rad/s³) of an optimized move (None: none)."""
    return jerk_limit(robot, settings.accel_time, settings.jerk_time)


def clearance_mm(cell: Cell, m: PlannedMove, q: FloatArray) -> float:
    """Smallest distance (mm) beyond the margin to the cell along ``q`` (joint positions of move
    ``m``'s robot with its tool); negative: too close."""
    assert m.step.tcp is not None
    c = clearance(cell, move_robot(m), q, m.step.tcp)
    return 1000.0 * (c.distance - cell.margin)


def passes_reachable(
    robot: Robot,
    amax: FloatArray,
    legs: Sequence[tuple[FloatArray, FloatArray]],
    radius: Sequence[FloatArray],
    edges: tuple[int, ...],
    units: int,
    *,
    rest: bool,
) -> bool:
    """Whether a chain of ``legs`` (each move's start and end, joint positions) can pass its inner
    targets at samples ``edges`` of ``units``, by a bound from kinematics alone: each leg at least
    two samples; each joint covers its travel between two targets, less their zones' ``radius``
    (per inner target), within the speed limit, and from rest (``rest``: a unit from rest to rest,
    its first and last leg; else its ends are the taught motion's and those legs are not bound)
    within the acceleration limit ``amax``, ``d ≤ a t² / 2``."""
    cuts = (0, *edges, units)
    if np.any(np.diff(cuts) < 2):
        return False
    v = np.asarray(robot.velocity_limit, dtype=float)
    radii = [np.zeros(robot.n_joints), *radius, np.zeros(robot.n_joints)]
    n_legs = len(legs)
    for k, (q0, q1) in enumerate(legs):
        if not rest and k in (0, n_legs - 1):
            continue
        d = np.maximum(np.abs(q1 - q0) - radii[k] - radii[k + 1], 0.0)
        t = (cuts[k + 1] - cuts[k]) * STEP
        if np.any(d > v * t + 1e-12):
            return False
        if rest and k in (0, n_legs - 1) and np.any(d > 0.5 * amax * t * t + 1e-12):
            return False
    return True


# ------------------------------------------------------------ zones
def reduced_zone_mm(zone_mm: float, into: PlannedMove, out: PlannedMove) -> float:
    """The zone (mm) the controller keeps at ``into``'s target before ``out``: its radius, reduced to
    half the TCP length of either move."""
    return float(max(0.0, min(zone_mm, 0.5 * into.path.length_mm, 0.5 * out.path.length_mm)))


def tcp_within_zone(
    plan: PlannedCycle, t: FloatArray, into: PlannedMove, out: PlannedMove
) -> NDArray[np.bool_]:
    """Whether the taught TCP at times ``t`` of ``plan`` is within the zone of ``into``'s target, its
    radius reduced to half of ``into``'s and ``out``'s TCP length (as for a chain's targets)."""
    step = into.step
    assert step.robot is not None and step.tcp is not None and step.zone_mm is not None
    R = reduced_zone_mm(step.zone_mm, into, out) / 1000.0
    p, _ = _tcp(step.robot, evaluate_cycle(plan, t).q, step.tcp)
    corner, _ = _tcp(step.robot, into.path.q1[None, :], step.tcp)
    inside: NDArray[np.bool_] = np.linalg.norm(p - corner, axis=1) <= R + 1e-9
    return inside


def within_zone(
    plan: PlannedCycle, lo: float, hi: float, into: PlannedMove, out: PlannedMove, *, earliest: bool
) -> float:
    """The earliest (``earliest``: on the 2.5 ms grid from ``lo``) or the latest (from ``hi``) time
    in ``[lo, hi]`` at which the taught TCP is within the zone of ``into``'s target (its radius
    reduced to half of ``into``'s and ``out``'s TCP length, as for a chain's targets); where it
    never is, the other end of the range (the blend then stays the controller's own)."""
    if into.step.zone_mm is None:
        return lo if earliest else hi
    k = np.arange(int(np.floor(max(hi - lo, 0.0) / FINE_DT + 1e-9)) + 1, dtype=float)
    t: FloatArray = lo + FINE_DT * k if earliest else hi - FINE_DT * k
    inside = np.flatnonzero(tcp_within_zone(plan, t, into, out))
    if inside.size == 0:
        return hi if earliest else lo
    return float(t[inside[0]])


def joint_zone_box(step: Step, zone_m: float) -> FloatArray:
    """The joint box (rad, the same for every joint) around ``step``'s target whose every point keeps
    the TCP within ``zone_m`` of it, to first order with a margin of 1/4:
    ``r = 0.75 R / Σ_j |dp/dq_j|`` (the TCP moves at most Σ_j |dp/dq_j| |dq_j|); zeros for no zone."""
    if zone_m <= 0.0:
        return np.zeros(step.q.size if step.q is not None else 0)
    assert step.q is not None and step.robot is not None and step.tcp is not None
    h = 1e-6
    n = step.q.size
    eye = np.eye(n) * h
    plus, _ = _tcp(step.robot, step.q[None, :] + eye, step.tcp)
    minus, _ = _tcp(step.robot, step.q[None, :] - eye, step.tcp)
    norm = float(np.linalg.norm((plus - minus) / (2 * h), axis=1).sum())
    return np.full(n, 0.75 * zone_m / max(norm, 1e-9))


def zone_miss_mm(step: Step, fine: Trajectory, passes: Passes, zones_mm: Sequence[float]) -> float:
    """Largest TCP distance (mm) beyond its zone (``zones_mm``, per inner target) of a chain's path
    ``fine`` from an inner target, at the time it passes it (0: within every zone)."""
    assert step.robot is not None and step.tcp is not None
    worst = 0.0
    for (t, q), zone in zip(passes, zones_mm, strict=True):
        k = int(np.argmin(np.abs(fine.t - t)))
        p, _ = _tcp(step.robot, fine.q[k][None, :], step.tcp)
        p0, _ = _tcp(step.robot, q[None, :], step.tcp)
        worst = max(worst, 1000.0 * float(np.linalg.norm(p - p0)) - zone)
    return worst


# ------------------------------------------------------------ where a motion passes its targets
def ordered_closest(dist: FloatArray, *, lo: int, hi: int, gap: int) -> list[int]:
    """Sample indices ``k_0 < k_1 < ...`` (at least ``gap`` apart, within ``[lo, hi]``) that
    minimize the summed distances ``dist[j, k_j]``: when the motion passes each target in order.

    A target the chain visits twice is matched to its own pass, not to the closer other one (a
    greedy nearest match could take a later pass and leave no samples for the targets after it).
    Too few samples for the targets: spread evenly over the window."""
    m, n = dist.shape
    hi = min(hi, n - 1)
    if m == 0:
        return []
    if hi - lo < gap * (m - 1):
        return [int(round(v)) for v in np.linspace(0, n - 1, m + 2)[1:-1]]
    cost = np.full((m, n), np.inf)
    arg = np.zeros((m, n), dtype=int)
    cost[0, lo : hi + 1] = dist[0, lo : hi + 1]
    for j in range(1, m):
        prev = cost[j - 1]
        # best predecessor at or before k - gap: a running minimum and where it is
        run = np.minimum.accumulate(prev)
        where = np.maximum.accumulate(np.where(prev == run, np.arange(n), 0))
        ks = np.arange(lo + gap * j, hi + 1)
        cost[j, ks] = dist[j, ks] + run[ks - gap]
        arg[j, ks] = where[ks - gap]
    ks_out = [int(np.argmin(cost[-1]))]
    for j in range(m - 1, 0, -1):
        ks_out.append(int(arg[j, ks_out[-1]]))
    return ks_out[::-1]


def taught_passes(step: Step, traj: Trajectory, targets: Sequence[FloatArray]) -> Passes:
    """Inner ``targets`` of a unit (its first move's ``step``) at the times (on the grid of ``traj``,
    the taught motion over its window) the taught motion comes closest to each (TCP)."""
    assert step.robot is not None and step.tcp is not None
    p, _ = _tcp(step.robot, traj.q, step.tcp)
    if not targets:
        return ()
    dist = np.stack([np.linalg.norm(p - _tcp(step.robot, q[None, :], step.tcp)[0], axis=1) for q in targets])
    ks = ordered_closest(dist, lo=2, hi=p.shape[0] - 3, gap=2)
    return tuple((float(traj.t[k]), q) for k, q in zip(ks, targets, strict=True))
