"""Work bounded before it starts (foundation): the documented limits on what one command may compute.

Each limit has a default and an environment variable that changes it, e.g.
``JOULEPATH_MAX_MOTION_S=600 joulepath cycle long.mod ...``. A program, cell or option
whose implied size (seconds of motion, moves, obstacles, triangles) is over a limit is
refused before any work, with one line that names the limit, its variable and what to
change in the input::

    name          default  what it bounds
    motion_s      3600     seconds the moves of one cycle take together (at the default or given cycle time)
    move_s        10       seconds one move to be optimized takes (its solve grows with the duration;
                           moves joined by zones into one fly-by chain count as one move)
    moves         10000    moves in one cycle
    obstacles     1000     obstacles of a cell (boxes, cylinders, spheres, meshes)
    triangles     200000   triangles of all the meshes of a cell together
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from joulepath.errors import InvalidInput


@dataclass(frozen=True, slots=True)
class WorkLimit:
    """One limit: its default and what it counts (for messages)."""

    default: float
    counts: str

    def env(self, name: str) -> str:
        """The environment variable that changes the limit ``name``."""
        return f"JOULEPATH_MAX_{name.upper()}"


WORK_LIMITS: dict[str, WorkLimit] = {
    "motion_s": WorkLimit(3600.0, "s of motion in one cycle"),
    "move_s": WorkLimit(10.0, "s of one move to optimize"),
    "moves": WorkLimit(10_000, "moves in one cycle"),
    "obstacles": WorkLimit(1000, "obstacles in a cell"),
    "triangles": WorkLimit(200_000, "mesh triangles in a cell"),
}
"""The limits by name (see the module docstring)."""


def work_limit(name: str) -> float:
    """The limit ``name``: its environment variable if set to a positive number, else its default.

    Raises
    ------
    InvalidInput
        The environment variable is set but is not a positive finite number.
    """
    spec = WORK_LIMITS[name]
    raw = os.environ.get(spec.env(name))
    if raw is None or not raw.strip():
        return spec.default
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise InvalidInput(f"{spec.env(name)}={raw[:40]!r}: give a positive number (or unset it)")
    return value


def check_work(name: str, value: float, where: str, fix: str) -> None:
    """Refuse ``value`` of the limit ``name`` when it is over the limit (one line, before any work).

    Parameters
    ----------
    name : str
        A key of :data:`WORK_LIMITS`.
    value : float
        What the input implies (e.g. the seconds its moves take).
    where : str
        The input, for the message (a file, a file and line, an option).
    fix : str
        What to change in the input to stay within the limit.

    Raises
    ------
    InvalidInput
        ``value`` is over the limit, or not a finite number.
    """
    limit = work_limit(name)
    spec = WORK_LIMITS[name]
    if not value <= limit:  # also NaN and infinity
        raise InvalidInput(
            f"{where}: {value:.6g} {spec.counts}, over the limit of {limit:g} (set {spec.env(name)} to "
            f"change it); {fix}"
        )
