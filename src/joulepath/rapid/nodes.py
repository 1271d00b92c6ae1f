"""The typed tree of a RAPID task: one frozen dataclass per construct, each with its position.

The model is Python's own :mod:`ast`: the grammar (``rapid.lark``) says what the text is,
:func:`joulepath.rapid.parse_module` turns lark's parse tree into these nodes, and the
interpreter (:mod:`joulepath.rapid.interpreter`) walks them. Every node carries a
:class:`Pos`: the file, its first and last line, and the character span in the module's
decoded text, so that a refusal, a kept move and a written statement point back at the
source, and the writer edits exactly that span.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True, slots=True)
class Pos:
    """Where a node stands: ``file``, lines ``line`` .. ``end_line`` (1-based), characters
    ``start`` .. ``end`` of the module's decoded text (end exclusive)."""

    file: str
    line: int
    end_line: int
    start: int
    end: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}"


# ------------------------------------------------------------------ expressions
@dataclass(frozen=True, slots=True)
class Num:
    pos: Pos
    value: float


@dataclass(frozen=True, slots=True)
class Str:
    pos: Pos
    value: str


@dataclass(frozen=True, slots=True)
class Bool:
    pos: Pos
    value: bool


@dataclass(frozen=True, slots=True)
class Aggregate:
    """``[e1, e2, ...]``: a record's or an array's value, typed where it is used."""

    pos: Pos
    items: tuple[Expr, ...]


@dataclass(frozen=True, slots=True)
class Name:
    pos: Pos
    name: str


@dataclass(frozen=True, slots=True)
class Index:
    """``base{i}``, ``base{i, j}`` (1-based, up to three dimensions)."""

    pos: Pos
    base: Expr
    indices: tuple[Expr, ...]


@dataclass(frozen=True, slots=True)
class Field:
    """``base.name`` of a record."""

    pos: Pos
    base: Expr
    name: str


@dataclass(frozen=True, slots=True)
class Arg:
    """An argument: ``kind`` ``"pos"`` (positional), ``"opt"`` (``\\Name`` or ``\\Name:=value``)
    or ``"named"`` (``Name:=value``, a required argument given by name)."""

    pos: Pos
    kind: str
    name: str | None
    value: Expr | None


@dataclass(frozen=True, slots=True)
class FuncCall:
    pos: Pos
    name: str
    args: tuple[Arg, ...]


@dataclass(frozen=True, slots=True)
class BinOp:
    """``a op b``; ``op`` upper-cased (``+ - * / DIV MOD = <> < <= > >= AND OR XOR``)."""

    pos: Pos
    op: str
    a: Expr
    b: Expr


@dataclass(frozen=True, slots=True)
class Not:
    pos: Pos
    a: Expr


@dataclass(frozen=True, slots=True)
class Neg:
    pos: Pos
    a: Expr


@dataclass(frozen=True, slots=True)
class Placeholder:
    """RobotStudio's placeholder of unfinished code (``<SMT>``, ``<EXP>`` ...): a statement or an
    expression that is read, and refused only where the program runs it."""

    pos: Pos
    text: str


Expr = Num | Str | Bool | Aggregate | Name | Index | Field | FuncCall | BinOp | Not | Neg | Placeholder


# ------------------------------------------------------------------ statements
@dataclass(frozen=True, slots=True)
class DataDecl:
    """``[LOCAL|TASK] CONST|PERS|VAR type name[{dims}] [:= value];``"""

    pos: Pos
    scope: str | None
    storage: str
    type: str
    name: str
    dims: tuple[Expr, ...]
    init: Expr | None


@dataclass(frozen=True, slots=True)
class Assign:
    """``target := value;``: ``target`` a :class:`Name`, :class:`Index` or :class:`Field` chain."""

    pos: Pos
    target: Expr
    value: Expr


@dataclass(frozen=True, slots=True)
class Call:
    """A procedure call (an instruction): ``Name arg, arg \\Opt:=v;``."""

    pos: Pos
    name: str
    args: tuple[Arg, ...]


@dataclass(frozen=True, slots=True)
class LateCall:
    """Late binding: ``%expr% args;``, the procedure named by a string expression."""

    pos: Pos
    target: Expr
    args: tuple[Arg, ...]


@dataclass(frozen=True, slots=True)
class If:
    """``IF`` / ``ELSEIF`` branches (condition, body) and the ``ELSE`` body; a compact ``IF``
    has one branch whose body is one statement."""

    pos: Pos
    branches: tuple[tuple[Expr, tuple[Stmt, ...]], ...]
    orelse: tuple[Stmt, ...]
    compact: bool = False


@dataclass(frozen=True, slots=True)
class For:
    pos: Pos
    var: str
    start: Expr
    stop: Expr
    step: Expr | None
    body: tuple[Stmt, ...]


@dataclass(frozen=True, slots=True)
class While:
    pos: Pos
    cond: Expr
    body: tuple[Stmt, ...]


@dataclass(frozen=True, slots=True)
class Test:
    """``TEST expr CASE v1, v2: ... DEFAULT: ... ENDTEST``."""

    pos: Pos
    expr: Expr
    cases: tuple[tuple[tuple[Expr, ...], tuple[Stmt, ...]], ...]
    default: tuple[Stmt, ...] | None


@dataclass(frozen=True, slots=True)
class Goto:
    pos: Pos
    label: str


@dataclass(frozen=True, slots=True)
class Label:
    pos: Pos
    name: str


@dataclass(frozen=True, slots=True)
class Return:
    pos: Pos
    value: Expr | None


@dataclass(frozen=True, slots=True)
class Raise:
    pos: Pos
    value: Expr | None


@dataclass(frozen=True, slots=True)
class Exit:
    pos: Pos


@dataclass(frozen=True, slots=True)
class Retry:
    pos: Pos


@dataclass(frozen=True, slots=True)
class TryNext:
    pos: Pos


@dataclass(frozen=True, slots=True)
class Connect:
    pos: Pos
    target: Expr
    trap: str


@dataclass(frozen=True, slots=True)
class Empty:
    pos: Pos


Stmt = (
    Placeholder
    | DataDecl
    | Assign
    | Call
    | LateCall
    | If
    | For
    | While
    | Test
    | Goto
    | Label
    | Return
    | Raise
    | Exit
    | Retry
    | TryNext
    | Connect
    | Empty
)


# ------------------------------------------------------------------ routines and modules
@dataclass(frozen=True, slots=True)
class Param:
    """A parameter: ``access`` (``IN`` when not written, ``INOUT``, ``VAR``, ``PERS``), its type
    and name, whether it is optional (``\\``), its alternatives group (``\\switch a | switch b``)
    and its array dimensions (``{*}``: 1, ``{*,*}``: 2 ...)."""

    access: str
    type: str
    name: str
    optional: bool
    group: int
    dims: int


@dataclass(frozen=True, slots=True)
class Routine:
    """``PROC``, ``FUNC`` (with its return type) or ``TRAP``; its handlers are kept, not run."""

    pos: Pos
    kind: str
    name: str
    type: str | None
    params: tuple[Param, ...]
    body: tuple[Stmt, ...]
    error: tuple[Stmt, ...] | None
    undo: tuple[Stmt, ...] | None
    backward: tuple[Stmt, ...] | None
    local: bool


@dataclass(frozen=True, slots=True)
class RecordDef:
    """``RECORD name`` with its fields (type, name) in order."""

    pos: Pos
    name: str
    fields: tuple[tuple[str, str], ...]


@dataclass(frozen=True, slots=True)
class Alias:
    pos: Pos
    type: str
    name: str


@dataclass(frozen=True, slots=True)
class Module:
    """A module as written: its declarations and routines, and how it was stored.

    ``text`` is the decoded text (``encoding`` ``"utf-8"`` or ``"latin-1"``; line ends
    normalised to ``\\n``); ``newline`` the file's own line end (``"\\r\\n"`` or ``"\\n"``), so
    that a written module keeps every byte it does not change.
    """

    pos: Pos
    name: str
    attributes: tuple[str, ...]
    records: tuple[RecordDef, ...]
    aliases: tuple[Alias, ...]
    data: tuple[DataDecl, ...]
    routines: tuple[Routine, ...]
    path: str
    text: str
    encoding: str
    newline: str

    @property
    def system(self) -> bool:
        return any(a.upper() == "SYSMODULE" for a in self.attributes)


def blocks(s: Stmt) -> tuple[tuple[Stmt, ...], ...]:
    """The statement lists a statement holds, one per alternative: ``IF``'s branches then its ``ELSE``,
    ``TEST``'s cases then its ``DEFAULT``, a loop's body (:data:`BLOCKS`); none for a simple one."""
    get = BLOCKS.get(type(s))
    return get(s) if get is not None else ()


def walk_statements(body: tuple[Stmt, ...]) -> Iterator[Stmt]:
    """Every statement of a statement list, nested blocks (``IF``, ``FOR``, ``WHILE``, ``TEST``) included,
    in source order."""
    for s in body:
        yield s
        for b in blocks(s):
            yield from walk_statements(b)


def walk_nodes(root: object) -> Iterator[object]:
    """Every node below ``root`` (a module, a routine, a statement list, an expression), depth first,
    for scans by kind."""
    stack: list[object] = [root]
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, tuple):
            stack.extend(node)
        elif hasattr(node, "__dataclass_fields__") and not isinstance(node, Pos):
            for name in node.__dataclass_fields__:
                if name in ("text", "pos", "path"):
                    continue
                v = getattr(node, name)
                if isinstance(v, (tuple, list)) or hasattr(v, "__dataclass_fields__"):
                    stack.append(v)


def base_name(e: object) -> str | None:
    """The datum an lvalue or argument names (``a{2}.b`` names ``a``), lower case; None for another
    expression."""
    while isinstance(e, (Index, Field)):
        e = e.base
    return e.name.lower() if isinstance(e, Name) else None


BLOCKS: dict[type, Callable[[Any], tuple[tuple[Stmt, ...], ...]]] = {
    If: lambda s: (*(b for _, b in s.branches), s.orelse),
    Test: lambda s: (*(b for _, b in s.cases), s.default or ()),
    For: lambda s: (s.body,),
    While: lambda s: (s.body,),
}
"""Compound statement type -> the statement lists it holds (:func:`blocks`)."""
