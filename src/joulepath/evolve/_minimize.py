"""The front door: ``minimize(problem, algorithm, termination, seed=...)``."""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from joulepath._rng import check_rng
from joulepath._typing import ArrayLike, FloatArray
from joulepath.errors import InvalidInput
from joulepath.evolve._algorithm import Algorithm, Population
from joulepath.evolve._operators import grid_limits, sample_grid, snap_to_grid
from joulepath.evolve._problem import Problem, check_bounds
from joulepath.evolve._termination import Termination


@dataclass(frozen=True, slots=True, eq=False)
class Result:
    """Outcome of :func:`minimize`.

    Attributes
    ----------
    x_best : ndarray of shape (n_var,)
        Best individual found.
    f_best : float
        Its fitness.
    f_initial_best : float
        Best fitness of the initial population: the baseline of the thesis'
        "improvement" (Tables 4.5, 4.6).
    history : ndarray of shape (n_gen + 1,)
        Best fitness of the initial population, then after each generation
        (``convergence.csv``).
    n_gen : int
        Generations run.
    n_evals : int
        Individuals evaluated (rows passed to ``problem.evaluate``).
    wall_s : float
        Wall time of the run, s.
    X : ndarray of shape (n_pop, n_var)
        Final population.
    F : ndarray of shape (n_pop,)
        Its fitness.
    """

    x_best: FloatArray
    f_best: float
    f_initial_best: float
    history: FloatArray
    n_gen: int
    n_evals: int
    wall_s: float
    X: FloatArray
    F: FloatArray


class _Evaluator:
    """The problem as the algorithm sees it: checked output, NaN as ``inf``, counted rows."""

    def __init__(self, problem: Problem, xl: FloatArray, xu: FloatArray) -> None:
        self._problem = problem
        self.n_var = xl.size
        self.xl = xl
        self.xu = xu
        self.n_evals = 0

    def evaluate(self, X: FloatArray) -> FloatArray:
        F = np.asarray(self._problem.evaluate(X), dtype=np.float64)
        if F.shape != (X.shape[0],):
            raise InvalidInput(
                f"problem.evaluate returned shape {F.shape} for {X.shape[0]} individuals; "
                f"expected ({X.shape[0]},): one fitness value per row of X"
            )
        self.n_evals += X.shape[0]
        return _nan_to_inf(F)


def _nan_to_inf(F: FloatArray) -> FloatArray:
    """A NaN fitness counts as the worst possible (``inf``)."""
    out: FloatArray = np.where(np.isnan(F), np.inf, F)
    return out


def _initial_population(
    initial: ArrayLike | None,
    n_pop: int,
    xl: FloatArray,
    xu: FloatArray,
    *,
    step: float,
    rng: np.random.Generator,
) -> FloatArray:
    """Uniform random grid values, with the rows of ``initial`` (snapped) in front."""
    X = sample_grid(n_pop, xl, xu, step=step, rng=rng)
    if initial is None:
        return X
    X0 = np.atleast_2d(np.asarray(initial, dtype=np.float64))
    if X0.ndim != 2 or X0.shape[1] != xl.size or X0.shape[0] > n_pop:
        raise InvalidInput(
            f"initial has shape {np.shape(initial)}; expected (n_var,) or (m, n_var) with "
            f"n_var = {xl.size} and m <= pop_size = {n_pop}"
        )
    if not np.all(np.isfinite(X0)):
        raise InvalidInput("initial contains NaN or infinite genes")
    X[: X0.shape[0]] = snap_to_grid(X0, xl, xu, step=step)
    return X


def minimize(
    problem: Problem,
    algorithm: Algorithm,
    termination: Termination | None = None,
    *,
    seed: int | np.random.Generator | None = None,
    initial: ArrayLike | None = None,
    callback: Callable[[int, Population], object] | None = None,
) -> Result:
    """Minimize ``problem`` with ``algorithm`` until ``termination``.

    Draws the initial population uniformly from the grid (``initial`` rows, e.g. the
    all-zero chromosome, are snapped and put in front), then advances it one generation
    at a time. The algorithm is deep-copied, so the call has no side effects on it.

    Parameters
    ----------
    problem : Problem
        ``n_var``, bounds ``xl``/``xu`` and a whole-population ``evaluate``.
    algorithm : GA, DE or MA
    termination : Termination, optional
        Default ``Termination()``: 10 stagnant generations or 200 generations.
    seed : int, Generator or None
        Resolved once with ``check_rng``; a seed reproduces a run exactly.
    initial : array_like of shape (n_var,) or (m, n_var), optional
        Individuals to put into the initial population (``m <= pop_size``).
    callback : callable, optional
        ``callback(n_gen, population)`` after every generation; must not modify the
        arrays.

    Returns
    -------
    Result

    Raises
    ------
    InvalidInput
        If the problem's bounds are invalid or hold no grid value, ``initial`` has the
        wrong shape, the algorithm cannot run on the problem, or ``evaluate`` returns
        the wrong shape.

    Notes
    -----
    A NaN fitness is treated as ``inf`` (the worst). Every gene stays on the grid
    ``k * algorithm.grid_step`` within ``[xl, xu]``.

    Examples
    --------
    >>> from joulepath.evolve import GA, FunctionProblem, Termination
    >>> p = FunctionProblem(lambda X: (X**2).sum(axis=1) + 1.0, n_var=4, xl=-2.0, xu=2.0)
    >>> res = minimize(p, GA(pop_size=20), Termination(n_max_gen=30), seed=0)
    >>> bool(res.f_best < res.f_initial_best), res.history.size == res.n_gen + 1
    (True, True)
    """
    t0 = time.perf_counter()
    xl, xu = check_bounds(problem.n_var, problem.xl, problem.xu)
    algorithm = copy.deepcopy(algorithm)
    termination = Termination() if termination is None else termination
    step = algorithm.grid_step
    k_lo, k_hi = grid_limits(xl, xu, step=step)
    if np.any(k_lo > k_hi):
        bad = np.flatnonzero(k_lo > k_hi).tolist()
        raise InvalidInput(
            f"genes {bad} have no multiple of grid_step = {step} within [xl, xu]; "
            "widen the bounds or change grid_step"
        )
    evaluator = _Evaluator(problem, xl, xu)
    algorithm.check(evaluator)
    rng = check_rng(seed)

    X = _initial_population(initial, algorithm.pop_size, xl, xu, step=step, rng=rng)
    pop = Population(X=X, F=evaluator.evaluate(X))
    history = [float(pop.F.min())]
    while termination.progress(history) < 1.0:
        pop = algorithm.advance(evaluator, pop, rng=rng)
        history.append(float(pop.F.min()))
        if callback is not None:
            callback(len(history) - 1, pop)

    i = int(np.argmin(pop.F))
    return Result(
        x_best=pop.X[i].copy(),
        f_best=float(pop.F[i]),
        f_initial_best=history[0],
        history=np.asarray(history),
        n_gen=len(history) - 1,
        n_evals=evaluator.n_evals,
        wall_s=time.perf_counter() - t0,
        X=pop.X,
        F=pop.F,
    )
