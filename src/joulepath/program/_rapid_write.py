"""The optimized RAPID module that keeps the program: only the optimized moves change.

What the input says stays as written: its modules, procedures, FOR loops, IF / TEST,
named targets and declarations. Each optimized move line becomes a call of an
optimized procedure, ``jp_opt_<proc>_<n>`` (the n-th move of procedure ``<proc>``),
added at the end of the module with its via points in ``CONST jointtarget``
arrays, ``jp_<proc>_<n>{k}``, added before the first routine. Where the planned
motion ends exactly at the move's target (a stop point, a pick, a place), the
optimized procedure's last move is the program's own move to its named target (the
same target expression, tool and work object; timed), so re-teaching the target on
the FlexPendant still moves the robot there.

A move that runs more than once in the cycle (a procedure called more than once, a
FOR loop) is written as one shared shape when every run is the same motion, else
per run: the optimized procedure's ``TEST jpCtx`` picks the run's via points, and
the run number is passed from the call sites. A procedure entered more than once
whose runs differ then gains a ``num jpRun`` parameter, and its call sites pass
their run number (an expression of the FOR loop variables around them); call
sites outside the cycle pass 0, which runs the taught move (``DEFAULT``).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from joulepath.abb import EXTERNAL_AXES_UNUSED, VIA_ZONE_MM
from joulepath.errors import LimitViolation
from joulepath.program._model import (
    Branch,
    Call,
    ForLoop,
    Module,
    Move,
    Procedure,
    Statement,
    TargetRef,
    WaitTime,
    WhileTrue,
)
from joulepath.program._write import _num

VIA_ZONE = f"z{VIA_ZONE_MM:.0f}"
"""Zone of the via points inside an optimized move (:data:`joulepath.abb.VIA_ZONE_MM`)."""

VIA_SPEED = "v7000"
"""Speeddata of the via moves: their ``\\T`` times them (the TCP speed is not a bound)."""

RUN_PARAM = "jpRun"
"""The parameter a procedure entered more than once gains when its runs differ."""

CONTEXT_PARAM = "jpCtx"
"""The parameter of an optimized procedure whose runs differ: the run, picked by ``TEST``."""

TARGET_ATOL_RAD = 1e-4
"""How close (each joint, rad) the planned motion's end must come to a move's target for the
written motion to end with the program's own move to that target (0.1 mrad: under 0.1 mm of TCP
on an IRB 120; the optimizer ends a stop at its target to its convergence, about 3e-5 rad)."""

MAX_NAME = 32
"""RAPID's longest identifier."""

_MOVE_HEAD = re.compile(r"^\s*(MoveAbsJ|MoveJ|MoveL)\b", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class WrittenMove:
    """One optimized move line as written.

    ``runs``: how often the line runs per cycle; ``optimized_runs``: of which
    optimized; ``shapes``: distinct written motions (1: one shared shape);
    ``final_target``: the program's target the last move goes to (None: the
    planned motion passes the target within its zone, so a generated via point
    ends it); ``reteach``: named targets whose re-teaching asks to optimize the
    line again.
    """

    line: int
    procedure: str
    call: str
    runs: int
    optimized_runs: int
    shapes: int
    selection: str
    final_target: str | None
    reteach: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class WrittenModule:
    """The written text and what it holds (``indexed``: procedures that gained ``num jpRun``)."""

    text: str
    moves: tuple[WrittenMove, ...]
    indexed: tuple[str, ...]
    reteach: dict[str, tuple[int, ...]] = field(default_factory=dict)

    def summary(self) -> dict[str, Any]:
        """For cycle.json."""
        return {
            "optimized_lines": [
                {
                    "line": m.line,
                    "procedure": m.procedure,
                    "call": m.call,
                    "runs": m.runs,
                    "optimized_runs": m.optimized_runs,
                    "shapes": m.shapes,
                    "selection": m.selection,
                    "final_target": m.final_target,
                }
                for m in self.moves
            ],
            "procedures_given_jpRun": list(self.indexed),
            "reteach": {k: list(v) for k, v in self.reteach.items()},
            "note": "optimized.mod keeps the program: each optimized move line calls jp_opt_<proc>_<n> "
            "(added at its end; via points in CONST jointtarget arrays jp_<proc>_<n>, added before the "
            "first routine); a move ending at its target ends with the program's own move to it. selection: "
            "'shared' = one motion for every run of the line; 'per run' = TEST jpCtx picks the run's via "
            "points (procedures_given_jpRun pass the run number). reteach: for each named target, the "
            "optimized lines whose via points were planned from it; after re-teaching it, run joulepath "
            "cycle on the re-taught optimized.mod (read as the program it was written from, each replaced "
            "line kept in a '! joulepath: was:' comment) to plan them again; until then the named target "
            "moves the final point and the via points before it stay as planned",
        }


@dataclass(frozen=True, slots=True)
class _Occurrence:
    """One run of a statement in the cycle: its procedure, FOR loops inside it, and the procedure's entry."""

    stmt: Statement
    proc: str  # lower-case name
    loops: tuple[tuple[ForLoop, int], ...]  # loops around it inside proc (outer first), run index
    entry: int  # which entry of proc, in cycle order (0-based)


def _walk(module: Module) -> tuple[list[_Occurrence], dict[str, int], dict[tuple[str, int], _Occurrence]]:
    """Every move, wait, verbatim and call of the cycle in order (as the reader flattens it);
    the number of entries of each procedure; for each entry the call that made it."""
    occ: list[_Occurrence] = []
    entries: dict[str, int] = {"main": 1}
    made_by: dict[tuple[str, int], _Occurrence] = {}

    def go(
        body: tuple[Statement, ...], proc: str, loops: tuple[tuple[ForLoop, int], ...], entry: int
    ) -> None:
        for s in body:
            if isinstance(s, Call):
                here = _Occurrence(s, proc, loops, entry)
                occ.append(here)
                callee = s.name.lower()
                k = entries.get(callee, 0)
                entries[callee] = k + 1
                made_by[(callee, k)] = here
                inner = s.body
                if inner is None:
                    p = module.procedure(s.name)
                    assert p is not None
                    inner = p.body
                go(inner, callee, (), k)
            elif isinstance(s, WhileTrue | Branch):
                go(s.body, proc, loops, entry)
            elif isinstance(s, ForLoop):
                for k, run in enumerate(s.runs):
                    go(run, proc, (*loops, (s, k)), entry)
            else:
                occ.append(_Occurrence(s, proc, loops, entry))

    main = module.procedure("main")
    assert main is not None
    loop = next((s for s in main.body if isinstance(s, WhileTrue)), None)
    go(loop.body if loop is not None else main.body, "main", (), 0)
    return occ, entries, made_by


def _jt(q_deg: np.ndarray) -> str:
    ext = ", ".join([EXTERNAL_AXES_UNUSED] * 6)
    return "[[" + ", ".join(_num(float(v)) for v in q_deg) + f"], [{ext}]]"


def _statement_text(source: tuple[str, ...], line: int, end_line: int) -> str:
    """A statement's text up to its ``;`` (comments dropped, lines joined)."""
    parts = []
    for raw in source[line - 1 : end_line]:
        cut = raw.split("!", 1)[0] if '"' not in raw else raw
        parts.append(cut.strip())
    text = " ".join(p for p in parts if p)
    return text[: text.index(";")] if ";" in text else text


def _split_move(source: tuple[str, ...], move: Move, path: str) -> tuple[str, list[str]]:
    from joulepath.program._parse import _split_args

    text = _statement_text(source, move.line, move.end_line)
    head = text.split(None, 1)[0]
    return head, _split_args(path, move.line, text[len(head) :].strip())


def _loop_index(loop: ForLoop) -> str:
    first = loop.values[0]
    step = loop.values[1] - loop.values[0] if len(loop.values) > 1 else 1
    var = loop.variable
    shifted = var if first == 0 else f"({var} - {first})" if first > 0 else f"({var} + {-first})"
    if step == 1:
        return shifted
    if step == -1:
        return f"({first} - {var})"
    return f"{shifted} DIV {step}"


def _run_expression(loops: Sequence[ForLoop], indexed: bool) -> str:
    """The run number (1, 2, ...) at a position inside a procedure, as RAPID: its FOR loops'
    indices (mixed radix, the outer loop first) and, for a procedure entered more than once,
    its ``jpRun``."""
    sizes = [len(f.values) for f in loops]
    if indexed and not loops:
        return RUN_PARAM
    terms = []
    if indexed:
        m = int(np.prod(sizes)) if sizes else 1
        terms.append(f"({RUN_PARAM} - 1)" + ("" if m == 1 else f" * {m}"))
    for k, f in enumerate(loops):
        w = int(np.prod(sizes[k + 1 :])) if k + 1 < len(sizes) else 1
        idx = _loop_index(f)
        terms.append(idx if w == 1 else f"{idx} * {w}")
    terms.append("1")
    return " + ".join(terms)


def _run_value(loops: Sequence[tuple[ForLoop, int]], run: int | None) -> int:
    sizes = [len(f.values) for f, _ in loops]
    value = 0
    for (_, k), n in zip(loops, sizes, strict=True):
        value = value * n + k
    if run is not None:
        value += (run - 1) * (int(np.prod(sizes)) if sizes else 1)
    return value + 1


def _site_argument(run_expr: str, sites: int, site: int) -> str:
    if run_expr == "1":
        return str(site + 1)
    if sites == 1:
        return run_expr
    return f"({run_expr} - 1) * {sites} + {site + 1}"


def _short(name: str, suffix: str, prefix: str) -> str:
    keep = MAX_NAME - len(prefix) - len(suffix)
    return prefix + name[: max(keep, 1)] + suffix


def _occurrence_of_steps(spec: Any, move_steps: Sequence[int], occ: Sequence[Any]) -> dict[int, Any]:
    """Each move step of the cycle (its index) with its statement's occurrence in the module's walk;
    refused where the cycle's moves do not match the module's statements."""
    move_occ = [o for o in occ if isinstance(o.stmt, Move)]
    if len(move_steps) != len(move_occ) or any(
        spec.steps[i].line != o.stmt.line for i, o in zip(move_steps, move_occ, strict=True)
    ):
        raise LimitViolation(
            "the cycle's moves do not match the module's statements; the program is not written"
        )
    return dict(zip(move_steps, move_occ, strict=True))


def _needs_run(occ: Sequence[Any], entries: dict[str, int], own: set[str]) -> dict[str, bool]:
    """Per procedure (lower-case name) met in the walk: whether it takes a run number, i.e. is entered
    more than once per cycle and holds a line whose runs are written differently (``own``: those
    procedures) or calls one that takes it."""
    callees: dict[str, set[str]] = {}
    for o in occ:
        if isinstance(o.stmt, Call):
            callees.setdefault(o.proc, set()).add(o.stmt.name.lower())
    needs: dict[str, bool] = {}

    def need(p: str) -> bool:
        if p not in needs:
            needs[p] = entries.get(p, 0) > 1 and (p in own or any(need(c) for c in callees.get(p, ())))
        return needs[p]

    for p in list(entries):
        need(p)
    return needs


def _group_bodies(
    groups: dict[tuple[tuple[str, ...], tuple[str, ...], str | None], list[int]],
    original: str,
    proc_name: str,
    n: int,
    base: str,
    decls: list[str],
) -> tuple[list[str], set[str]]:
    """The written body of one move line from its runs' ``groups`` (one body for all of them, else a
    ``CASE`` per group and the taught runs left to ``DEFAULT``), its arrays of via points added to
    ``decls`` (several groups: in a ``TEST`` of the run number); and the final targets its bodies end at."""
    body: list[str] = []
    finals = set()
    for g, (key, vals) in enumerate(groups.items(), start=1):
        elements, moves_text, final = key
        if final == "taught":
            part = [original]
        else:
            name = base if len(groups) == 1 else _short(proc_name, f"_{n}_{g}", "jp_")
            if elements:
                decls.append(f"CONST jointtarget {name}{{{len(elements)}}} := [")
                decls.extend(f"    {e}," for e in elements[:-1])
                decls.append(f"    {elements[-1]}")
                decls.append("];")
            part = [t.replace("{ARR}", name) for t in moves_text]
            if final is not None:
                finals.add(final)
        if len(groups) == 1:
            body.extend(part)
        elif final != "taught":  # the taught runs go to DEFAULT
            body.append(f"CASE {', '.join(map(str, sorted(vals)))}:")
            body.extend("    " + t for t in part)
    if len(groups) > 1:
        body = [f"TEST {CONTEXT_PARAM}", *body, "DEFAULT:", f"    {original}", "ENDTEST"]
    return body, finals


def _check_same_loops(ln: int, loops: Sequence[Any], others: Sequence[Any]) -> None:
    """Refuse a move line whose runs (``others``, after the first) sit in FOR loops other than the
    first run's ``loops``."""
    for o in others:
        other = [(f.line, f.values) for f, _ in o.loops]
        if other != [(f.line, f.values) for f in loops]:
            raise LimitViolation(
                f"line {ln}: the FOR loops around the move run differently in its runs; "
                "the program is not written"
            )


def _check_told_apart(ln: int, groups: dict[Any, list[int]]) -> None:
    """Refuse a move line whose runs, written differently, share a run number."""
    picked = {v: key for key, vs in groups.items() for v in vs}
    if len(groups) > 1 and len(picked) != sum(len(vs) for vs in groups.values()):
        raise LimitViolation(
            f"line {ln}: the runs of this move cannot be told apart by their run number "
            "(FOR loops whose bounds change between calls); the program is not written"
        )


def _refuse_name_clashes(
    source: tuple[str, ...], written: Sequence[WrittenMove], decls: Sequence[str]
) -> None:
    """Refuse names joulepath adds that the module already uses (or that shorten to the same name)."""
    taken = {w.lower() for w in re.findall(r"[A-Za-z]\w*", "\n".join(source))}  # any name the module uses
    added = [m.call.lower() for m in written] + [
        d.split()[2].split("{")[0].lower() for d in decls if d.startswith("CONST jointtarget")
    ]
    clash = sorted((set(added) & taken) | {a for a in added if added.count(a) > 1})
    if clash:
        raise LimitViolation(
            f"the names joulepath adds ({', '.join(clash)}) are already used in the module (or shortened "
            "to the same name); the program is not written (rename them in the module)"
        )


def _run_edits(
    source: tuple[str, ...], proc: Any, sites: Sequence[tuple[int, Any]], needs: dict[str, bool]
) -> dict[int, str]:
    """The lines edited to give procedure ``proc`` its run number: its declaration and each call site
    (``sites``: line, and the call's walk where it is in the cycle, else None: 0 runs the taught motion)."""
    edits = {proc.line: _add_parameter(source[proc.line - 1], proc, f"num {RUN_PARAM}")}
    site_lines = [s for s, _ in sites]
    for k, (s_line, in_cycle) in enumerate(sites):
        if in_cycle is None:  # outside the cycle: 0 runs the taught motion
            arg = "0"
        else:
            arg = _site_argument(
                _run_expression(list(in_cycle.loops_f), needs.get(in_cycle.proc, False)),
                len(site_lines),
                k,
            )
        edits[s_line] = _add_argument(source[s_line - 1], proc.name, arg, s_line)
    return edits


def _wait_edits(result: Any, module: Any, source: tuple[str, ...]) -> dict[int, tuple[int, list[str]]]:
    """The ``WaitTime`` statements whose time was spent on the moves (``--use-waits``), replaced."""
    out: dict[int, tuple[int, list[str]]] = {}
    for wline, before, after in result.waits:
        if after != before:
            end = next(
                s.end_line for s in _statements_of(module) if isinstance(s, WaitTime) and s.line == wline
            )
            out[wline] = (
                end,
                [
                    f"! joulepath: WaitTime {_num(before)} s spent on the moves (--use-waits)",
                    *_was(source, wline, end),
                    f"WaitTime {_num(after)};",
                ],
            )
    return out


def written_module(result: Any, header: Sequence[str]) -> WrittenModule:
    """The module of ``result`` (a :class:`~joulepath.program.CycleResult`) keeping its program.

    ``LimitViolation`` with one line when it cannot be written this way (a via point out
    of a range, a segment over a joint speed limit, a call or procedure line it cannot
    extend). A plan that re-times segments with a MoveL along their path is written as it was
    before that (:attr:`~joulepath.program.CycleResult.unretimed`): RAPID's own MoveL runs at its
    speeddata.
    """
    result = result.unretimed or result
    spec = result.spec
    module = spec.module
    assert module is not None
    source = module.source
    occ, entries, made_by = _walk(module)
    move_steps = [i for i, st in enumerate(spec.steps) if st.kind == "move"]
    occ_of_step = _occurrence_of_steps(spec, move_steps, occ)

    through = {j for chain in result.chains.values() for j in chain[:-1]} | set(result.open_ends)
    # ---- each run of each optimized line: its written body (array name left open)
    lines: dict[int, list[int]] = {}
    for i in move_steps:
        lines.setdefault(spec.steps[i].line, []).append(i)
    optimized_lines = sorted({spec.steps[i].line for i in result.paths})
    bodies: dict[int, tuple[tuple[str, ...], tuple[str, ...], str | None]] = {}
    for i, solved in result.paths.items():
        bodies[i] = _run_body(result, i, solved, through, source, module.path)

    proc_of_line = {ln: occ_of_step[lines[ln][0]].proc for ln in optimized_lines}
    differs = {ln: len({bodies.get(i, ((), (), "taught")) for i in lines[ln]}) > 1 for ln in optimized_lines}
    procs = {p.name.lower(): p for p in module.procedures}
    needs = _needs_run(occ, entries, {proc_of_line[ln] for ln in optimized_lines if differs[ln]})
    indexed = sorted(p for p, v in needs.items() if v)

    # ---- run values: the jpRun of every entry of an indexed procedure, from its call site
    sites = {p: _call_sites(module, procs[p]) for p in indexed}
    run_of_entry: dict[tuple[str, int], int] = {}

    def entry_run(p: str, e: int) -> int | None:
        if not needs.get(p):
            return None
        key = (p, e)
        if key not in run_of_entry:
            call = made_by[key]
            at = _run_value(call.loops, entry_run(call.proc, call.entry))
            lines_p = [ln for ln, _ in sites[p]]
            if call.stmt.line not in lines_p:
                raise LimitViolation(
                    f"line {call.stmt.line}: the call of {procs[p].name} is not one statement on one line; "
                    "the program is not written (write the call on one line)"
                )
            run_of_entry[key] = (at - 1) * len(lines_p) + lines_p.index(call.stmt.line) + 1
        return run_of_entry[key]

    # ---- additions and replacements
    replace: dict[int, tuple[int, list[str]]] = {}
    edits: dict[int, str] = {}
    decls: list[str] = []
    new_procs: list[str] = []
    written: list[WrittenMove] = []
    reteach_of = _reteach(result, spec, module)
    for ln in optimized_lines:
        steps_l = lines[ln]
        first = occ_of_step[steps_l[0]]
        move = first.stmt
        assert isinstance(move, Move)
        proc = procs[first.proc]
        n = _ordinal(source, proc, ln)
        call_name = _short(proc.name, f"_{n}", "jp_opt_")
        base = _short(proc.name, f"_{n}", "jp_")
        loops = [f for f, _ in first.loops]
        _check_same_loops(ln, loops, [occ_of_step[i] for i in steps_l[1:]])
        params = [f"{t} {nm}" for t, nm in proc.params] + [f"num {f.variable}" for f in loops]
        args = [nm for _, nm in proc.params] + [f.variable for f in loops]
        groups: dict[tuple[tuple[str, ...], tuple[str, ...], str | None], list[int]] = {}
        for i in steps_l:
            value = _run_value(occ_of_step[i].loops, entry_run(first.proc, occ_of_step[i].entry))
            groups.setdefault(bodies.get(i, ((), (), "taught")), []).append(value)
        _check_told_apart(ln, groups)
        head, mv_args = _split_move(source, move, module.path)
        original = f"{head} {', '.join(mv_args)};"
        body, finals = _group_bodies(groups, original, proc.name, n, base, decls)
        if len(groups) > 1:
            if CONTEXT_PARAM.lower() in {a.lower() for a in args}:
                raise LimitViolation(f"line {ln}: {CONTEXT_PARAM} is already a name here; not written")
            params.append(f"num {CONTEXT_PARAM}")
            args.append(_run_expression(loops, needs.get(first.proc, False)))
        opt_runs = sum(1 for i in steps_l if i in result.paths)
        shapes = sum(1 for k in groups if k[2] != "taught")
        how = "shared" if len(groups) == 1 else f"per run: TEST {CONTEXT_PARAM}"
        new_procs.append(f"PROC {call_name}({', '.join(params)})")
        new_procs.append(f"    ! joulepath: optimized {original} ({len(steps_l)} run(s) per cycle, {how})")
        new_procs.extend("    " + t for t in body)
        new_procs.append("ENDPROC")
        call = call_name + (" " + ", ".join(args) if args else "") + ";"
        replace[ln] = (move.end_line, [*_was(source, move.line, move.end_line), call])
        final_target = mv_args[0] if finals else None
        written.append(
            WrittenMove(
                ln,
                proc.name,
                call_name,
                len(steps_l),
                opt_runs,
                shapes,
                "shared" if len(groups) == 1 else "per run",
                final_target,
                tuple(sorted(k for k, v in reteach_of.items() if ln in v)),
            )
        )
    _refuse_name_clashes(source, written, decls)
    for p in indexed:
        edits.update(_run_edits(source, procs[p], sites[p], needs))
    replace.update(_wait_edits(result, module, source))
    text = _assemble(source, replace, edits, header, decls, new_procs)
    reteach = {k: tuple(sorted(v)) for k, v in reteach_of.items() if v}
    return WrittenModule(text, tuple(written), tuple(procs[p].name for p in indexed), reteach)


WAS = "! joulepath: was: "
"""Marks a line of the input that the written module replaces, kept verbatim (see :func:`restore_program`)."""


def _was(source: tuple[str, ...], line: int, end_line: int) -> list[str]:
    """The input's lines ``line..end_line`` as comments, relative to the first line's indentation."""
    first = source[line - 1]
    indent = first[: len(first) - len(first.lstrip())]
    return [
        WAS + (raw[len(indent) :] if raw.startswith(indent) else raw.lstrip())
        for raw in source[line - 1 : end_line]
    ]


def _statements_of(module: Module) -> list[Statement]:
    from joulepath.program._parse import _statements

    out: list[Statement] = []
    for p in module.procedures:
        out.extend(_statements(p.body))
    return out


def _ordinal(source: tuple[str, ...], proc: Procedure, line: int) -> int:
    """Which move of ``proc`` (1-based, in source order) starts at ``line``."""
    heads = [k for k in range(proc.line + 1, proc.end_line) if _MOVE_HEAD.match(source[k - 1])]
    return heads.index(line) + 1 if line in heads else line


@dataclass(frozen=True, slots=True)
class _Site:
    proc: str
    loops_f: tuple[ForLoop, ...]


def _call_sites(module: Module, proc: Procedure) -> list[tuple[int, _Site | None]]:
    """Every line that calls ``proc`` (source order): its position in the cycle, or None outside it."""
    occ, _, _ = _walk(module)
    in_cycle: dict[int, _Site] = {}
    for o in occ:
        if isinstance(o.stmt, Call) and o.stmt.name.lower() == proc.name.lower():
            if o.stmt.line != o.stmt.end_line:
                raise LimitViolation(
                    f"line {o.stmt.line}: the call of {proc.name} spans lines; write it on one line to "
                    "have the program written"
                )
            in_cycle.setdefault(o.stmt.line, _Site(o.proc, tuple(f for f, _ in o.loops)))
    pattern = re.compile(rf"^\s*{re.escape(proc.name)}\b(?!\s*:=)", re.IGNORECASE)
    out = []
    for k, raw in enumerate(module.source, start=1):
        if k == proc.line or not pattern.match(raw.split("!", 1)[0]):
            continue
        out.append((k, in_cycle.get(k)))
    return out


def _add_parameter(text: str, proc: Procedure, param: str) -> str:
    m = re.search(r"\(\s*(.*?)\s*\)", text)
    if m is None:
        raise LimitViolation(
            f"line {proc.line}: PROC {proc.name}'s parameters are not on its PROC line; the program is not "
            "written (write them on one line)"
        )
    inner = m.group(1)
    new = f"({inner}, {param})" if inner else f"({param})"
    return text[: m.start()] + new + text[m.end() :]


def _add_argument(text: str, name: str, arg: str, line: int) -> str:
    m = re.match(rf"^(\s*{re.escape(name)})(\s*)([^;]*);", text, re.IGNORECASE)
    if m is None:
        raise LimitViolation(f"line {line}: cannot extend the call of {name}; write it on one line")
    rest = m.group(3).rstrip()
    new = f"{m.group(1)}{m.group(2)}{rest}, {arg};" if rest else f"{m.group(1)} {arg};"
    return new + text[m.end() :]


def _assemble(
    source: tuple[str, ...],
    replace: dict[int, tuple[int, list[str]]],
    edits: dict[int, str],
    header: Sequence[str],
    decls: Sequence[str],
    procs: Sequence[str],
) -> str:
    out: list[str] = []
    module_line = next(k for k, t in enumerate(source) if t.strip().upper().startswith("MODULE"))
    routine = re.compile(r"^\s*(?:LOCAL\s+)?(?:PROC|FUNC|TRAP)\b", re.IGNORECASE)
    data_at = next((k for k, t in enumerate(source) if routine.match(t)), module_line + 1)
    end_line = max(k for k, t in enumerate(source) if t.strip().upper().startswith("ENDMODULE"))
    k = 0
    while k < len(source):
        lineno = k + 1
        if k == data_at and decls:
            out.append("    ! joulepath: via points of the optimized moves (additions)")
            out.extend("    " + d for d in decls)
            out.append("")
        if k == end_line and procs:
            out.append("")
            out.append("    ! joulepath: the optimized moves (additions; the program above calls them)")
            out.extend("    " + t for t in procs)
        if lineno in replace:
            raw = source[k]
            indent = raw[: len(raw) - len(raw.lstrip())]
            last, new = replace[lineno]
            out.extend(indent + t for t in new)
            k = last
            continue
        out.append(edits.get(lineno, source[k]))
        if k == module_line:
            out.extend("    " + h for h in header)
        k += 1
    return "\n".join(out) + "\n"


def _run_body(
    result: Any, i: int, solved: Any, through: set[int], source: tuple[str, ...], path: str
) -> tuple[tuple[str, ...], tuple[str, ...], str | None]:
    """One optimized run: its via array's elements, its move lines (``{ARR}`` for the array's name)
    and its final target (None: a generated via point ends it)."""
    spec = result.spec
    step = spec.steps[i]
    move = step.statement
    robot = step.robot
    assert isinstance(move, Move) and robot is not None and step.q is not None
    own = move.zone + ("" if move.z_tcp is None else f" \\Z:={_num(move.z_tcp)}")
    end = own if i in through else "fine" if step.zone_mm is None else "z1"
    idx = list(result.vias[i])
    samples = solved.fine
    lo, hi = robot.joint_ranges()
    q = samples.q[idx]
    if np.any(q < lo - 1e-9) or np.any(q > hi + 1e-9):
        raise LimitViolation(
            f"line {move.line}: a via point leaves a joint range; the program is not written"
        )
    times = np.diff([0.0, *samples.t[idx]])
    prev = np.vstack([samples.q[0], q[:-1]])
    speed = np.abs(q - prev) / times[:, None]
    if np.any(speed > robot.velocity_limit * (1 + 1e-9)):
        raise LimitViolation(f"line {move.line}: a via segment exceeds a joint speed limit; not written")
    named = bool(np.abs(q[-1] - step.q).max() <= TARGET_ATOL_RAD)
    vias = q[:-1] if named else q
    axes = robot.joints_to_axes(vias)  # a jointtarget holds the controller's axis values
    if any(robot.axes_outside(a) is not None for a in axes):
        raise LimitViolation(
            f"line {move.line}: a via point leaves the controller's axis-3 range; the program is not written"
        )
    elements = tuple(_jt(np.degrees(a)) for a in axes)
    lines = []
    for k, tk in enumerate(times[: len(vias)], start=1):
        zone = end if (k == len(vias) and not named) else VIA_ZONE
        lines.append(f"MoveAbsJ {{ARR}}{{{k}}}, {VIA_SPEED} \\T:={_num(float(tk))}, {zone}, {move.tool};")
    final = None
    if named:
        head, args = _split_move(source, move, path)
        lines.append(f"{head} {args[0]}, {VIA_SPEED} \\T:={_num(float(times[-1]))}, {end}, {args[3]};")
        final = args[0]
    return elements, tuple(lines), final


def _target_names(module: Module, move: Move) -> set[str]:
    """The declared targets a move's target is computed from (through Offs / RelTool declarations)."""
    ref = move.target_ref or TargetRef(move.target)
    out: set[str] = set()
    name = ref.name.partition("{")[0]
    while name and name.lower() not in {n.lower() for n in out}:
        out.add(name)
        d = module.declaration(name)
        if d is None or not isinstance(d.value, TargetRef):
            break
        name = d.value.name.partition("{")[0]
    return out


def _reteach(result: Any, spec: Any, module: Module) -> dict[str, set[int]]:
    """For each named target, the optimized lines whose planned motion starts, passes or ends at it."""
    moves = [i for i, st in enumerate(spec.steps) if st.kind == "move"]
    prev = {b: a for a, b in zip([moves[-1], *moves[:-1]], moves, strict=True)}
    unit_of: dict[int, tuple[int, ...]] = {}
    for chain in result.chains.values():
        for j in chain:
            unit_of[j] = tuple(chain)
    out: dict[str, set[int]] = {}
    for i in result.paths:
        members = unit_of.get(i, (i,))
        names: set[str] = set()
        for j in (prev[members[0]], *members):
            names |= _target_names(module, spec.steps[j].statement)
        for nm in names:
            out.setdefault(nm, set()).update(spec.steps[j].line for j in members)
    return out


HEADERS = ("! Optimized by joulepath", "! The program is kept as written;", "! WARNING: run by joulepath")
_DECLS_MARK = "! joulepath: via points of the optimized moves (additions)"
_PROCS_MARK = "! joulepath: the optimized moves (additions"
_USED_WAIT = re.compile(r"^! joulepath: WaitTime \S+ s spent on the moves \(--use-waits\)$")


def restore_program(text: str) -> str | None:
    """The program a module written by joulepath was written from, with whatever was changed in it
    since (a re-taught target); None when ``text`` is not such a module.

    The header, the added arrays and procedures go; each replaced line comes back from its
    ``! joulepath: was:`` comment; ``num jpRun`` leaves the procedures that gained it and the
    run number their call sites.
    """
    lines = text.splitlines()
    if not any(ln.strip().startswith(HEADERS[1]) for ln in lines):
        return None
    indexed: dict[str, bool] = {}  # procedure -> had parameters before jpRun
    for ln in lines:
        m = re.match(rf"^\s*(?:LOCAL\s+)?PROC\s+(\w+)\s*\((.*?)\bnum\s+{RUN_PARAM}\s*\)", ln, re.IGNORECASE)
        if m:
            indexed[m.group(1).lower()] = bool(m.group(2).strip())
    out: list[str] = []
    k = 0
    while k < len(lines):
        raw = lines[k]
        s = raw.strip()
        indent = raw[: len(raw) - len(raw.lstrip())]
        if s.startswith(HEADERS):
            k += 1
        elif s == _DECLS_MARK:
            while k < len(lines) and lines[k].strip():
                k += 1
            k += 1  # and the blank line after the block
        elif s.startswith(_PROCS_MARK):
            if out and not out[-1].strip():
                out.pop()
            while k < len(lines) and not lines[k].strip().upper().startswith("ENDMODULE"):
                k += 1
        elif s.startswith(WAS) or _USED_WAIT.match(s):
            k += 1 if _USED_WAIT.match(s) else 0
            prefix = indent + WAS
            while k < len(lines) and lines[k].startswith(prefix):
                out.append(indent + lines[k][len(prefix) :])
                k += 1
            k += 1  # the call (or the shortened WaitTime) that stood for them
        else:
            out.append(_restore_line(raw, indexed))
            k += 1
    return "\n".join(out) + "\n"


def _restore_line(raw: str, indexed: dict[str, bool]) -> str:
    m = re.match(r"^(\s*)(?:LOCAL\s+)?PROC\s+(\w+)\s*\(", raw, re.IGNORECASE)
    if m and m.group(2).lower() in indexed:
        return re.sub(rf"(?:,\s*|\b)num\s+{RUN_PARAM}\s*\)", ")", raw, count=1)
    m = re.match(r"^(\s*)(\w+)(\s*)([^;!]*);(.*)$", raw)
    if m is None or m.group(2).lower() not in indexed:
        return raw
    if not indexed[m.group(2).lower()]:
        return f"{m.group(1)}{m.group(2)};{m.group(5)}"
    args = m.group(4)
    depth, cut = 0, -1
    for i, ch in enumerate(args):
        depth += ch in "([{"
        depth -= ch in ")]}"
        if ch == "," and depth == 0:
            cut = i
    return f"{m.group(1)}{m.group(2)}{m.group(3)}{args[:cut]};{m.group(5)}"


def motion_model(spec: Any) -> list[tuple[Any, ...]]:
    """What the controller runs, in order, without source lines: moves (joints rad, speed, ``\\T``,
    zone, linear), waits (s) and kept instructions (their text)."""
    out: list[tuple[Any, ...]] = []
    for st in spec.steps:
        if st.kind == "move":
            out.append(("move", st.q, st.speed, st.time_s, st.zone_mm, st.linear))
        elif st.kind == "wait":
            out.append(("wait", st.seconds))
        else:
            out.append(("fixed", st.label))
    return out


def planned_model(result: Any) -> list[tuple[Any, ...]]:
    """The motion model the written module of ``result`` must read back as (:func:`motion_model`)."""
    from joulepath.program._parse import PREDEFINED_SPEEDS, PREDEFINED_ZONES

    result = result.unretimed or result
    spec = result.spec
    through = {j for chain in result.chains.values() for j in chain[:-1]} | set(result.open_ends)
    waits = {w[0]: w[2] for w in result.waits}
    out: list[tuple[Any, ...]] = []
    for i, st in enumerate(spec.steps):
        if st.kind == "wait":
            out.append(("wait", waits.get(st.line, st.seconds)))
        elif st.kind == "fixed":
            out.append(("fixed", st.label))
        elif i not in result.paths:
            out.append(("move", st.q, st.speed, st.time_s, st.zone_mm, st.linear))
        else:
            fine = result.paths[i].fine
            idx = list(result.vias[i])
            times = np.diff([0.0, *fine.t[idx]])
            if i in through:
                end_zone = st.zone_mm
            else:
                end_zone = None if st.zone_mm is None else PREDEFINED_ZONES["z1"].pzone_tcp
            via = PREDEFINED_SPEEDS[VIA_SPEED]
            named = bool(np.abs(fine.q[idx[-1]] - st.q).max() <= TARGET_ATOL_RAD)
            for k, (qk, tk) in enumerate(zip(fine.q[idx], times, strict=True)):
                last = k == len(idx) - 1
                zone = end_zone if last else VIA_ZONE_MM
                linear = st.linear and last and named
                out.append(("move", st.q if last and named else qk, via, float(tk), zone, linear))
    return out


def same_model(a: list[tuple[Any, ...]], b: list[tuple[Any, ...]], *, atol_rad: float = 1e-6) -> str | None:
    """None when two motion models agree (joints within ``atol_rad``, times within 1 µs), else where not."""
    if len(a) != len(b):
        return f"{len(a)} steps against {len(b)}"
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        if x[0] != y[0]:
            return f"step {k + 1}: a {x[0]} against a {y[0]}"
        if x[0] == "move":
            if np.abs(np.asarray(x[1]) - np.asarray(y[1])).max() > atol_rad:
                return f"step {k + 1}: joints differ"
            if x[2] != y[2] or x[5] != y[5]:
                return f"step {k + 1}: speed or interpolation differs"
            if (x[3] is None) != (y[3] is None) or (x[3] is not None and abs(x[3] - y[3]) > 1e-6):
                return f"step {k + 1}: \\T differs"
            if (x[4] is None) != (y[4] is None) or (x[4] is not None and abs(x[4] - y[4]) > 1e-9):
                return f"step {k + 1}: zone differs"
        elif x[0] == "wait" and abs(x[1] - y[1]) > 1e-6:
            return f"step {k + 1}: wait differs"
        elif x[0] == "fixed" and x[1] != y[1]:
            return f"step {k + 1}: instruction differs"
    return None


__all__ = [
    "WrittenModule",
    "WrittenMove",
    "motion_model",
    "planned_model",
    "restore_program",
    "same_model",
    "written_module",
]
