import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.evolve import (
    DE,
    GA,
    MA,
    FunctionProblem,
    Population,
    Termination,
    informed_local_search,
    minimize,
    random_local_search,
)

STEP = 0.05
N_VAR = 12
TARGET = np.linspace(-2.5, 3.0, N_VAR).round(1)  # on the grid


def sphere(X):
    return ((X - TARGET) ** 2).sum(axis=1) + 1.0


PROBLEM = FunctionProblem(sphere, n_var=N_VAR, xl=-10.0, xu=10.0)
SHORT = Termination(n_max_gen=40)

ALGORITHMS = {
    "ga-random": GA(pop_size=30),
    "ga-average": GA(pop_size=30, p_crossover=0.9, p_mutation=0.05, recombination="average"),
    "ga-differential": GA(pop_size=30, recombination="differential", F=0.15),
    "de": DE(pop_size=30),
    "ma-random": MA(base=GA(pop_size=30), n_samples=200, batch_size=64),
    "ma-informed": MA(base=GA(pop_size=30), local_search="informed", joints=(1, 0)),
    "ma-de": MA(base=DE(pop_size=30), n_samples=100),
}


def on_grid(X, xl=-10.0, xu=10.0):
    return bool(np.array_equal(X, np.rint(X * 20.0) / 20.0) and np.all(X >= xl) and np.all(X <= xu))


@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_minimize_lowers_separable_function(name):
    res = minimize(PROBLEM, ALGORITHMS[name], SHORT, seed=3)
    assert res.f_best < 0.5 * res.f_initial_best
    assert res.f_best == pytest.approx(sphere(res.x_best[None])[0])
    assert on_grid(res.X) and on_grid(res.x_best)
    assert res.history.shape == (res.n_gen + 1,) and res.history[0] == res.f_initial_best
    assert np.all(np.diff(res.history) <= 0)  # the best never gets worse
    assert res.history[-1] == res.f_best and res.n_evals > 30 and res.wall_s > 0


@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_minimize_seed_reproduces_run(name):
    a = minimize(PROBLEM, ALGORITHMS[name], Termination(n_max_gen=8), seed=11)
    b = minimize(PROBLEM, ALGORITHMS[name], Termination(n_max_gen=8), seed=11)
    c = minimize(PROBLEM, ALGORITHMS[name], Termination(n_max_gen=8), seed=12)
    assert np.array_equal(a.history, b.history) and np.array_equal(a.X, b.X) and a.n_evals == b.n_evals
    assert not np.array_equal(a.X, c.X)


def test_minimize_accepts_generator_seed():
    a = minimize(PROBLEM, GA(pop_size=10), Termination(n_max_gen=3), seed=np.random.default_rng(5))
    b = minimize(PROBLEM, GA(pop_size=10), Termination(n_max_gen=3), seed=np.random.default_rng(5))
    assert np.array_equal(a.X, b.X)
    with pytest.raises(TypeError, match="seed must be"):
        minimize(PROBLEM, GA(pop_size=10), seed=1.5)  # type: ignore[arg-type]


@pytest.mark.parametrize("name", ["ga-random", "de", "ma-random", "ma-informed"])
def test_minimize_stops_after_ten_stagnant_generations(name):
    flat = FunctionProblem(lambda X: np.full(X.shape[0], 2.0), n_var=N_VAR, xl=-1.0, xu=1.0)
    res = minimize(flat, ALGORITHMS[name], seed=0)
    assert res.n_gen == 10 and res.f_best == res.f_initial_best == 2.0


def test_minimize_generation_cap():
    res = minimize(PROBLEM, GA(pop_size=10), Termination(n_max_gen=5, n_stagnant=100), seed=0)
    assert res.n_gen == 5


def test_minimize_default_termination_is_thesis():
    term = Termination()
    assert (term.n_max_gen, term.n_stagnant) == (200, 10)


def test_termination_progress():
    term = Termination(n_max_gen=20, n_stagnant=4)
    assert term.progress([3.0]) == 0.0
    assert term.stagnant_generations([3.0, 2.0, 2.0, 2.0]) == 2
    assert term.progress([3.0, 2.0, 2.0, 2.0]) == 0.5
    assert term.progress([3.0, 2.0, 2.0, 2.0, 1.0]) == pytest.approx(4 / 20)
    assert term.progress([3.0] + [3.0] * 4) == 1.0
    assert term.progress(np.linspace(30, 10, 21)) == 1.0
    assert Termination(tol=0.5).stagnant_generations([3.0, 2.9, 2.8]) == 2


def test_ga_replaces_a_slot_only_when_better():
    seen = []
    minimize(
        PROBLEM, GA(pop_size=20), Termination(n_max_gen=10), seed=4, callback=lambda g, p: seen.append(p)
    )
    for before, after in zip(seen, seen[1:], strict=False):
        assert np.all(after.F <= before.F)
        same = after.F == before.F
        assert np.array_equal(after.X[same], before.X[same])


def test_ga_reproduction_only_costs_no_evaluations():
    res = minimize(
        PROBLEM, GA(pop_size=20, p_crossover=0.0, p_mutation=0.0), Termination(n_max_gen=5), seed=0
    )
    assert res.n_evals == 20


def test_ga_evaluates_once_per_generation():
    calls = []

    def f(X):
        calls.append(X.shape[0])
        return sphere(X)

    res = minimize(
        FunctionProblem(f, n_var=N_VAR, xl=-10, xu=10), GA(pop_size=25), Termination(n_max_gen=6), seed=1
    )
    assert len(calls) == res.n_gen + 1 and sum(calls) == res.n_evals
    assert calls[0] == 25 and all(c <= 25 for c in calls)


def test_minimize_does_not_mutate_algorithm():
    class Counting:
        pop_size = 10
        grid_step = STEP

        def __init__(self):
            self.calls = 0

        def check(self, problem):
            pass

        def advance(self, problem, pop, *, rng):
            self.calls += 1
            return pop

    algo = Counting()
    res = minimize(PROBLEM, algo, Termination(n_max_gen=3), seed=0)
    assert res.n_gen == 3 and algo.calls == 0
    ma = MA(base=GA(pop_size=10), local_search="informed", joints=(0,))
    snapshot = repr(ma)
    minimize(PROBLEM, ma, Termination(n_max_gen=3), seed=0)
    assert repr(ma) == snapshot


def test_minimize_initial_population_injected():
    zero = np.zeros(N_VAR)
    res = minimize(PROBLEM, GA(pop_size=10), Termination(n_max_gen=1), seed=0, initial=zero + 0.01)
    assert res.f_initial_best <= sphere(zero[None])[0]
    with pytest.raises(InvalidInput, match="initial has shape"):
        minimize(PROBLEM, GA(pop_size=10), seed=0, initial=np.zeros((11, N_VAR)))
    with pytest.raises(InvalidInput, match="initial has shape"):
        minimize(PROBLEM, GA(pop_size=10), seed=0, initial=np.zeros(N_VAR + 1))


def test_minimize_respects_per_gene_bounds():
    xl, xu = np.linspace(-1.0, 0.0, N_VAR), np.linspace(0.02, 2.0, N_VAR) + 0.05
    problem = FunctionProblem(sphere, n_var=N_VAR, xl=xl, xu=xu)
    for algo in (GA(pop_size=20), DE(pop_size=20), MA(base=GA(pop_size=20), n_samples=50)):
        res = minimize(problem, algo, Termination(n_max_gen=10), seed=2)
        assert on_grid(res.X, xl, xu)


def test_minimize_nan_fitness_counts_as_worst():
    def f(X):
        F = sphere(X)
        F[X[:, 0] > 0] = np.nan
        return F

    res = minimize(FunctionProblem(f, n_var=N_VAR, xl=-10, xu=10), GA(pop_size=20), SHORT, seed=0)
    assert np.isfinite(res.f_best) and res.x_best[0] <= 0


def test_minimize_rejects_wrong_fitness_shape():
    bad = FunctionProblem(lambda X: np.zeros((X.shape[0], 2)), n_var=N_VAR, xl=-1, xu=1)
    with pytest.raises(InvalidInput, match=r"returned shape \(10, 2\) for 10 individuals"):
        minimize(bad, GA(pop_size=10), seed=0)


def test_minimize_rejects_bounds_without_grid_value():
    problem = FunctionProblem(sphere, n_var=N_VAR, xl=0.01, xu=0.04)
    with pytest.raises(InvalidInput, match="no multiple of grid_step"):
        minimize(problem, GA(pop_size=10), seed=0)


def test_minimize_rejects_informed_joints_out_of_range():
    with pytest.raises(InvalidInput, match=r"joints \[2\] do not exist; the problem has joints 0..1"):
        minimize(PROBLEM, MA(local_search="informed", joints=(0, 2)), seed=0)
    with pytest.raises(InvalidInput, match="not a multiple of genes_per_joint"):
        minimize(PROBLEM, MA(local_search="informed", joints=(0,), genes_per_joint=5), seed=0)


def test_informed_local_search_shrinks_only_given_joints():
    # energy grows with |coefficients| of joint 1 only
    problem = FunctionProblem(lambda X: 1.0 + np.abs(X[:, 6:12]).sum(axis=1), n_var=N_VAR, xl=-10, xu=10)
    x = np.full(N_VAR, 2.0)
    x_new, f_new = informed_local_search(
        problem,
        x,
        float(problem.evaluate(x[None])[0]),
        joints=(1,),
        genes_per_joint=6,
        factor=0.9,
        steps=20,
        step=STEP,
    )
    assert f_new < 13.0
    assert np.array_equal(x_new[:6], x[:6]) and np.all(x_new[6:] < 2.0)
    np.testing.assert_allclose(x_new[6:], 2.0 * 0.9**20, atol=STEP / 2)
    # shrinking the other joint does not help: x is returned unchanged
    x_same, f_same = informed_local_search(
        problem, x, 13.0, joints=(0,), genes_per_joint=6, factor=0.9, steps=20, step=STEP
    )
    assert x_same is x and f_same == 13.0


def test_random_local_search_keeps_best_if_better(rng):
    x = TARGET + 0.25
    f = float(sphere(x[None])[0])
    x_new, f_new = random_local_search(
        PROBLEM, x, f, n_samples=300, radius=5, batch_size=100, step=STEP, rng=rng
    )
    assert f_new < f and f_new == pytest.approx(sphere(x_new[None])[0])
    assert np.all(np.abs(x_new - x) <= 5 * STEP + 1e-12)
    best, fb = random_local_search(
        PROBLEM, TARGET, 1.0, n_samples=50, radius=5, batch_size=50, step=STEP, rng=rng
    )
    assert fb == 1.0 and np.array_equal(best, TARGET)


def test_population_is_plain_arrays():
    pop = Population(X=np.zeros((2, 3)), F=np.zeros(2))
    assert pop.X.shape == (2, 3)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (
            lambda: GA(recombination="uniform"),
            "recombination must be one of 'average', 'differential', 'random'",
        ),
        (lambda: GA(pop_size=1), r"pop_size must be an integer >= 2, got 1"),
        (lambda: GA(pop_size=True), "pop_size must be an integer"),
        (lambda: GA(p_crossover=1.2), r"p_crossover must be a number in \[0, 1\], got 1.2"),
        (lambda: GA(p_crossover=0.95, p_mutation=0.1), "must not exceed 1"),
        (lambda: GA(F=0.0), r"F must be a number in \(0, 2\]"),
        (lambda: GA(grid_step=-0.05), "grid_step must be a number in"),
        (lambda: DE(pop_size=3), "pop_size must be an integer >= 4"),
        (lambda: DE(CR=-0.1), r"CR must be a number in \[0, 1\]"),
        (lambda: DE(F=float("nan")), "F must be a number"),
        (lambda: MA(local_search="greedy"), "local_search must be one of 'informed', 'random'"),
        (lambda: MA(local_search="informed"), "needs joints"),
        (lambda: MA(joints=(0, 0)), "must not repeat"),
        (lambda: MA(joints=(-1,)), "joint indices >= 0"),
        (lambda: MA(factor=1.0), r"factor must be a number in \(0, 1\)"),
        (lambda: MA(n_samples=0), "n_samples must be an integer >= 1"),
        (lambda: MA(base="GA"), "base must be a GA or DE config"),
        (lambda: Termination(n_max_gen=0), "n_max_gen must be an integer >= 1"),
        (lambda: Termination(tol=-1.0), "tol must be a number"),
        (lambda: FunctionProblem(sphere, n_var=0), "n_var must be a positive integer"),
        (lambda: FunctionProblem(sphere, n_var=3, xl=np.zeros(2)), r"xl has shape \(2,\); expected"),
        (lambda: FunctionProblem(sphere, n_var=3, xl=1.0, xu=0.0), "xl must not exceed xu"),
    ],
)
def test_invalid_configs_raise(make, match):
    with pytest.raises(InvalidInput, match=match):
        make()


def test_configs_are_frozen():
    ga = GA()
    with pytest.raises(AttributeError):
        ga.pop_size = 3  # type: ignore[misc]
    assert MA().pop_size == 100 and MA(base=DE(pop_size=50)).pop_size == 50
