"""What a task's text says before it runs: the statements it runs, the data they set, the signals it
names, and whether a routine moves the robot (read once, when the interpreter is made)."""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from joulepath.rapid import builtins
from joulepath.rapid import nodes as n
from joulepath.rapid._trace import Taint
from joulepath.rapid._vocabulary import (
    ALL_MOTIONS,
    IO_SETTERS,
    IO_WAITS,
)
from joulepath.rapid.task import Task


def walk_statements(task: Task) -> Iterator[n.Stmt]:
    """Every statement of the task's routines but its TRAPs, nested blocks included."""
    for m in task.modules:
        for r in m.routines:
            if r.kind != "TRAP":
                yield from n.walk_statements(r.body)


def assigned_names(task: Task) -> set[str]:
    out: set[str] = set()
    for s in walk_statements(task):
        if isinstance(s, n.Assign):
            out.add(n.base_name(s.target) or "")
        elif isinstance(s, n.Call):  # a variable passed to a routine may be written there
            out.update(a.value.name.lower() for a in s.args if isinstance(a.value, n.Name))
    return out - {""}


def set_names(task: Task, written: set[str]) -> set[str]:
    """Data the task's statements set: assigned, or ``written`` by its calls (:func:`written_by_calls`:
    passed to a routine of the task, or to an instruction that writes its argument: ``Incr``,
    ``TPReadNum``, ``SocketReceive`` ...)."""
    out = set(written)
    for s in walk_statements(task):
        if isinstance(s, n.Assign):
            out.add(n.base_name(s.target) or "")
    return out


_DEFAULTS: dict[str, tuple[str, object]] = {
    "bool": ("Bool", False),
    "num": ("Num", 0.0),
    "dnum": ("Num", 0.0),
    "string": ("Str", ""),
}
"""The literal a ``VAR`` of a plain type holds before it is assigned."""


def handshake_names(
    task: Task, written: set[str], declared: Mapping[str, tuple[n.DataDecl, n.Module]]
) -> set[str]:
    """Data the task only ever sets back to its declared value (a ``bool``, ``num`` or ``string``
    ``VAR``/``PERS``: a start flag it clears once it acts on it, a job number it resets): its other
    values come from outside the task (a PLC, a PC, the HMI or another task)."""
    rest: set[str] = set()
    other = set(written)  # what the calls write (:func:`written_by_calls`)
    for s in walk_statements(task):
        if not isinstance(s, n.Assign):
            continue
        key = (n.base_name(s.target) or "").lower()
        found = declared.get(key)
        initial = _initial(found[0]) if found is not None and isinstance(s.target, n.Name) else None
        (rest if initial is not None and _literal(s.value) == initial else other).add(key)
    return rest - other


def _initial(decl: n.DataDecl) -> tuple[str, object] | None:
    """The literal a ``VAR``/``PERS`` of a plain type is declared with (its type's default without one)."""
    if decl.storage == "CONST" or decl.dims or decl.type.lower() not in _DEFAULTS:
        return None
    return _DEFAULTS[decl.type.lower()] if decl.init is None else _literal(decl.init)


def _literal(e: n.Expr) -> tuple[str, object] | None:
    if isinstance(e, n.Bool):
        return "Bool", e.value
    if isinstance(e, n.Num):
        return "Num", float(e.value)
    if isinstance(e, n.Str):
        return "Str", e.value
    return None


def written_by_calls(task: Task, routines: Mapping[str, object]) -> set[str]:
    """Data the task's calls may write: passed to a routine of the task (or one declared nowhere), or
    to an argument an instruction writes."""
    out: set[str] = set()
    for s in walk_statements(task):
        if isinstance(s, n.Call):
            key = s.name.lower()
            documented = builtins.lookup(key) if key not in routines else None
            if documented is None:  # a routine of the task (or declared nowhere): it may write any
                args = [a.value for a in s.args]
            else:
                written = {p.name.lower() for p in documented.params if p.writes}
                try:
                    matched = builtins.match_arguments(documented, pairs(s.args))
                except builtins.ArgumentError:
                    matched = {}
                args = [v for k, v in matched.items() if k.lower() in written]
            out.update(name for name in map(n.base_name, args) if name)
    return out


def signal_names(task: Task, declared: Mapping[str, object]) -> set[str]:
    out = set(task.signals)
    io_first = IO_SETTERS | IO_WAITS | {"isignaldi", "isignaldo", "isignalgi", "isignalai", "triggio"}
    io_funcs = {"dinput", "doutput", "ginput", "goutput", "ainput", "aoutput", "testdi", "validio"}
    for s in walk_statements(task):
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
            if isinstance(v, n.Name) and v.name.lower() not in declared:
                out.add(v.name.lower())
    for m in task.modules:
        for node in n.walk_nodes(m):
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


def set_in(body: tuple[n.Stmt, ...]) -> set[str]:
    """Names (lower case) a statement list assigns or passes to a call, nested blocks included."""
    out: set[str | None] = set()
    for s in n.walk_statements(body):
        if isinstance(s, n.Assign):
            out.add(n.base_name(s.target))
        elif isinstance(s, n.Call):
            out.update(n.base_name(a.value) for a in s.args)
    return {name for name in out if name}


def pairs(args: tuple[n.Arg, ...]) -> list[tuple[str | None, n.Expr | None]]:
    """A call's arguments as :func:`joulepath.rapid.builtins.match_arguments` takes them: a switch's
    value None, every other argument its expression."""
    return [(None if a.kind == "pos" else a.name, a.value) for a in args if a.kind in ("pos", "opt", "named")]


def listed(names: list[str], most: int = 6) -> str:
    """Names for an error line: at most ``most`` of them, and how many more (the line stays short).

    >>> listed(["a", "b", "c"], 2)
    'a, b (and 1 more)'
    """
    more = f" (and {len(names) - most} more)" if len(names) > most else ""
    return ", ".join(names[:most]) + more


def moves_in(r: n.Routine, routines: Mapping[str, n.Routine] | None = None) -> bool:
    """Whether a routine holds a move, or a call that may move (listed for the user to choose): a
    motion instruction, a routine of ``routines`` that moves (followed 8 calls deep), a late-bound
    call, or a call to a name neither the task nor RAPID's table declares; not a documented
    instruction that does not move (``TPWrite``, ``SetDO`` ...)."""

    def walk(body: tuple[n.Stmt, ...], depth: int) -> bool:
        for s in body:
            if isinstance(s, n.LateCall):
                return True
            if isinstance(s, n.Call):
                key = s.name.lower()
                if key in ALL_MOTIONS:
                    return True
                found = None if routines is None else routines.get(key)
                if found is not None:
                    if depth >= 8 or walk(found.body, depth + 1):
                        return True
                    continue
                known = builtins.lookup(key)
                if known is None or known.motion is not None:
                    return True  # declared nowhere (a module not given, an option's move) or a move
                continue
            if any(walk(b, depth) for b in n.blocks(s)):
                return True
        return False

    return walk(r.body, 0)


def set_outside(
    e: object,
    declared: Mapping[str, tuple[n.DataDecl, n.Module]],
    signals: set[str],
    but: set[str] | frozenset[str] = frozenset(),
) -> Taint:
    """What in a condition the world outside the task may change: the task's ``VAR`` and ``PERS``
    data (of ``declared``, its global data) and its ``signals`` (another task, a PC, the HMI or the
    PLC sets them), but the names in ``but``. A condition that a loop or a wait spins on, moving
    nothing, ends when they change."""
    out: set[str] = set()
    for node in n.walk_nodes(e):
        if not isinstance(node, n.Name) or node.name.lower() in but:
            continue
        key = node.name.lower()
        found = declared.get(key)
        if found is not None and found[0].storage != "CONST":
            out.add(
                f"{found[0].pos}: {found[0].name} may be set outside this task (another task, a PC, the HMI)"
            )
        elif key in signals:
            out.add(f"{node.pos}: the signal {node.name} is set outside the task")
    return frozenset(out)
