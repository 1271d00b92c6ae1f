import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.trajectory import minimum_jerk, sample_times


def test_minimum_jerk_boundary_conditions(rng):
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    tr = minimum_jerk(q0, qf, 1.5)
    np.testing.assert_allclose(tr.q[0], q0)
    np.testing.assert_allclose(tr.q[-1], qf, atol=1e-15)
    np.testing.assert_allclose(tr.qd[[0, -1]], 0, atol=1e-15)
    np.testing.assert_allclose(tr.qdd[[0, -1]], 0, atol=1e-13)
    assert tr.t[-1] == pytest.approx(1.5) and tr.dt == pytest.approx(0.025)


def test_minimum_jerk_derivatives_match_finite_differences():
    tr = minimum_jerk(np.zeros(2), np.array([1.0, -2.0]), 1.0, dt=0.0005)
    np.testing.assert_allclose(np.gradient(tr.q, tr.t, axis=0)[1:-1], tr.qd[1:-1], atol=1e-5)
    np.testing.assert_allclose(np.gradient(tr.qd, tr.t, axis=0)[1:-1], tr.qdd[1:-1], atol=1e-3)


def test_minimum_jerk_batch():
    tr = minimum_jerk(np.zeros((5, 6)), np.ones((5, 6)), 1.0)
    assert tr.q.shape == (5, 41, 6)


def test_sample_times_rejects_fractional_durations():
    assert sample_times(1.0).size == 41
    with pytest.raises(InvalidInput, match="not a whole number"):
        sample_times(1.01)
    with pytest.raises(InvalidInput, match="positive"):
        sample_times(-1.0)
