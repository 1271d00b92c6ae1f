"""The interpreter's state: its limits, the data it stores (:class:`Cell`, :class:`Ref`, the call
:class:`Frame`), RAPID's predefined data, and the signals that end a statement list early (``GOTO``,
``RETURN``, ``EXIT``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from joulepath.errors import RapidError
from joulepath.rapid import nodes as n
from joulepath.rapid._trace import CLEAN, Taint
from joulepath.rapid.values import Array, Record, Types, Value

MAX_STEPS = 200_000
"""Statements and expression calls one run may take before it is stopped as never ending."""
MAX_SECONDS: float | None = None
"""Wall time one run may take (s; None: none, the default: a run is bounded by its statements, so the
same program is read the same on any machine)."""
MAX_DEPTH = 128
"""Deepest routine call (recursion) one run may take: published programs nest deeper than 32 (a
welding task's call chain; a palletizer that recurses once per box)."""
MAX_LOOP_TURNS = 200_000
"""Turns one loop may take."""
SPIN_TURNS = 1000
"""Turns of a loop that moves nothing, on data set outside the task, before it is taken to end."""
UNTYPED = "(declared nowhere)"
"""The type of a value declared nowhere whose role nothing fixes: it takes what it is assigned."""
UNKNOWN_TARGET = "an unknown target"
"""The words that mark a target the program does not give (declared nowhere, or known only at run time
and not reachable as its stand-in): its move is placed where the arm is and kept as taught."""

SPEEDS: tuple[int, ...] = (5, 10, 20, 30, 40, 50, 60, 80, 100, 150, 200, 300, 400, 500, 600, 800, 1000)
SPEEDS += (1500, 2000, 2500, 3000, 4000, 5000, 6000, 7000)
ZONES = (0, 1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200)


# ------------------------------------------------------------------ control flow signals
class GotoLabel(Exception):
    def __init__(self, label: str, pos: n.Pos) -> None:
        self.label, self.pos = label, pos


class ReturnValue(Exception):
    def __init__(self, value: Value, taint: Taint) -> None:
        self.value, self.taint = value, taint


class StopRun(Exception):
    """The run ends: ``EXIT``, ``ExitCycle``, or the cycle's turn is done."""

    def __init__(self, why: str) -> None:
        self.why = why


class CycleRestart(StopRun):
    """``ExitCycle``: the controller breaks the cycle and starts ``main`` again, its data kept."""


# ------------------------------------------------------------------ storage
class Cell:
    """A datum: its type, storage class, value, the reasons it is uncertain, and where it is declared."""

    __slots__ = ("type", "storage", "value", "taint", "pos", "name")

    def __init__(self, name: str, type_: str, storage: str, value: Value, taint: Taint, pos: n.Pos | None):
        self.name, self.type, self.storage, self.value, self.taint, self.pos = (
            name,
            type_,
            storage,
            value,
            taint,
            pos,
        )


@dataclass(slots=True)
class Ref:
    """A reference to part of a datum (``INOUT`` / ``VAR`` / ``PERS`` arguments, assignments)."""

    cell: Cell
    path: tuple[tuple[str, object], ...] = ()

    def get(self) -> Value:
        v = self.cell.value
        for kind, key in self.path:
            if kind == "opq":  # a component of an option's data that the interpreter does not model
                return 0.0
            if kind == "idx":
                assert isinstance(v, Array) and isinstance(key, tuple)
                v = v.items[v.offset(key)]
            else:
                assert isinstance(v, Record) and isinstance(key, str)
                v = v.get(key)
        return v

    def set(self, value: Value, taint: Taint) -> None:
        def put(v: Value, path: tuple[tuple[str, object], ...]) -> Value:
            if not path:
                return value
            kind, key = path[0]
            if kind == "idx":
                assert isinstance(v, Array) and isinstance(key, tuple)
                k = v.offset(key)
                items = list(v.items)
                items[k] = put(items[k], path[1:])
                return Array(v.type, v.dims, tuple(items))
            assert isinstance(v, Record) and isinstance(key, str)
            return v.replace(key, put(v.get(key), path[1:]))

        if any(kind == "opq" for kind, _ in self.path):
            return  # a component of an option's data (seamdata ...): not modelled, the datum kept
        self.cell.value = put(self.cell.value, self.path)
        self.cell.taint = (self.cell.taint | taint) if self.path else taint


@dataclass(slots=True)
class Frame:
    routine: n.Routine | None
    module: n.Module | None
    locals: dict[str, Cell | Ref]
    present: set[str]
    label: str


def predefined_data(types: Types) -> dict[str, Cell]:
    out: dict[str, Cell] = {}

    def put(name: str, type_: str, value: Value, storage: str = "CONST") -> None:
        out[name.lower()] = Cell(name, type_, storage, types.coerce(value, type_), CLEAN, None)

    for v in SPEEDS:
        put(f"v{v}", "speeddata", (float(v), 500.0, 5000.0, 1000.0))
    put("vmax", "speeddata", (5000.0, 500.0, 5000.0, 1000.0))
    put("fine", "zonedata", (True, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    for z in ZONES:
        r = float(z) if z else 0.3
        put(f"z{z}", "zonedata", (False, r, 1.5 * r, 1.5 * r, 0.15 * r, 1.5 * r, 0.15 * r))
    pose0 = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    load0 = (0.0, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 0.0, 0.0, 0.0)
    put("load0", "loaddata", load0)
    put("tool0", "tooldata", (True, pose0, load0), "PERS")
    put("wobj0", "wobjdata", (False, True, "", pose0, pose0), "PERS")
    for k in range(1, 6):
        put(f"reg{k}", "num", 0.0, "VAR")
    for pct in (20, 50, 100):  # ABB's in-position stop point data: position and speed in % of fine
        put(
            f"inpos{pct}",
            "stoppointdata",
            (1.0, False, float(pct), float(pct), 0.0, 20.0, 0.0, 0.0, "", 0.0, 0.0),
        )
    for name, value in (("pi", math.pi),):
        put(name, "num", value)
    put("WAIT_MAX", "num", 8388608.0)  # RAPID's "wait forever" for \\MaxTime, \\Time
    for k, state in enumerate(("CREATED", "CONNECTED", "BOUND", "LISTENING", "CLOSED"), start=1):
        put(f"SOCKET_{state}", "num", float(k))  # socketstatus (Socket Messaging: SocketGetStatus)
    return out


def signal_kind(name: str) -> str:
    low = name.lower()
    for k in ("di", "do", "gi", "go", "ai", "ao"):
        if low.startswith(k) or low.startswith("s" + k) or low.startswith(k + "_"):
            return k
    return "di"


def opaque_ok(type_: str) -> bool:
    return type_ in OPAQUE_TYPES


OPAQUE_TYPES = {
    "triggdata", "intnum", "clock", "iodev", "socketdev", "socketstatus", "rawbytes", "dir",
    "errstr", "btnres", "listitem", "cameradev", "cameratarget", "rmqslot", "rmqmessage",
    "syncident", "tasks", "identno", "mecunit", "seamdata", "welddata", "weavedata", "trackdata",
    "arcdata", "paintdata", "gundata", "dispdata", "triggios", "triggstrgo", "aiotrigg", "restrdata",
    "shapedata", "wzstationary", "wztemporary", "loadidnum", "sensor", "egmident", "egm_minmax",
    "pathrecid", "opnum", "dionum", "switch", "signalorigin", "datapos", "taskid", "tpnum", "uishownum",
    "icondata", "buttondata", "exec_level", "event_type", "handler_type", "trapdata", "errdomain",
    "errtype", "progdisp", "stoppointdata", "motsetdata", "corrdescr", "capdata", "capweavedata",
    "flypointdata", "capspeeddata", "captestno", "stopmovestartmove_mem", "string_format",
}  # fmt: skip


def show(v: Value) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return repr(v) if isinstance(v, str) else str(v)


def parse_literal(text: str) -> n.Expr:
    """A literal (number, bool, string or aggregate of them) parsed by the grammar; RapidError else."""
    from joulepath.rapid._parse import parse_module

    m = parse_module(f"MODULE jp_literal\nPROC jp_literal()\njp_value := {text};\nENDPROC\nENDMODULE\n")
    stmt = m.routines[0].body[0]
    assert isinstance(stmt, n.Assign)

    def literal(e: n.Expr) -> bool:
        if isinstance(e, (n.Num, n.Str, n.Bool)):
            return True
        if isinstance(e, n.Neg):
            return literal(e.a)
        if isinstance(e, n.Aggregate):
            return all(literal(i) for i in e.items)
        return False

    if not literal(stmt.value):
        raise RapidError(f"StrToVal: {text!r} is not a literal value")
    return stmt.value
