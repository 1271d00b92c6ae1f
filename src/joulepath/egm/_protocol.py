"""Protocol layer: bytes ↔ typed EGM messages, through ABB's published ``egm.proto``.

The message classes are the ``egm_pb2`` module that ``abb-robot-client`` ships
(generated from ABB's ``egm.proto``; ``pip install 'joulepath[abb]'``); nothing here
encodes protobuf by hand. The controller sends ``EgmRobot`` (feedback joints in deg,
its clock, motor and motion-control states); the PC answers each with an
``EgmSensor`` (``planned.joints`` in deg, ``speedRef.joints`` in deg/s).

Units at this boundary are the controller's (deg, deg/s, ms); :class:`RobotMessage`
and :class:`SensorMessage` carry them as sent. Conversions to rad happen in the
server.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from typing import Any

from joulepath.errors import InvalidMessage, MissingDependency

MAX_DATAGRAM = 65536
"""Largest UDP payload read."""


@cache
def egm_pb2() -> Any:
    """ABB's ``egm.proto`` messages (the ``egm_pb2`` module of ``abb-robot-client``).

    Raises
    ------
    MissingDependency
        ``abb-robot-client`` (or the protobuf runtime) is not installed.
    """
    try:
        from abb_robot_client._egm_protobuf import egm_pb2 as module
    except ImportError as err:
        raise MissingDependency(
            "EGM streaming needs ABB's egm.proto messages from abb-robot-client: pip install 'joulepath[abb]'"
        ) from err
    return module


@dataclass(frozen=True, slots=True)
class RobotMessage:
    """One ``EgmRobot`` datagram, validated.

    Attributes
    ----------
    seqno : int
        ``header.seqno``.
    tm_ms : int
        ``header.tm``, the controller's time stamp in ms.
    time_s : float
        The controller's clock in s: ``feedBack.time`` (sec + usec) when sent,
        else ``header.tm`` / 1000.
    joints_deg : tuple of float
        ``feedBack.joints``, deg.
    motors_on : bool
        ``motorState`` is ``MOTORS_ON``.
    egm_running : bool
        ``mciState`` is ``MCI_RUNNING`` (an EGMRunJoint is active).
    rapid_running : bool
        ``rapidExecState`` is ``RAPID_RUNNING``.
    convergence_met : bool or None
        ``mciConvergenceMet`` when sent.
    """

    seqno: int
    tm_ms: int
    time_s: float
    joints_deg: tuple[float, ...]
    motors_on: bool
    egm_running: bool
    rapid_running: bool
    convergence_met: bool | None = None


@dataclass(frozen=True, slots=True)
class SensorMessage:
    """One ``EgmSensor`` datagram: the references the PC sends."""

    seqno: int
    tm_ms: int
    planned_deg: tuple[float, ...]
    speed_deg_s: tuple[float, ...]


def decode_robot(data: bytes, n_joints: int) -> RobotMessage:
    """Parse and validate an ``EgmRobot`` datagram.

    Raises
    ------
    InvalidMessage
        ``reason`` is one of ``"not an EgmRobot"`` (does not parse), ``"no header"``,
        ``"no feedback joints"``, ``"wrong joint count"``, ``"joint not finite"``,
        ``"no controller time"``.
    """
    pb = egm_pb2()
    msg = pb.EgmRobot()
    try:
        msg.ParseFromString(data)
    except Exception as err:  # protobuf's DecodeError and the C runtime's own
        raise InvalidMessage("not an EgmRobot", f"{len(data)} bytes that do not parse") from err
    if not msg.HasField("header") or not msg.header.HasField("seqno"):
        raise InvalidMessage("no header", "EgmRobot without header.seqno")
    if not msg.HasField("feedBack") or not msg.feedBack.HasField("joints"):
        raise InvalidMessage("no feedback joints", "EgmRobot without feedBack.joints")
    joints = tuple(float(v) for v in msg.feedBack.joints.joints)
    if len(joints) != n_joints:
        raise InvalidMessage("wrong joint count", f"{len(joints)} feedback joints, expected {n_joints}")
    if not all(math.isfinite(v) for v in joints):
        raise InvalidMessage("joint not finite", f"feedback joints {joints}")
    if msg.feedBack.HasField("time"):
        time_s = msg.feedBack.time.sec + msg.feedBack.time.usec * 1e-6
    elif msg.header.HasField("tm"):
        time_s = msg.header.tm * 1e-3
    else:
        raise InvalidMessage("no controller time", "neither feedBack.time nor header.tm")
    return RobotMessage(
        seqno=int(msg.header.seqno),
        tm_ms=int(msg.header.tm),
        time_s=float(time_s),
        joints_deg=joints,
        motors_on=msg.HasField("motorState") and msg.motorState.state == pb.EgmMotorState.MOTORS_ON,
        egm_running=msg.HasField("mciState") and msg.mciState.state == pb.EgmMCIState.MCI_RUNNING,
        rapid_running=msg.HasField("rapidExecState")
        and msg.rapidExecState.state == pb.EgmRapidCtrlExecState.RAPID_RUNNING,
        convergence_met=bool(msg.mciConvergenceMet) if msg.HasField("mciConvergenceMet") else None,
    )


def encode_sensor(
    seqno: int, tm_ms: int, planned_deg: Sequence[float], speed_deg_s: Sequence[float]
) -> bytes:
    """An ``EgmSensor`` datagram: header (seqno, tm, ``MSGTYPE_CORRECTION``), position and speed.

    ``tm_ms`` is the ``header.tm`` of the ``EgmRobot`` answered, so that the controller
    (and any log) can pair an answer with the message it answers.
    """
    pb = egm_pb2()
    msg = pb.EgmSensor()
    msg.header.seqno = seqno & 0xFFFFFFFF
    msg.header.tm = tm_ms & 0xFFFFFFFF
    msg.header.mtype = pb.EgmHeader.MSGTYPE_CORRECTION
    msg.planned.joints.joints.extend(float(v) for v in planned_deg)
    msg.speedRef.joints.joints.extend(float(v) for v in speed_deg_s)
    out: bytes = msg.SerializeToString()
    return out


def encode_robot(message: RobotMessage) -> bytes:
    """An ``EgmRobot`` datagram (the controller's side; used by the emulated controller)."""
    pb = egm_pb2()
    msg = pb.EgmRobot()
    msg.header.seqno = message.seqno & 0xFFFFFFFF
    msg.header.tm = message.tm_ms & 0xFFFFFFFF
    msg.header.mtype = pb.EgmHeader.MSGTYPE_DATA
    msg.feedBack.joints.joints.extend(message.joints_deg)
    sec = math.floor(message.time_s)
    msg.feedBack.time.sec = sec
    msg.feedBack.time.usec = min(999_999, round((message.time_s - sec) * 1e6))
    msg.motorState.state = pb.EgmMotorState.MOTORS_ON if message.motors_on else pb.EgmMotorState.MOTORS_OFF
    msg.mciState.state = pb.EgmMCIState.MCI_RUNNING if message.egm_running else pb.EgmMCIState.MCI_STOPPED
    msg.rapidExecState.state = (
        pb.EgmRapidCtrlExecState.RAPID_RUNNING
        if message.rapid_running
        else pb.EgmRapidCtrlExecState.RAPID_STOPPED
    )
    if message.convergence_met is not None:
        msg.mciConvergenceMet = message.convergence_met
    out: bytes = msg.SerializeToString()
    return out


def decode_sensor(data: bytes, n_joints: int) -> SensorMessage:
    """Parse and validate an ``EgmSensor`` datagram (the emulated controller's side).

    Raises
    ------
    InvalidMessage
        Does not parse (``"not an EgmSensor"``), or a joint count other than ``n_joints``
        (``"wrong joint count"``), or a value that is not finite (``"joint not finite"``).
    """
    pb = egm_pb2()
    msg = pb.EgmSensor()
    try:
        msg.ParseFromString(data)
    except Exception as err:
        raise InvalidMessage("not an EgmSensor", f"{len(data)} bytes that do not parse") from err
    planned = tuple(float(v) for v in msg.planned.joints.joints)
    speed = tuple(float(v) for v in msg.speedRef.joints.joints)
    if len(planned) != n_joints or len(speed) not in (0, n_joints):
        raise InvalidMessage(
            "wrong joint count", f"{len(planned)} planned and {len(speed)} speed joints, expected {n_joints}"
        )
    if not all(math.isfinite(v) for v in planned + speed):
        raise InvalidMessage("joint not finite", f"planned {planned}, speed {speed}")
    return SensorMessage(
        seqno=int(msg.header.seqno), tm_ms=int(msg.header.tm), planned_deg=planned, speed_deg_s=speed
    )
