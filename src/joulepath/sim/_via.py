"""Where the via points of an optimized move go, so that the controller can follow them.

An optimized move (or a fly-by chain of them) is written as ``MoveAbsJ`` via points, each
with ``\\T`` and a large zone; the controller runs such a chain as the emulation in
:mod:`joulepath.sim._timing` models it: constant joint velocity between the points,
a corner path (velocity linear in time) inside each zone, the zone reduced to half the
TCP distance to the nearest point, sin² ramps from and to rest at the acceleration limit.
A corner the controller cannot keep (a joint over its acceleration limit in the corner,
or a ramp that does not fit) breaks the chain there and costs time.

The layout: inside each move, the points sit at equal TCP arc length along the planned
path (equal distances keep the zones, and so the corners, as wide as the rule allows),
about ``spacing`` seconds apart on average; the move's own target always stays a point.
Then, while the emulated chain breaks at a corner, the via point there is removed
(its two segments merge into one, longer, with a wider corner), unless it is a target.
What remains is checked by the caller, on the whole written program
(:func:`joulepath.program._output.check_written`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.abb import VIA_ZONE_MM
from joulepath.dynamics import Robot
from joulepath.sim._controller import ControllerConfig
from joulepath.sim._profile import Profile
from joulepath.sim._steps import SpeedData, Step
from joulepath.sim._timing import (
    FINE_DT,
    SegmentPath,
    _chain_profiles,
    _tcp,
    evaluate_cycle,
    fastest_profile,
    plan_cycle,
    segment_path,
)
from joulepath.trajectory import Trajectory

VIA_SPEED = SpeedData(7000.0, 500.0, 5000.0, 1000.0)
"""``v7000``: the speed data written with the via points (``\\T`` replaces it)."""
MAX_MERGES = 400
"""Via points removed at most per chain before the layout is returned as it is."""


def _leg_indices(robot: Robot, tcp: FloatArray, fine: Trajectory, spacing: float) -> list[int]:
    """Sample indices of one move's via points (its last sample included), equal in TCP arc length."""
    n_seg = max(2, int(round(float(fine.t[-1]) / spacing)))
    pos, _ = _tcp(robot, fine.q, tcp)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pos, axis=0), axis=1))])
    last = fine.t.size - 1
    if arc[-1] < 1e-6:  # the TCP hardly moves (a wrist turn): equal times
        marks = np.linspace(0.0, float(fine.t[-1]), n_seg + 1)[1:]
        idx = np.round(marks / fine.dt).astype(int)
    else:
        idx = np.searchsorted(arc, np.linspace(0.0, arc[-1], n_seg + 1)[1:], side="left")
    out = sorted({int(min(max(i, 1), last)) for i in idx} | {last})
    return out


def layout(
    robot: Robot,
    tcp: FloatArray,
    legs: Sequence[Trajectory],
    *,
    spacing: float,
    config: ControllerConfig,
    target_zones: Sequence[float | None] | None = None,
) -> list[list[int]]:
    """Via points of a chain of moves (one ``Trajectory`` per move, each from t = 0; the chain
    starts and ends at rest): per move, sample indices into its trajectory, the last its target.

    ``target_zones``: the zone (mm) written at each move's target inside the chain (the
    program's own, so the path stays as close to the taught target as the programmer allowed);
    default: the via points' zone."""
    zones = list(target_zones) if target_zones is not None else [VIA_ZONE_MM] * len(legs)
    points: list[tuple[int, int]] = []  # (move, sample index)
    for k, leg in enumerate(legs):
        points += [(k, i) for i in _leg_indices(robot, tcp, leg, spacing)]
    targets = {(k, leg.t.size - 1) for k, leg in enumerate(legs)}
    segments = [_segment(robot, tcp, legs, points, n, config, zones) for n in range(len(points))]
    for _ in range(MAX_MERGES):
        _, bad = _chain_profiles(segments, set(range(len(segments) - 1)), config)
        if bad is None:
            break
        # remove the via point at the broken corner; at a target, the point beyond the shorter of
        # its two segments (that one limits the zone); nothing to remove: leave the chain as it is
        drop: int | None = bad
        if points[bad] in targets:
            shorter_before = segments[bad][2].length_mm <= segments[bad + 1][2].length_mm
            drop = bad - 1 if shorter_before else bad + 1
            if drop < 0 or drop >= len(points) - 1 or points[drop] in targets:
                drop = None
        if drop is None:
            break
        del points[drop]
        del segments[drop]
        segments[drop] = _segment(robot, tcp, legs, points, drop, config, zones)
    out: list[list[int]] = [[] for _ in legs]
    for k, i in points:
        out[k].append(i)
    return out


def _segment(
    robot: Robot,
    tcp: FloatArray,
    legs: Sequence[Trajectory],
    points: Sequence[tuple[int, int]],
    n: int,
    config: ControllerConfig,
    zones: Sequence[float | None],
) -> tuple[int, Step, SegmentPath, Profile, float, bool]:
    """The controller's plan entry of the ``n``-th via move (what :func:`chain_corners` takes)."""
    k, i = points[n]
    if n == 0:
        q_prev, t_prev = legs[0].q[0], 0.0
    else:
        kp, ip = points[n - 1]
        q_prev, t_prev = legs[kp].q[ip], (float(legs[kp].t[ip]) if kp == k else 0.0)
    last = n == len(points) - 1
    step = Step(
        kind="move",
        line=n + 1,
        label=f"via {n + 1}",
        statement=None,
        q=legs[k].q[i],
        speed=VIA_SPEED,
        time_s=float(legs[k].t[i]) - t_prev,
        zone_mm=None if last else zones[k] if i == legs[k].t.size - 1 else VIA_ZONE_MM,
        tcp=tcp,
        robot=robot,
    )
    path = segment_path(step, q_prev, "via points")
    if np.abs(legs[k].q[i] - q_prev).max() <= 1e-12:
        fastest = Profile(ta=0.0, tc=0.0, v=0.0)
    else:
        fastest = fastest_profile(step, path, config)
    return (n, step, path, fastest, 0.0, last)


RAPID_ACCEL_SHARE = 3.0 / (2.0 * np.pi)
"""Share of the controller's acceleration limit that a path written as via points may use.

A timed chain starts and ends with the controller's own sin² ramp at its acceleration limit
``a``, inside the first (last) segment of ``T`` s, and the corner to the next segment takes
up to half of it (:func:`joulepath.sim._timing.chain_corners`). A path that accelerates
from rest at ``a_p`` covers ``a_p T² / 2`` in its first segment; the controller's ramp
``r = T - sqrt(T² - pi |dq| / a)`` fits before the corner (``r <= T / 2``) when
``pi a_p / (2 a) <= 3/4``, i.e. ``a_p <= 3 a / (2 pi)`` (0.477 a)."""
VIA_SPACINGS = (0.04, 0.05, 0.075, 0.1)
"""s between via points tried by :func:`follow_path` (the layout the controller keeps best wins)."""


@dataclass(frozen=True, slots=True, eq=False)
class FollowedPath:
    """A path written as timed via points, and the motion the emulated controller makes of it.

    ``indices``: the via points (sample indices into the planned path, its last sample the
    target); ``spacing``: the mean spacing (s) the layout started from; ``executed``: the
    commanded motion on a grid of ``dt`` from the first via move's start to the robot's stop
    at the target (``executed_duration_s``); ``max_joint_deviation_rad``: the largest
    difference between the planned and the executed joint positions at the same time.
    """

    indices: tuple[int, ...]
    spacing: float
    executed: Trajectory
    executed_duration_s: float
    max_joint_deviation_rad: float


class _Steps:
    """A :class:`~joulepath.sim.StepSequence` of loose steps."""

    def __init__(self, steps: Sequence[Step], start: FloatArray, source: str) -> None:
        self.steps = tuple(steps)
        self.start = np.asarray(start, dtype=float)
        self.source = source


def _run(
    robot: Robot, steps: Sequence[Step], start: FloatArray, config: ControllerConfig, dt: float
) -> tuple[float, Trajectory]:
    plan = plan_cycle(_Steps(steps, start, "the written program"), config)
    end = plan.moves[-1].t_end
    n = max(2, int(np.ceil(end / dt)) + 1)
    return end, evaluate_cycle(plan, np.linspace(0.0, end, n))


def timed_move(
    robot: Robot,
    q_start: FloatArray,
    q_end: FloatArray,
    duration: float,
    *,
    config: ControllerConfig | None = None,
    dt: float = FINE_DT,
) -> tuple[float, Trajectory]:
    """``MoveAbsJ q_end, v7000 \\T:=duration, fine`` from rest at ``q_start``: the controller's
    own move in (at least) ``duration`` s, as it runs it (its duration and motion on ``dt``)."""
    step = Step(
        kind="move",
        line=1,
        label="MoveAbsJ \\T",
        statement=None,
        q=np.asarray(q_end, dtype=float),
        speed=VIA_SPEED,
        time_s=float(duration),
        zone_mm=None,
        tcp=np.eye(4),
        robot=robot,
    )
    return _run(robot, [step], np.asarray(q_start, dtype=float), config or ControllerConfig(), dt)


def via_steps(
    robot: Robot, path: Trajectory, indices: Sequence[int], *, tcp: FloatArray | None = None
) -> list[Step]:
    """The ``MoveAbsJ`` via moves (``\\T``, ``z200``, the last ``fine``) through ``path``'s samples."""
    tool = np.eye(4) if tcp is None else tcp
    steps, prev = [], 0.0
    for k, i in enumerate(indices):
        last = k == len(indices) - 1
        steps.append(
            Step(
                kind="move",
                line=k + 1,
                label=f"via {k + 1}",
                statement=None,
                q=path.q[i],
                speed=VIA_SPEED,
                time_s=float(path.t[i]) - prev,
                zone_mm=None if last else VIA_ZONE_MM,
                tcp=tool,
                robot=robot,
            )
        )
        prev = float(path.t[i])
    return steps


def follow_path(
    robot: Robot,
    path: Trajectory,
    *,
    config: ControllerConfig | None = None,
    spacings: Sequence[float] = VIA_SPACINGS,
    dt: float = FINE_DT,
) -> FollowedPath:
    """The via-point layout of a rest-to-rest path that the emulated controller follows most closely.

    Each spacing of ``spacings`` is laid out (:func:`layout`, one move from rest to rest),
    written as :func:`via_steps` and run by the controller emulation; the layout whose
    executed motion stays closest to the plan (largest joint deviation at the same time,
    then the duration) is returned with its executed motion.
    """
    cfg = config or ControllerConfig()
    tcp = np.eye(4)
    best: FollowedPath | None = None
    for spacing in spacings:
        idx = layout(robot, tcp, [path], spacing=spacing, config=cfg, target_zones=[None])[0]
        end, executed = _run(robot, via_steps(robot, path, idx), path.q[0], cfg, dt)
        planned = _interpolate(path, np.minimum(executed.t, float(path.t[-1])))
        dev = float(np.abs(planned - executed.q).max())
        candidate = FollowedPath(tuple(idx), float(spacing), executed, float(end), dev)
        score = (round(dev, 6), abs(end - float(path.t[-1])))
        if best is None or score < (
            round(best.max_joint_deviation_rad, 6),
            abs(best.executed_duration_s - float(path.t[-1])),
        ):
            best = candidate
    assert best is not None
    return best


def _interpolate(path: Trajectory, t: FloatArray) -> FloatArray:
    """The path's positions at ``t``: quintic Hermite through its samples (q, qd, qdd)."""
    from joulepath.trajectory import quintic_hermite

    out: FloatArray = quintic_hermite(path.t, path.q, path.qd, path.qdd)(t)
    return out
