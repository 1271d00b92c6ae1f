import numpy as np
import pytest

from joulepath.energy import joint_energy, joint_power, path_energy, total_energy
from joulepath.errors import InvalidInput


def test_joint_energy_thesis_definition(rng):
    tau = rng.normal(size=(10, 6))
    qd = rng.normal(size=(10, 6))
    np.testing.assert_allclose(joint_energy(tau, qd, 0.025), np.abs(tau * qd) * 0.025)
    np.testing.assert_allclose(total_energy(tau, qd, 0.025), (np.abs(tau * qd) * 0.025).sum(1))


def test_joint_energy_modes_order(rng):
    tau = rng.normal(size=(50, 6))
    qd = rng.normal(size=(50, 6))
    signed = joint_energy(tau, qd, 0.01, mode="signed")
    positive = joint_energy(tau, qd, 0.01, mode="positive")
    absolute = joint_energy(tau, qd, 0.01)
    assert np.all(signed <= positive) and np.all(positive <= absolute)
    np.testing.assert_allclose(absolute - positive, np.maximum(-tau * qd, 0) * 0.01)


def test_copper_losses_are_spent_at_rest():
    e = joint_energy([[2.0, 0.0]], [[0.0, 0.0]], 0.5, copper_loss=(0.1, 0.1))
    np.testing.assert_allclose(e, [[0.2, 0.0]])


def test_joint_energy_per_sample_dt():
    e = joint_energy(np.ones((3, 2)), np.ones((3, 2)), np.array([0.1, 0.2, 0.3]))
    np.testing.assert_allclose(e[:, 0], [0.1, 0.2, 0.3])


def test_path_energy_sums_over_time(rng):
    tau = rng.normal(size=(4, 41, 6))
    qd = rng.normal(size=(4, 41, 6))
    res = path_energy(tau, qd, 0.025)
    assert res.per_joint.shape == (4, 6) and res.total.shape == (4,)
    np.testing.assert_allclose(res.total, joint_energy(tau, qd, 0.025).sum(axis=(1, 2)))


def test_energy_errors():
    with pytest.raises(InvalidInput, match=r"tau has shape \(2,\) but qd has shape \(3,\)"):
        joint_power(np.zeros(2), np.zeros(3))
    with pytest.raises(InvalidInput, match="mode must be one of"):
        joint_power(np.zeros(2), np.zeros(2), mode="regen")
    with pytest.raises(InvalidInput, match="dt must be finite"):
        joint_energy(np.zeros(2), np.zeros(2), -1.0)
    with pytest.raises(InvalidInput, match="copper_loss"):
        joint_power(np.zeros(2), np.zeros(2), copper_loss=-1)
    with pytest.raises(InvalidInput, match="expected shape"):
        path_energy(np.zeros(2), np.zeros(2), 0.1)


def test_robot_path_energy_of_a_move(irb120):
    from joulepath.trajectory import minimum_jerk

    move = minimum_jerk(np.zeros(6), np.full(6, 0.5), 1.0)
    res = irb120.path_energy(move.q, move.qd, move.qdd, 0.025)
    tau = irb120.inverse_dynamics(move.q, move.qd, move.qdd)
    np.testing.assert_allclose(res.per_joint, (np.abs(tau * move.qd) * 0.025).sum(0))
    assert res.total > 0
