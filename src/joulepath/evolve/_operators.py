"""Evolutionary operators as pure array functions (thesis §2.3, App. F).

Population on axis 0: ``X`` has shape (n_pop, n_var), ``F`` shape (n_pop,). Genes live
on a grid: the multiples of ``step`` that lie in ``[xl, xu]`` (the thesis uses
``-10:0.05:10``). Every grid value is produced from an integer index ``k`` as
``k / (1 / step)`` (:func:`from_index`): for ``step = 0.05`` that is ``k / 20``, the
double nearest to the decimal ``k · 0.05`` (``0.15`` rather than the
``0.15000000000000002`` of ``3 * 0.05``). So ``snap_to_grid`` is idempotent, and
``snap_to_grid(X, ...) == X`` tests "on the grid" exactly.

Operators that draw random numbers take a required keyword-only ``rng``; deterministic
ones (``snap_to_grid``, ``recombine_average``, ``recombine_differential``,
``reproduce``) take none. Inner functions trust their inputs (STYLE.md §6): shapes
and bounds are validated once, by ``minimize``.
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
import numpy.typing as npt

from joulepath._typing import FloatArray

IntArray: TypeAlias = npt.NDArray[np.intp]

MAX_MUTATED_GENES = 9
"""Mutation changes between 1 and this many genes (the thesis' ``randint(1, 10)``)."""


def to_index(X: FloatArray, *, step: float) -> IntArray:
    """Nearest grid index ``round(X / step)`` (ties to even)."""
    return np.rint(X * (1.0 / step)).astype(np.intp)


def from_index(k: IntArray, *, step: float) -> FloatArray:
    """Grid value of index ``k``: ``k / (1 / step)``."""
    out: FloatArray = k / (1.0 / step)
    return out


def grid_limits(xl: FloatArray, xu: FloatArray, *, step: float) -> tuple[IntArray, IntArray]:
    """Index range ``k_lo..k_hi`` of the grid values inside ``[xl, xu]``.

    The grid values of the returned indices lie within the bounds exactly (a bound
    that is a grid value is included). ``k_lo > k_hi`` means the interval holds no
    grid value (the caller must reject it).
    """
    k_lo = np.ceil(xl / step - 1e-6).astype(np.intp)
    k_hi = np.floor(xu / step + 1e-6).astype(np.intp)
    k_lo = np.where(from_index(k_lo, step=step) < xl, k_lo + 1, k_lo)
    k_hi = np.where(from_index(k_hi, step=step) > xu, k_hi - 1, k_hi)
    return k_lo, k_hi


def snap_to_grid(X: FloatArray, xl: FloatArray, xu: FloatArray, *, step: float) -> FloatArray:
    """Nearest grid value inside the bounds (repair operator).

    Parameters
    ----------
    X : ndarray of shape (n_pop, n_var)
    xl, xu : ndarray of shape (n_var,)
        Bounds holding at least one grid value each.
    step : float
        Grid spacing.

    Returns
    -------
    ndarray of shape (n_pop, n_var)
        The grid value of ``k = round(X / step)`` clipped to the grid range of each gene.

    Examples
    --------
    >>> import numpy as np
    >>> snap_to_grid(np.array([[0.07, -12.0, 0.025]]), np.full(3, -10.0), np.full(3, 10.0), step=0.05)
    array([[  0.05, -10.  ,   0.  ]])
    """
    k_lo, k_hi = grid_limits(xl, xu, step=step)
    return from_index(np.clip(to_index(X, step=step), k_lo, k_hi), step=step)


def sample_grid(
    n: int, xl: FloatArray, xu: FloatArray, *, step: float, rng: np.random.Generator
) -> FloatArray:
    """``n`` individuals with every gene uniform over its grid values (initial population).

    Returns
    -------
    ndarray of shape (n, n_var)
    """
    k_lo, k_hi = grid_limits(xl, xu, step=step)
    return from_index(rng.integers(k_lo, k_hi + 1, size=(n, xl.size)), step=step)


def roulette_weights(F: FloatArray) -> FloatArray:
    """Selection probabilities of inverse-fitness roulette-wheel selection (minimization).

    * All finite fitness values positive (the thesis' case, energies): ``P_i ∝ 1/f_i``
      (eqs. 2.50–2.52).
    * Some finite value ``<= 0`` (``1/f`` would be meaningless): the values are shifted,
      ``P_i ∝ 1 / (f_i - f_min + spread)`` with ``spread = f_max - f_min`` (1 when all
      are equal), so the best individual is twice as likely as the worst.
    * Equal fitness values give equal probabilities.
    * Non-finite values (``inf``, e.g. a NaN fitness replaced by ``minimize``) get
      probability 0; if none is finite, selection is uniform.

    Parameters
    ----------
    F : ndarray of shape (n_pop,)

    Returns
    -------
    ndarray of shape (n_pop,)
        Non-negative, summing to 1.

    Examples
    --------
    >>> import numpy as np
    >>> roulette_weights(np.array([10.0, 20.0, 5.0, 15.0]))  # the fitness of thesis Table 2.6
    array([0.24, 0.12, 0.48, 0.16])

    (Table 2.6 prints 0.273, 0.137, 0.546, 0.183: it sums ``1/f`` to 0.366 instead of
    0.417.)
    """
    finite = np.isfinite(F)
    if not finite.any():
        return np.full(F.shape, 1.0 / F.size)
    f = np.where(finite, F, 0.0)
    lo, hi = float(f[finite].min()), float(f[finite].max())
    if lo > 0:
        w = 1.0 / np.where(finite, f, 1.0)
    else:
        spread = hi - lo if hi > lo else 1.0
        w = 1.0 / (f - lo + spread)
    w = np.where(finite, w, 0.0)
    out: FloatArray = w / w.sum()
    return out


def select_roulette(F: FloatArray, n: int, *, rng: np.random.Generator) -> IntArray:
    """Draw ``n`` parent indices by roulette wheel (with replacement).

    One uniform draw per parent; the selected individual is the first whose cumulative
    probability exceeds it (thesis eq. 2.53). Weights from :func:`roulette_weights`.

    Returns
    -------
    ndarray of int, shape (n,)
    """
    c = np.cumsum(roulette_weights(F))
    r = rng.random(n) * c[-1]
    idx: IntArray = np.minimum(np.searchsorted(c, r, side="right"), F.size - 1)
    return idx


def recombine_random(A: FloatArray, B: FloatArray, *, rng: np.random.Generator) -> FloatArray:
    """Random (uniform) recombination: each gene from ``A`` or ``B`` with equal odds (eq. 2.57).

    Parameters
    ----------
    A, B : ndarray of shape (n, n_var)
        Row ``i`` of ``A`` is mated with row ``i`` of ``B``.

    Returns
    -------
    ndarray of shape (n, n_var)
    """
    out: FloatArray = np.where(rng.random(A.shape) < 0.5, B, A)
    return out


def recombine_average(A: FloatArray, B: FloatArray) -> FloatArray:
    """Average recombination ``(A + B) / 2`` (eq. 2.58); snap the result to the grid.

    Deterministic: no ``rng``.
    """
    out: FloatArray = 0.5 * (A + B)
    return out


def recombine_differential(A: FloatArray, B: FloatArray, C: FloatArray, *, F: float) -> FloatArray:
    """Differential recombination ``A + F (B - C)`` (eq. 2.59); snap the result to the grid.

    The thesis' GA uses ``F`` in {0.05, 0.15}. Deterministic: no ``rng``.
    """
    out: FloatArray = A + F * (B - C)
    return out


def reproduce(A: FloatArray) -> FloatArray:
    """Reproduction: an unchanged copy."""
    return A.copy()


def mutate(
    X: FloatArray,
    xl: FloatArray,
    xu: FloatArray,
    *,
    step: float,
    rng: np.random.Generator,
    max_genes: int = MAX_MUTATED_GENES,
) -> FloatArray:
    """Set 1 to ``max_genes`` random genes of every row to a new random grid value.

    The number of genes is uniform in ``1..max_genes`` (at most ``n_var``), the genes are
    distinct, and each new value is uniform over the gene's other grid values, so exactly
    that many genes change (a gene whose bounds hold one grid value cannot change). The
    thesis drew positions with replacement and could redraw the old value; this keeps
    the intent, "change 1–9 genes".

    Parameters
    ----------
    X : ndarray of shape (n, n_var)
        On the grid.
    xl, xu : ndarray of shape (n_var,)
    step : float
    rng : Generator
    max_genes : int

    Returns
    -------
    ndarray of shape (n, n_var)
    """
    n, n_var = X.shape
    k_lo, k_hi = grid_limits(xl, xu, step=step)
    n_genes = rng.integers(1, min(max_genes, n_var) + 1, size=n)
    rank = np.argsort(np.argsort(rng.random((n, n_var)), axis=1), axis=1)
    chosen = rank < n_genes[:, None]
    k = to_index(X, step=step)
    width = k_hi - k_lo  # number of *other* grid values
    draw = k_lo + np.floor(rng.random((n, n_var)) * width).astype(np.intp)
    new = np.where(draw >= k, draw + 1, draw)  # skip the current value
    chosen &= width > 0
    return from_index(np.where(chosen, new, k), step=step)
