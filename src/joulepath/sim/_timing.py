"""The cycle as the emulated controller runs it: paths, durations, zones, and the motion.

Same rules as :func:`joulepath.sim.plan_moves` (jerk-limited sin² profile of a path
parameter, the shortest duration within the speeddata's TCP and reorientation
speeds and the joints' speed and acceleration limits, superposition blending in
zones), extended to what a program holds:

* ``MoveJ`` and ``MoveAbsJ`` interpolate the joints; ``MoveL`` moves the TCP on the
  straight line (orientation by slerp), its joints from the inverse kinematics at 64
  points along the line joined by a cubic spline;
* ``\\T`` stretches the fastest profile to the given time (never shorter);
* a move stops (``fine`` or before a ``WaitTime``, and at the end of the cycle), dwells
  ``ControllerConfig.fine_dwell``, then the next starts; in a zone the next move
  starts while the TCP is the zone radius from the corner (at most half of either move);
* instructions kept verbatim take no modelled time.

Timed fly-by corners (:func:`chain_corners`): between two joint-interpolated moves
(``MoveJ``/``MoveAbsJ``) that both carry ``\\T``, the first ending in a zone, the
emulation follows what ABB documents instead of superposing two rest-to-rest profiles:
``\\T`` is substituted for the speed data (the segment between the two programmed
points runs at the constant joint velocity ``dq / T``); the zone is reduced to half the
distance to the nearest programmed point, forwards or backwards; the corner path is a
parabola that starts when the TCP enters the zone and ends when it leaves it, so the
joint velocity changes linearly from one segment's to the next's within the zone,
centred on the programmed point, and the robot keeps speed through the point (a chain
of timed fly-by points takes the sum of its ``\\T``). A chain starts and ends at rest
with the jerk-limited sin² ramp at the acceleration limit, inside its first and last
``\\T``. A corner is timed only if the controller can keep it: every joint within its
speed limit on both segments and within its acceleration limit in the corner path,
and the chain's first and last ``\\T`` long enough to reach and leave the segment
speed; else that corner is run as any other (superposition). Nothing else changes: a
program without such corners is timed exactly as before.

Motion settings (a :class:`~joulepath.sim.Step`'s ``AccSet`` and ``VelSet``, as ABB documents
them): ``AccSet Acc, Ramp`` scales a move's joint acceleration limits by ``Acc`` % (at least
20 %) and its jerk limits by ``Ramp`` % (at least 10 %), in its own profile and in a timed
fly-by chain's ramps and corners; ``VelSet Override, Max`` scales the speeddata's TCP and
reorientation speeds by ``Override`` % (a ``\\T`` by its inverse: 50 % doubles it) and caps
the TCP speed at ``Max`` mm/s. At 100 %, 100 % and no cap a move is timed exactly as without
them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.interpolate import CubicSpline

from joulepath._typing import FloatArray
from joulepath._work import check_work
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput
from joulepath.kinematics import solve_ik_along
from joulepath.sim._controller import ControllerConfig
from joulepath.sim._limits import jerk_limit
from joulepath.sim._profile import Profile, evaluate_profile, plan_profile, time_at_fraction
from joulepath.sim._steps import Step, StepSequence
from joulepath.trajectory import Trajectory

LINE_POINTS = 64
"""Points along a MoveL line where the inverse kinematics is solved."""
FINE_DT = 0.0025
"""s between the samples on which energies and limits of the cycle are evaluated."""
ACC_MIN_PCT = 20.0
"""``AccSet Acc`` below this gives this (% of the controller's acceleration; ABB's AccSet)."""
RAMP_MIN_PCT = 10.0
"""``AccSet Ramp`` below this gives this (% of the controller's rate of change of acceleration)."""


def acc_share(step: Step) -> float:
    """The share of the controller's acceleration a move runs at (``AccSet Acc``, at least 20 %)."""
    return max(step.acc_pct, ACC_MIN_PCT) / 100.0


def ramp_share(step: Step) -> float:
    """The share of the controller's jerk a move runs at (``AccSet Ramp``, at least 10 %)."""
    return max(step.ramp_pct, RAMP_MIN_PCT) / 100.0


def timed_s(step: Step) -> float | None:
    """A move's ``\\T`` as the controller runs it: stretched by ``VelSet``'s override below 100 %."""
    return None if step.time_s is None else step.time_s * (100.0 / step.vel_override_pct)


@dataclass(frozen=True, slots=True, eq=False)
class SegmentPath:
    """A move's joint path ``q(s)``, ``s`` in [0, 1], and its TCP length (mm) and turn (deg)."""

    q0: FloatArray
    q1: FloatArray
    spline: CubicSpline | None  # None: the joint line q0 + s (q1 - q0)
    length_mm: float
    angle_deg: float
    ends: tuple[FloatArray, FloatArray] | None = field(default=None, repr=False)
    """``q`` at ``s`` = 0 and 1 as :meth:`at` gives them, once :func:`evaluate_cycle` has asked."""

    def at(self, s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``q, dq/ds, d²q/ds²`` at ``s`` (n,) -> (n, joints)."""
        s = np.asarray(s, dtype=float)
        if self.spline is None:
            dq = self.q1 - self.q0
            return (
                self.q0 + s[:, None] * dq,
                np.broadcast_to(dq, (s.size, dq.size)),
                np.zeros((s.size, dq.size)),
            )
        return self.spline(s), self.spline(s, 1), self.spline(s, 2)


def tcp_pose(robot: Robot, q: FloatArray, tcp: FloatArray) -> tuple[FloatArray, FloatArray]:
    """TCP position (m) and rotation of joint values ``q`` (..., n) with the flange-to-TCP ``tcp``."""
    pose = robot.fk(q)
    pos = pose.position_m + np.einsum("...ij,j->...i", pose.rotation, tcp[:3, 3])
    rot = pose.rotation @ tcp[:3, :3]
    return pos, rot


_tcp = tcp_pose


def _angle_deg(r0: FloatArray, r1: FloatArray) -> float:
    rel = r0.T @ r1
    return float(np.degrees(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0))))


def _slerp(r0: FloatArray, r1: FloatArray, s: FloatArray) -> FloatArray:
    from scipy.spatial.transform import Rotation, Slerp

    out: FloatArray = Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([r0, r1])))(s).as_matrix()
    return out


@dataclass(frozen=True, slots=True)
class ChainProfile:
    """A move inside a chain of timed fly-by points (unit path parameter s: 0 -> 1).

    ``ds/dt = v (R_in(tau) - R_out(tau - b))``: a ramp in of ``w_in`` s, a ramp out of
    ``w_out`` s starting at ``b``; a ramp is ``"lin"`` (a corner path: velocity linear in
    time) or ``"sin2"`` (from or to rest, jerk-limited). ``rest`` is the move's own
    rest-to-rest profile (what :func:`standalone` runs).
    """

    w_in: float
    kind_in: str
    b: float
    w_out: float
    kind_out: str
    v: float
    rest: Profile

    @property
    def duration(self) -> float:
        return self.b + self.w_out


AnyProfile = Profile | ChainProfile


def _ramp(kind: str, w: float, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Integral, value and slope of a 0 -> 1 ramp of width ``w`` at ``x`` (0 before, 1 after)."""
    xc = np.clip(x, 0.0, w)
    after = np.maximum(x - w, 0.0)
    inside = (x > 0.0) & (x < w)
    if kind == "lin":
        integral = xc * xc / (2.0 * w) + after
        value = xc / w
        slope = np.where(inside, 1.0 / w, 0.0)
    else:
        integral = xc / 2.0 - w / (2.0 * np.pi) * np.sin(np.pi * xc / w) + after
        value = np.sin(np.pi * xc / (2.0 * w)) ** 2
        slope = np.where(inside, np.pi / (2.0 * w) * np.sin(np.pi * xc / w), 0.0)
    return integral, value, slope


def evaluate_any(p: AnyProfile, tau: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``s, ds/dt, d²s/dt²`` of either profile at ``tau`` (clipped to [0, T])."""
    if isinstance(p, Profile):
        return evaluate_profile(p, tau)
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, p.duration)
    i_in, r_in, d_in = _ramp(p.kind_in, p.w_in, tau)
    i_out, r_out, d_out = _ramp(p.kind_out, p.w_out, tau - p.b)
    return p.v * (i_in - i_out), p.v * (r_in - r_out), p.v * (d_in - d_out)


def _time_at_fraction(p: AnyProfile, fraction: float) -> float:
    if isinstance(p, Profile):
        return time_at_fraction(p, fraction)
    lo, hi = 0.0, p.duration
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        s, _, _ = evaluate_any(p, np.array([mid]))
        lo, hi = (mid, hi) if s[0] < fraction else (lo, mid)
    return 0.5 * (lo + hi)


def segment_path(step: Step, q0: FloatArray, where: str) -> SegmentPath:
    """The joint path of a move step from ``q0``; a MoveL that leaves the reachable space is refused."""
    assert step.q is not None and step.robot is not None and step.tcp is not None
    robot, q1 = step.robot, step.q
    if not step.linear:
        s = np.linspace(0.0, 1.0, 16)
        pos, rot = _tcp(robot, q0 + s[:, None] * (q1 - q0), step.tcp)
        length = float(np.linalg.norm(np.diff(pos, axis=0), axis=1).sum()) * 1000.0
        return SegmentPath(q0, q1, None, length, _angle_deg(rot[0], rot[-1]))
    p0, r0 = _tcp(robot, q0, step.tcp)
    p1, r1 = _tcp(robot, q1, step.tcp)
    s = np.linspace(0.0, 1.0, LINE_POINTS)
    rots = _slerp(r0, r1, s)
    points = p0 + s[:, None] * (p1 - p0)
    if step.circle_q is not None:
        pv, _ = _tcp(robot, step.circle_q, step.tcp)
        points = arc_points(p0, pv, p1, s, f"{where}:{step.line}: {step.label}")
    inv_tcp = np.linalg.inv(step.tcp)
    lo, hi = robot.joint_ranges()
    poses = np.zeros((LINE_POINTS - 1, 4, 4))
    poses[:, :3, :3] = rots[1:]
    poses[:, :3, 3] = points[1:]
    poses[:, 3, 3] = 1.0
    along = solve_ik_along(robot.chain, poses @ inv_tcp, lower=lo, upper=hi, start=q0)
    qs = [q0]
    for k, q in enumerate(along, start=1):
        if q is None or np.abs(q - qs[-1]).max() > 0.5:
            what, fix = _line_break(robot, poses @ inv_tcp, q0, k)
            raise InvalidInput(
                f"{where}:{step.line}: {step.label}: the straight line {what} at {100 * s[k]:.0f} % "
                f"of the way; {fix}"
            )
        qs.append(q)
    if np.abs(qs[-1] - q1).max() > 1e-6:
        raise InvalidInput(
            f"{where}:{step.line}: {step.label}: the straight line ends in another configuration than the "
            "target's confdata; use MoveJ or fix the confdata"
        )
    spline = CubicSpline(s, np.stack(qs), axis=0)
    length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum()) * 1000.0
    return SegmentPath(q0, q1, spline, length, _angle_deg(r0, r1))


SINGULAR_DEG = 5.0
"""Axis 5 within this of 0 (deg) where a line's joints jump: the wrist singularity (axes 4 and 6 aligned)."""


def _line_break(robot: Robot, poses: FloatArray, q0: FloatArray, k: int) -> tuple[str, str]:
    """Why the joints along a line's poses (tool0, from ``q0``) break off at pose ``k`` (1-based), and
    the fix, in words: an axis that passes its range on the way (the line is out of this arm's
    reach: perhaps a program for an arm with wider ranges), the wrist singularity, or another one
    (the arm's wrist centre over axis 1, or the arm stretched). The branch is followed again
    without the ranges to tell them apart."""
    lo, hi = robot.joint_ranges()
    free = solve_ik_along(robot.chain, poses, lower=lo - 4 * np.pi, upper=hi + 4 * np.pi, start=q0)
    qs = [q0]
    for q in free[:k]:
        if q is None or np.abs(q - qs[-1]).max() > 0.5:
            break
        qs.append(q)
    else:
        path = np.stack(qs)
        outside = (path < lo - 1e-9) | (path > hi + 1e-9)
        if outside.any():
            j = int(np.argmax(outside.any(axis=0)))
            return (
                f"needs axis {j + 1} past its range ({np.degrees(lo[j]):.0f} to {np.degrees(hi[j]):.0f} deg)",
                "out of this arm's reach: for an arm with wider ranges give it with --robot, else use MoveJ",
            )
    if abs(np.degrees(qs[-1][4])) < SINGULAR_DEG:
        wrist = "passes the wrist singularity (axis 5 at 0)"
        return wrist, "the controller stops there too: use MoveJ or move the target"
    other = "passes a singular point (the wrist over axis 1, or the arm stretched)"
    return other, "use MoveJ or move the target"


def arc_points(p0: FloatArray, pv: FloatArray, p1: FloatArray, s: FloatArray, where: str) -> FloatArray:
    """Points (m) at fractions ``s`` of the circular arc from ``p0`` through ``pv`` to ``p1`` (``MoveC``)."""
    a, b = pv - p0, p1 - p0
    normal = np.cross(a, b)
    nn = float(normal @ normal)
    if nn < 1e-14 or min(np.linalg.norm(a), np.linalg.norm(b), np.linalg.norm(p1 - pv)) < 1e-4:
        raise InvalidInput(
            f"{where}: the start, circle point and target lie on one line or too close (< 0.1 mm): "
            "no circle; "
            "move the circle point"
        )
    center = p0 + (np.cross(normal, a) * float(b @ b) + np.cross(b, normal) * float(a @ a)) / (2.0 * nn)
    u = p0 - center
    radius = float(np.linalg.norm(u))
    e1 = u / radius
    e2 = np.cross(normal / np.sqrt(nn), e1)

    def angle(p: FloatArray) -> float:
        d = p - center
        return float(np.arctan2(d @ e2, d @ e1)) % (2 * np.pi)

    total = angle(p1)
    if angle(pv) > total:  # the circle point lies past the target the short way: go the long way
        total -= 2 * np.pi
    th = s * total
    out: FloatArray = center + radius * (np.cos(th)[:, None] * e1 + np.sin(th)[:, None] * e2)
    return out


def fastest_profile(step: Step, path: SegmentPath, config: ControllerConfig) -> Profile:
    """The controller's profile for a move (its speeddata and the joint limits, scaled by its ``AccSet``
    and ``VelSet``; ``\\T`` stretches it)."""
    assert step.robot is not None and step.speed is not None
    robot = step.robot
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    amax = vmax / config.accel_time * acc_share(step)
    jerk = jerk_limit(robot, config.accel_time, config.jerk_time)
    jmax = np.full(vmax.shape, np.inf) if jerk is None else jerk * ramp_share(step)
    _, dqds, _ = path.at(np.linspace(0.0, 1.0, 33))
    peak = np.abs(dqds).max(axis=0)
    moving = peak > 1e-9
    bounds = [float(np.min(vmax[moving] / peak[moving]))]
    override = step.vel_override_pct / 100.0
    v_tcp = step.speed.v_tcp * override
    if step.vel_max_mm_s is not None:
        v_tcp = min(v_tcp, step.vel_max_mm_s)
    if path.length_mm > 1e-6:
        bounds.append(v_tcp / path.length_mm)
    if path.angle_deg > 1e-6:
        bounds.append(step.speed.v_ori * override / path.angle_deg)
    profile = plan_profile(
        min(bounds), float(np.min(amax[moving] / peak[moving])), float(np.min(jmax[moving] / peak[moving]))
    )
    time_s = timed_s(step)
    if time_s is not None and time_s > profile.duration:
        k = time_s / profile.duration
        profile = Profile(ta=profile.ta * k, tc=profile.tc * k, v=profile.v / k)
    return profile


@dataclass(frozen=True, slots=True, eq=False)
class PlannedMove:
    """A move of the planned cycle: its step, path, profile and start time (s)."""

    index: int  # position in StepSequence.steps
    step: Step
    path: SegmentPath
    profile: AnyProfile
    t0: float
    stops: bool

    @property
    def t_end(self) -> float:
        return self.t0 + self.profile.duration


@dataclass(frozen=True, slots=True, eq=False)
class PlannedCycle:
    """The default cycle: its moves, the waits' start times and the cycle time (s)."""

    moves: tuple[PlannedMove, ...]
    waits: tuple[tuple[int, float, float], ...]  # (step index, start, seconds)
    cycle_time: float
    start: FloatArray


def check_motion_time(plan: PlannedCycle, source: str, *, optimized: bool = False) -> None:
    """Refuse a cycle whose moves take longer than the work limits allow, before any work.

    Tiny speeds (``\\V:=0.0001``, a speeddata of 1e-9 mm/s) or a long ``\\T`` imply hours
    of motion, and arrays of every sample of it: the ``motion_s`` limit bounds the moves
    of the cycle together. ``optimized``: the moves are to be optimized, each in dense
    solves over spline coefficients as many as its duration holds knots (a 6 s move
    took about twice as long as a 3 s one, minutes on a busy 2-core machine), so the
    ``move_s`` limit bounds each move too; see :mod:`joulepath._work`.

    Raises
    ------
    InvalidInput
        The moves of ``plan`` take longer than a limit.
    """
    fix = (
        "the moves take that long at their programmed speeds and times (a tiny \\V or speeddata, a long "
        "\\T); give them faster speeds or shorter times"
    )
    motion = plan.cycle_time - sum(seconds for _, _, seconds in plan.waits)
    check_work("motion_s", motion, source, fix + ", or split the cycle")
    if optimized and plan.moves:
        longest = max(plan.moves, key=lambda m: m.profile.duration)
        where = f"{source}: the move {longest.step.label!r}"
        check_work("move_s", longest.profile.duration, where, fix + ", or split the move in two")


def moves_of(spec: StepSequence) -> list[int]:
    return [i for i, s in enumerate(spec.steps) if s.kind == "move"]


def stops_after(spec: StepSequence, i: int) -> bool:
    """Whether the robot stops at the end of move ``i``: fine, a wait next, or the end of the cycle."""
    step = spec.steps[i]
    if step.zone_mm is None:
        return True
    for nxt in spec.steps[i + 1 :]:
        if nxt.kind == "move":
            return False
        if nxt.kind == "wait":
            return True
    return True


def _rest_ramp(T: float, m: float) -> float | None:
    """The sin² ramp (s) from rest to the speed that, with the ramp, covers the segment in ``T``.

    ``m`` = max over joints of |dq| / a_max; the ramp is at the acceleration limit:
    ``r = (pi/2) v m`` with ``v = 1 / (T - r/2)``. None: ``T`` is too short.
    """
    disc = T * T - np.pi * m
    return None if disc < 0 else T - float(np.sqrt(disc))


def chain_corners(
    plans: Sequence[tuple[int, Step, SegmentPath, Profile, float, bool]],
    config: ControllerConfig,
    cache: dict[tuple[object, ...], dict[int, tuple[AnyProfile, float]]] | None = None,
) -> dict[int, tuple[AnyProfile, float]]:
    """Timed fly-by corners (see the module docstring): the moves they touch, by position in
    ``plans``, with their chain profiles and the overlap (s) with the next move (its ramp out).

    Each chain (a run of consecutive candidate corners) is timed on its own: what a chain's
    moves run depends only on them, and a corner the controller cannot keep is dropped from its
    chain. ``cache`` (optional; :class:`PathCache` keeps one) holds each chain's result by what it
    depends on, so that a search that changes one move re-times only the chain it is in.
    """
    n = len(plans)

    def candidate(k: int) -> bool:
        _, a, pa, fa, _, stop = plans[k]
        _, b, pb, fb, _, _ = plans[k + 1]
        return (
            not stop
            and a.zone_mm is not None
            and a.time_s is not None
            and b.time_s is not None
            and pa.spline is None
            and pb.spline is None
            and fa.duration > 0
            and fb.duration > 0
        )

    out: dict[int, tuple[AnyProfile, float]] = {}
    for chain in _runs(k for k in range(n - 1) if candidate(k)):
        key = None if cache is None else _chain_key(plans, chain, config)
        found = None if key is None or cache is None else cache.get(key)
        if found is None:
            found = _timed_chain(plans, chain, config)
            if key is not None and cache is not None:
                cache[key] = {j - chain[0]: v for j, v in found.items()}
        else:
            found = {j + chain[0]: v for j, v in found.items()}
        out.update(found)
    return out


def _runs(corners: Iterable[int]) -> list[list[int]]:
    """Consecutive corners grouped: the chains."""
    runs: list[list[int]] = []
    for k in corners:
        if runs and runs[-1][-1] == k - 1:
            runs[-1].append(k)
        else:
            runs.append([k])
    return runs


def _timed_chain(
    plans: Sequence[tuple[int, Step, SegmentPath, Profile, float, bool]],
    chain: list[int],
    config: ControllerConfig,
) -> dict[int, tuple[AnyProfile, float]]:
    """One chain's profiles, its corners the controller cannot keep dropped one at a time.

    A dropped corner splits the chain in two that share no move's timing (a move's profile depends
    only on the corners before and after it), so each part is timed on its own: the corners each
    part drops, and in what order, are those the whole chain would drop.
    """
    out, bad = _chain_profiles(plans, set(chain), config)
    if bad is None:
        return out
    found: dict[int, tuple[AnyProfile, float]] = {}
    for part in (chain[: chain.index(bad)], chain[chain.index(bad) + 1 :]):
        if part:
            found.update(_timed_chain(plans, part, config))
    return found


def _chain_key(
    plans: Sequence[tuple[int, Step, SegmentPath, Profile, float, bool]],
    chain: list[int],
    config: ControllerConfig,
) -> tuple[object, ...]:
    """What a chain's timing depends on: each of its moves' path, rest profile, ``\\T``, zone and
    ``AccSet`` share (the path by identity: a :class:`PathCache`'s paths are kept)."""
    members = range(chain[0], chain[-1] + 2)
    return (
        config,
        plans[chain[0]][1].robot,
        tuple(
            (plans[j][2], plans[j][3], timed_s(plans[j][1]), plans[j][1].zone_mm, acc_share(plans[j][1]))
            for j in members
        ),
    )


def _chain_profiles(
    plans: Sequence[tuple[int, Step, SegmentPath, Profile, float, bool]],
    active: set[int],
    config: ControllerConfig,
) -> tuple[dict[int, tuple[AnyProfile, float]], int | None]:
    """Profiles of the moves at the active corners, or the first corner the controller cannot keep."""
    if not active:
        return {}, None
    robot = plans[0][1].robot
    assert robot is not None
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    amax_all = vmax / config.accel_time
    width: dict[int, float] = {}
    for k in sorted(active):
        (_, a, pa, _, _, _), (_, b, pb, _, _, _) = plans[k], plans[k + 1]
        ta, tb = timed_s(a), timed_s(b)
        assert ta is not None and tb is not None and a.zone_mm is not None
        La, Lb = pa.length_mm, pb.length_mm
        if La > 1e-9 and Lb > 1e-9:
            R = min(a.zone_mm, 0.5 * La, 0.5 * Lb)  # reduced to half the distance to the nearest point
            width[k] = 2.0 * min(R / La * ta, R / Lb * tb)
        else:
            width[k] = min(ta, tb)
        if width[k] <= 0.0:
            return {}, k
    profiles: dict[int, tuple[AnyProfile, float]] = {}
    speed: dict[int, FloatArray] = {}  # joint velocity on the segment (rad/s)
    for j in sorted({k for c in active for k in (c, c + 1)}):
        _, step, path, rest, _, _ = plans[j]
        T_step = timed_s(step)
        assert T_step is not None
        T = T_step
        amax = amax_all * acc_share(step)
        dq = path.q1 - path.q0
        m = float(np.max(np.abs(dq) / amax))
        w_in = width.get(j - 1) if (j - 1) in active else None
        w_out = width.get(j) if j in active else None
        if w_in is not None and w_out is not None:
            v = 1.0 / T
            prof = ChainProfile(w_in, "lin", T + 0.5 * w_in - 0.5 * w_out, w_out, "lin", v, rest)
        elif w_out is not None:  # the chain starts at rest
            r = _rest_ramp(T, m)
            if r is None or T - 0.5 * w_out - r < -1e-12:
                return {}, j
            v = 1.0 / (T - 0.5 * r)
            prof = ChainProfile(r, "sin2", T - 0.5 * w_out, w_out, "lin", v, rest)
        else:  # the chain ends at rest
            assert w_in is not None
            r = _rest_ramp(T, m)
            if r is None or T - 0.5 * w_in - r < -1e-12:
                return {}, j - 1
            v = 1.0 / (T - 0.5 * r)
            prof = ChainProfile(w_in, "lin", 0.5 * w_in + T - r, r, "sin2", v, rest)
        if np.any(np.abs(v * dq) > vmax * (1 + 1e-9)):
            return {}, (j if j in active else j - 1)
        speed[j] = v * dq
        profiles[j] = (prof, prof.w_out if j in active else 0.0)
    for k in sorted(active):  # the corner within the lower of its two moves' acceleration limits
        amax = amax_all * min(acc_share(plans[k][1]), acc_share(plans[k + 1][1]))
        if np.any(np.abs(speed[k + 1] - speed[k]) / width[k] > amax * (1 + 1e-9)):
            return {}, k
    return profiles, None


class PathCache:
    """Joint paths of moves already planned (:func:`segment_path`), by step line, start, target and
    tool, and the times at which profiles reach a fraction of their path (zones' blends).

    A move's path depends on where it starts and ends, its interpolation and its tool, not on
    how it is timed (speed data, ``\\T``, zone, ``AccSet``, ``VelSet``): a search over those
    plans the cycle many times and solves each ``MoveL``'s inverse kinematics once, and each
    blend of a profile it has seen once (the same numbers as without the cache).
    """

    def __init__(self) -> None:
        self._paths: dict[tuple[int, bool, bytes, bytes, bytes], SegmentPath] = {}
        self._fractions: dict[tuple[AnyProfile, float], float] = {}
        self._profiles: dict[tuple[object, ...], Profile] = {}
        self.chains: dict[tuple[object, ...], dict[int, tuple[AnyProfile, float]]] = {}
        """Timed fly-by chains by what they depend on (:func:`chain_corners`)."""

    def profile(self, step: Step, path: SegmentPath, config: ControllerConfig) -> Profile:
        """:func:`fastest_profile` of ``step`` on ``path`` (a path of this cache), found once for the
        timing it depends on: the speed data, ``\\T``, ``AccSet`` and ``VelSet``."""
        assert step.speed is not None
        key = (
            path,
            step.robot,
            config,
            step.speed.v_tcp,
            step.speed.v_ori,
            step.time_s,
            step.acc_pct,
            step.ramp_pct,
            step.vel_override_pct,
            step.vel_max_mm_s,
        )
        found = self._profiles.get(key)
        if found is None:
            found = self._profiles[key] = fastest_profile(step, path, config)
        return found

    def time_at_fraction(self, p: AnyProfile, fraction: float) -> float:
        """When profile ``p`` reaches ``fraction`` of its path (s), found once."""
        key = (p, fraction)
        found = self._fractions.get(key)
        if found is None:
            found = self._fractions[key] = _time_at_fraction(p, fraction)
        return found

    def path(self, step: Step, q0: FloatArray, where: str) -> SegmentPath:
        """:func:`segment_path` of ``step`` from ``q0``, solved once."""
        assert step.q is not None and step.tcp is not None
        key = (step.line, step.linear, q0.tobytes(), step.q.tobytes(), step.tcp.tobytes())
        found = self._paths.get(key)
        if found is None:
            found = self._paths[key] = segment_path(step, q0, where)
        return found


def plan_cycle(
    spec: StepSequence,
    config: ControllerConfig,
    *,
    progress: Callable[[str], None] | None = None,
    paths: PathCache | None = None,
) -> PlannedCycle:
    """The controller's timing of one cycle (it starts at rest at ``spec.start``).

    ``progress`` (optional) is told each move planned (a ``MoveL`` solves the inverse
    kinematics along its line: milliseconds each, minutes for thousands). ``paths``
    (optional) keeps the moves' paths from one call to the next (:class:`PathCache`).
    """
    q = spec.start
    plans: list[tuple[int, Step, SegmentPath, Profile, float, bool]] = []
    indices = moves_of(spec)
    for k, i in enumerate(indices, start=1):
        if progress is not None:
            progress(f"planning the taught cycle: move {k}/{len(indices)}")
        step = spec.steps[i]
        assert step.q is not None
        path = segment_path(step, q, spec.source) if paths is None else paths.path(step, q, spec.source)
        if np.abs(step.q - q).max() <= 1e-9:
            fastest = Profile(ta=0.0, tc=0.0, v=0.0)
        else:
            fastest = (
                fastest_profile(step, path, config) if paths is None else paths.profile(step, path, config)
            )
        radius = step.zone_mm
        stop = stops_after(spec, i)
        frac = 0.0 if stop or radius is None or path.length_mm <= 0 else min(radius / path.length_mm, 0.5)
        plans.append((i, step, path, fastest, frac, stop))
        q = step.q
    chained = chain_corners(plans, config, None if paths is None else paths.chains)
    t = 0.0
    out: list[PlannedMove] = []
    waits: list[tuple[int, float, float]] = []
    k = 0
    for i, step in enumerate(spec.steps):
        if step.kind == "wait":
            waits.append((i, t, step.seconds))
            t += step.seconds
        if step.kind != "move":
            continue
        _, _, path, rest, frac, stop = plans[k]
        profile: AnyProfile = chained[k][0] if k in chained else rest
        out.append(PlannedMove(i, step, path, profile, t, stop))
        end = t + profile.duration
        nxt = (chained[k + 1][0] if k + 1 in chained else plans[k + 1][3]) if k + 1 < len(plans) else None
        if k in chained and chained[k][1] > 0.0:
            t = end - chained[k][1]
        elif profile.duration == 0.0:
            t = end
        elif frac > 0.0 and nxt is not None and nxt.duration > 0:
            at = _time_at_fraction if paths is None else paths.time_at_fraction
            blend = profile.duration - at(profile, 1.0 - frac)
            blend = min(blend, 0.5 * profile.duration, 0.5 * nxt.duration)
            t = end - blend
        else:
            t = end + config.fine_dwell
        k += 1
    return PlannedCycle(tuple(out), tuple(waits), t, spec.start)


def evaluate_cycle(plan: PlannedCycle, t: FloatArray) -> Trajectory:
    """The commanded motion (superposed moves) at times ``t``."""
    t = np.asarray(t, dtype=float)
    n_j = plan.start.size
    qd = np.zeros((t.size, n_j))
    qdd = np.zeros((t.size, n_j))
    ordered = t.size < 2 or bool(np.all(t[1:] >= t[:-1]))
    ends = _path_ends(plan)
    t_ends = np.array([m.t_end for m in plan.moves])
    # the moves a sample is past are a prefix of the moves when they end in order (a move that
    # blends into the next ends before it): the sample then starts from the running sum of the
    # prefix's displacements, added in the order the moves come (the same sums, to the bit)
    prefix = ordered and bool(np.all(np.diff(t_ends) >= 0.0))
    if prefix:
        steps = (
            np.vstack([plan.start[None], [end - base for base, end in ends]]) if ends else plan.start[None]
        )
        q = np.cumsum(steps, axis=0)[np.searchsorted(t_ends, t, side="right")]
    else:
        q = np.tile(plan.start, (t.size, 1))
    for m, (base, end) in zip(plan.moves, ends, strict=True):
        # the samples at or after the move's end, and those inside it: a suffix and a slice of
        # sorted times (the same samples, in the same order, as the masks of unsorted ones)
        after: slice | npt.NDArray[np.bool_]
        inside: slice | npt.NDArray[np.bool_]
        if ordered:
            a = int(np.searchsorted(t, m.t_end, side="left"))
            first = min(int(np.searchsorted(t, m.t0, side="left")), a)
            after, inside, any_inside = slice(a, None), slice(first, a), a > first
        else:
            late = t >= m.t_end
            within = (t >= m.t0) & ~late
            after, inside, any_inside = late, within, bool(within.any())
        if not prefix:
            q[after] += end - base
        if m.profile.duration > 0 and any_inside:
            s, sd, sdd = evaluate_any(m.profile, t[inside] - m.t0)
            pq, pd, pdd = m.path.at(s)
            q[inside] += pq - base
            qd[inside] += pd * sd[:, None]
            qdd[inside] += pdd * (sd * sd)[:, None] + pd * sdd[:, None]
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd)


def _path_ends(plan: PlannedCycle) -> list[tuple[FloatArray, FloatArray]]:
    """Each move's path at ``s`` = 0 and 1 (as :meth:`SegmentPath.at` gives them), found once a path."""
    out = []
    for m in plan.moves:
        found = m.path.ends
        if found is None:
            base, _, _ = m.path.at(np.array([0.0]))
            end, _, _ = m.path.at(np.array([1.0]))
            found = (base[0], end[0])
            object.__setattr__(m.path, "ends", found)
        out.append(found)
    return out


def standalone(move: PlannedMove, *, dt: float = FINE_DT) -> Trajectory:
    """One move on its own, rest to rest, on a grid of ``dt`` (its end sample at its end)."""
    profile = move.profile.rest if isinstance(move.profile, ChainProfile) else move.profile
    T = profile.duration
    n = max(2, int(np.ceil(T / dt)) + 1)
    t = np.linspace(0.0, T, n)
    s, sd, sdd = evaluate_profile(profile, t)
    pq, pd, pdd = move.path.at(s)
    return Trajectory(t=t, q=pq, qd=pd * sd[:, None], qdd=pdd * (sd * sd)[:, None] + pd * sdd[:, None])
