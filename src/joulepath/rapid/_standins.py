"""What a partial task leaves out: the role of each name declared nowhere, and its stand-in.

Real tasks are often incomplete: the tool, the work object or a target is declared in a module
that was not given (a backup's ``user.sys``, a ``CalibData`` module), a signal in an I/O
configuration that was not given, a routine in a library module or an option. A controller would
not load such a task; joulepath runs what it was given, with a stand-in for each missing name
chosen by the role the program gives it, and says so, a line each (:class:`Assumption`).

The role comes from where the program uses the name: an argument of a move instruction by its
place in the instruction's documented argument list (:data:`MOVE_LAYOUTS`: ``MoveL ToPoint, Speed,
Zone, Tool \\WObj``), the load of ``GripLoad``, a signal of an I/O instruction. A name used nowhere
in such a place is a value known only at run time.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from joulepath.rapid import builtins
from joulepath.rapid import nodes as n

ROBTARGET, JOINTTARGET = "robtarget", "jointtarget"
TARGET_TYPES = (ROBTARGET, JOINTTARGET)
STAND_IN_DATA = ("tooldata", "wobjdata", "speeddata", "zonedata", "loaddata")
"""The data types whose value, where the task does not give it, a stated stand-in takes."""

LOAD_FRACTION = 0.5
"""A tool declared nowhere carries this share of the robot's rated payload (at the flange, its
centre of gravity 50 mm out along tool0's z): a stated middle, overridable per tool in the
scenario file (``[tool.NAME]``)."""
LOAD_COG_MM = 50.0

_MOVE = (ROBTARGET, "speeddata", "zonedata", "tooldata")
_CIRC = (ROBTARGET, ROBTARGET, "speeddata", "zonedata", "tooldata")
_ABSJ = (JOINTTARGET, "speeddata", "zonedata", "tooldata")
MOVE_LAYOUTS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    **{k: (_MOVE, ()) for k in ("movej", "movel", "movejdo", "moveldo", "movejsync", "movelsync")},
    **{k: (_MOVE, ()) for k in ("movejgo", "movelgo", "movejao", "moveao", "movelao", "movelgo")},
    **{k: (_CIRC, ()) for k in ("movec", "movecdo", "movecsync", "movecgo", "movecao")},
    **{k: (_ABSJ, ()) for k in ("moveabsj", "moveabsjsync")},
    "moveextj": ((JOINTTARGET, "speeddata", "zonedata"), ()),
    # trigger moves: ToPoint, Speed, Trigg_1 [, Trigg_2 ...], Zone, Tool
    **{k: ((ROBTARGET, "speeddata"), ("zonedata", "tooldata")) for k in ("triggl", "triggj", "triggliosens")},
    "triggc": ((ROBTARGET, ROBTARGET, "speeddata"), ("zonedata", "tooldata")),
    "triggabsj": ((JOINTTARGET, "speeddata"), ("zonedata", "tooldata")),
    # search moves: Signal, SearchPoint, ToPoint, Speed, Tool
    "searchl": (("signal", ROBTARGET, ROBTARGET, "speeddata", "tooldata"), ()),
    "searchj": (("signal", ROBTARGET, ROBTARGET, "speeddata", "tooldata"), ()),
    "searchc": (("signal", ROBTARGET, ROBTARGET, ROBTARGET, "speeddata", "tooldata"), ()),
}
"""Each move instruction's positional arguments by type: (the first ones, the last ones); what lies
between (trigger data, process data) is not a stand-in's business."""
PROCESS_HEADS = {"l": (ROBTARGET, "speeddata"), "c": (ROBTARGET, ROBTARGET, "speeddata")}
"""Process moves (``ArcL``, ``PaintL``, ``DispL`` ...): ToPoint, Speed, the process's data, Zone, Tool."""
OPTIONAL_TYPES = {"wobj": "wobjdata", "tload": "loaddata", "v": "num", "t": "num", "z": "num"}
LOAD_FIRST = {"gripload": "loaddata", "mechunitload": "loaddata"}


@dataclass(frozen=True, slots=True)
class Assumption:
    """A name the task uses and declares nowhere, and what joulepath took for it.

    ``role`` is the data type the program uses it as (``tooldata``, ``wobjdata``, ``robtarget`` ...),
    ``signal``, ``routine`` (a procedure declared nowhere, or an option's instruction) or ``value``
    (a value known only at run time); ``value`` says what was taken, in words; ``pos`` the first
    place it is used.
    """

    name: str
    role: str
    value: str
    pos: n.Pos
    shared: bool = False
    """A ``PERS`` the task declares without a value (another task holds it), not a name declared nowhere."""

    def line(self) -> str:
        where = (
            "is a PERS declared without a value (another task's)"
            if self.shared
            else ("is declared nowhere in what was given")
        )
        return f"{self.pos}: {self.name} ({self.role}) {where}: {self.value}"

    def as_json(self) -> dict[str, str]:
        return {"name": self.name, "role": self.role, "value": self.value, "at": f"{self.pos}"}


def layout(
    key: str, process_linear: set[str], process_circular: set[str]
) -> tuple[tuple[str, ...], tuple[str, ...]] | None:
    """The positional argument types of a move instruction (see :data:`MOVE_LAYOUTS`), or None."""
    if key in MOVE_LAYOUTS:
        return MOVE_LAYOUTS[key]
    if key in process_linear:
        return PROCESS_HEADS["l"], ("zonedata", "tooldata")
    if key in process_circular:
        return PROCESS_HEADS["c"], ("zonedata", "tooldata")
    return None


ROLE_TYPES = frozenset({"tooldata", "wobjdata", "loaddata", "speeddata", "zonedata", ROBTARGET, JOINTTARGET})
"""The data types a stand-in is chosen for by its place in a built-in's call
(:mod:`joulepath.rapid.builtins`)."""


def table_types(call: n.Call | n.FuncCall) -> list[tuple[n.Arg, str]] | None:
    """Each argument of a built-in's call whose type its documented signature fixes (one of
    :data:`ROLE_TYPES`), with that type; None where the table does not know the routine, or the
    call does not match its signature."""
    b = builtins.lookup(call.name)
    if b is None:
        return None
    pairs = [(None if a.kind == "pos" else a.name, a) for a in call.args if a.kind in ("pos", "opt", "named")]
    try:
        matched = builtins.match_arguments(b, pairs)
    except builtins.ArgumentError:
        return None
    out = []
    for name, a in matched.items():
        param = b.param(name)
        if param is None or a is None or a.value is None:
            continue
        types = [t for t in param.types if t in ROLE_TYPES]
        if len(types) == 1:
            out.append((a, types[0]))
    return out


def argument_types(
    call: n.Call, process_linear: set[str], process_circular: set[str]
) -> Iterator[tuple[n.Arg, str]]:
    """Each argument of ``call`` whose type the instruction fixes, with that type: from the table of
    RAPID's built-ins where it knows the instruction, else from :data:`MOVE_LAYOUTS`."""
    found_in_table = table_types(call)
    if found_in_table is not None:
        yield from found_in_table
        return
    key = call.name.lower()
    found = layout(key, process_linear, process_circular)
    positional = [a for a in call.args if a.kind == "pos" and a.value is not None]
    if found is not None:
        head, tail = found
        for k, a in enumerate(positional):
            if k < len(head):
                yield a, head[k]
            elif tail and k >= len(positional) - len(tail):
                yield a, tail[k - (len(positional) - len(tail))]
        for a in call.args:
            if a.kind == "opt" and a.name and a.value is not None and a.name.lower() in OPTIONAL_TYPES:
                yield a, OPTIONAL_TYPES[a.name.lower()]
    elif key in LOAD_FIRST and positional:
        yield positional[0], LOAD_FIRST[key]


def name_roles(
    modules: tuple[n.Module, ...], process_linear: set[str], process_circular: set[str]
) -> dict[str, str]:
    """The data type each plain name is used as where an instruction fixes it (lower-case names).

    A name used as two types (a name declared in one module for one thing, used elsewhere for
    another) keeps the first; the interpreter's own type checks still hold."""
    out: dict[str, str] = {}
    declared = {r.name.lower() for m in modules for r in m.routines}
    for m in modules:
        for r in m.routines:
            for s in _calls(r.body):
                if s.name.lower() in declared:
                    continue
                for a, type_ in argument_types(s, process_linear, process_circular):
                    if isinstance(a.value, (n.Name, n.FuncCall)):  # a datum, or a function's value
                        out.setdefault(a.value.name.lower(), type_)
            for node in n.walk_nodes(r.body):  # the built-in functions' arguments (CalcJointT(p, tool ...))
                if isinstance(node, n.FuncCall) and node.name.lower() not in declared:
                    for a, type_ in table_types(node) or ():
                        if isinstance(a.value, (n.Name, n.FuncCall)):
                            out.setdefault(a.value.name.lower(), type_)
    return out


def _calls(body: tuple[n.Stmt, ...]) -> Iterator[n.Call]:
    return (s for s in n.walk_statements(body) if isinstance(s, n.Call))
