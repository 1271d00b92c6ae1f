"""The verified result of one allocation of a cycle's time: per-move outcomes, the units' pieces,
their via points, the figures (:class:`~joulepath.program._cycle_model.CycleResult`), from the motion
and the energies the orchestrator (:mod:`joulepath.program._cycle`) measured on it."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from joulepath.optimize import MeasureSummary
from joulepath.program._cycle_model import (
    STEP,
    Allocation,
    Breakdown,
    CycleMotion,
    CycleResult,
    MoveOutcome,
    Solved,
)
from joulepath.program._cycle_motion import split_chain, to_stop
from joulepath.program._cycle_solve import UnitSolver
from joulepath.program._cycle_units import CycleUnits
from joulepath.program._resolve import Step
from joulepath.sim import PlannedMove, via_layout
from joulepath.trajectory import Trajectory


@dataclass(frozen=True, slots=True, eq=False)
class CycleRun:
    """One allocation's motion and what was measured on it: the pieces re-timed along their
    segment's path (by step index), each move's physics and lab J on the motion (``spent``), every
    measure's energies of the whole cycle (``energies``; ``unavailable``: why not), and the default
    cycle's per-move (duration s, physics J, lab J) and motion."""

    motion: CycleMotion
    retimed: dict[int, Solved]
    spent: dict[int, tuple[float, float]]
    energies: tuple[MeasureSummary, ...]
    unavailable: dict[str, str]
    default: dict[int, tuple[float, float, float]]
    default_planned: Trajectory


def cycle_result(
    units: CycleUnits,
    solver: UnitSolver,
    final: Allocation,
    table: dict[int, list[Solved]],
    breakdown: Breakdown,
    run: CycleRun,
    *,
    target: float,
    shortest: float,
    t_start: float,
) -> CycleResult:
    """The verified result of one allocation ``final`` of the time ``table`` on its motion ``run``:
    per-move outcomes, pieces, via points and the figures."""
    spec, settings, plan = units.spec, units.settings, units.plan
    motion, retimed, spent = run.motion, run.retimed, run.spent
    e0 = breakdown.default_J
    e0_lab = sum(v[2] for v in run.default.values())
    taught_units = [i for i, s in final.choice.items() if s.taught]
    pieces, notes, ok = _unit_pieces(units, solver, final, table, retimed)
    _retimed_pieces(units, retimed, pieces, notes)
    vias = _via_points(units, final, pieces)
    outcomes, paths = _outcomes(units, run.default, spent, pieces, notes, vias)
    waits = tuple(
        (spec.steps[i].line, sec, 0.0 if settings.use_waits and spec.steps[i].idle else sec)
        for i, _, sec in plan.waits
    )
    result = CycleResult(
        moves=tuple(outcomes),
        default_cycle_s=plan.cycle_time,
        target_cycle_s=target,
        optimized_cycle_s=motion.cycle_time,
        default_energy_J=e0,
        optimized_energy_J=float(sum(v[0] for v in spent.values())),
        default_lab_J=e0_lab,
        optimized_lab_J=float(sum(v[1] for v in spent.values())),
        breakdown=breakdown,
        waits=waits,
        fixed_lines=spec.fixed_lines,
        limits_ok=ok,
        corridor_mm=settings.corridor_mm,
        cell=None
        if settings.cell is None
        else {"source": settings.cell.source, "margin_mm": 1000 * settings.cell.margin},
        shortest_cycle_s=shortest,
        wall_s=time.perf_counter() - t_start,
        n_solves=solver.n_solves,
        paths=paths,
        spec=spec,
        chains={i: c for i, c in units.chains.items() if len(c) > 1 and i in pieces},
        vias=vias,
        planned=motion.trajectory,
        taught_units=tuple(spec.steps[i].line for i in taught_units),
        long_units=tuple(spec.steps[i].line for i in units.long_units),
        timed_out=solver.timed_out,
        open_ends=frozenset(
            units.chains[i][-1]
            for i, s in final.choice.items()
            if not s.taught and i in units.within and spec.steps[units.chains[i][-1]].zone_mm is not None
        ),
        zone_miss_mm=max(
            [solver.zone_miss_mm(i, s) for i, s in final.choice.items() if not s.taught], default=0.0
        ),
        energy_measure=settings.energy,
        energies=run.energies,
        energies_unavailable=run.unavailable,
        path_retimed=tuple(sorted(retimed)),
        optimizable=tuple(units.optimizable),
        default_planned=run.default_planned,
    )
    return result


def _unit_pieces(
    units: CycleUnits,
    solver: UnitSolver,
    final: Allocation,
    table: dict[int, list[Solved]],
    retimed: dict[int, Solved],
) -> tuple[dict[int, Solved], dict[int, str], bool]:
    """The chosen units' pieces, one per move (as re-timed along their segment's path where they
    were, ``retimed``), each move's note (the units kept as taught too), and whether every chosen
    entry is usable."""
    pieces: dict[int, Solved] = {}
    notes: dict[int, str] = {}
    ok = True
    for i, whole in final.choice.items():
        members = units.chains[i]
        if whole.taught:
            for j in units.segment_of[i].moves:
                notes[j] = (
                    "kept as taught: no reshaped motion of this segment saves energy in the time it is given"
                    if len(table[i]) > 1
                    else "kept as taught: the optimizer's shortest motion of this segment is longer than "
                    "the taught one" + (" (or --max-time was reached first)" if solver.timed_out else "")
                )
            continue
        ok = ok and whole.usable
        robot = units.robot(units.by_index[i])
        plant = solver.plant(robot)
        passes = tuple(t for t, _ in solver.passes(i, whole))
        pieces.update(split_chain(whole, members, passes, robot, plant, units.settings.energy))
        last = members[-1]
        if i in units.within and units.by_index[last].stops:
            m = units.by_index[last]
            pieces[last] = to_stop(
                units.plan,
                units.segment_of[i],
                m,
                pieces[last],
                solver.plant(units.robot(m)),
                units.settings.energy,
            )
        for j in members:  # the unit's pieces as re-timed along their segment's path
            if j in retimed:
                pieces[j] = replace(
                    retimed[j], corridor_dev_mm=pieces[j].corridor_dev_mm, clearance_mm=pieces[j].clearance_mm
                )
        for j in members:
            notes[j] = _unit_note(units, j, members)
    return pieces, notes, ok


def _unit_note(units: CycleUnits, j: int, members: tuple[int, ...]) -> str:
    """What was done to move ``j`` of the unit of ``members``."""
    zones = any(units.zone_mm(k) > 0 for k in members[:-1])
    return (
        "MoveL re-timed along its line (its speeddata's TCP speed a bound)"
        if j in units.linear
        else "reshaped and re-timed"
        if len(members) == 1
        else "reshaped and re-timed in one fly-by chain with lines "
        + ", ".join(str(units.by_index[k].step.line) for k in members)
        + (
            " (passes each fly-by target within its zone, without stopping)"
            if zones
            else " (passes the zone targets exactly, without stopping)"
        )
    )


def _retimed_pieces(
    units: CycleUnits, retimed: dict[int, Solved], pieces: dict[int, Solved], notes: dict[int, str]
) -> None:
    """The moves of the segments re-timed along their path into ``pieces`` and ``notes`` (a unit's
    move, already there, only noted)."""
    for j, piece in retimed.items():
        if j in notes:
            notes[j] += "; then re-timed along its segment's path with the segment's MoveL"
            continue
        pieces[j] = piece
        notes[j] = (
            "MoveL re-timed along its segment's path: its line and tool orientation kept, its speeddata "
            "a bound"
            if units.spec.steps[j].linear
            else "its taught path kept, re-timed along its segment's path with the segment's MoveL"
        )


def _via_points(
    units: CycleUnits, final: Allocation, pieces: dict[int, Solved]
) -> dict[int, tuple[int, ...]]:
    """Per optimized move, its via points (indices into its piece's ``fine``), as the controller's
    zones round them (:func:`joulepath.sim.via_layout`)."""
    spec, settings = units.spec, units.settings
    vias: dict[int, tuple[int, ...]] = {}
    for i, whole in final.choice.items():
        if whole.taught:
            continue
        members = units.chains[i]
        step = spec.steps[i]
        assert step.robot is not None and step.tcp is not None
        legs = [pieces[j].fine for j in members]
        placed = via_layout(
            step.robot,
            step.tcp,
            legs,
            spacing=settings.via_every * STEP,
            config=settings.controller,
            target_zones=[*(spec.steps[j].zone_mm for j in members[:-1]), None],
        )
        vias.update({j: tuple(idx) for j, idx in zip(members, placed, strict=True)})
    return vias


def _outcomes(
    units: CycleUnits,
    default: dict[int, tuple[float, float, float]],
    spent: dict[int, tuple[float, float]],
    pieces: dict[int, Solved],
    notes: dict[int, str],
    vias: dict[int, tuple[int, ...]],
) -> tuple[list[MoveOutcome], dict[int, Solved]]:
    """Each move's outcome, default against optimized (``spent``: its energies on the cycle's motion),
    and the optimized moves' pieces by step index."""
    outcomes: list[MoveOutcome] = []
    paths: dict[int, Solved] = {}
    for m in units.plan.moves:
        d_T, d_e, d_lab = default[m.index]
        if m.index in pieces:
            s = pieces[m.index]
            paths[m.index] = s
            n_via, dev_q, dev_mm = (
                via_deviation(m.step, s, vias[m.index]) if m.index in vias else (0, 0.0, 0.0)
            )
            outcomes.append(
                MoveOutcome(
                    m.step.line,
                    m.step.label,
                    True,
                    notes[m.index],
                    d_T,
                    s.duration,
                    d_e,
                    spent[m.index][0],
                    d_lab,
                    spent[m.index][1],
                    s.limits_ok,
                    s.limit_excess,
                    n_via,
                    dev_q,
                    dev_mm,
                    s.corridor_dev_mm,
                    units.default_clearance.get(m.index),
                    s.clearance_mm,
                )
            )
            continue
        note = notes[m.index] if m.index in notes else _kept_note(units, m)
        outcomes.append(
            MoveOutcome(
                m.step.line,
                m.step.label,
                False,
                note,
                d_T,
                m.profile.duration,
                d_e,
                spent[m.index][0],
                d_lab,
                spent[m.index][1],
                True,
                (),
                0,
                0.0,
                0.0,
                0.0,
                units.default_clearance.get(m.index),
                units.default_clearance.get(m.index),
            )
        )
    return outcomes, paths


def _kept_note(units: CycleUnits, m: PlannedMove) -> str:
    """Why move ``m``, outside every unit, runs as taught."""
    if m.profile.duration == 0:
        return "no motion"
    if units.default_clearance.get(m.index, np.inf) < 0.0:
        return "the default move comes closer to the cell than the margin: reported, not optimized"
    if m.step.kept:
        return "kept as taught: " + m.step.kept[0]
    if m.step.repeated:
        return "occurs more than once in the cycle: kept as taught"
    if any(units.by_index[j].step.linear for j in units.segment_with(m.index).moves):
        return (
            "MoveL: kept as taught (straight line, controller timing)"
            if m.step.linear
            else "kept as taught: blended with a MoveL (the segment runs as the controller runs it)"
        )
    return "kept as taught: part of a fly-by chain (--stop-at-targets)"


def via_deviation(step: Step, solved: Solved, idx: Sequence[int]) -> tuple[int, float, float]:
    """Via points (indices into ``solved.fine``), and the largest joint (deg) and TCP (mm) distance
    of their joint-linear interpolation from the optimized path (what the controller's
    interpolation between via points departs from it, before its zones round the corners)."""
    assert step.robot is not None and step.tcp is not None
    fine = solved.fine
    at = [0, *idx]
    tv, qv = fine.t[at], fine.q[at]
    lin = np.column_stack([np.interp(fine.t, tv, qv[:, j]) for j in range(qv.shape[1])])
    dev_q = float(np.degrees(np.abs(lin - fine.q).max()))
    a = step.robot.fk(lin)
    b = step.robot.fk(fine.q)
    pa = a.position_m + np.einsum("kij,j->ki", a.rotation, step.tcp[:3, 3])
    pb = b.position_m + np.einsum("kij,j->ki", b.rotation, step.tcp[:3, 3])
    return len(idx), dev_q, float(1000 * np.linalg.norm(pa - pb, axis=1).max())
