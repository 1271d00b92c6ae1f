"""Writing a task back as it was written: edits at source positions, every other byte kept.

An :class:`Edit` replaces the characters ``start .. end`` of one module's decoded text (the
span of a node's :class:`~joulepath.rapid.nodes.Pos`). :func:`apply_edits` applies a set of
them and gives each module's bytes in the module's own encoding and line ends, so that a
module nothing touches is written byte for byte as it was read. Helpers build the edits a
motion's levers need: a move's speed data, ``\\T`` and zone, and a statement inserted before
or after another (``AccSet``), indented as the statement is.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from joulepath.errors import RapidError
from joulepath.rapid import nodes as n
from joulepath.rapid.task import Task


@dataclass(frozen=True, slots=True)
class Edit:
    """Replace ``text[start:end]`` of the module read from ``file`` by ``new``."""

    file: str
    start: int
    end: int
    new: str


def _module(task: Task, file: str) -> n.Module:
    m = task.module_of(file)
    if m is None:
        raise ValueError(f"{file}: not a module of the task")
    return m


def apply_edits(task: Task, edits: Iterable[Edit]) -> dict[str, bytes]:
    """Every module's bytes after the edits (unchanged modules as read); overlapping edits are refused."""
    by_file: dict[str, list[Edit]] = {}
    for e in edits:
        by_file.setdefault(e.file, []).append(e)
    out: dict[str, bytes] = {}
    for m in task.modules:
        text = m.text
        mine = sorted(by_file.pop(m.path, []), key=lambda e: (e.start, e.end))
        for a, b in zip(mine, mine[1:], strict=False):
            if b.start < a.end:
                raise ValueError(f"{m.path}: edits overlap at characters {b.start}..{a.end}")
        for e in reversed(mine):
            if not 0 <= e.start <= e.end <= len(text):
                raise ValueError(f"{m.path}: an edit outside the text ({e.start}..{e.end})")
            text = text[: e.start] + e.new + text[e.end :]
        if m.newline != "\n":
            text = text.replace("\n", m.newline)
        try:
            out[m.path] = text.encode(m.encoding)
        except UnicodeEncodeError as err:
            raise RapidError(
                f"{m.path}: the written text holds a character {m.encoding} cannot store ({err.reason})"
            ) from None
    if by_file:
        raise ValueError(f"edits of files not in the task: {', '.join(sorted(by_file))}")
    return out


def original_bytes(task: Task) -> dict[str, bytes]:
    """Each module's bytes as :func:`apply_edits` writes them with no edit (the read-back identity)."""
    return apply_edits(task, ())


def _arg(call: n.Call, k: int) -> n.Arg:
    positional = [a for a in call.args if a.kind == "pos"]
    return positional[k]


def _opt(call: n.Call, name: str) -> n.Arg | None:
    return next((a for a in call.args if a.kind == "opt" and a.name and a.name.lower() == name.lower()), None)


def replace_argument(call: n.Call, index: int, text: str) -> Edit:
    """The ``index``-th positional argument of a call (0-based) replaced by ``text``."""
    a = _arg(call, index)
    return Edit(call.pos.file, a.pos.start, a.pos.end, text)


def set_optional(module: n.Module, call: n.Call, name: str, value: str | None, after: int) -> Edit | None:
    """``\\name:=value`` set (``value`` None: removed) on a call; added after
    positional argument ``after``."""
    cur = _opt(call, name)
    if cur is not None:
        start = cur.pos.start
        # take the backslash and any comma before it with the argument
        while start > 0 and module.text[start - 1] in " \t":
            start -= 1
        if value is None:
            return Edit(call.pos.file, start, cur.pos.end, "")
        return Edit(call.pos.file, cur.pos.start, cur.pos.end, f"\\{cur.name}:={value}")
    if value is None:
        return None
    a = _arg(call, after)
    return Edit(call.pos.file, a.pos.end, a.pos.end, f" \\{name}:={value}")


def indentation(module: n.Module, pos: n.Pos) -> str:
    line_start = module.text.rfind("\n", 0, pos.start) + 1
    head = module.text[line_start : pos.start]
    return head if not head.strip() else " " * len(head)


def insert_before(module: n.Module, stmt: n.Stmt, text: str) -> Edit:
    """A statement inserted on its own line before ``stmt``, at its indentation."""
    line_start = module.text.rfind("\n", 0, stmt.pos.start) + 1
    ind = indentation(module, stmt.pos)
    return Edit(module.path, line_start, line_start, f"{ind}{text}\n")


def insert_after(module: n.Module, stmt: n.Stmt, text: str) -> Edit:
    """A statement inserted on its own line after ``stmt``, at its indentation."""
    end = module.text.find("\n", stmt.pos.end)
    end = len(module.text) if end < 0 else end
    ind = indentation(module, stmt.pos)
    return Edit(module.path, end, end, f"\n{ind}{text}")


def write_task(task: Task, texts: dict[str, bytes], out: Path) -> list[Path]:
    """Write every module into ``out`` under its path relative to the modules' common folder."""
    paths = [Path(m.path).resolve() for m in task.modules]
    common = Path(*_common_parts([p.parent.parts for p in paths])) if len(paths) > 1 else paths[0].parent
    written = []
    for m, p in zip(task.modules, paths, strict=True):
        rel = p.relative_to(common) if p.is_relative_to(common) else Path(p.name)
        dest = out / rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        dest.write_bytes(texts[m.path])
        written.append(dest)
    return written


def _common_parts(parts: Sequence[tuple[str, ...]]) -> tuple[str, ...]:
    first = parts[0]
    k = 0
    while k < len(first) and all(len(p) > k and p[k] == first[k] for p in parts):
        k += 1
    return first[:k]
