"""Re-timing a MoveL along its fixed line: invariants and agreement with the controller and TOPP-RA."""

from __future__ import annotations

import importlib.util
import sys
from dataclasses import dataclass

import numpy as np
import pytest

from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.errors import InvalidInput
from joulepath.kinematics._ik import solve_ik
from joulepath.optimize import (
    check_limits,
    controller_profile,
    retime_on_path,
    shortest_on_path,
    tcp_velocity,
)
from joulepath.optimize._retime import _Limits, _problem, _timing
from joulepath.optimize._verify import energy_on_samples
from joulepath.sim import ControllerConfig, SpeedData, Step, acceleration_limit, jerk_limit
from joulepath.sim._timing import PlannedMove, SegmentPath, fastest_profile, segment_path, standalone
from joulepath.trajectory import quintic_hermite

needs_toppra = pytest.mark.skipif(
    importlib.util.find_spec("toppra") is None, reason="toppra (the motion extra) is not installed"
)

TOOL = np.eye(4)
TOOL[:3, 3] = (0.0, 0.0, 0.1)  # a 100 mm tool along the flange's z


@dataclass(frozen=True)
class Line:
    step: Step
    path: SegmentPath
    p0: np.ndarray
    p1: np.ndarray
    v_tcp: float  # m/s


def _tcp_position(robot, q):
    pose = robot.fk(q)
    return pose.position_m + np.einsum("...ij,j->...i", pose.rotation, TOOL[:3, 3])


def _make_line(robot, q0, offset_m, v_tcp_mm_s):
    """A MoveL from ``q0`` by ``offset_m`` (base frame), orientation kept, as the program reader builds it."""
    q0 = np.asarray(q0, dtype=float)
    flange = robot.fk(q0)
    target = np.eye(4)
    target[:3, :3] = flange.rotation @ TOOL[:3, :3]
    target[:3, 3] = _tcp_position(robot, q0) + np.asarray(offset_m)
    lo, hi = robot.joint_ranges()
    q1 = solve_ik(robot.chain, target @ np.linalg.inv(TOOL), None, lower=lo, upper=hi, near=q0)
    assert q1 is not None
    step = Step(
        kind="move",
        line=1,
        label="MoveL",
        statement=None,
        q=q1,
        linear=True,
        speed=SpeedData(v_tcp_mm_s, 500.0, 5000.0, 1000.0),
        tcp=TOOL,
        robot=robot,
    )
    path = segment_path(step, q0, "test")
    return Line(step, path, _tcp_position(robot, q0), _tcp_position(robot, q1), v_tcp_mm_s / 1000.0)


@pytest.fixture(scope="module")
def lines(irb120):
    return {
        "fast": _make_line(irb120, [0.2, 0.3, 0.1, 0.3, 0.5, 0.2], [0.0, -0.25, -0.1], 1000.0),
        "slow": _make_line(irb120, [-0.3, 0.1, 0.3, -0.2, 0.7, 0.0], [0.15, 0.2, 0.05], 200.0),
    }


@pytest.fixture(scope="module")
def limits(irb120):
    return acceleration_limit(irb120, 0.25), jerk_limit(irb120, 0.25, 0.125)


def _controller(line, duration, jerk_time):
    """The controller's own move at ``duration`` (\\T), by the cycle's timing code."""
    config = ControllerConfig(jerk_time=jerk_time)
    fastest = fastest_profile(line.step, line.path, config)
    if duration is None:
        return fastest.duration, None
    step = Step(**{**{f: getattr(line.step, f) for f in Step.__dataclass_fields__}, "time_s": duration})
    profile = fastest_profile(step, line.path, config)
    return fastest.duration, standalone(PlannedMove(0, step, line.path, profile, 0.0, True))


@pytest.fixture(scope="module")
def fast_retimed(irb120, lines, limits):
    line = lines["fast"]
    shortest, _ = _controller(line, None, 0.125)
    duration = 1.2 * shortest
    kwargs = dict(acceleration_limit=limits[0], jerk_limit=limits[1], tcp_speed_limit=line.v_tcp, tcp=TOOL)
    return duration, retime_on_path(irb120, line.path, duration, **kwargs)


def test_retime_on_path_stays_on_the_line(irb120, lines, fast_retimed):
    line = lines["fast"]
    _, r = fast_retimed
    q, _, _ = line.path.at(r.s)
    np.testing.assert_allclose(r.fine.q, q, atol=1e-9, rtol=0)
    p = _tcp_position(irb120, r.fine.q)
    u = (line.p1 - line.p0) / np.linalg.norm(line.p1 - line.p0)
    off = (p - line.p0) - np.outer((p - line.p0) @ u, u)
    assert np.linalg.norm(off, axis=1).max() < 1e-4  # 0.1 mm
    np.testing.assert_allclose(p[[0, -1]], [line.p0, line.p1], atol=1e-6)


def test_retime_on_path_rest_to_rest_and_exact_duration(fast_retimed):
    duration, r = fast_retimed
    assert r.duration == duration
    assert r.fine.t[-1] == pytest.approx(duration, abs=1e-12)
    assert r.samples.t[-1] == pytest.approx(duration, abs=1e-12)
    assert r.fine.dt <= 0.0025 + 1e-12 and r.samples.dt <= 0.025 + 1e-12
    assert r.s[0] == pytest.approx(0.0, abs=1e-12) and r.s[-1] == pytest.approx(1.0, abs=1e-12)
    assert np.all(np.diff(r.s) >= -1e-12)
    for tr in (r.fine, r.samples):
        np.testing.assert_allclose(tr.qd[[0, -1]], 0.0, atol=1e-9)
        np.testing.assert_allclose(tr.qdd[[0, -1]], 0.0, atol=1e-7)


def test_retime_on_path_beats_the_controller_and_holds_the_limits(irb120, lines, limits, fast_retimed):
    line = lines["fast"]
    duration, r = fast_retimed
    _, reference = _controller(line, duration, 0.125)
    e_ref = energy_on_samples(irb120, reference, friction=NOMINAL_FRICTION)
    assert r.energy_J <= e_ref * (1 + 1e-9)
    assert r.energy_J == pytest.approx(energy_on_samples(irb120, r.fine, friction=NOMINAL_FRICTION))
    assert r.feasible and not r.limit_excess
    report = check_limits(
        irb120, r.fine, friction=NOMINAL_FRICTION, acceleration_limit=limits[0], jerk_limit=limits[1]
    )
    assert report.ok, [w.describe() for w in report.worst]


def test_retime_on_path_respects_the_tcp_speed(irb120, lines, limits):
    line = lines["slow"]  # 200 mm/s: the TCP speed, not the joints, bounds this move
    shortest, _ = _controller(line, None, 0.0)
    r = retime_on_path(
        irb120, line.path, shortest, acceleration_limit=limits[0], tcp_speed_limit=line.v_tcp, tcp=TOOL
    )
    assert r.feasible, r.limit_excess
    p = _tcp_position(irb120, r.fine.q)
    chord = np.linalg.norm(np.diff(p, axis=0), axis=1) / r.fine.dt  # FK differences, not the Jacobian
    assert chord.max() <= line.v_tcp * (1 + 1e-6)
    assert chord.max() >= 0.9 * line.v_tcp  # the bound is the one that binds
    jac_speed = np.linalg.norm(tcp_velocity(irb120, r.fine.q, r.fine.qd, TOOL), axis=1)
    np.testing.assert_allclose(jac_speed[1:-1], 0.5 * (chord[1:] + chord[:-1]), atol=2e-3)


@needs_toppra
def test_shortest_on_path_is_at_most_the_controllers_and_reachable(irb120, lines, limits):
    for line in lines.values():
        controller, _ = _controller(line, None, 0.0)
        kwargs = dict(acceleration_limit=limits[0], tcp_speed_limit=line.v_tcp, tcp=TOOL)
        fastest = shortest_on_path(irb120, line.path, **kwargs)
        assert fastest <= controller * (1 + 1e-6)
        assert controller_profile(irb120, line.path, **kwargs).duration == pytest.approx(controller)
        r = retime_on_path(irb120, line.path, 1.05 * fastest, **kwargs)
        assert r.feasible, r.limit_excess


@needs_toppra
def test_shortest_on_path_accepts_a_plain_callable(irb120, lines, limits):
    line = lines["fast"]
    a = shortest_on_path(irb120, line.path, acceleration_limit=limits[0])
    b = shortest_on_path(irb120, lambda s: line.path.at(s), acceleration_limit=limits[0])
    assert a == b


@needs_toppra
def test_retime_on_path_energy_does_not_grow_with_duration(irb120, lines, limits):
    line = lines["fast"]
    kwargs = dict(acceleration_limit=limits[0], tcp_speed_limit=line.v_tcp, tcp=TOOL)
    fastest = shortest_on_path(irb120, line.path, **kwargs)
    energies = [
        retime_on_path(irb120, line.path, k * fastest, **kwargs).energy_J for k in (1.05, 1.3, 1.6, 2.0)
    ]
    assert all(b <= a * 1.01 for a, b in zip(energies, energies[1:], strict=False)), energies


def test_retime_on_path_is_deterministic_and_takes_a_callable(irb120, lines, limits):
    line = lines["slow"]
    a = retime_on_path(irb120, line.path, 1.5, acceleration_limit=limits[0])
    b = retime_on_path(irb120, lambda s: line.path.at(s), 1.5, acceleration_limit=limits[0])
    assert a.energy_J == b.energy_J
    np.testing.assert_array_equal(a.fine.q, b.fine.q)


@needs_toppra
def test_shortest_on_path_with_a_jerk_limit_is_feasible_and_tight(irb120, lines, limits):
    line = lines["slow"]
    kwargs = dict(acceleration_limit=limits[0], jerk_limit=limits[1], tcp_speed_limit=line.v_tcp, tcp=TOOL)
    bound = shortest_on_path(
        irb120, line.path, acceleration_limit=limits[0], tcp_speed_limit=line.v_tcp, tcp=TOOL
    )
    fastest = shortest_on_path(irb120, line.path, **kwargs)
    assert fastest >= bound
    assert retime_on_path(irb120, line.path, fastest, **kwargs).feasible
    if fastest > bound * 1.01:
        assert not retime_on_path(irb120, line.path, 0.98 * fastest, **kwargs).feasible


@pytest.mark.parametrize("measure", ["thesis", "electrical"])
def test_search_gradients_match_finite_differences(irb120, lines, limits, measure):
    line = lines["fast"]
    duration = 0.8
    timing = _timing(duration, True, True)
    t = np.linspace(0.0, duration, 81)
    limits_ = _Limits(NOMINAL_FRICTION, limits[0], limits[1], line.v_tcp, TOOL, measure, irb120.drivetrain)
    problem = _problem(irb120, line.path.at, timing, t, limits_)
    x = np.sort(np.random.default_rng(3).uniform(0.05, 0.95, timing.n_free))
    h = 1e-6
    _, grad = problem.energy(x)
    _, jac = problem.constraints(x)
    fd_e = np.empty_like(x)
    fd_g = np.empty((jac.shape[0], x.size))
    for i in range(x.size):
        step = np.zeros_like(x)
        step[i] = h
        fd_e[i] = (problem.energy(x + step)[0] - problem.energy(x - step)[0]) / (2 * h)
        fd_g[:, i] = (problem.constraints(x + step)[0] - problem.constraints(x - step)[0]) / (2 * h)
    np.testing.assert_allclose(grad, fd_e, rtol=1e-4, atol=1e-6 * np.abs(fd_e).max())
    np.testing.assert_allclose(jac, fd_g, rtol=1e-4, atol=1e-6 * np.abs(fd_g).max())


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"duration": 0.0}, "duration must be a positive"),
        ({"acceleration_limit": np.ones(5)}, "acceleration_limit must be 6 positive"),
        ({"jerk_limit": -np.ones(6)}, "jerk_limit must be 6 positive"),
        ({"tcp_speed_limit": 0.0}, "tcp_speed_limit must be positive"),
        ({"path": 3}, "path must have .at"),
    ],
)
def test_retime_on_path_refuses_bad_input(irb120, lines, limits, change, match):
    kwargs = {"path": lines["fast"].path, "duration": 1.0, "acceleration_limit": limits[0], **change}
    with pytest.raises(InvalidInput, match=match):
        retime_on_path(irb120, **kwargs)


def test_shortest_on_path_without_toppra_names_the_extra(irb120, lines, limits, monkeypatch):
    monkeypatch.setitem(sys.modules, "toppra", None)
    with pytest.raises(ImportError, match=r"joulepath\[motion\]"):
        shortest_on_path(irb120, lines["fast"].path, acceleration_limit=limits[0])


def test_retime_on_path_free_end_keeps_the_path_and_its_start_at_rest(irb120, lines, limits):
    line = lines["fast"]
    r = retime_on_path(irb120, line.path, 0.8, acceleration_limit=limits[0], end_at_rest=False)
    assert r.s[-1] == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(r.fine.qd[0], 0.0, atol=1e-9)
    assert r.energy_J <= r.start_energy_J


def test_retime_on_path_minimizes_the_measure_it_is_given(irb120, lines, limits):
    """Re-timed on the electrical measure, a MoveL spends no more at the cabinet than the same line
    re-timed on the thesis' metric, measured electrically (and the reverse on the thesis' metric)."""
    line = lines["slow"]
    kwargs = dict(acceleration_limit=limits[0], tcp_speed_limit=line.v_tcp, tcp=TOOL)
    duration = 1.3 * shortest_on_path(irb120, line.path, **kwargs) if _has_toppra() else 2.0
    by = {
        m: retime_on_path(irb120, line.path, duration, energy_measure=m, **kwargs)
        for m in ("thesis", "electrical")
    }
    assert all(r.feasible for r in by.values())
    on = {
        (m, k): energy_on_samples(irb120, r.fine, friction=NOMINAL_FRICTION, measure=k)
        for m, r in by.items()
        for k in ("thesis", "electrical")
    }
    assert by["electrical"].energy_J == pytest.approx(on[("electrical", "electrical")])
    assert on[("electrical", "electrical")] <= on[("thesis", "electrical")] * 1.002
    assert on[("thesis", "thesis")] <= on[("electrical", "thesis")] * 1.002
    assert by["electrical"].energy_J <= by["electrical"].start_energy_J * (1 + 1e-9)


def test_retime_on_path_refuses_a_measure_without_its_data(tmp_path, lines, limits):
    import shutil

    import joulepath
    from joulepath.description import preset_path

    urdf = tmp_path / "arm.urdf"  # the IRB 120 without its drives file beside it
    shutil.copy(preset_path("irb120", fmt="urdf"), urdf)
    bare = joulepath.load_robot(str(urdf))
    with pytest.raises(InvalidInput, match="electrical energy needs drive data"):
        retime_on_path(
            bare, lines["slow"].path, 2.0, acceleration_limit=limits[0], energy_measure="electrical"
        )


def _has_toppra() -> bool:
    return importlib.util.find_spec("toppra") is not None


def _as_motion_path(line, duration, jerk_time):
    """The controller's move along ``line`` at ``duration`` as a joint path ``q(s)``, ``s = t / T``
    (a path that is itself a motion of this duration, as a cycle's segment is)."""
    _, ref = _controller(line, duration, jerk_time)
    T = float(ref.t[-1])
    poly = quintic_hermite(ref.t / T, ref.q, ref.qd * T, ref.qdd * T * T)
    d1, d2 = poly.derivative(1), poly.derivative(2)
    return T, lambda s: (poly(s), d1(s), d2(s))


def test_identity_start_keeps_the_ends_and_never_loses_to_its_start(irb120, lines, limits):
    """From a motion's own timing: the same path, the same duration, position, speed and acceleration at
    both ends as the motion's, every limit held and the energy at most the motion's own."""
    line = lines["fast"]
    shortest, _ = _controller(line, None, 0.125)
    T, path = _as_motion_path(line, 1.3 * shortest, 0.125)
    r = retime_on_path(
        irb120, path, T, acceleration_limit=limits[0], jerk_limit=limits[1], tcp=TOOL, start="identity"
    )
    assert r.feasible, r.limit_excess
    assert r.energy_J <= r.start_energy_J
    q, q1, q2 = path(np.array([0.0, 1.0]))
    np.testing.assert_allclose(r.fine.q[[0, -1]], q, atol=1e-9)
    np.testing.assert_allclose(r.fine.qd[[0, -1]], q1 / T, atol=1e-7)
    np.testing.assert_allclose(r.fine.qdd[[0, -1]], q2 / T**2, atol=1e-5)
    qs, _, _ = path(r.s)
    np.testing.assert_allclose(r.fine.q, qs, atol=1e-12)  # on the path at every sample
    # the identity itself is the motion: its energy is the controller move's, on the same grid
    _, ref = _controller(line, 1.3 * shortest, 0.125)
    assert r.start_energy_J == pytest.approx(
        energy_on_samples(irb120, ref, friction=NOMINAL_FRICTION), rel=2e-3
    )


def test_a_bound_per_point_holds_where_it_is_given(irb120, lines, limits):
    """A TCP speed bound per path point, tight over the middle half of the path only: held there, and
    a constant function gives the same timing as the same number."""
    line = lines["slow"]
    shortest, _ = _controller(line, None, 0.0)
    T, path = _as_motion_path(line, 1.2 * shortest, 0.0)
    cap = 0.8 * line.v_tcp

    def bound(s):
        return np.where((s > 0.25) & (s < 0.75), cap, 1e3)

    kwargs = dict(acceleration_limit=limits[0], tcp=TOOL, start="identity")
    r = retime_on_path(irb120, path, T, tcp_speed_limit=bound, **kwargs)
    speed = np.linalg.norm(tcp_velocity(irb120, r.fine.q, r.fine.qd, TOOL), axis=1)
    mid = (r.s > 0.25) & (r.s < 0.75)
    assert r.feasible, (
        r.limit_excess
    )  # the start breaks the cap (its cruise is v_tcp / 1.2); the search mends it
    assert speed[mid].max() <= cap * (1 + 1e-6)
    assert speed.max() > cap  # and the cap binds only where it is given
    same = [
        retime_on_path(irb120, path, T, tcp_speed_limit=v, **kwargs)
        for v in (line.v_tcp, lambda s: np.full(s.shape, line.v_tcp))
    ]
    np.testing.assert_allclose(same[0].fine.q, same[1].fine.q, atol=1e-9)
    assert same[0].energy_J == pytest.approx(same[1].energy_J, rel=1e-9)


def test_identity_timing_gradients_with_a_bound_per_point_match_finite_differences(irb120, lines, limits):
    from joulepath.optimize._retime import _identity_timing

    line = lines["fast"]
    duration = 0.8
    timing = _identity_timing(duration, 12)
    t = np.linspace(0.0, duration, 81)
    bound = lambda s: line.v_tcp * (1.0 + 0.5 * s**2)  # noqa: E731  (smooth, so that its slope counts)
    limits_ = _Limits(NOMINAL_FRICTION, limits[0], limits[1], bound, TOOL, "thesis", irb120.drivetrain)
    problem = _problem(irb120, line.path.at, timing, t, limits_)
    x = np.sort(np.random.default_rng(4).uniform(timing.lo_values[-1], timing.hi_values[0], timing.n_free))
    h = 1e-6
    _, jac = problem.constraints(x)
    fd_g = np.empty((jac.shape[0], x.size))
    for i in range(x.size):
        step = np.zeros_like(x)
        step[i] = h
        fd_g[:, i] = (problem.constraints(x + step)[0] - problem.constraints(x - step)[0]) / (2 * h)
    np.testing.assert_allclose(jac, fd_g, rtol=1e-4, atol=1e-6 * np.abs(fd_g).max())
    # the identity's own control points give s = t / T exactly
    s, sd, _ = timing.evaluate(_identity_free(timing), t)
    np.testing.assert_allclose(s, t / duration, atol=1e-12)
    np.testing.assert_allclose(sd, 1.0 / duration, atol=1e-9)


def _identity_free(timing):
    greville = np.array([timing.knots[k + 1 : k + 6].mean() for k in range(timing.n_ctrl)]) / timing.knots[-1]
    return greville[timing.fixed_lo : timing.n_ctrl - timing.fixed_hi]


def test_retime_on_path_refuses_an_unknown_start_and_a_bound_per_point_from_the_controller(
    irb120, lines, limits
):
    kwargs = dict(acceleration_limit=limits[0])
    with pytest.raises(InvalidInput, match="start must be one of"):
        retime_on_path(irb120, lines["fast"].path, 1.0, start="zero", **kwargs)
    with pytest.raises(InvalidInput, match="needs start='identity'"):
        retime_on_path(irb120, lines["fast"].path, 1.0, tcp_speed_limit=lambda s: s + 1.0, **kwargs)


def test_identity_start_with_free_ends_keeps_a_path_at_rest_at_rest(irb120, lines, limits):
    """A motion from rest to rest re-timed with its ends free (only ``s`` kept there): still at rest at
    both ends, on the same path, within the limits, never above its own timing's energy."""
    line = lines["fast"]
    shortest, _ = _controller(line, None, 0.125)
    T, path = _as_motion_path(line, 1.3 * shortest, 0.125)
    kwargs = dict(acceleration_limit=limits[0], jerk_limit=limits[1], tcp=TOOL, start="identity")
    free = retime_on_path(irb120, path, T, free_ends=(True, True), **kwargs)
    assert free.feasible, free.limit_excess
    assert free.energy_J <= free.start_energy_J
    np.testing.assert_allclose(free.fine.qd[[0, -1]], 0.0, atol=1e-9)
    np.testing.assert_allclose(free.fine.q, path(free.s)[0], atol=1e-12)
    assert free.s[0] == pytest.approx(0.0, abs=1e-12) and free.s[-1] == pytest.approx(1.0, abs=1e-12)


def test_a_deadline_already_past_keeps_what_the_search_has(irb120, lines, limits):
    """Past its deadline the search stops at its iterate: the result is still measured, and never
    worse than the start it would otherwise improve (the motion's own timing, feasible)."""
    import time

    line = lines["fast"]
    shortest, _ = _controller(line, None, 0.125)
    T, path = _as_motion_path(line, 1.3 * shortest, 0.125)
    kwargs = dict(acceleration_limit=limits[0], jerk_limit=limits[1], tcp=TOOL, start="identity")
    late = retime_on_path(irb120, path, T, deadline=time.perf_counter() - 1.0, **kwargs)
    assert late.feasible and late.energy_J <= late.start_energy_J
    full = retime_on_path(irb120, path, T, **kwargs)
    assert full.energy_J <= late.energy_J * (1 + 1e-9)
