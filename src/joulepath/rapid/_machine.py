"""The interpreter's machine: its state, the names it resolves, and its dispatch by node type.

:class:`Machine` holds one run's state explicitly (see :mod:`joulepath.rapid.interpreter`): the task's
data and routines, an environment per routine call, the motion settings in force, the step budget
(:meth:`Machine.tick`). It resolves names (:meth:`Machine.lookup`, a stand-in for a name declared
nowhere), declares data, and evaluates an expression (:meth:`Machine.ev`) or runs a statement
(:meth:`Machine.exec`) by the handler its node type has in :attr:`Machine.expressions` or
:attr:`Machine.statements`: the tables of :mod:`joulepath.rapid._expressions` and
:mod:`joulepath.rapid._statements`, plugged in by :class:`joulepath.rapid.interpreter.Interpreter`,
in the way of :class:`ast.NodeVisitor`. It has no ``isinstance`` chain over node types.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Iterable, Mapping
from typing import Any, ClassVar

import numpy as np

from joulepath._typing import FloatArray
from joulepath.errors import RapidError
from joulepath.rapid import _standins as standins
from joulepath.rapid import geometry as geo
from joulepath.rapid import nodes as n
from joulepath.rapid._scan import assigned_names, handshake_names, set_names, signal_names, written_by_calls
from joulepath.rapid._state import (
    MAX_SECONDS,
    MAX_STEPS,
    UNKNOWN_TARGET,
    UNTYPED,
    Cell,
    Frame,
    GotoLabel,
    Ref,
    StopRun,
    opaque_ok,
    parse_literal,
    predefined_data,
    signal_kind,
)
from joulepath.rapid._trace import CLEAN, Event, Kinematics, Motion, MotionSettings, Taint
from joulepath.rapid._vocabulary import PROCESS_CIRCULAR, PROCESS_LINEAR
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
    num,
)

ExprHandler = Callable[["Machine", Any], tuple[Value, Taint]]
"""The handler of one expression node type: its value and the reasons it is uncertain."""
StmtHandler = Callable[["Machine", Any], None]
"""The handler of one statement node type."""
CallHandler = Callable[["Machine", n.Call, str], None]
"""The handler of an instruction: the machine, the call, the instruction's name in lower case."""


RETRY_TURNS = 2
"""Jumps back to a label before each is compared with the one before (:meth:`Machine._retry_ends`)."""


READ_AT_RUN_TIME = "is read at run time"
"""How a note names an input read with no value (:meth:`Machine.signal_value`): ``NAME is read ...``."""


def inputs_read(notes: Iterable[str]) -> list[str]:
    """The inputs that ``notes`` say were read with no value (taken as 0), each once, in order."""
    found = (m.group(1) for note in notes for m in re.finditer(rf"(\w+) {READ_AT_RUN_TIME}", note))
    return list(dict.fromkeys(found))


class Machine:
    """One run's state, its names and its dispatch by node type (see the module's docstring)."""

    expressions: ClassVar[Mapping[type, ExprHandler]] = {}
    """Expression node type -> its handler (:data:`joulepath.rapid._expressions.EXPRESSIONS`)."""
    statements: ClassVar[Mapping[type, StmtHandler]] = {}
    """Statement node type -> its handler (:data:`joulepath.rapid._statements.STATEMENTS`)."""

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
        self.assumed_routines: set[str] = set()
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
        self.leaving = False  # a spinning loop's last turn: run-time branches toward its way out
        self.error_codes: dict[str, float] = {}  # ERR_ constants met, each a distinct number
        self.settings = MotionSettings()
        self.pdisp: FloatArray | None = None
        self.current_q: FloatArray | None = None
        self.current_taint: Taint = CLEAN
        self.stack: list[Frame] = []
        self.loops: list[str] = []
        self.outputs: dict[str, Value] = {}
        self._define_types()
        self.predefined = predefined_data(self.types)
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
        self.assigned = assigned_names(task)
        self.signals_used = signal_names(task, self.globals)
        self.roles = standins.name_roles(self.task.modules, PROCESS_LINEAR, PROCESS_CIRCULAR)
        written = written_by_calls(task, self.routines)  # the task's calls' arguments matched once
        self.set_names = set_names(task, written)
        self.handshake = handshake_names(task, written, self.globals)
        """Data the task only sets back to its declared value: its other values come from outside."""
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

    # ---- budget
    def tick(self, pos: n.Pos) -> None:
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

    def snapshot(self) -> tuple[object, ...]:
        """The task's data as it stands (values are immutable): every datum's value, the current
        routine's, the outputs set, the motion settings, where the arm is and the random generator's
        state (not the events: a wait adds one). Two equal snapshots a turn apart: the turn changed
        nothing the task can see."""
        frame = self.stack[-1].locals if self.stack else {}
        return (
            tuple((k, c.value) for k, c in self.cells.items()),
            tuple((k, c.value) for k, c in frame.items() if isinstance(c, Cell)),
            tuple(self.outputs.items()),
            self.settings,
            None if self.current_q is None else self.current_q.tobytes(),
            repr(self.rng.bit_generator.state),
        )

    def note(self, text: str) -> None:
        if text not in self._noted:
            self._noted.add(text)
            self.notes.append(text)

    def context(self) -> tuple[str, ...]:
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
            self.stack = [Frame(None, module, {}, set(), module.name)]
            try:
                cell = self.declare(decl)
            finally:
                self.stack = saved
        finally:
            self._initialising.discard(ck)
        self.cells[ck] = cell
        return cell

    def lookup(self, name: str, pos: n.Pos) -> Cell | Ref:
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
                self.cells[ck] = Cell(name, "signal", "IO", Signal(name, signal_kind(name)), CLEAN, None)
            return self.cells[ck]
        if key == "errno":
            return Cell(name, "errnum", "CONST", 0.0, CLEAN, None)
        if key.startswith("err_"):  # each error constant its own number, none 0 (a flag's "no error")
            code = self.error_codes.setdefault(key, float(len(self.error_codes) + 1))
            return Cell(name, "errnum", "CONST", code, CLEAN, None)
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
            value = self._given_value(name, role if role != "value" else "num", pos)
            said = "the scenario's value"
        else:
            value, taint, said = self._stand_in_value(name, role, pos)
        data = role in ("tooldata", "wobjdata", "speeddata", "zonedata", "loaddata")
        storage = "CONST" if data and key not in self.assigned and key not in self.set_names else "VAR"
        type_ = UNTYPED if role == "value" and key not in self.given else role
        cell = Cell(name, type_, storage, value, taint, pos)
        self.cells[("", key)] = cell
        self.assumed.append(standins.Assumption(name, role, said, pos))
        return cell

    def _given_value(self, name: str, type_: str, pos: n.Pos) -> Value:
        """The scenario's value for ``name`` as a ``type_`` (a RAPID literal where it is text)."""
        given = self.given[name.lower()]
        try:
            if isinstance(given, str) and type_ != "string":  # a RAPID literal: "[2000, 500, 5000, 1000]"
                given, _ = self.ev(parse_literal(given))
            return self.types.coerce(given, type_)
        except TypeErrorRapid as err:
            raise RapidError(f"{pos}: the scenario's {name}: {err}; give a {type_}") from None

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

    def declare(self, decl: n.DataDecl) -> Cell:
        type_ = self.types.resolve(decl.type)
        known = type_ in NUM_TYPES or type_ in ("bool", "string") or type_ in self.types.records
        if not known and type_ not in SIGNAL_TYPES and not opaque_ok(type_):
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
            if decl.storage == "PERS":
                value, taint = shared_persistent(self, decl, type_, value)
        elif decl.storage == "PERS":
            value, taint = shared_persistent(self, decl, type_, self.types.default(type_))
        else:
            value = self.types.default(type_)
            if type_ in standins.TARGET_TYPES and decl.storage == "VAR":  # known once the program sets it
                given = self.given.get(decl.name.lower())
                if given is not None:
                    value = self.types.coerce(given, type_)
                else:
                    taint = frozenset({f"{decl.pos}: {decl.name} is declared without a value"})
        return Cell(decl.name, type_, decl.storage, value, taint, decl.pos)

    # ---- dispatch by node type
    def ev(self, e: n.Expr) -> tuple[Value, Taint]:
        """The value of an expression and the reasons it is uncertain: the handler of its node type."""
        return self.expressions[type(e)](self, e)

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
        self.tick(s.pos)
        self.statements[type(s)](self, s)

    def exec_body(self, body: tuple[n.Stmt, ...]) -> None:
        k = 0
        retries: dict[int, tuple[int, object, int]] = {}  # label index -> (jumps back, snapshot, events)
        while k < len(body):
            s = body[k]
            try:
                self.exec(s)
            except GotoLabel as g:
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
                if idx < k and isinstance(s, n.Goto) and self.cycle_end is None and self.loop is None:
                    self._goto_loop(body[idx + 1 : k], s)
                if idx < k and retry_ends(self, retries, idx, g):
                    k += 1  # the retry is over: on as if the branch that jumped back were not taken
                    continue
                k = idx + 1
                continue
            k += 1

    def _goto_loop(self, turn: tuple[n.Stmt, ...], goto: n.Goto) -> None:
        """An unconditional ``GOTO`` back to a label of its own statement list: the statements from the
        label to it repeat for ever, the production loop written with ``GOTO`` (as ``WHILE TRUE``: the
        turn just run led there, the next is the cycle; a ``GOTO`` to the same label inside the turn
        ends it too)."""
        self.loop = goto.pos
        self.note(f"{goto.pos}: GOTO {goto.label} jumps back for ever: a turn from its label is the cycle")
        self.cycle_start = len(self.events)
        try:
            self.exec_body(turn)
        except GotoLabel as g:
            if g.label.lower() != goto.label.lower():
                raise
        self.cycle_end = len(self.events)
        raise StopRun(f"{goto.pos}: one turn of the production loop")

    # ---- values
    def unfinished(self, p: n.Placeholder) -> RapidError:
        return RapidError(
            f"{p.pos}: {p.text} is a placeholder of unfinished code, and the cycle runs it; write it "
            "(or give --routine NAME to run another routine)"
        )

    def conditionals(self, args: tuple[n.Arg, ...]) -> tuple[n.Arg, ...]:
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

    def as_num(self, v: Value, pos: n.Pos) -> float:
        try:
            return num(v)
        except TypeErrorRapid as err:
            raise RapidError(f"{pos}: {err}; correct the expression") from None

    def signal_value(self, v: Value, pos: n.Pos) -> Value:
        return self.read_signal(v, pos)[0] if isinstance(v, Signal) else v

    def outside_value(self, cell: Cell, pos: n.Pos) -> Value | None:
        """The scenario's value (``--io NAME=VALUE``) of a global ``bool``, ``num`` or ``string`` that
        the world outside the task sets (this task never sets it, or only back to its declared value:
        a handshake the PLC sets again each turn), on every read; None where the scenario gives none."""
        key = cell.name.lower()
        found = self.globals.get(key)
        if key not in self.io or found is None or found[0].pos != cell.pos or cell.storage == "CONST":
            return None
        if cell.type not in ("bool", "num", "dnum", "string"):
            return None
        if key in self.set_names and key not in self.handshake:
            return None
        v = self.io[key]
        self.io_used.add(key)
        if cell.type == "bool":
            if isinstance(v, bool) or v in (0.0, 1.0):
                return bool(v)
            raise RapidError(f"{pos}: --io {cell.name}={v!r}: {cell.name} is a bool; give TRUE or FALSE")
        if cell.type == "string":
            return v if isinstance(v, str) else f"{v:g}"
        if isinstance(v, str):
            raise RapidError(f"{pos}: --io {cell.name}={v!r}: {cell.name} is a {cell.type}; give a number")
        return float(v)

    def read_signal(self, sig: Signal, pos: n.Pos) -> tuple[Value, Taint]:
        key = sig.name.lower()
        if key in self.io:
            self.io_used.add(key)
            v = self.io[key]
            return (float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v), CLEAN
        if key in self.outputs:
            return self.outputs[key], CLEAN
        kind = sig.kind or signal_kind(sig.name)
        if kind in ("do", "go", "ao"):
            return 0.0, CLEAN  # an output the program has not set: its value at start, 0
        why = f"{pos}: {sig.name} {READ_AT_RUN_TIME} (not in the scenario; 0 assumed)"
        return 0.0, frozenset({why})

    def ref(self, e: n.Expr) -> Cell | Ref:
        if isinstance(e, n.Name):
            return self.lookup(e.name, e.pos)
        if isinstance(e, (n.Index, n.Field)):
            base = self.ref(e.base)
            r = base if isinstance(base, Ref) else Ref(base)
            if r.cell.type == UNTYPED:  # an element or component of a value declared nowhere: as unknown
                return r
            if isinstance(e, n.Index):
                idx = []
                for i in e.indices:
                    v, _ = self.ev(i)
                    f = self.as_num(v, e.pos)
                    if f != int(f):
                        raise RapidError(f"{e.pos}: the index {f:g} is not a whole number; correct it")
                    idx.append(int(f))
                cur = r.get()
                if not isinstance(cur, Array):
                    raise RapidError(f"{e.pos}: {describe(cur)} is not an array; remove the index")
                try:
                    cur.offset(tuple(idx))
                except IndexError as err:
                    if not any(self.ev(i)[1] for i in e.indices) and not self.ctx_taint:
                        raise RapidError(f"{e.pos}: {err}; correct the index") from None
                    where = (
                        "an index from run-time data"
                        if not self.ctx_taint
                        else "an index in a branch taken on run-time data"
                    )
                    self.note(f"{e.pos}: {where} ({err} for its stand-in): element 1 assumed")
                    idx = [1] * len(cur.dims)
                return Ref(r.cell, (*r.path, ("idx", tuple(idx))))
            cur = r.get()
            if not isinstance(cur, Record) and opaque_ok(self.types.resolve(r.cell.type)):
                # an option's data (Arc's seamdata ...), carried whole: its components are not modelled
                self.note(
                    f"{e.pos}: {r.cell.name}.{e.name}: a component of {r.cell.type} (an option's data), not "
                    "modelled: read as 0, set without effect on the motion"
                )
                return Ref(r.cell, (*r.path, ("opq", e.name.lower())))
            if not isinstance(cur, Record) or e.name.lower() not in cur.names:
                raise RapidError(f"{e.pos}: {describe(cur)} has no component {e.name}; correct the name")
            return Ref(r.cell, (*r.path, ("fld", e.name.lower())))
        raise RapidError(f"{e.pos}: this expression cannot be assigned to; assign to a variable")

    def ev_raw(self, e: n.Expr) -> tuple[Value, Taint]:
        """As :meth:`ev`, but a signal named is the signal, not its value (``SetDO do1, 1``)."""
        if isinstance(e, (n.Name, n.Index, n.Field)):
            ref = self.ref(e)
            value = ref.get() if isinstance(ref, Ref) else ref.value
            if isinstance(value, Signal):
                return value, CLEAN
        return self.ev(e)

    def args_of(
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

    def give(self, r: Ref) -> bool:
        """Set a datum the outside world writes to the scenario's value for it, where it gives one."""
        given = self.given.get(r.cell.name.lower())
        if given is None:
            return False
        cur = r.get()
        try:
            if isinstance(given, str) and not isinstance(cur, str):
                given, _ = self.ev(parse_literal(given))
            value = self.types.coerce(given, cur.type) if isinstance(cur, Record) else given
        except (RapidError, TypeErrorRapid) as err:
            raise RapidError(f"the scenario's {r.cell.name}: {err}; give a value of its type") from None
        self.io_used.add(r.cell.name.lower())
        r.set(value, CLEAN)
        return True


def shared_persistent(ip: Machine, decl: n.DataDecl, type_: str, zero: Value) -> tuple[Value, Taint]:
    """A ``PERS`` declared without a value: the controller gives it the value that another task's
    declaration of the same name holds (a task shares it with a server or a PLC-fed task), not
    given here. The scenario's value where it gives one; else a tool, work object, speed, zone or
    load takes the stand-in of a name declared nowhere (said), and any other value its type's
    zero, whose uses are marked as known only at run time (a target: an unknown target)."""
    where = f"{decl.pos}: {decl.name} is a PERS declared without a value (another task's)"
    if decl.name.lower() in ip.given and not decl.dims:
        value: Value = ip._given_value(decl.name, type_, decl.pos)
        ip.assumed.append(standins.Assumption(decl.name, type_, "the scenario's value", decl.pos, True))
        return value, CLEAN
    if type_ in standins.STAND_IN_DATA and not decl.dims:
        value, taint, said = ip._stand_in_value(decl.name, type_, decl.pos)
        ip.assumed.append(standins.Assumption(decl.name, type_, said, decl.pos, True))
        return value, taint
    if type_ in standins.TARGET_TYPES:
        said = (
            f"{UNKNOWN_TARGET}: the moves to and from it are kept as taught; give it in the "
            "scenario's [targets]"
        )
        ip.assumed.append(standins.Assumption(decl.name, type_, said, decl.pos, True))
        return zero, frozenset({f"{where}: {UNKNOWN_TARGET}"})
    return zero, frozenset({f"{where}: known only at run time"})


def retry_ends(ip: Machine, retries: dict[int, tuple[int, object, int]], idx: int, g: GotoLabel) -> bool:
    """Whether a ``GOTO`` back to a label (a retry: ask the operator again, check the input again)
    ends here: from its :data:`RETRY_TURNS`-th jump on, a jump that follows a turn which moved
    nothing and left the task's data as it found them (:meth:`Machine.snapshot`) would repeat for ever;
    only the world outside the task (the operator, a PLC, a sensor) ends it, so it is taken to
    end, said once (as ``WHILE``'s rule: :data:`joulepath.rapid._statements.FIXED_TURNS`)."""
    jumps, last, seen = retries.get(idx, (0, None, -1))
    jumps += 1
    if jumps < RETRY_TURNS:
        retries[idx] = (jumps, None, len(ip.events))
        return False
    moved = any(isinstance(e, Motion) for e in ip.events[seen:]) if seen >= 0 else True
    now = ip.snapshot()
    retries[idx] = (jumps, now, len(ip.events))
    if moved or now != last:
        return False
    ip.note(
        f"{g.pos}: GOTO {g.label} jumps back, moving nothing, and a turn leaves the task's data as it "
        "found them: only the world outside the task (an operator, a PLC, a sensor) ends it; assumed "
        f"to end after {jumps} turns"
    )
    retries.pop(idx)
    return True
