"""The controller's own levers for any RAPID task: the search of :mod:`joulepath.program._levers`,
written at the statements' source positions in every module (:mod:`joulepath.rapid.writer`).

The one-module writer of :mod:`joulepath.program._levers` edits a module the subset reader reads;
this one edits what the interpreter ran: a task of several modules, with records, loops and
routines, a scenario. Per move statement (its source position: every run of it in the cycle gets
the same) the levers are those of the one-module search: ``AccSet`` around the statement, its
speed data (or ``\\T``) and its zone, each open only where the statement can be edited in place:

* the statement stands alone on its lines (nothing but blanks and a comment beside it), so that
  an ``AccSet`` line can stand before it and the taught one be restored after it;
* the speed (zone) is written as a predefined name (``v500``, ``z10``), not a parameter or data
  of the program, and without ``\\V`` (``\\Z``); a ``fine`` point stays one;
* the move is not kept as taught (:attr:`joulepath.sim._steps.Step.kept`) and is a ``Move``
  instruction (not a process or search instruction).

The written task is read again by the interpreter (same scenario and routine), checked to give
the same targets, waits and the chosen settings, and run again by the controller emulation; its
executed cycle time and energy are what the result reports. Where it does not read back so, the
task is returned as taught. Idle waits are not spent here (the one-module search does it).
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput
from joulepath.program._levers import (
    _TOL_S,
    LeverResult,
    MoveLever,
    Setting,
    _Evaluator,
    _key,
    _num,
    _search,
    _Slot,
)
from joulepath.program._resolve import CycleSpec
from joulepath.rapid import nodes as n
from joulepath.rapid.interpreter import SPEEDS, ZONES, Motion
from joulepath.rapid.writer import (
    Edit,
    apply_edits,
    insert_after,
    insert_before,
    replace_argument,
    set_optional,
)
from joulepath.sim import ControllerConfig, stops_after

_SPEED_NAMES = {f"v{v}" for v in SPEEDS}
_ZONE_NAMES = {f"z{z}" for z in ZONES}
_LEVER_INSTRUCTIONS = {"movej", "movel", "movec", "moveabsj"}


@dataclass(frozen=True, slots=True)
class _Where:
    """A move statement's call and which positional arguments hold its speed and zone."""

    call: n.Call
    module: n.Module
    speed_arg: int | None
    zone_arg: int | None
    alone: bool


def statement_key(step: Any) -> tuple[int, str]:
    """The search's key of a move step of a task (:func:`joulepath.program._levers._key`)."""
    return _key(step)


def _alone(module: n.Module, call: n.Call) -> bool:
    text = module.text
    line_start = text.rfind("\n", 0, call.pos.start) + 1
    line_end = text.find("\n", call.pos.end)
    after = text[call.pos.end : len(text) if line_end < 0 else line_end].strip()
    return not text[line_start : call.pos.start].strip() and (not after or after.startswith("!"))


def _where(m: Motion, module: n.Module) -> _Where:
    positional = [a for a in m.stmt.args if a.kind == "pos"]
    speed = zone = None
    for k, a in enumerate(positional):
        if isinstance(a.value, n.Name):
            name = a.value.name.lower()
            if speed is None and name in _SPEED_NAMES:
                speed = k
            elif zone is None and (name in _ZONE_NAMES or name == "fine"):
                zone = k
    return _Where(m.stmt, module, speed, zone, _alone(module, m.stmt))


def _slots(spec: CycleSpec) -> tuple[list[_Slot], list[_Where]]:
    tc = spec.task
    assert tc is not None
    by: dict[tuple[str, int], list[int]] = {}
    for i, s in enumerate(spec.steps):
        if s.kind == "move" and isinstance(s.statement, Motion):
            by.setdefault((s.statement.pos.file, s.statement.pos.start), []).append(i)
    slots: list[_Slot] = []
    wheres: list[_Where] = []
    for (file, _), idx in by.items():
        steps = [spec.steps[i] for i in idx]
        first = steps[0]
        m = first.statement
        assert isinstance(m, Motion)
        module = tc.task.module_of(file)  # type: ignore[attr-defined]
        assert module is not None
        w = _where(m, module)
        args = {a.name.lower() for a in m.stmt.args if a.kind == "opt" and a.name}
        positional = [a for a in m.stmt.args if a.kind == "pos"]
        speed_name = zone_name = None
        if w.speed_arg is not None:
            value = positional[w.speed_arg].value
            speed_name = value.name if isinstance(value, n.Name) else None
        if w.zone_arg is not None:
            value = positional[w.zone_arg].value
            zone_name = value.name if isinstance(value, n.Name) else None
        open_: list[str] = []
        closed: list[str] = []
        if first.kept or any(s.kept for s in steps):
            closed.append("acc, speed, zone: the move is kept as taught (known only at run time)")
        elif m.instruction.lower() not in _LEVER_INSTRUCTIONS:
            closed.append(f"acc, speed, zone: {m.instruction} is not a Move instruction")
        else:
            if not w.alone:
                closed.append("acc: another statement stands on its line")
            elif len({(s.acc_pct, s.ramp_pct) for s in steps}) != 1:
                closed.append("acc: its runs start under different AccSet")
            else:
                open_.append("acc")
            if speed_name is None or "v" in args:
                closed.append("speed: written as data of the program, a parameter or with \\V")
            else:
                open_.append("speed")
            if first.zone_mm is None:
                closed.append("zone: a stop point (fine) stays one")
            elif any(stops_after(spec, i) for i in idx):
                closed.append("zone: the robot stops there (a wait or the cycle's end follows)")
            elif zone_name is None or "z" in args:
                closed.append("zone: written as data of the program, a parameter or with \\Z")
            else:
                open_.append("zone")
        taught = Setting(first.acc_pct, first.ramp_pct, speed_name or "", m.time_s, zone_name or "")
        key = statement_key(first)
        slots.append(
            _Slot(
                key[0],
                first.label,
                key[1],
                first.linear,
                tuple(idx),
                None,
                taught,
                tuple(open_),
                tuple(closed),
            )
        )
        wheres.append(w)
    return slots, wheres


def _edits(slots: list[_Slot], wheres: list[_Where], chosen: tuple[Setting, ...]) -> list[Edit]:
    out: list[Edit] = []
    for slot, w, c in zip(slots, wheres, chosen, strict=True):
        t = slot.taught
        if c == t:
            continue
        if (c.acc_pct, c.ramp_pct) != (t.acc_pct, t.ramp_pct):
            out.append(insert_before(w.module, w.call, f"AccSet {_num(c.acc_pct)}, {_num(c.ramp_pct)};"))
            out.append(insert_after(w.module, w.call, f"AccSet {_num(t.acc_pct)}, {_num(t.ramp_pct)};"))
        if c.speed != t.speed and w.speed_arg is not None:
            out.append(replace_argument(w.call, w.speed_arg, c.speed))
        if c.time_s != t.time_s and w.speed_arg is not None:
            e = set_optional(w.module, w.call, "T", None if c.time_s is None else _num(c.time_s), w.speed_arg)
            if e is not None:
                out.append(e)
        if c.zone != t.zone and w.zone_arg is not None:
            out.append(replace_argument(w.call, w.zone_arg, c.zone))
    return out


def _read_back(
    spec: CycleSpec, robot: Robot, texts: dict[str, bytes], io: Any, routine: str | None
) -> CycleSpec:
    """The written task, each module in a private folder under its own name, run by the interpreter."""
    from joulepath.program._resolve import read_cycle_program

    tc = spec.task
    assert tc is not None
    folder = Path(tempfile.mkdtemp(prefix="joulepath-levers-"))
    paths = []
    for k, m in enumerate(tc.task.modules):  # type: ignore[attr-defined]
        sub = folder / f"m{k}"
        sub.mkdir()
        dest = sub / Path(m.path).name
        dest.write_bytes(texts[m.path])
        paths.append(dest)
    again, _ = read_cycle_program(paths, robot, io=io, routine=routine)
    return again


def _differs(
    spec: CycleSpec, again: CycleSpec, slots: list[_Slot], chosen: tuple[Setting, ...]
) -> str | None:
    def without_accset(steps: tuple[Any, ...]) -> list[Any]:
        return [st for st in steps if not (st.kind == "fixed" and st.label.lower() == "accset")]

    ran, read = without_accset(spec.steps), without_accset(again.steps)
    if len(read) != len(ran):
        return f"{len(read)} steps read back against {len(ran)}"
    want: dict[int, Setting] = {}  # by the step's identity
    for slot, setting in zip(slots, chosen, strict=True):
        for i in slot.steps:
            want[id(spec.steps[i])] = setting
    for i, (a, b) in enumerate(zip(ran, read, strict=True)):
        if a.kind != b.kind:
            return f"step {i + 1}: a {b.kind} read back where a {a.kind} ran"
        if a.kind == "wait" and abs(a.seconds - b.seconds) > 1e-9:
            return f"step {i + 1}: the wait reads back as {b.seconds} s"
        if a.kind != "move":
            continue
        assert a.q is not None and b.q is not None
        if np.abs(a.q - b.q).max() > 1e-9:
            return f"step {i + 1}: the target reads back elsewhere"
        c = want.get(id(a))
        if c is not None and (b.acc_pct, b.ramp_pct) != (c.acc_pct, c.ramp_pct):
            return f"step {i + 1}: AccSet reads back as {b.acc_pct:g}, {b.ramp_pct:g}"
        if c is not None and (b.time_s != c.time_s):
            return f"step {i + 1}: \\T reads back as {b.time_s}"
    return None


def task_levers(
    spec: CycleSpec,
    robot: Robot,
    *,
    energy: str,
    io: Any = None,
    routine: str | None = None,
    max_evaluations: int = 1500,
    pairs: int = 8,
    config: ControllerConfig | None = None,
    max_seconds: float | None = None,
) -> LeverResult:
    """Search the controller's levers of a RAPID task's cycle and write them into its modules.

    Parameters
    ----------
    spec : CycleSpec
        The cycle of a task (:func:`joulepath.program.read_cycle_program`, any number of modules).
    robot : Robot
        The robot it was read on.
    energy : str
        The energy measure minimised.
    io, routine
        The scenario and routine the task was read with (the written task is read again with them).
    max_evaluations, pairs, config, max_seconds
        As :func:`joulepath.program.levers_module`.

    Returns
    -------
    LeverResult
        With ``written_files``: every module's bytes (unchanged ones as read).
    """
    start = time.perf_counter()
    if spec.task is None:
        raise InvalidInput(f"{spec.source}: the controller's levers are written into a RAPID task")
    config = config or ControllerConfig()
    slots, wheres = _slots(spec)
    ev = _Evaluator(spec, slots, energy, config, by_runs=True)
    taught_state = tuple(s.taught for s in slots)
    plan0, t0, _ = ev(taught_state)
    e0, lab0 = ev.energies(plan0)
    ev.deadline = None if max_seconds is None else start + max_seconds
    chosen = _search(ev, slots, t0, max_evaluations, pairs)
    plan_s, t_search, _ = ev(chosen)
    e_search = ev.whole_energy(plan_s)  # reported as the check takes it
    tc = spec.task
    texts = apply_edits(tc.task, _edits(slots, wheres, chosen))  # type: ignore[attr-defined]
    differs: str | None = None
    t_exec, e_exec, lab_exec = t0, e0, lab0
    if chosen != taught_state:
        try:
            again = _read_back(spec, robot, texts, io, routine)
            differs = _differs(spec, again, slots, chosen)
        except InvalidInput as err:
            differs, again = f"it cannot be read: {err}", None
        if differs is None and again is not None:
            plan_x, t_exec, _ = ev.run(replace(spec, steps=again.steps))
            e_exec, lab_exec = ev.energies(plan_x)
            if t_exec > t0 + _TOL_S or e_exec > e0:
                differs = f"run again it takes {t_exec:.3f} s and {e_exec:.3f} J"
        if differs is not None:
            chosen, t_exec, e_exec, lab_exec = taught_state, t0, e0, lab0
            texts = apply_edits(tc.task, ())  # type: ignore[attr-defined]
    moves = tuple(
        MoveLever(
            spec.steps[s.steps[0]].line,
            f"{spec.steps[s.steps[0]].file}: {s.label}",
            s.taught,
            c,
            s.open,
            s.closed,
        )
        for s, c in zip(slots, chosen, strict=True)
    )
    return LeverResult(
        source=spec.source,
        energy_measure=energy,
        taught_cycle_s=t0,
        default_energy_J=e0,
        cycle_s=t_exec,
        energy_J=e_exec,
        default_lab_J=lab0,
        energy_lab_J=lab_exec,
        searched_cycle_s=t_search,
        searched_energy_J=e_search,
        moves=moves,
        written_text="",
        encoding="utf-8",
        reads_back=differs,
        n_evaluations=len(ev.memo),  # the plans made (ev.n is set past the budget when time runs out)
        wall_s=time.perf_counter() - start,
        written_files=tuple(sorted(texts.items())),
    )
