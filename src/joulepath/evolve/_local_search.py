"""Local search operators of the memetic algorithm (thesis §2.3.4, App. F).

Each takes one individual ``x`` (n_var,) with its fitness ``f`` and returns a pair
``(x', f')`` with ``f' <= f``: the input itself when no candidate is strictly better.
Candidates are built as arrays and evaluated in whole batches.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from joulepath._typing import FloatArray
from joulepath.evolve._operators import IntArray, from_index, grid_limits, snap_to_grid, to_index
from joulepath.evolve._problem import Problem


def random_neighbours(
    x: FloatArray,
    n: int,
    xl: FloatArray,
    xu: FloatArray,
    *,
    step: float,
    radius: int,
    rng: np.random.Generator,
) -> FloatArray:
    """``n`` neighbours of ``x``: every gene moved by a uniform draw from ``{-radius..radius} * step``.

    With ``radius = 5`` and ``step = 0.05`` the offsets are the thesis' ``±{0, 0.05, …,
    0.25}`` (eq. 2.62). Neighbours are clipped to the bounds (on the grid).

    Returns
    -------
    ndarray of shape (n, n_var)
    """
    k_lo, k_hi = grid_limits(xl, xu, step=step)
    k = to_index(x, step=step) + rng.integers(-radius, radius + 1, size=(n, x.size))
    return from_index(np.clip(k, k_lo, k_hi), step=step)


def random_local_search(
    problem: Problem,
    x: FloatArray,
    f: float,
    *,
    n_samples: int,
    radius: int,
    batch_size: int,
    step: float,
    rng: np.random.Generator,
) -> tuple[FloatArray, float]:
    """Random local search: the best of ``n_samples`` random neighbours if better than ``x``.

    All neighbours are drawn around the *original* ``x``, as in the thesis listing, so
    keeping "each sample that beats the current best" (the thesis' loop) is the same as
    keeping the best sample when it beats ``x``. Evaluated in batches of ``batch_size``.
    """
    best_x, best_f = x, f
    remaining = n_samples
    while remaining > 0:
        m = min(batch_size, remaining)
        remaining -= m
        cand = random_neighbours(x, m, problem.xl, problem.xu, step=step, radius=radius, rng=rng)
        fc = problem.evaluate(cand)
        i = int(np.argmin(fc))
        if fc[i] < best_f:
            best_x, best_f = cand[i], float(fc[i])
    return best_x, best_f


def joint_genes(joints: Sequence[int], genes_per_joint: int) -> IntArray:
    """Gene indices of the given joints in a row-major (n_joints, genes_per_joint) chromosome."""
    j = np.asarray(joints, dtype=np.intp)
    out: IntArray = (j[:, None] * genes_per_joint + np.arange(genes_per_joint)).ravel()
    return out


def shrink_candidates(
    x: FloatArray,
    genes: IntArray,
    xl: FloatArray,
    xu: FloatArray,
    *,
    factor: float,
    steps: int,
    step: float,
) -> FloatArray:
    """``x`` with the given genes scaled by ``factor**s`` for ``s = 1..steps``, snapped to the grid.

    Returns
    -------
    ndarray of shape (steps, n_var)
    """
    cand = np.repeat(x[None, :], steps, axis=0)
    powers = factor ** np.arange(1, steps + 1, dtype=np.float64)
    cand[:, genes] = x[genes] * powers[:, None]
    return snap_to_grid(cand, xl, xu, step=step)


def informed_local_search(
    problem: Problem,
    x: FloatArray,
    f: float,
    *,
    joints: Sequence[int],
    genes_per_joint: int,
    factor: float,
    steps: int,
    step: float,
) -> tuple[FloatArray, float]:
    """Informed local search: shrink the coefficients of the most influential joints.

    Step ``s`` scales the coefficients of ``joints`` (ranked by feature importance of the
    data at hand; the thesis hard-coded joints 1 and 2, THESIS_NOTES defect 9) by
    ``factor**s``. The thesis applies the steps one after another and keeps a step when
    it improves; since step ``s`` does not depend on which earlier steps were kept, that
    equals evaluating the ``steps`` candidates at once and keeping the best when it beats
    ``x``. One ``problem.evaluate`` call; deterministic.
    """
    genes = joint_genes(joints, genes_per_joint)
    cand = shrink_candidates(x, genes, problem.xl, problem.xu, factor=factor, steps=steps, step=step)
    fc = problem.evaluate(cand)
    i = int(np.argmin(fc))
    if fc[i] < f:
        return cand[i], float(fc[i])
    return x, f
