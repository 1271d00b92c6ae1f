"""The EGM server: transport + protocol + policy in one bounded loop, and what it saw.

:func:`serve` answers every valid ``EgmRobot`` of the controller with an
``EgmSensor`` computed by the policy (:func:`joulepath.egm.step`) on the controller's
clock, until the plan is done, a fault stops it, or the controller is silent for
longer than ``timeout_s``. Datagrams that do not parse (or lack a field) are ignored
and counted by reason; datagrams from a second address are ignored and counted as
foreign; a message whose controller time is not after the previous one is ignored
and counted as late. :func:`stream_run` reads a run folder, checks the plan against
the robot's limits before the first reference, serves, and writes ``stream.csv`` and
``stream.json`` (:func:`summarize`), also when a fault stops the stream.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._io import atomic_write_text, finite_json, output_journal
from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.egm._plan import Plan, check_plan, plan_file, read_plan, read_run_result, run_robot
from joulepath.egm._policy import Phase, PolicyState, RobotState, StreamSettings, step
from joulepath.egm._protocol import decode_robot, encode_sensor
from joulepath.egm._transport import Address, UdpEndpoint
from joulepath.energy import path_energy
from joulepath.errors import InvalidInput, InvalidMessage, StreamAborted

STREAM_CSV = "stream.csv"
STREAM_JSON = "stream.json"
STREAM_FILES = (STREAM_CSV, STREAM_JSON)
"""What :func:`stream_run` writes in the run folder."""
CONTROL_PERIOD = 0.004
"""s between EGM messages at the controller's highest rate (250 Hz)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class ServeConfig:
    """Where to listen and when to give up.

    Attributes
    ----------
    host, port : str, int
        The UDP address to listen on (port 0: an ephemeral port).
    timeout_s : float
        Longest silence of the controller before the stream stops with a fault.
    max_wall_s : float
        Longest stream in wall time.
    settings : StreamSettings
        Tolerances and repetitions of the policy.
    """

    host: str = "127.0.0.1"
    port: int = 6510
    timeout_s: float = 10.0
    max_wall_s: float = 3600.0
    settings: StreamSettings = field(default_factory=StreamSettings)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.timeout_s) and 0 < self.timeout_s <= 3600):
            raise InvalidInput(f"timeout must be within (0, 3600] s, got {self.timeout_s}")
        if not (math.isfinite(self.max_wall_s) and self.max_wall_s > 0):
            raise InvalidInput(f"max_wall_s must be > 0, got {self.max_wall_s}")


@dataclass(frozen=True, slots=True)
class Repetition:
    """One run of the plan, on the controller's clock (s)."""

    started_s: float
    path_end_s: float | None
    settled_s: float | None


@dataclass(frozen=True, slots=True)
class Session:
    """Everything one :func:`serve` saw, one row per answered message.

    Attributes
    ----------
    t : ndarray of shape (n_rows,)
        Controller time, s.
    phase : tuple of str
        The policy's phase after each message.
    plan_time : ndarray of shape (n_rows,)
        Plan time of the reference (NaN when not on the plan).
    q_ref, qd_ref, q_fb : ndarray of shape (n_rows, n)
        Reference position (rad), speed (rad/s), feedback (rad).
    """

    t: FloatArray
    phase: tuple[str, ...]
    plan_time: FloatArray
    q_ref: FloatArray
    qd_ref: FloatArray
    q_fb: FloatArray
    received: int
    parsed: int
    ignored: dict[str, int]
    late: int
    foreign: int
    slow_replies: int
    controller: Address | None
    listen: Address
    repetitions: tuple[Repetition, ...]
    interrupted: int
    outcome: str
    fault: str | None
    wall_s: float


def serve(
    plan: Plan,
    endpoint: UdpEndpoint,
    config: ServeConfig,
    *,
    on_listening: Callable[[Address], None] | None = None,
    robot: Robot | None = None,
) -> Session:
    """Answer the controller on ``endpoint`` until done, a fault, or silence; return what was seen.

    The plan must have been checked (:func:`~joulepath.egm.check_plan`). Never raises
    on what the controller sends: faults end the session with :attr:`Session.fault`.
    EGM's joint messages carry the controller's axis values: ``robot`` converts them to and
    from the plan's joints (:meth:`~joulepath.dynamics.Robot.axes_to_joints`; none given: the
    identity, right for every arm whose axis 3 is not coupled). The session holds joints.
    """
    to_joints = robot.axes_to_joints if robot is not None else np.asarray
    to_axes = robot.joints_to_axes if robot is not None else np.asarray
    n = plan.n_joints
    settings = config.settings
    state = PolicyState()
    rows_t: list[float] = []
    rows_phase: list[str] = []
    rows_s: list[float] = []
    rows_ref: list[FloatArray] = []
    rows_qd: list[FloatArray] = []
    rows_fb: list[FloatArray] = []
    ignored: Counter[str] = Counter()
    received = parsed = late = foreign = slow = 0
    controller: Address | None = None
    last_t = -math.inf
    seqno = 0
    reps: list[dict[str, float | None]] = []
    fault: str | None = None
    outcome = "done"
    wall_start = time.monotonic()
    if on_listening is not None:
        on_listening(endpoint.address)
    while True:
        if time.monotonic() - wall_start > config.max_wall_s:
            fault = f"the stream ran longer than {config.max_wall_s:g} s of wall time; stopped"
            break
        dgram = endpoint.receive(config.timeout_s)
        if dgram is None:
            host, port = endpoint.address
            fault = f"no datagram from the controller for {config.timeout_s:g} s" + (
                f" (after {parsed} messages, at controller time {last_t:.3f} s); the last reference is held"
                if parsed
                else f"; check that its UDPUC device sends to {host}:{port}"
            )
            break
        received += 1
        if controller is not None and dgram.sender != controller:
            foreign += 1
            continue
        try:
            msg = decode_robot(dgram.data, n)
        except InvalidMessage as err:
            ignored[err.reason] += 1
            continue
        if controller is None:
            controller = dgram.sender
        if msg.time_s <= last_t:
            late += 1
            continue
        parsed += 1
        last_t = msg.time_s
        seen = RobotState(
            t=msg.time_s,
            q=to_joints(np.radians(msg.joints_deg)),
            running=msg.motors_on and msg.egm_running,
        )
        before = state
        ref, state = step(plan, settings, state, seen)
        _track(reps, before, state, seen.t)
        seqno += 1
        endpoint.send(
            encode_sensor(
                seqno, msg.tm_ms, np.degrees(to_axes(ref.q)).tolist(), np.degrees(to_axes(ref.qd)).tolist()
            ),
            dgram.sender,
        )
        if time.monotonic() - dgram.received_s > CONTROL_PERIOD:
            slow += 1
        rows_t.append(seen.t)
        rows_phase.append(state.phase.value)
        rows_s.append(math.nan if ref.plan_time is None else ref.plan_time)
        rows_ref.append(ref.q)
        rows_qd.append(ref.qd)
        rows_fb.append(seen.q)
        if state.phase is Phase.DONE:
            break
        if state.phase is Phase.FAULT:
            fault = state.fault
            break
    if fault is not None:
        outcome = "fault"
    empty = np.zeros((0, n))
    return Session(
        t=np.array(rows_t),
        phase=tuple(rows_phase),
        plan_time=np.array(rows_s),
        q_ref=np.array(rows_ref) if rows_ref else empty,
        qd_ref=np.array(rows_qd) if rows_qd else empty,
        q_fb=np.array(rows_fb) if rows_fb else empty,
        received=received,
        parsed=parsed,
        ignored=dict(sorted(ignored.items())),
        late=late,
        foreign=foreign,
        slow_replies=slow,
        controller=controller,
        listen=endpoint.address,
        repetitions=tuple(
            Repetition(
                started_s=float(r["started"] or 0.0),
                path_end_s=r["path_end"],
                settled_s=r["settled"],
            )
            for r in reps
        ),
        interrupted=state.interrupted,
        outcome=outcome,
        fault=fault,
        wall_s=time.monotonic() - wall_start,
    )


def _track(reps: list[dict[str, float | None]], before: PolicyState, after: PolicyState, t: float) -> None:
    """Note the controller times at which runs start, reach the plan's end and settle.

    A run's path ends at the first message past the plan's duration (the controller's
    clock, not the plan's), and settles at the message that completes the repetition.
    """
    if reps and after.done > before.done:
        reps[-1]["settled"] = t
        if reps[-1]["path_end"] is None:
            reps[-1]["path_end"] = t
    if reps and before.phase is Phase.RUN and after.phase is Phase.HOLD:
        reps[-1]["path_end"] = t
    if after.phase is Phase.RUN and (before.phase is not Phase.RUN or after.t0 != before.t0):
        if reps and reps[-1]["settled"] is None:  # an interrupted run is run again
            reps.pop()
        reps.append({"started": after.t0, "path_end": None, "settled": None})


def executed_energy(robot: Robot, t: FloatArray, q: FloatArray) -> float:
    """Energy ``Σ |tau qd| dt`` (J) of a motion sampled at controller times ``t`` (s), ``q`` (rad).

    Speeds and accelerations are estimated from consecutive controller times
    (second-order differences, ``numpy.gradient`` on the non-uniform times), as
    abb_libegm estimates speeds from consecutive feedback times; each sample weighs
    half the time to its neighbours. Physics model: the robot's rigid body and its
    friction (:attr:`Robot.friction`), as ``result.json``'s energies.
    """
    if t.size < 3:
        return 0.0
    qd = np.gradient(q, t, axis=0)
    qdd = np.gradient(qd, t, axis=0)
    tau = robot.inverse_dynamics(q, qd, qdd, friction=robot.friction)
    w = np.empty_like(t)
    w[1:-1] = (t[2:] - t[:-2]) / 2
    w[0], w[-1] = (t[1] - t[0]) / 2, (t[-1] - t[-2]) / 2
    return float(path_energy(tau, qd, w).total)


def _pct(default: float | None, value: float | None) -> float | None:
    if default is None or value is None or not default > 0:
        return None
    return 100.0 * (default - value) / default


def summarize(
    session: Session, plan: Plan, robot: Robot, result: dict[str, Any], config: ServeConfig
) -> dict[str, Any]:
    """``stream.json``: datagrams, tracking error, executed duration and energy against the plan.

    Keys of quantities measured on the executed motion contain ``executed``. Per run:
    ``executed_duration_s`` is the controller time from the run's first reference to
    the first message past the plan's end; ``executed_settle_s`` from there to the
    settled end; ``energy_executed_J`` the feedback's energy over both
    (:func:`executed_energy`), and ``saved_executed_pct`` against ``result.json``'s
    ``energy_default_J``. The tracking error is |reference − feedback| of the messages
    in ``run``. ``late``: messages whose controller time is not after the previous
    one's (ignored, not answered).
    """
    run = np.array([p == Phase.RUN.value for p in session.phase], dtype=bool)
    err_deg = np.degrees(np.abs(session.q_ref - session.q_fb))[run] if run.any() else np.zeros((0, 1))
    reps = []
    energies = []
    for r in session.repetitions:
        item: dict[str, Any] = {
            "started_controller_s": r.started_s,
            "path_end_controller_s": r.path_end_s,
            "settled_controller_s": r.settled_s,
            "executed_duration_s": None if r.path_end_s is None else r.path_end_s - r.started_s,
            "executed_settle_s": None
            if r.settled_s is None or r.path_end_s is None
            else r.settled_s - r.path_end_s,
            "energy_executed_J": None,
        }
        if r.settled_s is not None:
            window = (session.t >= r.started_s - 1e-9) & (session.t <= r.settled_s + 1e-9)
            e = executed_energy(robot, session.t[window], session.q_fb[window])
            item["energy_executed_J"] = e
            energies.append(e)
        reps.append(item)
    e_def = result.get("energy_default_J")
    e_opt = result.get("energy_optimized_J")
    e_exec = float(np.mean(energies)) if energies else None
    durations = [r["executed_duration_s"] for r in reps if r["executed_duration_s"] is not None]
    for item in reps:
        item["saved_executed_pct"] = _pct(e_def, item["energy_executed_J"])
    ignored_total = sum(session.ignored.values())
    summary: dict[str, Any] = {
        "outcome": session.outcome,
        "fault": session.fault,
        "plan_file": plan.source,
        "robot": robot.name,
        "listen": f"{session.listen[0]}:{session.listen[1]}",
        "controller": _address(session.controller),
        "datagrams": {
            "received": session.received,
            "parsed": session.parsed,
            "answered": int(session.t.size),
            "ignored": ignored_total,
            "ignored_why": session.ignored,
            "late": session.late,
            "foreign": session.foreign,
            "replies_slower_than_period": session.slow_replies,
        },
        "controller_period_median_s": float(np.median(np.diff(session.t))) if session.t.size > 1 else None,
        "start": _moment(session, 0),
        "end": _moment(session, -1),
        "repetitions_asked": config.settings.repeats,
        "repetitions_executed": sum(1 for r in session.repetitions if r.settled_s is not None),
        "repetitions_interrupted": session.interrupted,
        "repetitions": reps,
        "planned_duration_s": plan.duration,
        "executed_duration_s": float(np.mean(durations)) if durations else None,
        "executed_duration_error_max_s": float(max(abs(d - plan.duration) for d in durations))
        if durations
        else None,
        "executed_tracking_error_max_deg": float(err_deg.max()) if err_deg.size else None,
        "executed_tracking_error_rms_deg": float(np.sqrt(np.mean(err_deg**2))) if err_deg.size else None,
        "energy_planned_J": e_opt,
        "energy_default_J": e_def,
        "saved_planned_pct": result.get("saved_pct"),
        "energy_executed_J": e_exec,
        "saved_executed_pct": _pct(e_def, e_exec),
        "energy_model": "rigid body + the robot's friction; |tau*qd|*dt on the feedback at the controller's "
        "times (executed), result.json's energies at the 25 ms plan samples (planned, default)",
        "wall_s": session.wall_s,
        "settings": {**asdict(config.settings), "timeout_s": config.timeout_s},
    }
    return summary


def _address(address: Address | None) -> str | None:
    return None if address is None else f"{address[0]}:{address[1]}"


def _moment(session: Session, k: int) -> dict[str, Any] | None:
    if session.t.size == 0:
        return None
    return {
        "controller_s": float(session.t[k]),
        "feedback_deg": np.degrees(session.q_fb[k]).tolist(),
        "phase": session.phase[k],
    }


def stream_csv(session: Session) -> str:
    """``stream.csv``: controller time, phase, plan time, reference (rad, rad/s) and feedback (rad)."""
    n = session.q_fb.shape[1]
    head = [
        "t",
        "phase",
        "plan_time",
        *(f"q_ref{i}" for i in range(1, n + 1)),
        *(f"qd_ref{i}" for i in range(1, n + 1)),
        *(f"q_fb{i}" for i in range(1, n + 1)),
    ]
    lines = [",".join(head)]
    for k in range(session.t.size):
        values = [*session.q_ref[k], *session.qd_ref[k], *session.q_fb[k]]
        s = session.plan_time[k]
        lines.append(
            ",".join(
                [f"{session.t[k]:.6f}", session.phase[k], "" if math.isnan(s) else f"{s:.6f}"]
                + [f"{v:.10g}" for v in values]
            )
        )
    return "\n".join(lines) + "\n"


@dataclass(frozen=True, slots=True)
class StreamOutcome:
    """What :func:`stream_run` wrote: the summary (``stream.json``) and the files."""

    summary: dict[str, Any]
    files: dict[str, Path]


def stream_run(
    folder: str | os.PathLike[str],
    config: ServeConfig,
    *,
    robot: str | None = None,
    out_dir: str | os.PathLike[str] | None = None,
    on_listening: Callable[[Address], None] | None = None,
) -> StreamOutcome:
    """Stream a run folder's plan to an EGM controller; write ``stream.csv`` and ``stream.json``.

    Reads ``path.csv`` (or ``cycle_path.csv``) and ``result.json``, loads the robot
    (``robot``, else ``result.json``'s), refuses a plan outside the robot's ranges or
    speed limits before listening, then serves (:func:`serve`).

    Raises
    ------
    InvalidInput
        No plan in the folder, an unreadable plan, no robot, a port that cannot be bound.
    LimitViolation
        A reference of the plan outside the robot's limits (nothing is sent).
    StreamAborted
        A fault stopped the stream (robot away from the start, silence, a reference too
        far from the feedback); the log files are written first.
    """
    plan = read_plan(plan_file(folder))
    result = read_run_result(folder)
    r = run_robot(result.get("robot"), robot)
    check_plan(plan, r)
    out = Path(out_dir) if out_dir is not None else Path(folder)
    with UdpEndpoint(config.host, config.port) as endpoint:
        session = serve(plan, endpoint, config, on_listening=on_listening, robot=r)
    summary = finite_json(summarize(session, plan, r, result, config))
    with output_journal():  # both files or neither, kept even when the session faulted (its record)
        files = {
            STREAM_CSV: atomic_write_text(out / STREAM_CSV, stream_csv(session)),
            STREAM_JSON: atomic_write_text(out / STREAM_JSON, json.dumps(summary, indent=2, allow_nan=False)),
        }
    if session.fault is not None:
        raise StreamAborted(f"{session.fault} (log: {out / STREAM_JSON})")
    return StreamOutcome(summary=summary, files=files)
