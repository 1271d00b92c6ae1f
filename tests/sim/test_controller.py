"""The emulated controller: limits respected, boundary conditions, zones, timing, seeds."""

import numpy as np
import pytest

from joulepath.abb import SPEEDS
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.export import Move, draw_moves
from joulepath.sim import ControllerConfig, evaluate_plan, log_times, plan_moves
from joulepath.sim._profile import evaluate_profile, plan_profile, time_at_fraction

CFG = ControllerConfig()


def test_profile_reaches_one_at_rest_within_limits():
    for v, a in ((2.0, 5.0), (10.0, 3.0), (0.5, 100.0)):
        p = plan_profile(v, a)
        tau = np.linspace(0, p.duration, 20001)
        s, sd, sdd = evaluate_profile(p, tau)
        assert s[0] == 0.0 and s[-1] == pytest.approx(1.0, abs=1e-12)
        assert sd[0] == 0.0 and sd[-1] == pytest.approx(0.0, abs=1e-12)
        assert sd.max() <= v * (1 + 1e-12) and np.abs(sdd).max() <= a * (1 + 1e-9)
        np.testing.assert_allclose(np.gradient(s, tau)[1:-1], sd[1:-1], atol=2e-3 * sd.max())
        assert time_at_fraction(p, 0.5) == pytest.approx(p.duration / 2, abs=1e-9)


def test_fine_moves_stop_at_each_target(irb120):
    targets = [np.radians([30, 10, -20, 40, 30, 90]), np.radians([-20, 30, 10, -50, -40, -60])]
    moves = [Move(tuple(t), "v1000", "fine") for t in targets]
    plan = plan_moves(irb120, irb120.home, moves, CFG)
    seg0, seg1 = plan.segments
    assert seg1.t0 == pytest.approx(seg0.t_end + CFG.fine_dwell)
    q, qd, _ = evaluate_plan(plan, np.array([seg0.t_end, seg1.t_end, plan.end_time]))
    np.testing.assert_allclose(q[0], targets[0], atol=1e-12)
    np.testing.assert_allclose(q[1:], [targets[1], targets[1]], atol=1e-12)
    np.testing.assert_allclose(qd, 0.0, atol=1e-12)


def test_joint_speed_and_acceleration_limits_hold(irb120):
    moves = draw_moves(irb120, 30, rng=np.random.default_rng(2))
    plan = plan_moves(irb120, irb120.home, moves, CFG)
    t = np.arange(0, plan.end_time, 0.001)
    q, qd, qdd = evaluate_plan(plan, t)
    vmax = irb120.velocity_limit
    # overlapping (blended) moves may add up, but never beyond the limit by more than the blend share
    assert np.all(np.abs(qd) <= 1.5 * vmax + 1e-9)
    fine_only = plan_moves(irb120, irb120.home, [Move(m.target, m.speed, "fine") for m in moves], CFG)
    q, qd, qdd = evaluate_plan(fine_only, t)
    assert np.all(np.abs(qd) <= vmax * (1 + 1e-9))
    assert np.all(np.abs(qdd) <= vmax / CFG.accel_time * (1 + 1e-6))
    lo, hi = irb120.joint_ranges()
    assert np.all(q >= lo - 1e-9) and np.all(q <= hi + 1e-9)


def test_tcp_speed_bounds_the_duration(irb120):
    a, b = np.radians([0, 0, 0, 0, 30, 0]), np.radians([40, 20, -10, 0, 30, 0])
    durations = []
    for speed in ("v100", "v1000", "v7000"):
        plan = plan_moves(irb120, a, [Move(tuple(b), speed, "fine")], CFG)
        durations.append(plan.segments[0].profile.duration)
    assert durations[0] > durations[1] >= durations[2]
    seg = plan_moves(irb120, a, [Move(tuple(b), "v100", "fine")], CFG).segments[0]
    t = np.linspace(seg.t0, seg.t_end, 400)
    q, _, _ = evaluate_plan(plan_moves(irb120, a, [Move(tuple(b), "v100", "fine")], CFG), t)
    tcp = irb120.fk(q).position_mm
    speed = np.linalg.norm(np.diff(tcp, axis=0), axis=1) / np.diff(t)
    assert speed.max() <= SPEEDS["v100"] * 1.6  # joint interpolation: TCP speed varies along the path


def test_zones_blend_the_corner(irb120):
    a = np.radians([40, 10, 0, 0, 0, 0])
    b = np.radians([40, 10, 0, 0, 0, 90])
    fine = plan_moves(
        irb120, irb120.home, [Move(tuple(a), "v1000", "fine"), Move(tuple(b), "v1000", "fine")], CFG
    )
    blend = plan_moves(
        irb120, irb120.home, [Move(tuple(a), "v1000", "z200"), Move(tuple(b), "v1000", "fine")], CFG
    )
    assert blend.end_time < fine.end_time
    corner = blend.segments[0].t_end - 1e-3
    _, qd, _ = evaluate_plan(blend, np.array([corner]))
    assert np.abs(qd).max() > 0.05  # the arm does not stop at the corner


def test_plan_moves_refuses_targets_outside_the_ranges(irb120):
    with pytest.raises(LimitViolation, match=r"move 0: joint 2 target 120\.00 deg is outside"):
        plan_moves(
            irb120,
            irb120.home,
            [Move(tuple(np.radians([0, 120, 0, 0, 0, 0])), "v100", "fine")],
            CFG,
        )
    with pytest.raises(InvalidInput, match="unknown speeddata 'v42'"):
        plan_moves(irb120, irb120.home, [Move((0.1,) * 6, "v42", "fine")], CFG)


def test_log_times_jitter_and_seed():
    t = log_times(10.0, CFG, rng=np.random.default_rng(0))
    dt = np.diff(t)
    assert t[0] == 0 and t[-1] <= 10.0
    assert dt.min() >= CFG.sample_period and 0.025 < np.median(dt) < 0.028
    np.testing.assert_array_equal(t, log_times(10.0, CFG, rng=np.random.default_rng(0)))
    assert not np.array_equal(t[:50], log_times(10.0, CFG, rng=np.random.default_rng(1))[:50])


def test_controller_config_validation():
    with pytest.raises(InvalidInput, match="accel_time must be positive"):
        ControllerConfig(accel_time=0)
