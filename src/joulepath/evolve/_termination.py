"""When to stop: stagnation of the best fitness, or a generation cap (thesis §2.3.2)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import ArrayLike
from joulepath.evolve._validate import check_int, check_real


@dataclass(frozen=True, slots=True, kw_only=True)
class Termination:
    """Stop after ``n_stagnant`` generations without improvement or after ``n_max_gen``.

    The thesis stops on "the lack of change in the last ten generations or more than
    200 generations passing in total". An improvement is a best fitness lower than the
    best so far by more than ``tol``.

    Parameters
    ----------
    n_max_gen : int
        Generation cap (>= 1).
    n_stagnant : int
        Generations without improvement that end the run (>= 1).
    tol : float
        Smallest decrease that counts as an improvement (>= 0).

    Examples
    --------
    >>> term = Termination(n_max_gen=50, n_stagnant=10)
    >>> term.progress([5.0, 4.0, 4.0, 4.0]), term.progress([5.0] + [4.0] * 11)
    (0.2, 1.0)
    """

    n_max_gen: int = 200
    n_stagnant: int = 10
    tol: float = 0.0

    def __post_init__(self) -> None:
        check_int("Termination", "n_max_gen", self.n_max_gen, minimum=1)
        check_int("Termination", "n_stagnant", self.n_stagnant, minimum=1)
        check_real("Termination", "tol", self.tol, low=0.0, high=np.inf, high_open=True)

    def stagnant_generations(self, history: ArrayLike) -> int:
        """Generations since the best fitness last improved.

        Parameters
        ----------
        history : array_like of shape (n_gen + 1,)
            Best fitness of the initial population, then after each generation.
        """
        h = np.asarray(history, dtype=np.float64)
        best_before = np.minimum.accumulate(h)[:-1]
        improved = np.flatnonzero(h[1:] < best_before - self.tol)
        last = int(improved[-1]) + 1 if improved.size else 0
        return h.size - 1 - last

    def progress(self, history: ArrayLike) -> float:
        """Progress in [0, 1]; the run ends at 1.

        The larger of ``n_gen / n_max_gen`` and ``stagnant / n_stagnant``, capped at 1.
        """
        n_gen = np.size(history) - 1
        frac = max(n_gen / self.n_max_gen, self.stagnant_generations(history) / self.n_stagnant)
        return min(1.0, frac)
