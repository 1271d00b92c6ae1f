"""A RAPID module as joulepath reads it: declarations, procedures and statements.

Every statement keeps its first and last source line and its raw text, so a module
is written back unchanged wherever joulepath does not change it. Values are in the
program's units (mm, deg, mm/s, s) exactly as written; conversion to SI happens
where they are used (:mod:`joulepath.program._cycle`).
"""

from __future__ import annotations

from dataclasses import dataclass

from joulepath.errors import InvalidInput
from joulepath.sim._steps import SpeedData


class RapidError(InvalidInput):
    """A RAPID program joulepath cannot read: the message starts with ``file:line:``."""


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


Value = JointTarget | RobTarget | SpeedData | ZoneData | ToolData | float


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


@dataclass(frozen=True, slots=True)
class WaitTime:
    """``WaitTime seconds;``."""

    line: int
    end_line: int
    seconds: float


@dataclass(frozen=True, slots=True)
class Call:
    """A call of a procedure of the module without arguments (``Name;``)."""

    line: int
    end_line: int
    name: str


@dataclass(frozen=True, slots=True)
class Verbatim:
    """Anything else: kept as written; its run time is not modelled (treated as fixed)."""

    line: int
    end_line: int
    text: str


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


Statement = Move | WaitTime | Call | Verbatim | WhileTrue | ForLoop


@dataclass(frozen=True, slots=True)
class Procedure:
    """``PROC name() ... ENDPROC`` (no parameters)."""

    line: int
    end_line: int
    name: str
    body: tuple[Statement, ...]


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
