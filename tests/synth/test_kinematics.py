"""Physical consistency: TCP columns against FK(q), and their repair."""

from __future__ import annotations

import numpy as np
import pytest

import joulepath
from joulepath.data import EnergyTable
from joulepath.errors import InvalidInput
from joulepath.synth import (
    TCP_TOLERANCE_M,
    euler_zyx_rates,
    kinematic_consistency,
    repair_kinematics,
    tcp_error,
)

TCP = ["x", "y", "z", "qw", "qx", "qy", "qz", "yaw", "pitch", "roll"]


def test_real_rows_are_consistent(energy_table, irb120):
    assert kinematic_consistency(energy_table, irb120) == 1.0
    err = tcp_error(energy_table, "irb120")
    assert err.shape == (len(energy_table.frame),) and err.max() < 1e-6


def test_synthetic_rows_are_not_and_repaired_rows_are(fitted, irb120):
    _, synthetic = fitted("ctgan")
    assert kinematic_consistency(synthetic, irb120) < 0.5
    repaired = repair_kinematics(synthetic, irb120)
    assert kinematic_consistency(repaired, irb120) == 1.0
    assert tcp_error(repaired, irb120).max() < 1e-9
    assert kinematic_consistency(synthetic) < 0.5  # the input is not changed
    joints = [c for c in synthetic.frame.columns if c.startswith(("q", "dq", "ddq", "E")) and c[-1].isdigit()]
    assert synthetic.frame[joints].equals(repaired.frame[joints])
    assert repaired.sources[-1]["repaired_kinematics"] == irb120.name
    quat = repaired.frame[["qw", "qx", "qy", "qz"]].to_numpy()
    np.testing.assert_allclose(np.linalg.norm(quat, axis=1), 1.0)
    assert (quat[:, 0] >= 0).all()


def test_repair_reproduces_the_pose_columns_of_real_rows(energy_table, irb120):
    repaired = repair_kinematics(energy_table, irb120)
    np.testing.assert_allclose(repaired.frame[TCP[:7]], energy_table.frame[TCP[:7]], atol=1e-4)
    # yaw and roll alone are not defined at pitch = ±90 deg (the home pose: tool0 points down):
    # there only yaw - roll (pitch +90) is, and the log's 5 decimals move them apart
    pitch = energy_table.frame["pitch"].to_numpy()
    regular = np.abs(np.abs(pitch) - np.pi / 2) > 1e-3
    np.testing.assert_allclose(
        repaired.frame[TCP[7:]][regular], energy_table.frame[TCP[7:]][regular], atol=1e-4
    )
    lock = ~regular & (pitch > 0)
    diff = lambda f: (f["yaw"] - f["roll"]).to_numpy()[lock]  # noqa: E731
    np.testing.assert_allclose(diff(repaired.frame), diff(energy_table.frame), atol=1e-4)


def test_repaired_derivatives_match_finite_differences_along_a_motion(irb120):
    """TCP velocity/acceleration and Euler rates of repaired rows = derivatives of FK along q(t)."""
    t = np.linspace(0.0, 1.0, 2001)
    q0 = np.array([0.3, 0.2, -0.4, 0.5, 0.6, -0.2])
    amp = np.array([0.4, 0.3, 0.3, 0.6, 0.4, 0.8])
    q = q0 + amp * np.sin(2.0 * t)[:, None]
    qd = amp * 2.0 * np.cos(2.0 * t)[:, None]
    qdd = -amp * 4.0 * np.sin(2.0 * t)[:, None]
    pose = irb120.fk(q)
    frame = {"move_id": np.zeros(t.size, dtype=np.int64), "t": t}
    for i in range(6):
        frame[f"q{i + 1}"], frame[f"dq{i + 1}"], frame[f"ddq{i + 1}"] = q[:, i], qd[:, i], qdd[:, i]
    import pandas as pd

    from joulepath.data import table_columns

    for c in table_columns("full40"):
        frame.setdefault(c, np.zeros(t.size))
    table = EnergyTable(frame=pd.DataFrame(frame)[list(table_columns("full40"))], feature_set="full40")
    out = repair_kinematics(table, irb120).frame
    h = t[1] - t[0]
    pos = pose.position_m
    vel = np.gradient(pos, h, axis=0)
    acc = np.gradient(vel, h, axis=0)
    euler = np.unwrap(pose.euler_zyx, axis=0)
    rate = np.gradient(euler, h, axis=0)
    rate_acc = np.gradient(rate, h, axis=0)
    inner = slice(5, -5)
    np.testing.assert_allclose(out[["dx", "dy", "dz"]].to_numpy()[inner], vel[inner], atol=1e-5)
    np.testing.assert_allclose(out[["ddx", "ddy", "ddz"]].to_numpy()[inner], acc[inner], rtol=1e-4, atol=1e-4)
    np.testing.assert_allclose(
        out[["dphi", "dtheta", "dpsi"]].to_numpy()[inner], rate[inner], rtol=1e-4, atol=1e-5
    )
    np.testing.assert_allclose(
        out[["ddphi", "ddtheta", "ddpsi"]].to_numpy()[inner], rate_acc[inner], rtol=1e-3, atol=1e-3
    )


def test_euler_rates_at_gimbal_lock_are_nan():
    rates = euler_zyx_rates(np.array([[0.1, np.pi / 2, 0.0]]), np.array([[0.1, 0.2, 0.3]]))
    assert np.isnan(rates[0, 0]) and np.isnan(rates[0, 2]) and np.isfinite(rates[0, 1])


def test_tolerance_is_5_mm():
    assert TCP_TOLERANCE_M == 0.005


def test_kinematics_errors(energy_table, joint_table):
    with pytest.raises(InvalidInput, match="feature set 'joint', which has no TCP columns"):
        repair_kinematics(joint_table)
    with pytest.raises(InvalidInput, match="expects an EnergyTable"):
        kinematic_consistency(energy_table.frame)  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="tolerance_m must be > 0"):
        kinematic_consistency(energy_table, tolerance_m=0.0)
    other = EnergyTable(frame=energy_table.frame, feature_set="full40", robot="KR 300")
    with pytest.raises(InvalidInput, match="recorded on 'KR 300', but the robot given is 'IRB 120'"):
        tcp_error(other, joulepath.load_robot("irb120"))
    with pytest.raises(InvalidInput, match="robot must be a joulepath Robot or a robot name"):
        tcp_error(energy_table, 3)  # type: ignore[arg-type]
