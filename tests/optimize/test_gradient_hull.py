"""The gradient search's hull rows for the rate limits and its preconditioned solve (issue 36)."""

import numpy as np
import pytest
from scipy.interpolate import BSpline

from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.errors import InvalidInput
from joulepath.optimize import (
    ACCEL_TIME,
    JERK_TIME,
    MOVE_SEARCH,
    GradientSettings,
    SplineProblem,
    acceleration_limit,
    check_limits,
    jerk_limit,
)
from joulepath.optimize._gradient import (
    _derivative_controls,
    _preconditioner,
    _rate_control_blocks,
    _refinement,
    smooth_energy_hessian,
    solve_move,
)
from joulepath.optimize._verify import energy_on_samples
from joulepath.trajectory import SplineBasis

Q0 = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
QF = np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])


@pytest.mark.parametrize("refine", [1, 2, 3])
def test_rate_control_points_are_those_of_the_paths_derivatives_and_bound_them(rng, refine):
    """Evaluated independently: SciPy's derivative of the whole path's spline (minimum-jerk move plus
    shape), against the control points of its 2nd and 3rd derivative on the refined knots."""
    basis = SplineBasis(1.2, knot_spacing=0.1)
    C = rng.standard_normal((basis.n_free, 6)) * 0.05
    n_ctrl = basis.knots.size - basis.degree - 1
    full = basis.minimum_jerk_control(Q0, QF)[0].copy()
    full[3 : n_ctrl - 3] += C
    path = BSpline(basis.knots, full, basis.degree)
    t = np.linspace(0.0, 1.2, 4001)
    for order, (M, P) in zip((2, 3), _rate_control_blocks(basis, Q0, QF, refine), strict=True):
        ctrl = P + M @ C
        values = path.derivative(order)(t)
        assert np.all(values <= ctrl.max(axis=0) + 1e-8) and np.all(values >= ctrl.min(axis=0) - 1e-8)
        # the same curve on the refined knots
        _, deg, knots = _derivative_controls(basis.knots, basis.degree, full, order)
        inner = np.unique(knots)
        fine = np.concatenate(
            [np.full(deg, inner[0]), np.linspace(inner[0], inner[-1], refine * (inner.size - 1) + 1)]
            + [np.full(deg, inner[-1])]
        )
        np.testing.assert_allclose(BSpline(fine, ctrl, deg)(t), values, atol=1e-7 * np.abs(values).max())


def test_refined_control_points_lie_closer_to_the_curve(rng):
    basis = SplineBasis(1.0, knot_spacing=0.1)
    C = rng.standard_normal((basis.n_free, 6)) * 0.05
    t = np.linspace(0.0, 1.0, 2001)
    n_ctrl = basis.knots.size - basis.degree - 1
    full = basis.minimum_jerk_control(Q0, QF)[0].copy()
    full[3 : n_ctrl - 3] += C
    jerk = np.abs(BSpline(basis.knots, full, basis.degree).derivative(3)(t)).max(axis=0)
    gaps = []
    for refine in (1, 2, 4):
        M, P = _rate_control_blocks(basis, Q0, QF, refine)[1]
        gaps.append(np.abs(P + M @ C).max(axis=0) - jerk)
    assert np.all(gaps[0] >= -1e-8)
    assert np.all(gaps[1] <= gaps[0] + 1e-8) and np.all(gaps[2] <= gaps[1] + 1e-8)
    assert gaps[2].sum() < 0.5 * gaps[0].sum()


def test_refinement_keeps_the_curve(rng):
    knots = np.concatenate([np.zeros(2), np.linspace(0, 1, 6), np.ones(2)])
    c = rng.standard_normal(knots.size - 3)
    R = _refinement(knots, 2, 3)
    t = np.linspace(0, 1, 501)
    fine_inner = np.linspace(0, 1, 16)
    fine = np.concatenate([np.zeros(2), fine_inner, np.ones(2)])
    np.testing.assert_allclose(BSpline(fine, R @ c, 2)(t), BSpline(knots, c, 2)(t), atol=1e-10)
    np.testing.assert_array_equal(_refinement(knots, 2, 1), np.eye(c.size))


def _problem(irb120, rate_rows="hull"):
    basis = SplineBasis(1.0, knot_spacing=0.1)
    return SplineProblem(
        irb120,
        Q0,
        QF,
        1.0,
        NOMINAL_FRICTION,
        basis,
        acceleration_limit=acceleration_limit(irb120, ACCEL_TIME),
        jerk_limit=jerk_limit(irb120, ACCEL_TIME, JERK_TIME),
        rate_rows=rate_rows,
    )


def test_hull_rows_hold_on_the_fine_grid_where_they_hold(irb120, rng):
    """A point that meets every hull row meets the acceleration and jerk rows of the fine grid."""
    problem = _problem(irb120)
    for _ in range(20):
        x = rng.standard_normal(problem.n_var) * 0.02
        if problem.hull_slack(x).min() >= 0.0:
            assert problem.accel_slack(x).min() >= 0.0 and problem.jerk_slack(x).min() >= 0.0


def test_preconditioned_rows_are_the_rows_in_the_new_coordinates(irb120, rng):
    problem = _problem(irb120)
    x0 = rng.standard_normal(problem.n_var) * 0.02
    W = rng.standard_normal((problem.n_var, problem.n_var)) * 0.1
    y = rng.standard_normal(problem.n_var) * 0.1
    active = {"hull": np.arange(problem.hull[0].shape[0])[:40], "tau": np.arange(0, 60, 7)}
    plain = problem.constraints(active)
    changed = problem.constraints(active, (x0, W))
    assert len(plain) == len(changed) == 2
    for a, b in zip(plain, changed, strict=True):
        np.testing.assert_allclose(b["fun"](y), a["fun"](x0 + W @ y), rtol=1e-10, atol=1e-9)
        np.testing.assert_allclose(b["jac"](y), a["jac"](x0 + W @ y) @ W, rtol=1e-10, atol=1e-9)


def test_energy_hessian_predicts_the_change_of_the_gradient(irb120, rng):
    problem = _problem(irb120)
    x = rng.standard_normal(problem.n_var) * 0.02
    eps = 0.05
    H = smooth_energy_hessian(problem, x, eps)
    np.testing.assert_allclose(H, H.T)
    d = rng.standard_normal(problem.n_var)
    d /= np.linalg.norm(d)
    h = 1e-4
    g_p, g_m = problem.smooth_energy(x + h * d, eps)[1], problem.smooth_energy(x - h * d, eps)[1]
    np.testing.assert_allclose((g_p - g_m) / (2 * h), H @ d, rtol=1e-3, atol=1e-3 * np.abs(H @ d).max())
    W = _preconditioner(problem, x, eps, 1.0, 1e-3)
    assert W is not None
    w = np.linalg.eigvalsh(W.T @ H @ W)
    assert w.max() == pytest.approx(1.0, rel=1e-6) and w.min() >= -1.0 - 1e-6
    assert _preconditioner(problem, x, eps, 1.0, 0.0) is None


def test_settings_refuse_an_unknown_row_kind_and_a_bad_preconditioner():
    with pytest.raises(InvalidInput, match="rate_rows must be one of hull, grid"):
        GradientSettings(rate_rows="dense")
    with pytest.raises(InvalidInput, match="precondition must be in"):
        GradientSettings(precondition=1.5)
    with pytest.raises(InvalidInput, match="hull_refine must be 1..8"):
        GradientSettings(hull_refine=0)
    with pytest.raises(InvalidInput, match=r"screen_band must be in \(0, 1\]"):
        GradientSettings(screen_band=0.0)


def test_default_search_reaches_the_search_before_within_every_limit(irb120):
    """The hull rows and the preconditioned solve against the fine-grid rows and the plain solve on a
    short move (half the fixed task's travel in 1.2 s): within every limit on the 10x grid, and at
    least 97 % of the saving of the search before (on the benchmark's tasks the two differ by a few
    per cent either way: BENCHMARKS.md)."""
    amax = acceleration_limit(irb120, ACCEL_TIME)
    jmax = jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    before = GradientSettings(rate_rows="grid", precondition=0.0, max_iter=200, ftol=1e-7)
    saved = {}
    for label, settings in (("default", GradientSettings(**MOVE_SEARCH)), ("before", before)):
        res, problem = solve_move(
            irb120,
            Q0,
            Q0 + 0.5 * (QF - Q0),
            1.2,
            friction=irb120.friction,
            settings=settings,
            rng=np.random.default_rng(0),
            acceleration_limit=amax,
            jerk_limit=jmax,
        )
        fine = problem.path(res.coefficients.ravel(), fine=True)
        report = check_limits(
            irb120, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=jmax
        )
        assert report.ok, label
        default = problem.path(np.zeros(problem.n_var), fine=True)
        e0 = energy_on_samples(irb120, default, friction=NOMINAL_FRICTION)
        saved[label] = e0 - energy_on_samples(irb120, fine, friction=NOMINAL_FRICTION)
    assert saved["before"] > 0.0
    assert saved["default"] >= 0.97 * saved["before"]


def test_effort_rows_are_evaluated_once_per_point(irb120, rng, monkeypatch):
    """SLSQP asks for a nonlinear row's value and gradient at the same point one after the other: one
    evaluation of the dynamics' derivatives serves both, the same numbers; a new point is evaluated."""
    problem = _problem(irb120)
    idx = np.arange(0, 60, 7)
    plain = problem._effort_rows
    calls: list[np.ndarray] = []

    def counted(x, idx):
        calls.append(np.array(x))
        return plain(x, idx)

    monkeypatch.setattr(problem, "_effort_rows", counted)
    x = rng.standard_normal(problem.n_var) * 0.02
    W = rng.standard_normal((problem.n_var, problem.n_var)) * 0.1
    for change, at in ((None, x), ((x, W), np.zeros(problem.n_var))):
        calls.clear()
        (row,) = problem.constraints({"tau": idx}, change)
        value, grad = row["fun"](at), row["jac"](at)
        x_at = at if change is None else x + W @ at
        assert len(calls) == 1
        want_value, want_grad = plain(x_at, idx)
        np.testing.assert_array_equal(value, want_value)
        np.testing.assert_array_equal(grad, want_grad if change is None else want_grad @ W)
        moved = at.copy()
        moved[3] += 1e-3  # a point changed in place is a new point
        row["jac"](moved)
        row["fun"](moved)
        assert len(calls) == 2
        x_moved = moved if change is None else x + W @ moved
        np.testing.assert_array_equal(row["fun"](moved), plain(x_moved, idx)[0])


def test_via_point_plan_searches_the_wide_knots(via_points_run):
    """The plan for RAPID via points (tests/conftest.py: the fixed task, ``follow="via-points"``) is
    a spline on knots ``VIA_KNOT_FACTOR`` times ``knot_spacing`` apart (or, at the coarse level, twice
    that), not on the 0.05 s knots of a streamed path."""
    from joulepath.optimize import OptimizeConfig
    from joulepath.optimize._search import VIA_KNOT_FACTOR, via_point_settings

    result, _ = via_points_run
    spacing = OptimizeConfig().knot_spacing
    assert via_point_settings(OptimizeConfig())["knot_spacing"] == VIA_KNOT_FACTOR * spacing > spacing
    T = result.summary.duration_s
    wide = {SplineBasis(T, knot_spacing=f * VIA_KNOT_FACTOR * spacing).n_free for f in (1, 2)}
    assert result.parameters.shape[0] in wide
    assert result.parameters.shape[0] != SplineBasis(T, knot_spacing=spacing).n_free


def test_pruned_stages_carry_fewer_rows_and_end_within_every_limit(irb120, monkeypatch):
    """``prune_stages``: a continuation stage that starts within every limit starts from the rows near
    its limits there, not from every row the earlier rounds gathered: its solves carry fewer rows in
    all (the first the same), and the search still ends within every limit on the 10x grid."""
    amax = acceleration_limit(irb120, ACCEL_TIME)
    rows_per_solve: dict[bool, list[int]] = {}
    seen: list[int] = []
    original = SplineProblem.constraints

    def counting(self, active, change=None):
        seen.append(sum(int(v.size) for v in active.values()))
        return original(self, active, change)

    monkeypatch.setattr(SplineProblem, "constraints", counting)
    for prune in (True, False):
        seen.clear()
        settings = GradientSettings(
            rate_rows="grid", precondition=0.0, coarse_factor=1, screen_band=0.1, prune_stages=prune
        )
        res, problem = solve_move(
            irb120,
            Q0,
            Q0 + 0.5 * (QF - Q0),
            1.2,
            friction=irb120.friction,
            settings=settings,
            rng=np.random.default_rng(0),
            acceleration_limit=amax,
        )
        fine = problem.path(res.coefficients.ravel(), fine=True)
        report = check_limits(irb120, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax)
        assert res.feasible and report.ok, prune
        rows_per_solve[prune] = list(seen)
    assert rows_per_solve[True][0] == rows_per_solve[False][0]
    assert sum(rows_per_solve[True]) < sum(rows_per_solve[False])
