"""What the controller emulation runs: the steps of a program (moves, waits) and their speed data.

The RAPID reader (:mod:`joulepath.program`) resolves a module into these steps; the
controller's timing (:mod:`joulepath.sim._timing`) runs them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot


@dataclass(frozen=True, slots=True)
class SpeedData:
    """``speeddata``: TCP speed (mm/s), reorientation (deg/s), external axes (mm/s, deg/s)."""

    v_tcp: float
    v_ori: float
    v_leax: float
    v_reax: float


@dataclass(frozen=True, slots=True, eq=False)
class Step:
    """One step of the cycle.

    ``kind`` is ``"move"``, ``"wait"`` or ``"fixed"`` (an instruction kept verbatim).
    For a move: the joint target (rad), whether the TCP moves on a straight line
    (``MoveL``), the speed, ``\\T`` (s), the zone radius (mm; None: a stop point), the
    tool (TCP in m as a 4x4 flange-to-TCP transform) and the robot carrying its load.
    ``idle``: a wait the user declared idle time that an optimizer may spend on the moves.
    ``kept``: why the move must run as taught (its target, speed or branch known only at run
    time ...; empty: an optimizer may reshape it). ``circle_q``: a ``MoveC``'s circle point
    (joint values, rad): the TCP moves on the circle through it. ``file``: the module the
    statement stands in (a task has several).

    The motion settings in force at a move (RAPID's ``AccSet`` and ``VelSet``, as ABB
    documents them; :mod:`joulepath.sim._timing` applies them): ``acc_pct``, the
    acceleration and deceleration in % of the controller's (``AccSet Acc``; below 20 it
    is 20), ``ramp_pct``, the rate of change of acceleration (the jerk) in % of the
    controller's (``AccSet Ramp``; below 10 it is 10); ``vel_override_pct``, the speeds
    of the speeddata and ``\\T`` in % of the programmed (``VelSet Override``: 50 halves
    the speeds and doubles a ``\\T``), ``vel_max_mm_s``, the highest TCP speed (``VelSet
    Max``; None: no cap).
    """

    kind: str
    line: int
    label: str
    statement: Any
    q: FloatArray | None = None
    linear: bool = False
    speed: SpeedData | None = None
    time_s: float | None = None
    zone_mm: float | None = None
    tcp: FloatArray | None = None
    robot: Robot | None = None
    seconds: float = 0.0
    repeated: bool = False
    idle: bool = False
    kept: tuple[str, ...] = ()
    circle_q: FloatArray | None = None
    file: str = ""
    acc_pct: float = 100.0
    ramp_pct: float = 100.0
    vel_override_pct: float = 100.0
    vel_max_mm_s: float | None = None


class StepSequence(Protocol):
    """What :func:`joulepath.sim.plan_cycle` runs: steps from a start configuration (rad)."""

    @property
    def steps(self) -> tuple[Step, ...]: ...

    @property
    def start(self) -> FloatArray: ...

    @property
    def source(self) -> str: ...
