"""The cycle optimum over every segment of a cycle, MoveL included: IPOPT through CasADi.

:func:`joulepath.optimize.cycle_optimum` solves legs of joint moves from rest to rest.
A cycle's segment (its moves between two stops of the robot) also holds ``MoveL`` moves,
blended into the joint moves and into each other. :func:`segment_optimum` transcribes a
whole segment, in the representation of :mod:`joulepath.optimize._cycle_reference`
(piecewise-constant jerk, CasADi inverse dynamics, ``Σ |tau qd| dt`` smoothed by
continuation), with two kinds of pieces:

* a **line piece** for each ``MoveL``: the TCP keeps its straight line and its tool
  orientation. The move's joint path ``q(s)`` (the inverse kinematics along the line,
  as the controller emulation has it) is a cubic B-spline interpolant of CasADi, so
  ``q'(s)``, ``q''(s)`` and ``q'''(s)`` come by automatic differentiation; the unknowns
  are the path coordinate ``s`` and its first two derivatives at the nodes, with a
  piecewise-constant ``s⃛``. Then ``qd = q' ṡ``, ``qdd = q'' ṡ² + q' s̈``. ``ṡ`` stays in
  ``[0, line_speed]`` (the speeddata's TCP and reorientation speeds over the line's
  length and turn) everywhere: ``ṡ`` is quadratic in each interval, bounded at its nodes
  and by its middle Bernstein coefficient;
* a **joint piece** between two line pieces, or between a line piece and a stop: the
  joint moves in between (their path free, as in :func:`cycle_optimum`), passing each
  target between two joint moves within its joint box, and the blends at the corners.

The relaxation of the zones (stated, and the reason the optimum is a yardstick): a line
piece runs over the part of its line outside the zones at its ends. Where the move before
is blended into it, it may start anywhere in ``s ≤ blend_in``; where the move after is
blended, it may end anywhere in ``s ≥ 1 - blend_out`` (a stop: ``s`` is 0 or 1 at rest).
The joint piece that connects two line pieces is free in joint space (the controller's
corner path stays near the corner; this one need not), continuous in position, speed and
acceleration with the line pieces at both ends. When ``initial`` is given (the taught
motion, as the controller emulation runs it), each zone is widened where needed so that
the initial motion lies inside the relaxation: the line parts ``initial`` spends on the
lines, and its closest approach to each joint target. So the optimum is at least as free
as the controller's motion (and the plan's, which keeps the lines), and its saving is an
upper bound of what the plan can save on the same time: a yardstick, never tighter than
the taught motion. Two limits to that, stated: the transcription's resolution (a piecewise
cubic of ``intervals`` steps per piece; a taught motion near its shortest time, e.g. a MoveL
at its speeddata from rest to rest, may need more intervals to be matched), and IPOPT's
local optimum (it starts from ``initial`` and, in the tests and the bundled examples, ends
below it). Joint, speed, acceleration, jerk and effort limits hold at
``substeps`` points per interval of every piece (on a line piece, the kinematic ones at
``KINEMATIC_CHECKS`` times as many and at each interval's end: not polynomial there).

Time: the segments share ``budget`` (``Σ durations ≤ budget``), each within its own
``t_min``/``t_max``; one segment with ``budget`` = the time the taught program gives it is
the comparison at the taught cycle time (benchmarks/cycle_examples.py).

Verified as :func:`cycle_optimum` is: each segment resampled on a grid of at most
``FINE_DT``, the energy :func:`energy_on_samples` of it, the limits :func:`check_limits`
of it, and each line piece's ``ṡ`` within its ``line_speed``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Friction, Robot
from joulepath.errors import InvalidInput
from joulepath.optimize._cycle_reference import (
    FINE_DT,
    MIN_SUBLEG_S,
    CycleLeg,
    _from_initial,
    _held,
    _interval_function,
    _Leg,
    _node_times,
    _vector,
    _warm_start,
    ipopt_stages,
    leg_lower_bound,
)
from joulepath.optimize._reference import _casadi, _casadi_friction, casadi_rnea
from joulepath.optimize._retime import JointPath
from joulepath.optimize._verify import LimitReport, check_limits, energy_on_samples
from joulepath.sim import PlannedCycle
from joulepath.trajectory import Trajectory

LINE_SAMPLES = 257
"""Points along ``s`` where a line's joint path is sampled for its CasADi B-spline."""
ON_LINE_RAD = 1e-6
"""Largest joint distance (rad) from a line's path at which a sample of ``initial`` is on the line."""
KINEMATIC_CHECKS = 4
"""On a line piece, the joint range, speed, acceleration and jerk are bounded at this many times
``substeps`` points per interval (cheap: the path's spline, no dynamics)."""
SPEED_TOLERANCE = 1e-4
"""Largest relative excess of ``ṡ`` over ``line_speed`` on the verification grid that still counts as held."""


@dataclass(frozen=True, slots=True)
class SegmentMove:
    """One move of a segment, to ``q_end``.

    ``line``: a ``MoveL``'s joint path ``q(s)``, ``s`` in [0, 1], from the move's start
    to ``q_end`` (None: a joint move, its path free). ``zone``: for a joint move followed
    by a joint move, the box (rad, per joint or a scalar) its target is passed in (0:
    exactly). ``blend_in``, ``blend_out``: for a line, how far into the line (share of
    ``s``) the move before may be blended, and from how far before its end the move after
    may be. ``line_speed``: for a line, the largest ``ds/dt`` (1/s).
    """

    q_end: FloatArray
    line: JointPath | None = None
    zone: FloatArray | float = 0.0
    blend_in: float = 0.0
    blend_out: float = 0.0
    line_speed: float = math.inf


@dataclass(frozen=True, slots=True)
class CycleSegment:
    """Moves from rest at ``q_start`` to rest at the last move's target (s: ``t_min``, ``t_max``)."""

    q_start: FloatArray
    moves: tuple[SegmentMove, ...]
    t_min: float = 0.0
    t_max: float = math.inf


@dataclass(frozen=True, slots=True)
class SegmentOptimum:
    """The segments' optimum, verified on a fine grid.

    ``energy_J``, ``segments_energy_J``: ``Σ |tau qd| dt`` of ``paths`` (one per
    segment, a uniform grid of at most ``FINE_DT``); ``lines_s``: per segment, per line
    piece, the samples of that grid inside the piece: their times, and ``s`` and ``ṡ``
    (rows); ``line_speed_excess``: the largest ``ṡ / line_speed - 1`` on them;
    ``feasible``: IPOPT converged, every limit holds on ``paths`` and every line piece
    within its ``line_speed``; ``status``: IPOPT's last status, or why it did not run.
    """

    durations: tuple[float, ...]
    energy_J: float
    segments_energy_J: tuple[float, ...]
    paths: tuple[Trajectory, ...]
    feasible: bool
    status: str
    wall_s: float
    limits: tuple[LimitReport, ...] = ()
    lines_s: tuple[tuple[tuple[FloatArray, FloatArray], ...], ...] = ()
    line_speed_excess: float = 0.0


@dataclass(frozen=True, slots=True, eq=False)
class _Line:
    """A line piece: its move, the B-spline of its path, the ranges of ``s`` at its ends."""

    path: JointPath
    fn: Any  # CasADi Function s -> (q, q', q'', q''')
    s0: tuple[float, float]  # range of s at its start (a stop: (0, 0))
    s1: tuple[float, float]
    rest0: bool
    rest1: bool
    speed: float


@dataclass(frozen=True, slots=True, eq=False)
class _Joint:
    """A joint piece: its vias and radii; its ends at rest at a given point, or joined to a line."""

    q0: FloatArray | None  # None: joined to the line piece before
    q1: FloatArray | None  # None: joined to the line piece after
    via: tuple[FloatArray, ...]
    radius: tuple[FloatArray, ...]


_Piece = _Line | _Joint


def _line_function(cs: Any, path: JointPath, n: int) -> Any:
    """``s -> (q, q', q'', q''')`` of the path as a CasADi B-spline interpolant (n-vectors)."""
    grid = np.linspace(0.0, 1.0, LINE_SAMPLES)
    q, _, _ = path.at(grid)
    interp = cs.interpolant("line", "bspline", [grid], np.asarray(q, dtype=float).ravel())
    s = cs.SX.sym("s")
    e = interp(s)
    d1 = cs.jacobian(e, s)
    d2 = cs.jacobian(d1, s)
    d3 = cs.jacobian(d2, s)
    return cs.Function("line_path", [s], [e, d1, d2, d3])


def _pieces(cs: Any, seg: CycleSegment, n: int, name: str) -> list[_Piece]:
    """The segment as alternating joint and line pieces (see the module docstring)."""
    q_prev = _vector(seg.q_start, n, f"{name} q_start")
    moves = seg.moves
    out: list[_Piece] = []
    run_start: FloatArray | None = q_prev  # start of the open joint piece (None: a line's end)
    via: list[FloatArray] = []
    radius: list[FloatArray] = []
    run_open = True
    for k, m in enumerate(moves):
        where = f"{name} move {k}"
        q1 = _vector(m.q_end, n, f"{where} q_end")
        last = k == len(moves) - 1
        if m.line is None:
            if not run_open:
                run_start, via, radius, run_open = None, [], [], True
            if last:
                out.append(_Joint(run_start, q1, tuple(via), tuple(radius)))
                run_open = False
            elif moves[k + 1].line is None:
                r = np.asarray(m.zone, dtype=float)
                if r.ndim > 1 or r.size not in (1, n) or not np.all(np.isfinite(r)) or np.any(r < 0):
                    raise InvalidInput(f"{where} zone must be ≥ 0 rad, a scalar or one per joint ({n})")
                via.append(q1)
                radius.append(np.broadcast_to(r, (n,)).astype(float))
            q_prev = q1
            continue
        for what, v in (("blend_in", m.blend_in), ("blend_out", m.blend_out)):
            if not (math.isfinite(v) and 0.0 <= v <= 1.0):
                raise InvalidInput(f"{where} {what} must be a share of the line in [0, 1], got {v}")
        if not m.line_speed > 0:
            raise InvalidInput(f"{where} line_speed must be > 0 (1/s), got {m.line_speed}")
        rest0 = k == 0
        if not rest0:
            if not run_open:  # a line after a line: the blend between them
                run_start, via, radius = None, [], []
            out.append(_Joint(run_start, None, tuple(via), tuple(radius)))
        run_open = False
        q_line, _, _ = m.line.at(np.array([0.0, 1.0]))
        if np.abs(q_line[0] - q_prev).max() > 1e-6 or np.abs(q_line[1] - q1).max() > 1e-6:
            raise InvalidInput(f"{where} line must run from the move's start to q_end (q(0), q(1))")
        out.append(
            _Line(
                path=m.line,
                fn=_line_function(cs, m.line, n),
                s0=(0.0, 0.0) if rest0 else (0.0, float(m.blend_in)),
                s1=(1.0, 1.0) if last else (1.0 - float(m.blend_out), 1.0),
                rest0=rest0,
                rest1=last,
                speed=float(m.line_speed),
            )
        )
        q_prev = q1
    return out


def _line_interval_function(cs: Any, rnea: Any, friction: Any, path: Any, n: int, substeps: int) -> Any:
    """One interval of a line piece: ``(s, sd, sdd, u, h, eps) -> (next (3,), q, qd, qdd, qddd
    (n, KINEMATIC_CHECKS · substeps + 1), tau (n, substeps + 1), smoothed energy)``, ``u`` the
    constant ``s⃛``. The energy at ``substeps`` points; the effort also at the interval's end; the
    joint range, speed, acceleration and jerk (not polynomial in time on a line) at
    ``KINEMATIC_CHECKS`` times as many points and the end."""
    s, sd, sdd, u, h, eps = (cs.SX.sym(x) for x in ("s", "sd", "sdd", "u", "h", "eps"))
    nxt = cs.vertcat(s + h * sd + h**2 / 2 * sdd + h**3 / 6 * u, sd + h * sdd + h**2 / 2 * u, sdd + h * u)
    kin: list[list[Any]] = [[] for _ in range(4)]
    taus = []
    energy = cs.SX(0)
    dense = KINEMATIC_CHECKS * substeps
    for j in range(dense + 1):
        t_ = h * (j / dense)
        sj = s + t_ * sd + t_**2 / 2 * sdd + t_**3 / 6 * u
        vj = sd + t_ * sdd + t_**2 / 2 * u
        aj = sdd + t_ * u
        q, d1, d2, d3 = path(sj)
        qd = d1 * vj
        qdd = d2 * vj**2 + d1 * aj
        qddd = d3 * vj**3 + 3 * d2 * vj * aj + d1 * u
        for col, x in zip(kin, (q, qd, qdd, qddd), strict=True):
            col.append(x)
        if j % KINEMATIC_CHECKS:
            continue
        tau = rnea(q, qd, qdd)
        if friction is not None:
            tau = tau + friction(qd)
        taus.append(tau)
        if j < dense:
            power = tau * qd
            energy = energy + cs.sum1(cs.sqrt(power**2 + eps**2) - eps) * (h / substeps)
    return cs.Function(
        "line_interval",
        [s, sd, sdd, u, h, eps],
        [nxt, *(cs.horzcat(*c) for c in kin), cs.horzcat(*taus), energy],
    )


def _line_state(path: Any, s: Any, sd: Any, sdd: Any) -> tuple[Any, Any, Any]:
    q, d1, d2, _ = path(s)
    return q, d1 * sd, d2 * sd**2 + d1 * sdd


def _project(path: JointPath, q: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Per row of ``q`` (K, n): the path coordinate of the closest point of ``path``, and the distance."""
    grid = np.linspace(0.0, 1.0, 2049)
    table, _, _ = path.at(grid)
    d = np.abs(q[:, None, :] - table[None, :, :]).max(axis=2)
    s = grid[np.argmin(d, axis=1)]
    for _ in range(4):  # Newton on |q(s) - q|²
        p, d1, d2 = path.at(s)
        r = p - q
        g = np.einsum("ij,ij->i", r, d1)
        hess = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", r, d2)
        s = np.clip(s - g / np.where(hess > 1e-12, hess, 1e-12), 0.0, 1.0)
    p, _, _ = path.at(s)
    return s, np.abs(p - q).max(axis=1)


def _line_start(
    line: _Line, path: Trajectory, a: int, b: int, intervals: int
) -> tuple[FloatArray, FloatArray, FloatArray, float]:
    """A line piece's nodes (s, sd, sdd of shape (N + 1,)) and duration from ``initial``'s samples a..b."""
    t = path.t[a : b + 1]
    s, _ = _project(line.path, path.q[a : b + 1])
    s = np.maximum.accumulate(s)
    _, d1, d2 = line.path.at(s)
    norm = np.maximum(np.einsum("ij,ij->i", d1, d1), 1e-12)
    sd = np.maximum(np.einsum("ij,ij->i", d1, path.qd[a : b + 1]) / norm, 0.0)
    sdd = np.einsum("ij,ij->i", d1, path.qdd[a : b + 1] - d2 * sd[:, None] ** 2) / norm
    T = max(float(t[-1] - t[0]), 2 * MIN_SUBLEG_S)
    nodes = t[0] + np.linspace(0.0, 1.0, intervals + 1) * (t[-1] - t[0])
    return np.interp(nodes, t, s), np.interp(nodes, t, sd), np.interp(nodes, t, sdd), T


def _windows(pieces: list[_Piece], path: Trajectory) -> list[tuple[int, int]]:
    """Per piece, its first and last sample in ``initial``: the line pieces where it runs on their lines."""
    K = path.t.size
    out: list[tuple[int, int]] = []
    lo = 0
    spans: list[tuple[int, int] | None] = []
    for p in pieces:
        if not isinstance(p, _Line):
            spans.append(None)
            continue
        s, dist = _project(p.path, path.q[lo:])
        on = np.flatnonzero(dist <= ON_LINE_RAD)
        if on.size == 0:
            raise InvalidInput("initial does not run on one of the segment's lines; give the taught motion")
        breaks = np.flatnonzero(np.diff(on) > 1)
        run = on[: breaks[0] + 1] if breaks.size else on
        # the line is run forwards: the window ends where s turns back (a line retraced by the
        # next, e.g. a MoveL down and the same MoveL up, stays on this line's path)
        back = np.flatnonzero(np.diff(s[run]) < -1e-7)
        run = run[: back[0] + 1] if back.size else run
        first, last = lo + int(run[0]), lo + int(run[-1])
        spans.append((min(first, K - 2), min(max(last, first + 1), K - 1)))
        lo = last
    edge = 0
    for k, span in enumerate(spans):
        if span is not None:
            out.append(span)
            edge = span[1]
            continue
        nxt = next((x for x in spans[k + 1 :] if x is not None), None)
        end = K - 1 if nxt is None else nxt[0]
        out.append((min(edge, K - 2), min(max(end, edge + 1), K - 1)))
    return out


def _widened(pieces: list[_Piece], path: Trajectory, windows: list[tuple[int, int]]) -> list[_Piece]:
    """The pieces with each zone widened where needed for ``initial`` to lie inside the relaxation."""
    out: list[_Piece] = []
    for p, (a, b) in zip(pieces, windows, strict=True):
        if isinstance(p, _Line):
            s, _ = _project(p.path, path.q[[a, b]])
            s0 = p.s0 if p.rest0 else (0.0, max(p.s0[1], float(s[0])))
            s1 = p.s1 if p.rest1 else (min(p.s1[0], float(s[1])), 1.0)
            out.append(_Line(p.path, p.fn, s0, s1, p.rest0, p.rest1, p.speed))
            continue
        radius, lo = [], a + 1
        for v, r in zip(p.via, p.radius, strict=True):
            dev = np.abs(path.q[lo:b] - v)
            k = int(np.argmin(dev.max(axis=1))) if dev.size else 0
            closest = dev[k] if dev.size else np.zeros_like(r)
            radius.append(np.maximum(r, closest * (1 + 1e-9)))
            lo += k + 1
        out.append(_Joint(p.q0, p.q1, p.via, tuple(radius)))
    return out


def _piece_lower_bound(
    robot: Robot, p: _Piece, q0: FloatArray, amax: FloatArray | None, jmax: FloatArray | None
) -> float:
    if isinstance(p, _Line):
        q, _, _ = p.path.at(np.array([p.s0[1], p.s1[0]]))
        return max(
            leg_lower_bound(
                robot, CycleLeg(q_start=q[0], q_end=q[1]), acceleration_limit=amax, jerk_limit=jmax
            ),
            (p.s1[0] - p.s0[1]) / p.speed,
            1e-3,
        )
    q1 = q0 if p.q1 is None else p.q1
    return max(
        leg_lower_bound(
            robot, CycleLeg(q_start=q0, q_end=q1, via=p.via), acceleration_limit=amax, jerk_limit=jmax
        ),
        1e-3,
    )


def _default_start(
    robot: Robot,
    pieces: list[_Piece],
    seg: CycleSegment,
    budget: float,
    intervals: int,
    amax: FloatArray | None,
    jmax: FloatArray | None,
) -> list[tuple[FloatArray, ...]]:
    """Without ``initial``: a minimum-jerk motion per piece (rest to rest at its ends and vias),
    the time split in proportion to each piece's kinematic lower bound."""
    ends: list[tuple[FloatArray, FloatArray]] = []
    for k, p in enumerate(pieces):
        if isinstance(p, _Line):
            q, _, _ = p.path.at(np.array([sum(p.s0) / 2, sum(p.s1) / 2]))
            ends.append((q[0], q[1]))
            continue
        q0 = p.q0 if p.q0 is not None else ends[-1][1]
        if p.q1 is not None:
            q1 = p.q1
        else:
            nxt = pieces[k + 1]
            assert isinstance(nxt, _Line)
            q1 = nxt.path.at(np.array([sum(nxt.s0) / 2]))[0][0]
        ends.append((q0, q1))
    w = np.array([_piece_lower_bound(robot, p, e[0], amax, jmax) for p, e in zip(pieces, ends, strict=True)])
    T_all = w * min(budget, seg.t_max) / w.sum()
    T_all = np.maximum(T_all, 2 * MIN_SUBLEG_S)
    out: list[tuple[FloatArray, ...]] = []
    for p, (q0, q1), T in zip(pieces, ends, T_all, strict=True):
        if isinstance(p, _Line):
            x = np.linspace(0.0, 1.0, intervals + 1)
            a, b = sum(p.s0) / 2, sum(p.s1) / 2
            out.append(
                (
                    a + (b - a) * x**3 * (10 - 15 * x + 6 * x**2),
                    (b - a) * 30 * x**2 * (1 - x) ** 2 / T,
                    (b - a) * 60 * x * (1 - x) * (1 - 2 * x) / T**2,
                    np.array([T]),
                )
            )
            continue
        leg = _Leg(np.stack([q0, *p.via, q1]), np.zeros((len(p.via), q0.size)), 0.0, math.inf)
        ((Q, V, A, Ts),) = _warm_start(robot, [leg], float(T), intervals, amax, jmax)
        out.append((Q, V, A, Ts))
    return out


def _initial_start(
    pieces: list[_Piece], path: Trajectory, windows: list[tuple[int, int]], intervals: int
) -> list[tuple[FloatArray, ...]]:
    out: list[tuple[FloatArray, ...]] = []
    for p, (a, b) in zip(pieces, windows, strict=True):
        if isinstance(p, _Line):
            s, sd, sdd, T = _line_start(p, path, a, b, intervals)
            out.append((s, sd, sdd, np.array([T])))
            continue
        t = path.t[a : b + 1] - path.t[a]
        part = Trajectory(t=t, q=path.q[a : b + 1], qd=path.qd[a : b + 1], qdd=path.qdd[a : b + 1])
        leg = _Leg(
            np.stack([path.q[a], *p.via, path.q[b]]), np.zeros((len(p.via), path.q.shape[1])), 0.0, 1.0
        )
        out.append(_from_initial(leg, part, intervals))
    return out


def _sample_segment(
    pieces: list[_Piece], values: list[tuple[FloatArray, ...]], intervals: int, n: int
) -> tuple[Trajectory, tuple[tuple[FloatArray, FloatArray], ...]]:
    """The segment's solved pieces on one uniform grid of at most ``FINE_DT``; per line, (t, s)."""
    durations = [float(np.sum(v[3])) for v in values]
    edges = np.concatenate([[0.0], np.cumsum(durations)])
    total = float(edges[-1])
    steps = max(1, math.ceil(total / FINE_DT - 1e-9))
    t = np.linspace(0.0, total, steps + 1)
    q, qd, qdd = (np.zeros((t.size, n)) for _ in range(3))
    lines: list[tuple[FloatArray, FloatArray]] = []
    for k, (p, v) in enumerate(zip(pieces, values, strict=True)):
        last = k == len(pieces) - 1
        mask = (t >= edges[k]) & ((t <= edges[k + 1]) if last else (t < edges[k + 1]))
        local = np.clip(t[mask] - edges[k], 0.0, durations[k])
        if isinstance(p, _Joint):
            Q, V, A, T = v
            tn = _node_times(T, intervals)
            h = np.diff(tn)
            U = np.diff(A, axis=1) / h
            j = np.clip(np.searchsorted(tn, local, side="right") - 1, 0, h.size - 1)
            x = local - tn[j]
            pq = (Q[:, j] + x * V[:, j] + x**2 / 2 * A[:, j] + x**3 / 6 * U[:, j]).T
            pd = (V[:, j] + x * A[:, j] + x**2 / 2 * U[:, j]).T
            pdd = (A[:, j] + x * U[:, j]).T
        else:
            S, SD, SDD, T = v
            tn = np.linspace(0.0, float(T[0]), intervals + 1)
            h = np.diff(tn)
            U = np.diff(SDD) / h
            j = np.clip(np.searchsorted(tn, local, side="right") - 1, 0, h.size - 1)
            x = local - tn[j]
            s = np.clip(S[j] + x * SD[j] + x**2 / 2 * SDD[j] + x**3 / 6 * U[j], 0.0, 1.0)
            sd = SD[j] + x * SDD[j] + x**2 / 2 * U[j]
            sdd = SDD[j] + x * U[j]
            res = p.fn.map(s.size)(s[None, :])
            pq, d1, d2 = (np.asarray(r, dtype=float).T for r in res[:3])
            pd = d1 * sd[:, None]
            pdd = d2 * sd[:, None] ** 2 + d1 * sdd[:, None]
            lines.append((t[mask], np.vstack([s, sd])))
        q[mask], qd[mask], qdd[mask] = pq, pd, pdd
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd), tuple(lines)


def segment_optimum(
    robot: Robot | Sequence[Robot],
    segments: Sequence[CycleSegment],
    budget: float,
    *,
    acceleration_limit: FloatArray | None = None,
    jerk_limit: FloatArray | None = None,
    friction: Friction | None = NOMINAL_FRICTION,
    intervals: int = 16,
    substeps: int = 4,
    initial: Sequence[Trajectory] | None = None,
    continuation: tuple[float, ...] = (0.1, 0.03, 0.01),
    tol: float = 1e-8,
    max_iter: int = 3000,
    time_limit_s: float = 600.0,
) -> SegmentOptimum:
    """Solve the segments together by direct transcription and IPOPT with ``Σ durations ≤ budget``.

    Parameters
    ----------
    robot : Robot or sequence of Robot
        One robot for every segment, or one per segment (its tool and load).
    segments : sequence of CycleSegment
    budget : float
        s, the time the segments share (one segment: its duration at most).
    acceleration_limit, jerk_limit : ndarray of shape (n,), optional
        rad/s², rad/s³, as for :func:`cycle_optimum`.
    friction : Friction or None
        In the objective and the effort limits (Coulomb–viscous terms only).
    intervals : int
        Jerk intervals per piece (a joint piece: per sub-leg between its vias).
    substeps : int
        Points per interval where energy and limits are evaluated inside the solve.
    initial : sequence of Trajectory, optional
        One motion per segment, from its start at rest to its end at rest (the taught
        motion): the start of the solve, and the zones are widened to contain it (see
        the module docstring). Default: a minimum-jerk motion per piece; a segment of
        joint moves only then starts as :func:`cycle_optimum` does.
    continuation, tol, max_iter, time_limit_s
        As for :func:`cycle_optimum`.

    Returns
    -------
    SegmentOptimum
        Verified on a grid of at most ``FINE_DT``.

    Raises
    ------
    InvalidInput
        A budget that is not a positive number, a joint vector of the wrong length, a line
        that does not join its move's ends, an ``initial`` that does not fit the segments.
    """
    t_start = time.perf_counter()
    cs = _casadi()
    robots = [robot] * len(segments) if isinstance(robot, Robot) else list(robot)
    if not (isinstance(budget, (int, float)) and math.isfinite(budget) and budget > 0):
        raise InvalidInput(f"budget must be a positive, finite number of seconds, got {budget!r}")
    if not segments:
        raise InvalidInput("segments is empty; give at least one CycleSegment")
    if len(robots) != len(segments):
        raise InvalidInput(f"{len(robots)} robots for {len(segments)} segments; give one or one per segment")
    if not isinstance(intervals, int) or intervals < 1 or substeps < 1:
        raise InvalidInput(f"intervals and substeps must be whole numbers ≥ 1, got {intervals}, {substeps}")
    if initial is not None and len(initial) != len(segments):
        raise InvalidInput(
            f"initial holds {len(initial)} paths for {len(segments)} segments; give one per segment"
        )
    n = robots[0].n_joints
    if any(r.n_joints != n for r in robots):
        raise InvalidInput("the robots of the segments have different joint counts")
    amax = None if acceleration_limit is None else _vector(acceleration_limit, n, "acceleration_limit")
    jmax = None if jerk_limit is None else _vector(jerk_limit, n, "jerk_limit")
    all_pieces: list[list[_Piece]] = []
    starts: list[list[tuple[FloatArray, ...]]] = []
    for i, seg in enumerate(segments):
        if not seg.moves:
            raise InvalidInput(f"segment {i} has no moves; give at least one SegmentMove")
        if not (math.isfinite(seg.t_min) and 0 <= seg.t_min < seg.t_max):
            raise InvalidInput(f"segment {i} needs 0 ≤ t_min < t_max (s), got {seg.t_min}, {seg.t_max}")
        pieces = _pieces(cs, seg, n, f"segment {i}")
        if initial is not None:
            init = initial[i]
            if init.q.ndim != 2 or init.q.shape[1] != n or init.t.size < 2:
                raise InvalidInput(f"initial path {i} must be (n_steps ≥ 2, {n}), got {init.q.shape}")
            windows = _windows(pieces, init)
            pieces = _widened(pieces, init, windows)
            starts.append(_initial_start(pieces, init, windows, intervals))
        else:
            starts.append(
                _default_start(robots[i], pieces, seg, budget / len(segments), intervals, amax, jmax)
            )
        all_pieces.append(pieces)

    fr = None
    if friction is not None:
        v_sym = cs.SX.sym("v", n)
        fr = cs.Function("friction", [v_sym], [_casadi_friction(cs, friction, v_sym, n)])
    rneas: dict[int, Any] = {}
    steps: dict[int, Any] = {}
    opti = cs.Opti()
    eps = opti.parameter()
    variables: list[list[tuple[Any, ...]]] = []
    energy_terms = []
    total_time = 0
    for seg, pieces, rb in zip(segments, all_pieces, robots, strict=True):
        if id(rb) not in rneas:
            rneas[id(rb)] = casadi_rnea(rb)
            steps[id(rb)] = _interval_function(cs, rneas[id(rb)], fr, n, substeps)
        rnea, step = rneas[id(rb)], steps[id(rb)]
        lo, hi = rb.joint_ranges()
        vmax = np.asarray(rb.velocity_limit, dtype=float)
        emax = np.asarray(rb.effort_limit, dtype=float)

        def bound(
            qs: Any,
            vs: Any,
            accs: Any,
            jerks: Any,
            taus: Any,
            *,
            lo: FloatArray = lo,
            hi: FloatArray = hi,
            vmax: FloatArray = vmax,
            emax: FloatArray = emax,
        ) -> None:
            """Joint, speed, acceleration, jerk and effort limits on the values at the check points."""
            for i in range(n):
                if np.isfinite(lo[i]):
                    opti.subject_to(qs[i, :] >= lo[i])
                if np.isfinite(hi[i]):
                    opti.subject_to(qs[i, :] <= hi[i])
                if np.isfinite(vmax[i]):
                    opti.subject_to(opti.bounded(-vmax[i], vs[i, :], vmax[i]))
                if amax is not None and np.isfinite(amax[i]):
                    opti.subject_to(opti.bounded(-amax[i], accs[i, :], amax[i]))
                if jmax is not None and np.isfinite(jmax[i]):
                    opti.subject_to(opti.bounded(-jmax[i], jerks[i, :], jmax[i]))
                if np.isfinite(emax[i]):
                    opti.subject_to(opti.bounded(-emax[i], taus[i, :], emax[i]))

        seg_vars: list[tuple[Any, ...]] = []
        seg_time = 0
        for p in pieces:
            N = intervals
            if isinstance(p, _Joint):
                S = len(p.via) + 1
                M = S * N
                Q, V, A = (opti.variable(n, M + 1) for _ in range(3))
                U = opti.variable(n, M)
                T = opti.variable(S)
                ends = [(c, q) for c, q in ((0, p.q0), (-1, p.q1)) if q is not None]
                for c, q_end in ends:
                    opti.subject_to(Q[:, c] == q_end)
                for X in (V, A):
                    for c, _ in ends:
                        opti.subject_to(X[:, c] == 0)
                for k in range(1, S):
                    node, r, v = Q[:, k * N], p.radius[k - 1], p.via[k - 1]
                    for i in range(n):
                        if r[i] > 0:
                            opti.subject_to(opti.bounded(v[i] - r[i], node[i], v[i] + r[i]))
                        else:
                            opti.subject_to(node[i] == v[i])
                opti.subject_to(T >= MIN_SUBLEG_S)
                H = cs.horzcat(*[cs.repmat(T[k] / N, 1, N) for k in range(S)])
                nxt, qs, vs, taus, e = step.map(M)(Q[:, :-1], V[:, :-1], A[:, :-1], U, H, eps)
                opti.subject_to(cs.vertcat(Q[:, 1:], V[:, 1:], A[:, 1:]) == nxt)
                bound(qs, vs, A, U, taus)
                seg_vars.append((Q, V, A, U, T))
            else:
                X, XD, XDD = (opti.variable(1, N + 1) for _ in range(3))
                U = opti.variable(1, N)
                T = opti.variable(1)
                fn = _line_interval_function(cs, rnea, fr, p.fn, n, substeps)
                out = fn.map(N)(X[:, :-1], XD[:, :-1], XDD[:, :-1], U, cs.repmat(T / N, 1, N), eps)
                nxt, qs, vs, accs, jerks, taus, e = out
                opti.subject_to(cs.vertcat(X[:, 1:], XD[:, 1:], XDD[:, 1:]) == nxt)
                opti.subject_to(opti.bounded(0.0, X, 1.0))
                opti.subject_to(opti.bounded(p.s0[0], X[0, 0], p.s0[1]))
                opti.subject_to(opti.bounded(p.s1[0], X[0, -1], p.s1[1]))
                speed = p.speed if math.isfinite(p.speed) else 1e3
                # ṡ is quadratic in each interval: its nodes and the middle Bernstein coefficient
                # bound it (convex hull), so 0 ≤ ṡ ≤ speed holds everywhere, not only at points
                opti.subject_to(opti.bounded(0.0, XD, speed))
                opti.subject_to(opti.bounded(0.0, XD[:, :-1] + (T / N) / 2 * XDD[:, :-1], speed))
                if p.rest0:
                    opti.subject_to(XD[0, 0] == 0)
                    opti.subject_to(XDD[0, 0] == 0)
                if p.rest1:
                    opti.subject_to(XD[0, -1] == 0)
                    opti.subject_to(XDD[0, -1] == 0)
                bound(qs, vs, accs, jerks, taus)
                seg_vars.append((X, XD, XDD, U, T))
                opti.subject_to(T >= MIN_SUBLEG_S)
            seg_time = seg_time + cs.sum1(T)
            energy_terms.append(cs.sum2(e))
        # joints: rest at the segment's ends, continuity with the line pieces
        for k, (p, var) in enumerate(zip(pieces, seg_vars, strict=True)):
            if not isinstance(p, _Joint):
                continue
            Q, V, A = var[0], var[1], var[2]
            for col, fixed, other in ((0, p.q0, k - 1), (-1, p.q1, k + 1)):
                if fixed is not None:  # at rest there (above)
                    continue
                line = pieces[other]
                assert isinstance(line, _Line)
                X, XD, XDD = seg_vars[other][:3]
                j = -1 if col == 0 else 0
                q_j, qd_j, qdd_j = _line_state(line.fn, X[0, j], XD[0, j], XDD[0, j])
                opti.subject_to(Q[:, col] == q_j)
                opti.subject_to(V[:, col] == qd_j)
                opti.subject_to(A[:, col] == qdd_j)
        if seg.t_min > 0:
            opti.subject_to(seg_time >= seg.t_min)
        if math.isfinite(seg.t_max):
            opti.subject_to(seg_time <= seg.t_max)
        total_time = total_time + seg_time
        variables.append(seg_vars)
    opti.subject_to(total_time <= budget)

    # scale of the objective and of ε: the start's energy and mean |tau qd| at its nodes (as
    # cycle_optimum has them, so that a segment of joint moves is the same problem)
    unit_num, unit_den, scale = 0.0, 0, 0.0
    for rb, pieces, start in zip(robots, all_pieces, starts, strict=True):
        for p, val in zip(pieces, start, strict=True):
            if isinstance(p, _Joint):
                Q0, V0, A0 = val[0], val[1], val[2]
                h0 = np.diff(_node_times(val[3], intervals))
            else:
                qs0, d1, d2 = p.path.at(np.clip(val[0], 0.0, 1.0))
                Q0, V0, A0 = (
                    qs0.T,
                    (d1 * val[1][:, None]).T,
                    (d2 * val[1][:, None] ** 2 + d1 * val[2][:, None]).T,
                )
                h0 = np.full(intervals, float(val[3][0]) / intervals)
            tau0 = rb.inverse_dynamics(Q0.T, V0.T, A0.T, friction=friction)
            p0 = np.abs(tau0 * V0.T)
            unit_num += float(p0.sum())
            unit_den += p0.size
            scale += float((p0[:-1].sum(axis=1) * h0).sum())
    unit = unit_num / unit_den or 1.0
    opti.minimize(cs.sum1(cs.vertcat(*energy_terms)) / max(scale, 1e-9))

    def set_start(values: list[list[tuple[FloatArray, ...]]]) -> None:
        for seg_vars, pieces, seg_values in zip(variables, all_pieces, values, strict=True):
            for var, p, v in zip(seg_vars, pieces, seg_values, strict=True):
                for X, x in zip(var[:3], v[:3], strict=True):
                    opti.set_initial(X, np.atleast_2d(x))
                if isinstance(p, _Joint):
                    h = np.diff(_node_times(v[3], intervals))
                else:
                    h = np.full(intervals, float(v[3][0]) / intervals)
                opti.set_initial(var[3], np.atleast_2d(np.diff(np.atleast_2d(v[2]), axis=1) / h))
                opti.set_initial(var[4], np.asarray(v[3], dtype=float))

    set_start(starts)

    def read(value: Callable[[Any], Any]) -> list[list[Any]]:
        raw = [
            [
                tuple(np.atleast_2d(np.asarray(value(X), dtype=float)) for X in var[:3])
                + (np.atleast_1d(np.asarray(value(var[4]), dtype=float)).ravel(),)
                for var in seg_vars
            ]
            for seg_vars in variables
        ]
        return [
            [
                v if isinstance(p, _Joint) else (v[0][0], v[1][0], v[2][0], v[3])
                for p, v in zip(pieces, vals, strict=True)
            ]
            for pieces, vals in zip(all_pieces, raw, strict=True)
        ]

    current, status, succeeded = ipopt_stages(
        opti,
        eps,
        unit,
        continuation,
        read=read,
        set_start=set_start,
        tol=tol,
        max_iter=max_iter,
        deadline=t_start + time_limit_s,
        start=starts,
    )

    paths, energies, reports, lines = [], [], [], []
    speed_excess = 0.0
    for rb, pieces, vals in zip(robots, all_pieces, current, strict=True):
        path, line_s = _sample_segment(pieces, vals, intervals, n)
        paths.append(path)
        lines.append(line_s)
        energies.append(energy_on_samples(rb, path, friction=friction))
        reports.append(check_limits(rb, path, friction=friction, acceleration_limit=amax, jerk_limit=jmax))
        for p, (_, ssd) in zip((p for p in pieces if isinstance(p, _Line)), line_s, strict=True):
            if math.isfinite(p.speed) and ssd.shape[1]:
                speed_excess = max(speed_excess, float(np.max(ssd[1])) / p.speed - 1.0)
    durations = tuple(float(p.t[-1]) for p in paths)
    feasible = (
        succeeded
        and speed_excess <= SPEED_TOLERANCE
        and all(_held(r) for r in reports)
        and sum(durations) <= budget + 1e-6
    )
    return SegmentOptimum(
        durations=durations,
        energy_J=float(sum(energies)),
        segments_energy_J=tuple(energies),
        paths=tuple(paths),
        feasible=feasible,
        status=status,
        wall_s=time.perf_counter() - t_start,
        limits=tuple(reports),
        lines_s=tuple(lines),
        line_speed_excess=speed_excess,
    )


@dataclass(frozen=True, slots=True, eq=False)
class PlanSegment:
    """One segment of a planned cycle for :func:`segment_optimum`: the segment, its robot (the
    tool and load of its moves), the taught motion over it (from its start, at rest at both
    ends, on a grid of at most ``FINE_DT``), its window in the taught cycle (s) and its moves."""

    segment: CycleSegment
    robot: Robot
    taught: Trajectory
    t0: float
    t1: float
    moves: tuple[int, ...]  # step indices of the moves with motion

    @property
    def span(self) -> float:
        return self.t1 - self.t0


def _zone_box(step: Any, zone_mm: float) -> FloatArray:
    """The joint box (rad) whose every point keeps the TCP within ``zone_mm`` of the step's
    target, to first order with a margin of 1/4 (as the cycle optimizer's zones)."""
    from joulepath.sim import tcp_path as _tcp

    n = step.q.size
    if zone_mm <= 0.0:
        return np.zeros(n)
    h = 1e-6
    eye = np.eye(n) * h
    plus, _ = _tcp(step.robot, step.q[None, :] + eye, step.tcp)
    minus, _ = _tcp(step.robot, step.q[None, :] - eye, step.tcp)
    norm = float(np.linalg.norm((plus - minus) / (2 * h), axis=1).sum())
    return np.full(n, 0.75 * zone_mm / 1000.0 / max(norm, 1e-9))


def plan_segments(plan: PlannedCycle) -> list[PlanSegment]:
    """The planned cycle cut at every stop of the robot, each piece as a :class:`CycleSegment`
    with its zones and its taught motion.

    A fly-by corner's zone is its zone radius reduced to half the TCP length of either move
    (as the controller reduces it); between two joint moves it is a joint box (first order,
    a margin of 1/4), at a line's end a share of its ``s``. A line's ``line_speed`` is the
    speeddata's TCP speed over its length and reorientation speed over its turn. Moves
    without motion (to where the robot already is) are left out.

    Parameters
    ----------
    plan : PlannedCycle
        The controller emulation's timing of the cycle (:func:`joulepath.sim.plan_cycle`).

    Returns
    -------
    list of PlanSegment
        In the cycle's order; the segments' taught motions add up to the cycle's motion.
    """
    from joulepath.sim import evaluate_cycle

    out: list[PlanSegment] = []
    run: list[Any] = []
    for m in plan.moves:
        run.append(m)
        if not m.stops and m is not plan.moves[-1]:
            continue
        moving = [x for x in run if x.profile.duration > 0]
        t0, t1 = run[0].t0, max(x.t_end for x in run)
        run = []
        if not moving:
            continue
        moves: list[SegmentMove] = []
        for k, x in enumerate(moving):
            prev = moving[k - 1] if k > 0 else None
            nxt = moving[k + 1] if k + 1 < len(moving) else None

            def reduced(a: Any, b: Any) -> float:
                z = a.step.zone_mm
                return (
                    0.0
                    if z is None
                    else float(max(0.0, min(z, 0.5 * a.path.length_mm, 0.5 * b.path.length_mm)))
                )

            if not x.step.linear:
                zone = _zone_box(x.step, reduced(x, nxt)) if nxt is not None else 0.0
                moves.append(SegmentMove(q_end=x.path.q1, zone=zone))
                continue
            L, angle = x.path.length_mm, x.path.angle_deg
            speeds = [x.step.speed.v_tcp / L] if L > 1e-6 else []
            if angle > 1e-6:
                speeds.append(x.step.speed.v_ori / angle)
            moves.append(
                SegmentMove(
                    q_end=x.path.q1,
                    line=x.path,
                    blend_in=0.0 if prev is None or L <= 1e-6 else min(reduced(prev, x) / L, 1.0),
                    blend_out=0.0 if nxt is None or L <= 1e-6 else min(reduced(x, nxt) / L, 1.0),
                    line_speed=min(speeds) if speeds else math.inf,
                )
            )
        steps = max(1, math.ceil((t1 - t0) / FINE_DT - 1e-9))
        t = np.linspace(0.0, t1 - t0, steps + 1)
        tr = evaluate_cycle(plan, t0 + t)
        taught = Trajectory(t=t, q=tr.q, qd=tr.qd, qdd=tr.qdd)
        out.append(
            PlanSegment(
                segment=CycleSegment(q_start=moving[0].path.q0, moves=tuple(moves)),
                robot=moving[0].step.robot,
                taught=taught,
                t0=float(t0),
                t1=float(t1),
                moves=tuple(x.index for x in moving),
            )
        )
    return out
