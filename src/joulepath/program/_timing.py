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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput
from joulepath.kinematics._ik import solve_ik
from joulepath.program._resolve import CycleSpec, Step
from joulepath.sim import ControllerConfig
from joulepath.sim._profile import Profile, evaluate_profile, plan_profile, time_at_fraction
from joulepath.trajectory import Trajectory

LINE_POINTS = 64
"""Points along a MoveL line where the inverse kinematics is solved."""
FINE_DT = 0.0025
"""s between the samples on which energies and limits of the cycle are evaluated."""


@dataclass(frozen=True, slots=True, eq=False)
class SegmentPath:
    """A move's joint path ``q(s)``, ``s`` in [0, 1], and its TCP length (mm) and turn (deg)."""

    q0: FloatArray
    q1: FloatArray
    spline: CubicSpline | None  # None: the joint line q0 + s (q1 - q0)
    length_mm: float
    angle_deg: float

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


def _tcp(robot: Robot, q: FloatArray, tcp: FloatArray) -> tuple[FloatArray, FloatArray]:
    pose = robot.fk(q)
    pos = pose.position_m + np.einsum("...ij,j->...i", pose.rotation, tcp[:3, 3])
    rot = pose.rotation @ tcp[:3, :3]
    return pos, rot


def _angle_deg(r0: FloatArray, r1: FloatArray) -> float:
    rel = r0.T @ r1
    return float(np.degrees(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0))))


def _slerp(r0: FloatArray, r1: FloatArray, s: FloatArray) -> FloatArray:
    from scipy.spatial.transform import Rotation, Slerp

    out: FloatArray = Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([r0, r1])))(s).as_matrix()
    return out


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
    inv_tcp = np.linalg.inv(step.tcp)
    lo, hi = robot.joint_ranges()
    qs = [q0]
    for k in range(1, LINE_POINTS):
        pose = np.eye(4)
        pose[:3, :3] = rots[k]
        pose[:3, 3] = p0 + s[k] * (p1 - p0)
        q = solve_ik(robot.chain, pose @ inv_tcp, None, lower=lo, upper=hi, near=qs[-1])
        if q is None or np.abs(q - qs[-1]).max() > 0.5:
            raise InvalidInput(
                f"{where}:{step.line}: {step.label}: the straight line leaves the reachable space or "
                f"passes a singularity at {100 * s[k]:.0f} % of the way; use MoveJ or move the target"
            )
        qs.append(q)
    if np.abs(qs[-1] - q1).max() > 1e-6:
        raise InvalidInput(
            f"{where}:{step.line}: {step.label}: the straight line ends in another configuration than the "
            "target's confdata; use MoveJ or fix the confdata"
        )
    spline = CubicSpline(s, np.stack(qs), axis=0)
    return SegmentPath(q0, q1, spline, float(np.linalg.norm(p1 - p0)) * 1000.0, _angle_deg(r0, r1))


def fastest_profile(step: Step, path: SegmentPath, config: ControllerConfig) -> Profile:
    """The controller's profile for a move (its speeddata and the joint limits; ``\\T`` stretches it)."""
    assert step.robot is not None and step.speed is not None
    robot = step.robot
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    amax = vmax / config.accel_time
    _, dqds, _ = path.at(np.linspace(0.0, 1.0, 33))
    peak = np.abs(dqds).max(axis=0)
    moving = peak > 1e-9
    bounds = [float(np.min(vmax[moving] / peak[moving]))]
    if path.length_mm > 1e-6:
        bounds.append(step.speed.v_tcp / path.length_mm)
    if path.angle_deg > 1e-6:
        bounds.append(step.speed.v_ori / path.angle_deg)
    profile = plan_profile(min(bounds), float(np.min(amax[moving] / peak[moving])))
    if step.time_s is not None and step.time_s > profile.duration:
        k = step.time_s / profile.duration
        profile = Profile(ta=profile.ta * k, tc=profile.tc * k, v=profile.v / k)
    return profile


@dataclass(frozen=True, slots=True, eq=False)
class PlannedMove:
    """A move of the planned cycle: its step, path, profile and start time (s)."""

    index: int  # position in CycleSpec.steps
    step: Step
    path: SegmentPath
    profile: Profile
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


def moves_of(spec: CycleSpec) -> list[int]:
    return [i for i, s in enumerate(spec.steps) if s.kind == "move"]


def stops_after(spec: CycleSpec, i: int) -> bool:
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


def plan_cycle(spec: CycleSpec, config: ControllerConfig) -> PlannedCycle:
    """The controller's timing of one cycle (it starts at rest at ``spec.start``)."""
    q = spec.start
    plans: list[tuple[int, Step, SegmentPath, Profile, float, bool]] = []
    for i in moves_of(spec):
        step = spec.steps[i]
        assert step.q is not None
        path = segment_path(step, q, spec.source)
        if np.abs(step.q - q).max() <= 1e-9:
            profile = Profile(ta=0.0, tc=0.0, v=0.0)
        else:
            profile = fastest_profile(step, path, config)
        radius = step.zone_mm
        stop = stops_after(spec, i)
        frac = 0.0 if stop or radius is None or path.length_mm <= 0 else min(radius / path.length_mm, 0.5)
        plans.append((i, step, path, profile, frac, stop))
        q = step.q
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
        _, _, path, profile, frac, stop = plans[k]
        out.append(PlannedMove(i, step, path, profile, t, stop))
        end = t + profile.duration
        if profile.duration == 0.0:
            t = end
        elif frac > 0.0 and k + 1 < len(plans) and plans[k + 1][3].duration > 0:
            blend = profile.duration - time_at_fraction(profile, 1.0 - frac)
            blend = min(blend, 0.5 * profile.duration, 0.5 * plans[k + 1][3].duration)
            t = end - blend
        else:
            t = end + config.fine_dwell
        k += 1
    return PlannedCycle(tuple(out), tuple(waits), t, spec.start)


def evaluate_cycle(plan: PlannedCycle, t: FloatArray) -> Trajectory:
    """The commanded motion (superposed moves) at times ``t``."""
    n_j = plan.start.size
    q = np.tile(plan.start, (t.size, 1))
    qd = np.zeros((t.size, n_j))
    qdd = np.zeros((t.size, n_j))
    for m in plan.moves:
        base, _, _ = m.path.at(np.array([0.0]))
        end, _, _ = m.path.at(np.array([1.0]))
        after = t >= m.t_end
        q[after] += end[0] - base[0]
        inside = (t >= m.t0) & ~after
        if m.profile.duration > 0 and inside.any():
            s, sd, sdd = evaluate_profile(m.profile, t[inside] - m.t0)
            pq, pd, pdd = m.path.at(s)
            q[inside] += pq - base[0]
            qd[inside] += pd * sd[:, None]
            qdd[inside] += pdd * (sd * sd)[:, None] + pd * sdd[:, None]
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd)


def standalone(move: PlannedMove, *, dt: float = FINE_DT) -> Trajectory:
    """One move on its own, rest to rest, on a grid of ``dt`` (its end sample at its end)."""
    T = move.profile.duration
    n = max(2, int(np.ceil(T / dt)) + 1)
    t = np.linspace(0.0, T, n)
    s, sd, sdd = evaluate_profile(move.profile, t)
    pq, pd, pdd = move.path.at(s)
    return Trajectory(t=t, q=pq, qd=pd * sd[:, None], qdd=pdd * (sd * sd)[:, None] + pd * sdd[:, None])
