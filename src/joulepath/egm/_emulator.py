"""An emulated EGM controller: a UDP client on 127.0.0.1 that plays the robot's side.

Every ``period_s`` of its own clock it sends an ``EgmRobot`` (feedback joints in deg,
``feedBack.time`` and ``header.tm`` from its clock, motors on, ``mciState`` running
from ``running_after_s`` on) and waits up to ``reply_timeout_s`` (wall time) for the
``EgmSensor`` answer. Its joints follow the last position reference through a
first-order lag of time constant ``lag_s`` (``q += (ref - q) * (1 - exp(-period/lag))``
per tick; the speed reference is not used). It waits for each answer, so a run is
the same whatever the PC's load; ``wall_period_s`` below ``period_s`` runs it faster
than real time, which also shows whether a server follows the controller's clock.

Once answered, it stops when the server's port is closed (the ICMP "port unreachable"
of loopback) or after ``stop_after_missed`` consecutive unanswered messages; in any case
after ``max_ticks`` ticks or ``timeout_s`` seconds of wall time.

Faults to inject: ``garbage_every`` (a datagram that is not an ``EgmRobot`` before
every k-th message), ``foreign_every`` (a valid ``EgmRobot`` from a second socket,
another port of 127.0.0.1, every k-th tick), ``silent_after_s`` (stop sending at that
controller time, stay quiet for ``silence_s`` of wall time, then stop), and any
``q_start_deg`` (e.g. away from the path's start).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from joulepath._typing import FloatArray
from joulepath.egm._protocol import RobotMessage, decode_sensor, encode_robot
from joulepath.egm._transport import Address, UdpEndpoint
from joulepath.errors import InvalidInput, InvalidMessage

LOOPBACK = "127.0.0.1"
GARBAGE = b"\xff\xff\xff\xff joulepath emulator: this is not an EgmRobot \x00"
"""The injected datagram: starts with an invalid protobuf tag, so it never parses."""


@dataclass(frozen=True, slots=True, kw_only=True)
class EmulatorConfig:
    """How the emulated controller behaves (see the module docstring)."""

    q_start_deg: tuple[float, ...]
    period_s: float = 0.004
    wall_period_s: float = 0.004
    lag_s: float = 0.01
    clock_start_s: float = 1000.0
    running_after_s: float = 0.04
    reply_timeout_s: float = 1.0
    stop_after_missed: int = 5
    max_ticks: int = 20_000
    timeout_s: float = 60.0
    garbage_every: int = 0
    foreign_every: int = 0
    silent_after_s: float | None = None
    silence_s: float = 1.0

    def __post_init__(self) -> None:
        if not self.q_start_deg or not all(math.isfinite(v) for v in self.q_start_deg):
            raise InvalidInput("q_start_deg needs finite joint values")
        for name in ("period_s", "reply_timeout_s", "timeout_s"):
            if not getattr(self, name) > 0:
                raise InvalidInput(f"{name} must be > 0")
        if self.wall_period_s < 0 or self.lag_s < 0 or self.silence_s < 0:
            raise InvalidInput("wall_period_s, lag_s and silence_s must be ≥ 0")
        if self.max_ticks < 1 or self.stop_after_missed < 1:
            raise InvalidInput("max_ticks and stop_after_missed must be ≥ 1")


@dataclass(frozen=True, slots=True)
class EmulatorLog:
    """What the emulated controller did, one row per tick.

    Attributes
    ----------
    t : ndarray of shape (n_ticks,)
        Its clock, s.
    q_deg : ndarray of shape (n_ticks, n)
        Feedback joints sent at each tick, deg.
    ref_deg : ndarray of shape (n_ticks, n)
        The position reference answered to that tick (NaN when unanswered).
    speed_deg_s : ndarray of shape (n_ticks, n)
        The speed reference answered (NaN when unanswered).
    answered : int
        Ticks answered.
    garbage_sent, foreign_sent, foreign_answered : int
        Injected datagrams, and answers the second socket received (should be 0).
    stopped : str
        Why it stopped.
    """

    t: FloatArray
    q_deg: FloatArray
    ref_deg: FloatArray
    speed_deg_s: FloatArray
    answered: int
    garbage_sent: int
    foreign_sent: int
    foreign_answered: int
    stopped: str
    reply_seqnos: tuple[int, ...] = field(default=())
    reply_tms: tuple[int, ...] = field(default=())


def _message(k: int, t: float, q: FloatArray, running: bool, converged: bool) -> RobotMessage:
    return RobotMessage(
        seqno=k,
        tm_ms=round(t * 1000.0),
        time_s=t,
        joints_deg=tuple(float(v) for v in q),
        motors_on=True,
        egm_running=running,
        rapid_running=True,
        convergence_met=converged,
    )


def run_emulator(server: Address, config: EmulatorConfig) -> EmulatorLog:
    """Play the controller against an EGM server at ``server`` (an address on 127.0.0.1).

    Raises
    ------
    InvalidInput
        ``server`` is not on 127.0.0.1: the emulator talks to this machine only.
    """
    if server[0] != LOOPBACK:
        raise InvalidInput(f"the emulated controller talks to {LOOPBACK} only, not {server[0]}")
    n = len(config.q_start_deg)
    q = np.array(config.q_start_deg, dtype=float)
    ref = q.copy()
    alpha = 1.0 if config.lag_s == 0 else 1.0 - math.exp(-config.period_s / config.lag_s)
    rows_t: list[float] = []
    rows_q: list[FloatArray] = []
    rows_ref: list[FloatArray] = []
    rows_speed: list[FloatArray] = []
    seqnos: list[int] = []
    tms: list[int] = []
    answered = missed = garbage = foreign = foreign_answered = refused_before = 0
    stopped = f"max_ticks ({config.max_ticks}) reached"
    wall_start = time.monotonic()
    with UdpEndpoint(LOOPBACK, 0) as sock, UdpEndpoint(LOOPBACK, 0) as other:
        sock.connect(server)  # as a controller's UDPUC device: one remote address
        for k in range(config.max_ticks):
            tick_wall = time.monotonic()
            if tick_wall - wall_start > config.timeout_s:
                stopped = f"timeout_s ({config.timeout_s:g} s) reached"
                break
            elapsed = k * config.period_s
            t = config.clock_start_s + elapsed
            if config.silent_after_s is not None and elapsed >= config.silent_after_s:
                time.sleep(config.silence_s)
                stopped = f"went silent at {elapsed:.3f} s for {config.silence_s:g} s"
                break
            running = elapsed >= config.running_after_s
            converged = bool(np.all(np.abs(ref - q) < 0.1))
            if config.garbage_every and k % config.garbage_every == 0:
                sock.send(GARBAGE, server)
                garbage += 1
            if config.foreign_every and k % config.foreign_every == 0 and k > 0:
                other.send(encode_robot(_message(k, t, q + 3.0, running, converged)), server)
                foreign += 1
            sock.send(encode_robot(_message(k, t, q, running, converged)), server)
            rows_t.append(t)
            rows_q.append(q.copy())
            got = _await_reply(sock, round(t * 1000.0), n, config.reply_timeout_s)
            if other.receive(0.0) is not None:
                foreign_answered += 1
            if answered and sock.refused > refused_before:
                rows_ref.append(np.full(n, np.nan))
                rows_speed.append(np.full(n, np.nan))
                stopped = "the server closed its port"
                break
            if got is None:
                rows_ref.append(np.full(n, np.nan))
                rows_speed.append(np.full(n, np.nan))
                missed += 1
                if answered and missed >= config.stop_after_missed:
                    stopped = f"{missed} messages unanswered in a row"
                    break
            else:
                planned, speed, seqno, tm = got
                if not answered:
                    refused_before = sock.refused  # before the server listened: not an end
                ref = planned
                rows_ref.append(planned)
                rows_speed.append(speed)
                seqnos.append(seqno)
                tms.append(tm)
                answered += 1
                missed = 0
            if running:
                q = q + alpha * (ref - q)
            pause = config.wall_period_s - (time.monotonic() - tick_wall)
            if pause > 0:
                time.sleep(pause)
    empty = np.zeros((0, n))
    return EmulatorLog(
        t=np.array(rows_t),
        q_deg=np.array(rows_q) if rows_q else empty,
        ref_deg=np.array(rows_ref) if rows_ref else empty,
        speed_deg_s=np.array(rows_speed) if rows_speed else empty,
        answered=answered,
        garbage_sent=garbage,
        foreign_sent=foreign,
        foreign_answered=foreign_answered,
        stopped=stopped,
        reply_seqnos=tuple(seqnos),
        reply_tms=tuple(tms),
    )


def _await_reply(
    sock: UdpEndpoint, tm_ms: int, n: int, timeout_s: float
) -> tuple[FloatArray, FloatArray, int, int] | None:
    """The answer to the message stamped ``tm_ms`` (older answers are dropped), or None."""
    deadline = time.monotonic() + timeout_s
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return None
        dgram = sock.receive(left, stop_on_refused=True)
        if dgram is None:
            return None
        try:
            msg = decode_sensor(dgram.data, n)
        except InvalidMessage:
            continue
        if msg.tm_ms != tm_ms & 0xFFFFFFFF:
            continue
        speed = np.array(msg.speed_deg_s) if msg.speed_deg_s else np.zeros(n)
        return np.array(msg.planned_deg), speed, msg.seqno, msg.tm_ms
