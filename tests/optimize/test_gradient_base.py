"""The gradient search's shape added to a given motion (its ends kept) and waypoints within a box."""

import numpy as np
import pytest

import joulepath
from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.errors import InvalidInput
from joulepath.optimize import GradientSettings
from joulepath.optimize._gradient import SplineProblem, solve_move
from joulepath.sim import acceleration_limit
from joulepath.trajectory import SplineBasis, Trajectory

FAST = GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), max_iter=60, coarse_factor=1)
Q0 = np.array([-0.5, 0.2, 0.2, 0.0, 0.7, 0.0])
Q1 = np.array([0.6, 0.4, -0.1, 0.3, 0.9, 0.5])


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


def moving_base(T: float) -> Trajectory:
    """A motion that starts and ends moving: a cubic in time with non-zero end speeds."""
    t = np.linspace(0.0, T, int(round(T / 0.0025)) + 1)
    s = t / T
    q = Q0 + np.outer(s + 0.3 * s * (1 - s), Q1 - Q0)
    qd = np.outer((1 + 0.3 * (1 - 2 * s)) / T, Q1 - Q0)
    qdd = np.outer(np.full_like(s, -0.6 / T**2), Q1 - Q0)
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd)


def test_a_given_base_keeps_its_end_states_for_every_shape(robot):
    T = 1.0
    base = moving_base(T)
    p = SplineProblem(
        robot, base.q[0], base.q[-1], T, NOMINAL_FRICTION, SplineBasis(T, knot_spacing=0.1), base=base
    )
    np.testing.assert_allclose(p.path(p.origin, fine=True).q, base.q, atol=1e-12)
    x = np.random.default_rng(1).normal(size=p.n_var)
    path = p.path(x, fine=True)
    on_samples = p.path(x)
    for a, b in ((path.q, base.q), (path.qd, base.qd), (path.qdd, base.qdd)):
        np.testing.assert_allclose(a[[0, -1]], b[[0, -1]], atol=1e-9)
    # the bounds (base given) agree with the path's ranges and speeds on the samples
    A, b = p.hull
    slack = A @ x + b
    lo, hi = robot.joint_ranges()
    sq = on_samples
    inside = bool(np.all((sq.q > lo) & (sq.q < hi)) and np.all(np.abs(sq.qd) < p.vmax))
    assert inside == bool(slack.min() >= 0)


def test_a_base_on_another_grid_is_refused(robot):
    T = 1.0
    base = moving_base(0.5)
    with pytest.raises(InvalidInput, match="fine grid"):
        SplineProblem(robot, Q0, Q1, T, NOMINAL_FRICTION, SplineBasis(T, knot_spacing=0.1), base=base)


def test_the_search_from_a_base_saves_energy_and_keeps_the_ends(robot):
    T = 1.2
    base = moving_base(T)
    amax = acceleration_limit(robot, 0.25)
    res, p = solve_move(
        robot,
        base.q[0],
        base.q[-1],
        T,
        friction=NOMINAL_FRICTION,
        settings=FAST,
        rng=np.random.default_rng(0),
        acceleration_limit=amax,
        base=base,
    )
    assert res.feasible
    assert p.true_energy(res.coefficients.ravel()) <= p.true_energy(p.origin) + 1e-9


def test_a_waypoint_box_is_kept_and_never_costs_more_than_exact(robot):
    T = 1.6
    mid = 0.5 * (Q0 + Q1) + np.array([0.0, 0.2, 0.0, 0.0, 0.0, 0.0])
    amax = acceleration_limit(robot, 0.25)
    out = {}
    for r in (0.0, 0.05):
        res, p = solve_move(
            robot,
            Q0,
            Q1,
            T,
            friction=NOMINAL_FRICTION,
            settings=FAST,
            rng=np.random.default_rng(0),
            acceleration_limit=amax,
            waypoints=((0.8, mid),),
            waypoint_radius=(np.full(6, r),),
        )
        x = res.coefficients.ravel()
        assert res.feasible and p.waypoint_error(x) <= 1e-6
        q_mid = p.path(x, fine=True).q[int(round(0.8 / 0.0025))]
        assert np.abs(q_mid - mid).max() <= r + 1e-6
        out[r] = p.true_energy(x)
    assert out[0.05] <= out[0.0] * 1.01
    # a negative radius is refused in one line
    with pytest.raises(InvalidInput, match="waypoint_radius"):
        SplineProblem(
            robot,
            Q0,
            Q1,
            T,
            NOMINAL_FRICTION,
            SplineBasis(T, knot_spacing=0.1),
            waypoints=((0.8, mid),),
            waypoint_radius=(np.full(6, -1.0),),
        )
