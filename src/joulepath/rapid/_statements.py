"""Statements: one handler per node type of :data:`joulepath.rapid.nodes.Stmt`, in :data:`STATEMENTS`,
which :meth:`joulepath.rapid._machine.Machine.exec` dispatches by; a call (:func:`call`) by the name it
calls: a routine of the task, else a handler of :data:`CALLS` (the moves of
:mod:`joulepath.rapid._motion`, the instructions of :mod:`joulepath.rapid._instructions`), else an
instruction of the documented table (:mod:`joulepath.rapid.builtins`), else a routine declared nowhere.

A branch or a loop decided at run time runs its stand-in's choice with everything inside marked
(:func:`under`); one decided by data set outside the task that moves nothing now is taken to be the
production turn: the branch that moves most, said.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from joulepath.errors import RapidError
from joulepath.rapid import _standins as standins
from joulepath.rapid import builtins
from joulepath.rapid import nodes as n
from joulepath.rapid._expressions import index_taint
from joulepath.rapid._instructions import INSTRUCTIONS, documented_instruction, write_inputs
from joulepath.rapid._machine import CallHandler, Machine, StmtHandler
from joulepath.rapid._motion import MOTIONS
from joulepath.rapid._routines import invoke
from joulepath.rapid._scan import set_in, set_outside
from joulepath.rapid._state import (
    MAX_LOOP_TURNS,
    SPIN_TURNS,
    UNTYPED,
    Cell,
    GotoLabel,
    Ref,
    ReturnValue,
    StopRun,
    show,
)
from joulepath.rapid._trace import CLEAN, Action, Motion, Taint, assumed, run_time
from joulepath.rapid._vocabulary import ALL_MOTIONS
from joulepath.rapid.values import Array, Record, TypeErrorRapid, describe, equal, num


def _placeholder(ip: Machine, s: n.Placeholder) -> None:
    raise ip.unfinished(s)


def _assign(ip: Machine, s: n.Assign) -> None:
    value, taint = ip.ev(s.value)
    target = ip.ref(s.target)
    r = target if isinstance(target, Ref) else Ref(target)
    cell = r.cell
    if cell.storage == "CONST" or cell.storage == "IO":
        raise RapidError(f"{s.pos}: {cell.name} is a {cell.storage}; it cannot be assigned")
    try:
        cur = r.get()
        if cell.type == UNTYPED and not r.path:  # a value declared nowhere: typed by what it gets
            pass
        elif isinstance(cur, Array):
            value = ip.types.array(value, cur.type, cur.dims)
        elif isinstance(cur, Record):
            value = ip.types.coerce(value, cur.type)
        elif isinstance(cur, bool):
            value = ip.types.coerce(ip.signal_value(value, s.pos), "bool")
        elif isinstance(cur, float):
            value = ip.types.coerce(ip.signal_value(value, s.pos), "num")
        elif isinstance(cur, str):
            value = ip.types.coerce(value, "string")
    except TypeErrorRapid as err:
        if not taint:
            raise RapidError(f"{s.pos}: {err}; correct the assignment") from None
        # a stand-in of run-time data that cannot take the datum's type: it keeps its value, marked
        value = cur
        ip.note(f"{s.pos}: {' '.join(sorted(taint))[:120]}: its stand-in does not fit; value kept")
    r.set(value, taint | ip.ctx_taint | index_taint(ip, s.target))
    ip.events.append(Action(s, _lvalue_text(s.target), ip.context()))


def _goto(ip: Machine, s: n.Goto) -> None:
    raise GotoLabel(s.label, s.pos)


def _return(ip: Machine, s: n.Return) -> None:
    if s.value is None:
        raise ReturnValue(None, CLEAN)
    v, t = ip.ev(s.value)
    raise ReturnValue(ip.signal_value(v, s.pos), t | ip.ctx_taint)


def _exit(ip: Machine, s: n.Exit) -> None:
    raise StopRun(f"{s.pos}: EXIT ends the program")


def _raise(ip: Machine, s: n.Raise) -> None:
    ip.note(
        f"{s.pos}: RAISE: an error raised while running is handled by the program's ERROR handler, "
        "which is not part of the cycle; the run goes on after it"
    )


def _nothing(ip: Machine, s: n.Label | n.Empty | n.DataDecl | n.Retry | n.TryNext | n.Connect) -> None:
    """A statement the cycle runs as nothing (a label, a declaration, an error handler's or an
    interrupt's)."""


def call(ip: Machine, s: n.Call) -> None:
    """A procedure call: a routine of the task, else its handler in :data:`CALLS`, else an instruction
    of the documented table, else a routine declared nowhere (no motion, no time; said once)."""
    s = replace(s, args=ip.conditionals(s.args))
    key = s.name.lower()
    found = ip.routine(s.name, s.pos)
    if found is not None:
        r, m = found
        if r.kind == "FUNC":
            raise RapidError(f"{s.pos}: {s.name} is a FUNC; use its value in an expression")
        if r.kind == "TRAP":
            raise RapidError(f"{s.pos}: {s.name} is a TRAP; it runs on an interrupt, not by a call")
        invoke(ip, r, m, s.args, s.pos)
        return
    handler = CALLS.get(key)
    if handler is not None:
        handler(ip, s, key)
        return
    if not s.name.strip():
        raise RapidError(f"{s.pos}: a call with no procedure name; give the procedure's name")
    documented = builtins.lookup(key)
    if documented is not None and documented.kind is builtins.Kind.INSTRUCTION:
        documented_instruction(ip, s, documented)
        return
    if key not in ip.assumed_routines:
        ip.assumed_routines.add(key)
        said = (
            "a call that does not move the arm and takes no time (an option's instruction or a routine "
            "of a module not given)"
        )
        ip.assumed.append(standins.Assumption(s.name, "routine", said, s.pos))
    write_inputs(ip, s, key)
    ip.events.append(Action(s, s.name, ip.context()))


def _call_by_var(ip: Machine, s: n.Call, key: str) -> None:
    """``CallByVar Name, Number``: the procedure ``Name`` + ``Number``."""
    pos, _ = ip.args_of(s.args)
    name = f"{pos[0][0]}{int(num(pos[1][0]))}"
    under(ip, pos[0][1] | pos[1][1], lambda: call(ip, n.Call(s.pos, name, ())), s)


def late_call(ip: Machine, s: n.LateCall) -> None:
    v, t = ip.ev(s.target)
    if not isinstance(v, str):
        raise RapidError(f"{s.pos}: late binding needs a string (the procedure's name), not {describe(v)}")
    if t and ip.routine(v, s.pos) is None:  # the name arrives at run time: which routine is unknown
        why = f"{s.pos}: the procedure called here is chosen at run time ({'; '.join(sorted(t))})"
        ip.note(f"{why}: not run; the move after it starts from where that leaves the arm")
        ip.after_branch = ip.after_branch | frozenset({why})
        ip.events.append(Action(s, "%late call%", ip.context()))
        return
    if t and not ip.ctx_taint:
        ip.note(f"{s.pos}: the procedure {v!r} is chosen at run time: {'; '.join(sorted(t))}")
    late = n.Call(s.pos, v, s.args)
    under(ip, t, lambda: call(ip, late), s)


PLANNED_FOR = " (assumed: its moves are planned; give the value in the scenario to plan another)"


def exec_if(ip: Machine, s: n.If) -> None:
    taint: Taint = CLEAN
    chosen: tuple[n.Stmt, ...] = s.orelse
    label = "ELSE" if s.orelse else "no branch"
    for k, (cond, body) in enumerate(s.branches):
        v, t = condition(ip, cond)
        taint |= run_time(t)  # a value known under an assumed branch decides as it is
        if v:
            chosen, label = body, "THEN" if k == 0 else f"ELSEIF at line {cond.pos.line}"
            break
    options = [
        (b, "THEN" if k == 0 else f"ELSEIF at line {c.pos.line}") for k, (c, b) in enumerate(s.branches)
    ] + [(s.orelse, "ELSE")]
    if not taint and not has_motion(ip, chosen, 0) and has_motion(ip, (s,), 0):
        shared = frozenset().union(*(_shared(ip, c) for c, _ in s.branches))
        if shared:  # the production turn of data the HMI, a PC or another task sets: stated, then known
            chosen, label = _production_turn(ip, s.pos, "IF", options, shared)
    if taint and not has_motion(ip, chosen, 0):
        # decided at run time: the stand-in's branch does not move; assume the one that moves most
        # (of equals the first: where no branch moves, a menu's first choice, which moves on)
        chosen, label = _most_moving(ip, options, "assumed")
    if taint and ip.leaving:
        chosen, label = _way_out(options, chosen, label)
    moves = has_motion(ip, chosen, 0)
    if taint and not ip.ctx_taint:
        ip.note(
            f"{s.pos}: IF decided at run time: {'; '.join(sorted(taint))} -> {label} taken"
            + (PLANNED_FOR if moves else "")
        )
    elif (
        not taint
        and not ip.ctx_taint
        and not s.compact
        and has_motion(ip, (s,), 0)
        and "assumed" not in label
    ):
        cond = s.branches[0][0]
        v, _ = condition(ip, cond)
        ip.note(f"{s.pos}: IF {ip.source_of(cond.pos)} ({'TRUE' if v else 'FALSE'}) -> {label} branch")
    under(ip, taint, lambda: ip.exec_body(chosen), s, assume=moves)


def exec_test(ip: Machine, s: n.Test) -> None:
    v, t = ip.ev(s.expr)
    t = run_time(t)
    v = ip.signal_value(v, s.pos)
    chosen = s.default or ()
    label = "DEFAULT"
    for values, body in s.cases:
        for ve in values:
            cv, ct = ip.ev(ve)
            t |= run_time(ct)
            if equal(v, cv):
                chosen, label = body, f"CASE {show(cv)} (line {ve.pos.line})"
                break
        else:
            continue
        break
    options = [(b, f"CASE at line {vs[0].pos.line}") for vs, b in s.cases] + [(s.default or (), "DEFAULT")]
    if not t and not has_motion(ip, chosen, 0) and has_motion(ip, (s,), 0):
        shared = _shared(ip, s.expr)
        if shared:
            chosen, label = _production_turn(ip, s.pos, "TEST", options, shared)
    if t and not has_motion(ip, chosen, 0):
        chosen, label = _most_moving(ip, options, "assumed")
    if t and ip.leaving:
        chosen, label = _way_out(options, chosen, label)
    moves = has_motion(ip, chosen, 0)
    if t and not ip.ctx_taint:
        ip.note(
            f"{s.pos}: TEST decided at run time: {'; '.join(sorted(t))} -> {label} taken"
            + (PLANNED_FOR if moves else "")
        )
    elif not t and not ip.ctx_taint and has_motion(ip, (s,), 0) and "assumed" not in label:
        ip.note(f"{s.pos}: TEST {ip.source_of(s.expr.pos)} ({show(v)}) -> {label} branch")
    under(ip, t, lambda: ip.exec_body(chosen), s, assume=moves)


def exec_for(ip: Machine, s: n.For) -> None:
    a, ta = ip.ev(s.start)
    b, tb = ip.ev(s.stop)
    step, ts = ip.ev(s.step) if s.step is not None else (1.0, CLEAN)
    a, b, step = ip.as_num(a, s.pos), ip.as_num(b, s.pos), ip.as_num(step, s.pos)
    if step == 0:
        raise RapidError(f"{s.pos}: FOR with STEP 0 never ends; give a step")
    taint = run_time(ta | tb | ts)
    if taint and not ip.ctx_taint:
        ip.note(f"{s.pos}: FOR bounds known only at run time: {'; '.join(sorted(taint))}")
    frame = ip.stack[-1]
    key = s.var.lower()
    saved = frame.locals.get(key)

    def run() -> None:
        i, turns = a, 0
        while (i <= b) if step > 0 else (i >= b):
            turns += 1
            if turns > MAX_LOOP_TURNS:
                raise RapidError(f"{s.pos}: FOR runs more than {MAX_LOOP_TURNS} turns; run fewer")
            frame.locals[key] = Cell(s.var, "num", "CONST", float(i), taint | ip.ctx_taint, s.pos)
            ip.loops.append(f"{s.var}={i:g}")
            try:
                ip.exec_body(s.body)
            finally:
                ip.loops.pop()
            i += step

    try:
        under(ip, taint, run, s, assume=has_motion(ip, s.body, 0))
    finally:
        if saved is not None:
            frame.locals[key] = saved
        else:
            frame.locals.pop(key, None)


def _endless(ip: Machine, cond: n.Expr) -> bool:
    if isinstance(cond, n.Bool):
        return cond.value
    if isinstance(cond, n.Name):
        key = cond.name.lower()
        if key in ip.assigned:
            return False
        try:
            v, t = ip.ev(cond)
        except RapidError:
            return False
        return v is True and not t
    return False


FIXED_TURNS = 2
"""Turns a ``WHILE`` that moves nothing runs before each turn is compared with the one before: a turn
that leaves the task's data as it found them (:meth:`Machine.snapshot`) would repeat for ever."""


LEAVING = (n.Return, n.Exit, n.Raise)
"""Statements that leave a loop wherever they stand (a ``GOTO``: where its label is outside)."""


def _left_by_a_statement(body: tuple[n.Stmt, ...]) -> bool:
    """Whether a loop's body leaves it by a statement: ``RETURN``, ``EXIT``, ``RAISE``, or a ``GOTO`` to
    a label outside it (a ``WHILE TRUE`` a routine returns from is a wait for an answer, not the
    production loop)."""
    labels = {s.name.lower() for s in n.walk_statements(body) if isinstance(s, n.Label)}
    return any(
        isinstance(s, LEAVING) or (isinstance(s, n.Goto) and s.label.lower() not in labels)
        for s in n.walk_statements(body)
    )


def _way_out(
    options: list[tuple[tuple[n.Stmt, ...], str]], chosen: tuple[n.Stmt, ...], label: str
) -> tuple[tuple[n.Stmt, ...], str]:
    """In the last turn of a spinning loop that a statement leaves: the first branch holding that
    statement (the answer the loop waits for), else the branch chosen."""
    for body, name in options:
        if any(isinstance(x, (*LEAVING, n.Goto)) for x in n.walk_statements(body)):
            return body, f"{name} (assumed: the way out of the loop that waits for it)"
    return chosen, label


def _wait_for_an_answer(ip: Machine, s: n.While) -> None:
    """A ``WHILE TRUE`` that moves nothing and that a statement leaves (``RETURN`` the operator's
    answer, ``GOTO`` on): a wait for the world outside the task. Its turns run; where they do not
    leave it, the last takes, at each choice made at run time, the branch that leaves it (the answer
    assumed to come). Returns only where even that turn stays in the loop."""
    for _ in range(FIXED_TURNS):
        ip.exec_body(s.body)
    ip.leaving = True
    try:
        ip.exec_body(s.body)
    except (ReturnValue, GotoLabel, StopRun):
        ip.note(
            f"{s.pos}: WHILE TRUE waits, moving nothing, for what only the world outside the task "
            "gives (an operator, a PLC): its way out taken"
        )
        raise
    finally:
        ip.leaving = False


def exec_while(ip: Machine, s: n.While) -> None:
    if _endless(ip, s.cond) and _left_by_a_statement(s.body) and not has_motion(ip, s.body, 0):
        _wait_for_an_answer(ip, s)  # returns only where no turn leaves it: as any endless loop below
    if _endless(ip, s.cond):
        if ip.cycle_end is None and ip.loop is None:
            # the production loop: its first turn starts from where the way there left the robot
            # and with the settings made before it; the turns after it are the cycle that repeats
            # (it starts where a turn ends, with the motion settings a turn leaves), so the cycle
            # is the second turn
            ip.loop = s.pos
            ip.exec_body(s.body)
            ip.cycle_start = len(ip.events)
            ip.exec_body(s.body)
            ip.cycle_end = len(ip.events)
            raise StopRun(f"{s.pos}: one turn of the production loop")
        ip.note(f"{s.pos}: an endless loop inside the cycle: its first turn is taken")
        ip.exec_body(s.body)
        raise StopRun(f"{s.pos}: an endless loop inside the cycle")
    turns = 0
    moving = has_motion(ip, s.body, 0)
    last: tuple[object, ...] | None = None
    seen = len(ip.events)
    while True:
        v, t = condition(ip, s.cond)
        t = run_time(t)
        still = not any(isinstance(e, Motion) for e in ip.events[seen:])  # the last turn moved nothing
        seen = len(ip.events)
        if v and not t and turns >= FIXED_TURNS:
            now = ip.snapshot()
            if now == last and still:  # a turn left every datum as it found it: it would spin for ever
                leaves = _left_by_a_statement(s.body)
                ip.note(
                    f"{s.pos}: WHILE spins, moving nothing, and a turn leaves the task's data as it found "
                    "them: only the world outside the task (a PLC, the HMI, an operator, another task) "
                    f"ends it; assumed to end after {turns} turns"
                    + (", by the statement that leaves it" if leaves else "")
                )
                if leaves:  # a last turn, its branches decided at run time toward the way out
                    ip.leaving = True
                    try:
                        ip.exec_body(s.body)
                    finally:
                        ip.leaving = False
                return
            if now == last and ip.cycle_end is None and ip.loop is None:
                # it moves, and each turn repeats the last: the production loop, until the outside ends it
                ip.note(
                    f"{s.pos}: WHILE repeats the same turn, moving, until the world outside the task ends "
                    "it: taken as the production loop"
                )
                ip.loop = s.pos
                ip.cycle_start = len(ip.events)
                ip.exec_body(s.body)
                ip.cycle_end = len(ip.events)
                raise StopRun(f"{s.pos}: one turn of the production loop")
            last = now
        if v and not t and not moving and turns >= SPIN_TURNS:
            shared = set_outside(
                s.cond, ip.globals, ip.signals_used, but=set_in(s.body)
            )  # what the loop's own statements set ends it
            if shared:  # it spins, moving nothing, until another task or the HMI sets its data
                ip.note(
                    f"{s.pos}: WHILE waits on data set outside this task ({'; '.join(sorted(shared))}): "
                    f"assumed to end after {turns} turns"
                )
                return
        if not v and t and turns == 0 and has_motion(ip, s.body, 0):
            v = True  # decided at run time and the stand-in skips it: assume one turn that moves
        if not v:
            if t and has_motion(ip, s.body, 0):
                ip.after_branch |= t
            return
        if t:
            if not ip.ctx_taint:
                ip.note(f"{s.pos}: WHILE decided at run time: {'; '.join(sorted(t))} -> one turn taken")
            under(ip, t, lambda: ip.exec_body(s.body), s, assume=has_motion(ip, s.body, 0))
            return
        turns += 1
        if turns > MAX_LOOP_TURNS:
            raise RapidError(
                f"{s.pos}: WHILE runs more than {MAX_LOOP_TURNS} turns "
                "without its condition turning FALSE; "
                "give the inputs it waits for (--io) or check the condition"
            )
        ip.exec_body(s.body)


def condition(ip: Machine, e: n.Expr) -> tuple[bool, Taint]:
    v, t = ip.ev(e)
    v = ip.signal_value(v, e.pos)
    if isinstance(v, float):
        v = v != 0.0  # a signal compared implicitly
    if not isinstance(v, bool):
        raise RapidError(f"{e.pos}: a condition needs a bool, not {describe(v)}; correct the expression")
    return v, t


def under(
    ip: Machine, taint: Taint, run: Callable[[], None], stmt: n.Stmt | None = None, *, assume: bool = False
) -> None:
    """Run ``run`` with ``taint`` added to everything it does (a branch decided at run time); where
    the statement holds a move (``stmt``), the first move after it starts from a place decided too.

    ``assume``: the branch run moves the arm and is the one assumed taken (said): what runs inside it
    is known under that assumption (:data:`ASSUMED_CHOICE`), so its moves are planned. A branch that
    moves nothing passes the run-time mark on to the data it sets, so that the decisions they make
    later are taken toward the motion as any decision at run time."""
    if not taint:
        run()
        return
    saved = ip.ctx_taint
    ip.ctx_taint = saved | (assumed(taint) if assume else taint)
    try:
        run()
    finally:
        ip.ctx_taint = saved
    if stmt is not None and has_motion(ip, (stmt,), 0):
        ip.after_branch = ip.after_branch | taint


def has_motion(ip: Machine, body: tuple[n.Stmt, ...], depth: int) -> bool:
    """Whether a statement list holds a move, directly or in a routine it calls (8 calls deep)."""
    if depth > 8:
        return True
    for s in body:
        if isinstance(s, n.Call):
            key = s.name.lower()
            if key in ALL_MOTIONS:
                return True
            found = ip.routines.get(key)
            if found is not None and has_motion(ip, found[0].body, depth + 1):
                return True
        elif isinstance(s, n.LateCall):
            return True
        elif any(has_motion(ip, b, depth) for b in n.blocks(s)):
            return True
    return False


def _shared(ip: Machine, e: object) -> Taint:
    """Why a condition may turn at run time though the task decides none of it: the ``PERS`` and
    ``VAR`` ``bool``, ``num`` and ``string`` data it reads that this task never sets, or only sets back
    to its declared value (a handshake: another task, a PLC or a PC through the robot's interfaces,
    or the HMI sets its other values). Empty where it reads none."""
    out: set[str] = set()
    for node in n.walk_nodes(e):
        if not isinstance(node, n.Name):
            continue
        key = node.name.lower()
        found = ip.globals.get(key)
        if found is None or (key in ip.set_names and key not in ip.handshake):
            continue
        decl = found[0]
        if decl.storage == "CONST" or ip.types.resolve(decl.type) not in ("bool", "num", "dnum", "string"):
            continue
        if key in ip.handshake:
            out.add(f"{decl.name} ({decl.pos}), which this task only sets back to its declared value")
        else:
            out.add(f"{decl.name} ({decl.pos}), which this task never sets")
    return frozenset(out)


def _motion_weight(ip: Machine, body: tuple[n.Stmt, ...], depth: int = 0) -> int:
    """How many move statements a statement list runs once through (calls followed 8 deep)."""
    if depth > 8:
        return 1
    total = 0
    for s in body:
        if isinstance(s, n.Call):
            key = s.name.lower()
            found = ip.routines.get(key)
            total += 1 if key in ALL_MOTIONS else _motion_weight(ip, found[0].body, depth + 1) if found else 0
        else:  # the alternative that moves most (a loop's body: its one turn)
            total += max((_motion_weight(ip, b, depth) for b in n.blocks(s)), default=0)
    return total


def _ends_the_program(body: tuple[n.Stmt, ...]) -> bool:
    return any(isinstance(x, n.Exit) for x in n.walk_statements(body))


def _most_moving(
    ip: Machine, options: list[tuple[tuple[n.Stmt, ...], str]], why: str
) -> tuple[tuple[n.Stmt, ...], str]:
    """The branch that runs the most moves (the first of equals; of branches that move nothing, the
    first that does not end the program: an alarm's ``EXIT`` is not the production turn), labelled
    with ``why``."""
    weights = [_motion_weight(ip, o[0]) for o in options]
    top = max(weights)
    tied = [o for o, w in zip(options, weights, strict=True) if w == top]
    body, label = next((o for o in tied if top > 0 or not _ends_the_program(o[0])), tied[0])
    return body, f"{label} ({why}: the branch that moves most)"


def _production_turn(
    ip: Machine, pos: n.Pos, what: str, options: list[tuple[tuple[n.Stmt, ...], str]], shared: Taint
) -> tuple[tuple[n.Stmt, ...], str]:
    """A branch decided by data set outside the task, whose value now runs no move: the production
    turn is taken to be the branch that moves most; said, with how to name another."""
    body, label = _most_moving(ip, options, "assumed")
    reasons = sorted(shared)
    while len(reasons) > 1 and len("; ".join(reasons)) > 200:
        reasons = reasons[:-1]
    names = "; ".join(reasons) + ("; ..." if len(reasons) < len(shared) else "")
    ip.note(
        f"{pos}: {what} on data a PLC, a PC, the HMI or another task sets: {names} -> {label}; give "
        "its value (--io NAME=VALUE) to optimize another turn"
    )
    return body, label


def _lvalue_text(e: n.Expr) -> str:
    if isinstance(e, n.Name):
        return e.name
    if isinstance(e, n.Index):
        return _lvalue_text(e.base) + "{...}"
    if isinstance(e, n.Field):
        return _lvalue_text(e.base) + "." + e.name
    return "(assignment)"


STATEMENTS: dict[type, StmtHandler] = {
    n.Placeholder: _placeholder,
    n.DataDecl: _nothing,
    n.Assign: _assign,
    n.Call: call,
    n.LateCall: late_call,
    n.If: exec_if,
    n.For: exec_for,
    n.While: exec_while,
    n.Test: exec_test,
    n.Goto: _goto,
    n.Label: _nothing,
    n.Return: _return,
    n.Raise: _raise,
    n.Exit: _exit,
    n.Retry: _nothing,
    n.TryNext: _nothing,
    n.Connect: _nothing,
    n.Empty: _nothing,
}
"""Statement node type -> its handler: one for each type of :data:`joulepath.rapid.nodes.Stmt`."""

CALLS: dict[str, CallHandler] = {**INSTRUCTIONS, "callbyvar": _call_by_var, **MOTIONS}
"""The instructions the interpreter runs (by name in lower case) -> their handler: the moves first, then
``CallByVar``, then the other instructions it knows."""
