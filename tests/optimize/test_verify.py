"""The limit check's jerk: its definition on a grid, its agreement with the analytic jerk, its report."""

import numpy as np
import pytest

from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.optimize import ACCEL_TIME, JERK_TIME, check_limits, jerk_limit, path_jerk
from joulepath.trajectory import minimum_jerk

Q0 = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
QF = np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])


def test_path_jerk_agrees_with_the_minimum_jerk_moves_analytic_jerk():
    """60 Δq (1 - 6x + 6x²) / T³ at each step's midpoint, to O(dt²); its peak 60 |Δq| / T³ at the ends."""
    T, dt = 1.6, 0.0025
    t, jerk = path_jerk(minimum_jerk(Q0, QF, T, dt=dt))
    x = t / T
    exact = 60 * (QF - Q0) * (1 - 6 * x + 6 * x**2)[:, None] / T**3
    assert t.shape == (640,) and jerk.shape == (640, 6)
    np.testing.assert_allclose(jerk, exact, atol=1e-5 * np.abs(exact).max())
    np.testing.assert_allclose(np.abs(jerk).max(axis=0), 60 * np.abs(QF - Q0) / T**3, rtol=0.01)


def test_path_jerk_of_a_batch_is_that_of_each_path():
    a, b = minimum_jerk(Q0, QF, 1.0, dt=0.01), minimum_jerk(QF, Q0, 1.0, dt=0.01)
    batch = minimum_jerk(np.stack([Q0, QF]), np.stack([QF, Q0]), 1.0, dt=0.01)
    _, both = path_jerk(batch)
    np.testing.assert_allclose(both, np.stack([path_jerk(a)[1], path_jerk(b)[1]]))


def test_check_limits_reports_the_jerk_excess(irb120):
    fine = minimum_jerk(Q0, QF, 1.6, dt=0.0025)
    peak = np.abs(path_jerk(fine)[1]).max(axis=0)
    assert check_limits(irb120, fine, friction=NOMINAL_FRICTION, jerk_limit=peak * 1.001).ok
    report = check_limits(irb120, fine, friction=NOMINAL_FRICTION, jerk_limit=peak * 0.9)
    (worst,) = report.worst
    assert worst.kind == "jerk" and worst.excess == pytest.approx(1 / 0.9 - 1)
    assert "deg/s³" in worst.describe()
    assert worst.t_s < 0.01 or worst.t_s > 1.59  # at an end
    assert report.overspeed > 0  # counted with the speeds and accelerations
    # the default limits: the controller's (v_max / ACCEL_TIME / JERK_TIME); this move keeps them
    jmax = jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    assert check_limits(irb120, fine, friction=NOMINAL_FRICTION, jerk_limit=jmax).ok
