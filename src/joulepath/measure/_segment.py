"""Finding the moves from START to GOAL in a joint log, and telling default from optimized by shape."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.measure._plan import PlannedPath

POSITION_TOL_RAD = np.radians(0.25)
"""How close (every joint) the robot must be to START or GOAL to be there."""
REST_SPEED_RAD_S = np.radians(0.5)
"""Every joint slower than this: the robot is at rest."""
PATH_POINTS = 200
"""Points on which an executed move is compared with a planned path."""


@dataclass(frozen=True, slots=True)
class Window:
    """One move from START to GOAL in the log: sample indices ``first..last`` (both included).

    ``first`` is the last sample at rest at START before the robot leaves it; ``last``
    the first sample at rest at GOAL after it arrives.
    """

    first: int
    last: int


def find_moves(
    t: FloatArray,
    q: FloatArray,
    qd: FloatArray,
    start: FloatArray,
    goal: FloatArray,
    *,
    position_tol: float = POSITION_TOL_RAD,
    rest_speed: float = REST_SPEED_RAD_S,
) -> list[Window]:
    """Every move of the log from rest at ``start`` to rest at ``goal``, in time order.

    A departure is a sample at ``start`` followed by one away from it; the move ends
    at the first later sample at rest within ``position_tol`` of ``goal``. A departure
    that comes back to ``start`` (or reaches the log's end) before it reaches ``goal``
    is not a move of the plan and is skipped.
    """
    at_start = np.abs(q - start).max(axis=1) <= position_tol
    rest = np.abs(qd).max(axis=1) <= rest_speed
    at_goal = (np.abs(q - goal).max(axis=1) <= position_tol) & rest
    out: list[Window] = []
    k = 0
    n = t.size
    while k < n - 1:
        if not (at_start[k] and not at_start[k + 1]):
            k += 1
            continue
        first = k
        while first > 0 and not rest[first] and at_start[first - 1]:
            first -= 1  # back to rest: the move starts from standstill
        j = k + 1
        while j < n and not at_goal[j] and not at_start[j]:
            j += 1
        if j < n and at_goal[j]:
            out.append(Window(first, j))
        k = j
    return out


def _arc_resample(q: FloatArray, n: int) -> FloatArray:
    """``n`` points equally spaced along the joint-space path through the rows of ``q``."""
    step = np.linalg.norm(np.diff(q, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)])
    if s[-1] <= 0:
        return np.repeat(q[:1], n, axis=0)
    u = np.linspace(0.0, s[-1], n)
    return np.column_stack([np.interp(u, s, q[:, j]) for j in range(q.shape[1])])


def path_distance(q: FloatArray, planned: PlannedPath) -> float:
    """Mean distance (rad, largest joint) from an executed move's path to a planned path, timing aside.

    Both are resampled at equal arc length; each executed point is matched to the nearest
    planned point. Zero when the robot went along the planned path, whatever its speed.
    """
    a = _arc_resample(q, PATH_POINTS)
    b = _arc_resample(planned.q, 4 * PATH_POINTS)
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2).min(axis=1)
    return float(d.mean())


def tracking_error(t: FloatArray, q: FloatArray, planned: PlannedPath) -> tuple[float, float]:
    """Largest and RMS error (rad, over samples and joints) of a move against a planned path.

    ``t`` starts at the move's first sample (aligned with the path's start); after the
    path's end the planned position is its end.
    """
    err = np.abs(q - planned.at(t - t[0]))
    return float(err.max()), float(np.sqrt(np.mean(err * err)))
