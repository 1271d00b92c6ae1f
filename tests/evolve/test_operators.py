import numpy as np
import pytest

from joulepath.evolve import (
    de_rand_1_bin,
    joint_genes,
    mutate,
    random_neighbours,
    recombine_average,
    recombine_differential,
    recombine_random,
    reproduce,
    roulette_weights,
    sample_grid,
    select_roulette,
    shrink_candidates,
    snap_to_grid,
)

STEP = 0.05
N_VAR = 36
XL, XU = np.full(N_VAR, -10.0), np.full(N_VAR, 10.0)


def on_grid(X, xl=XL, xu=XU):
    k = np.rint(X * 20.0)
    return bool(np.array_equal(X, k / 20.0) and np.all(X >= xl) and np.all(X <= xu))


@pytest.fixture
def population(rng):
    return sample_grid(100, XL, XU, step=STEP, rng=rng)


def test_sample_grid_on_grid_and_covers_bounds(rng):
    X = sample_grid(2000, XL, XU, step=STEP, rng=rng)
    assert X.shape == (2000, N_VAR) and on_grid(X)
    assert X.min() == -10.0 and X.max() == 10.0
    assert len(np.unique(X)) == 401


def test_sample_grid_seeded():
    a = sample_grid(5, XL, XU, step=STEP, rng=np.random.default_rng(1))
    b = sample_grid(5, XL, XU, step=STEP, rng=np.random.default_rng(1))
    c = sample_grid(5, XL, XU, step=STEP, rng=np.random.default_rng(2))
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_snap_to_grid_clips_and_rounds():
    xl, xu = np.array([-1.0, 0.01]), np.array([1.0, 0.33])
    X = np.array([[0.074, -0.2], [-3.0, 0.5], [0.026, 0.0]])
    out = snap_to_grid(X, xl, xu, step=STEP)
    np.testing.assert_allclose(out, [[0.05, 0.05], [-1.0, 0.3], [0.05, 0.05]])
    assert on_grid(out, xl, xu)
    assert np.array_equal(snap_to_grid(out, xl, xu, step=STEP), out)  # idempotent


def test_roulette_weights_inverse_fitness():
    w = roulette_weights(np.array([10.0, 20.0, 5.0, 15.0]))
    np.testing.assert_allclose(
        w, np.array([1 / 10, 1 / 20, 1 / 5, 1 / 15]) / (1 / 10 + 1 / 20 + 1 / 5 + 1 / 15)
    )


@pytest.mark.parametrize(
    "F",
    [np.array([-3.0, 0.0, 2.0, 5.0]), np.array([0.0, 1.0, 2.0, 3.0]), np.array([1.0, 2.0, np.inf, 4.0])],
)
def test_roulette_weights_non_positive_and_infinite(F):
    w = roulette_weights(F)
    assert np.all(w >= 0) and w.sum() == pytest.approx(1.0)
    finite = np.isfinite(F)
    assert np.all(np.diff(w[finite]) < 0)  # strictly decreasing with worse fitness
    assert np.all(w[~finite] == 0)


@pytest.mark.parametrize("F", [np.full(4, 7.0), np.full(4, -2.0), np.zeros(4), np.full(4, np.inf)])
def test_roulette_weights_equal_fitness_is_uniform(F):
    np.testing.assert_allclose(roulette_weights(F), 0.25)


def test_select_roulette_favours_better(rng):
    F = np.array([1.0, 2.0, 4.0, 8.0])
    idx = select_roulette(F, 40_000, rng=rng)
    assert idx.shape == (40_000,) and idx.min() >= 0 and idx.max() <= 3
    freq = np.bincount(idx, minlength=4) / idx.size
    np.testing.assert_allclose(freq, roulette_weights(F), atol=0.01)
    assert np.all(np.diff(freq) < 0)


def test_select_roulette_never_picks_zero_weight(rng):
    idx = select_roulette(np.array([np.inf, 1.0, np.inf]), 1000, rng=rng)
    assert np.all(idx == 1)


def test_recombine_random_takes_each_gene_from_a_parent(population, rng):
    A, B = population[:50], population[50:]
    Y = recombine_random(A, B, rng=rng)
    assert Y.shape == A.shape and on_grid(Y)
    assert np.all((Y == A) | (Y == B))
    from_b = (Y == B) & (A != B)
    assert 0.45 < from_b.sum() / (A != B).sum() < 0.55


def test_recombine_average_and_differential_on_grid_after_snapping(population):
    A, B, C = population[:30], population[30:60], population[60:90]
    avg = recombine_average(A, B)
    np.testing.assert_allclose(avg, (A + B) / 2)
    for F in (0.05, 0.15, 1.5):
        diff = recombine_differential(A, B, C, F=F)
        np.testing.assert_allclose(diff, A + F * (B - C))
        snapped = snap_to_grid(diff, XL, XU, step=STEP)
        assert on_grid(snapped)
        assert np.abs(snapped - np.clip(diff, -10, 10)).max() <= STEP / 2 + 1e-12
    assert on_grid(snap_to_grid(avg, XL, XU, step=STEP))


def test_reproduce_copies(population):
    Y = reproduce(population)
    assert np.array_equal(Y, population) and Y is not population
    Y[0, 0] = 99.0
    assert population[0, 0] != 99.0


def test_mutate_changes_one_to_nine_genes(population, rng):
    Y = mutate(population, XL, XU, step=STEP, rng=rng)
    assert Y.shape == population.shape and on_grid(Y)
    n_changed = (Y != population).sum(axis=1)
    assert n_changed.min() >= 1 and n_changed.max() <= 9
    assert set(np.unique(n_changed)) == set(range(1, 10))


def test_mutate_respects_per_gene_bounds(rng):
    xl, xu = np.array([0.0, -0.1, 5.0]), np.array([0.1, 0.0, 5.0])  # last gene: one grid value
    X = np.tile([0.05, -0.05, 5.0], (200, 1))
    Y = mutate(X, xl, xu, step=STEP, rng=rng, max_genes=3)
    assert on_grid(Y, xl, xu)
    assert np.all(Y[:, 2] == 5.0)
    assert np.all((Y != X).sum(axis=1) <= 3)


def test_mutate_does_not_modify_input(population, rng):
    saved = population.copy()
    mutate(population, XL, XU, step=STEP, rng=rng)
    assert np.array_equal(population, saved)


def test_de_rand_1_bin_shapes_and_crossover(population, rng):
    U = de_rand_1_bin(population, F=0.5, CR=0.0, rng=rng)
    assert U.shape == population.shape
    assert np.all((U != population).sum(axis=1) <= 1)  # CR = 0: exactly one gene from the mutant
    assert on_grid(snap_to_grid(de_rand_1_bin(population, F=0.5, CR=0.9, rng=rng), XL, XU, step=STEP))


def test_random_neighbours_within_radius(population, rng):
    x = population[0]
    N = random_neighbours(x, 1000, XL, XU, step=STEP, radius=5, rng=rng)
    assert N.shape == (1000, N_VAR) and on_grid(N)
    offsets = np.rint((N - x) / STEP)
    assert np.all(np.abs(offsets) <= 5)
    inside = (x > -9.7) & (x < 9.7)
    assert set(np.unique(offsets[:, inside])) == set(range(-5, 6))


def test_shrink_candidates_scale_only_given_joints():
    x = np.full(N_VAR, 4.0)
    genes = joint_genes((2, 0), 6)
    assert genes.tolist() == [12, 13, 14, 15, 16, 17, 0, 1, 2, 3, 4, 5]
    C = shrink_candidates(x, genes, XL, XU, factor=0.9, steps=20, step=STEP)
    assert C.shape == (20, N_VAR) and on_grid(C)
    others = np.setdiff1d(np.arange(N_VAR), genes)
    assert np.all(C[:, others] == 4.0)
    np.testing.assert_allclose(C[:, genes[0]], 4.0 * 0.9 ** np.arange(1, 21), atol=STEP / 2)
    assert np.all(np.diff(C[:, genes[0]]) <= 0)
