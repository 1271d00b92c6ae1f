"""The optimization problem as the search sees it: bounds and a whole-population fitness."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from joulepath._typing import ArrayLike, FloatArray
from joulepath.errors import InvalidInput


@runtime_checkable
class Problem(Protocol):
    """What ``minimize`` needs from a problem (single objective, box bounds).

    Implemented by the fitness functions of other stages (surrogate model, physics
    model); ``evolve`` imports none of them (STYLE.md §2).

    Attributes
    ----------
    n_var : int
        Number of genes per individual.
    xl, xu : ndarray of shape (n_var,)
        Lower and upper bound of every gene.
    """

    @property
    def n_var(self) -> int: ...

    @property
    def xl(self) -> FloatArray: ...

    @property
    def xu(self) -> FloatArray: ...

    def evaluate(self, X: FloatArray) -> FloatArray:
        """Fitness (to be minimized) of a whole population.

        Parameters
        ----------
        X : ndarray of shape (n_pop, n_var)

        Returns
        -------
        ndarray of shape (n_pop,)
        """
        ...


@dataclass(frozen=True, slots=True, eq=False)
class FunctionProblem:
    """A :class:`Problem` made of a vectorized function and box bounds.

    Parameters
    ----------
    function : callable
        ``function(X)`` with ``X`` of shape (n_pop, n_var) returns shape (n_pop,).
    n_var : int
        Number of genes.
    xl, xu : float or array_like of shape (n_var,)
        Bounds, broadcast to (n_var,); ``xl <= xu``.

    Raises
    ------
    InvalidInput
        If ``n_var`` is not a positive integer or the bounds are not finite, not of
        shape (n_var,) or not ordered.

    Examples
    --------
    >>> import numpy as np
    >>> p = FunctionProblem(lambda X: (X**2).sum(axis=1), n_var=3, xl=-1.0, xu=1.0)
    >>> p.evaluate(np.ones((2, 3))).tolist(), p.xu.tolist()
    ([3.0, 3.0], [1.0, 1.0, 1.0])
    """

    function: Callable[[FloatArray], ArrayLike]
    n_var: int
    xl: FloatArray = field(default_factory=lambda: np.array(-10.0))
    xu: FloatArray = field(default_factory=lambda: np.array(10.0))

    def __post_init__(self) -> None:
        xl, xu = check_bounds(self.n_var, self.xl, self.xu)
        object.__setattr__(self, "xl", xl)
        object.__setattr__(self, "xu", xu)

    def evaluate(self, X: FloatArray) -> FloatArray:
        """``function(X)`` as a float array of shape (n_pop,)."""
        return np.asarray(self.function(X), dtype=np.float64)


def check_bounds(n_var: object, xl: ArrayLike, xu: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Validate ``n_var`` and broadcast the bounds to read-only arrays of shape (n_var,)."""
    if not isinstance(n_var, (int, np.integer)) or isinstance(n_var, bool) or n_var < 1:
        raise InvalidInput(f"n_var must be a positive integer, got {n_var!r}")
    out = []
    for name, value in (("xl", xl), ("xu", xu)):
        try:
            arr = np.broadcast_to(np.asarray(value, dtype=np.float64), (int(n_var),)).copy()
        except (TypeError, ValueError) as err:
            shape = np.shape(value)
            raise InvalidInput(
                f"{name} has shape {shape}; expected a number or an array of shape ({n_var},)"
            ) from err
        if not np.all(np.isfinite(arr)):
            raise InvalidInput(f"{name} must be finite, got {arr}")
        arr.flags.writeable = False
        out.append(arr)
    lo, hi = out
    if np.any(lo > hi):
        bad = np.flatnonzero(lo > hi).tolist()
        raise InvalidInput(f"xl must not exceed xu; genes {bad} have xl > xu")
    return lo, hi
