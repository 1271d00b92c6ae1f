"""The thesis' genetic algorithm (§2.3.2, App. F) with steady-state per-slot replacement."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath.errors import InvalidInput
from joulepath.evolve._algorithm import Population
from joulepath.evolve._operators import (
    mutate,
    recombine_average,
    recombine_differential,
    recombine_random,
    select_roulette,
    snap_to_grid,
)
from joulepath.evolve._problem import Problem
from joulepath.evolve._validate import check_choice, check_int, check_real

RECOMBINATIONS = ("average", "differential", "random")


@dataclass(frozen=True, slots=True, kw_only=True)
class GA:
    """Genetic algorithm of the thesis: roulette selection, per-slot replacement when better.

    One generation, for every slot ``i`` of the population (vectorized, see below):

    1. select a parent by inverse-fitness roulette wheel;
    2. draw ``r ~ U(0, 1)``: if ``r < p_crossover`` recombine it with a second
       roulette-selected parent (``"differential"`` also selects a third:
       ``a + F (b - c)``); else if ``r < p_crossover + p_mutation`` mutate it (1–9 genes
       to random grid values); otherwise reproduce it (copy). This is the thesis'
       listing and text (§2.3.2: crossover with P(C), mutation with P(M), "in the
       remaining cases, reproduction"): the three are exclusive;
    3. snap the offspring to the grid and evaluate it;
    4. the offspring replaces slot ``i`` only if its fitness is strictly lower than the
       slot's (THESIS_NOTES defect 8: a steady-state scheme, not generational
       replacement).

    **Vectorized equivalent.** All ``pop_size`` offspring are built from the population
    at the start of the generation, evaluated with one ``problem.evaluate`` call (copies
    reuse their parent's fitness and are not re-evaluated), and each slot is replaced
    where its offspring is better. The thesis loops over the slots, so a slot replaced
    early in a generation could already be selected as a parent later in the same
    generation; here parents always come from the previous generation. The thesis'
    operators also overwrote the selected parent in place (aliasing); ours do not.

    Parameters
    ----------
    pop_size : int
        Population size (>= 2), 100 in the thesis.
    p_crossover : float
        P(C) in [0, 1]; the thesis tests 0.90 and 0.95.
    p_mutation : float
        P(M) in [0, 1], with ``p_crossover + p_mutation <= 1``; the thesis tests 0.01
        and 0.05.
    recombination : {"random", "average", "differential"}
        Random (each gene from either parent), average, or differential ``a + F (b - c)``.
    F : float
        Scale factor of the differential recombination, in (0, 2]; the thesis tests
        0.05 and 0.15.
    grid_step : float
        Spacing of the gene grid (0.05 in the thesis).

    Raises
    ------
    InvalidInput
        For a value out of range or an unknown recombination (the message lists the
        allowed values).

    Examples
    --------
    >>> GA(p_crossover=0.9, p_mutation=0.01, recombination="average").pop_size
    100
    """

    pop_size: int = 100
    p_crossover: float = 0.95
    p_mutation: float = 0.05
    recombination: str = "random"
    F: float = 0.05
    grid_step: float = 0.05

    def __post_init__(self) -> None:
        check_int("GA", "pop_size", self.pop_size, minimum=2)
        check_real("GA", "p_crossover", self.p_crossover, low=0.0, high=1.0)
        check_real("GA", "p_mutation", self.p_mutation, low=0.0, high=1.0)
        if self.p_crossover + self.p_mutation > 1.0 + 1e-12:
            raise InvalidInput(
                f"GA: p_crossover + p_mutation must not exceed 1 (reproduction takes the rest), "
                f"got {self.p_crossover} + {self.p_mutation}"
            )
        check_choice("GA", "recombination", self.recombination, RECOMBINATIONS)
        check_real("GA", "F", self.F, low=0.0, high=2.0, low_open=True)
        check_real("GA", "grid_step", self.grid_step, low=0.0, high=np.inf, low_open=True, high_open=True)

    def check(self, problem: Problem) -> None:
        """Nothing beyond ``minimize``'s own checks."""

    def advance(self, problem: Problem, pop: Population, *, rng: np.random.Generator) -> Population:
        """One generation (see the class docstring); one ``problem.evaluate`` call."""
        X, F = pop.X, pop.F
        n = F.size
        xl, xu = problem.xl, problem.xu
        parent = select_roulette(F, n, rng=rng)
        r = rng.random(n)
        cross = r < self.p_crossover
        mut = ~cross & (r < self.p_crossover + self.p_mutation)

        Y = X[parent]
        n_cross = int(cross.sum())
        if n_cross:
            A, B = Y[cross], X[select_roulette(F, n_cross, rng=rng)]
            if self.recombination == "random":
                Y[cross] = recombine_random(A, B, rng=rng)
            elif self.recombination == "average":
                Y[cross] = recombine_average(A, B)
            else:
                C = X[select_roulette(F, n_cross, rng=rng)]
                Y[cross] = recombine_differential(A, B, C, F=self.F)
        if mut.any():
            Y[mut] = mutate(Y[mut], xl, xu, step=self.grid_step, rng=rng)

        changed = cross | mut
        FY = F[parent]
        if changed.any():
            Y[changed] = snap_to_grid(Y[changed], xl, xu, step=self.grid_step)
            FY[changed] = problem.evaluate(Y[changed])
        better = FY < F
        return Population(X=np.where(better[:, None], Y, X), F=np.where(better, FY, F))
