"""Writing a module back: the source unchanged except the statements joulepath replaces."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from joulepath.errors import InvalidInput
from joulepath.program._model import Module, Move, Statement


def _num(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def format_move(move: Move) -> str:
    """A move instruction in canonical form (no comments), e.g. ``MoveJ p10, v1000 \\T:=1.2, z50, tool0;``."""
    speed = move.speed
    if move.v_tcp is not None:
        speed += f" \\V:={_num(move.v_tcp)}"
    if move.time_s is not None:
        speed += f" \\T:={_num(move.time_s)}"
    zone = move.zone + (f" \\Z:={_num(move.z_tcp)}" if move.z_tcp is not None else "")
    return f"{move.instruction} {move.target}, {speed}, {zone}, {move.tool};"


def write_module(
    module: Module,
    *,
    replace: Mapping[int, Sequence[str]] | None = None,
    declarations: Sequence[str] = (),
    header: Sequence[str] = (),
) -> str:
    """The module's source with the statements starting at the lines in ``replace`` replaced.

    ``replace`` maps a statement's first line (1-based) to its new lines (written with
    the statement's indentation); the statement's lines up to its last line go.
    ``declarations`` and ``header`` (comment lines) are inserted after the
    ``MODULE`` line. Nothing else changes: with no replacements the text is the source.
    """
    replace = dict(replace or {})
    spans = {s.line: s.end_line for s in _all_statements(module)}
    for line in replace:
        if line not in spans:
            raise InvalidInput(f"no statement starts at line {line}; cannot replace it")
    src = module.source
    out: list[str] = []
    module_line = next(i for i, text in enumerate(src) if text.strip().upper().startswith("MODULE"))
    i = 0
    while i < len(src):
        lineno = i + 1
        if lineno in replace:
            text = src[i]
            indent = text[: len(text) - len(text.lstrip())]
            out.extend(indent + new for new in replace[lineno])
            i = spans[lineno]
            continue
        out.append(src[i])
        if i == module_line and (declarations or header):
            indent = "    "
            out.extend(indent + h for h in header)
            out.extend(indent + d for d in declarations)
        i += 1
    return "\n".join(out) + "\n"


def _all_statements(module: Module) -> list[Statement]:
    from joulepath.program._parse import _statements

    out: list[Statement] = []
    for p in module.procedures:
        out.extend(_statements(p.body))
    return out
