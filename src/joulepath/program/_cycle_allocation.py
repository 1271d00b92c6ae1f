"""The cycle time shared among a cycle's units: pure functions over its time table.

The table holds, per unit (in the optimizer's order), the durations (s) and energies (J) of its
solved entries, which are usable (within every limit) and which is its taught motion. Two ways of
sharing a budget of time among the units:

* :func:`least_energy_choice`: one usable entry per unit, the least energy in all with the summed
  durations within the budget (dynamic programming on a grid of :data:`TIME_UNIT`);
* :func:`fitted_share`: durations in whole 25 ms samples from the curves ``E(T) = a + b/T + c/T²``
  (a, b, c ≥ 0) fitted to each unit's solved entries, the budget shared on them by SLSQP (the units
  are then solved at those durations by the caller).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from joulepath._typing import FloatArray
from joulepath.sim import FINE_DT

TIME_UNIT = FINE_DT
"""s: the resolution at which the time budget is shared (taught durations are not whole samples)."""


@dataclass(frozen=True, slots=True, eq=False)
class UnitEntries:
    """One unit's entries of the time table, in the table's order."""

    durations: FloatArray  # s
    energies: FloatArray  # J, on the cycle's measure
    usable: NDArray[np.bool_]  # within every limit (and clear of the cell)
    taught: NDArray[np.bool_]  # the unit's taught motion (not re-solved)


def least_energy_choice(table: Sequence[UnitEntries], budget: float) -> tuple[int, ...] | None:
    """The least-energy choice of one usable entry per unit (its index in the unit's entries) with
    ``Σ durations ≤ budget``, on a grid of :data:`TIME_UNIT` (each duration rounded up; the choice is
    checked in exact time, and the grid's budget tightened where the rounding let it over). None
    where no choice fits."""
    if not table:
        return ()
    n_units = len(table)
    cap = int(np.floor(budget / TIME_UNIT + 1e-9)) + n_units
    while cap >= 0:
        best = np.full(cap + 1, np.inf)
        best[0] = 0.0
        choice: list[np.ndarray] = []
        for unit in table:
            new = np.full(cap + 1, np.inf)
            pick = np.full(cap + 1, -1)
            for k in range(unit.durations.size):
                if not unit.usable[k]:
                    continue
                u = int(np.ceil(unit.durations[k] / TIME_UNIT - 1e-6))
                if u > cap:
                    continue
                cand = np.full(cap + 1, np.inf)
                cand[u:] = best[: cap + 1 - u] + unit.energies[k]
                better = cand < new
                new[better] = cand[better]
                pick[better] = k
            choice.append(pick)
            best = new
        end = int(np.argmin(best))
        if not np.isfinite(best[end]):
            return None
        out: list[int] = []
        u = end
        total = 0.0
        for unit, pick in zip(reversed(table), reversed(choice), strict=True):
            k = int(pick[u])
            out.append(k)
            total += float(unit.durations[k])
            u -= int(np.ceil(unit.durations[k] / TIME_UNIT - 1e-6))
        if total <= budget + 1e-9:
            return tuple(reversed(out))
        cap = end - 1  # the rounding let it over the budget: a tighter grid budget
    return None


def fitted_share(
    table: Sequence[UnitEntries],
    lo: FloatArray,
    fixed: NDArray[np.bool_],
    budget: float,
    *,
    step: float,
) -> NDArray[np.int_] | None:
    """Each unit's duration, in whole samples of ``step`` s, from the budget shared on the curves
    ``a + b/T + c/T²`` fitted (non-negative least squares) to its usable solved entries (its taught
    motion left out): SLSQP between each unit's shortest ``lo`` and its longest solved duration, then
    the samples left handed one by one to the steepest curves. A ``fixed`` unit keeps ``lo``. None
    where a unit has no usable solved entry or the budget does not reach every unit's shortest."""
    from scipy.optimize import minimize, nnls

    coef = []
    for unit in table:
        sel = unit.usable & ~unit.taught
        if not sel.any():
            return None
        T = unit.durations[sel]
        E = unit.energies[sel]
        A = np.column_stack([np.ones_like(T), 1 / T, 1 / T**2])
        c, _ = nnls(A, E) if T.size >= 2 else (np.array([E[0], 0.0, 0.0]), 0.0)
        coef.append(c)
    if not table:
        return None
    C = np.array(coef)
    if lo.sum() > budget + 1e-9:
        return None
    hi = np.array([unit.durations[~unit.taught].max() for unit in table])
    hi = np.maximum(hi, lo)

    def f(T: FloatArray) -> tuple[float, FloatArray]:
        e = C[:, 0] + C[:, 1] / T + C[:, 2] / T**2
        g = -C[:, 1] / T**2 - 2 * C[:, 2] / T**3
        return float(e.sum()), g

    x0 = np.clip(lo + (budget - lo.sum()) * (hi - lo) / max((hi - lo).sum(), 1e-9), lo, hi)
    res = minimize(
        f,
        x0,
        jac=True,
        method="SLSQP",
        bounds=list(zip(lo, hi, strict=True)),
        constraints=[{"type": "ineq", "fun": lambda T: budget - T.sum(), "jac": lambda T: -np.ones_like(T)}],
        options={"maxiter": 200, "ftol": 1e-10},
    )
    T = np.clip(np.asarray(res.x, dtype=float), lo, hi)
    units = np.maximum(np.floor(T / step + 1e-9), np.ceil(lo / step - 1e-9)).astype(int)
    units[fixed] = np.round(lo[fixed] / step).astype(int)  # their duration stays
    spare = int(np.floor(budget / step + 1e-9)) - int(units.sum())
    while spare > 0 and not fixed.all():  # hand the remaining samples to the steepest curves
        _, g = f(units * step)
        k = int(np.argmin(np.where(fixed, np.inf, g)))
        units[k] += 1
        spare -= 1
    if units.sum() * step > budget + 1e-9:
        return None
    out: NDArray[np.int_] = units
    return out
