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

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.sim._controller import ControllerConfig
from joulepath.sim._profile import Profile
from joulepath.sim._steps import SpeedData, Step
from joulepath.sim._timing import SegmentPath, _chain_profiles, _tcp, fastest_profile, segment_path
from joulepath.trajectory import Trajectory

VIA_ZONE_MM = 200.0
"""Zone of the via points (``z200``): large, so that the controller reduces it to half the
distance to the neighbouring via points and keeps speed through them."""
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
