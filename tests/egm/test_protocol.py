"""Protocol layer: EgmRobot / EgmSensor round trips through ABB's egm.proto, and validation."""

import math

import pytest

pytest.importorskip("abb_robot_client._egm_protobuf.egm_pb2")

from joulepath.egm import (  # noqa: E402
    GARBAGE,
    RobotMessage,
    decode_robot,
    decode_sensor,
    egm_pb2,
    encode_robot,
    encode_sensor,
)
from joulepath.errors import InvalidMessage  # noqa: E402

JOINTS = (10.0, -20.5, 30.25, -40.0, 50.0, -60.125)


def robot_message(**kw):
    base = dict(
        seqno=7,
        tm_ms=1234,
        time_s=1001.236,
        joints_deg=JOINTS,
        motors_on=True,
        egm_running=True,
        rapid_running=True,
        convergence_met=False,
    )
    return RobotMessage(**{**base, **kw})


def test_decode_robot_round_trip():
    sent = robot_message()
    got = decode_robot(encode_robot(sent), 6)
    assert got.seqno == sent.seqno and got.tm_ms == sent.tm_ms
    assert got.joints_deg == sent.joints_deg
    assert math.isclose(got.time_s, sent.time_s, abs_tol=1e-6)
    assert got.motors_on and got.egm_running and got.rapid_running
    assert got.convergence_met is False


def test_decode_robot_states_off():
    off = robot_message(motors_on=False, egm_running=False, rapid_running=False)
    got = decode_robot(encode_robot(off), 6)
    assert not got.motors_on and not got.egm_running and not got.rapid_running


def test_encode_sensor_round_trip_and_header():
    data = encode_sensor(3, 1234, [1.0, 2, 3, 4, 5, 6], [0.5] * 6)
    got = decode_sensor(data, 6)
    assert (got.seqno, got.tm_ms) == (3, 1234)
    assert got.planned_deg == (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)
    assert got.speed_deg_s == (0.5,) * 6
    pb = egm_pb2()
    raw = pb.EgmSensor.FromString(data)
    assert raw.header.mtype == pb.EgmHeader.MSGTYPE_CORRECTION


def test_decode_robot_falls_back_to_header_tm():
    pb = egm_pb2()
    msg = pb.EgmRobot()
    msg.header.seqno = 1
    msg.header.tm = 2500
    msg.feedBack.joints.joints.extend(JOINTS)
    got = decode_robot(msg.SerializeToString(), 6)
    assert got.time_s == pytest.approx(2.5)
    assert not got.egm_running  # no mciState: not running


@pytest.mark.parametrize(
    ("build", "reason"),
    [
        ("garbage", "not an EgmRobot"),
        ("empty", "no header"),
        ("no_joints", "no feedback joints"),
        ("five_joints", "wrong joint count"),
        ("nan", "joint not finite"),
        ("no_time", "no controller time"),
    ],
)
def test_decode_robot_refuses_with_reason(build, reason):
    pb = egm_pb2()
    msg = pb.EgmRobot()
    msg.header.seqno = 1
    if build == "garbage":
        data = GARBAGE
    elif build == "empty":
        data = b""
    else:
        if build != "no_time":
            msg.header.tm = 10
        if build == "five_joints":
            msg.feedBack.joints.joints.extend(JOINTS[:5])
        elif build == "nan":
            msg.feedBack.joints.joints.extend((*JOINTS[:5], float("nan")))
        elif build != "no_joints":
            msg.feedBack.joints.joints.extend(JOINTS)
        else:
            msg.feedBack.cartesian.pos.x = 1.0
            msg.feedBack.cartesian.pos.y = 1.0
            msg.feedBack.cartesian.pos.z = 1.0
        data = msg.SerializeToString()
    with pytest.raises(InvalidMessage, match=reason) as info:
        decode_robot(data, 6)
    assert info.value.reason == reason


def test_decode_sensor_refuses_wrong_count():
    with pytest.raises(InvalidMessage, match="wrong joint count"):
        decode_sensor(encode_sensor(1, 1, [1.0] * 5, [0.0] * 5), 6)
