"""A strict reader of the RAPID subset joulepath optimizes; every error names its line.

Keywords, instructions and names are read in any case (``MoveJ`` / ``movej``), and the
``%%%`` header of a saved module is skipped (line numbers kept).

Read (and checked): ``MODULE`` / ``ENDMODULE``; ``PROC name(params)`` / ``ENDPROC`` (an
``ERROR`` / ``UNDO`` / ``BACKWARD`` handler is kept verbatim, never part of the cycle);
``CONST`` / ``PERS`` / ``VAR`` declarations of ``jointtarget``, ``robtarget`` (a literal or
``Offs`` / ``RelTool`` of another), ``speeddata``, ``zonedata``, ``tooldata``,
``wobjdata``, ``num`` and ``bool``; predefined ``v5`` .. ``v7000``, ``vmax``, ``fine``,
``z0`` .. ``z200``, ``tool0``, ``wobj0``; ``MoveAbsJ`` / ``MoveJ`` / ``MoveL`` with ``\\V``,
``\\T``, ``\\Z``, ``\\WObj`` (a fixed work object) and ``\\NoEOffs`` on ``MoveAbsJ``, to a
declared target, an array element, ``Offs(p, dx, dy, dz)`` or ``RelTool(p, dx, dy, dz
\\Rx \\Ry \\Rz)`` with constant arguments; ``WaitTime [\\InPos,] t`` (``t`` a constant
expression; ``! joulepath: idle`` marks idle time); ``WHILE TRUE DO`` in ``main``;
calls of the module's procedures, with arguments (num, bool, targets, speeds, zones,
tools, work objects) substituted: the callee is read at each call; one-dimensional
arrays; ``FOR`` loops with constant bounds, unrolled; ``IF`` / ``TEST`` with moves
inside whose conditions are constant (``CONST`` / ``PERS`` num and bool no statement
assigns; a ``PERS`` reads as declared): the chosen branch is read and the choice noted.

Kept verbatim, their run time treated as fixed: every other instruction
(``SetDO``, ``WaitDI``, ``TPWrite``, ``PDispOff`` ...), declarations of other types,
``FUNC`` and ``TRAP`` routines, and blocks without a move inside.

Refused (:class:`RapidError`, one line ``file:line: what; how to fix``): syntax
errors, unknown names, arguments joulepath does not model (``\\Conc``, ``\\ID``, ...),
moving work objects, other motion instructions (``MoveC``, ``SearchL`` ...),
instructions that change how the robot moves (``PDispOn``, ``PDispSet``, ``EOffsSet``,
``ConfJ \\Off`` ...; ``AccSet Acc, Ramp`` and ``VelSet Override, Max`` are read, as
:class:`~joulepath.program._model.MotionSetting`), targets computed while the program runs
(``CRobT``, a target some statement assigns), moves under conditions known only at run
time, in other ``WHILE`` loops, and in FOR loops whose bounds are not constants.
Reading never executes anything.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from joulepath._io import read_capped
from joulepath.program._model import (
    Branch,
    Call,
    Declaration,
    ForLoop,
    JointTarget,
    Module,
    MotionSetting,
    Move,
    Offset,
    Procedure,
    RapidError,
    RobTarget,
    Statement,
    TargetRef,
    ToolData,
    Value,
    Verbatim,
    WaitTime,
    WhileTrue,
    WObjData,
    ZoneData,
)
from joulepath.sim import SpeedData

READ_TYPES = ("jointtarget", "robtarget", "speeddata", "zonedata", "tooldata", "wobjdata", "num")
MOVES = ("MoveAbsJ", "MoveJ", "MoveL")
OTHER_MOTION = re.compile(
    r"^(Move\w*|Search[LCJ]\w*|Trigg[LCJ]\w*|Cap[LC]\w*|Arc\w*|Spot\w*|StartMove\w*|StopMove\w*|"
    r"StorePath|RestoPath|ClearPath)$",
    re.IGNORECASE,
)
MOTION_SETTINGS = (
    "VelSet",
    "AccSet",
    "PathAccLim",
    "WorldAccLim",
    "SingArea",
    "CirPathMode",
    "ConfJ",
    "ConfL",
    "GripLoad",
    "MotionSup",
    "SoftAct",
    "PDispOn",
    "PDispSet",
    "EOffsOn",
    "EOffsSet",
    "PathResol",
    "TuneServo",
    "SpeedRefresh",
    "SpeedLimAxis",
    "SpeedLimCheckPoint",
    "CorrCon",
    "SyncMoveOn",
)
MAX_RUNS = 10_000
"""Most runs of one FOR loop with moves inside that are unrolled."""
MAX_UNROLLED = 100_000
"""Most runs of all such FOR loops of a module together (nested runs count each)."""
MAX_NESTING = 32
"""Deepest nesting of blocks (IF, FOR, TEST, WHILE), calls and aggregate or expression brackets."""
MAX_MODULE_BYTES = 8 << 20
"""Largest RAPID module read (a controller's program memory holds a few MB)."""
_FOR = re.compile(
    r"FOR\s+([A-Za-z]\w*)\s+FROM\s+(.+?)\s+TO\s+(.+?)(?:\s+STEP\s+(.+?))?\s+DO", re.IGNORECASE | re.DOTALL
)
BLOCK_CLOSE = {"IF": "ENDIF", "FOR": "ENDFOR", "WHILE": "ENDWHILE", "TEST": "ENDTEST"}
_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")

# predefined data (RobotWare): speeddata v5..v7000 and vmax, zonedata fine, z0..z200, tool0, wobj0
PREDEFINED_SPEEDS = {
    f"v{v}": SpeedData(float(v), 500.0, 5000.0, 1000.0)
    for v in (5, 10, 20, 30, 40, 50, 60, 80, 100, 150, 200, 300, 400, 500, 600, 800, 1000)
    + (1500, 2000, 2500, 3000, 4000, 5000, 6000, 7000)
} | {"vmax": SpeedData(5000.0, 500.0, 5000.0, 1000.0)}
"""``vmax``: 5000 mm/s TCP as declared in RobotWare's base module (the manual names the robot's
``MaxRobSpeed`` for its TCP speed; the joint speed limits bound the motion either way)."""
PREDEFINED_ZONES = {"fine": ZoneData(True, 0.0)} | {
    f"z{z}": ZoneData(False, float(z) if z else 0.3)
    for z in (0, 1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200)
}
TOOL0 = ToolData(True, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 0.0, (0.0, 0.0, 0.0))
WOBJ0 = WObjData(
    False, True, "", ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)), ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
)


@dataclass(frozen=True, slots=True)
class Unit:
    """One logical statement: first and last line, text without comments."""

    line: int
    end_line: int
    text: str

    @property
    def head(self) -> str:
        words = self.text.split()
        while words and words[0].upper() in ("LOCAL", "TASK"):
            words = words[1:]
        return re.split(r"[\s\\;(:,]", words[0], maxsplit=1)[0] if words else ""


def _opens_block_line(text: str) -> bool:
    head = text.split()[0].upper() if text.split() else ""
    while head in ("LOCAL", "TASK") and len(text.split()) > 1:
        text = text.split(None, 1)[1]
        head = text.split()[0].upper()
    up = text.rstrip().upper()
    if head in ("MODULE", "ENDMODULE", "PROC", "ENDPROC", "FUNC", "ENDFUNC", "TRAP", "ENDTRAP"):
        return True
    if head in (
        "ENDIF",
        "ENDFOR",
        "ENDWHILE",
        "ENDTEST",
        "ELSE",
        "DEFAULT:",
        "DEFAULT",
        "BACKWARD",
        "ERROR",
        "UNDO",
    ):
        return True
    if head in ("IF", "ELSEIF") and up.endswith("THEN"):
        return True
    if head in ("WHILE", "FOR") and up.endswith("DO"):
        return True
    if head in ("TEST",):
        return True
    return head == "CASE" and up.endswith(":")


def _statement_text(buf: list[str], first: int) -> str:
    """Enough of the statement in ``buf`` (content from ``first``) for :func:`_opens_block_line`.

    Its first words and its last characters, so the test at each line end costs the
    same however long the statement already is (the splitter stays linear in the text).
    """
    if len(buf) - first <= 512:
        return "".join(buf[first:]).strip()
    last = len(buf)
    while last > first and buf[last - 1].isspace():
        last -= 1
    return "".join(buf[first : first + 256]) + " " + "".join(buf[max(first, last - 16) : last])


def split_units(path: str, text: str) -> list[Unit]:
    """Statements of a RAPID source: comments removed, strings kept, line numbers kept.

    One pass, linear in the text (a statement of a megabyte costs what its characters cost).
    """
    units: list[Unit] = []
    buf: list[str] = []
    first: int | None = None  # index in buf of the statement's first non-space character
    start = 0
    line = 1
    depth = 0
    i = 0
    n = len(text)
    in_string = False
    while i < n:
        ch = text[i]
        if in_string:
            buf.append(ch)
            if ch == '"':
                if i + 1 < n and text[i + 1] == '"':
                    buf.append('"')
                    i += 1
                else:
                    in_string = False
            elif ch == "\n":
                raise RapidError(f'{path}:{line}: a string is not closed on its line; add the closing "')
            i += 1
            continue
        if ch == "!":
            while i < n and text[i] != "\n":
                i += 1
            continue
        if ch == "\n":
            if first is not None and depth == 0 and _opens_block_line(_statement_text(buf, first)):
                units.append(Unit(start, line, "".join(buf[first:]).strip()))
                buf, first = [], None
            line += 1
            i += 1
            if first is None:
                buf = []
                start = line
            elif not buf[-1].isspace():
                buf.append(" ")
            continue
        if first is None:
            start = line
        if ch == '"':
            in_string = True
        elif ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
            if depth < 0:
                raise RapidError(f"{path}:{line}: unbalanced {ch!r}; remove it or add its opening bracket")
        elif ch == ";" and depth == 0:
            buf.append(ch)
            units.append(Unit(start, line, "".join(buf).strip()))
            buf, first = [], None
            i += 1
            continue
        elif ch == ";":
            raise RapidError(f"{path}:{line}: ';' inside brackets; close the brackets before the ';'")
        if first is None and not ch.isspace():
            first = len(buf)
        buf.append(ch)
        i += 1
    rest = "".join(buf).strip()
    if rest:
        if _opens_block_line(rest):
            units.append(Unit(start, line, rest))
        else:
            raise RapidError(f"{path}:{start}: statement {rest[:40]!r} does not end with ';'; add the ';'")
    return units


# ---------------------------------------------------------------- aggregates
def _aggregate(path: str, line: int, text: str) -> object:
    """A literal: number, TRUE/FALSE, or ``[ ... ]`` of literals (nested lists)."""
    pos = 0

    def fail(what: str) -> RapidError:
        return RapidError(f"{path}:{line}: {what} in the value {text.strip()[:60]!r}")

    def skip() -> None:
        nonlocal pos
        while pos < len(text) and text[pos].isspace():
            pos += 1

    def value(depth: int = 0) -> object:
        nonlocal pos
        skip()
        if pos >= len(text):
            raise fail("a value is missing")
        if text[pos] == "[":
            if depth >= MAX_NESTING:
                raise fail(f"brackets nested more than {MAX_NESTING} deep")
            pos += 1
            items: list[object] = []
            skip()
            if pos < len(text) and text[pos] == "]":
                pos += 1
                return items
            while True:
                items.append(value(depth + 1))
                skip()
                if pos < len(text) and text[pos] == ",":
                    pos += 1
                    continue
                if pos < len(text) and text[pos] == "]":
                    pos += 1
                    return items
                raise fail("',' or ']' expected")
        if text[pos] == '"':  # a string (wobjdata ufmec); "" inside is one quote
            end = pos + 1
            chars: list[str] = []
            while end < len(text):
                if text[end] == '"':
                    if text[end + 1 : end + 2] == '"':
                        chars.append('"')
                        end += 2
                        continue
                    pos = end + 1
                    return "".join(chars)
                chars.append(text[end])
                end += 1
            raise fail("a string is not closed")
        m = _NUMBER.match(text, pos)
        if m:
            pos = m.end()
            number = float(m.group())
            if not math.isfinite(number):
                raise fail(f"{m.group()[:20]} is not a finite number (RAPID holds at most 3.4E38)")
            return number
        for word, v in (("TRUE", True), ("FALSE", False)):
            if text[pos : pos + len(word)].upper() == word:
                pos += len(word)
                return v
        raise fail("a number, TRUE/FALSE or '[' expected (names and expressions are not read here)")

    out = value()
    skip()
    if pos != len(text):
        raise fail("unexpected text after the value")
    return out


def _nums(path: str, line: int, item: object, size: int, what: str) -> tuple[float, ...]:
    if not isinstance(item, list) or len(item) != size or not all(isinstance(v, float) for v in item):
        raise RapidError(f"{path}:{line}: {what} needs [{size} numbers]")
    return tuple(float(v) for v in item)


def _value(path: str, line: int, type_: str, text: str) -> Value:
    return _value_of(path, line, type_, _aggregate(path, line, text), text)


def _value_of(path: str, line: int, type_: str, agg: object, text: str) -> Value:
    """A value of ``type_`` from its parsed aggregate (``text``: how it was written, for messages)."""
    if type_ == "num":
        if not isinstance(agg, float):
            raise RapidError(f"{path}:{line}: a num value must be a number, got {text.strip()!r}")
        return agg
    if not isinstance(agg, list):
        raise RapidError(f"{path}:{line}: a {type_} value is an aggregate [...], got {text.strip()!r}")
    if type_ == "jointtarget":
        if len(agg) != 2:
            raise RapidError(f"{path}:{line}: jointtarget needs [[6 axes], [6 external axes]]")
        return JointTarget(_nums(path, line, agg[0], 6, "robax"), _nums(path, line, agg[1], 6, "extax"))
    if type_ == "robtarget":
        if len(agg) != 4:
            raise RapidError(
                f"{path}:{line}: robtarget needs [[x,y,z], [q1,q2,q3,q4], [cf1,cf4,cf6,cfx], "
                "[6 external axes]]"
            )
        pos = _nums(path, line, agg[0], 3, "trans")
        quat = _nums(path, line, agg[1], 4, "rot")
        conf = _nums(path, line, agg[2], 4, "robconf")
        if any(c != round(c) for c in conf):
            raise RapidError(f"{path}:{line}: robconf values are integers, got {list(conf)}")
        norm = sum(v * v for v in quat) ** 0.5
        if abs(norm - 1.0) > 1e-3:
            raise RapidError(
                f"{path}:{line}: the orientation quaternion has norm {norm:.5f}, not 1; normalize it"
            )
        ext = _nums(path, line, agg[3], 6, "extax")
        c = tuple(int(round(v)) for v in conf)
        return RobTarget(
            (pos[0], pos[1], pos[2]), (quat[0], quat[1], quat[2], quat[3]), (c[0], c[1], c[2], c[3]), ext
        )
    if type_ == "speeddata":
        v = _nums(path, line, agg, 4, "speeddata")
        if v[0] <= 0 or v[1] <= 0:
            raise RapidError(f"{path}:{line}: speeddata v_tcp and v_ori must be positive, got {list(v)}")
        return SpeedData(*v)
    if type_ == "zonedata":
        if not isinstance(agg, list) or len(agg) != 7 or not isinstance(agg[0], bool):
            raise RapidError(
                f"{path}:{line}: zonedata needs [finep, pzone_tcp, pzone_ori, pzone_eax, zone_ori, "
                "zone_leax, zone_reax]"
            )
        rest = _nums(path, line, agg[1:], 6, "zonedata")
        if rest[0] < 0:
            raise RapidError(f"{path}:{line}: zonedata pzone_tcp must be ≥ 0, got {rest[0]:g}")
        return ZoneData(bool(agg[0]), rest[0])
    if type_ == "wobjdata":
        return _wobjdata(path, line, agg)
    # tooldata
    if (
        len(agg) != 3
        or not isinstance(agg[0], bool)
        or not isinstance(agg[1], list)
        or not isinstance(agg[2], list)
    ):
        raise RapidError(
            f"{path}:{line}: tooldata needs [robhold, [[x,y,z],[q1..q4]], [mass, [cog], [aom], ix, iy, iz]]"
        )
    frame, load = agg[1], agg[2]
    if len(frame) != 2 or len(load) != 6:
        raise RapidError(
            f"{path}:{line}: tooldata needs [robhold, [[x,y,z],[q1..q4]], [mass, [cog], [aom], ix, iy, iz]]"
        )
    tcp = _nums(path, line, frame[0], 3, "tframe.trans")
    rot = _nums(path, line, frame[1], 4, "tframe.rot")
    if not isinstance(load[0], float) or load[0] < 0:
        raise RapidError(f"{path}:{line}: tooldata load mass must be a number ≥ 0")
    cog = _nums(path, line, load[1], 3, "tload.cog")
    if not agg[0]:
        raise RapidError(
            f"{path}:{line}: a stationary tool (robhold FALSE) is not supported; use a tool the robot holds"
        )
    return ToolData(
        True,
        (tcp[0], tcp[1], tcp[2]),
        (rot[0], rot[1], rot[2], rot[3]),
        float(load[0]),
        (cog[0], cog[1], cog[2]),
    )


def _wobjdata(path: str, line: int, agg: list[object]) -> WObjData:
    shape = "wobjdata needs [robhold, ufprog, ufmec, [[x,y,z],[q1..q4]], [[x,y,z],[q1..q4]]]"
    if (
        len(agg) != 5
        or not isinstance(agg[0], bool)
        or not isinstance(agg[1], bool)
        or not isinstance(agg[2], str)
    ):
        raise RapidError(f"{path}:{line}: {shape}")
    frames = []
    for item, what in ((agg[3], "uframe"), (agg[4], "oframe")):
        if not isinstance(item, list) or len(item) != 2:
            raise RapidError(f"{path}:{line}: {shape} ({what} is not [[x,y,z],[q1..q4]])")
        pos = _nums(path, line, item[0], 3, f"{what}.trans")
        rot = _nums(path, line, item[1], 4, f"{what}.rot")
        norm = sum(v * v for v in rot) ** 0.5
        if abs(norm - 1.0) > 1e-3:
            raise RapidError(f"{path}:{line}: the {what} quaternion has norm {norm:.5f}, not 1; normalize it")
        frames.append(((pos[0], pos[1], pos[2]), (rot[0], rot[1], rot[2], rot[3])))
    return WObjData(agg[0], agg[1], agg[2], frames[0], frames[1])


_DECL = re.compile(
    r"^(?:(?:LOCAL|TASK)\s+)?(CONST|PERS|VAR)\s+([A-Za-z]\w*)\s+([A-Za-z]\w*)\s*(\{[^}]*\})?\s*(?::=\s*(.*))?;$",
    re.IGNORECASE | re.DOTALL,
)


def _declaration(path: str, unit: Unit, names: Names) -> Declaration | None:
    """A declaration of a type joulepath reads; None: another type, or a value read where it is used.

    A ``robtarget`` may be computed from another one (``:= Offs(pB, 0, 0, 50)``). A target
    without a value is refused where a move goes to it (``names.novalue``).
    """
    m = _DECL.match(unit.text)
    if not m:
        raise RapidError(f"{path}:{unit.line}: cannot read the declaration {unit.text[:60]!r}")
    storage, type_, name, dims, value = m.groups()
    type_l = type_.lower()
    if type_l not in READ_TYPES:
        return None
    if dims:
        return _array_declaration(path, unit, storage, type_l, name, dims, value)
    if value is None:
        if type_l != "num":
            names.novalue[name.lower()] = unit.line
        return None
    if type_l == "robtarget" and _CALL.match(value.strip()):
        ref = _target_ref(path, unit.line, value.strip(), names, f"the value of {name}")
        return Declaration(unit.line, unit.end_line, storage.upper(), type_l, name, ref)
    try:
        parsed = _value(path, unit.line, type_l, value)
    except RapidError:
        if type_l == "num":  # an expression: its value where the module's constants give it
            try:
                number = _evaluate(path, unit.line, value, names, f"the value of {name}")
            except RapidError:
                return None  # kept verbatim, refused only where a move needs it
            if isinstance(number, bool):
                return None
            return Declaration(unit.line, unit.end_line, storage.upper(), type_l, name, number)
        raise
    return Declaration(unit.line, unit.end_line, storage.upper(), type_l, name, parsed)


ARRAY_TYPES = ("jointtarget", "robtarget", "num", "speeddata", "zonedata")
"""Types whose one-dimensional arrays are read (their elements are indexed by a FOR loop's variable)."""
_NAME_LIST = re.compile(r"^\s*\[\s*([A-Za-z]\w*(?:\s*,\s*[A-Za-z]\w*)*)\s*\]\s*$", re.DOTALL)


def _predefined_list(path: str, line: int, type_: str, name: str, text: str) -> list[Value] | None:
    """``[v100, v200, ...]`` / ``[fine, z10, ...]``: predefined data by name; None: not such a list."""
    m = _NAME_LIST.match(text)
    if m is None or type_ not in ("speeddata", "zonedata"):
        return None
    table: dict[str, SpeedData] | dict[str, ZoneData] = (
        PREDEFINED_SPEEDS if type_ == "speeddata" else PREDEFINED_ZONES
    )
    out: list[Value] = []
    for k, item in enumerate(re.split(r"\s*,\s*", m.group(1).strip())):
        if item.lower() not in table:
            raise RapidError(
                f"{path}:{line}: element {k + 1} of {name} is {item!r}; an array of {type_} holds predefined "
                f"names ({'v5 .. v7000' if type_ == 'speeddata' else 'fine, z0 .. z200'}) or literal values"
            )
        out.append(table[item.lower()])
    return out


def _array_declaration(
    path: str, unit: Unit, storage: str, type_: str, name: str, dims: str, value: str | None
) -> Declaration | None:
    """``type name{n} := [v1, ..., vn];``: the elements as a tuple (one dimension, literal values)."""
    size = dims.strip()[1:-1].strip()
    if type_ not in ARRAY_TYPES:
        raise RapidError(
            f"{path}:{unit.line}: arrays of {type_} are not supported; declare each {type_} by name"
        )
    if not re.fullmatch(r"\d+", size) or int(size) < 1:
        if type_ == "num":  # kept verbatim, refused only where a move needs it
            return None
        raise RapidError(
            f"{path}:{unit.line}: the array {name}{dims} needs one positive whole size, e.g. {name}{{4}}"
        )
    n = int(size)
    if value is None:
        if type_ == "num":
            return None
        raise RapidError(f"{path}:{unit.line}: {type_} {name}{{{n}}} has no value; give it one with := [...]")
    named = _predefined_list(path, unit.line, type_, name, value)
    try:
        agg = _aggregate(path, unit.line, value) if named is None else named
    except RapidError:
        if type_ == "num":  # an expression: kept verbatim, refused only where a move needs it
            return None
        raise
    if not isinstance(agg, list) or len(agg) != n:
        got = len(agg) if isinstance(agg, list) else "not a list"
        raise RapidError(f"{path}:{unit.line}: {name}{{{n}}} needs [{n} elements], got {got}")
    if named is not None:
        return Declaration(unit.line, unit.end_line, storage.upper(), type_, name, tuple(named))
    items = tuple(
        _value_of(path, unit.line, type_, item, f"{name}{{{k + 1}}} = {item}") for k, item in enumerate(agg)
    )
    return Declaration(unit.line, unit.end_line, storage.upper(), type_, name, items)


# ---------------------------------------------------------------- instructions
def _split_args(path: str, line: int, text: str) -> list[str]:
    out: list[str] = []
    cur: list[str] = []
    depth = 0
    for ch in text:
        if ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
        if ch == "," and depth == 0:
            out.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    out.append("".join(cur).strip())
    if any(not a for a in out):
        raise RapidError(f"{path}:{line}: an argument is empty (two commas in a row?); remove the extra ','")
    return out


_SWITCH = re.compile(r"\\\s*([A-Za-z]\w*)\s*(?::=\s*([^\\]+?))?\s*(?=\\|$)")
SWITCH_NAMES = {s.lower(): s for s in ("V", "T", "Z", "WObj", "NoEOffs", "InPos", "Rx", "Ry", "Rz")}
"""Optional arguments joulepath reads, by their lower-case name (RAPID names ignore case)."""


def _top_level_backslash(text: str) -> int:
    depth = 0
    for k, ch in enumerate(text):
        if ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
        elif ch == "\\" and depth == 0:
            return k
    return -1


def _argument(path: str, line: int, text: str) -> tuple[str, dict[str, str | None]]:
    """``primary \\Sw:=value \\Flag`` -> (primary, {switch: value or None}); switch names canonical."""
    cut = _top_level_backslash(text)
    primary = (text if cut < 0 else text[:cut]).strip()
    switches: dict[str, str | None] = {}
    if cut >= 0:
        tail = text[cut:]
        pos = 0
        for m in _SWITCH.finditer(tail):
            if m.start() != pos:
                raise RapidError(f"{path}:{line}: cannot read the argument {text!r}")
            name = SWITCH_NAMES.get(m.group(1).lower(), m.group(1))
            switches[name] = m.group(2).strip() if m.group(2) else None
            pos = m.end()
        if pos != len(tail):
            raise RapidError(f"{path}:{line}: cannot read the argument {text!r}")
    return primary, switches


Binding = float | bool | str | TargetRef
"""A procedure argument as the callee sees it: a number, a truth value, a declared name, a target."""


@dataclass
class Names:
    """What a name may stand for while a routine is read.

    ``nums`` / ``bools``: the module's ``CONST`` and ``PERS`` num and bool values that no
    statement assigns (lower-case names; a ``PERS`` reads as declared); ``arrays``: its
    arrays as (storage, type, elements); ``loop``: the variables of the FOR loops being
    unrolled around the statement, bound to their value in this run; ``params``: the
    arguments of the procedure call being read; ``assigned``: names some statement of the
    module assigns (line, text); ``novalue``: targets declared without a value (line).
    """

    nums: dict[str, float] = field(default_factory=dict)
    arrays: dict[str, tuple[str, str, tuple[Value, ...]]] = field(default_factory=dict)
    loop: dict[str, int] = field(default_factory=dict)
    bools: dict[str, bool] = field(default_factory=dict)
    params: dict[str, Binding] = field(default_factory=dict)
    assigned: dict[str, tuple[int, str]] = field(default_factory=dict)
    novalue: dict[str, int] = field(default_factory=dict)

    def called(self, params: dict[str, Binding]) -> Names:
        """The names a called procedure sees: the module's, its arguments, no loop variables."""
        return Names(dict(self.nums), self.arrays, {}, dict(self.bools), params, self.assigned, self.novalue)


_ELEMENT = re.compile(r"^([A-Za-z]\w*)\s*\{\s*(.*?)\s*\}$", re.DOTALL)
_CALL = re.compile(r"^([A-Za-z]\w*)\s*\((.*)\)$", re.DOTALL)


def _index(path: str, line: int, text: str, names: Names) -> int:
    """An array index: a number, a ``CONST num``, a FOR loop's variable or an element of a CONST num array."""
    text = text.strip()
    value: float | None = None
    if _ELEMENT.match(text):
        value = _number(path, line, text, names, f"the index {text!r}")
    elif _NUMBER.fullmatch(text):
        value = float(text)
    elif _IDENT.match(text) and text.lower() in names.loop:
        value = float(names.loop[text.lower()])
    elif _IDENT.match(text) and isinstance(names.params.get(text.lower()), float):
        value = float(names.params[text.lower()])  # type: ignore[arg-type]
    elif _IDENT.match(text) and text.lower() in names.nums:
        value = names.nums[text.lower()]
    if value is None:
        raise RapidError(
            f"{path}:{line}: the index {text!r} must be a number, a CONST num, the variable of a FOR "
            "loop around it or an element of a CONST num array (expressions are not read)"
        )
    if value != round(value):
        raise RapidError(f"{path}:{line}: the index {text!r} = {value:g} is not a whole number")
    return int(round(value))


def _array_element(path: str, line: int, text: str, names: Names) -> tuple[str, int] | None:
    """``NAME{index}`` -> (the array's declared name, index), checked against its size; None: not indexed."""
    m = _ELEMENT.match(text.strip())
    if m is None:
        return None
    name, index = m.group(1), m.group(2)
    if name.lower() not in names.arrays:
        raise RapidError(
            f"{path}:{line}: {name} is not an array declared in the module before this line; declare "
            f"it (CONST ... {name}{{n}} := [...])"
        )
    k = _index(path, line, index, names)
    n = len(names.arrays[name.lower()][2])
    if not 1 <= k <= n:
        raise RapidError(f"{path}:{line}: {name}{{{k}}} is outside the array {name}{{{n}}} (indices 1..{n})")
    return name, k


def _number(path: str, line: int, text: str, names: Names, what: str) -> float:
    text = text.strip()
    if _NUMBER.fullmatch(text):
        if not math.isfinite(float(text)):
            raise RapidError(f"{path}:{line}: {what} {text[:20]} is not a finite number (at most 3.4E38)")
        return float(text)
    if _IDENT.match(text) and text.lower() in names.loop:
        return float(names.loop[text.lower()])
    bound = names.params.get(text.lower())
    if _IDENT.match(text) and isinstance(bound, float):
        return bound
    if _IDENT.match(text) and text.lower() in names.nums:
        return names.nums[text.lower()]
    at = _array_element(path, line, text, names)
    if at is not None:
        storage, type_, items = names.arrays[at[0].lower()]
        if type_ == "num" and storage == "CONST":
            value = items[at[1] - 1]
            assert isinstance(value, float)
            return value
    raise RapidError(
        f"{path}:{line}: {what} must be a number, a CONST or PERS num of the module or an element of a "
        f"CONST num array, got {text!r}"
    )


# ---------------------------------------------------------------- expressions
_TOKEN = re.compile(
    r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z]\w*(?:\s*\{[^}]*\})?)"
    r"|(?P<op><>|<=|>=|[-+*/()=<>]))"
)


def _evaluate(
    path: str, line: int, text: str, names: Names, what: str, seen: dict[str, str] | None = None
) -> float | bool:
    """A num or bool expression of numbers, constants, loop variables and arguments.

    ``+ - * / DIV MOD``, comparisons ``= <> < > <= >=``, ``AND OR XOR NOT``, brackets.
    ``seen`` collects the names read and their values (for notes). Anything else
    (functions, VAR data, data some statement assigns) is refused with the reason.
    """
    tokens: list[tuple[str, str]] = []
    pos = 0
    body = text.strip()
    while pos < len(body):
        m = _TOKEN.match(body, pos)
        if m is None or m.end() == pos:
            raise RapidError(
                f"{path}:{line}: cannot read {what} {text.strip()!r} at {body[pos : pos + 10]!r}"
            )
        pos = m.end()
        kind = m.lastgroup or ""
        tokens.append((kind, m.group(kind)))
    expr = _Expression(path, line, text, names, what, seen, tokens)
    if not tokens:
        raise expr.fail("it is empty")
    out = expr.disjunction()
    if expr.k != len(tokens):
        raise expr.fail(f"unexpected {tokens[expr.k][1]!r}")
    if not isinstance(out, bool) and not math.isfinite(out):
        raise expr.fail("its value is not a finite number; write numbers RAPID can hold (at most 3.4E38)")
    return out


class _Expression:
    """One tokenised num or bool expression read by recursive descent (:func:`_evaluate`): from
    :meth:`disjunction` (``OR``, ``XOR``) through ``AND``, comparisons, sums and products down to
    :meth:`unary`; ``k`` the next token, ``level`` the depth of brackets and signs."""

    def __init__(
        self,
        path: str,
        line: int,
        text: str,
        names: Names,
        what: str,
        seen: dict[str, str] | None,
        tokens: list[tuple[str, str]],
    ) -> None:
        self.path = path
        self.line = line
        self.text = text
        self.names = names
        self.what = what
        self.seen = seen
        self.tokens = tokens
        self.k = 0
        self.level = 0

    def fail(self, msg: str) -> RapidError:
        shown = self.text.strip() if len(self.text.strip()) <= 60 else self.text.strip()[:57] + "..."
        return RapidError(f"{self.path}:{self.line}: {self.what} {shown!r}: {msg}")

    def peek(self) -> str:
        return self.tokens[self.k][1].upper() if self.k < len(self.tokens) else ""

    def take(self) -> tuple[str, str]:
        if self.k >= len(self.tokens):
            raise self.fail("it ends too early")
        self.k += 1
        return self.tokens[self.k - 1]

    def num(self, v: float | bool) -> float:
        if isinstance(v, bool):
            raise self.fail("a truth value where a number is needed")
        return v

    def name_value(self, word: str) -> float | bool:
        low = word.lower()
        if "{" in word:
            return _number(self.path, self.line, word, self.names, self.what)
        if low in ("true", "false"):
            return low == "true"
        if low in self.names.loop:
            return float(self.names.loop[low])
        if low in self.names.params:
            bound = self.names.params[low]
            if isinstance(bound, float | bool):
                return bound
            raise self.fail(f"{word} is a {type(bound).__name__} argument, not a num or bool")
        if low in self.names.nums:
            return self.names.nums[low]
        if low in self.names.bools:
            return self.names.bools[low]
        if low in self.names.assigned:
            at, stmt = self.names.assigned[low]
            raise self.fail(
                f"{word} is assigned at line {at} ({stmt[:40]!r}), so its value is known only while the "
                "program runs; use a CONST or PERS value no statement changes"
            )
        raise self.fail(
            f"{word} is not a CONST or PERS num or bool of the module (a VAR, a function or unknown); "
            "declare it CONST"
        )

    def primary(self) -> float | bool:
        self.level += 1
        try:
            return self.unary()
        finally:
            self.level -= 1

    def unary(self) -> float | bool:
        if self.level > MAX_NESTING:
            raise self.fail(f"brackets or signs nested more than {MAX_NESTING} deep")
        kind, tok = self.take()
        if kind == "num":
            return float(tok)
        if kind == "name":
            if tok.upper() == "NOT":
                v = self.primary()
                if not isinstance(v, bool):
                    raise self.fail("NOT needs a truth value")
                return not v
            if self.peek() == "(":
                raise self.fail(f"the function {tok} is evaluated only while the program runs")
            value = self.name_value(tok)
            if self.seen is not None and tok.lower() not in ("true", "false"):
                self.seen[tok] = _show(value)
            return value
        if tok == "(":
            v = self.disjunction()
            if self.take()[1] != ")":
                raise self.fail("')' expected")
            return v
        if tok in "+-":
            v = self.num(self.primary())
            return v if tok == "+" else -v
        raise self.fail(f"unexpected {tok!r}")

    def product(self) -> float | bool:
        v = self.primary()
        while self.peek() in ("*", "/", "DIV", "MOD"):
            op = self.take()[1].upper()
            r = self.num(self.primary())
            a = self.num(v)
            if not (math.isfinite(a) and math.isfinite(r)):
                raise self.fail(
                    "a value is not a finite number; write numbers RAPID can hold (at most 3.4E38)"
                )
            if op in ("DIV", "MOD") and (a != round(a) or r != round(r)):
                raise self.fail(f"{op} needs whole numbers, got {a:g} {op} {r:g}")
            if op != "*" and r == 0:
                raise self.fail("division by zero")
            v = (
                a * r
                if op == "*"
                else a / r
                if op == "/"
                else float(int(a) // int(r))
                if op == "DIV"
                else a % r
            )
        return v

    def total(self) -> float | bool:
        v = self.product()
        while self.peek() in ("+", "-"):
            op = self.take()[1]
            r = self.num(self.product())
            v = self.num(v) + r if op == "+" else self.num(v) - r
        return v

    def comparison(self) -> float | bool:
        v = self.total()
        if self.peek() in ("=", "<>", "<", ">", "<=", ">="):
            op = self.take()[1]
            r = self.total()
            if op in ("=", "<>"):
                if isinstance(v, bool) != isinstance(r, bool):
                    raise self.fail("compares a number with a truth value")
                same = v == r if isinstance(v, bool) else abs(float(v) - float(r)) <= 1e-9
                return same if op == "=" else not same
            a, b = self.num(v), self.num(r)
            return {"<": a < b, ">": a > b, "<=": a <= b, ">=": a >= b}[op]
        return v

    def conjunction(self) -> float | bool:
        v = self.comparison()
        while self.peek() == "AND":
            self.take()
            r = self.comparison()
            if not isinstance(v, bool) or not isinstance(r, bool):
                raise self.fail("AND needs truth values")
            v = v and r
        return v

    def disjunction(self) -> float | bool:
        v = self.conjunction()
        while self.peek() in ("OR", "XOR"):
            op = self.take()[1].upper()
            r = self.conjunction()
            if not isinstance(v, bool) or not isinstance(r, bool):
                raise self.fail(f"{op} needs truth values")
            v = (v or r) if op == "OR" else (v != r)
        return v


def _show(value: float | bool) -> str:
    return ("TRUE" if value else "FALSE") if isinstance(value, bool) else f"{value:g}"


# ---------------------------------------------------------------- targets
COMPUTED_AT_RUN_TIME = ("CRobT", "CJointT", "CalcRobT", "CalcJointT", "CTool", "CWObj", "MirPos")


def _target_ref(path: str, line: int, text: str, names: Names, what: str) -> TargetRef:
    """A target: a declared name, an array element, an argument, ``Offs(...)`` or ``RelTool(...)``."""
    text = text.strip()
    m = _CALL.match(text)
    if m is None:
        at = _array_element(path, line, text, names)
        if at is not None:
            return TargetRef(f"{at[0]}{{{at[1]}}}")
        if not _IDENT.match(text):
            raise RapidError(
                f"{path}:{line}: {what} must be a declared target, Offs(...) or RelTool(...), got "
                f"{text[:40]!r}; declare it (CONST robtarget ... := [...]) and use its name"
            )
        low = text.lower()
        if low in names.params:
            bound = names.params[low]
            if not isinstance(bound, TargetRef):
                raise RapidError(f"{path}:{line}: {what}: the argument {text} is not a target")
            return bound
        if low in names.assigned:
            at_line, stmt = names.assigned[low]
            raise RapidError(
                f"{path}:{line}: {what} {text} is assigned at line {at_line} ({stmt[:40]!r}): a target "
                "computed while the program runs is not modelled; move to a declared CONST robtarget"
            )
        if low in names.novalue:
            raise RapidError(
                f"{path}:{names.novalue[low]}: {text} is declared without a value, and line {line} moves "
                "to it; give it one with := [...]"
            )
        return TargetRef(text)
    func, inner = m.group(1), m.group(2)
    kind = next((k for k in ("Offs", "RelTool") if k.lower() == func.lower()), None)
    if kind is None:
        run_time = func.lower() in [f.lower() for f in COMPUTED_AT_RUN_TIME]
        how = "while the program runs" if run_time else "by a function joulepath does not read"
        raise RapidError(
            f"{path}:{line}: {what} {func}(...) is computed {how}; not modelled; move to a declared "
            "robtarget (Offs and RelTool are read)"
        )
    args = _split_args(path, line, inner)
    if len(args) != 4:
        raise RapidError(f"{path}:{line}: {kind} needs 4 arguments (target, dx, dy, dz), got {len(args)}")
    last, switches = _argument(path, line, args[3])
    if switches and kind == "Offs":
        raise RapidError(f"{path}:{line}: Offs takes no optional arguments; use RelTool for \\Rx, \\Ry, \\Rz")
    rotation = [0.0, 0.0, 0.0]
    for sw, value in switches.items():
        if sw not in ("Rx", "Ry", "Rz") or value is None:
            raise RapidError(f"{path}:{line}: RelTool \\{sw} is not read; use \\Rx:=, \\Ry:=, \\Rz:= (deg)")
        rotation["xyz".index(sw[1])] = _real(path, line, value, names, f"RelTool \\{sw}")
    base = _target_ref(path, line, args[0], names, f"the target of {kind}")
    d = tuple(
        _real(path, line, t, names, f"{kind}'s {axis}")
        for t, axis in zip((*args[1:3], last), "xyz", strict=True)
    )
    offset = Offset(kind, (d[0], d[1], d[2]), (rotation[0], rotation[1], rotation[2]))
    return TargetRef(base.name, (*base.offsets, offset))


def _real(path: str, line: int, text: str, names: Names, what: str) -> float:
    value = _evaluate(path, line, text, names, what)
    if isinstance(value, bool):
        raise RapidError(f"{path}:{line}: {what} {text.strip()!r} is a truth value; give a number")
    return value


def _target_text(ref: TargetRef, written: str) -> str:
    """What a move's ``target`` says: the declared name, or the expression as written."""
    return ref.name if not ref.offsets else re.sub(r"\s+", " ", written.strip())


def _name_argument(path: str, line: int, text: str, names: Names, what: str) -> str:
    """A speed, zone, tool or work object: a declared name (an argument stands for its value's name)."""
    low = text.lower()
    if _IDENT.match(text) and low in names.params:
        bound = names.params[low]
        if not isinstance(bound, str):
            raise RapidError(f"{path}:{line}: the {what} argument {text} is not a {what} name")
        return bound
    return text


def _move(path: str, unit: Unit, names: Names, instr: str) -> Move:
    body = unit.text[len(unit.head) :].rstrip(";").strip()
    if body.startswith("\\"):
        sw = body[1:].split()[0].split(",")[0]
        what = " (concurrent execution)" if sw.lower() == "conc" else ""
        raise RapidError(
            f"{path}:{unit.line}: {instr} \\{sw}{what} is not modelled; remove the \\{sw} argument"
        )
    args = _split_args(path, unit.line, body)
    if len(args) != 4:
        raise RapidError(
            f"{path}:{unit.line}: {instr} needs 4 arguments (target, speed, zone, tool), got {len(args)}"
        )
    allowed = ({"NoEOffs"} if instr == "MoveAbsJ" else set(), {"V", "T"}, {"Z"}, {"WObj"})
    parsed = []
    ref: TargetRef | None = None
    for text, ok, what in zip(args, allowed, ("target", "speed", "zone", "tool"), strict=True):
        primary, switches = _argument(path, unit.line, text)
        for sw in switches:
            if sw not in ok:
                raise RapidError(
                    f"{path}:{unit.line}: {instr} argument \\{sw} (on the {what}) is not supported; remove it"
                )
        if what == "target":
            ref = _target_ref(path, unit.line, primary, names, f"the target of {instr}")
            primary = _target_text(ref, primary)
            parsed.append((primary, switches))
            continue
        at = _array_element(path, unit.line, primary, names) if what != "tool" else None
        if at is not None:
            primary = f"{at[0]}{{{at[1]}}}"  # the element this run of the loops names
        elif not _IDENT.match(primary):
            raise RapidError(
                f"{path}:{unit.line}: the {what} of {instr} must be a name declared in the module, got "
                f"{primary!r}; declare it (CONST ... := ...) and use its name"
            )
        else:
            primary = _name_argument(path, unit.line, primary, names, what)
        parsed.append((primary, switches))
    (target, _), (speed, sp), (zone, zs), (tool, ts) = parsed
    wobj: str | None = None
    if "WObj" in ts:
        written = ts["WObj"]
        if written is None or not _IDENT.match(written):
            raise RapidError(f"{path}:{unit.line}: \\WObj needs a work object name (\\WObj:=wobj1)")
        wobj = _name_argument(path, unit.line, written, names, "work object")
        if wobj.lower() == "wobj0":
            wobj = None
    for key, sws in (("V", sp), ("T", sp), ("Z", zs)):
        if key in sws and sws[key] is None:
            raise RapidError(f"{path}:{unit.line}: \\{key} needs a value (\\{key}:=...)")
    if "V" in sp and "T" in sp:
        raise RapidError(f"{path}:{unit.line}: \\V and \\T together; keep one")
    v = _number(path, unit.line, sp["V"] or "", names, "\\V") if "V" in sp else None
    t = _number(path, unit.line, sp["T"] or "", names, "\\T") if "T" in sp else None
    z = _number(path, unit.line, zs["Z"] or "", names, "\\Z") if "Z" in zs else None
    if t is not None and not 0 < t <= 600:
        raise RapidError(f"{path}:{unit.line}: \\T:={t:g} s must be within (0, 600] s")
    if v is not None and v <= 0:
        raise RapidError(f"{path}:{unit.line}: \\V:={v:g} mm/s must be positive")
    if z is not None and z < 0:
        raise RapidError(f"{path}:{unit.line}: \\Z:={z:g} mm must be ≥ 0")
    target_ref = ref if ref is not None and ref.offsets else None
    return Move(unit.line, unit.end_line, instr, target, speed, v, t, zone, z, tool, wobj, target_ref)


_IDLE_MARK = re.compile(r"^\s*!\s*joulepath\s*:\s*idle\b", re.IGNORECASE)
_IDLE_AFTER = re.compile(r";\s*!\s*joulepath\s*:\s*idle\b", re.IGNORECASE)


def _is_idle(source: tuple[str, ...], unit: Unit) -> bool:
    """``! joulepath: idle`` after the statement's ``;`` or alone on the line directly above it."""
    last = source[unit.end_line - 1] if unit.end_line <= len(source) else ""
    above = source[unit.line - 2] if unit.line >= 2 else ""
    return bool(_IDLE_AFTER.search(last) or _IDLE_MARK.match(above))


def _wait(path: str, unit: Unit, names: Names, source: tuple[str, ...]) -> WaitTime:
    body = unit.text[len(unit.head) :].rstrip(";").strip()
    inpos = False
    if body.startswith("\\"):
        first, _, rest = body.partition(",")
        if first[1:].strip().lower() != "inpos":
            raise RapidError(
                f"{path}:{unit.line}: WaitTime {first.strip()} is not read; remove it (\\InPos is read)"
            )
        inpos, body = True, rest.strip()
    if not body:
        raise RapidError(f"{path}:{unit.line}: WaitTime needs a time in s")
    seconds = _real(path, unit.line, body, names, "the WaitTime")
    if not 0 <= seconds <= 3600:
        raise RapidError(f"{path}:{unit.line}: WaitTime {seconds:g} s must be within [0, 3600] s")
    return WaitTime(unit.line, unit.end_line, seconds, inpos, _is_idle(source, unit))


def _motion_setting(path: str, unit: Unit, names: Names, instr: str) -> MotionSetting:
    """``AccSet Acc, Ramp;`` (each in (0, 100] %) or ``VelSet Override, Max;`` (% > 0, mm/s > 0)."""
    body = unit.text[len(unit.head) :].rstrip(";").strip()
    what = (
        "Acc, Ramp (% of the acceleration and of its rate of change)"
        if instr == "AccSet"
        else ("Override, Max (% of the programmed speeds, the highest TCP speed in mm/s)")
    )
    parts = [p.strip() for p in body.split(",")]
    if len(parts) != 2 or any(not p or "\\" in p for p in parts):
        raise RapidError(
            f"{path}:{unit.line}: {instr} {body!r} is not read; write {instr} {what}, without optional "
            "arguments"
        )
    a = _real(path, unit.line, parts[0], names, f"the {instr}")
    b = _real(path, unit.line, parts[1], names, f"the {instr}")
    if instr == "AccSet" and not (0 < a <= 100 and 0 < b <= 100):
        raise RapidError(f"{path}:{unit.line}: AccSet {a:g}, {b:g}: Acc and Ramp must be within (0, 100] %")
    if instr == "VelSet" and not (0 < a and 0 < b):
        raise RapidError(
            f"{path}:{unit.line}: VelSet {a:g}, {b:g}: Override (%) and Max (mm/s) must be positive"
        )
    return MotionSetting(unit.line, unit.end_line, instr, (a, b))


# ---------------------------------------------------------------- routines
MOTION_FIXES = {
    "PDispOn": "it displaces every following target (program displacement); remove it and PDispOff, or "
    "write the displaced targets (Offs)",
    "PDispSet": "it displaces every following target (program displacement); remove it and PDispOff, or "
    "write the displaced targets (Offs)",
    "EOffsOn": "it offsets the external axes; remove it and EOffsOff",
    "EOffsSet": "it offsets the external axes; remove it and EOffsOff",
    "VelSet": "it scales the programmed speeds; remove it and write the speeds in the moves",
    "AccSet": "it lowers the acceleration; remove it to optimize",
}
_PROC_LINE = re.compile(r"(?:LOCAL\s+)?PROC\s+([A-Za-z]\w*)\s*\(\s*(.*?)\s*\)", re.IGNORECASE | re.DOTALL)
_PARAM = re.compile(r"^(?:(VAR|PERS|INOUT)\s+)?([A-Za-z]\w*)\s+([A-Za-z]\w*)$", re.IGNORECASE)
ARGUMENT_TYPES = ("num", "bool", "robtarget", "jointtarget", "speeddata", "zonedata", "tooldata", "wobjdata")
"""Parameter types whose arguments are substituted; others (string, signals, ...) are passed as written."""
MAX_EXPANDED = 200_000
"""Most statements the calls of procedures with parameters may read in all."""
WRITES_FIRST_ARGUMENT = ("Incr", "Decr", "Add", "Clear", "TPReadNum", "TPReadFK", "TPReadDnum", "GetDataVal")
"""Instructions that change the data named by their first argument."""
_ASSIGN = re.compile(r"^([A-Za-z]\w*)\s*(?:\{[^}]*\})?\s*(?:\.\s*\w+\s*)*:=", re.DOTALL)


@dataclass
class _Routine:
    unit: Unit
    start: int  # index of the PROC unit in the reader's units
    end: int  # index of its ENDPROC
    params: tuple[tuple[str, str], ...]


@dataclass
class _Reader:
    path: str
    units: list[Unit]
    procs: set[str]
    names: Names
    source: tuple[str, ...] = ()
    routines: dict[str, _Routine] = field(default_factory=dict)
    pos: int = 0
    unrolled: int = 0
    expanded: int = 0
    stack: tuple[str, ...] = ()
    level: int = 0  # how deep the statement being read is nested in blocks and calls

    def peek(self) -> Unit | None:
        return self.units[self.pos] if self.pos < len(self.units) else None

    def take(self) -> Unit:
        u = self.units[self.pos]
        self.pos += 1
        return u

    def fail(self, line: int, msg: str) -> RapidError:
        return RapidError(f"{self.path}:{line}: {msg}")

    def is_motion(self, u: Unit) -> bool:
        head = u.head
        return bool(head.lower() in _MOVES_LOWER or OTHER_MOTION.match(head) or head.lower() in self.procs)

    def block(self, close: str, opener: Unit, *, inside: str) -> tuple[list[Statement], Unit]:
        self.level += 1
        try:
            return self._block(close, opener, inside=inside)
        finally:
            self.level -= 1

    def _block(self, close: str, opener: Unit, *, inside: str) -> tuple[list[Statement], Unit]:
        body: list[Statement] = []
        while True:
            u = self.peek()
            if u is None:
                raise self.fail(opener.line, f"{inside} is not closed; add {close}")
            up = u.head.upper()
            if up == close:
                return body, self.take()
            if close == "ENDPROC" and up in ("ERROR", "UNDO", "BACKWARD"):
                # the routine's handler: kept verbatim in the source, never part of the cycle
                while (v := self.peek()) is not None and v.head.upper() != "ENDPROC":
                    self.take()
                continue
            if up in ("ENDPROC", "ENDMODULE", "ENDFUNC", "ENDTRAP") and close != up:
                raise self.fail(
                    u.line, f"{u.head} before {close} (opened at line {opener.line}); add {close}"
                )
            if up in ("CONST", "PERS", "VAR") and inside.startswith("PROC"):
                self.take()
                self.local_declaration(u)
                continue
            body.append(self.statement(inside))

    def local_declaration(self, u: Unit) -> None:
        """Data declared in a routine: a ``CONST num`` joins the names; the rest is not read."""
        m = _DECL.match(u.text)
        if m is None:
            raise self.fail(u.line, f"cannot read the declaration {u.text[:60]!r}")
        storage, type_, name, dims, value = m.groups()
        if storage.upper() == "CONST" and type_.lower() == "num" and not dims and value is not None:
            self.names.nums[name.lower()] = _real(
                self.path, u.line, value, self.names, f"the value of {name}"
            )

    def find_end(self, opener: Unit, close: str) -> int:
        """Index of the unit that closes the block just opened (nested blocks skipped)."""
        depth = 1
        for k in range(self.pos, len(self.units)):
            u = self.units[k]
            up = u.head.upper()
            if _opens_nested(u):
                depth += 1
            elif up in BLOCK_CLOSE.values():
                depth -= 1
                if depth == 0:
                    if up != close:
                        raise self.fail(
                            u.line,
                            f"{u.head} closes {opener.head.upper()} (line {opener.line}); write {close}",
                        )
                    return k
            elif up in ("ENDPROC", "ENDMODULE"):
                break
        raise self.fail(opener.line, f"{opener.head.upper()} is not closed; add {close}")

    def skip_block(self, opener: Unit, close: str, *, refuse_motion: bool = True) -> Unit:
        """A block kept verbatim; a move inside it is refused."""
        end = self.find_end(opener, close)
        for u in self.units[self.pos : end]:
            if refuse_motion and self.is_motion(u):
                raise self.fail(
                    u.line,
                    f"{u.head} inside {opener.head.upper()} (line {opener.line}): moves or calls under a "
                    "condition or a WHILE loop are not supported; take them out of the block",
                )
        self.pos = end + 1
        return self.units[end]

    def has_motion(self) -> bool:
        """Whether the block just opened holds a move or a call; reads nothing."""
        depth = 1
        for u in self.units[self.pos :]:
            up = u.head.upper()
            if _opens_nested(u):
                depth += 1
            elif up in BLOCK_CLOSE.values():
                depth -= 1
                if depth == 0:
                    return False
            elif up in ("ENDPROC", "ENDMODULE"):
                return False  # the unclosed block is refused by whoever reads it
            elif self.is_motion(u):
                return True
            elif up == "IF" and any(
                OTHER_MOTION.match(w) or w.lower() in self.procs for w in re.findall(r"[A-Za-z]\w*", u.text)
            ):
                return True
        return False

    def for_loop(self, u: Unit) -> ForLoop:
        """A FOR loop with moves inside: its constant bounds, and its body read once per run."""
        m = _FOR.fullmatch(u.text.strip())
        if m is None:
            raise self.fail(u.line, f"cannot read {u.text[:50]!r}; write FOR i FROM 1 TO n [STEP s] DO")
        var = m.group(1)
        bounds = []
        for text, what in ((m.group(2), "FROM"), (m.group(3), "TO"), (m.group(4), "STEP")):
            if text is None:
                bounds.append(1)
                continue
            try:
                bounds.append(_index(self.path, u.line, text, self.names))
            except RapidError:
                raise self.fail(
                    u.line,
                    f"the FOR loop's {what} {text.strip()!r} must be a whole number or a CONST num of the "
                    "module to read the moves inside (they are unrolled); write it as a constant",
                ) from None
        first, last, step = bounds
        if step == 0:
            raise self.fail(u.line, "the FOR loop's STEP is 0; the loop would never end")
        runs_of = range(first, last + (1 if step > 0 else -1), step)  # its length without building it
        if len(runs_of) > MAX_RUNS or self.unrolled + len(runs_of) > MAX_UNROLLED:
            raise self.fail(
                u.line,
                f"the FOR loop runs {len(runs_of)} times; at most {MAX_RUNS} runs per loop and "
                f"{MAX_UNROLLED} in the module are unrolled; run fewer",
            )
        values = tuple(runs_of)
        self.unrolled += len(values)
        if var.lower() in self.names.loop:
            raise self.fail(u.line, f"the FOR variable {var} is already the variable of a loop around it")
        body_start = self.pos
        runs: list[tuple[Statement, ...]] = []
        end: Unit | None = None
        try:
            for value in values:
                self.pos = body_start
                self.names.loop[var.lower()] = value
                body, end = self.block("ENDFOR", u, inside=f"FOR {var}")
                runs.append(tuple(body))
        finally:
            self.names.loop.pop(var.lower(), None)
        if end is None:  # no run: the body is skipped as written (its moves never run)
            self.pos = body_start
            end = self.skip_block(u, "ENDFOR", refuse_motion=False)
        return ForLoop(u.line, end.end_line, var, values, tuple(runs))

    def branches(self, opener: Unit, close: str, heads: tuple[str, ...]) -> list[tuple[Unit, int, int]]:
        """The parts of an IF / TEST just opened: (its first unit, first body index, end index)."""
        end = self.find_end(opener, close)
        parts: list[tuple[Unit, int, int]] = []
        start, first, depth = opener, self.pos, 0
        for k in range(self.pos, end):
            u = self.units[k]
            up = u.head.upper()
            if depth == 0 and up in heads:
                parts.append((start, first, k))
                start, first = u, k + 1
            if _opens_nested(u):
                depth += 1
            elif up in BLOCK_CLOSE.values():
                depth -= 1
        parts.append((start, first, end))
        return parts

    def choose(self, u: Unit) -> Branch:
        """An IF / TEST with moves inside: the branch its constant condition picks is read, the others not."""
        up = u.head.upper()
        close = BLOCK_CLOSE[up]
        motion = next((v for v in self.units[self.pos : self.find_end(u, close)] if self.is_motion(v)), u)

        def evaluate(text: str) -> tuple[float | bool, dict[str, str]]:
            seen: dict[str, str] = {}
            try:
                return _evaluate(self.path, u.line, text, self.names, "the condition", seen), seen
            except RapidError as err:
                reason = str(err).split(": ", 2)[-1]
                raise self.fail(
                    motion.line,
                    f"{motion.head} inside {up} (line {u.line}): {reason}; moves under a condition known "
                    "only while the program runs are not modelled (or take them out of the block)",
                ) from None

        def shown(text: str, value: float | bool, seen: dict[str, str]) -> str:
            text = text.strip()
            if _IDENT.match(text) or not seen:
                return f"{text} ({_show(value)})"
            return f"{text} ({', '.join(f'{k} = {v}' for k, v in seen.items())}: {_show(value)})"

        chosen: tuple[Unit, int, int] | None = None
        said: list[str] = []
        if up == "IF":
            parts = self.branches(u, close, ("ELSEIF", "ELSE"))
            for part, first, last in parts:
                kind = part.head.upper()
                if kind == "ELSE":
                    chosen = (part, first, last)
                    break
                cond = re.sub(r"^\s*(?:ELSE)?IF\s+|\s+THEN\s*$", "", part.text, flags=re.IGNORECASE)
                value, seen = evaluate(cond)
                if not isinstance(value, bool):
                    raise self.fail(
                        part.line, f"the condition {cond.strip()!r} is a number; write a comparison"
                    )
                said.append(f"{kind} {shown(cond, value, seen)}")
                if value:
                    chosen = (part, first, last)
                    break
        else:
            parts = self.branches(u, close, ("CASE", "DEFAULT"))
            subject = u.text.strip()[4:].strip()
            value, seen = evaluate(subject)
            said.append(f"TEST {shown(subject, value, seen)}")
            for part, first, last in parts[1:]:
                if part.head.upper() == "DEFAULT":
                    chosen = (part, first, last)
                    break
                labels = part.text.strip()[4:].rstrip(":").strip()
                cases = [evaluate(c)[0] for c in _split_args(self.path, part.line, labels)]
                if any(
                    type(c) is type(value)
                    and (c == value if isinstance(c, bool) else abs(float(c) - float(value)) <= 1e-9)
                    for c in cases
                ):
                    chosen = (part, first, last)
                    break
        end = self.units[parts[-1][2]]
        body: list[Statement] = []
        if chosen is None:
            where = "no branch (nothing runs)"
        else:
            part, first, last = chosen
            head = part.head.upper()
            where = "THEN branch" if head == "IF" else f"{head} branch"
            if head != "IF" and (head != "ELSE" or up == "TEST"):
                where += f" (line {part.line})"
            self.pos = first
            self.level += 1
            try:
                while self.pos < last:
                    body.append(self.statement(f"{up} (line {u.line})"))
            finally:
                self.level -= 1
        self.pos = parts[-1][2] + 1
        note = f"line {u.line}: {', '.join(said)} -> {where}"
        return Branch(u.line, end.end_line, note, tuple(body))

    def call(self, u: Unit, head: str) -> Call:
        """A call: without arguments as it is; with arguments, the procedure read with them bound."""
        rest = u.text[len(head) :].rstrip(";").strip()
        routine = self.routines[head.lower()]
        name = routine.unit.head
        if not rest and not routine.params:
            return Call(u.line, u.end_line, head)
        if rest.startswith("\\") or "\\" in rest and _top_level_backslash(rest) >= 0:
            raise self.fail(
                u.line,
                f"call of {head} with optional arguments (\\...) is not supported; "
                "pass every argument by position",
            )
        args = _split_args(self.path, u.line, rest) if rest else []
        if len(args) != len(routine.params):
            raise self.fail(
                u.line,
                f"{head} takes {len(routine.params)} argument(s) (line {routine.unit.line}), got {len(args)}",
            )
        if head.lower() in self.stack:
            raise self.fail(u.line, f"{head} calls itself (through {' -> '.join(self.stack)}); not supported")
        bound: dict[str, Binding] = {}
        for (type_, pname), text in zip(routine.params, args, strict=True):
            what = f"argument {pname} of {head}"
            if type_ in ("num", "bool"):
                value = _evaluate(self.path, u.line, text, self.names, f"the {what}")
                if isinstance(value, bool) != (type_ == "bool"):
                    raise self.fail(u.line, f"the {what} must be a {type_}, got {text!r}")
                bound[pname.lower()] = value
            elif type_ in ("robtarget", "jointtarget"):
                bound[pname.lower()] = _target_ref(self.path, u.line, text, self.names, f"the {what}")
            elif type_ in ARGUMENT_TYPES:
                at = _array_element(self.path, u.line, text, self.names)
                if at is not None:
                    bound[pname.lower()] = f"{at[0]}{{{at[1]}}}"
                elif not _IDENT.match(text):
                    raise self.fail(u.line, f"the {what} must be a declared {type_} name, got {text[:40]!r}")
                else:
                    bound[pname.lower()] = _name_argument(self.path, u.line, text, self.names, type_)
        size = routine.end - routine.start
        self.expanded += size
        if self.expanded > MAX_EXPANDED:
            raise self.fail(
                u.line,
                f"the calls of procedures with parameters read more than {MAX_EXPANDED} "
                "statements; call them fewer times",
            )
        sub = _Reader(
            self.path,
            self.units,
            self.procs,
            self.names.called(bound),
            self.source,
            self.routines,
            routine.start + 1,
            self.unrolled,
            self.expanded,
            (*self.stack, head.lower()),
            self.level,
        )
        body, _ = sub.block("ENDPROC", routine.unit, inside=f"PROC {name}")
        self.unrolled, self.expanded = sub.unrolled, sub.expanded
        return Call(u.line, u.end_line, head, tuple(args), tuple(body))

    def statement(self, inside: str) -> Statement:
        u = self.take()
        if self.level > MAX_NESTING:
            raise self.fail(
                u.line,
                f"blocks and calls nest more than {MAX_NESTING} deep here; "
                "flatten the nested blocks, or call the procedures one after another",
            )
        head = u.head
        up = head.upper()
        if up == "FOR" and u.text.rstrip().upper().endswith("DO") and self.has_motion():
            return self.for_loop(u)
        if up == "WHILE" and re.fullmatch(r"WHILE\s+TRUE\s+DO", u.text, re.IGNORECASE):
            if inside != "PROC main":
                raise self.fail(u.line, "WHILE TRUE is read as the cycle only directly in PROC main")
            body, end = self.block("ENDWHILE", u, inside="WHILE TRUE")
            return WhileTrue(u.line, end.end_line, tuple(body))
        if up in ("IF", "TEST") and (u.text.rstrip().upper().endswith("THEN") or up == "TEST"):
            if self.has_motion():
                return self.choose(u)
            end = self.skip_block(u, BLOCK_CLOSE[up])
            return Verbatim(u.line, end.end_line, up)
        if up in BLOCK_CLOSE and (u.text.rstrip().upper().endswith(("THEN", "DO")) or up == "TEST"):
            end = self.skip_block(u, BLOCK_CLOSE[up])
            return Verbatim(u.line, end.end_line, up)
        if up == "IF":  # compact IF: IF condition instruction;
            words = set(re.findall(r"[A-Za-z]\w*", u.text))
            if any(OTHER_MOTION.match(w) or w.lower() in self.procs for w in words):
                raise self.fail(
                    u.line, "a move or call in a compact IF is not supported; write IF ... THEN ... ENDIF"
                )
            return Verbatim(u.line, u.end_line, "IF")
        if up in ("ERROR", "UNDO", "BACKWARD"):
            raise self.fail(u.line, f"{head} handler inside {inside}; it goes at the end of the routine")
        if up in ("ELSE", "ELSEIF", "CASE", "DEFAULT", "ENDIF", "ENDFOR", "ENDWHILE", "ENDTEST"):
            raise self.fail(u.line, f"{head} without its opening block")
        if up in ("MODULE", "PROC", "FUNC", "TRAP") or up in ("CONST", "PERS", "VAR"):
            raise self.fail(u.line, f"{head} inside {inside}; close {inside} first")
        if not u.text.endswith(";"):
            raise self.fail(u.line, f"cannot read {u.text[:50]!r}; an instruction ends with ';'")
        if head.lower() in _MOVES_LOWER:
            return _move(self.path, u, self.names, _MOVES_LOWER[head.lower()])
        if OTHER_MOTION.match(head):
            raise self.fail(
                u.line, f"{head} is not supported (joulepath reads MoveAbsJ, MoveJ and MoveL); replace it"
            )
        if head.lower() == "waittime":
            return _wait(self.path, u, self.names, self.source)
        if head.lower() in ("accset", "velset"):
            return _motion_setting(
                self.path, u, self.names, "AccSet" if head.lower() == "accset" else "VelSet"
            )
        for s in MOTION_SETTINGS:
            if head.lower() == s.lower():
                if s in ("ConfJ", "ConfL") and re.search(r"\\\s*On\b", u.text, re.IGNORECASE):
                    return Verbatim(u.line, u.end_line, s)
                fix = MOTION_FIXES.get(s, "remove it to optimize")
                raise self.fail(u.line, f"{s} changes how the robot moves and is not modelled; {fix}")
        if head.lower() in self.procs:
            return self.call(u, head)
        if not _IDENT.match(head):
            raise self.fail(u.line, f"cannot read {u.text[:50]!r}")
        return Verbatim(u.line, u.end_line, head)


_MOVES_LOWER = {m.lower(): m for m in MOVES}


def _opens_nested(u: Unit) -> bool:
    up = u.head.upper()
    return (up in BLOCK_CLOSE and u.text.rstrip().upper().endswith(("THEN", "DO"))) or up == "TEST"


def _blank_header(path: str, text: str) -> str:
    """A saved module's ``%%% VERSION:1 LANGUAGE:ENGLISH %%%`` header as blank lines (numbers kept)."""
    lines = text.split("\n")
    first = next((k for k, t in enumerate(lines) if t.strip()), None)
    if first is None or lines[first].strip() != "%%%":
        return text
    close = next((k for k in range(first + 1, len(lines)) if lines[k].strip() == "%%%"), None)
    if close is None:
        raise RapidError(f"{path}:{first + 1}: the %%% header is not closed; add a line %%% after it")
    return "\n".join([""] * (close + 1) + lines[close + 1 :])


def _assignments(units: list[Unit]) -> dict[str, tuple[int, str]]:
    """Names some statement assigns (``x := ...``, ``Incr x``, ``TPReadNum x, ...``): their first line."""
    out: dict[str, tuple[int, str]] = {}
    writers = {w.lower() for w in WRITES_FIRST_ARGUMENT}
    for u in units:
        if u.head.upper() in ("CONST", "PERS", "VAR", "PROC", "FUNC", "TRAP", "MODULE"):
            continue
        m = _ASSIGN.match(u.text)
        if m:
            out.setdefault(m.group(1).lower(), (u.line, u.text))
        elif u.head.lower() in writers:
            rest = u.text[len(u.head) :].strip()
            w = re.match(r"([A-Za-z]\w*)", rest)
            if w:
                out.setdefault(w.group(1).lower(), (u.line, u.text))
    return out


def _routines(path: str, units: list[Unit]) -> tuple[list[tuple[Unit, int, int]], list[Unit]]:
    """Module level: its routines (opener, index, index of the closing unit) and declarations."""
    routines: list[tuple[Unit, int, int]] = []
    decls: list[Unit] = []
    i = 0
    while i < len(units):
        u = units[i]
        head = u.head.upper()
        if head in ("CONST", "PERS", "VAR"):
            decls.append(u)
            i += 1
            continue
        if head not in ("PROC", "FUNC", "TRAP"):
            raise RapidError(
                f"{path}:{u.line}: {u.text[:40]!r} at module level; only declarations and routines go there"
            )
        close = "END" + head
        j = i + 1
        while j < len(units) and units[j].head.upper() != close:
            v = units[j]
            if v.head.upper() in ("PROC", "FUNC", "TRAP", "ENDPROC", "ENDFUNC", "ENDTRAP"):
                raise RapidError(
                    f"{path}:{v.line}: {v.head} inside {head} (line {u.line}); add {close} before it"
                )
            j += 1
        if j == len(units):
            raise RapidError(f"{path}:{u.line}: {head} is not closed; add {close}")
        routines.append((u, i, j))
        i = j + 1
    return routines, decls


def _params(path: str, u: Unit, text: str) -> tuple[tuple[str, str], ...]:
    if not text:
        return ()
    out = []
    for item in re.split(r"\s*[,|]\s*", text):
        m = _PARAM.match(item.strip())
        if m is None:
            raise RapidError(
                f"{path}:{u.line}: cannot read the parameter {item.strip()!r}; write 'type name' (optional "
                "\\parameters and arrays are not supported)"
            )
        out.append((m.group(2).lower(), m.group(3)))
    return tuple(out)


def parse_module(text: str, *, path: str = "<program>") -> Module:
    """Read a RAPID module (the subset above); ``RapidError`` naming the line otherwise."""
    if "\x00" in text:
        raise RapidError(f"{path}:1: the file holds NUL bytes; it is not a RAPID text file")
    units = split_units(path, _blank_header(path, text))
    if not units:
        raise RapidError(f"{path}:1: the file is empty; a RAPID module starts with MODULE name")
    first = units[0]
    m = re.fullmatch(r"MODULE\s+([A-Za-z]\w*)\s*(\([^)]*\))?", first.text, re.IGNORECASE)
    if first.head.upper() != "MODULE" or not m:
        raise RapidError(f"{path}:{first.line}: expected 'MODULE name', got {first.text[:40]!r}")
    if len(units) < 2 or units[-1].head.upper() != "ENDMODULE":
        raise RapidError(f"{path}:{units[-1].end_line}: the module does not end with ENDMODULE; add it")
    inner = units[1:-1]
    for u in inner:
        if u.head.upper() in ("MODULE", "ENDMODULE"):
            raise RapidError(f"{path}:{u.line}: {u.head} inside the module; one module per file")
    found, decl_units = _routines(path, inner)
    routines: dict[str, _Routine] = {}
    for u, start, end in found:
        if u.head.upper() != "PROC":
            continue
        pm = _PROC_LINE.fullmatch(u.text)
        if not pm:
            raise RapidError(f"{path}:{u.line}: expected 'PROC name()', got {u.text[:40]!r}")
        if pm.group(1).lower() in routines:
            raise RapidError(f"{path}:{u.line}: PROC {pm.group(1)} is defined twice; rename one")
        routines[pm.group(1).lower()] = _Routine(u, start, end, _params(path, u, pm.group(2)))
    scope = Names(assigned=_assignments(inner))
    source = tuple(text.splitlines())
    decls = _declarations(path, decl_units, scope)
    procedures: list[Procedure] = []
    reader = _Reader(path, inner, set(routines), scope, source, routines)
    for key, routine in routines.items():
        u = routine.unit
        name = _PROC_LINE.fullmatch(u.text).group(1)  # type: ignore[union-attr]
        if routine.params:  # read at each call, with its arguments bound
            procedures.append(Procedure(u.line, inner[routine.end].end_line, name, (), routine.params))
            continue
        reader.names = scope.called({})
        reader.pos = routine.start + 1
        reader.stack = (key,)
        body, closing = reader.block("ENDPROC", u, inside=f"PROC {name}")
        procedures.append(Procedure(u.line, closing.end_line, name, tuple(body)))
    module = Module(m.group(1), tuple(decls), tuple(procedures), tuple(text.splitlines()), path)
    main = module.procedure("main")
    if main is None:
        raise RapidError(f"{path}:{first.line}: the module has no PROC main(); the cycle is read from main")
    if main.params:
        raise RapidError(f"{path}:{main.line}: PROC main has parameters; the cycle starts at main()")
    _check_calls(module)
    return module


def _declarations(path: str, units: list[Unit], scope: Names) -> list[Declaration]:
    """The module's data: nums and bools first (targets may use them), then the rest in order."""
    seen: dict[str, int] = {}
    for u in units:
        dm = _DECL.match(u.text)
        name = dm.group(3).lower() if dm else ""
        if name in seen:
            raise RapidError(f"{path}:{u.line}: {name} is declared twice (first at line {seen[name]})")
        seen[name] = u.line
    by_line: dict[int, Declaration] = {}
    for numeric in (True, False):
        for u in units:
            dm = _DECL.match(u.text)
            type_ = dm.group(2).lower() if dm else ""
            if (type_ in ("num", "bool")) != numeric:
                continue
            if type_ == "bool":
                _bool_declaration(path, u, dm, scope)
                continue
            d = _declaration(path, u, scope)
            if d is None:
                continue
            by_line[u.line] = d
            constant = d.storage in ("CONST", "PERS") and d.name.lower() not in scope.assigned
            if d.type == "num" and isinstance(d.value, float) and constant:
                scope.nums[d.name.lower()] = d.value
            if isinstance(d.value, tuple):
                scope.arrays[d.name.lower()] = (d.storage, d.type, d.value)
    return [by_line[k] for k in sorted(by_line)]


def _bool_declaration(path: str, u: Unit, dm: re.Match[str] | None, scope: Names) -> None:
    assert dm is not None
    storage, _, name, dims, value = dm.groups()
    if dims or value is None or storage.upper() == "VAR" or name.lower() in scope.assigned:
        return
    try:
        v = _evaluate(path, u.line, value, scope, f"the value of {name}")
    except RapidError:
        return
    if isinstance(v, bool):
        scope.bools[name.lower()] = v


def _statements(body: tuple[Statement, ...]) -> Iterator[Statement]:
    """Every statement of a body: inside WHILE TRUE, every run of a FOR loop, chosen branches, calls read."""
    for s in body:
        yield s
        if isinstance(s, WhileTrue | Branch):
            yield from _statements(s.body)
        elif isinstance(s, ForLoop):
            for run in s.runs:
                yield from _statements(run)
        elif isinstance(s, Call) and s.body is not None:
            yield from _statements(s.body)


def _call_sites(body: tuple[Statement, ...]) -> tuple[list[tuple[Call, int]], int]:
    """The calls of procedures read as they are (no arguments) in ``body``, each with how deep
    in blocks it stands, and the deepest block level of ``body``; an explicit stack, no recursion."""
    sites: list[tuple[Call, int]] = []
    deepest = 0
    todo: list[tuple[tuple[Statement, ...], int]] = [(body, 0)]
    while todo:
        stmts, level = todo.pop()
        deepest = max(deepest, level)
        for s in stmts:
            if isinstance(s, Call) and s.body is None:
                sites.append((s, level))
            elif isinstance(s, WhileTrue | Branch):
                todo.append((s.body, level + 1))
            elif isinstance(s, ForLoop):
                todo.extend((run, level + 1) for run in s.runs)
            elif isinstance(s, Call) and s.body is not None:
                todo.append((s.body, level + 1))
    sites.sort(key=lambda site: site[0].line)
    return sites, deepest


def _check_calls(module: Module) -> None:
    """No recursion; calls and blocks nested at most :data:`MAX_NESTING` deep; one WHILE TRUE in main.

    A depth-first walk of the call graph with an explicit stack: each procedure is
    visited once, so the check is linear in the program (30 procedures that each call
    the next twice cost 30 visits, not 2**30), and no chain of calls, however long,
    reaches Python's recursion limit.
    """
    main = module.procedure("main")
    assert main is not None
    loops = [s for s in main.body if isinstance(s, WhileTrue)]
    if len(loops) > 1:
        raise module.error(loops[1].line, "a second WHILE TRUE in main; the cycle is one loop")
    depth: dict[str, int] = {}  # a finished procedure: how deep blocks and calls nest below its start
    sites_of: dict[str, tuple[list[tuple[Call, int]], int]] = {"main": _call_sites(main.body)}
    path: list[tuple[str, int]] = [("main", 0)]  # the procedures being walked, each with its next site
    while path:
        name, k = path[-1]
        sites, deepest = sites_of[name]
        if k == len(sites):
            path.pop()
            depth[name] = max([deepest, *(lv + 1 + depth[c.name.lower()] for c, lv in sites)])
            if depth[name] > MAX_NESTING:
                proc = module.procedure(name)
                assert proc is not None
                raise module.error(
                    proc.line,
                    f"blocks and calls nest {depth[name]} deep below {proc.name} (at most {MAX_NESTING}); "
                    "call the procedures one after another instead of each from the previous",
                )
            continue
        path[-1] = (name, k + 1)
        call, _ = sites[k]
        key = call.name.lower()
        if key in depth:
            continue
        on_path = [n for n, _ in path]
        if key in on_path:
            raise module.error(
                call.line, f"{call.name} calls itself (through {' -> '.join(on_path)}); not supported"
            )
        if len(path) > MAX_NESTING:
            raise module.error(
                call.line,
                f"calls nest more than {MAX_NESTING} deep ({' -> '.join(on_path[:3])} -> ... -> "
                f"{call.name}); call the procedures one after another instead of each from the previous",
            )
        callee = module.procedure(call.name)
        assert callee is not None
        sites_of[key] = _call_sites(callee.body)
        path.append((key, 0))


def read_module(path: str | Path) -> Module:
    """Read a RAPID module file (UTF-8 or Latin-1)."""
    p = Path(path)
    raw = read_capped(p, max_bytes=MAX_MODULE_BYTES, what="a RAPID .mod file", error=RapidError)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    return parse_module(text, path=str(p))
