"""What one run of a RAPID task gives: its moves, waits and other instructions (:class:`Trace`), and
what the interpreter asks of the robot (:class:`Kinematics`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

from joulepath._typing import FloatArray
from joulepath.rapid import _standins as standins
from joulepath.rapid import nodes as n
from joulepath.rapid.values import Record, num

Taint = frozenset[str]
CLEAN: Taint = frozenset()

ASSUMED_CHOICE = " (the branch taken on it is assumed)"
"""The end of a reason whose value is known once a branch decided at run time is assumed taken: data
set inside that branch, and the branch's own moves. The branch is stated (a note); what it runs is
known under that assumption, so it is planned, not kept as taught."""


def assumed(taint: Taint) -> Taint:
    """``taint`` as what runs inside a branch decided on it (its reasons marked :data:`ASSUMED_CHOICE`)."""
    return frozenset(r if r.endswith(ASSUMED_CHOICE) else r + ASSUMED_CHOICE for r in taint)


def run_time(taint: Taint) -> Taint:
    """The reasons of ``taint`` that are known only at run time, not under an assumed branch."""
    return frozenset(r for r in taint if not r.endswith(ASSUMED_CHOICE))


class Kinematics(Protocol):
    """What the interpreter asks of the robot (SI, 4x4 transforms of the flange in the base).

    ``q`` are the model's serial joints; a ``jointtarget``'s ``robax`` holds the controller's axis
    values, which ``axes_to_joints`` / ``joints_to_axes`` convert (the identity but for an arm
    whose axis 3 is coupled to axis 2); ``axes_outside`` says why axis values are refused by a
    range only the controller's axes have, or None.
    """

    def joints(
        self, flange: FloatArray, conf: tuple[int, int, int, int] | None, near: FloatArray | None
    ) -> FloatArray | None: ...

    def flange(self, q: FloatArray) -> FloatArray: ...

    def confdata(self, q: FloatArray) -> tuple[int, int, int, int]: ...

    def in_range(self, q: FloatArray) -> int | None: ...

    def reach_m(self) -> float | None: ...

    def axes_to_joints(self, axes: FloatArray) -> FloatArray: ...

    def joints_to_axes(self, q: FloatArray) -> FloatArray: ...

    def axes_outside(self, axes: FloatArray) -> str | None: ...


@dataclass(frozen=True, slots=True)
class MotionSettings:
    """The motion settings in force for a move, as the program set them."""

    acc_pct: float = 100.0
    ramp_pct: float = 100.0
    vel_override_pct: float = 100.0
    vel_max_mm_s: float | None = None
    conf_j: bool = True
    conf_l: bool = True
    sing_area: str = "Off"
    grip_load: Record | None = None
    grip_load_name: str = "load0"
    path_acc_lim: tuple[float | None, float | None] = (None, None)
    world_acc_lim: float | None = None


@dataclass(frozen=True, slots=True)
class Motion:
    """One move of the robot as the program commanded it.

    ``kind``: ``"joint"``, ``"linear"``, ``"circular"`` or ``"absjoint"``. ``target`` is a
    ``robtarget`` (in the work object ``wobj``) or a ``jointtarget``; ``circle`` the
    ``CirPoint`` of a circular move. ``speed`` and ``zone`` are the effective ones (``\\V``,
    ``\\Z`` applied). ``joints`` (rad) where a robot model was given. ``kept`` names why the
    move must stay as taught (empty: known). ``context`` is the call stack and loop indices.
    """

    instruction: str
    kind: str
    target: Record
    circle: Record | None
    speed: Record
    time_s: float | None
    zone: Record
    inpos: bool
    tool: Record
    wobj: Record
    tool_name: str
    wobj_name: str
    settings: MotionSettings
    conc: bool
    process: str | None
    stmt: n.Call
    context: tuple[str, ...]
    kept: Taint
    joints: FloatArray | None = field(default=None, compare=False)
    circle_joints: FloatArray | None = field(default=None, compare=False)
    target_text: str = ""

    @property
    def pos(self) -> n.Pos:
        return self.stmt.pos

    @property
    def fine(self) -> bool:
        return bool(self.zone.get("finep"))

    @property
    def zone_mm(self) -> float:
        return float(num(self.zone.get("pzone_tcp")))


@dataclass(frozen=True, slots=True)
class Wait:
    """A wait: ``WaitTime`` (``seconds``), or an I/O wait whose length is the process's (``io``)."""

    stmt: n.Call
    seconds: float
    inpos: bool
    io: bool
    context: tuple[str, ...]
    note: str = ""

    @property
    def pos(self) -> n.Pos:
        return self.stmt.pos


@dataclass(frozen=True, slots=True)
class Action:
    """Any other instruction the cycle runs (``SetDO``, ``TPWrite`` ...): kept, its time not modelled."""

    stmt: n.Call | n.LateCall | n.Assign
    name: str
    context: tuple[str, ...]

    @property
    def pos(self) -> n.Pos:
        return self.stmt.pos


Event = Motion | Wait | Action


@dataclass(frozen=True, slots=True)
class Trace:
    """What one run of the program did: its events, which of them are the cycle, and what was assumed.

    ``events[cycle_start:cycle_end]`` is the cycle; ``notes`` are one line each: a branch decided
    by the scenario or assumed, an input read with no value given, a loop cut at its first turn.
    ``loop`` is the production loop's position (None: the cycle is one run of the routine).
    """

    events: tuple[Event, ...]
    cycle_start: int
    cycle_end: int
    notes: tuple[str, ...]
    routine: str
    loop: n.Pos | None
    steps: int
    assumed: tuple[standins.Assumption, ...] = ()

    @property
    def cycle(self) -> tuple[Event, ...]:
        return self.events[self.cycle_start : self.cycle_end]

    @property
    def motions(self) -> tuple[Motion, ...]:
        return tuple(e for e in self.cycle if isinstance(e, Motion))
