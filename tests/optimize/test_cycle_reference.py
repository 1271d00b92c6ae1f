"""The cycle optimum (several legs in one IPOPT transcription) against independent solvers and invariants."""

import numpy as np
import pytest

pytest.importorskip("casadi")

from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.errors import InvalidInput  # noqa: E402
from joulepath.optimize import (  # noqa: E402
    ACCEL_TIME,
    JERK_TIME,
    CycleLeg,
    GradientSettings,
    acceleration_limit,
    check_limits,
    cycle_optimum,
    jerk_limit,
)
from joulepath.optimize._gradient import solve_move  # noqa: E402
from joulepath.optimize._reference import reference_optimum  # noqa: E402
from joulepath.optimize._verify import energy_on_samples  # noqa: E402

QA = np.array([0.2, -0.1, 0.1, 0.4, -0.3, 0.5])
QB = np.array([-0.3, 0.2, -0.1, -0.2, 0.3, -0.3])
QC = np.array([0.4, 0.3, 0.2, 0.2, -0.2, 0.3])
N = 8  # intervals per sub-leg: few, for speed; the reference gets the same count
TOL = 0.02  # relative energy tolerance between solvers and between nearby problems


@pytest.fixture(scope="module")
def limits(irb120):
    return acceleration_limit(irb120, ACCEL_TIME), jerk_limit(irb120, ACCEL_TIME, JERK_TIME)


@pytest.fixture(scope="module")
def solve(irb120, limits):
    cache = {}

    def run(legs, budget):
        key = (repr(legs), budget)
        if key not in cache:
            cache[key] = cycle_optimum(
                irb120, legs, budget, acceleration_limit=limits[0], jerk_limit=limits[1], intervals=N
            )
        return cache[key]

    return run


def _reference(robot, limits, q0, qf, duration):
    return reference_optimum(
        robot,
        q0,
        qf,
        duration,
        friction=NOMINAL_FRICTION,
        acceleration_limit=limits[0],
        jerk_limit=limits[1],
        dt=duration / N,
    )


def _verified(robot, limits, res):
    """Energy and limits of the result's paths, measured again here."""
    energy = sum(energy_on_samples(robot, p, friction=NOMINAL_FRICTION) for p in res.paths)
    ok = all(
        all(
            w.excess <= 1e-4
            for w in check_limits(
                robot, p, friction=NOMINAL_FRICTION, acceleration_limit=limits[0], jerk_limit=limits[1]
            ).worst
        )
        for p in res.paths
    )
    return energy, ok


def test_cycle_optimum_of_one_leg_agrees_with_the_reference_and_the_gradient_optimizer(irb120, limits, solve):
    T = 0.6
    res = solve((CycleLeg(QA, QB),), T)
    assert res.feasible, res.status
    assert sum(res.durations) <= T + 1e-6
    energy, ok = _verified(irb120, limits, res)
    assert ok and energy == pytest.approx(res.energy_J, rel=1e-9)
    for p in res.paths:  # from rest to rest at the targets
        np.testing.assert_allclose(p.q[[0, -1]], [QA, QB], atol=1e-6)
        np.testing.assert_allclose(p.qd[[0, -1]], 0.0, atol=1e-6)
    ref = _reference(irb120, limits, QA, QB, T)
    assert ref.status == "Solve_Succeeded"
    assert res.energy_J == pytest.approx(ref.energy_fine_J, rel=TOL)
    grad, problem = solve_move(
        irb120,
        QA,
        QB,
        T,
        friction=NOMINAL_FRICTION,
        settings=GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), coarse_factor=1),
        rng=np.random.default_rng(0),
        acceleration_limit=limits[0],
        jerk_limit=limits[1],
    )
    assert grad.feasible
    grad_fine = energy_on_samples(
        irb120, problem.path(grad.coefficients.ravel(), fine=True), friction=NOMINAL_FRICTION
    )
    assert res.energy_J <= grad_fine * (1 + TOL)


def test_cycle_optimum_of_two_legs_is_no_worse_than_the_legs_solved_apart(irb120, limits, solve):
    budget = 1.2
    res = solve((CycleLeg(QA, QB), CycleLeg(QB, QC)), budget)
    assert res.feasible, res.status
    assert sum(res.durations) <= budget + 1e-6
    assert res.energy_J == pytest.approx(sum(res.legs_energy_J))
    apart = (
        _reference(irb120, limits, QA, QB, budget / 2).energy_fine_J
        + _reference(irb120, limits, QB, QC, budget / 2).energy_fine_J
    )
    assert res.energy_J <= apart * (1 + TOL)


def test_cycle_optimum_passes_its_vias_and_a_larger_zone_never_costs_more(irb120, limits, solve):
    budget = 1.2
    energies = []
    for radius in (0.0, 0.05):
        res = solve((CycleLeg(QA, QC, via=(QB,), via_radius=(np.full(6, radius),)),), budget)
        assert res.feasible, res.status
        (path,) = res.paths
        ((t_via,),) = res.via_times_s
        assert 0 < t_via < res.durations[0]
        # the path at the passing time, from the fine sample before it (exact to jerk dt³/6)
        k = int(np.searchsorted(path.t, t_via, side="right") - 1)
        s = t_via - path.t[k]
        q_via = path.q[k] + s * path.qd[k] + s**2 / 2 * path.qdd[k]
        assert np.max(np.abs(q_via - QB)) <= radius + 1e-4
        energies.append(res.energy_J)
    assert energies[1] <= energies[0] * (1 + TOL)


def test_cycle_optimum_more_budget_never_costs_more(solve):
    tight = solve((CycleLeg(QA, QB),), 0.6)
    loose = solve((CycleLeg(QA, QB),), 0.8)
    assert tight.feasible and loose.feasible
    assert loose.energy_J <= tight.energy_J * (1 + TOL)


def test_cycle_optimum_below_the_shortest_duration_is_infeasible_not_an_error(irb120, limits):
    res = cycle_optimum(irb120, [CycleLeg(QA, QB)], 0.1, acceleration_limit=limits[0], jerk_limit=limits[1])
    assert not res.feasible and "below" in res.status


@pytest.mark.parametrize(
    ("legs", "budget", "match"),
    [
        ([CycleLeg(QA, QB)], -1.0, "budget must be a positive"),
        ([CycleLeg(QA[:5], QB)], 1.0, "must be a finite vector of 6 joint values"),
        ([CycleLeg(QA, QB, via=(QC[:3],))], 1.0, "via 0 must be a finite vector"),
        ([CycleLeg(QA, QB, via=(QC,), via_radius=(-1.0,))], 1.0, "via_radius 0 must be ≥ 0"),
        ([], 1.0, "legs is empty"),
    ],
)
def test_cycle_optimum_invalid_input(irb120, legs, budget, match):
    with pytest.raises(InvalidInput, match=match) as err:
        cycle_optimum(irb120, legs, budget)
    assert "\n" not in str(err.value)
