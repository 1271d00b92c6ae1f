"""What every algorithm shares: the population state and the ``Algorithm`` protocol."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from joulepath._typing import FloatArray
from joulepath.evolve._problem import Problem


@dataclass(frozen=True, slots=True, eq=False)
class Population:
    """Individuals and their fitness, passed between operators as plain arrays.

    Attributes
    ----------
    X : ndarray of shape (n_pop, n_var)
        Genes, on the grid and within the problem's bounds.
    F : ndarray of shape (n_pop,)
        Fitness (minimized); ``inf`` marks an unusable individual.
    """

    X: FloatArray
    F: FloatArray


class Algorithm(Protocol):
    """An algorithm config that can advance a population by one generation.

    Configs are frozen dataclasses of plain values; all run state lives in the
    :class:`Population` passed in and returned, and all randomness comes from ``rng``.
    """

    @property
    def pop_size(self) -> int: ...

    @property
    def grid_step(self) -> float: ...

    def check(self, problem: Problem) -> None:
        """Raise ``InvalidInput`` if this config cannot run on ``problem``."""
        ...

    def advance(self, problem: Problem, pop: Population, *, rng: np.random.Generator) -> Population:
        """One generation: new individuals, evaluated with one ``problem.evaluate`` call."""
        ...
