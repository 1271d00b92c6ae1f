"""``MoveAbsJ`` instructions and the thesis' random choice of them (Appendix D.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.abb import SPEEDS, ZONES
from joulepath.dynamics import Robot


@dataclass(frozen=True, slots=True)
class Move:
    """One ``MoveAbsJ``: joint target (rad), speeddata and zonedata names."""

    target: tuple[float, ...]
    speed: str
    zone: str


def random_moves(
    n_moves: int, lower: FloatArray, upper: FloatArray, *, rng: np.random.Generator
) -> list[Move]:
    """Random moves as thesis Appendix D.1 draws them.

    Targets uniform in ``[lower, upper]`` (rad); speed and zone indices
    ``1 + ROUND(RAND()/RAND_MAX * (N - 1))``, so the first and last entries come up
    half as often as the others.
    """
    speeds = list(SPEEDS)
    zones = list(ZONES)
    u = rng.random((n_moves, lower.size))
    targets = lower + u * (upper - lower)
    si = np.round(rng.random(n_moves) * (len(speeds) - 1)).astype(int)
    zi = np.round(rng.random(n_moves) * (len(zones) - 1)).astype(int)
    return [Move(tuple(float(x) for x in targets[k]), speeds[si[k]], zones[zi[k]]) for k in range(n_moves)]


def draw_moves(
    robot: Robot, n_moves: int, *, range_set: str = "collection", rng: np.random.Generator
) -> list[Move]:
    """``n_moves`` random moves inside one of the robot's range sets (nominal for a missing default one)."""
    _, lower, upper = robot.ranges_for(range_set)
    return random_moves(n_moves, lower, upper, rng=rng)
