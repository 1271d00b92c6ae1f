import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.optimize import PENALTY, TrajectoryProblem, limit_violation, path_features, physics_energy
from joulepath.trajectory import minimum_jerk

Q0 = np.radians([-60, 10, -30, 40, 20, 0])
QF = np.radians([70, 30, 10, -50, -40, 90])


@pytest.fixture(scope="module")
def problem(irb120):
    return TrajectoryProblem(robot=irb120, q_start=Q0, q_end=QF, duration=1.5)


def test_zero_chromosome_is_the_default_path(problem, irb120):
    traj = problem.trajectory(np.zeros(36))
    default = minimum_jerk(Q0, QF, 1.5)
    np.testing.assert_allclose(traj.q[0], default.q, atol=1e-12)
    f = problem.evaluate(np.zeros((1, 36)))
    e, _ = physics_energy(irb120, default)
    np.testing.assert_allclose(f, e)


def test_evaluate_population_in_one_call(problem, rng):
    X = rng.uniform(-2, 2, size=(20, 36))
    F = problem.evaluate(X)
    assert F.shape == (20,) and np.all(np.isfinite(F))
    np.testing.assert_allclose(F[3], problem.evaluate(X[3:4])[0])


def test_limit_violation_is_penalized(problem, irb120):
    X = np.zeros((2, 36))
    X[1, 6:12] = 10.0  # a 2 rad bulge on joint 2 drives it past its +110 deg limit
    traj = problem.trajectory(X)
    viol = limit_violation(irb120, traj)
    assert viol.total[0] == 0 and viol.total[1] > 0
    F = problem.evaluate(X)
    assert F[1] > F[0] + PENALTY * 0.9 * viol.total[1]


def test_path_features_match_kinematics(irb120):
    traj = minimum_jerk(np.stack([Q0, QF]), np.stack([QF, Q0]), 1.0)
    cols = ("q1", "dq1", "x", "y", "z", "qw", "dx", "ddq3", "dt")
    rows = path_features(irb120, traj, cols)
    assert rows.shape == (2 * 41, len(cols))
    pose = irb120.fk(traj.q)
    np.testing.assert_allclose(rows[:, 2].reshape(2, 41), pose.position_m[..., 0])
    np.testing.assert_allclose(rows[:, -1], 0.025)
    # TCP speed by central differences, as ingestion computes it
    vx = np.gradient(pose.position_m[0, :, 0], 0.025)
    np.testing.assert_allclose(rows[1:40, 6], vx[1:40], atol=1e-12)


def test_problem_validation(irb120):
    with pytest.raises(InvalidInput, match="fitness 'surrogate' needs 1 model"):
        TrajectoryProblem(robot=irb120, q_start=Q0, q_end=QF, duration=1.0, fitness="surrogate")
    with pytest.raises(InvalidInput, match="parametrization must be one of"):
        TrajectoryProblem(robot=irb120, q_start=Q0, q_end=QF, duration=1.0, parametrization="spline")


def test_cmaes_fine_grid_penalty_agrees_with_limit_violation(irb120):
    """CMA-ES's fast fine-grid check equals limit_violation on the same 10x grid, violations included."""
    from joulepath.optimize._problem import limit_violation
    from joulepath.optimize._run import ACCEL_TIME, acceleration_limit
    from joulepath.optimize._search import SearchTask, _FineKinematics
    from joulepath.optimize._verify import FINE_FACTOR
    from joulepath.trajectory import SplineBasis
    from joulepath.units import SAMPLE_PERIOD

    q0, qf, T = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0]), np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5]), 1.6
    amax = acceleration_limit(irb120, ACCEL_TIME)
    task = SearchTask(irb120, q0, qf, T, amax, (), (), SAMPLE_PERIOD)
    basis = SplineBasis(T, knot_spacing=0.2)
    scales = np.array([0.01, 0.3, 2.0])[:, None, None]  # three shapes, from gentle to wild
    C = scales * np.random.default_rng(4).standard_normal((3, basis.n_free, 6))
    fast = _FineKinematics(task, basis)(C)
    fine = basis.trajectory(C, q0, qf, dt=SAMPLE_PERIOD / FINE_FACTOR)
    slow = limit_violation(irb120, fine, None, acceleration_limit=amax).total
    assert fast[0] < fast[-1] and fast[-1] > 0.1  # small shapes pass, large ones break limits
    np.testing.assert_allclose(fast, slow, rtol=1e-12, atol=1e-12)
    # with the jerk limit: the same agreement, and the jerk adds to the penalty
    from joulepath.optimize import JERK_TIME, jerk_limit

    jmax = jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    jerky = SearchTask(irb120, q0, qf, T, amax, (), (), SAMPLE_PERIOD, jerk_limit=jmax)
    fast_j = _FineKinematics(jerky, basis)(C)
    slow_j = limit_violation(irb120, fine, None, acceleration_limit=amax, jerk_limit=jmax).total
    np.testing.assert_allclose(fast_j, slow_j, rtol=1e-12, atol=1e-12)
    assert np.all(fast_j >= fast) and fast_j[-1] > fast[-1]


def test_jerk_penalty_of_the_evolutionary_fitness_is_measured_on_the_fine_grid(irb120):
    """The GA's chromosomes are penalized for a jerk the samples' differences average away."""
    from joulepath.optimize import ACCEL_TIME, FINE_FACTOR, JERK_TIME, acceleration_limit, jerk_limit

    amax, jmax = acceleration_limit(irb120, ACCEL_TIME), jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    plain = TrajectoryProblem(robot=irb120, q_start=Q0, q_end=QF, duration=1.5, acceleration_limit=amax)
    jerky = TrajectoryProblem(
        robot=irb120, q_start=Q0, q_end=QF, duration=1.5, acceleration_limit=amax, jerk_limit=jmax
    )
    X = np.random.default_rng(7).uniform(-5, 5, (40, plain.n_var))  # half the GA's box
    f_plain, f_jerk = plain.evaluate(X), jerky.evaluate(X)
    assert np.all(f_jerk >= f_plain - 1e-9)
    fine = jerky.trajectory(X, dt=jerky.dt / FINE_FACTOR)
    samples = jerky.trajectory(X)
    jerk_fine = (
        limit_violation(irb120, fine, None, jerk_limit=jmax).speed - limit_violation(irb120, fine).speed
    )
    jerk_samples = (
        limit_violation(irb120, samples, None, jerk_limit=jmax).speed - limit_violation(irb120, samples).speed
    )
    # fine-grid excesses include the samples' (the samples are points of the fine grid)
    np.testing.assert_array_less(f_plain + PENALTY * jerk_fine * (1 - 1e-9) - 1e-9, f_jerk)
    assert np.any(jerk_fine > jerk_samples + 1e-6)  # a jerk the samples alone would miss
