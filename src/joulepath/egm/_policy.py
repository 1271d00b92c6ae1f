"""Policy layer: which reference to send for which robot state, as a pure function.

:func:`step` takes the plan, the settings, the policy's own state and what the
controller just reported (:class:`RobotState`: its clock, its feedback joints,
whether EGM is running) and returns the reference to send and the next policy state.
No socket, no clock of the PC: the plan is indexed by the controller's time.

Phases (:class:`Phase`):

* ``wait`` — hold: the reference is the start while the robot is within
  ``start_tolerance_deg`` of it, else the robot's own feedback. The path starts
  ``ramp_in_s`` of controller time after the first message that reports EGM running
  (motors on, ``mciState`` running) with the feedback at the start. EGM running with
  the robot away from the start is a fault: the controller would ramp in to a far
  reference.
* ``run`` — the plan at (controller time − the time the run started).
* ``hold`` — the plan's end, until the feedback stays within ``end_tolerance_deg``
  of it for ``settle_messages`` messages: one repetition done.
* ``return`` — between repetitions of a plan that does not end where it starts: the
  plan backwards, then its start until the robot has settled there.
* ``done`` — every repetition ran; the end is held.
* ``fault`` — the robot's feedback is held (zero speed); :attr:`PolicyState.fault` says why.

Every reference is at most ``max_step_deg`` from the feedback on every joint; one
farther away is not sent: the policy goes to ``fault`` and holds the feedback.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np

from joulepath._typing import FloatArray
from joulepath.egm._plan import Plan
from joulepath.errors import InvalidInput


class Phase(StrEnum):
    """What the stream is doing (see the module docstring)."""

    WAIT = "wait"
    RUN = "run"
    HOLD = "hold"
    RETURN = "return"
    DONE = "done"
    FAULT = "fault"


@dataclass(frozen=True, slots=True, kw_only=True)
class StreamSettings:
    """Tolerances and repetitions of a stream.

    Attributes
    ----------
    repeats : int
        Runs of the plan (``--repeat``).
    start_tolerance_deg : float
        The feedback must be this close to the start on every joint to begin a run.
    end_tolerance_deg : float
        Converged: the feedback this close to the held end (or start) on every joint...
    settle_messages : int
        ...for this many consecutive messages.
    max_step_deg : float
        No reference farther than this from the feedback on any joint is ever sent.
    max_hold_s : float
        Controller time allowed to converge after the plan's end (or a return); longer
        is a fault.
    ramp_in_s : float
        Controller time the start is held after EGM reports running, before the run
        begins: at least the RAPID module's ``\\RampInTime``, so that the controller's
        ramp-in from its own position ends before the path moves.
    """

    repeats: int = 1
    start_tolerance_deg: float = 0.5
    end_tolerance_deg: float = 0.1
    settle_messages: int = 5
    max_step_deg: float = 5.0
    max_hold_s: float = 2.0
    ramp_in_s: float = 0.1

    def __post_init__(self) -> None:
        if not 1 <= self.repeats <= 1000:
            raise InvalidInput(f"repeats must be 1..1000, got {self.repeats}")
        for name in ("start_tolerance_deg", "end_tolerance_deg", "max_step_deg", "max_hold_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise InvalidInput(f"{name} must be a positive number, got {value}")
        if not (math.isfinite(self.ramp_in_s) and 0 <= self.ramp_in_s <= 10):
            raise InvalidInput(f"ramp_in_s must be 0..10 s, got {self.ramp_in_s}")
        if self.end_tolerance_deg > self.start_tolerance_deg:
            raise InvalidInput(
                f"end_tolerance_deg ({self.end_tolerance_deg}) must not exceed start_tolerance_deg "
                f"({self.start_tolerance_deg}): a settled robot must count as at the start"
            )
        if self.start_tolerance_deg >= self.max_step_deg:
            raise InvalidInput("start_tolerance_deg must be below max_step_deg")
        if not 1 <= self.settle_messages <= 1000:
            raise InvalidInput(f"settle_messages must be 1..1000, got {self.settle_messages}")


@dataclass(frozen=True, slots=True)
class RobotState:
    """What one ``EgmRobot`` reported, in SI units.

    Attributes
    ----------
    t : float
        The controller's clock, s.
    q : ndarray of shape (n,)
        Feedback joints, rad.
    running : bool
        Motors on and EGM running (``mciState`` ``MCI_RUNNING``).
    """

    t: float
    q: FloatArray
    running: bool


@dataclass(frozen=True, slots=True)
class Reference:
    """What to send: position (rad) and speed (rad/s), and the plan time it was taken at (or None)."""

    q: FloatArray
    qd: FloatArray
    plan_time: float | None = None


@dataclass(frozen=True, slots=True)
class PolicyState:
    """The policy's memory between messages.

    Attributes
    ----------
    phase : Phase
    t0 : float
        Controller time at which the current run, return or hold began (s).
    done : int
        Repetitions completed.
    settled : int
        Consecutive converged messages in ``hold`` / ``return``.
    interrupted : int
        Runs cut short because EGM stopped running.
    fault : str or None
        Why the stream stopped, in ``fault``.
    running_since : float or None
        Controller time since which EGM has been running at the start, in ``wait``.
    """

    phase: Phase = Phase.WAIT
    t0: float = 0.0
    done: int = 0
    settled: int = 0
    interrupted: int = 0
    fault: str | None = None
    running_since: float | None = None


def _far(a: FloatArray, b: FloatArray, tol_deg: float) -> int | None:
    """First joint where a and b differ by more than tol_deg, or None."""
    over = np.nonzero(np.abs(a - b) > math.radians(tol_deg))[0]
    return int(over[0]) if over.size else None


def _hold(robot: RobotState) -> Reference:
    return Reference(q=robot.q.copy(), qd=np.zeros_like(robot.q))


def _fault(state: PolicyState, robot: RobotState, why: str) -> tuple[Reference, PolicyState]:
    return _hold(robot), replace(state, phase=Phase.FAULT, fault=why)


def _converging(
    target: FloatArray, settings: StreamSettings, state: PolicyState, robot: RobotState
) -> tuple[bool, PolicyState]:
    """Count consecutive settled messages at ``target``; whether there are enough."""
    settled = state.settled + 1 if _far(robot.q, target, settings.end_tolerance_deg) is None else 0
    return settled >= settings.settle_messages, replace(state, settled=settled)


def step(
    plan: Plan, settings: StreamSettings, state: PolicyState, robot: RobotState
) -> tuple[Reference, PolicyState]:
    """The reference for what the robot reported, and the policy's next state.

    Pure: the same arguments give the same result. See the module docstring for the
    phases and the guarantees.
    """
    if state.phase is Phase.FAULT:
        return _hold(robot), state
    ref, nxt = _step(plan, settings, state, robot)
    if nxt.phase is Phase.FAULT:
        return ref, nxt
    j = _far(ref.q, robot.q, settings.max_step_deg)
    if j is not None:
        return _fault(
            nxt,
            robot,
            f"the reference for joint {j + 1} is {math.degrees(abs(ref.q[j] - robot.q[j])):.2f} deg from "
            f"the robot's feedback at controller time {robot.t:.3f} s, more than "
            f"{settings.max_step_deg:g} deg; holding the robot where it is",
        )
    return ref, nxt


def _step(
    plan: Plan, settings: StreamSettings, state: PolicyState, robot: RobotState
) -> tuple[Reference, PolicyState]:
    zero = np.zeros(plan.n_joints)
    phase = state.phase
    if phase is Phase.DONE:
        return Reference(q=plan.end.copy(), qd=zero, plan_time=plan.duration), state
    if not robot.running and phase in (Phase.RUN, Phase.RETURN):  # a return cut short is no lost run
        cut = state.interrupted + (phase is Phase.RUN)
        return _hold(robot), replace(state, phase=Phase.WAIT, settled=0, interrupted=cut)
    if not robot.running and phase is Phase.HOLD:
        if _far(robot.q, plan.end, settings.end_tolerance_deg) is None:  # the controller ended at the end
            return _next_repetition(plan, settings, state, robot, running=False)
        return _hold(robot), replace(state, phase=Phase.WAIT, settled=0, interrupted=state.interrupted + 1)
    if phase is Phase.WAIT:
        j = _far(robot.q, plan.start, settings.start_tolerance_deg)
        if j is not None:
            if robot.running:
                return _fault(
                    state,
                    robot,
                    f"EGM is running but joint {j + 1} is at {math.degrees(robot.q[j]):.2f} deg, "
                    f"{math.degrees(abs(robot.q[j] - plan.start[j])):.2f} deg from the path's start "
                    f"{math.degrees(plan.start[j]):.2f} deg (tolerance "
                    f"{settings.start_tolerance_deg:g} deg); move the robot to the start (the RAPID module's "
                    "MoveAbsJ START) and run again",
                )
            return _hold(robot), state
        if not robot.running:
            return Reference(q=plan.start.copy(), qd=zero, plan_time=0.0), replace(state, running_since=None)
        since = robot.t if state.running_since is None else state.running_since
        if robot.t - since < settings.ramp_in_s:  # the controller's ramp-in: hold the start
            return Reference(q=plan.start.copy(), qd=zero, plan_time=0.0), replace(state, running_since=since)
        start = replace(state, phase=Phase.RUN, t0=robot.t, settled=0, running_since=None)
        return _run_from(plan, start, robot)
    if phase is Phase.RUN:
        return _run_from(plan, state, robot)
    if phase is Phase.HOLD:
        return _settle(plan, settings, state, robot, plan.end, "the path's end")
    # Phase.RETURN
    back = plan.reversed()
    s = robot.t - state.t0
    if s < back.duration:
        q, qd = back.at(s)
        return Reference(q=q, qd=qd, plan_time=None), state
    return _settle(plan, settings, state, robot, plan.start, "the path's start after the return")


def _run_from(plan: Plan, state: PolicyState, robot: RobotState) -> tuple[Reference, PolicyState]:
    s = robot.t - state.t0
    if s >= plan.duration:
        state = replace(state, phase=Phase.HOLD, t0=state.t0 + plan.duration, settled=0)
        return Reference(q=plan.end.copy(), qd=np.zeros(plan.n_joints), plan_time=plan.duration), state
    q, qd = plan.at(s)
    return Reference(q=q, qd=qd, plan_time=float(s)), state


def _settle(
    plan: Plan,
    settings: StreamSettings,
    state: PolicyState,
    robot: RobotState,
    target: FloatArray,
    what: str,
) -> tuple[Reference, PolicyState]:
    held = Reference(q=target.copy(), qd=np.zeros(plan.n_joints), plan_time=None)
    hold_start = state.t0 if state.phase is Phase.HOLD else state.t0 + plan.duration
    converged, state = _converging(target, settings, state, robot)
    if not converged:
        if robot.t - hold_start > settings.max_hold_s:
            j = _far(robot.q, target, settings.end_tolerance_deg)
            joint = 0 if j is None else j
            return _fault(
                state,
                robot,
                f"the robot did not settle at {what} within {settings.max_hold_s:g} s of controller time: "
                f"joint {joint + 1} at {math.degrees(robot.q[joint]):.3f} deg, target "
                f"{math.degrees(target[joint]):.3f} deg (tolerance {settings.end_tolerance_deg:g} deg)",
            )
        if state.phase is Phase.HOLD:
            held = Reference(q=target.copy(), qd=np.zeros(plan.n_joints), plan_time=plan.duration)
        return held, state
    if state.phase is Phase.RETURN:  # back at the start: the next repetition begins now
        return _run_from(plan, replace(state, phase=Phase.RUN, t0=robot.t, settled=0), robot)
    return _next_repetition(plan, settings, state, robot, running=True)


def _next_repetition(
    plan: Plan, settings: StreamSettings, state: PolicyState, robot: RobotState, *, running: bool
) -> tuple[Reference, PolicyState]:
    state = replace(state, done=state.done + 1, settled=0)
    zero = np.zeros(plan.n_joints)
    if state.done >= settings.repeats:
        done = replace(state, phase=Phase.DONE)
        return Reference(q=plan.end.copy(), qd=zero, plan_time=plan.duration), done
    if not running:  # the controller ended its EGM motion: the next run starts when it is back at the start
        return _hold(robot), replace(state, phase=Phase.WAIT)
    if plan.closed:
        return _run_from(plan, replace(state, phase=Phase.RUN, t0=robot.t), robot)
    state = replace(state, phase=Phase.RETURN, t0=robot.t)
    q, qd = plan.reversed().at(0.0)
    return Reference(q=q, qd=qd, plan_time=None), state
