"""RAPID text to the typed tree: decode, parse with the grammar (lark, LALR), build nodes.

A module file is ISO-8859-1 or UTF-8 text (UTF-8 where it decodes as such), with ``\\n``
or ``\\r\\n`` line ends, and may start with the ``%%%`` header a controller writes
(``VERSION`` / ``LANGUAGE``): the header's lines are blanked, so lines keep their numbers.
Parsing never executes anything.
"""

from __future__ import annotations

import functools
import math
import re
import sys
from importlib import resources
from pathlib import Path
from typing import Any

import lark

from joulepath._io import read_capped
from joulepath.errors import RapidError
from joulepath.rapid import nodes as n

MAX_BYTES = 16 * 1024 * 1024
"""Largest module file read (bytes); a controller's program memory is far smaller."""


@functools.cache
def _parser() -> lark.Lark:
    grammar = resources.files("joulepath.rapid").joinpath("rapid.lark").read_text(encoding="utf-8")
    return lark.Lark(grammar, parser="lalr", propagate_positions=True, maybe_placeholders=False)


def decode(data: bytes) -> tuple[str, str, str]:
    """``(text, encoding, newline)`` of a module's bytes: UTF-8 if it decodes, else ISO-8859-1;
    the text's line ends normalised to ``\\n``; ``newline`` the file's own."""
    try:
        text, encoding = data.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        text, encoding = data.decode("latin-1"), "latin-1"
    if text.startswith("\ufeff"):
        text = text[1:]
    newline = "\r\n" if "\r\n" in text else "\n"
    return text.replace("\r\n", "\n").replace("\r", "\n"), encoding, newline


def _blank_header(text: str) -> str:
    """The ``%%%`` ... ``%%%`` header replaced by blank lines (same line count and length)."""
    lines = text.split("\n")
    k = 0
    while k < len(lines) and not lines[k].strip():
        k += 1
    if k < len(lines) and lines[k].strip() == "%%%":
        for j in range(k + 1, len(lines)):
            if lines[j].strip() == "%%%":
                for i in range(k, j + 1):
                    lines[i] = " " * len(lines[i])
                break
    return "\n".join(lines)


def read_module_file(path: str | Path) -> n.Module:
    """Parse one module file; :class:`RapidError` (``file:line: what; how to fix``) otherwise."""
    p = Path(path)
    data = read_capped(p, max_bytes=MAX_BYTES, what="a RAPID module (.mod, .sys)", error=RapidError)
    if b"\x00" in data:
        raise RapidError(f"{p}:1: a binary file, not RAPID text; give a .mod / .sys module")
    text, encoding, newline = decode(data)
    return parse_module(text, path=str(p), encoding=encoding, newline=newline)


def parse_module(
    text: str, *, path: str = "<text>", encoding: str = "utf-8", newline: str = "\n"
) -> n.Module:
    """Parse a module's text (line ends ``\\n``) into a :class:`~joulepath.rapid.nodes.Module`."""
    source = _blank_header(text)
    _check_nesting(source, path)
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, PARSE_RECURSION))  # a chain of operators is a tree as deep
    try:
        try:
            tree = _parser().parse(source)
        except lark.exceptions.UnexpectedInput as err:
            raise RapidError(_syntax_message(err, source, path)) from None
        try:
            module = _Builder(path, text, encoding, newline).transform(tree)
        except lark.exceptions.VisitError as err:
            if isinstance(err.orig_exc, RapidError):
                raise err.orig_exc from None
            raise
    except RecursionError:
        raise RapidError(
            f"{path}: a statement chains more operators than this reader follows (a tree over "
            f"{PARSE_RECURSION} calls deep); split it into shorter statements"
        ) from None
    finally:
        sys.setrecursionlimit(limit)
    assert isinstance(module, n.Module)
    return module


def _syntax_message(err: lark.exceptions.UnexpectedInput, text: str, path: str) -> str:
    line = getattr(err, "line", 1) or 1
    if isinstance(err, lark.exceptions.UnexpectedToken):
        tok = err.token
        start = tok.start_pos if tok.start_pos is not None else 0
        line_start = text.rfind("\n", 0, start) + 1
        if tok.type != "$END" and not text[line_start:start].strip() and "SEMICOLON" in err.expected:
            # the statement before this line ended without ';': name its line
            prev = text[:line_start].rstrip()
            if prev:
                return f"{path}:{prev.count(chr(10)) + 1}: the statement ends without ';'; add it"
        if tok.type == "$END":
            return (
                f"{path}:{line}: the text ends inside a declaration or routine; close it (ENDPROC, ENDMODULE)"
            )
        expected = sorted(e.lstrip("_") for e in err.expected)[:6]
        return (
            f"{path}:{line}: syntax error at {quoted(str(tok))!r}: RAPID expects {', '.join(expected)} here; "
            "correct the statement"
        )
    if isinstance(err, lark.exceptions.UnexpectedCharacters):
        at = err.pos_in_stream if err.pos_in_stream is not None else -1
        ch = text[at] if 0 <= at < len(text) else "?"
        return f"{path}:{line}: {ch!r} is not RAPID here; correct the statement"
    return f"{path}:{line}: not RAPID text; give a RAPID module (MODULE name ... ENDMODULE)"


MAX_NESTING = 32
"""Deepest nesting of brackets, signs and blocks (IF, FOR, WHILE, TEST) a module may hold."""
PARSE_RECURSION = 30_000
"""Python calls deep the parse may go: a chain of binary operators (``1 + 1 + ...``) is a tree as deep
as it is long, and its building recurses (some thousands of terms are read; more are refused)."""

_OPENERS = re.compile(r"\b(IF|FOR|WHILE|TEST|ENDIF|ENDFOR|ENDWHILE|ENDTEST|THEN)\b", re.IGNORECASE)


def _check_nesting(text: str, path: str) -> None:
    """Refuse, before parsing, brackets, signs or blocks nested deeper than :data:`MAX_NESTING`
    (no program nests so deep; the parse tree would be as deep)."""
    depth, line, run = 0, 1, 0
    in_string = in_comment = False
    for ch in text:
        if ch == "\n":
            line += 1
            in_comment = False
            continue
        if in_comment:
            continue
        if ch == '"':
            in_string = not in_string
            continue
        if in_string:
            continue
        if ch == "!":
            in_comment = True
            continue
        if ch in "([{":
            depth += 1
            if depth > MAX_NESTING:
                raise RapidError(
                    f"{path}:{line}: brackets nested more than {MAX_NESTING} deep; write it flatter"
                )
        elif ch in ")]}":
            depth = max(0, depth - 1)
        if ch in "+-":
            run += 1
            if run > MAX_NESTING:
                raise RapidError(
                    f"{path}:{line}: signs nested more than {MAX_NESTING} deep; simplify the expression"
                )
        elif not ch.isspace():
            run = 0
    blocks = 0
    for k, raw in enumerate(text.split("\n"), start=1):
        code = raw.split("!", 1)[0]
        words = [w.upper() for w in _OPENERS.findall(code)]
        for w in words:
            if w in ("FOR", "WHILE", "TEST") or (w == "IF" and "THEN" in words):
                blocks += 1
                if blocks > MAX_NESTING:
                    raise RapidError(
                        f"{path}:{k}: blocks and calls nest more than {MAX_NESTING} deep; split the routine"
                    )
            elif w.startswith("END"):
                blocks = max(0, blocks - 1)


def quoted(text: str, most: int = 60) -> str:
    """``text`` as an error line quotes input: at most ``most`` characters, the rest counted."""
    return text if len(text) <= most else f"{text[: most - 1]}… ({len(text)} characters)"


def _number(text: str) -> float:
    try:
        value = float(int(text, 16)) if text[:2].lower() == "0x" else float(text)
    except (ValueError, OverflowError):
        value = math.inf
    if not math.isfinite(value):
        raise RapidError(f"{quoted(text)} is not a finite number")
    return value


def _string(text: str) -> str:
    body = text[1:-1]
    out: list[str] = []
    k = 0
    while k < len(body):
        c = body[k]
        if c == '"' and k + 1 < len(body) and body[k + 1] == '"':
            out.append('"')
            k += 2
        elif c == "\\" and k + 1 < len(body):
            if body[k + 1] == "\\":
                out.append("\\")
                k += 2
            elif k + 2 < len(body) and all(ch in "0123456789abcdefABCDEF" for ch in body[k + 1 : k + 3]):
                out.append(chr(int(body[k + 1 : k + 3], 16)))
                k += 3
            else:
                out.append(c)
                k += 1
        else:
            out.append(c)
            k += 1
    return "".join(out)


class _Builder(lark.Transformer[Any, Any]):
    """lark's tree to :mod:`joulepath.rapid.nodes` (each node with its :class:`Pos`)."""

    def __init__(self, path: str, text: str, encoding: str, newline: str) -> None:
        super().__init__(visit_tokens=False)
        self.path, self.text, self.encoding, self.newline = path, text, encoding, newline

    def _pos(self, meta: Any) -> n.Pos:
        if getattr(meta, "empty", True):
            return n.Pos(self.path, 0, 0, 0, 0)
        return n.Pos(self.path, meta.line, meta.end_line, meta.start_pos, meta.end_pos)

    def _tpos(self, tok: lark.Token) -> n.Pos:
        return n.Pos(self.path, tok.line or 0, tok.end_line or 0, tok.start_pos or 0, tok.end_pos or 0)

    def __default__(self, data: Any, children: Any, meta: Any) -> Any:  # pragma: no cover - grammar bug
        raise AssertionError(f"no builder for {data}")

    # ---- expressions
    @lark.v_args(meta=True)
    def number(self, meta: Any, c: list[Any]) -> n.Num:
        try:
            return n.Num(self._pos(meta), _number(str(c[0])))
        except RapidError as err:
            raise RapidError(f"{self.path}:{meta.line}: {err}; give a finite number") from None

    @lark.v_args(meta=True)
    def string(self, meta: Any, c: list[Any]) -> n.Str:
        return n.Str(self._pos(meta), _string(str(c[0])))

    @lark.v_args(meta=True)
    def true(self, meta: Any, c: list[Any]) -> n.Bool:
        return n.Bool(self._pos(meta), True)

    @lark.v_args(meta=True)
    def false(self, meta: Any, c: list[Any]) -> n.Bool:
        return n.Bool(self._pos(meta), False)

    @lark.v_args(meta=True)
    def aggregate(self, meta: Any, c: list[Any]) -> n.Aggregate:
        return n.Aggregate(self._pos(meta), tuple(c))

    @lark.v_args(meta=True)
    def name(self, meta: Any, c: list[Any]) -> n.Name:
        return n.Name(self._pos(meta), str(c[0]))

    @lark.v_args(meta=True)
    def index(self, meta: Any, c: list[Any]) -> n.Index:
        return n.Index(self._pos(meta), c[0], tuple(c[1:]))

    @lark.v_args(meta=True)
    def field(self, meta: Any, c: list[Any]) -> n.Field:
        return n.Field(self._pos(meta), c[0], str(c[1]))

    @lark.v_args(meta=True)
    def func_call(self, meta: Any, c: list[Any]) -> n.FuncCall:
        args = c[1] if len(c) > 1 else ()
        return n.FuncCall(self._pos(meta), str(c[0]), tuple(args))

    def fargs(self, c: list[Any]) -> tuple[n.Arg, ...]:
        return tuple(c)

    def args(self, c: list[Any]) -> tuple[n.Arg, ...]:
        return tuple(c)

    @lark.v_args(meta=True)
    def positional(self, meta: Any, c: list[Any]) -> n.Arg:
        return n.Arg(self._pos(meta), "pos", None, c[0])

    @lark.v_args(meta=True)
    def optional(self, meta: Any, c: list[Any]) -> n.Arg:
        return n.Arg(self._pos(meta), "opt", str(c[1]), c[2] if len(c) > 2 else None)

    @lark.v_args(meta=True)
    def conditional(self, meta: Any, c: list[Any]) -> n.Arg:
        """``\\Arg?Par``: the optional argument passed only where the caller's ``Par`` is present."""
        pos = self._pos(meta)
        return n.Arg(pos, "cond", str(c[1]), n.Name(pos, str(c[2])))

    @lark.v_args(meta=True)
    def placeholder(self, meta: Any, c: list[Any]) -> n.Placeholder:
        return n.Placeholder(self._pos(meta), str(c[0]))

    @lark.v_args(meta=True)
    def placeholder_stmt(self, meta: Any, c: list[Any]) -> n.Placeholder:
        return n.Placeholder(self._pos(meta), str(c[0]))

    @lark.v_args(meta=True)
    def named(self, meta: Any, c: list[Any]) -> n.Arg:
        return n.Arg(self._pos(meta), "named", str(c[0]), c[1])

    @lark.v_args(meta=True)
    def binop(self, meta: Any, c: list[Any]) -> n.BinOp:
        return n.BinOp(self._pos(meta), str(c[1]).upper(), c[0], c[2])

    @lark.v_args(meta=True)
    def not_(self, meta: Any, c: list[Any]) -> n.Not:
        return n.Not(self._pos(meta), c[0])

    @lark.v_args(meta=True)
    def neg(self, meta: Any, c: list[Any]) -> n.Expr:
        if str(c[0]) == "+":
            return c[1]  # type: ignore[no-any-return]
        return n.Neg(self._pos(meta), c[1])

    # ---- statements
    def scope(self, c: list[Any]) -> str:
        return str(c[0]).upper()

    def dims(self, c: list[Any]) -> tuple[n.Expr, ...]:
        return tuple(c)

    @lark.v_args(meta=True)
    def data_decl(self, meta: Any, c: list[Any]) -> n.DataDecl:
        scope = c.pop(0) if isinstance(c[0], str) and not isinstance(c[0], lark.Token) else None
        storage, type_, name = str(c[0]).upper(), str(c[1]), str(c[2])
        rest = c[3:]
        dims: tuple[n.Expr, ...] = ()
        if rest and isinstance(rest[0], tuple):
            dims = rest.pop(0)
        init = rest[0] if rest else None
        return n.DataDecl(self._pos(meta), scope, storage, type_, name, dims, init)

    @lark.v_args(meta=True)
    def lvalue(self, meta: Any, c: list[Any]) -> n.Expr:
        tok = c[0]
        node: n.Expr = n.Name(self._tpos(tok), str(tok))
        for sel in c[1:]:
            node = sel(node)
        return node

    @lark.v_args(meta=True)
    def sel_index(self, meta: Any, c: list[Any]) -> Any:
        pos = self._pos(meta)
        return lambda base: n.Index(pos, base, tuple(c))

    @lark.v_args(meta=True)
    def sel_field(self, meta: Any, c: list[Any]) -> Any:
        pos = self._pos(meta)
        return lambda base: n.Field(pos, base, str(c[0]))

    @lark.v_args(meta=True)
    def assign(self, meta: Any, c: list[Any]) -> n.Assign:
        return n.Assign(self._pos(meta), c[0], c[1])

    @lark.v_args(meta=True)
    def call(self, meta: Any, c: list[Any]) -> n.Call:
        return n.Call(self._pos(meta), str(c[0]), tuple(c[1]) if len(c) > 1 else ())

    @lark.v_args(meta=True)
    def late_call(self, meta: Any, c: list[Any]) -> n.LateCall:
        return n.LateCall(self._pos(meta), c[0], tuple(c[1]) if len(c) > 1 else ())

    def body(self, c: list[Any]) -> tuple[n.Stmt, ...]:
        return tuple(c)

    def elseif(self, c: list[Any]) -> tuple[n.Expr, tuple[n.Stmt, ...]]:
        return (c[0], c[1])

    def else_part(self, c: list[Any]) -> tuple[str, tuple[n.Stmt, ...]]:
        return ("else", c[0])

    @lark.v_args(meta=True)
    def if_stmt(self, meta: Any, c: list[Any]) -> n.If:
        branches = [(c[0], c[1])]
        orelse: tuple[n.Stmt, ...] = ()
        for part in c[2:]:
            if part[0] == "else":
                orelse = part[1]
            else:
                branches.append(part)
        return n.If(self._pos(meta), tuple(branches), orelse)

    @lark.v_args(meta=True)
    def compact_if(self, meta: Any, c: list[Any]) -> n.If:
        return n.If(self._pos(meta), ((c[0], (c[1],)),), (), compact=True)

    @lark.v_args(meta=True)
    def for_stmt(self, meta: Any, c: list[Any]) -> n.For:
        step = c[3] if len(c) == 5 else None
        return n.For(self._pos(meta), str(c[0]), c[1], c[2], step, c[-1])

    @lark.v_args(meta=True)
    def while_stmt(self, meta: Any, c: list[Any]) -> n.While:
        return n.While(self._pos(meta), c[0], c[1])

    def case(self, c: list[Any]) -> tuple[str, tuple[n.Expr, ...], tuple[n.Stmt, ...]]:
        return ("case", tuple(c[:-1]), c[-1])

    def default(self, c: list[Any]) -> tuple[str, tuple[n.Stmt, ...]]:
        return ("default", c[0])

    @lark.v_args(meta=True)
    def test_stmt(self, meta: Any, c: list[Any]) -> n.Test:
        cases = tuple((p[1], p[2]) for p in c[1:] if p[0] == "case")
        default = next((p[1] for p in c[1:] if p[0] == "default"), None)
        return n.Test(self._pos(meta), c[0], cases, default)

    @lark.v_args(meta=True)
    def goto(self, meta: Any, c: list[Any]) -> n.Goto:
        return n.Goto(self._pos(meta), str(c[0]))

    @lark.v_args(meta=True)
    def label(self, meta: Any, c: list[Any]) -> n.Label:
        return n.Label(self._pos(meta), str(c[0]))

    @lark.v_args(meta=True)
    def return_stmt(self, meta: Any, c: list[Any]) -> n.Return:
        return n.Return(self._pos(meta), c[0] if c else None)

    @lark.v_args(meta=True)
    def raise_stmt(self, meta: Any, c: list[Any]) -> n.Raise:
        return n.Raise(self._pos(meta), c[0] if c else None)

    @lark.v_args(meta=True)
    def exit_stmt(self, meta: Any, c: list[Any]) -> n.Exit:
        return n.Exit(self._pos(meta))

    @lark.v_args(meta=True)
    def retry_stmt(self, meta: Any, c: list[Any]) -> n.Retry:
        return n.Retry(self._pos(meta))

    @lark.v_args(meta=True)
    def trynext_stmt(self, meta: Any, c: list[Any]) -> n.TryNext:
        return n.TryNext(self._pos(meta))

    @lark.v_args(meta=True)
    def connect_stmt(self, meta: Any, c: list[Any]) -> n.Connect:
        return n.Connect(self._pos(meta), c[0], str(c[1]))

    @lark.v_args(meta=True)
    def empty_stmt(self, meta: Any, c: list[Any]) -> n.Empty:
        return n.Empty(self._pos(meta))

    # ---- routines and module
    def pdims(self, c: list[Any]) -> int:
        return len(c) + 1

    def param(self, c: list[Any]) -> tuple[str, str, str, int]:
        access = "IN"
        if len(c) >= 3 and isinstance(c[0], lark.Token) and c[0].type == "ACCESS":
            access = str(c.pop(0)).upper()
        dims = c[2] if len(c) > 2 else 0
        return (access, str(c[0]), str(c[1]), dims)

    def param_group(self, c: list[Any]) -> tuple[bool, list[tuple[str, str, str, int]]]:
        optional = bool(c) and isinstance(c[0], lark.Token) and c[0].type == "OPTMARK"
        return (optional, [p for p in c if isinstance(p, tuple)])

    def params(self, c: list[Any]) -> tuple[n.Param, ...]:
        out = []
        for g, (optional, group) in enumerate(c):
            for access, type_, name, dims in group:
                out.append(n.Param(access, type_, name, optional, g, dims))
        return tuple(out)

    def backward(self, c: list[Any]) -> tuple[str, tuple[n.Stmt, ...]]:
        return ("backward", c[-1])

    def error_handler(self, c: list[Any]) -> tuple[str, tuple[n.Stmt, ...]]:
        return ("error", c[-1])

    def undo(self, c: list[Any]) -> tuple[str, tuple[n.Stmt, ...]]:
        return ("undo", c[-1])

    def handlers(self, c: list[Any]) -> dict[str, tuple[n.Stmt, ...]]:
        return dict(c)

    def _routine(self, meta: Any, kind: str, c: list[Any]) -> n.Routine:
        local = False
        if isinstance(c[0], str) and not isinstance(c[0], lark.Token):
            local = c.pop(0) == "LOCAL"
        type_ = None
        if kind == "FUNC":
            type_ = str(c.pop(0))
        name = str(c[0])
        params: tuple[n.Param, ...] = ()
        rest = c[1:]
        if len(rest) == 3:
            params = rest.pop(0)
        body, handlers = rest[0], rest[1]
        return n.Routine(
            self._pos(meta),
            kind,
            name,
            type_,
            params,
            body,
            handlers.get("error"),
            handlers.get("undo"),
            handlers.get("backward"),
            local,
        )

    @lark.v_args(meta=True)
    def proc(self, meta: Any, c: list[Any]) -> n.Routine:
        return self._routine(meta, "PROC", c)

    @lark.v_args(meta=True)
    def func(self, meta: Any, c: list[Any]) -> n.Routine:
        return self._routine(meta, "FUNC", c)

    @lark.v_args(meta=True)
    def trap(self, meta: Any, c: list[Any]) -> n.Routine:
        return self._routine(meta, "TRAP", c)

    @lark.v_args(meta=True)
    def field_decl(self, meta: Any, c: list[Any]) -> tuple[str, str]:
        return (str(c[0]), str(c[1]))

    @lark.v_args(meta=True)
    def record_def(self, meta: Any, c: list[Any]) -> n.RecordDef:
        fields = tuple(x for x in c if isinstance(x, tuple))
        name = [x for x in c if not isinstance(x, tuple)][-1]  # after its scope, where it has one
        return n.RecordDef(self._pos(meta), str(name), fields)

    @lark.v_args(meta=True)
    def alias_decl(self, meta: Any, c: list[Any]) -> n.Alias:
        return n.Alias(self._pos(meta), str(c[0]), str(c[1]))

    def module_attrs(self, c: list[Any]) -> tuple[str, ...]:
        return tuple(str(t) for t in c)

    @lark.v_args(meta=True)
    def module(self, meta: Any, c: list[Any]) -> n.Module:
        name = str(c[0])
        attrs: tuple[str, ...] = ()
        items = c[1:]
        if items and isinstance(items[0], tuple):
            attrs = items.pop(0)
        return n.Module(
            self._pos(meta),
            name,
            attrs,
            tuple(i for i in items if isinstance(i, n.RecordDef)),
            tuple(i for i in items if isinstance(i, n.Alias)),
            tuple(i for i in items if isinstance(i, n.DataDecl)),
            tuple(i for i in items if isinstance(i, n.Routine)),
            self.path,
            self.text,
            self.encoding,
            self.newline,
        )

    def start(self, c: list[Any]) -> n.Module:
        return c[0]  # type: ignore[no-any-return]
