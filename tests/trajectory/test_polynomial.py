import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.trajectory import (
    GRID_HIGH,
    GRID_LOW,
    GRID_STEP,
    minimum_jerk,
    rest_to_rest,
    thesis_quintic,
)

PARAMETRIZATIONS = [rest_to_rest, thesis_quintic]


def grid_chromosomes(rng, n_pop):
    k = rng.integers(round(GRID_LOW / GRID_STEP), round(GRID_HIGH / GRID_STEP) + 1, size=(n_pop, 6, 6))
    return k * GRID_STEP


def test_grid_constants():
    assert (GRID_LOW, GRID_HIGH, GRID_STEP) == (-10.0, 10.0, 0.05)


def test_rest_to_rest_boundary_conditions_exact(rng):
    c = grid_chromosomes(rng, 50)
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    tr = rest_to_rest(c, q0, qf, 1.75)
    assert np.array_equal(tr.q[:, 0], np.broadcast_to(q0, (50, 6)))
    assert np.array_equal(tr.q[:, -1], np.broadcast_to(qf, (50, 6)))
    assert np.all(tr.qd[:, [0, -1]] == 0)
    assert np.all(tr.qdd[:, [0, -1]] == 0)
    assert tr.t[0] == 0 and tr.t[-1] == pytest.approx(1.75) and tr.dt == pytest.approx(0.025)


def test_thesis_quintic_boundary_positions_exact(rng):
    c = grid_chromosomes(rng, 50)
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    tr = thesis_quintic(c, q0, qf, 2.5)
    assert np.array_equal(tr.q[:, 0], np.broadcast_to(q0, (50, 6)))
    assert np.array_equal(tr.q[:, -1], np.broadcast_to(qf, (50, 6)))


@pytest.mark.parametrize("parametrization", PARAMETRIZATIONS)
@pytest.mark.parametrize("duration", [1.0, 3.0])
def test_derivatives_match_finite_differences(parametrization, duration, rng):
    c = grid_chromosomes(rng, 3)
    c[0, 2] = 0.0  # one degenerate joint for thesis_quintic
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    dt = 0.0005
    tr = parametrization(c, q0, qf, duration, dt=dt)
    qd_fd = np.gradient(tr.q, dt, axis=1)
    qdd_fd = np.gradient(tr.qd, dt, axis=1)
    scale_qd = np.abs(tr.qd).max() + 1.0
    scale_qdd = np.abs(tr.qdd).max() + 1.0
    np.testing.assert_allclose(qd_fd[:, 1:-1], tr.qd[:, 1:-1], atol=1e-5 * scale_qd)
    np.testing.assert_allclose(qdd_fd[:, 1:-1], tr.qdd[:, 1:-1], atol=1e-4 * scale_qdd)


@pytest.mark.parametrize("parametrization", PARAMETRIZATIONS)
def test_zero_chromosome_is_minimum_jerk(parametrization, rng):
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    tr = parametrization(np.zeros((6, 6)), q0, qf, 2.0)
    mj = minimum_jerk(q0, qf, 2.0)
    np.testing.assert_array_equal(tr.t, mj.t)
    for a, b in ((tr.q, mj.q), (tr.qd, mj.qd), (tr.qdd, mj.qdd)):
        np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-13)


def test_rest_to_rest_scale_gives_useful_bulges():
    c = np.zeros((6, 6))
    c[0, 0] = GRID_HIGH
    tr = rest_to_rest(c, np.zeros(6), np.zeros(6), 2.0)
    mid = tr.q.shape[0] // 2
    assert tr.q[mid, 0] == pytest.approx(1.0)
    np.testing.assert_array_equal(tr.q[:, 1:], 0.0)
    half = rest_to_rest(c, np.zeros(6), np.zeros(6), 2.0, scale=3.2)
    assert half.q[mid, 0] == pytest.approx(0.5)


def test_thesis_quintic_is_rescaled_polynomial(rng):
    # away from degeneracy the path is q0 + (p(t) - p(0)) (qf - q0) / (p(T) - p(0)), t in seconds
    c = grid_chromosomes(rng, 1)[0]
    c[:, 1] = 5.0  # strong linear term: far from degenerate
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    tr = thesis_quintic(c, q0, qf, 1.5)
    p = np.stack([np.polynomial.polynomial.polyval(tr.t, row) for row in c], axis=1)
    dp = np.stack(
        [np.polynomial.polynomial.polyval(tr.t, np.polynomial.polynomial.polyder(row)) for row in c], 1
    )
    ratio = (qf - q0) / (p[-1] - p[0])
    np.testing.assert_allclose(tr.q, q0 + (p - p[0]) * ratio, atol=1e-9)
    np.testing.assert_allclose(tr.qd, dp * ratio, atol=1e-9)


def test_thesis_quintic_degenerate_rescale_is_finite(rng):
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    c = np.zeros((4, 6, 6))
    c[1, :, 0] = 3.0  # constant polynomial: p(T) = p(0)
    c[2, :, 1], c[2, :, 2] = -1.0, 1.0  # p(t) = t² - t vanishes again at T = 1
    c[3, :, 1], c[3, :, 2] = -1.0, 1.0 + 1e-9  # nearly degenerate
    with np.errstate(all="raise"):
        tr = thesis_quintic(c, q0, qf, 1.0)
    for a in (tr.q, tr.qd, tr.qdd):
        assert np.all(np.isfinite(a))
    assert np.array_equal(tr.q[:, -1], np.broadcast_to(qf, (4, 6)))
    mj = minimum_jerk(q0, qf, 1.0)
    np.testing.assert_allclose(tr.q[1], mj.q, atol=1e-13)  # constant -> minimum jerk
    # t² - t is added on top of the minimum-jerk blend
    np.testing.assert_allclose(tr.q[2], mj.q + (tr.t**2 - tr.t)[:, None], atol=1e-12)
    assert np.abs(tr.q[3]).max() < 5.0


@pytest.mark.parametrize("parametrization", PARAMETRIZATIONS)
def test_single_and_batch_shapes_agree(parametrization, rng):
    c = grid_chromosomes(rng, 5)
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    batch = parametrization(c, q0, qf, 1.0)
    assert batch.q.shape == batch.qd.shape == batch.qdd.shape == (5, 41, 6)
    single = parametrization(c[3], q0, qf, 1.0)
    assert single.q.shape == (41, 6)
    for a, b in ((single.q, batch.q[3]), (single.qd, batch.qd[3]), (single.qdd, batch.qdd[3])):
        np.testing.assert_allclose(a, b, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("parametrization", PARAMETRIZATIONS)
def test_does_not_modify_inputs(parametrization, rng):
    c = grid_chromosomes(rng, 2)
    q0, qf = rng.uniform(-2, 2, size=(2, 6))
    saved = c.copy(), q0.copy(), qf.copy()
    parametrization(c, q0, qf, 1.0)
    for a, b in zip((c, q0, qf), saved, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("parametrization", PARAMETRIZATIONS)
def test_invalid_inputs(parametrization):
    z = np.zeros(6)
    with pytest.raises(InvalidInput, match=r"expected \(6, 6\) .* \(n_pop, 6, 6\)"):
        parametrization(np.zeros((2, 6, 5)), z, z, 1.0)
    with pytest.raises(InvalidInput, match="q_start .* must both have shape"):
        parametrization(np.zeros((6, 6)), np.zeros(5), z, 1.0)
    with pytest.raises(InvalidInput, match="NaN or infinite"):
        parametrization(np.full((6, 6), np.nan), z, z, 1.0)
    with pytest.raises(InvalidInput, match="finite"):
        parametrization(np.zeros((6, 6)), np.full(6, np.inf), z, 1.0)
    with pytest.raises(InvalidInput, match="not a whole number"):
        parametrization(np.zeros((6, 6)), z, z, 1.01)


def test_rest_to_rest_rejects_bad_scale():
    with pytest.raises(InvalidInput, match="scale must be a positive"):
        rest_to_rest(np.zeros((6, 6)), np.zeros(6), np.ones(6), 1.0, scale=0.0)


def test_other_joint_counts(rng):
    tr = rest_to_rest(rng.uniform(-1, 1, size=(3, 2, 6)), [0.0, 1.0], [1.0, 0.0], 0.5)
    assert tr.q.shape == (3, 21, 2)
