"""Differential evolution, DE/rand/1/bin, on the gene grid (thesis §2.3.3)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.evolve._algorithm import Population
from joulepath.evolve._operators import IntArray, snap_to_grid
from joulepath.evolve._problem import Problem
from joulepath.evolve._validate import check_int, check_real


def distinct_others(n: int, k: int, *, rng: np.random.Generator) -> IntArray:
    """For every row ``i`` of ``n``, ``k`` distinct random indices other than ``i``.

    Returns
    -------
    ndarray of int, shape (n, k)
        Row ``i`` is a uniformly random ordered ``k``-subset of ``{0..n-1} \\ {i}``
        (requires ``n > k``).
    """
    keys = rng.random((n, n))
    np.fill_diagonal(keys, np.inf)
    idx = np.argpartition(keys, k - 1, axis=1)[:, :k]
    order = np.argsort(np.take_along_axis(keys, idx, axis=1), axis=1)
    out: IntArray = np.take_along_axis(idx, order, axis=1)
    return out


def de_rand_1_bin(X: FloatArray, *, F: float, CR: float, rng: np.random.Generator) -> FloatArray:
    """Trial vectors of DE/rand/1/bin.

    For every target ``i``: mutant ``v = x_a + F (x_b - x_c)`` with ``a, b, c`` distinct
    and different from ``i``; binomial crossover takes each gene from ``v`` with
    probability ``CR`` and at least one (random) gene from ``v``.

    Parameters
    ----------
    X : ndarray of shape (n_pop, n_var)
        ``n_pop >= 4``.

    Returns
    -------
    ndarray of shape (n_pop, n_var)
        Not snapped to the grid.
    """
    n, n_var = X.shape
    abc = distinct_others(n, 3, rng=rng)
    V = X[abc[:, 0]] + F * (X[abc[:, 1]] - X[abc[:, 2]])
    take = rng.random((n, n_var)) < CR
    take[np.arange(n), rng.integers(n_var, size=n)] = True
    out: FloatArray = np.where(take, V, X)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class DE:
    """Differential evolution DE/rand/1/bin with grid snapping.

    Every generation builds one trial vector per target (:func:`de_rand_1_bin`), snaps
    it to the grid, evaluates all trials in one call and keeps a trial where its fitness
    is lower than or equal to its target's (the usual DE rule, which lets the search
    drift along plateaus).

    The thesis' "differential" variant (§2.3.3, Table 4.5) is the GA with
    ``recombination="differential"``; this class is the standard algorithm.

    Parameters
    ----------
    pop_size : int
        >= 4.
    F : float
        Differential weight in (0, 2].
    CR : float
        Crossover rate in [0, 1].
    grid_step : float
        Spacing of the gene grid.

    Raises
    ------
    InvalidInput
        For a value out of range.
    """

    pop_size: int = 100
    F: float = 0.5
    CR: float = 0.9
    grid_step: float = 0.05

    def __post_init__(self) -> None:
        check_int("DE", "pop_size", self.pop_size, minimum=4)
        check_real("DE", "F", self.F, low=0.0, high=2.0, low_open=True)
        check_real("DE", "CR", self.CR, low=0.0, high=1.0)
        check_real("DE", "grid_step", self.grid_step, low=0.0, high=np.inf, low_open=True, high_open=True)

    def check(self, problem: Problem) -> None:
        """Nothing beyond ``minimize``'s own checks."""

    def advance(self, problem: Problem, pop: Population, *, rng: np.random.Generator) -> Population:
        """One generation; one ``problem.evaluate`` call."""
        U = snap_to_grid(
            de_rand_1_bin(pop.X, F=self.F, CR=self.CR, rng=rng), problem.xl, problem.xu, step=self.grid_step
        )
        FU = problem.evaluate(U)
        keep = FU <= pop.F
        return Population(X=np.where(keep[:, None], U, pop.X), F=np.where(keep, FU, pop.F))
