"""The emulated controller: first-order tracking of the references, its clock, its refusals."""

import math
import threading

import numpy as np
import pytest

pytest.importorskip("abb_robot_client._egm_protobuf.egm_pb2")

from joulepath.egm import (  # noqa: E402
    EmulatorConfig,
    UdpEndpoint,
    decode_robot,
    encode_sensor,
    run_emulator,
)
from joulepath.errors import InvalidInput  # noqa: E402

REF = (10.0, 20.0, 30.0, 40.0, 50.0, 60.0)


def constant_server(endpoint, n_replies, seen):
    """Answer the first ``n_replies`` EgmRobot with the constant reference REF, then stay quiet."""
    for k in range(n_replies):
        got = endpoint.receive(5.0)
        if got is None:
            return
        msg = decode_robot(got.data, 6)
        seen.append(msg)
        endpoint.send(encode_sensor(k + 1, msg.tm_ms, REF, [0.0] * 6), got.sender)


def test_emulator_follows_a_step_with_a_first_order_lag():
    seen = []
    with UdpEndpoint("127.0.0.1", 0) as server:
        th = threading.Thread(target=constant_server, args=(server, 60, seen), daemon=True)
        th.start()
        config = EmulatorConfig(
            q_start_deg=(0.0,) * 6, lag_s=0.02, running_after_s=0.0, wall_period_s=0.0, stop_after_missed=3
        )
        log = run_emulator(server.address, config)
        th.join(5.0)
    assert log.answered == 60 and "unanswered" in log.stopped
    alpha = 1 - math.exp(-0.004 / 0.02)
    k = np.arange(1, 61)
    expected = np.array(REF) * (1 - (1 - alpha) ** k)[:, None]  # the feedback sent at tick k
    np.testing.assert_allclose(log.q_deg[1:61], expected, rtol=1e-9, atol=1e-9)
    times = np.array([m.time_s for m in seen])
    np.testing.assert_allclose(np.diff(times), 0.004, atol=2e-6)  # its own clock, 4 ms a message
    assert all(m.egm_running and m.motors_on for m in seen)


def test_emulator_holds_before_egm_runs():
    seen = []
    with UdpEndpoint("127.0.0.1", 0) as server:
        th = threading.Thread(target=constant_server, args=(server, 20, seen), daemon=True)
        th.start()
        config = EmulatorConfig(
            q_start_deg=(0.0,) * 6, running_after_s=1.0, wall_period_s=0.0, stop_after_missed=2
        )
        log = run_emulator(server.address, config)
        th.join(5.0)
    assert not any(m.egm_running for m in seen)
    np.testing.assert_allclose(log.q_deg, 0.0)


def test_emulator_talks_to_loopback_only():
    with pytest.raises(InvalidInput, match="127.0.0.1"):
        run_emulator(("10.0.0.1", 6510), EmulatorConfig(q_start_deg=(0.0,) * 6))


def test_emulator_config_refuses_bad_values():
    with pytest.raises(InvalidInput):
        EmulatorConfig(q_start_deg=(math.nan,))
    with pytest.raises(InvalidInput):
        EmulatorConfig(q_start_deg=(0.0,), period_s=0.0)
