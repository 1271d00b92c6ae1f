"""A RAPID module as joulepath reads it: declarations, procedures and statements.

Every statement keeps its first and last source line and its raw text, so a module
is written back unchanged wherever joulepath does not change it. Values are in the
program's units (mm, deg, mm/s, s) exactly as written; conversion to SI happens
where they are used (:mod:`joulepath.program._cycle`).
"""

from __future__ import annotations

from dataclasses import dataclass

from joulepath.errors import RapidError  # one definition: the RAPID language's
from joulepath.sim import SpeedData

__all__ = ["RapidError"]


@dataclass(frozen=True, slots=True)
class JointTarget:
    """``jointtarget``: robot axes (deg) and external axes."""

    joints_deg: tuple[float, ...]
    external: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class RobTarget:
    """``robtarget``: position (mm), quaternion ``(q1..q4)`` = (w, x, y, z), confdata, external axes."""

    position_mm: tuple[float, float, float]
    quaternion: tuple[float, float, float, float]
    conf: tuple[int, int, int, int]
    external: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class ZoneData:
    """``zonedata``: ``finep`` (a stop point) and the TCP zone radius ``pzone_tcp`` (mm)."""

    finep: bool
    pzone_tcp: float


@dataclass(frozen=True, slots=True)
class ToolData:
    """``tooldata``: TCP frame on the flange (mm, quaternion) and the load (kg, mm)."""

    robhold: bool
    tcp_mm: tuple[float, float, float]
    rotation: tuple[float, float, float, float]
    mass_kg: float
    cog_mm: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class WObjData:
    """``wobjdata``: a work object; only fixed ones (robhold FALSE, ufprog TRUE, ufmec "") are modelled.

    ``uframe`` and ``oframe`` are (position mm, quaternion w-first); a target given in
    the work object is at ``uframe * oframe * target`` in the base frame.
    """

    robhold: bool
    ufprog: bool
    ufmec: str
    uframe: tuple[tuple[float, float, float], tuple[float, float, float, float]]
    oframe: tuple[tuple[float, float, float], tuple[float, float, float, float]]

    @property
    def moving(self) -> bool:
        """Held by the robot or moved by a mechanical unit: not a fixed frame."""
        return self.robhold or not self.ufprog or bool(self.ufmec.strip())


@dataclass(frozen=True, slots=True)
class Offset:
    """One ``Offs`` or ``RelTool`` applied to a robtarget.

    ``Offs(p, dx, dy, dz)``: ``p`` displaced by (dx, dy, dz) mm in the frame the target is
    given in (the work object), same orientation. ``RelTool(p, dx, dy, dz \\Rx \\Ry \\Rz)``:
    displaced in the tool frame of ``p``, then turned about the tool's x, the new y and
    the new z axis by ``rotation_deg``.
    """

    kind: str
    displacement_mm: tuple[float, float, float]
    rotation_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True)
class TargetRef:
    """A target as a move (or a robtarget declaration) computes it: a declared target and offsets.

    ``name`` is a declared ``robtarget`` / ``jointtarget`` (or an array element ``NAME{k}``);
    ``offsets`` are applied in order (the innermost ``Offs`` / ``RelTool`` first).
    """

    name: str
    offsets: tuple[Offset, ...] = ()


Value = JointTarget | RobTarget | SpeedData | ZoneData | ToolData | WObjData | TargetRef | float


@dataclass(frozen=True, slots=True)
class Declaration:
    """``CONST|PERS|VAR type name := value;`` of a type joulepath reads (``num`` included).

    An array ``type name{n} := [v1, ..., vn];`` (one dimension; ``jointtarget``,
    ``robtarget`` or ``num``) holds its elements as a tuple; ``name{k}`` is element k
    (1-based, as in RAPID).
    """

    line: int
    end_line: int
    storage: str
    type: str
    name: str
    value: Value | tuple[Value, ...]


@dataclass(frozen=True, slots=True)
class Move:
    """``MoveAbsJ``, ``MoveJ`` or ``MoveL``: the arguments as written (names, numbers)."""

    line: int
    end_line: int
    instruction: str
    target: str
    speed: str
    v_tcp: float | None  # \V
    time_s: float | None  # \T
    zone: str
    z_tcp: float | None  # \Z
    tool: str
    wobj: str | None = None  # \WObj (None: wobj0, the base frame)
    target_ref: TargetRef | None = None  # Offs / RelTool or a procedure's argument; None: ``target``


@dataclass(frozen=True, slots=True)
class WaitTime:
    """``WaitTime [\\InPos,] seconds;``; ``idle``: marked ``! joulepath: idle`` (time to spend on moves)."""

    line: int
    end_line: int
    seconds: float
    inpos: bool = False
    idle: bool = False


@dataclass(frozen=True, slots=True)
class Call:
    """A call of a procedure of the module (``Name;`` or ``Name arg1, arg2;``).

    A procedure with parameters is read at each of its calls with the arguments bound:
    ``body`` holds its statements for this call (None: read once, ``Procedure.body``).
    """

    line: int
    end_line: int
    name: str
    args: tuple[str, ...] = ()
    body: tuple[Statement, ...] | None = None


@dataclass(frozen=True, slots=True)
class Verbatim:
    """Anything else: kept as written; its run time is not modelled (treated as fixed)."""

    line: int
    end_line: int
    text: str


@dataclass(frozen=True, slots=True)
class MotionSetting(Verbatim):
    """``AccSet Acc, Ramp;`` or ``VelSet Override, Max;`` (``text``: the instruction), kept as written.

    ``values``: its two numbers (``AccSet``: % of the acceleration and of its rate of
    change; ``VelSet``: % of the programmed speeds, the highest TCP speed in mm/s). It
    takes no modelled time; the moves after it run with it (:class:`joulepath.sim.Step`).
    """

    values: tuple[float, float] = (100.0, 100.0)


@dataclass(frozen=True, slots=True)
class WhileTrue:
    """``WHILE TRUE DO ... ENDWHILE``: the cycle when it is in ``main``."""

    line: int
    end_line: int
    body: tuple[Statement, ...]


@dataclass(frozen=True, slots=True)
class ForLoop:
    """``FOR var FROM first TO last [STEP step] DO ... ENDFOR`` with moves inside, unrolled.

    The bounds are constants (numbers or ``CONST num``), so the loop's runs are known
    when the module is read: ``runs`` holds the body once per value of the loop
    variable (``values``), each read with the variable bound (``OPT{k}`` names element
    k of an array). A statement of the body keeps its source line in every run.
    """

    line: int
    end_line: int
    variable: str
    values: tuple[int, ...]
    runs: tuple[tuple[Statement, ...], ...]


@dataclass(frozen=True, slots=True)
class Branch:
    """``IF`` / ``TEST`` with moves inside whose condition is known when the module is read.

    ``body`` is the branch the cycle runs; ``note`` says which and why, e.g.
    ``"line 12: IF bDoubleGrip (FALSE) -> ELSE branch"``.
    """

    line: int
    end_line: int
    note: str
    body: tuple[Statement, ...]


Statement = Move | WaitTime | Call | Verbatim | WhileTrue | ForLoop | Branch  # MotionSetting is a Verbatim


@dataclass(frozen=True, slots=True)
class Procedure:
    """``PROC name(params) ... ENDPROC``; ``params``: (type, name) pairs.

    A procedure with parameters is read at each call (:class:`Call` ``body``); its own
    ``body`` is then empty.
    """

    line: int
    end_line: int
    name: str
    body: tuple[Statement, ...]
    params: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True, slots=True)
class Module:
    """A parsed module: its name, declarations by name, procedures by name, and the source."""

    name: str
    declarations: tuple[Declaration, ...]
    procedures: tuple[Procedure, ...]
    source: tuple[str, ...]
    path: str

    def declaration(self, name: str) -> Declaration | None:
        for d in self.declarations:
            if d.name.lower() == name.lower():
                return d
        return None

    def procedure(self, name: str) -> Procedure | None:
        for p in self.procedures:
            if p.name.lower() == name.lower():
                return p
        return None

    def error(self, line: int, message: str) -> RapidError:
        return RapidError(f"{self.path}:{line}: {message}")
