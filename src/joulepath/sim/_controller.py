"""An emulation of the ABB controller's ``MoveAbsJ`` and of the 40 Hz measurement loop.

Each move is a synchronised joint interpolation: every joint follows the same
jerk-limited profile (:mod:`joulepath.sim._profile`) of its own displacement, so all
joints start and arrive together. The move's duration is the shortest that keeps

* the TCP speed along the path at or below the speeddata's ``v_tcp`` (mm/s) and the
  reorientation speed at or below ``v_ori`` (deg/s);
* every joint's speed at or below its limit, its acceleration at or below
  ``velocity_limit / accel_time`` and its jerk at or below that over ``jerk_time``
  (ABB publishes no acceleration or jerk limits; these are our assumptions, defined
  once in :mod:`joulepath.sim._limits`, see :class:`ControllerConfig`).

Zones: ``fine`` stops at the target (and dwells ``fine_dwell``); ``zX`` starts the
next move while the TCP is still X mm from the corner, the two profiles overlap
and the corner is rounded (superposition blending), never longer than half of
either move. The measurement loop samples every ``WaitTime 0.025`` plus the loop's
own execution time and jitter.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.abb import SPEEDS, V_ORI_DEG_S, ZONES
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.export import Move
from joulepath.sim._limits import ACCEL_TIME, JERK_TIME, acceleration_limit, jerk_limit
from joulepath.sim._profile import Profile, evaluate_profile, plan_profile, time_at_fraction


@dataclass(frozen=True, slots=True, kw_only=True)
class ControllerConfig:
    """Settings of the emulated controller and measurement loop (s unless noted).

    Attributes
    ----------
    sample_period : float
        ``WaitTime`` of the measurement loop (thesis: 0.025 s, 40 Hz).
    loop_overhead, loop_jitter : float
        Mean execution time of one loop iteration beyond ``WaitTime``, and the
        standard deviation of its (half-normal) random part.
    accel_time : float
        Time for a joint to reach its speed limit at full acceleration: joint
        acceleration limit = velocity limit / accel_time (an assumption;
        :data:`joulepath.sim.ACCEL_TIME`).
    jerk_time : float
        Time for a joint's acceleration to reach its limit at full jerk: joint jerk
        limit = acceleration limit / jerk_time (an assumption;
        :data:`joulepath.sim.JERK_TIME`, the peak jerk of a sin² ramp to full speed).
        0 disables the jerk limit (ramps as short as the acceleration limit allows).
    fine_dwell : float
        Stand-still at a ``fine`` point before the next move starts.
    idle : float
        Rest logged before the first move and after the last.
    path_points : int
        Points used to measure the TCP path length of a move.
    """

    sample_period: float = 0.025
    loop_overhead: float = 0.0008
    loop_jitter: float = 0.0006
    accel_time: float = ACCEL_TIME
    jerk_time: float = JERK_TIME
    fine_dwell: float = 0.048
    idle: float = 0.5
    path_points: int = 16

    def __post_init__(self) -> None:
        for name in ("sample_period", "accel_time"):
            if not getattr(self, name) > 0:
                raise InvalidInput(f"ControllerConfig.{name} must be positive")
        for name in ("loop_overhead", "loop_jitter", "jerk_time", "fine_dwell", "idle"):
            if not getattr(self, name) >= 0:
                raise InvalidInput(f"ControllerConfig.{name} must be ≥ 0")
        if self.path_points < 2:
            raise InvalidInput("ControllerConfig.path_points must be ≥ 2")


@dataclass(frozen=True, slots=True)
class Segment:
    """A planned move: starts at ``t0`` from ``q0`` and adds ``dq`` along ``profile``."""

    t0: float
    q0: FloatArray
    dq: FloatArray
    profile: Profile
    move: Move

    @property
    def t_end(self) -> float:
        return self.t0 + self.profile.duration


@dataclass(frozen=True, slots=True)
class MotionPlan:
    """Planned motion: the start configuration, the segments, and when the log ends."""

    start: FloatArray
    segments: tuple[Segment, ...]
    end_time: float


def _check_move(robot: Robot, move: Move, k: int) -> None:
    if move.speed not in SPEEDS:
        raise InvalidInput(f"move {k}: unknown speeddata {move.speed!r}; use one of {', '.join(SPEEDS)}")
    if move.zone not in ZONES:
        raise InvalidInput(f"move {k}: unknown zonedata {move.zone!r}; use one of {', '.join(ZONES)}")
    q = np.asarray(move.target, dtype=float)
    lo, hi = robot.joint_ranges()
    bad = np.nonzero((q < lo - 1e-9) | (q > hi + 1e-9))[0]
    if bad.size:
        j = int(bad[0])
        raise LimitViolation(
            f"move {k}: joint {j + 1} target {np.degrees(q[j]):.2f} deg is outside its range "
            f"[{np.degrees(lo[j]):.1f}, {np.degrees(hi[j]):.1f}] deg"
        )


def _path_length_mm(robot: Robot, q0: FloatArray, dq: FloatArray, n: int) -> tuple[float, float]:
    s = np.linspace(0.0, 1.0, n)
    pose = robot.fk(q0 + s[:, None] * dq)
    length = float(np.linalg.norm(np.diff(pose.position_mm, axis=0), axis=1).sum())
    rel = pose.rotation[0].T @ pose.rotation[-1]
    angle = float(np.degrees(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0))))
    return length, angle


def plan_moves(
    robot: Robot, start: FloatArray, moves: Sequence[Move], config: ControllerConfig
) -> MotionPlan:
    """Plan a program of ``MoveAbsJ`` instructions from ``start`` (rad).

    Raises
    ------
    InvalidInput
        Unknown speeddata or zonedata, or a robot without speed limits.
    LimitViolation
        A target outside the robot's joint ranges.
    """
    vmax = robot.velocity_limit
    if not np.all(np.isfinite(vmax)):
        raise InvalidInput(f"robot {robot.name!r} has no joint speed limits; the controller needs them")
    amax = acceleration_limit(robot, config.accel_time)
    jmax = jerk_limit(robot, config.accel_time, config.jerk_time)
    assert amax is not None  # accel_time > 0 (ControllerConfig)
    jmax = np.full(vmax.shape, np.inf) if jmax is None else jmax
    q = np.asarray(start, dtype=float).copy()
    plans: list[tuple[FloatArray, FloatArray, Profile, Move, float]] = []
    for k, move in enumerate(moves):
        _check_move(robot, move, k)
        target = np.asarray(move.target, dtype=float)
        dq = target - q
        moving = np.abs(dq) > 1e-9
        if not moving.any():
            continue
        length, angle = _path_length_mm(robot, q, dq, config.path_points)
        bounds = [np.min(vmax[moving] / np.abs(dq[moving]))]
        if length > 1e-6:
            bounds.append(SPEEDS[move.speed] / length)
        if angle > 1e-6:
            bounds.append(V_ORI_DEG_S / angle)
        profile = plan_profile(
            min(bounds),
            float(np.min(amax[moving] / np.abs(dq[moving]))),
            float(np.min(jmax[moving] / np.abs(dq[moving]))),
        )
        radius = ZONES[move.zone]
        fraction = 0.0 if radius is None or length <= 0 else min(radius / length, 0.5)
        plans.append((q.copy(), dq, profile, move, fraction))
        q = target
    segments: list[Segment] = []
    t = config.idle
    for i, (q0, dq, profile, move, fraction) in enumerate(plans):
        segments.append(Segment(t0=t, q0=q0, dq=dq, profile=profile, move=move))
        end = t + profile.duration
        if i + 1 == len(plans):
            t = end
        elif fraction > 0.0:
            blend = profile.duration - time_at_fraction(profile, 1.0 - fraction)
            blend = min(blend, 0.5 * profile.duration, 0.5 * plans[i + 1][2].duration)
            t = end - blend
        else:
            t = end + config.fine_dwell
    return MotionPlan(start=np.asarray(start, float), segments=tuple(segments), end_time=t + config.idle)


def evaluate_plan(plan: MotionPlan, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Commanded ``q, qd, qdd`` (rad, rad/s, rad/s²) at increasing times ``t``; shape (n, 6)."""
    n = t.size
    n_j = plan.start.size
    q = np.zeros((n, n_j))
    qd = np.zeros((n, n_j))
    qdd = np.zeros((n, n_j))
    done = np.zeros((n + 1, n_j))  # displacement of finished segments, as a difference array
    for seg in plan.segments:
        a = int(np.searchsorted(t, seg.t0, side="left"))
        b = int(np.searchsorted(t, seg.t_end, side="left"))
        if b > a:
            s, sd, sdd = evaluate_profile(seg.profile, t[a:b] - seg.t0)
            q[a:b] += s[:, None] * seg.dq
            qd[a:b] += sd[:, None] * seg.dq
            qdd[a:b] += sdd[:, None] * seg.dq
        done[b] += seg.dq
    q += plan.start + np.cumsum(done[:-1], axis=0)
    return q, qd, qdd


def log_times(duration: float, config: ControllerConfig, *, rng: np.random.Generator) -> FloatArray:
    """Sample times of the measurement loop over ``duration`` s (first sample at 0)."""
    mean = config.sample_period + config.loop_overhead + config.loop_jitter * np.sqrt(2 / np.pi)
    n = int(duration / mean * 1.2) + 10
    steps = config.sample_period + config.loop_overhead + np.abs(rng.normal(0.0, config.loop_jitter, n))
    t = np.concatenate([[0.0], np.cumsum(steps)])
    return t[t <= duration]
