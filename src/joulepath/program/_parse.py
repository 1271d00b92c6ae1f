"""A strict reader of the RAPID subset joulepath optimizes; every error names its line.

Read (and checked): ``MODULE`` / ``ENDMODULE``; ``PROC name()`` / ``ENDPROC``;
``CONST`` / ``PERS`` / ``VAR`` declarations of ``jointtarget``, ``robtarget``,
``speeddata``, ``zonedata``, ``tooldata`` and ``num`` (a literal value);
``MoveAbsJ`` / ``MoveJ`` / ``MoveL`` with ``\\V``, ``\\T``, ``\\Z``, ``\\WObj:=wobj0``
(and ``\\NoEOffs`` on ``MoveAbsJ``); ``WaitTime``; ``WHILE TRUE DO`` in ``main``;
calls of the module's procedures without arguments; one-dimensional arrays of
``jointtarget``, ``robtarget`` and ``num`` (``CONST jointtarget OPT{3} := [...]``), and
of ``speeddata`` / ``zonedata`` (literal values or predefined names: ``[v100, v7000]``);
``FOR i FROM a TO b [STEP s] DO`` with moves or calls inside, when its bounds are
whole numbers or ``CONST num``: the loop is unrolled (its body read once per value
of ``i``), and ``i`` may index the arrays (``MoveAbsJ OPT{i}, v1000 \\T:=OPT_T{i}, ...``).
Indices are whole numbers, ``CONST num``, the variables of the FOR loops around or
elements of ``CONST num`` arrays (``SPEED_ARR{SPEED_IDX{i}}``, as ``JPCollect.mod`` in
table mode writes).

Kept verbatim, their run time treated as fixed: every other instruction
(``SetDO``, ``WaitDI``, ``TPWrite`` ...), declarations of other types, ``FUNC`` and
``TRAP`` routines, and ``IF`` / ``FOR`` / ``TEST`` / other ``WHILE`` blocks without a
move inside.

Refused (:class:`RapidError`, one line ``file:line: what; how to fix``): syntax
errors, unknown names, arguments joulepath does not model (``\\Conc``, ``\\ID``,
``\\Inpos``, a work object other than ``wobj0`` ...), other motion instructions
(``MoveC``, ``SearchL`` ...), instructions that change how the robot moves
(``VelSet``, ``AccSet``, ``ConfJ \\Off`` ...), moves inside conditional blocks and
other ``WHILE`` loops, and FOR loops with moves inside whose bounds are not constants.
Reading never executes anything.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from joulepath.program._model import (
    Call,
    Declaration,
    ForLoop,
    JointTarget,
    Module,
    Move,
    Procedure,
    RapidError,
    RobTarget,
    Statement,
    ToolData,
    Value,
    Verbatim,
    WaitTime,
    WhileTrue,
    ZoneData,
)
from joulepath.sim._steps import SpeedData

READ_TYPES = ("jointtarget", "robtarget", "speeddata", "zonedata", "tooldata", "num")
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
)
MAX_RUNS = 10_000
"""Most runs of one FOR loop with moves inside that are unrolled."""
MAX_UNROLLED = 100_000
"""Most runs of all such FOR loops of a module together (nested runs count each)."""
_FOR = re.compile(
    r"FOR\s+([A-Za-z]\w*)\s+FROM\s+(.+?)\s+TO\s+(.+?)(?:\s+STEP\s+(.+?))?\s+DO", re.IGNORECASE | re.DOTALL
)
BLOCK_CLOSE = {"IF": "ENDIF", "FOR": "ENDFOR", "WHILE": "ENDWHILE", "TEST": "ENDTEST"}
_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")

# predefined data (RobotWare): speeddata v5..v7000, zonedata fine, z0..z200, tool0
PREDEFINED_SPEEDS = {
    f"v{v}": SpeedData(float(v), 500.0, 5000.0, 1000.0)
    for v in (5, 10, 20, 30, 40, 50, 60, 80, 100, 150, 200, 300, 400, 500, 600, 800, 1000)
    + (1500, 2000, 2500, 3000, 4000, 5000, 6000, 7000)
}
PREDEFINED_ZONES = {"fine": ZoneData(True, 0.0)} | {
    f"z{z}": ZoneData(False, float(z) if z else 0.3)
    for z in (0, 1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200)
}
TOOL0 = ToolData(True, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 0.0, (0.0, 0.0, 0.0))


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


def split_units(path: str, text: str) -> list[Unit]:
    """Statements of a RAPID source: comments removed, strings kept, line numbers kept."""
    units: list[Unit] = []
    buf: list[str] = []
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
            current = "".join(buf).strip()
            if current and depth == 0 and _opens_block_line(current):
                units.append(Unit(start, line, current))
                buf = []
            line += 1
            i += 1
            if buf and not "".join(buf).strip():
                buf = []
            if not buf:
                start = line
            else:
                buf.append(" ")
            continue
        if not "".join(buf).strip():
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
            buf = []
            i += 1
            continue
        elif ch == ";":
            raise RapidError(f"{path}:{line}: ';' inside brackets; close the brackets before the ';'")
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

    def value() -> object:
        nonlocal pos
        skip()
        if pos >= len(text):
            raise fail("a value is missing")
        if text[pos] == "[":
            pos += 1
            items: list[object] = []
            skip()
            if pos < len(text) and text[pos] == "]":
                pos += 1
                return items
            while True:
                items.append(value())
                skip()
                if pos < len(text) and text[pos] == ",":
                    pos += 1
                    continue
                if pos < len(text) and text[pos] == "]":
                    pos += 1
                    return items
                raise fail("',' or ']' expected")
        m = _NUMBER.match(text, pos)
        if m:
            pos = m.end()
            return float(m.group())
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


_DECL = re.compile(
    r"^(?:(?:LOCAL|TASK)\s+)?(CONST|PERS|VAR)\s+([A-Za-z]\w*)\s+([A-Za-z]\w*)\s*(\{[^}]*\})?\s*(?::=\s*(.*))?;$",
    re.IGNORECASE | re.DOTALL,
)


def _declaration(path: str, unit: Unit) -> Declaration | None:
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
        if type_l == "num":
            return None
        raise RapidError(f"{path}:{unit.line}: {type_l} {name} has no value; give it one with := [...]")
    try:
        parsed = _value(path, unit.line, type_l, value)
    except RapidError:
        if type_l == "num":  # an expression: kept verbatim, refused only where a move needs it
            return None
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


def _argument(path: str, line: int, text: str) -> tuple[str, dict[str, str | None]]:
    """``primary \\Sw:=value \\Flag`` -> (primary, {switch: value or None})."""
    head, _, rest = text.partition("\\")
    primary = head.strip()
    switches: dict[str, str | None] = {}
    if rest:
        tail = "\\" + rest
        pos = 0
        for m in _SWITCH.finditer(tail):
            if m.start() != pos:
                raise RapidError(f"{path}:{line}: cannot read the argument {text!r}")
            switches[m.group(1)] = m.group(2).strip() if m.group(2) else None
            pos = m.end()
        if pos != len(tail):
            raise RapidError(f"{path}:{line}: cannot read the argument {text!r}")
    return primary, switches


@dataclass
class Names:
    """What a number or an index may name while a routine is read.

    ``nums``: the module's ``CONST num`` (lower-case names); ``arrays``: its arrays
    as (storage, type, elements); ``loop``: the variables of the FOR loops being
    unrolled around the statement, bound to their value in this run.
    """

    nums: dict[str, float] = field(default_factory=dict)
    arrays: dict[str, tuple[str, str, tuple[Value, ...]]] = field(default_factory=dict)
    loop: dict[str, int] = field(default_factory=dict)


_ELEMENT = re.compile(r"^([A-Za-z]\w*)\s*\{\s*(.*?)\s*\}$", re.DOTALL)


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
        return float(text)
    if _IDENT.match(text) and text.lower() in names.loop:
        return float(names.loop[text.lower()])
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
        f"{path}:{line}: {what} must be a number, a num constant of the module or an element of a "
        f"CONST num array, got {text!r}"
    )


def _move(path: str, unit: Unit, names: Names) -> Move:
    instr = unit.head
    body = unit.text[len(instr) :].rstrip(";").strip()
    if body.startswith("\\"):
        sw = body[1:].split()[0].split(",")[0]
        raise RapidError(f"{path}:{unit.line}: {instr} \\{sw} is not supported; remove the \\{sw} argument")
    args = _split_args(path, unit.line, body)
    if len(args) != 4:
        raise RapidError(
            f"{path}:{unit.line}: {instr} needs 4 arguments (target, speed, zone, tool), got {len(args)}"
        )
    allowed = ({"NoEOffs"} if instr == "MoveAbsJ" else set(), {"V", "T"}, {"Z"}, {"WObj"})
    parsed = []
    for text, ok, what in zip(args, allowed, ("target", "speed", "zone", "tool"), strict=True):
        primary, switches = _argument(path, unit.line, text)
        for sw in switches:
            if sw not in ok:
                raise RapidError(
                    f"{path}:{unit.line}: {instr} argument \\{sw} (on the {what}) is not supported; remove it"
                )
        at = _array_element(path, unit.line, primary, names) if what != "tool" else None
        if at is not None:
            primary = f"{at[0]}{{{at[1]}}}"  # the element this run of the loops names
        elif not _IDENT.match(primary):
            raise RapidError(
                f"{path}:{unit.line}: the {what} of {instr} must be a name declared in the module, got "
                f"{primary!r}; declare it (CONST ... := ...) and use its name"
            )
        parsed.append((primary, switches))
    (target, _), (speed, sp), (zone, zs), (tool, ts) = parsed
    wobj = ts.get("WObj")
    if "WObj" in ts and (wobj is None or wobj.strip().lower() != "wobj0"):
        raise RapidError(
            f"{path}:{unit.line}: work object {wobj!r} is not supported; only wobj0 (the base frame)"
        )
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
    return Move(unit.line, unit.end_line, instr, target, speed, v, t, zone, z, tool)


def _wait(path: str, unit: Unit, names: Names) -> WaitTime:
    body = unit.text.split(None, 1)[1].rstrip(";").strip() if len(unit.text.split()) > 1 else ""
    if body.startswith("\\"):
        raise RapidError(f"{path}:{unit.line}: WaitTime {body.split()[0]} is not supported; remove it")
    if not body:
        raise RapidError(f"{path}:{unit.line}: WaitTime needs a time in s")
    seconds = _number(path, unit.line, body, names, "the WaitTime")
    if not 0 <= seconds <= 3600:
        raise RapidError(f"{path}:{unit.line}: WaitTime {seconds:g} s must be within [0, 3600] s")
    return WaitTime(unit.line, unit.end_line, seconds)


@dataclass
class _Reader:
    path: str
    units: list[Unit]
    procs: set[str]
    names: Names
    pos: int = 0
    unrolled: int = 0

    def peek(self) -> Unit | None:
        return self.units[self.pos] if self.pos < len(self.units) else None

    def take(self) -> Unit:
        u = self.units[self.pos]
        self.pos += 1
        return u

    def fail(self, line: int, msg: str) -> RapidError:
        return RapidError(f"{self.path}:{line}: {msg}")

    def block(self, close: str, opener: Unit, *, inside: str) -> tuple[list[Statement], Unit]:
        body: list[Statement] = []
        while True:
            u = self.peek()
            if u is None:
                raise self.fail(opener.line, f"{inside} is not closed; add {close}")
            if u.head.upper() == close:
                return body, self.take()
            if u.head.upper() in ("ENDPROC", "ENDMODULE", "ENDFUNC", "ENDTRAP") and close != u.head.upper():
                raise self.fail(
                    u.line, f"{u.head} before {close} (opened at line {opener.line}); add {close}"
                )
            body.append(self.statement(inside))

    def skip_block(self, opener: Unit, close: str, *, refuse_motion: bool = True) -> Unit:
        """A conditional block kept verbatim; a move inside it is refused."""
        depth = 1
        while True:
            u = self.peek()
            if u is None:
                raise self.fail(opener.line, f"{opener.head.upper()} is not closed; add {close}")
            self.take()
            head = u.head
            up = head.upper()
            if up in BLOCK_CLOSE and u.text.rstrip().upper().endswith(("THEN", "DO")) or up == "TEST":
                depth += 1
            elif up in BLOCK_CLOSE.values():
                depth -= 1
                if depth == 0:
                    return u
            elif up in ("ENDPROC", "ENDMODULE"):
                raise self.fail(u.line, f"{head} before {close} (opened at line {opener.line}); add {close}")
            elif refuse_motion and (head in MOVES or OTHER_MOTION.match(head) or head.lower() in self.procs):
                raise self.fail(
                    u.line,
                    f"{head} inside {opener.head.upper()} (line {opener.line}): moves or calls under a "
                    "condition or a WHILE loop are not supported; take them out of the block",
                )

    def has_motion(self) -> bool:
        """Whether the block just opened holds a move or a call; reads nothing."""
        depth = 1
        for u in self.units[self.pos :]:
            head = u.head
            up = head.upper()
            if up in BLOCK_CLOSE and u.text.rstrip().upper().endswith(("THEN", "DO")) or up == "TEST":
                depth += 1
            elif up in BLOCK_CLOSE.values():
                depth -= 1
                if depth == 0:
                    return False
            elif up in ("ENDPROC", "ENDMODULE"):
                return False  # the unclosed block is refused by whoever reads it
            elif head in MOVES or OTHER_MOTION.match(head) or head.lower() in self.procs:
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

    def statement(self, inside: str) -> Statement:
        u = self.take()
        head = u.head
        up = head.upper()
        if up == "FOR" and u.text.rstrip().upper().endswith("DO") and self.has_motion():
            return self.for_loop(u)
        if up == "WHILE" and re.fullmatch(r"WHILE\s+TRUE\s+DO", u.text, re.IGNORECASE):
            if inside != "PROC main":
                raise self.fail(u.line, "WHILE TRUE is read as the cycle only directly in PROC main")
            body, end = self.block("ENDWHILE", u, inside="WHILE TRUE")
            return WhileTrue(u.line, end.end_line, tuple(body))
        if up in BLOCK_CLOSE and (u.text.rstrip().upper().endswith(("THEN", "DO")) or up == "TEST"):
            end = self.skip_block(u, BLOCK_CLOSE[up])
            return Verbatim(u.line, end.end_line, up)
        if up == "IF":  # compact IF: IF condition instruction;
            words = set(re.findall(r"[A-Za-z]\w*", u.text))
            if any(OTHER_MOTION.match(w) or w.lower() in self.procs for w in words):
                raise self.fail(u.line, "a move or call under IF is not supported; take it out of the IF")
            return Verbatim(u.line, u.end_line, "IF")
        if up in ("ELSE", "ELSEIF", "CASE", "DEFAULT", "ENDIF", "ENDFOR", "ENDWHILE", "ENDTEST"):
            raise self.fail(u.line, f"{head} without its opening block")
        if up in ("MODULE", "PROC", "FUNC", "TRAP") or up in ("CONST", "PERS", "VAR"):
            raise self.fail(u.line, f"{head} inside {inside}; close {inside} first")
        if not u.text.endswith(";"):
            raise self.fail(u.line, f"cannot read {u.text[:50]!r}; an instruction ends with ';'")
        if head in MOVES:
            return _move(self.path, u, self.names)
        for m in MOVES:
            if head.lower() == m.lower():
                raise self.fail(u.line, f"{head}: write {m} (RAPID names are read as written here)")
        if OTHER_MOTION.match(head):
            raise self.fail(
                u.line, f"{head} is not supported (joulepath reads MoveAbsJ, MoveJ and MoveL); replace it"
            )
        if head.lower() == "waittime":
            return _wait(self.path, u, self.names)
        for s in MOTION_SETTINGS:
            if head.lower() == s.lower():
                if s in ("ConfJ", "ConfL") and re.search(r"\\\s*On\b", u.text, re.IGNORECASE):
                    return Verbatim(u.line, u.end_line, s)
                raise self.fail(
                    u.line, f"{s} changes how the robot moves and is not modelled; remove it to optimize"
                )
        if head.lower() in self.procs:
            if u.text.rstrip(";").strip().lower() != head.lower():
                raise self.fail(u.line, f"call of {head} with arguments is not supported; call it without")
            return Call(u.line, u.end_line, head)
        if not _IDENT.match(head):
            raise self.fail(u.line, f"cannot read {u.text[:50]!r}")
        return Verbatim(u.line, u.end_line, head)


def parse_module(text: str, *, path: str = "<program>") -> Module:
    """Read a RAPID module (the subset above); ``RapidError`` naming the line otherwise."""
    if "\x00" in text:
        raise RapidError(f"{path}:1: the file holds NUL bytes; it is not a RAPID text file")
    units = split_units(path, text)
    if not units:
        raise RapidError(f"{path}:1: the file is empty; a RAPID module starts with MODULE name")
    first = units[0]
    m = re.fullmatch(r"MODULE\s+([A-Za-z]\w*)\s*(\([^)]*\))?", first.text, re.IGNORECASE)
    if first.head.upper() != "MODULE" or not m:
        raise RapidError(f"{path}:{first.line}: expected 'MODULE name', got {first.text[:40]!r}")
    if units[-1].head.upper() != "ENDMODULE":
        raise RapidError(f"{path}:{units[-1].end_line}: the module does not end with ENDMODULE; add it")
    for u in units[1:-1]:
        if u.head.upper() in ("MODULE", "ENDMODULE"):
            raise RapidError(f"{path}:{u.line}: {u.head} inside the module; one module per file")
    procs = set()
    for u in units:
        pm = re.fullmatch(r"(?:LOCAL\s+)?PROC\s+([A-Za-z]\w*)\s*\(\s*(.*?)\s*\)", u.text, re.IGNORECASE)
        if u.head.upper() == "PROC":
            if not pm:
                raise RapidError(f"{path}:{u.line}: expected 'PROC name()', got {u.text[:40]!r}")
            if pm.group(1).lower() in procs:
                raise RapidError(f"{path}:{u.line}: PROC {pm.group(1)} is defined twice; rename one")
            procs.add(pm.group(1).lower())
    decls: list[Declaration] = []
    names: dict[str, int] = {}
    scope = Names()
    procedures: list[Procedure] = []
    reader = _Reader(path, units[1:-1], procs, scope)
    while (cur := reader.peek()) is not None:
        u = cur
        head = u.head.upper()
        if head in ("CONST", "PERS", "VAR"):
            reader.take()
            d = _declaration(path, u)
            dm = _DECL.match(u.text)
            name = dm.group(3).lower() if dm else ""
            if name in names:
                raise RapidError(f"{path}:{u.line}: {name} is declared twice (first at line {names[name]})")
            names[name] = u.line
            if d is not None:
                decls.append(d)
                if d.type == "num" and isinstance(d.value, float) and d.storage == "CONST":
                    scope.nums[d.name.lower()] = d.value
                if isinstance(d.value, tuple):
                    scope.arrays[d.name.lower()] = (d.storage, d.type, d.value)
        elif head == "PROC":
            reader.take()
            pm = re.fullmatch(r"(?:LOCAL\s+)?PROC\s+([A-Za-z]\w*)\s*\(\s*(.*?)\s*\)", u.text, re.IGNORECASE)
            assert pm is not None
            if pm.group(2):
                raise RapidError(f"{path}:{u.line}: PROC {pm.group(1)} has parameters; not supported")
            body, end = reader.block("ENDPROC", u, inside=f"PROC {pm.group(1)}")
            procedures.append(Procedure(u.line, end.end_line, pm.group(1), tuple(body)))
        elif head in ("FUNC", "TRAP"):
            reader.take()
            close = "END" + head
            while (v := reader.peek()) is not None and v.head.upper() != close:
                if v.head.upper() in ("PROC", "FUNC", "TRAP", "ENDPROC"):
                    raise RapidError(f"{path}:{v.line}: {v.head} inside {head} (line {u.line}); add {close}")
                reader.take()
            if v is None:
                raise RapidError(f"{path}:{u.line}: {head} is not closed; add {close}")
            reader.take()
        else:
            raise RapidError(
                f"{path}:{u.line}: {u.text[:40]!r} at module level; only declarations and routines go there"
            )
    module = Module(m.group(1), tuple(decls), tuple(procedures), tuple(text.splitlines()), path)
    if module.procedure("main") is None:
        raise RapidError(f"{path}:{first.line}: the module has no PROC main(); the cycle is read from main")
    _check_calls(module)
    return module


def _statements(body: tuple[Statement, ...]) -> Iterator[Statement]:
    """Every statement of a body, those inside WHILE TRUE and every run of a FOR loop included."""
    for s in body:
        yield s
        if isinstance(s, WhileTrue):
            yield from _statements(s.body)
        elif isinstance(s, ForLoop):
            for run in s.runs:
                yield from _statements(run)


def _check_calls(module: Module) -> None:
    """No recursion; at most one WHILE TRUE in main."""
    main = module.procedure("main")
    assert main is not None
    loops = [s for s in main.body if isinstance(s, WhileTrue)]
    if len(loops) > 1:
        raise module.error(loops[1].line, "a second WHILE TRUE in main; the cycle is one loop")

    def visit(proc: Procedure, stack: tuple[str, ...]) -> None:
        calls: dict[str, Call] = {}  # each callee once (a FOR loop repeats its calls)
        for s in _statements(proc.body):
            if isinstance(s, Call):
                calls.setdefault(s.name.lower(), s)
        for s in calls.values():
            if s.name.lower() in stack:
                raise module.error(
                    s.line, f"{s.name} calls itself (through {' -> '.join(stack)}); not supported"
                )
            callee = module.procedure(s.name)
            assert callee is not None
            visit(callee, (*stack, callee.name.lower()))

    visit(main, ("main",))


def read_module(path: str | Path) -> Module:
    """Read a RAPID module file (UTF-8 or Latin-1)."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as err:
        raise RapidError(f"{p}: cannot be read ({err.strerror}); give a RAPID .mod file") from err
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    return parse_module(text, path=str(p))
