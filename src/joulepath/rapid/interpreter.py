"""Run a RAPID task as the controller would, to find the motion of one cycle.

The interpreter walks the typed tree (:mod:`joulepath.rapid.nodes`) with its state held
explicitly: the task's data (module scope, ``LOCAL`` data per module), an environment per
routine call (parameters by reference for ``INOUT`` / ``VAR`` / ``PERS``, by value for
``IN``), typed values with RAPID's rules (:mod:`joulepath.rapid.values`), the motion
settings in force (``AccSet``, ``VelSet``, ``GripLoad``, ``ConfJ`` / ``ConfL``, ``SingArea``,
``PDispSet``), and one step budget checked in one place (:meth:`Interpreter._tick`).

**Known and unknown.** What the program learns only while it runs (digital, group and
analog inputs, ``WaitDI`` / ``WaitUntil``, socket and vision data, operator input, another
task's data, a random number) comes from the scenario (``io``) where the user gives it.
Where not, it takes a stand-in (an input reads 0, a received string is empty, a variable
keeps the value it holds) and is *marked*: every value carries the set of reasons it is
not certain, which flows through expressions, assignments and calls. A branch or loop
decided by a marked condition runs its stand-in choice with everything inside marked,
and the first move after it (whose start depends on that choice) is marked too. A move
with a marked target, speed, zone, tool or context is kept as taught by the optimizer,
and the report names it with the reasons. Only text that is not RAPID, a name declared
nowhere, an unreachable target and a program that never ends are refused
(:class:`~joulepath.rapid.RapidError`, one line ``file:line: what; how to fix``).

**The cycle.** The program runs from ``main`` (or the routine given). The first endless
loop it enters (``WHILE TRUE``, or ``WHILE`` on a ``bool`` no statement assigns) is the
production loop: a turn of it is the cycle (the second: it starts where a turn ends, with the
motion settings a turn leaves, as every later one does); what ran before it is the way there.
Without such a loop the cycle is one run of the routine. ``TRAP`` routines and ``ERROR`` /
``UNDO`` / ``BACKWARD`` handlers are read and kept, never run.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from joulepath._typing import FloatArray
from joulepath.errors import RapidError
from joulepath.rapid import _standins as standins
from joulepath.rapid import builtins
from joulepath.rapid import geometry as geo
from joulepath.rapid import nodes as n
from joulepath.rapid.task import Task
from joulepath.rapid.values import (
    NUM_TYPES,
    SIGNAL_TYPES,
    Array,
    Record,
    Signal,
    TypeErrorRapid,
    Types,
    Value,
    describe,
    equal,
    make_orient,
    make_pos,
    num,
    pos_values,
)

Taint = frozenset[str]
CLEAN: Taint = frozenset()

MAX_STEPS = 200_000
"""Statements and expression calls one run may take before it is stopped as never ending."""
MAX_SECONDS: float | None = None
"""Wall time one run may take (s; None: none, the default: a run is bounded by its statements, so the
same program is read the same on any machine)."""
MAX_DEPTH = 32
"""Deepest routine call (recursion) one run may take."""
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

RAPID_AXES = 6
JOINT_MOTIONS = {"movej": "MoveJ", "movejdo": "MoveJ", "movejsync": "MoveJ", "triggj": "MoveJ"}
LINEAR_MOTIONS = {
    "movel": "MoveL",
    "moveldo": "MoveL",
    "movelsync": "MoveL",
    "triggl": "MoveL",
    "triggliosens": "MoveL",
}
CIRCULAR_MOTIONS = {"movec": "MoveC", "movecdo": "MoveC", "movecsync": "MoveC", "triggc": "MoveC"}
ABSJ_MOTIONS = {"moveabsj": "MoveAbsJ", "moveabsjsync": "MoveAbsJ", "triggabsj": "MoveAbsJ"}
PROCESS_LINEAR = {
    "arcl", "arclstart", "arclend", "arcl1", "arcl2", "paintl", "displ", "capl", "caplstart", "caplend",
    "laserl", "cutl", "gluel", "dispensel",
}  # fmt: skip
PROCESS_CIRCULAR = {"arcc", "arccstart", "arccend", "arcc1", "arcc2", "paintc", "dispc", "capc", "gluec"}
SEARCH_MOTIONS = {"searchl": "MoveL", "searchc": "MoveC", "searchj": "MoveJ", "searchextj": "MoveJ"}

IO_SETTERS = {"setdo", "set", "reset", "pulsedo", "invertdo", "setgo", "setao", "setdosync"}
IO_WAITS = {"waitdi", "waitdo", "waitgi", "waitgo", "waitai", "waitao"}
INPUT_WRITERS = {
    "tpreadnum": (0,),
    "tpreaddnum": (0,),
    "tpreadfk": (0,),
    "uiNumEntry".lower(): (),
    "socketreceive": (),
    "socketreceivefrom": (),
    "readanybin": (1,),
    "readrawbytes": (1,),
    "rmqreadwait": (0,),
    "rmqgetmsgdata": (1,),
    "camgetresult": (1,),
    "searchl": (1,),
    "searchc": (1,),
    "getdataval": (1,),
    "strtoval": (),
    "waitsynctask": (),
}
"""Instructions that write what the program learns at run time: the positional arguments (0-based)
they write; every variable passed as an optional argument (``\\Str:=s``) is written too."""
KNOWN_INSTRUCTIONS = {
    # motion settings and motion control
    "accset", "velset", "gripload", "confj", "confl", "singarea", "pathacclim", "worldacclim",
    "pdispon", "pdispset", "pdispoff", "eoffson", "eoffsset", "eoffsoff", "circpathmode", "motionsup",
    "stopmove", "startmove", "startmovelretry", "stopmovereset", "storepath", "restopath", "clearpath",
    "tuneservo", "tunereset", "softact", "softdeact", "actunit", "deactunit", "mechunitload",
    "syncmoveon", "syncmoveoff", "syncmoveundo", "waitrob", "speedrefresh", "movecsync", "moveextj",
    "indamove", "indcmove", "inddmove", "indrmove", "indreset", "corrcon", "corrdiscon", "corrwrite",
    "corrclear", "triggio", "triggeq", "triggequip", "triggint", "triggspeed", "triggcheckio",
    "triggrampaio", "triggdataset", "triggstopproc", "triggdatareset", "pathrecstart", "pathrecstop",
    "pathrecmovebwd", "pathrecmovefwd", "pathresol", "setsysdata", "getsysdata", "loadid",
    "egmactjoint", "egmactpose", "egmrunjoint", "egmrunpose", "egmstop", "egmreset", "egmsetupuc",
    "egmgetid", "egmstreamstart", "egmstreamstop", "egmmovel", "egmmovec",
    # waits and flow
    "waittime", "waituntil", "waitdi", "waitdo", "waitgi", "waitgo", "waitai", "waitao", "waitsynctask",
    "waitload", "waittestandset", "waitwobj", "dropwobj", "stop", "break", "exitcycle", "systemstopaction",
    "callbyvar", "load", "unload", "startload", "erasemodule", "done",
    # data
    "incr", "decr", "add", "clear", "copyrawbytes", "clearrawbytes", "packrawbytes", "unpackrawbytes",
    "setdataval", "getdataval", "setalldataval", "bitset", "bitclear", "strtoval", "packdnheader",
    # I/O
    "setdo", "set", "reset", "pulsedo", "invertdo", "setgo", "setao", "setdosync", "ioenable",
    "iodisable", "aliasio", "aliasioreset",
    # interrupts and errors
    "connect", "isignaldi", "isignaldo", "isignalgi", "isignalgo", "isignalai", "isignalao", "itimer",
    "idelete", "ienable", "idisable", "isleep", "iwatch", "ipers", "ierror", "ivarval", "raisetouser",
    "errwrite", "errlog", "errraise", "skipwarn", "reseterr", "resetretrycount",
    # operator and text
    "tpwrite", "tperase", "tpreadnum", "tpreaddnum", "tpreadfk", "tpshow", "uimsgbox", "uishow",
    "uinumentry", "uinumtune", "uialphaentry", "uilistview",
    # clocks, files, sockets, messages
    "clkreset", "clkstart", "clkstop", "open", "close", "write", "writebin", "writestrbin",
    "writeanybin", "writerawbytes", "readanybin", "readrawbytes", "rewind", "makedir", "removedir",
    "removefile", "renamefile", "copyfile", "closedir", "opendir", "socketcreate", "socketconnect",
    "socketsend", "socketsendto", "socketreceive", "socketreceivefrom", "socketclose", "socketbind",
    "socketlisten", "socketaccept", "rmqsendmessage", "rmqreadwait", "rmqgetmessage", "rmqgetmsgdata",
    "rmqgetmsgheader", "rmqfindslot", "rmqemptyqueue", "sendsoftid",
    # vision (Integrated Vision), welding and other process setup
    "camreqimage", "camgetresult", "camsetprogrammode", "camsetrunningmode", "camloadjob",
    "camsetexposure", "camsetparameter", "camstartloadjob", "camwaitloadjob", "camflush",
    "arcrefresh", "arckill", "setgripload",
}  # fmt: skip
KNOWN_FUNCTIONS_UNKNOWN_RESULT = {
    "clkread": 0.0, "cdate": "", "ctime": "", "gettime": 0.0, "readnum": 0.0, "readstr": "",
    "readbin": 0.0, "readstrbin": "", "opmode": "", "runmode": "", "isfile": False, "filesize": 0.0,
    "robos": True, "getnextsym": False, "getsysinfo": "", "getservicedata": 0.0, "numtoboolsafe": False,
    "testandset": True, "socketgetstatus": 0.0, "getmecunitname": "", "isstopstateevent": False,
    "rmqgetslotname": "", "uinumentry": 0.0, "uinumtune": 0.0, "uialphaentry": "", "uilistview": 1.0,
    "uimessagebox": 1.0, "tpreadfk": 0.0, "getmotorTorque".lower(): 0.0, "gettaskname": "T_ROB1",
    "isstopmoveact": False, "ismechunitactive": True, "getnextmechunit": False, "distance": 0.0,
    "camnumberofresults": 1.0, "camgetexposure": 0.0, "camgetloadedjob": "", "camgetname": "",
    "ispers": True, "isvar": True, "type": "", "argname": "", "getjointdata": 0.0,
    "testsignread": 0.0, "eventtype": 0.0, "execlevel": 0.0, "remainingretries": 0.0,
}  # fmt: skip
"""Built-in functions whose result is known only while the program runs, with their stand-in."""


class Kinematics(Protocol):
    """What the interpreter asks of the robot (SI, 4x4 transforms of the flange in the base)."""

    def joints(
        self, flange: FloatArray, conf: tuple[int, int, int, int] | None, near: FloatArray | None
    ) -> FloatArray | None: ...

    def flange(self, q: FloatArray) -> FloatArray: ...

    def confdata(self, q: FloatArray) -> tuple[int, int, int, int]: ...

    def in_range(self, q: FloatArray) -> int | None: ...

    def reach_m(self) -> float | None: ...


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


# ------------------------------------------------------------------ control flow signals
class _Goto(Exception):
    def __init__(self, label: str, pos: n.Pos) -> None:
        self.label, self.pos = label, pos


class _Return(Exception):
    def __init__(self, value: Value, taint: Taint) -> None:
        self.value, self.taint = value, taint


class _Stop(Exception):
    """The run ends: ``EXIT``, ``ExitCycle``, or the cycle's turn is done."""

    def __init__(self, why: str) -> None:
        self.why = why


class _Raise(Exception):
    def __init__(self, pos: n.Pos) -> None:
        self.pos = pos


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
class _Ref:
    """A reference to part of a datum (``INOUT`` / ``VAR`` / ``PERS`` arguments, assignments)."""

    cell: Cell
    path: tuple[tuple[str, object], ...] = ()

    def get(self) -> Value:
        v = self.cell.value
        for kind, key in self.path:
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

        self.cell.value = put(self.cell.value, self.path)
        self.cell.taint = (self.cell.taint | taint) if self.path else taint


@dataclass(slots=True)
class _Frame:
    routine: n.Routine | None
    module: n.Module | None
    locals: dict[str, Cell | _Ref]
    present: set[str]
    label: str


def _predefined(types: Types) -> dict[str, Cell]:
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


ERROR_CONSTANTS = {"errno", "err_", "intno"}


# ------------------------------------------------------------------ the interpreter
class Interpreter:
    """One run of a task: :meth:`run` gives the :class:`Trace` (see the module's docstring)."""

    def __init__(
        self,
        task: Task,
        *,
        io: Mapping[str, float | str | bool] | None = None,
        seed: int = 0,
        kinematics: Kinematics | None = None,
        max_steps: int = MAX_STEPS,
        max_seconds: float | None = MAX_SECONDS,
        progress: Callable[[str], None] | None = None,
        given: Mapping[str, Value] | None = None,
        rated_payload_kg: float | None = None,
    ) -> None:
        self.task = task
        self.given = {k.lower(): v for k, v in (given or {}).items()}
        self.rated_payload_kg = rated_payload_kg
        self.assumed: list[standins.Assumption] = []
        self._assumed_routines: set[str] = set()
        self.types = Types()
        self.kin = kinematics
        self.rng = np.random.default_rng(seed)
        self.seed = seed
        self.io = {k.lower(): v for k, v in (io or {}).items()}
        self.io_used: set[str] = set()
        self.max_steps, self.max_seconds = max_steps, max_seconds
        self.progress = progress
        self.steps = 0
        self.t0 = time.perf_counter()
        self.events: list[Event] = []
        self.notes: list[str] = []
        self._noted: set[str] = set()
        self.cycle_start = 0
        self.cycle_end: int | None = None
        self.loop: n.Pos | None = None
        self.ctx_taint: Taint = CLEAN
        self.after_branch: Taint = CLEAN
        self.settings = MotionSettings()
        self.pdisp: FloatArray | None = None
        self.current_q: FloatArray | None = None
        self.current_taint: Taint = CLEAN
        self.stack: list[_Frame] = []
        self.loops: list[str] = []
        self.outputs: dict[str, Value] = {}
        self._define_types()
        self.predefined = _predefined(self.types)
        for line in task.notes:
            self.note(line)
        self.base = np.eye(4)  # the robot's base frame in the world (MOC.cfg), m
        if task.moc is not None:
            x, y, z = (1000.0 * v for v in task.moc.base_pos_m)
            self.base = geo.frame((x, y, z), task.moc.base_quat)
            for line in task.moc.lines():
                self.note(line)
        self.globals: dict[str, tuple[n.DataDecl, n.Module]] = {}
        self.locals_of: dict[str, dict[str, tuple[n.DataDecl, n.Module]]] = {}
        self.cells: dict[tuple[str, str], Cell] = {}
        self.routines: dict[str, tuple[n.Routine, n.Module]] = {}
        self.local_routines: dict[str, dict[str, tuple[n.Routine, n.Module]]] = {}
        self._index()
        self.assigned = self._assigned_names()
        self.signals_used = self._signal_names()
        self.roles = standins.name_roles(self.task.modules, PROCESS_LINEAR, PROCESS_CIRCULAR)
        self.set_names = self._set_names()
        self._initialising: set[tuple[str, str]] = set()

    # ---- setup
    def _define_types(self) -> None:
        for m in self.task.modules:
            for r in m.records:
                key = r.name.lower()
                if key in self.types.records:
                    raise RapidError(
                        f"{r.pos}: the record type {r.name} is defined twice; keep one definition"
                    )
                self.types.records[key] = tuple((ft, fn.lower()) for ft, fn in r.fields)
            for a in m.aliases:
                self.types.aliases[a.name.lower()] = a.type.lower()
        # RECORD fields were read as (type, name): store as (name, type)
        for m in self.task.modules:
            for r in m.records:
                self.types.records[r.name.lower()] = tuple((fn.lower(), ft) for ft, fn in r.fields)

    def _index(self) -> None:
        where: dict[str, n.Pos] = {}
        for m in self.task.modules:
            mkey = m.name.lower()
            self.locals_of[mkey] = {}
            self.local_routines[mkey] = {}
            for d in m.data:
                key = d.name.lower()
                if d.scope == "LOCAL":
                    self.locals_of[mkey][key] = (d, m)
                    continue
                if key in self.globals and not (
                    d.storage == "PERS" and self.globals[key][0].storage == "PERS"
                ):
                    raise RapidError(
                        f"{d.pos}: {d.name} is also declared at {where[key]}; a task's global names are "
                        "unique: rename one or make it LOCAL"
                    )
                if key not in self.globals:
                    self.globals[key] = (d, m)
                    where[key] = d.pos
            for r in m.routines:
                key = r.name.lower()
                if r.local:
                    self.local_routines[mkey][key] = (r, m)
                    continue
                if key in self.routines:
                    other = self.routines[key][0]
                    raise RapidError(
                        f"{r.pos}: routine {r.name} is also declared at {other.pos}; "
                        "rename one or make it LOCAL"
                    )
                self.routines[key] = (r, m)

    def _walk_stmts(self) -> Iterator[n.Stmt]:
        for m in self.task.modules:
            for r in m.routines:
                if r.kind != "TRAP":
                    yield from n.walk_statements(r.body)

    def _assigned_names(self) -> set[str]:
        out: set[str] = set()
        for s in self._walk_stmts():
            if isinstance(s, n.Assign):
                out.add(n.base_name(s.target) or "")
            elif isinstance(s, n.Call):  # a variable passed to a routine may be written there
                out.update(a.value.name.lower() for a in s.args if isinstance(a.value, n.Name))
        return out - {""}

    def _set_names(self) -> set[str]:
        """Data the task's statements set: assigned, passed to a routine of the task, or written by an
        instruction that writes its argument (``Incr``, ``TPReadNum``, ``SocketReceive`` ...)."""
        out: set[str] = set()
        for s in self._walk_stmts():
            if isinstance(s, n.Assign):
                out.add(n.base_name(s.target) or "")
            elif isinstance(s, n.Call):
                key = s.name.lower()
                documented = builtins.lookup(key) if key not in self.routines else None
                if documented is None:  # a routine of the task (or declared nowhere): it may write any
                    args = [a.value for a in s.args]
                else:
                    written = {p.name.lower() for p in documented.params if p.writes}
                    try:
                        matched = builtins.match_arguments(documented, _pairs(s.args))
                    except builtins.ArgumentError:
                        matched = {}
                    args = [v for k, v in matched.items() if k.lower() in written]
                out.update(name for name in map(n.base_name, args) if name)
        return out

    def _signal_names(self) -> set[str]:
        out = set(self.task.signals)
        io_first = IO_SETTERS | IO_WAITS | {"isignaldi", "isignaldo", "isignalgi", "isignalai", "triggio"}
        io_funcs = {"dinput", "doutput", "ginput", "goutput", "ainput", "aoutput", "testdi", "validio"}
        for s in self._walk_stmts():
            first = next((a for a in s.args if a.kind == "pos"), None) if isinstance(s, n.Call) else None
            if isinstance(s, n.Call) and s.name.lower() in io_first and first is not None:
                v = first.value
                if isinstance(v, n.Name):
                    out.add(v.name.lower())
            if isinstance(s, n.Call) and s.name.lower() in ("movejdo", "moveldo", "movecdo"):
                # MoveLDO ToPoint, Speed, Zone, Tool, Signal, Value (MoveCDO: CirPoint first)
                positional = [a for a in s.args if a.kind == "pos"]
                k = 5 if s.name.lower() == "movecdo" else 4
                v = positional[k].value if len(positional) > k else None
                if isinstance(v, n.Name) and v.name.lower() not in self.globals:
                    out.add(v.name.lower())
        for m in self.task.modules:
            for node in _expressions(m):
                first = (
                    next((a for a in node.args if a.kind == "pos"), None)
                    if isinstance(node, n.FuncCall)
                    else None
                )
                if isinstance(node, n.FuncCall) and node.name.lower() in io_funcs and first is not None:
                    v = first.value
                    if isinstance(v, n.Name):
                        out.add(v.name.lower())
        return out

    # ---- budget
    def _tick(self, pos: n.Pos) -> None:
        self.steps += 1
        if self.steps > self.max_steps or (
            self.max_seconds is not None
            and self.steps % 4096 == 0
            and time.perf_counter() - self.t0 > self.max_seconds
        ):
            raise RapidError(
                f"{pos}: the program runs more than {self.max_steps} statements without finishing a cycle "
                f"({time.perf_counter() - self.t0:.0f} s): a loop that never ends or never moves, or calls "
                "that multiply; give the inputs it waits for (--io) or check the loop's condition"
            )

    def source_of(self, pos: n.Pos) -> str:
        """The source text at ``pos`` (one line, spaces collapsed)."""
        m = self.task.module_of(pos.file)
        if m is None:
            return "(expression)"
        return " ".join(m.text[pos.start : pos.end].split())

    def note(self, text: str) -> None:
        if text not in self._noted:
            self._noted.add(text)
            self.notes.append(text)

    def _context(self) -> tuple[str, ...]:
        out = [f"{f.label}" for f in self.stack[2:]]
        return tuple(out + self.loops)

    # ---- names
    def _module(self) -> n.Module | None:
        return self.stack[-1].module if self.stack else None

    def _global_cell(self, key: str, decl: n.DataDecl, module: n.Module) -> Cell:
        ck = (module.name.lower() if decl.scope == "LOCAL" else "", key)
        cell = self.cells.get(ck)
        if cell is not None:
            return cell
        if ck in self._initialising:
            raise RapidError(f"{decl.pos}: {decl.name} is initialised from itself; give it a value")
        self._initialising.add(ck)
        try:
            saved = self.stack
            self.stack = [_Frame(None, module, {}, set(), module.name)]
            try:
                cell = self._declare(decl)
            finally:
                self.stack = saved
        finally:
            self._initialising.discard(ck)
        self.cells[ck] = cell
        return cell

    def lookup(self, name: str, pos: n.Pos) -> Cell | _Ref:
        key = name.lower()
        if self.stack:
            frame = self.stack[-1]
            if key in frame.locals:
                return frame.locals[key]
            if frame.module is not None:
                local = self.locals_of.get(frame.module.name.lower(), {}).get(key)
                if local is not None:
                    return self._global_cell(key, local[0], local[1])
        if key in self.globals:
            decl, module = self.globals[key]
            return self._global_cell(key, decl, module)
        if key in self.predefined:
            return self.predefined[key]
        if key in self.signals_used or key in self.io:
            ck = ("", key)
            if ck not in self.cells:
                self.cells[ck] = Cell(name, "signal", "IO", Signal(name, _signal_kind(name)), CLEAN, None)
            return self.cells[ck]
        if key == "errno" or key.startswith("err_"):
            return Cell(name, "errnum", "CONST", 0.0, CLEAN, None)
        return self.stand_in(name, pos)

    def stand_in(self, name: str, pos: n.Pos) -> Cell:
        """A name declared nowhere in what was given: a stand-in by the role the program gives it
        (:mod:`joulepath.rapid._standins`), or the scenario's value for it; said once, in
        :attr:`Trace.assumed`."""
        key = name.lower()
        found = self.cells.get(("", key))
        if found is not None:
            return found
        role = self.roles.get(key, "value")
        taint: Taint = CLEAN
        if key in self.given:
            type_ = role if role != "value" else "num"
            given = self.given[key]
            try:
                if isinstance(given, str) and type_ != "string":  # a RAPID literal: "[2000, 500, 5000, 1000]"
                    given, _ = self.ev(_parse_literal(given))
                value = self.types.coerce(given, type_)
            except TypeErrorRapid as err:
                raise RapidError(f"{pos}: the scenario's {name}: {err}; give a {type_}") from None
            said = "the scenario's value"
        else:
            value, taint, said = self._stand_in_value(name, role, pos)
        storage = "CONST" if role in ("tooldata", "wobjdata", "speeddata", "zonedata", "loaddata") else "VAR"
        type_ = UNTYPED if role == "value" and key not in self.given else role
        cell = Cell(name, type_, storage, value, taint, pos)
        self.cells[("", key)] = cell
        self.assumed.append(standins.Assumption(name, role, said, pos))
        return cell

    def _stand_in_value(self, name: str, role: str, pos: n.Pos) -> tuple[Value, Taint, str]:
        pre = self.predefined
        if role == "tooldata":
            payload = self.rated_payload_kg
            mass = 0.0 if payload is None else round(standins.LOAD_FRACTION * payload, 3)
            cog = standins.LOAD_COG_MM if mass > 0 else 0.0
            value = self.types.coerce(
                (
                    True,
                    ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)),
                    (mass, (0.0, 0.0, cog), (1.0, 0.0, 0.0, 0.0), 0.0, 0.0, 0.0),
                ),
                "tooldata",
            )
            load = (
                f"a load of {mass:g} kg ({100 * standins.LOAD_FRACTION:.0f} % of the rated payload) "
                f"{cog:g} mm out along tool0's z"
                if mass > 0
                else "no load (the robot's rated payload is not known)"
            )
            return value, CLEAN, f"tool0's frame and {load}; give [tool.{name}] in the scenario file"
        if role == "wobjdata":
            return (
                pre["wobj0"].value,
                CLEAN,
                f"wobj0 (the robot's base frame); give [wobj.{name}] in the scenario file",
            )
        if role == "speeddata":
            return pre["v1000"].value, CLEAN, f"v1000; give {name} in the scenario file's [data]"
        if role == "zonedata":
            return pre["fine"].value, CLEAN, f"fine (a stop point); give {name} in the scenario file's [data]"
        if role == "loaddata":
            return pre["load0"].value, CLEAN, f"load0 (no load); give {name} in the scenario file's [data]"
        if role in standins.TARGET_TYPES:
            why = frozenset({f"{pos}: {name} is declared nowhere in what was given: {UNKNOWN_TARGET}"})
            said = (
                f"{UNKNOWN_TARGET}: the moves to and from it are kept as taught; give it in the scenario's "
                "[targets]"
            )
            return self.types.default(role), why, said
        why = frozenset({f"{pos}: {name} is declared nowhere in what was given: known only at run time"})
        return 0.0, why, "a value known only at run time (0 taken, and what it decides is marked)"

    def routine(self, name: str, pos: n.Pos) -> tuple[n.Routine, n.Module] | None:
        key = name.lower()
        module = self._module()
        if module is not None:
            local = self.local_routines.get(module.name.lower(), {}).get(key)
            if local is not None:
                return local
        return self.routines.get(key)

    # ---- declarations
    def _dims(self, decl: n.DataDecl) -> tuple[int, ...]:
        dims = []
        for e in decl.dims:
            v, _ = self.ev(e)
            d = num(v)
            if d != int(d) or not 1 <= d <= 100_000:
                raise RapidError(f"{decl.pos}: the array {decl.name} has dimension {d:g}; give 1 to 100000")
            dims.append(int(d))
        if len(dims) > 3:
            raise RapidError(f"{decl.pos}: {decl.name} has {len(dims)} dimensions; RAPID allows 1 to 3")
        return tuple(dims)

    def _declare(self, decl: n.DataDecl) -> Cell:
        type_ = self.types.resolve(decl.type)
        known = type_ in NUM_TYPES or type_ in ("bool", "string") or type_ in self.types.records
        if not known and type_ not in SIGNAL_TYPES and not _opaque_ok(type_):
            raise RapidError(
                f"{decl.pos}: the data type {decl.type} is declared nowhere; pass the module with its "
                "RECORD definition"
            )
        dims = self._dims(decl)
        taint: Taint = CLEAN
        if decl.init is not None:
            value, taint = self.ev(decl.init)
            try:
                value = self.types.array(value, type_, dims) if dims else self.types.coerce(value, type_)
            except TypeErrorRapid as err:
                raise RapidError(f"{decl.pos}: {decl.name}: {err}; correct the value") from None
        elif type_ in SIGNAL_TYPES:
            value = Signal(decl.name, type_[6:])
        elif dims:
            size = int(np.prod(dims))
            value = Array(type_, dims, tuple(self.types.default(type_) for _ in range(size)))
        else:
            value = self.types.default(type_)
            if type_ in standins.TARGET_TYPES and decl.storage == "VAR":  # known once the program sets it
                given = self.given.get(decl.name.lower())
                if given is not None:
                    value = self.types.coerce(given, type_)
                else:
                    taint = frozenset({f"{decl.pos}: {decl.name} is declared without a value"})
        return Cell(decl.name, type_, decl.storage, value, taint, decl.pos)

    # ---- expressions
    def _unfinished(self, p: n.Placeholder) -> RapidError:
        return RapidError(
            f"{p.pos}: {p.text} is a placeholder of unfinished code, and the cycle runs it; write it "
            "(or give --routine NAME to run another routine)"
        )

    def _conditionals(self, args: tuple[n.Arg, ...]) -> tuple[n.Arg, ...]:
        """``\\Arg?Par`` resolved: passed as ``\\Arg:=Par`` where the caller's optional ``Par`` is
        present, else left out (RAPID's conditional argument)."""
        if not any(a.kind == "cond" for a in args):
            return args
        present = self.stack[-1].present if self.stack else set()
        out = []
        for a in args:
            if a.kind != "cond":
                out.append(a)
            elif isinstance(a.value, n.Name) and a.value.name.lower() in present:
                out.append(n.Arg(a.pos, "opt", a.name, a.value))
        return tuple(out)

    def ev(self, e: n.Expr) -> tuple[Value, Taint]:
        if isinstance(e, n.Placeholder):
            raise self._unfinished(e)
        if isinstance(e, n.Num):
            return e.value, CLEAN
        if isinstance(e, n.Str):
            return e.value, CLEAN
        if isinstance(e, n.Bool):
            return e.value, CLEAN
        if isinstance(e, n.Aggregate):
            vals, taint = [], CLEAN
            for item in e.items:
                v, t = self.ev(item)
                vals.append(v)
                taint |= t
            return tuple(vals), taint
        if isinstance(e, (n.Name, n.Index, n.Field)):
            ref = self.ref(e)
            try:
                value = ref.get() if isinstance(ref, _Ref) else ref.value
            except (IndexError, KeyError) as err:
                raise RapidError(f"{e.pos}: {err}; correct the index or component") from None
            cell = ref.cell if isinstance(ref, _Ref) else ref
            taint = cell.taint | self._index_taint(e)
            if isinstance(value, Signal) and value.name:
                return self.read_signal(value, e.pos)
            return value, taint
        if isinstance(e, n.FuncCall):
            self._tick(e.pos)
            return self.call_function(e)
        if isinstance(e, n.Not):
            v, t = self.ev(e.a)
            v = self._signal_value(v, e.pos)
            if not isinstance(v, bool):
                raise RapidError(f"{e.pos}: NOT needs a bool, not {describe(v)}; correct the expression")
            return (not v), t
        if isinstance(e, n.Neg):
            v, t = self.ev(e.a)
            v = self._signal_value(v, e.pos)
            if isinstance(v, Record) and v.type == "pos":
                x, y, z = pos_values(v)
                return make_pos(-x, -y, -z), t
            return -self._num(v, e.pos), t
        if isinstance(e, n.BinOp):
            return self.binop(e)
        raise AssertionError(e)  # pragma: no cover

    def _index_taint(self, e: n.Expr) -> Taint:
        out: Taint = CLEAN
        while isinstance(e, (n.Index, n.Field)):
            if isinstance(e, n.Index):
                for i in e.indices:
                    out |= self.ev(i)[1]
            e = e.base
        return out

    def _num(self, v: Value, pos: n.Pos) -> float:
        try:
            return num(v)
        except TypeErrorRapid as err:
            raise RapidError(f"{pos}: {err}; correct the expression") from None

    def _signal_value(self, v: Value, pos: n.Pos) -> Value:
        return self.read_signal(v, pos)[0] if isinstance(v, Signal) else v

    def read_signal(self, sig: Signal, pos: n.Pos) -> tuple[Value, Taint]:
        key = sig.name.lower()
        if key in self.io:
            self.io_used.add(key)
            v = self.io[key]
            return (float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v), CLEAN
        if key in self.outputs:
            return self.outputs[key], CLEAN
        kind = sig.kind or _signal_kind(sig.name)
        if kind in ("do", "go", "ao"):
            return 0.0, CLEAN  # an output the program has not set: its value at start, 0
        why = f"{pos}: {sig.name} is read at run time (not in the scenario; 0 assumed)"
        return 0.0, frozenset({why})

    def binop(self, e: n.BinOp) -> tuple[Value, Taint]:
        a, ta = self.ev(e.a)
        op = e.op
        if op in ("AND", "OR") and not (ta or self.ctx_taint):
            a = self._signal_value(a, e.pos)
            if op == "AND" and a is False:
                return False, ta
            if op == "OR" and a is True:
                return True, ta
        b, tb = self.ev(e.b)
        a, b = self._signal_value(a, e.pos), self._signal_value(b, e.pos)
        taint = ta | tb
        try:
            result = _apply(op, a, b)
        except (TypeErrorRapid, ZeroDivisionError, ValueError) as err:
            if taint and isinstance(err, (ZeroDivisionError, ValueError)):
                self.note(f"{e.pos}: {op} of a stand-in value fails ({err}); its result is assumed 0")
                return 0.0, taint
            why = "division by zero" if isinstance(err, ZeroDivisionError) else str(err)
            raise RapidError(
                f"{e.pos}: {describe(a)} {op} {describe(b)}: {why}; correct the expression"
            ) from None
        if isinstance(result, float) and not math.isfinite(result):
            if taint:
                self.note(f"{e.pos}: {op} of a stand-in value is not finite; its result is assumed 0")
                return 0.0, taint
            raise RapidError(f"{e.pos}: {describe(a)} {op} {describe(b)} is not a finite number; correct it")
        return result, taint

    def ref(self, e: n.Expr) -> Cell | _Ref:
        if isinstance(e, n.Name):
            return self.lookup(e.name, e.pos)
        if isinstance(e, (n.Index, n.Field)):
            base = self.ref(e.base)
            r = base if isinstance(base, _Ref) else _Ref(base)
            if r.cell.type == UNTYPED:  # an element or component of a value declared nowhere: as unknown
                return r
            if isinstance(e, n.Index):
                idx = []
                for i in e.indices:
                    v, _ = self.ev(i)
                    f = self._num(v, e.pos)
                    if f != int(f):
                        raise RapidError(f"{e.pos}: the index {f:g} is not a whole number; correct it")
                    idx.append(int(f))
                cur = r.get()
                if not isinstance(cur, Array):
                    raise RapidError(f"{e.pos}: {describe(cur)} is not an array; remove the index")
                try:
                    cur.offset(tuple(idx))
                except IndexError as err:
                    if not any(self.ev(i)[1] for i in e.indices):
                        raise RapidError(f"{e.pos}: {err}; correct the index") from None
                    self.note(
                        f"{e.pos}: an index from run-time data ({err} for its stand-in): element 1 assumed"
                    )
                    idx = [1] * len(cur.dims)
                return _Ref(r.cell, (*r.path, ("idx", tuple(idx))))
            cur = r.get()
            if not isinstance(cur, Record) or e.name.lower() not in cur.names:
                raise RapidError(f"{e.pos}: {describe(cur)} has no component {e.name}; correct the name")
            return _Ref(r.cell, (*r.path, ("fld", e.name.lower())))
        raise RapidError(f"{e.pos}: this expression cannot be assigned to; assign to a variable")

    # ---- functions
    def ev_raw(self, e: n.Expr) -> tuple[Value, Taint]:
        """As :meth:`ev`, but a signal named is the signal, not its value (``SetDO do1, 1``)."""
        if isinstance(e, (n.Name, n.Index, n.Field)):
            ref = self.ref(e)
            value = ref.get() if isinstance(ref, _Ref) else ref.value
            if isinstance(value, Signal):
                return value, CLEAN
        return self.ev(e)

    def _args(
        self, args: tuple[n.Arg, ...], *, raw_first: bool = False
    ) -> tuple[list[tuple[Value, Taint]], dict[str, tuple[Value, Taint]]]:
        pos: list[tuple[Value, Taint]] = []
        opt: dict[str, tuple[Value, Taint]] = {}
        for a in args:
            if a.kind == "pos":
                assert a.value is not None
                pos.append(self.ev_raw(a.value) if raw_first and not pos else self.ev(a.value))
            else:
                assert a.name is not None
                opt[a.name.lower()] = self.ev(a.value) if a.value is not None else (True, CLEAN)
        return pos, opt

    def call_function(self, e: n.FuncCall) -> tuple[Value, Taint]:
        e = replace(e, args=self._conditionals(e.args))
        found = self.routine(e.name, e.pos)
        if found is not None:
            r, m = found
            if r.kind != "FUNC":
                raise RapidError(f"{e.pos}: {e.name} is a {r.kind}, not a FUNC; call it as an instruction")
            return self.invoke(r, m, e.args, e.pos)
        key = e.name.lower()
        if key == "strtoval":
            return self.str_to_val(e)
        if key == "present":
            if not e.args or not isinstance(e.args[0].value, n.Name):
                raise RapidError(f"{e.pos}: Present needs a parameter's name")
            name = e.args[0].value.name.lower()
            frame = self.stack[-1]
            return (name in frame.present), CLEAN
        if key == "dim":
            if len(e.args) != 2 or e.args[0].value is None or e.args[1].value is None:
                raise RapidError(f"{e.pos}: Dim needs an array and a dimension number")
            arr, t = self.ev(e.args[0].value)
            d, _ = self.ev(e.args[1].value)
            if not isinstance(arr, Array):
                raise RapidError(f"{e.pos}: Dim of {describe(arr)}, which is not an array")
            k = int(self._num(d, e.pos))
            if not 1 <= k <= len(arr.dims):
                raise RapidError(f"{e.pos}: Dim asks for dimension {k} of an array of {len(arr.dims)}")
            return float(arr.dims[k - 1]), t
        pos, opt = self._args(e.args, raw_first=key in _SIGNAL_FUNCS)
        taint = CLEAN
        for _, t in pos:
            taint |= t
        for _, t in opt.values():
            taint |= t
        vals = [self._signal_value(v, e.pos) if key not in _SIGNAL_FUNCS else v for v, _ in pos]
        try:
            result = self.builtin(key, e, vals, {k: v for k, (v, _) in opt.items()})
        except (TypeErrorRapid, IndexError, ValueError, ZeroDivisionError) as err:
            if not taint:
                raise RapidError(f"{e.pos}: {e.name}: {err}; correct the arguments") from None
            # a stand-in of run-time data the function cannot take: its result is a stand-in too
            self.note(f"{e.pos}: {e.name} of a stand-in value fails ({err}); its result is assumed")
            return _STANDIN_RESULT.get(key, 0.0), taint
        value, extra = result
        return value, taint | extra

    def str_to_val(self, e: n.FuncCall) -> tuple[Value, Taint]:
        """``StrToVal(Str, Val)``: the string read as a value of ``Val``'s type into ``Val``; TRUE if it
        reads. The string is parsed by the grammar as a RAPID literal, never executed."""
        args = [a for a in e.args if a.kind == "pos"]
        if len(args) != 2 or args[0].value is None or args[1].value is None:
            raise RapidError(f"{e.pos}: StrToVal needs a string and a variable")
        text, t = self.ev(args[0].value)
        if not isinstance(text, str):
            raise RapidError(f"{e.pos}: StrToVal reads a string, not {describe(text)}")
        target = self.ref(args[1].value)
        r = target if isinstance(target, _Ref) else _Ref(target)
        cur = r.get()
        ok = False
        value: Value = cur
        if len(text) <= 512 and not any(c in text for c in ";%\n"):
            try:
                node = _parse_literal(text)
                v, _ = self.ev(node)
                if isinstance(cur, Record):
                    value = self.types.coerce(v, cur.type)
                elif isinstance(cur, (float, bool, str)):
                    value = self.types.coerce(
                        v,
                        "num"
                        if isinstance(cur, float) and not isinstance(cur, bool)
                        else "bool"
                        if isinstance(cur, bool)
                        else "string",
                    )
                ok = True
            except (RapidError, TypeErrorRapid):
                ok = False
        if t and not r.path and self._give(r):  # the scenario gives what the string brings
            return True, CLEAN
        if ok:
            r.set(value, t | self.ctx_taint)
        elif t:
            r.set(cur, r.cell.taint | t)
        return ok, t

    def _give(self, r: _Ref) -> bool:
        """Set a datum the outside world writes to the scenario's value for it, where it gives one."""
        given = self.given.get(r.cell.name.lower())
        if given is None:
            return False
        cur = r.get()
        try:
            if isinstance(given, str) and not isinstance(cur, str):
                given, _ = self.ev(_parse_literal(given))
            value = self.types.coerce(given, cur.type) if isinstance(cur, Record) else given
        except (RapidError, TypeErrorRapid) as err:
            raise RapidError(f"the scenario's {r.cell.name}: {err}; give a value of its type") from None
        self.io_used.add(r.cell.name.lower())
        r.set(value, CLEAN)
        return True

    def builtin(self, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]) -> tuple[Value, Taint]:
        pos = e.pos
        t = self.types
        if key in _MATH:
            return _MATH[key](a, opt), CLEAN
        if key == "offs":
            p = t.coerce(a[0], "robtarget")
            assert isinstance(p, Record)
            x, y, z = pos_values(p.get("trans"))
            return p.replace("trans", make_pos(x + num(a[1]), y + num(a[2]), z + num(a[3]))), CLEAN
        if key == "reltool":
            p = t.coerce(a[0], "robtarget")
            assert isinstance(p, Record)
            m = geo.pose_matrix(p)
            step = np.eye(4)
            step[:3, 3] = np.array([num(a[1]), num(a[2]), num(a[3])]) / 1000.0
            m = m @ step @ geo.rotation(0, num(opt.get("rx", 0.0))) @ geo.rotation(1, num(opt.get("ry", 0.0)))
            m = m @ geo.rotation(2, num(opt.get("rz", 0.0)))
            return geo.with_pose(p, m), CLEAN
        if key == "orientzyx":
            return make_orient(geo.orient_zyx(num(a[0]), num(a[1]), num(a[2]))), CLEAN
        if key == "eulerzyx":
            o = t.coerce(a[0], "orient")
            r = geo.quat_to_matrix(geo.orient_values(o))
            zyx = geo.euler_zyx_deg(r)
            k = 0 if "z" in opt else 1 if "y" in opt else 2
            return float(zyx[k]), CLEAN
        if key == "nOrient".lower():
            q = geo.orient_values(t.coerce(a[0], "orient"))
            norm = math.sqrt(sum(v * v for v in q))
            return make_orient(tuple(v / norm for v in q)), CLEAN  # type: ignore[arg-type]
        if key in ("posemult", "poseinv", "posevect"):
            p1 = t.coerce(a[0], "pose")
            assert isinstance(p1, Record)
            m1 = geo.pose_matrix(p1)
            if key == "poseinv":
                return geo.with_pose(p1, np.asarray(np.linalg.inv(m1), dtype=float)), CLEAN
            if key == "posemult":
                p2 = t.coerce(a[1], "pose")
                assert isinstance(p2, Record)
                return geo.with_pose(p1, m1 @ geo.pose_matrix(p2)), CLEAN
            v = np.array([*pos_values(t.coerce(a[1], "pos")), 1000.0]) / 1000.0
            v[3] = 1.0
            w = (m1 @ v)[:3] * 1000.0
            return make_pos(float(w[0]), float(w[1]), float(w[2])), CLEAN
        if key in ("crobt", "cjointt", "calcjointt", "calcrobt", "cpos"):
            return self.kinematic_function(key, e, a, opt)
        if key in ("dinput", "doutput", "ginput", "goutput", "ainput", "aoutput", "testdi"):
            sig = a[0]
            if not isinstance(sig, Signal):
                raise TypeErrorRapid(f"needs an I/O signal, not {describe(sig)}")
            level, taint = self.read_signal(sig, pos)
            if key == "testdi":
                return (num(level) == 1.0), taint
            return level, taint
        if key == "rand":
            why = f"{pos}: Rand() is a random number (the run's seed {self.seed} gives the stand-in)"
            return float(self.rng.random()), frozenset({why})
        if key in KNOWN_FUNCTIONS_UNKNOWN_RESULT:
            why = f"{pos}: {e.name}() is known only while the program runs"
            return KNOWN_FUNCTIONS_UNKNOWN_RESULT[key], frozenset({why})
        if key in _STRING_FUNCS:
            return _STRING_FUNCS[key](a, opt), CLEAN
        documented = builtins.lookup(key)
        if documented is not None and documented.kind is builtins.Kind.FUNCTION:
            why = f"{pos}: {e.name}() " + (
                "is known only while the program runs"
                if documented.runtime
                else "is a RAPID function joulepath does not evaluate: its value is taken as unknown"
            )
            type_ = self.types.resolve(documented.returns or "num")
            try:
                return self.types.default(type_), frozenset({why})
            except (TypeErrorRapid, KeyError):
                return 0.0, frozenset({why})
        role = self.roles.get(key, "value")
        if key not in self._assumed_routines:
            self._assumed_routines.add(key)
            said = (
                f"{UNKNOWN_TARGET} (its value is known only at run time)"
                if role in standins.TARGET_TYPES
                else "a value known only at run time (0 taken, and what it decides is marked)"
            )
            self.assumed.append(standins.Assumption(e.name, "function", said, pos))
        reason = f"{pos}: the function {e.name} is declared nowhere in what was given: " + (
            UNKNOWN_TARGET if role in standins.TARGET_TYPES else "known only at run time"
        )
        if role in standins.TARGET_TYPES:
            return self.types.default(role), frozenset({reason})
        return 0.0, frozenset({reason})

    def kinematic_function(
        self, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
    ) -> tuple[Value, Taint]:
        t = self.types
        tool = t.coerce(opt.get("tool", self.predefined["tool0"].value), "tooldata")
        wobj = t.coerce(opt.get("wobj", self.predefined["wobj0"].value), "wobjdata")
        assert isinstance(tool, Record) and isinstance(wobj, Record)
        if key in ("calcjointt", "calcrobt"):
            tool = t.coerce(a[1], "tooldata") if len(a) > 1 else tool
            assert isinstance(tool, Record)
        if self.kin is None:
            why = frozenset({f"{e.pos}: {e.name} needs the robot's kinematics (none given)"})
            if key in ("cjointt", "calcjointt"):
                return self.types.default("jointtarget"), why
            stand_in = self.types.default("robtarget")
            assert isinstance(stand_in, Record)
            stand_in = stand_in.replace("rot", make_orient((1.0, 0.0, 0.0, 0.0)))
            return (stand_in.get("trans") if key == "cpos" else stand_in), why
        if key == "calcjointt":
            rt = t.coerce(a[0], "robtarget")
            assert isinstance(rt, Record)
            q = self.solve(rt, tool, wobj, e.pos, "CalcJointT")
            return _jointtarget(t, q), CLEAN
        if key == "calcrobt":
            jt = t.coerce(a[0], "jointtarget")
            assert isinstance(jt, Record)
            q = np.radians(_robax(jt))
            return self._robtarget_at(q, tool, wobj), CLEAN
        taint = self.current_taint
        if self.current_q is None:
            taint = frozenset({f"{e.pos}: {e.name} before any move: where the robot stands at the start"})
            q = np.zeros(6)
        else:
            q = self.current_q
        if key == "cjointt":
            return _jointtarget(t, q), taint
        rt = self._robtarget_at(q, tool, wobj)
        if key == "cpos":
            return rt.get("trans"), taint
        return rt, taint

    def _robtarget_at(self, q: FloatArray, tool: Record, wobj: Record) -> Record:
        assert self.kin is not None
        flange = self.base @ self.kin.flange(q)
        tcp = flange @ geo.pose_matrix(_as_record(tool.get("tframe")))
        obj = _wobj_matrix(wobj)
        in_obj = np.linalg.inv(obj) @ tcp
        rt = self.types.default("robtarget")
        assert isinstance(rt, Record)
        rt = geo.with_pose(rt, in_obj)
        conf = self.kin.confdata(q)
        rt = rt.replace("robconf", self.types.coerce(tuple(float(c) for c in conf), "confdata"))
        ext = self.types.coerce((9e9,) * 6, "extjoint")
        return rt.replace("extax", ext)

    def solve(
        self, rt: Record, tool: Record, wobj: Record, pos: n.Pos, what: str, *, linear: bool = False
    ) -> FloatArray:
        """Joint values (rad) of a robtarget in ``wobj`` with ``tool``, as the controller reaches it.

        A joint move with ``ConfJ \\On`` goes to the target's confdata; where no solution matches it
        exactly, the solution nearest the arm whose quadrants of axes 1, 4 and 6 lie within one of the
        programmed ones and whose ``cfx`` is the programmed one is taken, with a warning (the
        controller's configuration monitoring allows a quadrant's change); else the controller stops,
        and so is the program refused. A linear or circular move's configuration follows its path
        from where the arm is (``ConfL`` only monitors it): the solution nearest the arm, with a
        warning where its confdata is not the programmed one. Out of reach: refused, saying how far
        the target lies beyond the robot's reach (a program for a larger arm).
        """
        assert self.kin is not None
        flange = np.linalg.inv(self.base) @ target_flange(rt, tool, wobj, self.pdisp)
        conf = _conf(rt) if (self.settings.conf_l if linear else self.settings.conf_j) else None
        q = self.kin.joints(flange, conf, self.current_q)
        if q is None:
            q = self.kin.joints(flange, None, self.current_q)
            if q is not None and conf is not None:
                q = self._toward_quadrants(q, conf)
                got = self.kin.confdata(q)
                if not linear and (got[3] != conf[3] or any(abs(got[k] - conf[k]) > 1 for k in range(3))):
                    raise RapidError(
                        f"{pos}: {what}: no joint solution matches the target's confdata {list(conf)} (the "
                        f"reachable one nearest the arm is {list(got)}); the controller stops here with "
                        "ConfJ \\On: correct the confdata, or ConfJ \\Off"
                    )
                if got != conf:
                    self.note(
                        f"{pos}: {what}: its confdata {list(conf)} matches no joint solution exactly; "
                        f"moved as the controller moves it, to {list(got)} (the solution nearest the arm)"
                    )
        if q is None:
            raise RapidError(f"{pos}: {what}: {self._beyond_reach(rt, flange)}")
        return q

    def _toward_quadrants(self, q: FloatArray, conf: tuple[int, int, int, int]) -> FloatArray:
        """``q`` with axes 1, 4 and 6 turned by whole turns toward the programmed quadrants (``cf1``,
        ``cf4``, ``cf6``), where the turned value stays within the axis' range: the same pose."""
        assert self.kin is not None
        out = q.copy()
        for axis, cf in ((0, conf[0]), (3, conf[1]), (5, conf[2])):
            centre = (cf + 0.5) * (math.pi / 2)
            turns = round((centre - out[axis]) / (2 * math.pi))
            if turns:
                trial = out.copy()
                trial[axis] += turns * 2 * math.pi
                if self.kin.in_range(trial) is None:
                    out = trial
        return out

    def _beyond_reach(self, rt: Record, flange: FloatArray) -> str:
        where = [round(float(v), 1) for v in (geo.pose_matrix(rt)[:3, 3] * 1000.0)]
        reach = self.kin.reach_m() if self.kin is not None else None
        far = float(np.linalg.norm(flange[:3, 3]))
        if reach is not None and far > reach:
            return (
                f"{1000 * far:.0f} mm from the robot's base, {1000 * (far - reach):.0f} mm beyond its reach "
                f"({1000 * reach:.0f} mm): probably a program for a larger arm; give it with --robot"
            )
        return (
            f"the target at {where} mm (in its work object) is out of the robot's reach with this "
            "orientation and tool; move the target (or give the robot it was taught on with --robot)"
        )

    # ---- routines
    def invoke(self, r: n.Routine, m: n.Module, args: tuple[n.Arg, ...], pos: n.Pos) -> tuple[Value, Taint]:
        if len(self.stack) - 1 >= MAX_DEPTH:  # (the module's frame, then one per routine entered)
            if any(f.routine is r for f in self.stack):
                raise RapidError(
                    f"{pos}: {r.name} calls itself, and calls nest more than {MAX_DEPTH} deep: a recursion "
                    "that never ends; check its end condition"
                )
            raise RapidError(
                f"{pos}: {r.name}: calls nest more than {MAX_DEPTH} deep (a chain of routines); call fewer "
                "routines from each other"
            )
        frame = _Frame(r, m, {}, set(), f"{r.name} ({pos.file}:{pos.line})")
        positional = [p for p in r.params if not p.optional]
        given = [a for a in args if a.kind == "pos"]
        if len(given) != len(positional):
            names = ", ".join(p.name for p in positional) or "none"
            raise RapidError(
                f"{pos}: {r.name} takes {len(positional)} required argument(s) ({names}), "
                f"this call gives {len(given)}; correct the call"
            )
        bindings: list[tuple[n.Param, n.Arg]] = list(zip(positional, given, strict=True))
        for a in args:
            if a.kind == "pos":
                continue
            p = next((p for p in r.params if a.name is not None and p.name.lower() == a.name.lower()), None)
            if p is None:
                raise RapidError(f"{pos}: {r.name} has no parameter {a.name}; correct the call")
            if a.kind == "named":
                bindings = [(q, a) if q is p else (q, b) for q, b in bindings]
            else:
                bindings.append((p, a))
        for p, a in bindings:
            key = p.name.lower()
            frame.present.add(key)
            if a.value is None:  # a switch
                frame.locals[key] = Cell(p.name, "switch", "IN", True, CLEAN, None)
                continue
            if p.access in ("INOUT", "VAR", "PERS") and isinstance(a.value, (n.Name, n.Index, n.Field)):
                frame.locals[key] = self.ref(a.value)
                continue
            value, taint = self.ev(a.value)
            type_ = self.types.resolve(p.type)
            if type_ not in SIGNAL_TYPES:
                value = self._signal_value(value, a.pos)
            try:
                if p.dims:
                    if not isinstance(value, Array):
                        raise TypeErrorRapid(f"an array is needed for {p.name}, not {describe(value)}")
                else:
                    value = self.types.coerce(value, type_)
            except TypeErrorRapid as err:
                raise RapidError(f"{a.pos}: {r.name}, argument {p.name}: {err}; correct the call") from None
            frame.locals[key] = Cell(p.name, type_, "IN", value, taint, None)
        self.stack.append(frame)
        try:
            for d in (s for s in r.body if isinstance(s, n.DataDecl)):
                frame.locals[d.name.lower()] = self._declare(d)
            self.exec_body(r.body)
        except _Return as ret:
            if r.kind == "FUNC":
                assert r.type is not None
                try:
                    value = self.types.coerce(ret.value, r.type)
                except TypeErrorRapid as err:
                    raise RapidError(f"{r.pos}: {r.name} returns {err}; correct its RETURN") from None
                return value, ret.taint
            return None, CLEAN
        finally:
            self.stack.pop()
        if r.kind == "FUNC":
            raise RapidError(f"{r.pos}: the function {r.name} ends without RETURN; add RETURN value;")
        return None, CLEAN

    # ---- statements
    def exec_body(self, body: tuple[n.Stmt, ...]) -> None:
        k = 0
        while k < len(body):
            s = body[k]
            try:
                self.exec(s)
            except _Goto as g:
                idx = next(
                    (
                        j
                        for j, t in enumerate(body)
                        if isinstance(t, n.Label) and t.name.lower() == g.label.lower()
                    ),
                    None,
                )
                if idx is None:
                    raise
                k = idx + 1
                continue
            k += 1

    def exec(self, s: n.Stmt) -> None:
        """Run one statement; an error of a value's type or geometry is refused in one line there."""
        try:
            self._exec(s)
        except RapidError:
            raise
        except (ValueError, TypeErrorRapid, ZeroDivisionError, IndexError, OverflowError) as err:
            text = " ".join(str(err).split())[:160]
            raise RapidError(f"{s.pos}: {text}; correct the statement") from None

    def _exec(self, s: n.Stmt) -> None:
        self._tick(s.pos)
        if isinstance(s, n.Placeholder):
            raise self._unfinished(s)
        if isinstance(s, n.Call):
            self.call(s)
        elif isinstance(s, n.Assign):
            value, taint = self.ev(s.value)
            target = self.ref(s.target)
            r = target if isinstance(target, _Ref) else _Ref(target)
            cell = r.cell
            if cell.storage == "CONST" or cell.storage == "IO":
                raise RapidError(f"{s.pos}: {cell.name} is a {cell.storage}; it cannot be assigned")
            try:
                cur = r.get()
                if cell.type == UNTYPED and not r.path:  # a value declared nowhere: typed by what it gets
                    pass
                elif isinstance(cur, Array):
                    value = self.types.array(value, cur.type, cur.dims)
                elif isinstance(cur, Record):
                    value = self.types.coerce(value, cur.type)
                elif isinstance(cur, bool):
                    value = self.types.coerce(self._signal_value(value, s.pos), "bool")
                elif isinstance(cur, float):
                    value = self.types.coerce(self._signal_value(value, s.pos), "num")
                elif isinstance(cur, str):
                    value = self.types.coerce(value, "string")
            except TypeErrorRapid as err:
                if not taint:
                    raise RapidError(f"{s.pos}: {err}; correct the assignment") from None
                # a stand-in of run-time data that cannot take the datum's type: it keeps its value, marked
                value = cur
                self.note(f"{s.pos}: {' '.join(sorted(taint))[:120]}: its stand-in does not fit; value kept")
            r.set(value, taint | self.ctx_taint | self._index_taint(s.target))
            self.events.append(Action(s, _lvalue_text(s.target), self._context()))
        elif isinstance(s, n.If):
            self.exec_if(s)
        elif isinstance(s, n.For):
            self.exec_for(s)
        elif isinstance(s, n.While):
            self.exec_while(s)
        elif isinstance(s, n.Test):
            self.exec_test(s)
        elif isinstance(s, n.Goto):
            raise _Goto(s.label, s.pos)
        elif isinstance(s, n.Return):
            if s.value is None:
                raise _Return(None, CLEAN)
            v, t = self.ev(s.value)
            raise _Return(self._signal_value(v, s.pos), t | self.ctx_taint)
        elif isinstance(s, n.Exit):
            raise _Stop(f"{s.pos}: EXIT ends the program")
        elif isinstance(s, n.Raise):
            self.note(
                f"{s.pos}: RAISE: an error raised while running is handled by the program's ERROR handler, "
                "which is not part of the cycle; the run goes on after it"
            )
        elif isinstance(s, n.LateCall):
            self.late_call(s)
        elif isinstance(s, (n.Label, n.Empty, n.DataDecl, n.Retry, n.TryNext)):
            return
        elif isinstance(s, n.Connect):
            return
        else:  # pragma: no cover
            raise AssertionError(s)

    def _condition(self, e: n.Expr) -> tuple[bool, Taint]:
        v, t = self.ev(e)
        v = self._signal_value(v, e.pos)
        if isinstance(v, float):
            v = v != 0.0  # a signal compared implicitly
        if not isinstance(v, bool):
            raise RapidError(f"{e.pos}: a condition needs a bool, not {describe(v)}; correct the expression")
        return v, t

    def _under(self, taint: Taint, run: Callable[[], None], stmt: n.Stmt | None = None) -> None:
        """Run ``run`` with ``taint`` added to everything it does (a branch decided at run time); where
        the statement holds a move (``stmt``), the first move after it starts from a place decided too."""
        if not taint:
            run()
            return
        saved = self.ctx_taint
        self.ctx_taint = saved | taint
        try:
            run()
        finally:
            self.ctx_taint = saved
        if stmt is not None and self._has_motion((stmt,), 0):
            self.after_branch = self.after_branch | taint

    def _moves(self) -> int:
        return sum(isinstance(e, Motion) for e in self.events)

    def _has_motion(self, body: tuple[n.Stmt, ...], depth: int) -> bool:
        """Whether a statement list holds a move, directly or in a routine it calls (8 calls deep)."""
        if depth > 8:
            return True
        for s in body:
            if isinstance(s, n.Call):
                key = s.name.lower()
                if key in _ALL_MOTIONS:
                    return True
                found = self.routines.get(key)
                if found is not None and self._has_motion(found[0].body, depth + 1):
                    return True
            elif isinstance(s, n.LateCall):
                return True
            elif isinstance(s, n.If):
                if any(self._has_motion(b, depth) for _, b in s.branches) or self._has_motion(
                    s.orelse, depth
                ):
                    return True
            elif isinstance(s, (n.For, n.While)):
                if self._has_motion(s.body, depth):
                    return True
            elif isinstance(s, n.Test):
                if any(self._has_motion(b, depth) for _, b in s.cases) or self._has_motion(
                    s.default or (), depth
                ):
                    return True
        return False

    def _shared(self, e: object) -> Taint:
        """Why a condition may turn at run time though the task decides none of it: the ``PERS`` and
        ``VAR`` ``bool``, ``num`` and ``string`` data it reads that this task never sets (another task,
        a PC through the robot's interfaces or the HMI sets them). Empty where it reads none."""
        out: set[str] = set()
        for node in _expressions(e):
            if not isinstance(node, n.Name):
                continue
            key = node.name.lower()
            found = self.globals.get(key)
            if found is None or key in self.set_names:
                continue
            decl = found[0]
            if decl.storage != "CONST" and self.types.resolve(decl.type) in ("bool", "num", "dnum", "string"):
                out.add(
                    f"{decl.pos}: {decl.name} is data this task never sets (another task, a PC or the HMI "
                    "sets it)"
                )
        return frozenset(out)

    def _outside(self, e: object, but: set[str] | frozenset[str] = frozenset()) -> Taint:
        """What in a condition the world outside the task may change: the task's ``VAR`` and ``PERS``
        data and its signals (another task, a PC, the HMI or the PLC sets them). A condition that a
        loop or a wait spins on, moving nothing, ends when they change."""
        out: set[str] = set()
        for node in _expressions(e):
            if not isinstance(node, n.Name) or node.name.lower() in but:
                continue
            key = node.name.lower()
            found = self.globals.get(key)
            if found is not None and found[0].storage != "CONST":
                out.add(
                    f"{found[0].pos}: {found[0].name} may be set outside this task (another task, a PC, "
                    "the HMI)"
                )
            elif key in self.signals_used:
                out.add(f"{node.pos}: the signal {node.name} is set outside the task")
        return frozenset(out)

    def _motion_weight(self, body: tuple[n.Stmt, ...], depth: int = 0) -> int:
        """How many move statements a statement list runs once through (calls followed 8 deep)."""
        if depth > 8:
            return 1
        total = 0
        for s in body:
            if isinstance(s, n.Call):
                key = s.name.lower()
                found = self.routines.get(key)
                total += (
                    1
                    if key in _ALL_MOTIONS
                    else self._motion_weight(found[0].body, depth + 1)
                    if found
                    else 0
                )
            elif isinstance(s, n.If):
                total += max(
                    [self._motion_weight(b, depth) for _, b in s.branches]
                    + [self._motion_weight(s.orelse, depth)]
                )
            elif isinstance(s, (n.For, n.While)):
                total += self._motion_weight(s.body, depth)
            elif isinstance(s, n.Test):
                total += max(
                    [self._motion_weight(b, depth) for _, b in s.cases]
                    + [self._motion_weight(s.default or (), depth)]
                )
        return total

    def _most_moving(
        self, options: list[tuple[tuple[n.Stmt, ...], str]], why: str
    ) -> tuple[tuple[n.Stmt, ...], str]:
        """The branch that runs the most moves (the first of equals), labelled with ``why``."""
        body, label = max(options, key=lambda o: self._motion_weight(o[0]))
        return body, f"{label} ({why}: the branch that moves most)"

    def _production_turn(
        self, pos: n.Pos, what: str, options: list[tuple[tuple[n.Stmt, ...], str]], shared: Taint
    ) -> tuple[tuple[n.Stmt, ...], str]:
        """A branch decided by data set outside the task, whose value now runs no move: the production
        turn is taken to be the branch that moves most; said, with how to name another."""
        body, label = self._most_moving(options, "assumed")
        names = "; ".join(sorted(shared))
        self.note(
            f"{pos}: {what} on data set outside the task ({names[:160]}) -> {label}; give the data's value "
            "(--io NAME=VALUE) to optimize another turn"
        )
        return body, label

    def exec_if(self, s: n.If) -> None:
        taint: Taint = CLEAN
        chosen: tuple[n.Stmt, ...] = s.orelse
        label = "ELSE" if s.orelse else "no branch"
        for k, (cond, body) in enumerate(s.branches):
            v, t = self._condition(cond)
            taint |= t
            if v:
                chosen, label = body, "THEN" if k == 0 else f"ELSEIF at line {cond.pos.line}"
                break
        options = [
            (b, "THEN" if k == 0 else f"ELSEIF at line {c.pos.line}") for k, (c, b) in enumerate(s.branches)
        ] + [(s.orelse, "ELSE")]
        if not taint and not self._has_motion(chosen, 0) and self._has_motion((s,), 0):
            shared = frozenset().union(*(self._shared(c) for c, _ in s.branches))
            if shared:  # the production turn of data the HMI, a PC or another task sets: stated, then known
                chosen, label = self._production_turn(s.pos, "IF", options, shared)
        if taint and not self._has_motion(chosen, 0):
            # decided at run time: the stand-in's branch does not move; assume the one that moves most
            chosen, label = self._most_moving(options, "assumed")
        if taint and not self.ctx_taint:
            self.note(f"{s.pos}: IF decided at run time: {'; '.join(sorted(taint))} -> {label} taken")
        elif (
            not taint
            and not self.ctx_taint
            and not s.compact
            and self._has_motion((s,), 0)
            and "assumed" not in label
        ):
            cond = s.branches[0][0]
            v, _ = self._condition(cond)
            self.note(
                f"{s.pos}: IF {self.source_of(cond.pos)} ({'TRUE' if v else 'FALSE'}) -> {label} branch"
            )
        self._under(taint, lambda: self.exec_body(chosen), s)

    def exec_test(self, s: n.Test) -> None:
        v, t = self.ev(s.expr)
        v = self._signal_value(v, s.pos)
        chosen = s.default or ()
        label = "DEFAULT"
        for values, body in s.cases:
            for ve in values:
                cv, ct = self.ev(ve)
                t |= ct
                if equal(v, cv):
                    chosen, label = body, f"CASE {_show(cv)} (line {ve.pos.line})"
                    break
            else:
                continue
            break
        options = [(b, f"CASE at line {vs[0].pos.line}") for vs, b in s.cases] + [
            (s.default or (), "DEFAULT")
        ]
        if not t and not self._has_motion(chosen, 0) and self._has_motion((s,), 0):
            shared = self._shared(s.expr)
            if shared:
                chosen, label = self._production_turn(s.pos, "TEST", options, shared)
        if t and not self._has_motion(chosen, 0):
            chosen, label = self._most_moving(options, "assumed")
        if t and not self.ctx_taint:
            self.note(f"{s.pos}: TEST decided at run time: {'; '.join(sorted(t))} -> {label} taken")
        elif not t and not self.ctx_taint and self._has_motion((s,), 0) and "assumed" not in label:
            self.note(f"{s.pos}: TEST {self.source_of(s.expr.pos)} ({_show(v)}) -> {label} branch")
        self._under(t, lambda: self.exec_body(chosen), s)

    def exec_for(self, s: n.For) -> None:
        a, ta = self.ev(s.start)
        b, tb = self.ev(s.stop)
        step, ts = self.ev(s.step) if s.step is not None else (1.0, CLEAN)
        a, b, step = self._num(a, s.pos), self._num(b, s.pos), self._num(step, s.pos)
        if step == 0:
            raise RapidError(f"{s.pos}: FOR with STEP 0 never ends; give a step")
        taint = ta | tb | ts
        if taint and not self.ctx_taint:
            self.note(f"{s.pos}: FOR bounds known only at run time: {'; '.join(sorted(taint))}")
        frame = self.stack[-1]
        key = s.var.lower()
        saved = frame.locals.get(key)

        def run() -> None:
            i, turns = a, 0
            while (i <= b) if step > 0 else (i >= b):
                turns += 1
                if turns > MAX_LOOP_TURNS:
                    raise RapidError(f"{s.pos}: FOR runs more than {MAX_LOOP_TURNS} turns; run fewer")
                frame.locals[key] = Cell(s.var, "num", "CONST", float(i), taint | self.ctx_taint, s.pos)
                self.loops.append(f"{s.var}={i:g}")
                try:
                    self.exec_body(s.body)
                finally:
                    self.loops.pop()
                i += step

        try:
            self._under(taint, run, s)
        finally:
            if saved is not None:
                frame.locals[key] = saved
            else:
                frame.locals.pop(key, None)

    def _endless(self, cond: n.Expr) -> bool:
        if isinstance(cond, n.Bool):
            return cond.value
        if isinstance(cond, n.Name):
            key = cond.name.lower()
            if key in self.assigned:
                return False
            try:
                v, t = self.ev(cond)
            except RapidError:
                return False
            return v is True and not t
        return False

    def exec_while(self, s: n.While) -> None:
        if self._endless(s.cond):
            if self.cycle_end is None and self.loop is None:
                # the production loop: its first turn starts from where the way there left the robot
                # and with the settings made before it; the turns after it are the cycle that repeats
                # (it starts where a turn ends, with the motion settings a turn leaves), so the cycle
                # is the second turn
                self.loop = s.pos
                self.exec_body(s.body)
                self.cycle_start = len(self.events)
                self.exec_body(s.body)
                self.cycle_end = len(self.events)
                raise _Stop(f"{s.pos}: one turn of the production loop")
            self.note(f"{s.pos}: an endless loop inside the cycle: its first turn is taken")
            self.exec_body(s.body)
            raise _Stop(f"{s.pos}: an endless loop inside the cycle")
        turns = 0
        moving = self._has_motion(s.body, 0)
        while True:
            v, t = self._condition(s.cond)
            if v and not t and not moving and turns >= SPIN_TURNS:
                shared = self._outside(
                    s.cond, but=_set_in(s.body)
                )  # what the loop's own statements set ends it
                if shared:  # it spins, moving nothing, until another task or the HMI sets its data
                    self.note(
                        f"{s.pos}: WHILE waits on data set outside this task ({'; '.join(sorted(shared))}): "
                        f"assumed to end after {turns} turns"
                    )
                    return
            if not v and t and turns == 0 and self._has_motion(s.body, 0):
                v = True  # decided at run time and the stand-in skips it: assume one turn that moves
            if not v:
                if t and self._has_motion(s.body, 0):
                    self.after_branch |= t
                return
            if t:
                if not self.ctx_taint:
                    self.note(f"{s.pos}: WHILE decided at run time: {'; '.join(sorted(t))} -> one turn taken")
                self._under(t, lambda: self.exec_body(s.body), s)
                return
            turns += 1
            if turns > MAX_LOOP_TURNS:
                raise RapidError(
                    f"{s.pos}: WHILE runs more than {MAX_LOOP_TURNS} turns "
                    "without its condition turning FALSE; "
                    "give the inputs it waits for (--io) or check the condition"
                )
            self.exec_body(s.body)

    def late_call(self, s: n.LateCall) -> None:
        v, t = self.ev(s.target)
        if not isinstance(v, str):
            raise RapidError(
                f"{s.pos}: late binding needs a string (the procedure's name), not {describe(v)}"
            )
        if t and self.routine(v, s.pos) is None:  # the name arrives at run time: which routine is unknown
            why = f"{s.pos}: the procedure called here is chosen at run time ({'; '.join(sorted(t))})"
            self.note(f"{why}: not run; the move after it starts from where that leaves the arm")
            self.after_branch = self.after_branch | frozenset({why})
            self.events.append(Action(s, "%late call%", self._context()))
            return
        if t and not self.ctx_taint:
            self.note(f"{s.pos}: the procedure {v!r} is chosen at run time: {'; '.join(sorted(t))}")
        call = n.Call(s.pos, v, s.args)
        self._under(t, lambda: self.call(call), s)

    # ---- instructions
    def call(self, s: n.Call) -> None:
        s = replace(s, args=self._conditionals(s.args))
        key = s.name.lower()
        found = self.routine(s.name, s.pos)
        if found is not None:
            r, m = found
            if r.kind == "FUNC":
                raise RapidError(f"{s.pos}: {s.name} is a FUNC; use its value in an expression")
            if r.kind == "TRAP":
                raise RapidError(f"{s.pos}: {s.name} is a TRAP; it runs on an interrupt, not by a call")
            self.invoke(r, m, s.args, s.pos)
            return
        if key in JOINT_MOTIONS or key in LINEAR_MOTIONS or key in CIRCULAR_MOTIONS or key in ABSJ_MOTIONS:
            self.motion(s, key)
            return
        if key in PROCESS_LINEAR or key in PROCESS_CIRCULAR or key in SEARCH_MOTIONS:
            self.motion(s, key)
            return
        if key == "callbyvar":
            pos, _ = self._args(s.args)
            name = f"{pos[0][0]}{int(num(pos[1][0]))}"
            self._under(pos[0][1] | pos[1][1], lambda: self.call(n.Call(s.pos, name, ())), s)
            return
        if key in KNOWN_INSTRUCTIONS or key in INPUT_WRITERS:
            self.instruction(s, key)
            return
        if not s.name.strip():
            raise RapidError(f"{s.pos}: a call with no procedure name; give the procedure's name")
        documented = builtins.lookup(key)
        if documented is not None and documented.kind is builtins.Kind.INSTRUCTION:
            self.documented_instruction(s, documented)
            return
        if key not in self._assumed_routines:
            self._assumed_routines.add(key)
            said = (
                "a call that does not move the arm and takes no time (an option's instruction or a routine "
                "of a module not given)"
            )
            self.assumed.append(standins.Assumption(s.name, "routine", said, s.pos))
        self.write_inputs(s, key)
        self.events.append(Action(s, s.name, self._context()))

    def documented_instruction(self, s: n.Call, b: builtins.Builtin) -> None:
        """An instruction of RAPID or of an option (:mod:`joulepath.rapid.builtins`) that the cycle's
        model does not run: its arguments checked against its documented signature, what it writes
        from the outside world marked; one that moves the arm makes the next move's start unknown."""
        try:
            matched = builtins.match_arguments(b, _pairs(s.args))
        except builtins.ArgumentError as err:
            raise RapidError(f"{s.pos}: {s.name}: {err}; correct its arguments ({b.signature})") from None
        whose = f"the {b.option} option's" if b.option else "a RAPID"
        if b.effect is builtins.Effect.MOVE:
            why = f"{s.pos}: {s.name} ({whose} instruction) moves the arm in a way joulepath does not model"
            self.note(f"{why}: the move after it starts from where it leaves the arm")
            self.after_branch = self.after_branch | frozenset({why})
        elif b.name.lower() not in self._assumed_routines:
            self._assumed_routines.add(b.name.lower())
            self.note(f"{s.pos}: {s.name}: {whose} instruction, run as no motion and no time")
        written = {p.name.lower() for p in b.writes}
        if written:
            self._mark_written(s, written, matched)
        self.events.append(Action(s, s.name, self._context()))

    def _mark_written(self, s: n.Call, written: set[str], matched: Mapping[str, n.Expr | None]) -> None:
        """Mark the arguments a documented instruction writes (with data known only at run time);
        ``matched``: its arguments by parameter (:func:`joulepath.rapid.builtins.match_arguments`)."""
        why = frozenset({f"{s.pos}: {s.name} writes data known only at run time"})
        for name, a in matched.items():
            if name.lower() not in written or not isinstance(a, (n.Name, n.Index, n.Field)):
                continue
            try:
                target = self.ref(a)
            except RapidError:
                continue
            r = target if isinstance(target, _Ref) else _Ref(target)
            if r.cell.storage in ("CONST", "IO"):
                continue
            if not r.path and self._give(r):
                continue
            r.set(r.get(), r.cell.taint | why)

    def instruction(self, s: n.Call, key: str) -> None:
        ctx = self._context()
        pos_args = [a for a in s.args if a.kind == "pos"]
        if key == "waittime":
            args, opt = self._args(s.args)
            if not args:
                raise RapidError(f"{s.pos}: WaitTime needs a time in s")
            secs, t = args[0]
            seconds = self._num(secs, s.pos)
            if seconds < 0:
                raise RapidError(f"{s.pos}: WaitTime {seconds:g} s: a time is not negative")
            note = ""
            if t:
                note = "its time is known only at run time: " + "; ".join(sorted(t))
            self.events.append(Wait(s, seconds, "inpos" in opt, False, ctx, note))
            return
        if key in IO_WAITS or key == "waituntil":
            self.io_wait(s, key, ctx)
            return
        if key in IO_SETTERS:
            args, _ = self._args(s.args, raw_first=True)
            if args and isinstance(args[0][0], Signal):
                sig = args[0][0]
                value: Value = (
                    1.0
                    if key in ("set", "pulsedo")
                    else 0.0
                    if key == "reset"
                    else (args[1][0] if len(args) > 1 else 0.0)
                )
                self.outputs[sig.name.lower()] = value if key != "pulsedo" else 0.0
            self.events.append(Action(s, s.name, ctx))
            return
        if key in ("incr", "decr", "add", "clear"):
            if not pos_args or pos_args[0].value is None:
                raise RapidError(f"{s.pos}: {s.name} needs a variable")
            target = self.ref(pos_args[0].value)
            r = target if isinstance(target, _Ref) else _Ref(target)
            cur = self._num(r.get(), s.pos)
            if key == "add":
                d, t = self.ev(pos_args[1].value) if len(pos_args) > 1 and pos_args[1].value else (0.0, CLEAN)
                r.set(cur + self._num(d, s.pos), r.cell.taint | t | self.ctx_taint)
            else:
                new = 0.0 if key == "clear" else cur + (1.0 if key == "incr" else -1.0)
                r.set(new, r.cell.taint | self.ctx_taint)
            return
        if key in ("accset", "velset", "gripload", "confj", "confl", "singarea", "pathacclim", "worldacclim"):
            self.setting(s, key)
            return
        if key in ("pdispset", "pdispoff", "pdispon"):
            self.displacement(s, key)
            return
        if key in ("exitcycle",):
            raise _Stop(f"{s.pos}: ExitCycle ends the cycle")
        if key in ("stop", "break"):
            self.note(f"{s.pos}: {s.name} stops the program in manual runs; the cycle goes on after it")
        if key in INPUT_WRITERS or key not in KNOWN_INSTRUCTIONS:
            self.write_inputs(s, key)
        self.events.append(Action(s, s.name, ctx))

    def write_inputs(self, s: n.Call, key: str) -> None:
        """Mark what an instruction that reads the outside world writes."""
        indices = INPUT_WRITERS.get(key, ())
        pos_args = [a for a in s.args if a.kind == "pos"]
        targets = [pos_args[i].value for i in indices if i < len(pos_args)]
        targets += [a.value for a in s.args if a.kind == "opt" and a.value is not None]
        why = frozenset({f"{s.pos}: {s.name} writes data known only at run time"})
        for e in targets:
            if isinstance(e, (n.Name, n.Index, n.Field)):
                try:
                    target = self.ref(e)
                except RapidError:
                    continue
                r = target if isinstance(target, _Ref) else _Ref(target)
                if r.cell.storage in ("CONST", "IO"):
                    continue
                key_name = r.cell.name.lower()
                if not r.path and self._give(r):
                    continue
                if key_name in self.io:  # the scenario gives the value
                    v = self.io[key_name]
                    self.io_used.add(key_name)
                    cur = r.get()
                    if isinstance(cur, float) and isinstance(v, (int, float)):
                        r.set(float(v), CLEAN)
                    elif isinstance(cur, str):
                        r.set(str(v), CLEAN)
                    continue
                r.set(r.get(), r.cell.taint | why)

    def io_wait(self, s: n.Call, key: str, ctx: tuple[str, ...]) -> None:
        args, opt = self._args(s.args)
        if key == "waituntil":
            cond, t = args[0] if args else (True, CLEAN)
            cond = self._signal_value(cond, s.pos)
            if isinstance(cond, float):
                cond = cond != 0.0
            known = not t
            met = cond is True
        else:
            args, opt = self._args(s.args, raw_first=True)
            sig, t0 = args[0]
            v, t1 = self.read_signal(sig, s.pos) if isinstance(sig, Signal) else (sig, CLEAN)
            want = args[1][0] if len(args) > 1 else 1.0
            t = t0 | t1 | (args[1][1] if len(args) > 1 else CLEAN)
            known = not t
            met = equal(v, want)
        note = ""
        outside = (
            self._outside(s.args[0].value) if key == "waituntil" and s.args and known and not met else CLEAN
        )
        if outside:  # a wait on data the task's own statements never met: the outside world ends it
            known, t = False, outside
        if known and not met and "maxtime" not in opt:
            raise RapidError(
                f"{s.pos}: {s.name} never ends: the scenario keeps its condition false; give the input's "
                "value in --io"
            )
        if not known:
            note = "the wait ends when the process says (assumed met): " + "; ".join(sorted(t))
            if not self.ctx_taint:
                self.note(f"{s.pos}: {s.name}: {note}")
        self.events.append(Wait(s, 0.0, "inpos" in opt, True, ctx, note))

    def setting(self, s: n.Call, key: str) -> None:
        args, opt = self._args(s.args)
        taint = CLEAN
        for _, t in args:
            taint |= t
        if taint:
            self.note(
                f"{s.pos}: {s.name} takes values known only at run time; the values it holds now assumed"
            )
        st = self.settings
        vals = [self._signal_value(v, s.pos) for v, _ in args]
        if key == "accset":
            acc, ramp = self._num(vals[0], s.pos), self._num(vals[1], s.pos)
            if not (0 < acc <= 100 and 0 < ramp <= 100):
                raise RapidError(f"{s.pos}: AccSet {acc:g}, {ramp:g}: both are percent, 1 to 100")
            st = replace(st, acc_pct=acc, ramp_pct=ramp)
        elif key == "velset":
            ov, vmax = self._num(vals[0], s.pos), self._num(vals[1], s.pos)
            if not (0 < ov <= 100) or vmax <= 0:
                raise RapidError(
                    f"{s.pos}: VelSet {ov:g}, {vmax:g}: the override is 1 to 100 %, the max above 0"
                )
            st = replace(st, vel_override_pct=ov, vel_max_mm_s=vmax)
        elif key == "gripload":
            load = self.types.coerce(vals[0], "loaddata")
            assert isinstance(load, Record)
            name = s.args[0].value.name if s.args and isinstance(s.args[0].value, n.Name) else "load"
            st = replace(st, grip_load=load if num(load.get("mass")) > 0 else None, grip_load_name=name)
        elif key in ("confj", "confl"):
            on = "off" not in opt
            st = replace(st, conf_j=on) if key == "confj" else replace(st, conf_l=on)
        elif key == "singarea":
            mode = next((k for k in ("wrist", "lockaxis4", "off") if k in opt), "off")
            st = replace(st, sing_area=mode.capitalize())
        elif key == "pathacclim":  # PathAccLim AccLim [\AccMax], DecelLim [\DecelMax]: each on when TRUE
            lims = [v is True for v in vals[:2]] + [False, False]
            acc_max = self._num(opt["accmax"][0], s.pos) if lims[0] and "accmax" in opt else None
            dec_max = self._num(opt["decelmax"][0], s.pos) if lims[1] and "decelmax" in opt else None
            for what, lim in (("AccMax", acc_max), ("DecelMax", dec_max)):
                if lim is not None and not lim > 0:
                    raise RapidError(f"{s.pos}: PathAccLim \\{what}:={lim:g}: give a positive m/s²")
            st = replace(st, path_acc_lim=(acc_max, dec_max))
        elif key == "worldacclim":
            world = self._num(opt["acc"][0], s.pos) if "acc" in opt else None
            st = replace(st, world_acc_lim=world if world is not None and world > 0 else None)
        self.settings = st
        self.events.append(Action(s, s.name, self._context()))

    def displacement(self, s: n.Call, key: str) -> None:
        if key == "pdispoff":
            self.pdisp = None
        elif key == "pdispset":
            args, _ = self._args(s.args)
            p = self.types.coerce(args[0][0], "pose")
            assert isinstance(p, Record)
            self.pdisp = geo.pose_matrix(p)
        else:
            raise RapidError(
                f"{s.pos}: PDispOn computes a displacement from the robot's position when it runs; "
                "use PDispSet with a pose, or remove it"
            )
        self.events.append(Action(s, s.name, self._context()))

    def motion(self, s: n.Call, key: str) -> None:
        """A move: its target, speed, zone, tool and work object, classified by the values' types."""
        if key in JOINT_MOTIONS:
            kind = "joint"
        elif key in LINEAR_MOTIONS or key in PROCESS_LINEAR or key == "searchl":
            kind = "linear"
        elif key in CIRCULAR_MOTIONS or key in PROCESS_CIRCULAR or key == "searchc":
            kind = "circular"
        elif key in ABSJ_MOTIONS:
            kind = "absjoint"
        else:
            kind = "joint"
        taint = self.ctx_taint | self.after_branch
        start_taint = self.current_taint  # the move starts where the last one ended
        self.after_branch = CLEAN
        targets: list[tuple[Record, Taint, str]] = []
        speed = zone = tool = None
        speed_t = zone_t = tool_t = CLEAN
        tool_name = "tool0"
        for a in s.args:
            if a.kind != "pos" or a.value is None:
                continue
            v, t = self.ev(a.value)
            text = _text_of(a, s.pos)
            want = "jointtarget" if kind == "absjoint" else "robtarget"
            if isinstance(v, tuple) and len(targets) < (2 if kind == "circular" else 1):
                try:
                    v = self.types.coerce(v, want)
                except TypeErrorRapid:
                    pass
            if isinstance(v, Record):
                if v.type in ("robtarget", "jointtarget") and len(targets) < (2 if kind == "circular" else 1):
                    targets.append((v, t, text))
                elif v.type == "speeddata" and speed is None:
                    speed, speed_t = v, t
                elif v.type == "zonedata" and zone is None:
                    zone, zone_t = v, t
                elif v.type == "tooldata" and tool is None:
                    tool, tool_t, tool_name = v, t, text
        args_opt = {a.name.lower(): a for a in s.args if a.kind == "opt" and a.name}
        if not targets or speed is None or tool is None or (zone is None and key not in SEARCH_MOTIONS):
            missing = (
                "a target"
                if not targets
                else "a speeddata"
                if speed is None
                else ("a tooldata" if tool is None else "a zonedata")
            )
            raise RapidError(f"{s.pos}: {s.name} needs {missing}; correct the instruction")
        if zone is None:
            fine = self.predefined["fine"].value
            assert isinstance(fine, Record)
            zone = fine
        if speed_t and not all(isinstance(v, float) and v > 0 for v in speed.values[:2]):
            fallback = self.predefined["v1000"].value
            assert isinstance(fallback, Record)
            self.note(
                f"{s.pos}: {s.name}: its speed comes at run time and its stand-in is not a speed: v1000 taken"
            )
            speed = fallback
        self._check_motion_data(speed, zone, s)
        if kind == "circular" and len(targets) < 2:
            raise RapidError(f"{s.pos}: {s.name} needs a circle point and a target; correct the instruction")
        wobj = self.predefined["wobj0"].value
        wobj_name, wobj_t = "wobj0", CLEAN
        time_s = None
        inpos = "inpos" in args_opt
        for name, a in args_opt.items():
            if a.value is None:
                continue
            v, t = self.ev(a.value)
            v = self._signal_value(v, a.pos)
            if name == "wobj":
                wobj, wobj_t, wobj_name = self.types.coerce(v, "wobjdata"), t, _text_of(a, s.pos, value=True)
            elif name == "v":
                speed = speed.replace("v_tcp", self._num(v, a.pos))
                speed_t |= t
            elif name == "t":
                time_s = self._num(v, a.pos)
                if time_s <= 0:
                    raise RapidError(f"{a.pos}: \\T:={time_s:g}: a move's time is positive")
                speed_t |= t
            elif name == "z":
                zone = zone.replace("pzone_tcp", self._num(v, a.pos))
                zone_t |= t
        assert isinstance(wobj, Record)
        circle = targets[0][0] if kind == "circular" else None
        target, target_t, target_text = targets[-1]
        want = "jointtarget" if kind == "absjoint" else "robtarget"
        for rec, _, text in targets:
            if rec.type != want:
                fix = "use MoveAbsJ" if want == "robtarget" else "use MoveJ (or give a jointtarget)"
                raise RapidError(f"{s.pos}: {s.name} goes to a {want}; {text} is a {rec.type}: {fix}")
        for k, (rec, t, text) in enumerate(targets):
            if rec.type == "robtarget" and not t:
                q = geo.orient_values(rec.get("rot"))
                norm = math.sqrt(sum(v * v for v in q))
                if norm == 0.0:  # no orientation at all: never given a value here (filled at run time)
                    why = f"{s.pos}: {text} has no orientation, never given a value here: {UNKNOWN_TARGET}"
                    targets[k] = (rec, frozenset({why}), text)
                    continue
                if abs(norm - 1.0) > 1e-3:
                    raise RapidError(
                        f"{s.pos}: {text}: its orientation {list(q)} is not a unit quaternion "
                        f"(norm {norm:.4g}); "
                        "correct it (or NOrient it)"
                    )
        target_t = targets[-1][1]
        kept = set(taint | start_taint | target_t | speed_t | zone_t | tool_t | wobj_t)
        if circle is not None:
            kept |= targets[0][1]
        if key in PROCESS_LINEAR or key in PROCESS_CIRCULAR:
            kept.add(f"{s.pos}: {s.name} is a process instruction: its speed is the process's")
        if key in SEARCH_MOTIONS:
            kept.add(f"{s.pos}: {s.name} stops where its signal comes: its end is known only at run time")
        if bool(wobj.get("robhold")) and bool(tool.get("robhold")):
            raise RapidError(
                f"{s.pos}: both the tool and the work object are held by the robot; one must stand"
            )
        if str(wobj.get("ufmec")).strip() or not bool(wobj.get("ufprog")):
            kept.add(f"{s.pos}: the work object {wobj_name} moves with a mechanical unit (coordinated)")
        process = s.name if key in PROCESS_LINEAR or key in PROCESS_CIRCULAR else None
        conc = "conc" in args_opt
        if conc:
            kept.add(f"{s.pos}: \\Conc: the instructions after it run while it moves")
        joints = circle_joints = None
        unknown = self._unknown_target(targets, tool, wobj, s, kind, tool_name, wobj_name)
        if unknown is not None:
            kept.add(unknown)
            joints = self._where_the_arm_is()
            if joints is not None:
                circle_joints = joints if circle is not None else None
                target = (
                    _jointtarget(self.types, joints)
                    if kind == "absjoint"
                    else self._robtarget_at(joints, tool, wobj)
                )
                circle = target if circle is not None else None
        elif self.kin is not None:
            if kind == "absjoint":
                joints = np.radians(_robax(target))
                bad = self.kin.in_range(joints)
                if bad is not None:
                    raise RapidError(
                        f"{s.pos}: {target_text}: joint {bad + 1} = {math.degrees(joints[bad]):.2f} deg is "
                        "outside this robot's range: correct the jointtarget, or give the robot it was "
                        "taught on with --robot"
                    )
            else:
                linear = kind in ("linear", "circular")
                joints = self.solve(target, tool, wobj, s.pos, f"{s.name} {target_text}", linear=linear)
                if circle is not None:
                    circle_joints = self.solve(
                        circle, tool, wobj, s.pos, f"{s.name} circle point", linear=True
                    )
        m = Motion(
            instruction=s.name,
            kind=kind,
            target=target,
            circle=circle,
            speed=speed,
            time_s=time_s,
            zone=zone,
            inpos=inpos,
            tool=tool,
            wobj=wobj,
            tool_name=tool_name,
            wobj_name=wobj_name,
            settings=self.settings,
            conc=conc,
            process=process,
            stmt=s,
            context=self._context(),
            kept=frozenset(kept),
            joints=joints,
            circle_joints=circle_joints,
            target_text=target_text,
        )
        self.events.append(m)
        if joints is not None:
            self.current_q = joints
        self.current_taint = target_t | self.ctx_taint | wobj_t | tool_t
        if unknown is not None:
            self.current_taint = self.current_taint | frozenset({unknown})
        if self.progress is not None and len(self.events) % 50 == 0:
            self.progress(f"reading the program: {self._moves()} moves")

    def _check_motion_data(self, speed: Record, zone: Record, s: n.Call) -> None:
        """A move's speed data positive and its zone sizes not negative, as the controller checks them."""
        for k, v in enumerate(speed.values[:2]):
            if isinstance(v, float) and not v > 0:
                what = ("v_tcp", "v_ori")[k]
                raise RapidError(f"{s.pos}: {s.name}: its speed data's {what} is {v:g}; a speed is positive")
        for name, v in zip(zone.names, zone.values, strict=True):
            if isinstance(v, float) and v < 0:
                raise RapidError(
                    f"{s.pos}: {s.name}: its zone data's {name} is {v:g}; a zone's size is 0 or more"
                )

    def _where_the_arm_is(self) -> FloatArray | None:
        """The arm's joints now: the last move's end, else every joint at 0 (the calibration position)."""
        if self.kin is None:
            return None
        if self.current_q is not None:
            return self.current_q.copy()
        q = np.zeros(RAPID_AXES)
        return q if self.kin.in_range(q) is None else None

    def _unknown_target(
        self,
        targets: list[tuple[Record, Taint, str]],
        tool: Record,
        wobj: Record,
        s: n.Call,
        kind: str,
        tool_name: str = "",
        wobj_name: str = "",
    ) -> str | None:
        """Why the move's target is unknown (None: it is known): declared nowhere, or known only at run
        time and its stand-in out of reach. Such a move is placed where the arm is and kept as taught."""
        for _rec, t, _text in targets:
            marked = next((w for w in sorted(t) if UNKNOWN_TARGET in w), None)
            if marked is not None:
                return f"{marked}; the move to it and the one after it are kept as taught"
        if self.kin is None or kind == "absjoint":
            return None
        stand_in = next(
            (
                a
                for a in self.assumed
                if a.role in ("wobjdata", "tooldata") and a.name in (tool_name, wobj_name)
            ),
            None,
        )
        for rec, t, text in targets:
            if rec.type != "robtarget":
                continue
            if not t and stand_in is not None:  # placed by a stand-in frame: where it lies is not known
                try:
                    self.solve(rec, tool, wobj, s.pos, f"{s.name} {text}")
                except (RapidError, ValueError):
                    return (
                        f"{s.pos}: {text} is {UNKNOWN_TARGET}: it lies in {stand_in.name}, declared nowhere "
                        f"in what was given ({stand_in.role}, give it in the scenario file); the move to it "
                        "and the one after it are kept as taught"
                    )
                continue
            if not t:
                continue
            try:
                self.solve(rec, tool, wobj, s.pos, f"{s.name} {text}")
            except (RapidError, ValueError):  # out of reach, or no orientation at all
                return (
                    f"{s.pos}: {text} is {UNKNOWN_TARGET}: its value comes at run time "
                    f"({'; '.join(sorted(t))}); the move to it and the one after it are kept as taught"
                )
        return None

    # ---- the run
    def run(self, routine: str | None = None) -> Trace:
        name = routine or "main"
        found = self.routines.get(name.lower())
        if found is None:
            for m in self.task.modules:
                found = self.local_routines[m.name.lower()].get(name.lower()) or found
        if found is None:
            movers = sorted({r.name for r, _ in self.routines.values() if r.kind == "PROC" and moves_in(r)})
            where = f"{self.task.modules[0].path}:{self.task.modules[0].pos.line}"
            if routine is None:
                raise RapidError(
                    f"{where}: no main routine in {self.task.source}; give --routine NAME, one of the "
                    f"routines that move the robot: {', '.join(movers) or '(none)'}"
                )
            raise RapidError(
                f"{where}: no routine {routine} in {self.task.source}; give --routine NAME, one of: "
                f"{', '.join(movers) or '(none)'}"
            )
        r, m = found
        if r.kind != "PROC" or any(not p.optional for p in r.params):
            raise RapidError(
                f"{r.pos}: {r.name} is a {r.kind} with required parameters; give a PROC that runs on its own"
            )
        for k in self.io:
            if (
                k not in self.signals_used
                and k not in self.globals
                and not any(k in loc for loc in self.locals_of.values())
            ):
                raise RapidError(
                    f"--io {k}: the program reads no signal or data of that name; "
                    "give a name the program uses"
                )
        self.stack = [_Frame(None, m, {}, set(), m.name)]
        limit = sys.getrecursionlimit()
        sys.setrecursionlimit(max(limit, 20 * MAX_DEPTH + 2000))
        try:
            self.invoke(r, m, (), r.pos)
        except _Stop as stop:
            if self.cycle_end is None:
                self.note(stop.why)
        except _Goto as g:
            raise RapidError(
                f"{g.pos}: GOTO {g.label}: no such label in the routine; add the label"
            ) from None
        except _Return:
            pass
        finally:
            sys.setrecursionlimit(limit)
        end = self.cycle_end if self.cycle_end is not None else len(self.events)
        return Trace(
            tuple(self.events),
            self.cycle_start,
            end,
            tuple(self.notes),
            r.name,
            self.loop,
            self.steps,
            tuple(self.assumed),
        )


# ------------------------------------------------------------------ helpers
_ALL_MOTIONS = (
    set(JOINT_MOTIONS)
    | set(LINEAR_MOTIONS)
    | set(CIRCULAR_MOTIONS)
    | set(ABSJ_MOTIONS)
    | PROCESS_LINEAR
    | PROCESS_CIRCULAR
    | set(SEARCH_MOTIONS)
)
_STANDIN_RESULT: dict[str, Value] = {
    k: ""
    for k in (
        "strpart",
        "numtostr",
        "dnumtostr",
        "valtostr",
        "booltostr",
        "bytetostr",
        "strmap",
        "stroneupper",
    )
} | {"strmemb": False, "strorder": False}
_SIGNAL_FUNCS = {"dinput", "doutput", "ginput", "goutput", "ainput", "aoutput", "testdi", "validio"}


def _signal_kind(name: str) -> str:
    low = name.lower()
    for k in ("di", "do", "gi", "go", "ai", "ao"):
        if low.startswith(k) or low.startswith("s" + k) or low.startswith(k + "_"):
            return k
    return "di"


def _opaque_ok(type_: str) -> bool:
    return type_ in _OPAQUE_TYPES


_OPAQUE_TYPES = {
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


def _show(v: Value) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return repr(v) if isinstance(v, str) else str(v)


def _as_record(v: Value) -> Record:
    assert isinstance(v, Record)
    return v


def _robax(jt: Record) -> FloatArray:
    rob = _as_record(jt.get("robax"))
    return np.array([num(v) for v in rob.values], dtype=float)


def _set_in(body: tuple[n.Stmt, ...]) -> set[str]:
    """Names (lower case) a statement list assigns or passes to a call, nested blocks included."""
    out: set[str | None] = set()
    for s in n.walk_statements(body):
        if isinstance(s, n.Assign):
            out.add(n.base_name(s.target))
        elif isinstance(s, n.Call):
            out.update(n.base_name(a.value) for a in s.args)
    return {name for name in out if name}


def _pairs(args: tuple[n.Arg, ...]) -> list[tuple[str | None, n.Expr | None]]:
    """A call's arguments as :func:`joulepath.rapid.builtins.match_arguments` takes them: a switch's
    value None, every other argument its expression."""
    return [(None if a.kind == "pos" else a.name, a.value) for a in args if a.kind in ("pos", "opt", "named")]


def _jointtarget(types: Types, q: FloatArray) -> Record:
    deg = tuple(float(v) for v in np.degrees(q)[:6])
    deg = deg + (0.0,) * (6 - len(deg))
    out = types.coerce((deg, (9e9,) * 6), "jointtarget")
    assert isinstance(out, Record)
    return out


def _conf(rt: Record) -> tuple[int, int, int, int]:
    c = _as_record(rt.get("robconf"))
    return tuple(int(round(num(v))) for v in c.values)  # type: ignore[return-value]


def _wobj_matrix(wobj: Record) -> FloatArray:
    return geo.pose_matrix(_as_record(wobj.get("uframe"))) @ geo.pose_matrix(_as_record(wobj.get("oframe")))


def target_flange(rt: Record, tool: Record, wobj: Record, pdisp: FloatArray | None = None) -> FloatArray:
    """Where the flange must be (base frame, m) for the TCP of ``tool`` to be at ``rt`` in ``wobj``.

    A robot-held tool (the usual case): ``flange = uframe oframe [pdisp] target tframe^-1``. A
    stationary tool with a robot-held work object: the target is fixed to the work object on the
    flange, the TCP stands in the world: ``flange = tframe target^-1 (uframe oframe)^-1``.
    """
    target = geo.pose_matrix(rt)
    if pdisp is not None:
        target = pdisp @ target
    tframe = geo.pose_matrix(_as_record(tool.get("tframe")))
    obj = _wobj_matrix(wobj)
    if bool(wobj.get("robhold")) and not bool(tool.get("robhold")):
        out: FloatArray = tframe @ np.linalg.inv(target) @ np.linalg.inv(obj)
        return out
    result: FloatArray = obj @ target @ np.linalg.inv(tframe)
    return result


def _text_of(a: n.Arg, pos: n.Pos, *, value: bool = False) -> str:
    e = a.value
    if isinstance(e, n.Name):
        return e.name
    if isinstance(e, n.FuncCall):
        inner = e.args[0].value if e.args else None
        return f"{e.name}({inner.name if isinstance(inner, n.Name) else '...'}, ...)"
    if isinstance(e, n.Index) and isinstance(e.base, n.Name):
        return f"{e.base.name}{{...}}"
    if isinstance(e, n.Aggregate):
        return "[...]"
    return "(expression)"


def _parse_literal(text: str) -> n.Expr:
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


def _lvalue_text(e: n.Expr) -> str:
    if isinstance(e, n.Name):
        return e.name
    if isinstance(e, n.Index):
        return _lvalue_text(e.base) + "{...}"
    if isinstance(e, n.Field):
        return _lvalue_text(e.base) + "." + e.name
    return "(assignment)"


def moves_in(r: n.Routine) -> bool:
    motion = set(JOINT_MOTIONS) | set(LINEAR_MOTIONS) | set(CIRCULAR_MOTIONS) | set(ABSJ_MOTIONS)

    def walk(body: tuple[n.Stmt, ...]) -> bool:
        for s in body:
            if isinstance(s, n.Call) and s.name.lower() in motion:
                return True
            if isinstance(s, n.If) and (any(walk(b) for _, b in s.branches) or walk(s.orelse)):
                return True
            if isinstance(s, (n.For, n.While)) and walk(s.body):
                return True
            if isinstance(s, n.Test) and (any(walk(b) for _, b in s.cases) or walk(s.default or ())):
                return True
            if isinstance(s, n.Call):
                return True  # a call may move; listed for the user to choose
        return False

    return walk(r.body)


def _expressions(m: object) -> Iterator[object]:
    """Every node of a module (depth first), for scans by kind."""
    return n.walk_nodes(m)


def _apply(op: str, a: Value, b: Value) -> Value:
    if op in ("=", "<>"):
        same = equal(a, b)
        return same if op == "=" else not same
    if op in ("AND", "OR", "XOR"):
        if not isinstance(a, bool) or not isinstance(b, bool):
            raise TypeErrorRapid(f"{op} needs two bools")
        return (a and b) if op == "AND" else (a or b) if op == "OR" else (a != b)
    if isinstance(a, str) and isinstance(b, str):
        if op == "+":
            return a + b
        raise TypeErrorRapid(f"strings take + and = only, not {op}")
    if isinstance(a, Record) or isinstance(b, Record):
        return _record_op(op, a, b)
    x, y = num(a), num(b)
    if op == "+":
        return x + y
    if op == "-":
        return x - y
    if op == "*":
        return x * y
    if op == "/":
        return x / y
    if op == "DIV":
        if not (math.isfinite(x) and math.isfinite(y)) or x != int(x) or y != int(y):
            raise TypeErrorRapid("DIV needs whole numbers")
        return float(math.trunc(x / y)) if y != 0 else x / y
    if op == "MOD":
        if not (math.isfinite(x) and math.isfinite(y)) or x != int(x) or y != int(y):
            raise TypeErrorRapid("MOD needs whole numbers")
        return float(math.fmod(x, y)) if y != 0 else x / y
    if op == "<":
        return x < y
    if op == "<=":
        return x <= y
    if op == ">":
        return x > y
    if op == ">=":
        return x >= y
    raise TypeErrorRapid(f"unknown operator {op}")


def _record_op(op: str, a: Value, b: Value) -> Value:
    if isinstance(a, Record) and isinstance(b, Record) and a.type == b.type == "pos":
        pa, pb = np.array(pos_values(a)), np.array(pos_values(b))
        if op == "+":
            return make_pos(*(float(v) for v in pa + pb))
        if op == "-":
            return make_pos(*(float(v) for v in pa - pb))
        if op == "*":  # the vector product
            return make_pos(*(float(v) for v in np.cross(pa, pb)))
    if isinstance(a, Record) and a.type == "pos" and not isinstance(b, Record):
        pa, k = np.array(pos_values(a)), num(b)
        if op == "*":
            return make_pos(*(float(v) for v in pa * k))
        if op == "/":
            return make_pos(*(float(v) for v in pa / k))
    if isinstance(b, Record) and b.type == "pos" and not isinstance(a, Record) and op == "*":
        return make_pos(*(float(v) for v in np.array(pos_values(b)) * num(a)))
    if isinstance(a, Record) and isinstance(b, Record) and a.type == b.type == "orient" and op == "*":
        return make_orient(geo.quat_mult(geo.orient_values(a), geo.orient_values(b)))
    if isinstance(a, Record) and isinstance(b, Record) and a.type == b.type == "pose" and op == "*":
        return geo.with_pose(a, geo.pose_matrix(a) @ geo.pose_matrix(b))
    raise TypeErrorRapid(f"{describe(a)} {op} {describe(b)} is not defined")


def _round(a: list[Value], opt: dict[str, Value], f: Callable[[float], float]) -> float:
    dec = int(num(opt.get("dec", 0.0)))
    k = 10.0**dec
    return f(num(a[0]) * k) / k


def _round_half_away(x: float) -> float:
    return float(math.floor(abs(x) + 0.5)) * (1.0 if x >= 0 else -1.0)


_MATH: dict[str, Callable[[list[Value], dict[str, Value]], Value]] = {
    "abs": lambda a, o: abs(num(a[0])),
    "absdnum": lambda a, o: abs(num(a[0])),
    "sqrt": lambda a, o: math.sqrt(num(a[0])),
    "sin": lambda a, o: math.sin(math.radians(num(a[0]))),
    "cos": lambda a, o: math.cos(math.radians(num(a[0]))),
    "tan": lambda a, o: math.tan(math.radians(num(a[0]))),
    "asin": lambda a, o: math.degrees(math.asin(num(a[0]))),
    "acos": lambda a, o: math.degrees(math.acos(num(a[0]))),
    "atan": lambda a, o: math.degrees(math.atan(num(a[0]))),
    "atan2": lambda a, o: math.degrees(math.atan2(num(a[0]), num(a[1]))),
    "exp": lambda a, o: math.exp(num(a[0])),
    "pow": lambda a, o: math.pow(num(a[0]), num(a[1])),
    "round": lambda a, o: _round(a, o, _round_half_away),
    "trunc": lambda a, o: _round(a, o, lambda x: float(math.trunc(x))),
    "vectmagn": lambda a, o: float(np.linalg.norm(pos_values(a[0]))),
    "dotprod": lambda a, o: float(np.dot(pos_values(a[0]), pos_values(a[1]))),
    "numtodnum": lambda a, o: num(a[0]),
    "dnumtonum": lambda a, o: num(a[0]),
}


def _num_to_str(a: list[Value], o: dict[str, Value]) -> str:
    dec = int(num(a[1])) if len(a) > 1 else 0
    return f"{num(a[0]):.{dec}f}"


def _str_part(a: list[Value], o: dict[str, Value]) -> str:
    s = str(a[0])
    start, length = int(num(a[1])), int(num(a[2]))
    if start < 1 or length < 0 or start - 1 + length > len(s):
        raise IndexError(f"StrPart({start}, {length}) outside a string of {len(s)} characters")
    return s[start - 1 : start - 1 + length]


_STRING_FUNCS: dict[str, Callable[[list[Value], dict[str, Value]], Value]] = {
    "numtostr": _num_to_str,
    "dnumtostr": _num_to_str,
    "strlen": lambda a, o: float(len(str(a[0]))),
    "strpart": _str_part,
    "strfind": lambda a, o: float(str(a[0]).find(str(a[2]), int(num(a[1])) - 1) + 1 or len(str(a[0])) + 1),
    "strmatch": lambda a, o: float(str(a[0]).find(str(a[2]), int(num(a[1])) - 1) + 1 or len(str(a[0])) + 1),
    "strmemb": lambda a, o: str(a[0])[int(num(a[1])) - 1] in str(a[2]),
    "strmap": lambda a, o: str(a[0]).translate(str.maketrans(str(a[1]), str(a[2]))),
    "valtostr": lambda a, o: _show(a[0]),
    "booltostr": lambda a, o: "TRUE" if a[0] is True else "FALSE",
    "strtobyte": lambda a, o: float(int(str(a[0]))),
    "bytetostr": lambda a, o: str(int(num(a[0]))),
    "strorder": lambda a, o: str(a[0]) < str(a[1]),
    "stroneupper": lambda a, o: str(a[0]).upper(),
}
