"""The default (gradient) search: exact gradients, limits between samples, reproducibility, feasibility."""

import json

import numpy as np
import pytest
from scipy.interpolate import BSpline

from joulepath.dynamics import NOMINAL_FRICTION, inverse_dynamics_derivatives
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.optimize import (
    ACCEL_TIME,
    JERK_TIME,
    OptimizeConfig,
    SplineProblem,
    acceleration_limit,
    check_default_feasible,
    check_limits,
    jerk_limit,
    optimize_move,
    random_tasks,
    shortest_feasible_duration,
    write_run,
)
from joulepath.optimize._verify import energy_on_samples
from joulepath.trajectory import SplineBasis, minimum_jerk

Q0 = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
QF = np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])


def test_rnea_derivatives_match_finite_differences(irb120, rng):
    q, qd, qdd = rng.standard_normal((3, 4, 6))
    d = inverse_dynamics_derivatives(irb120, q, qd, qdd, friction=NOMINAL_FRICTION)
    np.testing.assert_allclose(
        d.tau, irb120.inverse_dynamics(q, qd, qdd, friction=NOMINAL_FRICTION), atol=1e-12
    )
    h = 1e-6
    for which, jac in ((0, d.dq), (1, d.dqd), (2, d.dqdd)):
        for j in range(6):
            args_p = [q.copy(), qd.copy(), qdd.copy()]
            args_m = [q.copy(), qd.copy(), qdd.copy()]
            args_p[which][:, j] += h
            args_m[which][:, j] -= h
            fd = (
                irb120.inverse_dynamics(*args_p, friction=NOMINAL_FRICTION)
                - irb120.inverse_dynamics(*args_m, friction=NOMINAL_FRICTION)
            ) / (2 * h)
            np.testing.assert_allclose(jac[:, :, j], fd, rtol=1e-5, atol=1e-5)


@pytest.mark.parametrize(("eps", "every"), [(0.5, 1), (0.01, 1), (0.01, 2)])
def test_energy_gradient_matches_finite_differences(irb120, rng, eps, every):
    basis = SplineBasis(1.0, knot_spacing=0.1)
    problem = SplineProblem(irb120, Q0, QF, 1.0, NOMINAL_FRICTION, basis, energy_every=every)
    x = rng.standard_normal(problem.n_var) * 0.05
    _, g = problem.smooth_energy(x, eps)
    h = 1e-6
    for i in rng.choice(problem.n_var, size=12, replace=False):
        e = np.zeros_like(x)
        e[i] = h
        fd = (problem.smooth_energy(x + e, eps)[0] - problem.smooth_energy(x - e, eps)[0]) / (2 * h)
        assert g[i] == pytest.approx(fd, rel=1e-5, abs=1e-8)


def test_energy_on_a_finer_grid_is_the_energy_of_the_path_sampled_there(irb120, rng):
    """``energy_every``: the objective is the path's energy on a grid that many times finer than the
    samples, evaluated here from the fine path's own samples; it tends to the fine grid's energy."""
    basis = SplineBasis(1.0, knot_spacing=0.1)
    x = rng.standard_normal(basis.n_free * 6) * 0.05
    fine_problem = SplineProblem(irb120, Q0, QF, 1.0, NOMINAL_FRICTION, basis)
    fine = fine_problem.path(x, fine=True)  # every 2.5 ms (check_factor 10)
    errors = []
    for every in (1, 2, 5):
        problem = SplineProblem(irb120, Q0, QF, 1.0, NOMINAL_FRICTION, basis, energy_every=every)
        k = 10 // every
        sub = type(fine)(t=fine.t[::k], q=fine.q[::k], qd=fine.qd[::k], qdd=fine.qdd[::k])
        e = problem.true_energy(x)
        assert e == pytest.approx(energy_on_samples(irb120, sub, friction=NOMINAL_FRICTION), rel=1e-12)
        assert problem.smooth_energy(x, 1e-9)[0] == pytest.approx(e, rel=1e-6)
        errors.append(abs(e - energy_on_samples(irb120, fine, friction=NOMINAL_FRICTION)))
    assert errors[2] <= errors[0]
    with pytest.raises(InvalidInput, match="energy_every must divide"):
        SplineProblem(irb120, Q0, QF, 1.0, NOMINAL_FRICTION, basis, energy_every=3)


def test_zero_coefficients_are_the_default_and_every_path_rests_at_both_ends(irb120, rng):
    basis = SplineBasis(1.6, knot_spacing=0.1)
    zero = basis.trajectory(np.zeros((basis.n_free, 6)), Q0, QF)
    np.testing.assert_allclose(zero.q, minimum_jerk(Q0, QF, 1.6).q, atol=1e-12)
    tr = basis.trajectory(rng.standard_normal((basis.n_free, 6)), Q0, QF)
    np.testing.assert_allclose(tr.q[[0, -1]], [Q0, QF], atol=1e-12)
    np.testing.assert_allclose(tr.qd[[0, -1]], 0.0, atol=1e-10)
    np.testing.assert_allclose(tr.qdd[[0, -1]], 0.0, atol=1e-8)


def test_control_point_hull_bounds_the_path_everywhere(rng):
    basis = SplineBasis(1.2, knot_spacing=0.1)
    C = rng.standard_normal((basis.n_free, 6))
    Mq, Mv, Ma = basis.control_maps
    Pq, Pv, Pa = basis.minimum_jerk_control(Q0, QF)
    t = np.linspace(0, 1.2, 2001)
    for deg, (M, P), trim in ((5, (Mq, Pq), 0), (4, (Mv, Pv), 1), (3, (Ma, Pa), 2)):
        ctrl = P + M @ C
        knots = basis.knots[trim : basis.knots.size - trim]
        values = BSpline(knots, ctrl, deg)(t)
        assert np.all(values <= ctrl.max(axis=0) + 1e-9) and np.all(values >= ctrl.min(axis=0) - 1e-9)
        expect = basis.trajectory(C, Q0, QF, dt=0.0006).q if deg == 5 else None
        if expect is not None:
            np.testing.assert_allclose(BSpline(knots, ctrl, deg)(np.arange(2001) * 0.0006), expect, atol=1e-9)


@pytest.fixture(scope="module")
def fixed(irb120):
    return optimize_move(irb120, Q0, QF, 1.6, OptimizeConfig(seed=1))


def test_default_search_saves_energy_within_every_limit(fixed, irb120):
    s = fixed.summary
    assert s.algorithm == "gradient" and s.representation == "bspline"
    assert s.limits_ok and s.saved_pct > 5.0
    assert abs(s.energy_optimized_fine_J - s.energy_optimized_J) < 0.01 * s.energy_optimized_J
    np.testing.assert_allclose(fixed.optimized.q[[0, -1]], [Q0, QF], atol=1e-10)


def test_limits_hold_on_a_ten_times_finer_grid(fixed, irb120):
    """Evaluated independently: the spline itself at 10x the sample rate, by SciPy."""
    spline = _result_spline(fixed)
    t = np.arange(641) * 0.0025
    q, qd, qdd = spline(t), spline.derivative()(t), spline.derivative(2)(t)
    np.testing.assert_allclose(q[::10], fixed.optimized.q, atol=1e-9)
    lo, hi = irb120.joint_ranges()
    amax = acceleration_limit(irb120, OptimizeConfig().accel_time)
    assert np.all(q <= hi + 1e-9) and np.all(q >= lo - 1e-9)
    assert np.all(np.abs(qd) <= irb120.velocity_limit * (1 + 1e-7))
    assert np.all(np.abs(qdd) <= amax * (1 + 1e-7))


def test_same_seed_same_result(irb120):
    cfg = OptimizeConfig(seed=4, knot_spacing=0.1, n_starts=2)
    a = optimize_move(irb120, Q0, QF, 1.0, cfg)
    b = optimize_move(irb120, Q0, QF, 1.0, cfg)
    np.testing.assert_array_equal(a.parameters, b.parameters)
    np.testing.assert_array_equal(a.optimized.q, b.optimized.q)


def _result_spline(result):
    c = result.parameters
    for spacing in (OptimizeConfig().knot_spacing, 2 * OptimizeConfig().knot_spacing):
        basis = SplineBasis(1.6, knot_spacing=spacing)
        if basis.n_free == c.shape[0]:
            ctrl = basis.minimum_jerk_control(Q0, QF)[0] + basis.control_maps[0] @ c
            return BSpline(basis.knots, ctrl, 5)
    raise AssertionError("coefficients fit no basis")


def test_path_csv_derivatives_are_those_of_its_positions(fixed, irb120, tmp_path):
    """path.csv's qd and qdd are the exact derivatives of the curve through its q (SciPy, independently)."""
    write_run(fixed, irb120, tmp_path)
    data = np.loadtxt(tmp_path / "path.csv", delimiter=",", skiprows=1)
    t, q, qd, qdd = data[:, 0], data[:, 1:7], data[:, 7:13], data[:, 13:19]
    spline = _result_spline(fixed)
    np.testing.assert_allclose(q, spline(t), atol=1e-8)
    np.testing.assert_allclose(qd, spline.derivative()(t), atol=1e-7)
    np.testing.assert_allclose(qdd, spline.derivative(2)(t), atol=1e-6)
    # and, to the sampling error, integrating qd gives q back
    q_int = q[0] + np.concatenate(
        [[np.zeros(6)], np.cumsum((qd[1:] + qd[:-1]) / 2 * np.diff(t)[:, None], axis=0)]
    )
    assert np.abs(q_int - q).max() < 2e-3
    summary = json.loads((tmp_path / "result.json").read_text())
    assert summary["algorithm"] == "gradient" and "executed_saved_pct" in summary
    # planned for sampled interfaces (follow="samples"), path.mod is written only if the emulation follows it
    assert (summary["rapid"] == "path.mod") == summary["executed_matches_plan"]


def test_corridor_keeps_the_tcp_near_the_default(irb120):
    free = optimize_move(irb120, Q0, QF, 1.0, OptimizeConfig(knot_spacing=0.1, n_starts=1))
    bound = 0.4 * free.summary.max_tcp_deviation_mm
    held = optimize_move(
        irb120, Q0, QF, 1.0, OptimizeConfig(knot_spacing=0.1, n_starts=1, max_deviation_mm=bound)
    )
    assert held.summary.limits_ok
    tcp = irb120.fk(held.optimized.q).position_m
    ref = irb120.fk(held.default.q).position_m
    assert 1000 * np.linalg.norm(tcp - ref, axis=1).max() <= bound
    assert held.summary.max_tcp_deviation_mm <= bound
    assert held.summary.energy_optimized_J <= held.summary.energy_default_J


def test_infeasible_default_is_refused_with_the_shortest_feasible_duration(irb120):
    with pytest.raises(
        LimitViolation, match=r"infeasible task: .*joint \d (speed|acceleration|jerk).*shortest duration"
    ):
        optimize_move(irb120, Q0, QF, 0.5, OptimizeConfig())
    T = shortest_feasible_duration(
        irb120,
        Q0,
        QF,
        dt=0.025,
        friction=NOMINAL_FRICTION,
        acceleration_limit=acceleration_limit(irb120, ACCEL_TIME),
        jerk_limit=jerk_limit(irb120, ACCEL_TIME, JERK_TIME),
    )
    assert T is not None
    check_default_feasible(irb120, Q0, QF, T)
    with pytest.raises(LimitViolation):
        check_default_feasible(irb120, Q0, QF, round(T - 0.025, 3))


def test_random_tasks_are_feasible(irb120):
    amax = acceleration_limit(irb120, ACCEL_TIME)
    jmax = jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    tasks = random_tasks(irb120, 20, seed=3, durations=(0.5, 1.5))
    for q0, qf, T in tasks:
        fine = minimum_jerk(q0, qf, T, dt=0.0025)
        report = check_limits(
            irb120, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=jmax
        )
        assert report.ok


QW = np.array([-0.2, 0.1, 0.1, -0.3, 0.2, -0.2])


def test_waypoint_rows_agree_with_the_path_and_the_start_meets_them(irb120, rng):
    """The equality rows are the path's distance from the waypoint at its time (evaluated
    independently from the path samples); the start path meets them and rests at both ends."""
    basis = SplineBasis(1.2, knot_spacing=0.1)
    problem = SplineProblem(irb120, Q0, QF, 1.2, NOMINAL_FRICTION, basis, waypoints=((0.5, QW),))
    k = int(round(0.5 / basis.dt))
    for x in (problem.origin, problem.origin + rng.standard_normal(problem.n_var) * 0.05):
        residual = problem.way_A @ x - problem.way_b
        np.testing.assert_allclose(residual, problem.path(x).q[k] - QW, atol=1e-12)
    start = problem.path(problem.origin)
    np.testing.assert_allclose(start.q[k], QW, atol=1e-12)
    np.testing.assert_allclose(start.q[[0, -1]], [Q0, QF], atol=1e-12)
    np.testing.assert_allclose(start.qd[[0, -1]], 0.0, atol=1e-10)
    assert problem.waypoint_error(problem.origin) < 1e-12
    assert problem.violation(problem.origin + 0.01) > 0.0  # missing the waypoint counts as a violation


def test_a_move_through_a_waypoint_passes_it_at_speed_within_every_limit(irb120):
    from joulepath.optimize._gradient import GradientSettings, solve_move

    amax = acceleration_limit(irb120, 0.25)
    res, problem = solve_move(
        irb120,
        Q0,
        QF,
        1.2,
        friction=NOMINAL_FRICTION,
        settings=GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), coarse_factor=1),
        rng=np.random.default_rng(0),
        acceleration_limit=amax,
        waypoints=((0.5, QW),),
    )
    assert res.feasible
    k = int(round(0.5 / problem.dt))
    np.testing.assert_allclose(res.path.q[k], QW, atol=2e-6)
    assert np.abs(res.path.qd[k]).max() > 0.1  # it does not stop there
    fine = problem.path(res.coefficients.ravel(), fine=True)
    assert check_limits(irb120, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax).ok
    assert res.energy_J <= problem.true_energy(problem.origin) + 1e-9
    with pytest.raises(Exception, match="waypoint times"):
        SplineProblem(
            irb120, Q0, QF, 1.2, NOMINAL_FRICTION, SplineBasis(1.2, knot_spacing=0.1), waypoints=((1.2, QW),)
        )


# ------------------------------------------------------------------ jerk limits
def _independent_fine(basis, C, q0, qf, T, dt):
    """q̈ and the jerk on a grid, from SciPy's B-spline of the control points and the quintic's own formula."""
    t = np.arange(round(T / dt) + 1) * dt
    ctrl = basis.minimum_jerk_control(q0, qf)[0] + basis.control_maps[0] @ C
    spline = BSpline(basis.knots, ctrl, basis.degree)
    return t, spline.derivative(2)(t), spline.derivative(3)


def test_jerk_rows_are_the_differences_of_the_fine_grid_accelerations(irb120, rng):
    """Rows against an independent evaluation: SciPy's spline, differences of its q̈ on the fine grid."""
    T = 1.2
    basis = SplineBasis(T, knot_spacing=0.1)
    jmax = jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    problem = SplineProblem(irb120, Q0, QF, T, NOMINAL_FRICTION, basis, jerk_limit=jmax)
    x = rng.standard_normal(problem.n_var) * 0.05
    t, qdd, third = _independent_fine(basis, problem.coefficients(x), Q0, QF, T, 0.0025)
    jerk = np.diff(qdd, axis=0) / 0.0025
    K = jerk.shape[0]
    idx = np.arange(2 * K * 6)
    A, b = problem._jerk_rows(idx)
    slack = (A @ x + b).reshape(2 * K, 6)
    lim = jmax * (1 - 1e-6)
    np.testing.assert_allclose(slack[:K], lim - jerk, rtol=0, atol=1e-6 * jmax.max())
    np.testing.assert_allclose(slack[K:], lim + jerk, rtol=0, atol=1e-6 * jmax.max())
    np.testing.assert_allclose(problem.jerk_slack(x), slack, atol=1e-9 * jmax.max())
    # the mean jerk over each 2.5 ms step agrees with the analytic third derivative at its midpoint
    mid = third(0.5 * (t[1:] + t[:-1]))
    assert np.abs(jerk - mid).max() <= 1e-3 * np.abs(mid).max()


@pytest.fixture(scope="module")
def fixed_no_jerk(irb120):
    return optimize_move(irb120, Q0, QF, 1.6, OptimizeConfig(seed=1, jerk_time=0))


def test_fixed_task_keeps_the_jerk_limit_on_the_ten_times_finer_grid(fixed, irb120):
    """The default (jerk-limited) result, evaluated independently by SciPy on the 10x grid."""
    s = fixed.summary
    jmax = jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    assert s.jerk_limit_rad_s3 == pytest.approx(tuple(jmax))
    spline = _result_spline(fixed)
    t = np.arange(641) * 0.0025
    jerk = np.diff(spline.derivative(2)(t), axis=0) / 0.0025
    assert np.all(np.abs(jerk) <= jmax * (1 + 1e-7))
    assert s.max_jerk_rad_s3 == pytest.approx(np.abs(jerk).max(), rel=1e-6)
    # pointwise, the spline's own jerk: between grid points within a sliver of the limit (the
    # checked quantity is each 2.5 ms step's mean jerk); in the first and last half step, which no
    # step's midpoint is nearer than 1.25 ms to, up to a few % above it (measured: 4.3 % at t = T)
    t_dense = np.linspace(0, 1.6, 64001)
    dense = np.abs(spline.derivative(3)(t_dense)) / jmax
    inner = (t_dense >= 0.0025) & (t_dense <= 1.6 - 0.0025)
    assert dense[inner].max() <= 1.005
    assert dense[~inner].max() <= 1.06


def test_jerk_limit_costs_saving_but_keeps_some(fixed, fixed_no_jerk, irb120):
    """Adding a constraint cannot improve the optimum: checked from the other side, where it holds for
    any local search too: the jerk-limited optimum is feasible without the jerk limit, so a search
    without it started there ends no higher (to solver tolerance)."""
    with_jerk, without = fixed.summary, fixed_no_jerk.summary
    assert without.jerk_limit_rad_s3 is None and without.limits_ok and with_jerk.limits_ok
    assert 0 < with_jerk.saved_pct < without.saved_pct
    assert without.max_jerk_rad_s3 > 2 * max(with_jerk.jerk_limit_rad_s3)  # what the limit removes
    from joulepath.optimize import GradientSettings, optimize_spline

    start = fixed.parameters  # on the fine knots, or the coarse ones when those won
    spacing = next(
        k * OptimizeConfig().knot_spacing
        for k in (1, 2)
        if SplineBasis(1.6, knot_spacing=k * OptimizeConfig().knot_spacing).n_free == start.shape[0]
    )
    basis = SplineBasis(1.6, knot_spacing=spacing)
    relaxed = SplineProblem(
        irb120,
        Q0,
        QF,
        1.6,
        irb120.friction,
        basis,
        acceleration_limit=acceleration_limit(irb120, ACCEL_TIME),
    )
    assert relaxed.violation(start.ravel()) == 0.0
    settings = GradientSettings(continuation=GradientSettings().continuation[-1:])
    again = optimize_spline(relaxed, settings, rng=np.random.default_rng(0), initial=start)
    assert again.feasible
    assert again.energy_J <= with_jerk.energy_optimized_J * (1 + 1e-6)


def test_jerk_time_zero_is_the_search_without_a_jerk_limit(fixed_no_jerk, irb120):
    """``jerk_time=0`` runs exactly the search as it was before jerk limits (no jerk argument at all)."""
    from joulepath.optimize import MOVE_SEARCH, GradientSettings
    from joulepath.optimize._gradient import solve_move

    res, _ = solve_move(
        irb120,
        Q0,
        QF,
        1.6,
        friction=irb120.friction,
        settings=GradientSettings(knot_spacing=OptimizeConfig().knot_spacing, check_factor=10, **MOVE_SEARCH),
        rng=np.random.default_rng(1),
        acceleration_limit=acceleration_limit(irb120, ACCEL_TIME),
    )
    np.testing.assert_array_equal(res.path.q, fixed_no_jerk.optimized.q)


def test_infeasible_jerk_alone_is_refused_with_the_shortest_duration(irb120):
    """A move within its speed and acceleration limits but not its jerk limit: the message names jerk."""
    q0, qf = np.zeros(6), np.array([0.0, 0.0, 0.0, 0.0, 0.0, 2.0])
    T = 0.95  # 60 |Δq| / T³ = 140 rad/s³ > 98 rad/s³, joint 6's jerk limit at jerk_time 0.3 s
    check_default_feasible(irb120, q0, qf, T, jerk_time=0)
    with pytest.raises(LimitViolation, match=r"joint 6 jerk .* deg/s³ .*shortest duration .* is (\d\.\d+) s"):
        check_default_feasible(irb120, q0, qf, T, jerk_time=0.3)
    shortest = shortest_feasible_duration(
        irb120,
        q0,
        qf,
        dt=0.025,
        friction=irb120.friction,
        acceleration_limit=acceleration_limit(irb120, ACCEL_TIME),
        jerk_limit=jerk_limit(irb120, ACCEL_TIME, 0.3),
    )
    assert shortest is not None and shortest > T
    check_default_feasible(irb120, q0, qf, shortest, jerk_time=0.3)
    with pytest.raises(LimitViolation, match="jerk"):
        check_default_feasible(irb120, q0, qf, round(shortest - 0.025, 3), jerk_time=0.3)


@pytest.mark.parametrize("measure", ["mechanical", "electrical"])
def test_energy_gradient_matches_finite_differences_on_every_measure(irb120, rng, measure):
    """The pluggable energy term: the measure's smoothed power (gears, copper, drives, the bleeder's
    max(·, 0)) chained through the dynamics; its gradient against central differences."""
    basis = SplineBasis(1.0, knot_spacing=0.1)
    problem = SplineProblem(irb120, Q0, QF, 1.0, NOMINAL_FRICTION, basis, energy_measure=measure)
    x = rng.standard_normal(problem.n_var) * 0.05
    eps = 0.05
    _, g = problem.smooth_energy(x, eps)
    h = 1e-6
    for i in rng.choice(problem.n_var, size=10, replace=False):
        e = np.zeros_like(x)
        e[i] = h
        fd = (problem.smooth_energy(x + e, eps)[0] - problem.smooth_energy(x - e, eps)[0]) / (2 * h)
        assert g[i] == pytest.approx(fd, rel=1e-4, abs=1e-6)
    # smoothing tends to the measure's exact motion energy
    exact = problem.true_energy(x)
    assert problem.smooth_energy(x, 1e-4)[0] == pytest.approx(exact, rel=1e-3)


def test_electrical_search_saves_electrical_energy_and_reports_every_measure(irb120):
    res = optimize_move(
        irb120,
        Q0,
        QF,
        1.6,
        OptimizeConfig(energy="electrical", knot_spacing=0.1, accel_time=0.0),
    )
    s = res.summary
    assert s.energy_measure == "electrical" and s.limits_ok
    electrical = s.measure("electrical")
    assert electrical is not None and electrical.stage == "bus"
    # the headline is the meter-level figure: the standby over the move is part of both energies
    assert s.energy_default_J == pytest.approx(electrical.default_J)
    assert electrical.standby_J == pytest.approx(irb120.drives.standby_W * 1.6)
    assert s.energy_optimized_J < s.energy_default_J
    assert {m.measure for m in s.energies} == {"thesis", "mechanical", "electrical"}
    thesis = s.measure("thesis")
    assert thesis is not None and thesis.stage == "joint" and thesis.standby_J == 0.0
    assert "irb120.drives.toml" in electrical.source
    out = s.to_json()
    assert set(out["energies"]) == {"thesis", "mechanical", "electrical"}


# ------------------------------------------------------------------ long moves
def test_near_limit_keeps_every_bump_of_a_long_move_within_the_band(rng):
    """Over the row cap only each bump's deepest samples enter the solve: a subset of the samples
    within the band, and every contiguous run of them keeps its deepest sample."""
    from joulepath.optimize._gradient import _near_limit

    t = np.linspace(0.0, 6.0, 2401)
    slack = np.column_stack([1.0 + (0.9 + 0.2 * rng.random()) * np.sin((2 + p) * t + p) for p in range(6)])
    within = np.full(6, 0.5)
    near = slack < within
    every = _near_limit(slack, within, cap=10**9)
    np.testing.assert_array_equal(every, np.flatnonzero(near.ravel()))
    thin = _near_limit(slack, within, cap=10)
    assert 0 < thin.size < every.size / 4
    assert np.isin(thin, every).all()
    kept = np.zeros(slack.size, bool)
    kept[thin] = True
    kept = kept.reshape(slack.shape)
    for j in range(6):  # each run of samples within the band keeps its deepest one
        edges = np.flatnonzero(np.diff(np.r_[0, near[:, j].astype(int), 0]))
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            assert kept[a + int(np.argmin(slack[a:b, j])), j]


def test_a_long_move_gets_at_most_max_knots_and_stays_within_every_limit(irb120):
    from joulepath.optimize._gradient import GradientSettings, solve_move

    amax = acceleration_limit(irb120, 0.25)
    settings = GradientSettings(knot_spacing=0.05, continuation=(0.3, 0.03), max_knots=20)
    assert settings.spacing_for(1.0) == pytest.approx(0.05)
    assert settings.spacing_for(4.0) == pytest.approx(0.2)
    res, problem = solve_move(
        irb120, Q0, QF, 4.0, friction=NOMINAL_FRICTION, settings=settings,
        rng=np.random.default_rng(0), acceleration_limit=amax,
    )  # fmt: skip
    assert problem.basis.knot_spacing == pytest.approx(0.2)
    assert problem.thin_rows and settings.is_long(4.0) and not settings.is_long(1.0)
    assert res.feasible
    fine = problem.path(res.coefficients.ravel(), fine=True)
    assert check_limits(irb120, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax).ok
    with pytest.raises(InvalidInput, match="max_knots"):
        GradientSettings(max_knots=2)


def test_a_deadline_stops_the_search_where_it_is(irb120):
    """Past its deadline the search takes no further iteration, round, start or refinement (the
    cycle's --max-time holds inside a solve); without one the same search iterates on."""
    import time

    from joulepath.optimize._gradient import GradientSettings, solve_move

    amax = acceleration_limit(irb120, 0.25)
    settings = GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), n_starts=3)
    args = dict(friction=NOMINAL_FRICTION, settings=settings, acceleration_limit=amax)
    free, _ = solve_move(irb120, Q0, QF, 1.5, rng=np.random.default_rng(0), **args)
    late, _ = solve_move(
        irb120, Q0, QF, 1.5, rng=np.random.default_rng(0), deadline=time.perf_counter(), **args
    )
    assert free.n_iterations > 5
    assert late.n_iterations <= 1
    assert len(late.starts) == 1


def test_an_initial_path_on_other_knots_is_not_used(irb120):
    """A start whose size is not the search's (a search its deadline stopped on its coarse knots) is left
    aside: the search runs as it would without one, to the same result."""
    from joulepath.optimize import GradientSettings
    from joulepath.optimize._gradient import solve_move

    settings = GradientSettings(knot_spacing=0.1, coarse_factor=1, max_rounds=2)

    def run(initial):
        res, problem = solve_move(
            irb120,
            Q0,
            QF,
            1.6,
            friction=irb120.friction,
            settings=settings,
            rng=np.random.default_rng(1),
            initial=initial,
        )
        return res, problem

    plain, problem = run(None)
    other = np.zeros(problem.m * problem.n + 7)  # a path on other knots
    again, _ = run(other)
    np.testing.assert_array_equal(again.path.q, plain.path.q)
