"""The speed data of a program's ``MoveL`` lines, kept by a module written from a plan.

A ``MoveL``'s speed data is the programmer's bound on the TCP speed along its line (an approach
to a part at ``v200``, a retreat at ``v500``). The cycle's plan keeps it (between the blends at the
line's ends, :func:`joulepath.program._cycle_motion.line_bounds`); a via-point module written
from the plan replaces such a line by joint moves with ``\\T``, which the controller runs at
whatever speed their times give. This module finds each line's interior on the taught cycle as
the controller emulation runs it (from the end of the blend into the ``MoveL`` to the start of
the blend out of it), and measures how fast another motion moves its TCP there: a written module
whose TCP runs faster on a line than its speed data is not the program's motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.sim import PlannedCycle, PlannedMove, evaluate_cycle, tcp_pose

ON_LINE_M = 0.001
"""A TCP position this close (m) to a line's interior is on the line."""
ALONG = 0.5
"""A velocity runs a line's way where its angle to the line is under 60 degrees."""
SPEED_TOL = 0.01
"""Share by which a speed on a line may exceed the line's speed data (the 2.5 ms samples' own error)."""


@dataclass(frozen=True, slots=True)
class LineSpeed:
    """A ``MoveL``'s line between its blends (TCP positions in m) and its speed bound (m/s)."""

    line: int  # the statement's line in the program
    a: FloatArray
    b: FloatArray
    v: float
    speed_mm_s: float  # the speed data's TCP speed as written (mm/s)


def blends(plan: PlannedCycle) -> list[tuple[PlannedMove, float, float]]:
    """Each moving move of ``plan`` with the time (s) the controller blends the move before into it
    and it into the next (superposed; 0 where one stops first)."""
    moving = [m for m in plan.moves if m.profile.duration > 0]
    out: list[tuple[PlannedMove, float, float]] = []
    for k, m in enumerate(moving):
        into = max(0.0, moving[k - 1].t_end - m.t0) if k > 0 else 0.0
        out_of = max(0.0, m.t_end - moving[k + 1].t0) if k + 1 < len(moving) else 0.0
        out.append((m, into, out_of))
    return out


def line_speeds(plan: PlannedCycle) -> tuple[LineSpeed, ...]:
    """The interior of each ``MoveL`` line of the taught cycle ``plan`` with its speed bound: the
    speed data's ``v_tcp``, and ``v_ori`` over the line's turn as a TCP speed along it (the
    lesser), as the plan bounds it."""
    out: list[LineSpeed] = []
    for m, into, out_of in blends(plan):
        step = m.step
        if not step.linear or step.speed is None or step.robot is None or step.tcp is None:
            continue
        a, b = m.t0 + into, m.t_end - out_of  # after the blend into it, before the blend out of it
        if b - a <= 1e-6 or m.path.length_mm <= 1e-6:
            continue
        v = step.speed.v_tcp
        if m.path.angle_deg > 1e-6:
            v = min(v, step.speed.v_ori * m.path.length_mm / m.path.angle_deg)
        pos, _ = tcp_pose(step.robot, evaluate_cycle(plan, np.array([a, b])).q, step.tcp)
        out.append(LineSpeed(step.line, pos[0], pos[1], v / 1000.0, step.speed.v_tcp))
    return tuple(out)


def _on_line(line: LineSpeed, pos: FloatArray, vel: FloatArray) -> FloatArray:
    """Whether each position (..., 3) lies on the interior of ``line`` (within :data:`ON_LINE_M`)
    and its velocity ``vel`` (..., 3) runs the line's way (a line back over the same points is
    another ``MoveL``, with its own speed data)."""
    d = line.b - line.a
    length2 = float(d @ d)
    s = np.clip(((pos - line.a) @ d) / max(length2, 1e-18), 0.0, 1.0)
    near = np.linalg.norm(pos - (line.a + s[..., None] * d), axis=-1) <= ON_LINE_M
    along = vel @ d > ALONG * np.linalg.norm(vel, axis=-1) * np.sqrt(length2)
    out: FloatArray = near & along
    return out


def fastest_on_lines(
    lines: tuple[LineSpeed, ...], pos: FloatArray, vel: FloatArray
) -> tuple[float, LineSpeed | None]:
    """The largest ratio of a TCP speed (of the velocities ``vel``, m/s, at positions ``pos``) to the
    bound of the line it runs on, and that line (1.0 and None where none is faster)."""
    speed = np.linalg.norm(vel, axis=-1)
    worst, where = 1.0, None
    for line in lines:
        on = _on_line(line, pos, vel)
        if np.any(on):
            r = float(np.max(speed[on])) / line.v
            if r > worst:
                worst, where = r, line
    return worst, where


def chord_floor(lines: tuple[LineSpeed, ...], p0: FloatArray, p1: FloatArray) -> float:
    """The least time (s) in which the TCP may go from ``p0`` to ``p1`` where both lie on one
    line's interior (its length at the line's bound), else 0."""
    pair = np.vstack([p0, p1])
    way = np.vstack([p1 - p0, p1 - p0])
    best = 0.0
    for line in lines:
        if bool(np.all(_on_line(line, pair, way))):
            best = max(best, float(np.linalg.norm(p1 - p0)) / line.v)
    return best
