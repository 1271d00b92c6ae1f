"""The controller's acceleration and jerk limits, and the emulation keeping its own moves within them."""

import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.export import Move, draw_moves
from joulepath.sim import (
    ACCEL_TIME,
    JERK_TIME,
    ControllerConfig,
    acceleration_limit,
    evaluate_plan,
    jerk_limit,
    plan_moves,
)
from joulepath.sim._profile import evaluate_profile, plan_profile


def _jerk(qdd, dt):
    return np.diff(qdd, axis=0) / dt


def test_limits_are_speed_over_accel_time_then_over_jerk_time(irb120):
    vmax = np.asarray(irb120.velocity_limit)
    np.testing.assert_allclose(acceleration_limit(irb120, 0.5), vmax / 0.5)
    np.testing.assert_allclose(jerk_limit(irb120, 0.5, 0.2), vmax / 0.5 / 0.2)
    assert acceleration_limit(irb120, 0.0) is None
    assert jerk_limit(irb120, 0.25, 0.0) is None and jerk_limit(irb120, 0.0, 0.1) is None
    assert ControllerConfig().accel_time == ACCEL_TIME and ControllerConfig().jerk_time == JERK_TIME


def test_default_jerk_time_is_the_peak_jerk_of_a_ramp_to_full_speed():
    """A sin² ramp to the speed limit at the acceleration limit jerks at exactly a_max / JERK_TIME."""
    v, a = 1.0, 1.0 / ACCEL_TIME  # a unit joint: speed limit 1, acceleration limit 1 / ACCEL_TIME
    p = plan_profile(v / 4, a / 4)  # a 4-unit move: room to cruise
    assert p.tc > 0
    tau = np.linspace(0.0, p.ta, 200_001)
    _, _, sdd = evaluate_profile(p, tau)
    peak_jerk = np.abs(_jerk(sdd, tau[1])).max() * 4
    assert peak_jerk == pytest.approx(a / JERK_TIME, rel=1e-4)
    # so the jerk limit does not stretch a full-speed ramp: same profile with and without it
    assert plan_profile(v / 4, a / 4, a / JERK_TIME / 4) == p


@pytest.mark.parametrize(("v", "a", "j"), [(2.0, 5.0, 20.0), (0.5, 100.0, 50.0), (10.0, 3.0, 1e9)])
def test_profile_keeps_speed_acceleration_and_jerk(v, a, j):
    p = plan_profile(v, a, j)
    tau = np.linspace(0.0, p.duration, 200_001)
    s, sd, sdd = evaluate_profile(p, tau)
    assert s[-1] == pytest.approx(1.0, abs=1e-12) and sd[-1] == pytest.approx(0.0, abs=1e-12)
    assert sd.max() <= v * (1 + 1e-12) and np.abs(sdd).max() <= a * (1 + 1e-9)
    assert np.abs(_jerk(sdd, tau[1])).max() <= j * (1 + 1e-6)
    # and it is the fastest such profile: one of the three bounds is reached
    reached = (sd.max() / v, np.abs(sdd).max() / a, np.abs(_jerk(sdd, tau[1])).max() / j)
    assert max(reached) == pytest.approx(1.0, rel=1e-3)


def test_emulated_moves_stay_within_the_jerk_limit(irb120):
    """Short and slow moves (which would reach the acceleration limit in a short ramp) included."""
    moves = draw_moves(irb120, 30, rng=np.random.default_rng(2))
    config = ControllerConfig()
    jmax = jerk_limit(irb120, config.accel_time, config.jerk_time)
    dt = 0.0005
    for speed in ("v100", "v1000"):
        program = [Move(m.target, speed, "fine") for m in moves]
        plan = plan_moves(irb120, irb120.home, program, config)
        _, _, qdd = evaluate_plan(plan, np.arange(0, plan.end_time, dt))
        assert np.all(np.abs(_jerk(qdd, dt)) <= jmax * (1 + 1e-6))
        # without the jerk limit the same program jerks harder, in less time
        loose = plan_moves(irb120, irb120.home, program, ControllerConfig(jerk_time=0))
        _, _, qdd = evaluate_plan(loose, np.arange(0, loose.end_time, dt))
        assert (np.abs(_jerk(qdd, dt)) / jmax).max() > 1.1
        assert loose.end_time < plan.end_time


def test_controller_config_refuses_a_negative_jerk_time():
    with pytest.raises(InvalidInput, match="jerk_time must be ≥ 0"):
        ControllerConfig(jerk_time=-0.1)
