"""What ``joulepath cycle`` writes: the optimized module, cycle.json, the trade-off (CSV + plot)."""

from __future__ import annotations

import json
import os
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from joulepath import __version__
from joulepath._io import (
    atomic_write_bytes,
    atomic_write_text,
    finite_json,
    make_folder,
    remove_output,
    save_figure,
)
from joulepath.errors import LimitViolation
from joulepath.program._cell import Cell, clearance
from joulepath.program._cycle_model import LAB_MEASURE, CycleResult, ParetoPoint
from joulepath.program._model import RapidError
from joulepath.program._rapid_write import (
    WrittenModule,
    motion_model,
    planned_model,
    same_model,
    written_module,
)

CYCLE_FILES = (
    "cycle.json",
    "optimized_task",
    "optimized.mod",
    "pareto.csv",
    "pareto.png",
    "optimized_cycle.csv",
    "cycle_path.csv",
    "egm.mod",
    "EGM_SETUP.md",
)
"""Files ``joulepath cycle`` may write in its run folder (``optimized.mod`` only within every limit;
``egm.mod`` and ``EGM_SETUP.md`` with ``--export egm``)."""

ASSUMPTIONS = (
    "energy: sum over 2.5 ms samples of the energy measure's power times dt (thesis: |tau * qd| summed over "
    "joints; see energies for every measure and the stage it is taken at), physics = nominal rigid body with "
    "the tool's load and NOMINAL_FRICTION; lab = the emulated lab robot's drive torque on the same motion",
    "default: the emulated controller (jerk-limited profile, speeddata, joint limits, accel = vmax/0.25 s, "
    "zones blended by superposition, 48 ms dwell at stop points; a move before WaitTime stops)",
    "units: the default cycle is cut where the robot stands still; a segment of MoveJ/MoveAbsJ only (each "
    "occurring once) is one unit, optimized by the single-move gradient optimizer as one move through its "
    "fly-by targets (each passed within its zone: the zone radius reduced to half of either move's TCP "
    "length, as a joint box; or exactly with --exact-targets), with its taught motion kept as a candidate "
    "at its taught duration, so the taught cycle time is always reachable (at worst 0 % saved); written as "
    "MoveAbsJ via points with \\T in z200 zones in an added PROC jp_opt_<proc>_<n> per move line, called "
    "where the move stood (the rest of the program as written); the last point of a unit keeps its stop "
    "(fine), and where the plan ends at the target it is the program's own move to its named target",
    "segments with a MoveL, and moves that occur more than once: run as taught (the controller's own "
    "blends and timing, as emulated)",
    "waits are process time; only waits declared idle (`! joulepath: idle` or --idle-wait LINE) are "
    "spent on the moves with --use-waits",
    "corridor: tool0 (the flange) stays within corridor_mm of the joint-interpolated taught move at every "
    "25 ms sample of an optimized move (corridor_dev_mm per move; for a fly-by chain, of the smoothest path "
    "through its targets at the same times, and the value is the chain's)",
    "speeddata of an optimized move is not a bound: its TCP may move faster than programmed (joint speed, "
    "acceleration and effort limits hold)",
    "instructions kept verbatim (I/O, assignments, ...): their run time is not modelled (treated as fixed)",
)


def optimized_module(result: CycleResult, check: dict[str, Any] | None = None) -> str:
    """The module that keeps the program, its optimized moves calling added procedures
    (:func:`joulepath.program._rapid_write.written_module`); refused outside a limit.

    The header states the saving of the module as the controller emulation runs it
    (``check``, from :func:`check_written`), else that of the plan, named as such.
    """
    return written_rapid(result, check).text


def written_rapid(result: CycleResult, check: dict[str, Any] | None = None) -> WrittenModule:
    """:func:`optimized_module` with what it holds (which lines, shared or per run, re-teaching)."""
    spec = result.spec
    assert spec.module is not None
    if not result.limits_ok:
        bad = "; ".join(e for m in result.moves for e in m.limit_excess)
        raise LimitViolation(
            f"the optimized cycle breaks a limit or the cell's margin ({bad or 'clearance'}); "
            "the program is not written"
        )
    if check is not None:
        e = check["emulated_energy_J"]
        header = [
            f"! Optimized by joulepath {__version__} for energy: run by the controller emulation this module "
            f"takes {check['emulated_cycle_s']:.3f} s per cycle (taught {result.default_cycle_s:.3f} s) and "
            f"{e:.2f} J on physics against the taught {result.default_energy_J:.2f} J "
            f"({100.0 * (1.0 - e / result.default_energy_J):.1f} % saved). See cycle.json.",
        ]
    else:
        header = [
            f"! Optimized by joulepath {__version__} for energy, planned at cycle time "
            f"{result.optimized_cycle_s:.3f} s (taught {result.default_cycle_s:.3f} s): physics "
            f"{result.default_energy_J:.2f} -> {result.optimized_energy_J:.2f} J planned "
            f"({result.saved_pct:.1f} %). See cycle.json.",
        ]
    header.append(
        "! The program is kept as written; each optimized move calls jp_opt_<proc>_<n> (at the module's "
        "end). Re-teaching a target: see cycle.json rapid_structure.reteach, then optimize again."
    )
    return written_module(result, header)


CHECK_TOLERANCES = {"slower_than_taught_s": 0.001, "path_mm": 5.0, "saved_at_least_pct": 0.1}
"""What the written module, run by the controller emulation, must keep: its cycle never longer than
the target (the taught) cycle time (to 1 ms), its TCP path within 5 mm of the plan's, and it saves
at least 0.1 % of the taught program's energy. It may run faster than planned."""


def check_written(result: CycleResult, text: str, cell: Cell | None = None) -> dict[str, Any]:
    """The written module run by the controller emulation against the planned cycle.

    Cycle time, energy on physics (same model and 2.5 ms grid as the plan) and the TCP
    path: the largest distance from an emulated TCP sample to the planned TCP samples
    and back. ``within_tolerances`` compares them with :data:`CHECK_TOLERANCES`.
    """
    from scipy.spatial import cKDTree

    from joulepath.program._cycle_model import trajectory_energy
    from joulepath.program._task import as_sequence, read_written
    from joulepath.sim import FINE_DT, ControllerConfig, evaluate_cycle, make_plant, plan_cycle
    from joulepath.sim import tcp_pose as _tcp

    spec = result.spec
    config = ControllerConfig()
    written = read_written(text, f"{spec.source} (optimized)", spec.robot)
    plan = plan_cycle(as_sequence(written), config)
    n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
    traj = evaluate_cycle(plan, np.linspace(0.0, plan.cycle_time, n))
    first = plan.moves[0].step
    assert first.robot is not None and first.tcp is not None
    energy, energy_lab = trajectory_energy(
        first.robot, make_plant("lab", first.robot), traj, result.energy_measure
    )
    assert result.planned is not None
    p_plan, _ = _tcp(first.robot, result.planned.q, first.tcp)
    p_emu, _ = _tcp(first.robot, traj.q, first.tcp)
    dev = 1000.0 * max(cKDTree(p_plan).query(p_emu)[0].max(), cKDTree(p_emu).query(p_plan)[0].max())
    clear_mm = None
    if cell is not None:  # the written program's own motion against the cell, on the same grid
        clear_mm = 1000.0 * (clearance(cell, first.robot, traj.q, first.tcp).distance - cell.margin)
    cycle_pct = 100.0 * (plan.cycle_time / result.optimized_cycle_s - 1.0)
    energy_pct = 100.0 * (energy / result.optimized_energy_J - 1.0)
    tol = CHECK_TOLERANCES
    ok = (
        plan.cycle_time <= result.target_cycle_s + tol["slower_than_taught_s"]
        and energy <= result.default_energy_J * (1.0 - tol["saved_at_least_pct"] / 100.0)
        and dev <= tol["path_mm"]
    )
    return {
        "emulated_cycle_s": plan.cycle_time,
        "planned_cycle_s": result.optimized_cycle_s,
        "cycle_diff_pct": cycle_pct,
        "emulated_energy_J": energy,
        "planned_energy_J": result.optimized_energy_J,
        "energy_diff_pct": energy_pct,
        "emulated_energy_lab_J": energy_lab,
        "target_cycle_s": result.target_cycle_s,
        "default_energy_J": result.default_energy_J,
        "tcp_path_deviation_mm": dev,
        "cell_clearance_mm": clear_mm,
        "tolerances": dict(tol),
        "within_tolerances": bool(ok),
    }


def _unfaithful_reason(check: dict[str, Any]) -> str:
    """Why a module the controller emulation does not run as planned is not written (one line)."""
    tol = CHECK_TOLERANCES
    cyc, target = check["emulated_cycle_s"], check["target_cycle_s"]
    e, e0, dev = check["emulated_energy_J"], check["default_energy_J"], check["tcp_path_deviation_mm"]
    why = []
    if cyc > target + tol["slower_than_taught_s"]:
        why.append(f"takes {cyc:.3f} s per cycle, longer than the taught {target:.3f} s")
    if e > e0 * (1.0 - tol["saved_at_least_pct"] / 100.0):
        why.append(
            f"spends {e:.2f} J against the taught {e0:.2f} J "
            f"(at least {tol['saved_at_least_pct']:g} % less asked)"
        )
    if dev > tol["path_mm"]:
        why.append(f"leaves the planned TCP path by {dev:.1f} mm (at most {tol['path_mm']:g} mm)")
    return (
        "run by the controller emulation, the module's via points do not keep the plan: it "
        + "; it ".join(why)
        + "; not written. Stream the planned cycle instead (--export egm: egm.mod and cycle_path.csv for "
        "`joulepath stream RUN --repeat K`), or give a gentler plan (--accel-time, with a longer "
        "--cycle-time); --write-anyway writes the module with this warning"
    )


def _mark_unfaithful(text: str, check: dict[str, Any]) -> str:
    """The module with a warning under its header: what the controller emulation measured instead."""
    cyc, plan_cyc = check["emulated_cycle_s"], check["planned_cycle_s"]
    e, plan_e = check["emulated_energy_J"], check["planned_energy_J"]
    warning = (
        f"! WARNING: run by joulepath's controller emulation this module takes {cyc:.3f} s per cycle "
        f"(planned {plan_cyc:.3f} s) and {e:.2f} J (planned {plan_e:.2f} J): the via points do not "
        "reproduce the plan. See cycle.json."
    )
    lines = text.splitlines(keepends=True)
    at = next((k for k, ln in enumerate(lines) if "! Optimized by joulepath" in ln), 0)
    indent = lines[at][: len(lines[at]) - len(lines[at].lstrip())]
    lines.insert(at + 1, indent + warning + "\n")
    return "".join(lines)


def emulated_cycle_time(result: CycleResult, text: str) -> float:
    """The written module's cycle time as the controller emulation runs it."""
    return float(check_written(result, text)["emulated_cycle_s"])


def _energy_figures(result: CycleResult, check: dict[str, Any] | None) -> dict[str, Any]:
    """The headline keys and ``energy_figures`` of ``cycle.json``: each stage on ``energy_measure``.

    The cycle's motion (no standby) at every stage: planned on the model, the same motion on
    the emulated lab robot, and the written module as the controller emulation runs it.
    """
    from joulepath.optimize import CYCLE_DEPRECATED, EnergyPair, figures_json, headline_keys, lab_pair

    m = result.energy_measure
    pairs = [
        EnergyPair(
            stage="planned",
            measure=m,
            on=f"the planning model of {result.spec.robot.name}, the cycle's motion (no standby)",
            default_J=result.default_energy_J,
            optimized_J=result.optimized_energy_J,
        ),
        lab_pair(
            m, result.energies, on="the emulated lab robot, the cycle's motion (no standby)", standby=False
        ),
    ]
    if check is not None:
        pairs.append(
            EnergyPair(
                stage="executed",
                measure=m,
                on="the written module (and the taught program) run by the controller emulation, on the "
                "planning model",
                default_J=result.default_energy_J,
                optimized_J=check["emulated_energy_J"],
                note="the emulated module on the lab robot is on mechanical only (executed_energy_lab_J)",
            )
        )
    return {
        **finite_json(headline_keys(pairs)),
        "energy_figures": finite_json(figures_json(m, pairs)),
        "deprecated_keys": dict(CYCLE_DEPRECATED),
    }


def cycle_json(
    result: CycleResult,
    pareto: list[ParetoPoint] | None,
    rapid: str | None,
    refused: str | None,
    check: dict[str, Any] | None = None,
) -> dict[str, Any]:
    b = result.breakdown
    executed: dict[str, Any] = {
        "executed_cycle_s": None,
        "executed_energy_J": None,
        "executed_saved_pct": None,
        "executed_energy_lab_J": None,
        "executed_saved_lab_pct": None,
        "executed_note": "the written optimized.mod as the controller emulation runs it (its cycle time and "
        "energy per cycle on physics and the lab robot), against the taught program run by the same "
        "emulation (energy_default_J, energy_default_lab_J); null when no module was written",
    }
    if check is not None and rapid is not None:
        e, lab = check["emulated_energy_J"], check["emulated_energy_lab_J"]
        e0, lab0 = result.default_energy_J, result.default_lab_J
        executed.update(
            executed_cycle_s=check["emulated_cycle_s"],
            executed_energy_J=e,
            executed_saved_pct=100.0 * (1.0 - e / e0) if e0 else None,
            executed_energy_lab_J=lab,
            executed_saved_lab_pct=100.0 * (1.0 - lab / lab0) if lab0 else None,
        )
    return {
        **executed,
        **_energy_figures(result, check if rapid is not None else None),
        "source": result.spec.source,
        "robot": result.spec.robot.name,
        "choices": list(result.spec.choices),
        "read_notes": list(result.spec.choices),
        "kept_moves": [{"move": m, "why": why} for m, why in result.spec.kept],
        "assumed": [a.as_json() for a in result.spec.assumed],
        "assumed_note": "names the task uses and declares nowhere in what was given (a module, the I/O "
        "configuration or an option not given), with what was taken for each; the saving is stated on them",
        "open_to_optimization_pct": _open_share(result),
        "open_to_optimization_note": "share of the taught cycle's motion energy (energy_default_J) in moves "
        "the optimizer may change: every move but those kept as taught (kept_moves: their target, speed, "
        "zone or branch is known only at run time, a process instruction, \\Conc)",
        "taught_units": list(result.taught_units),
        "long_units": list(result.long_units),
        "long_units_note": "first lines of the units (a move, or moves joined by zones) longer than the "
        "move_s limit (JOULEPATH_MAX_MOVE_S): kept as taught, not optimized",
        "timed_out": result.timed_out,
        "zone_miss_mm": result.zone_miss_mm,
        "default_cycle_s": result.default_cycle_s,
        "target_cycle_s": result.target_cycle_s,
        "optimized_cycle_s": result.optimized_cycle_s,
        "written_program_emulated_cycle_s": None if check is None else check["emulated_cycle_s"],
        "written_program_check": check,
        "written_program_matches_plan": None if check is None else check["within_tolerances"],
        "written_program_note": "optimized_cycle_s and energy_optimized_J are those of the planned "
        "(optimized) motion; written_program_check is the written module run by the controller emulation "
        "(timed fly-by via points, see joulepath.sim._timing); when written_program_matches_plan is "
        "false the written program does not reproduce the plan within the tolerances and the savings "
        "claimed are not those of the written program",
        "shortest_cycle_s": result.shortest_cycle_s,
        "energy_default_J": result.default_energy_J,
        "energy_optimized_J": result.optimized_energy_J,
        "saved_pct": result.saved_pct,
        "energy_default_lab_J": result.default_lab_J,
        "energy_optimized_lab_J": result.optimized_lab_J,
        "saved_lab_pct": result.saved_lab_pct,
        "energy_measure": result.energy_measure,
        "energy_lab_measure": LAB_MEASURE,
        "energies": {m.measure: asdict(m) for m in result.energies},
        "energies_unavailable": dict(result.energies_unavailable),
        "energies_note": "energy_*_J: the cycle's motion energy on energy_measure (no standby), the "
        "quantity optimized; energies: every measure of the whole cycle (stage: where it is taken), "
        "standby over each cycle's time included where the measure counts it (the meter-level figure); "
        "lab figures: the emulated lab plant measured alike",
        "breakdown": {
            "default_J": b.default_J,
            "shapes_at_default_proportions_J": b.shape_J,
            "reallocated_durations_J": b.allocation_J,
            "waits_spent_J": b.waits_J,
            "segments_retimed_along_their_path_J": b.path_retimed_J,
            "saved_by_shape_pct": b.by_shape_pct,
            "saved_by_time_allocation_pct": b.by_allocation_pct,
            "saved_by_waits_pct": b.by_waits_pct,
            "saved_by_path_retiming_pct": b.by_path_retiming_pct,
        },
        "limits_ok": result.limits_ok,
        "corridor_mm": result.corridor_mm,
        "cell": result.cell,
        "cell_note": None
        if result.cell is None
        else "clearance_mm per move = smallest distance beyond the margin between the robot's capsules "
        "(lower arm, upper arm, wrist, tool) and the obstacles, coal distance queries on the 2.5 ms grid; "
        "an optimized move too close is solved again in a tighter corridor (down to 1/8), else not used",
        "moves": [asdict(m) for m in result.moves],
        "waits": [{"line": w[0], "default_s": w[1], "optimized_s": w[2]} for w in result.waits],
        "kept_verbatim_lines": list(result.fixed_lines),
        "kept_verbatim_note": "run time not modelled (treated as fixed); not part of the cycle times above",
        "assumptions": list(ASSUMPTIONS),
        "solves": result.n_solves,
        "wall_s": result.wall_s,
        "pareto": None if pareto is None else [asdict(p) for p in pareto],
        "rapid": rapid,
        "rapid_refused": refused,
    }


def _open_share(result: CycleResult) -> float:
    """% of the taught cycle's motion energy in moves not kept as taught."""
    moves = [st for st in result.spec.steps if st.kind == "move"]
    total = sum(m.default_energy_J for m in result.moves)
    closed = sum(m.default_energy_J for m, st in zip(result.moves, moves, strict=True) if st.kept)
    return 100.0 * (1.0 - closed / total) if total > 0 else 100.0


def optimized_cycle_csv(result: CycleResult) -> str:
    """The optimized moves' sampled paths (25 ms, rad), one block of rows per move (its first line)."""
    n = result.spec.robot.n_joints
    rows = ["line,t," + ",".join(f"q{j}" for j in range(1, n + 1))]
    for i, s in result.paths.items():
        line = result.spec.steps[i].line
        for t, q in zip(s.samples.t, s.samples.q, strict=True):
            rows.append(f"{line},{t:.4f}," + ",".join(f"{v:.8f}" for v in q))
    return "\n".join(rows) + "\n"


def cycle_path_csv(result: CycleResult) -> str:
    """The planned cycle, the file ``joulepath stream`` follows: ``t, q1..qn, qd1..qdn, qdd1..qdn``
    (s, rad, rad/s, rad/s²) on the 2.5 ms grid, from the cycle's start to its end."""
    traj = result.planned
    assert traj is not None
    n = traj.q.shape[1]
    head = ["t", *(f"q{j}" for j in range(1, n + 1)), *(f"qd{j}" for j in range(1, n + 1))]
    head += [f"qdd{j}" for j in range(1, n + 1)]
    rows = [",".join(head)]
    for k in range(traj.t.size):
        vals = [f"{traj.t[k]:.6f}", *(f"{v:.9f}" for v in traj.q[k]), *(f"{v:.9f}" for v in traj.qd[k])]
        vals += [f"{v:.9f}" for v in traj.qdd[k]]
        rows.append(",".join(vals))
    return "\n".join(rows) + "\n"


def egm_cycle_files(result: CycleResult) -> dict[str, str]:
    """``egm.mod`` and ``EGM_SETUP.md`` streaming the planned cycle (checked against the limits)."""
    from joulepath.export import render_egm

    traj = result.planned
    assert traj is not None
    return render_egm(result.spec.robot, traj, float(traj.t[-1]), cycle=True)


def pareto_csv(points: list[ParetoPoint], default: tuple[float, float, float]) -> str:
    rows = ["cycle_time_s,energy_J,energy_lab_J,kind"]
    rows += [f"{p.cycle_time_s:.4f},{p.energy_J:.6f},{p.energy_lab_J:.6f},optimized" for p in points]
    rows.append(f"{default[0]:.4f},{default[1]:.6f},{default[2]:.6f},default program")
    return "\n".join(rows) + "\n"


def pareto_plot(points: list[ParetoPoint], default: tuple[float, float, float], path: Path) -> Path:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    ax.plot([p.cycle_time_s for p in points], [p.energy_J for p in points], "o-", label="optimized (physics)")
    ax.plot(
        [p.cycle_time_s for p in points], [p.energy_lab_J for p in points], "s--", label="optimized (lab)"
    )
    ax.plot([default[0]], [default[1]], "k*", ms=12, label="default program (physics)")
    ax.set_xlabel("cycle time [s]")
    ax.set_ylabel("energy per cycle [J]")
    ax.legend()
    fig.tight_layout()
    return save_figure(fig, path, dpi=100)


def reads_back(result: CycleResult, text: str) -> str | None:
    """None when the written module, parsed and resolved again, runs the motion it was written
    for (:func:`joulepath.program._rapid_write.planned_model`); else what differs."""
    from joulepath.program._task import read_written

    spec = result.spec
    again = read_written(text, f"{spec.source} (optimized)", spec.robot)
    return same_model(motion_model(again), planned_model(result))


def _rapid_attempt(
    result: CycleResult, cell: Cell | None, write_anyway: bool
) -> tuple[str | None, dict[str, Any] | None, str | None, WrittenModule | None]:
    """The module of ``result`` (of :attr:`CycleResult.unretimed` where the plan re-times segments with
    a MoveL along their path, which RAPID's own MoveL at its speeddata does not follow), its check and
    its structure, or None and why it is not written."""
    result = result.unretimed or result
    try:
        first = written_rapid(result)
    except LimitViolation as err:
        return None, None, str(err), None
    try:
        differs = reads_back(result, first.text)
    except RapidError as err:
        differs = f"it cannot be read: {err}"
    if differs is not None:
        return (
            None,
            None,
            f"the written module does not read back as the motion written ({differs}); not written",
            None,
        )
    check = check_written(result, first.text, cell)
    layout = written_rapid(result, check)  # the header states what the emulation measured
    text = layout.text
    inside = check["cell_clearance_mm"]
    if inside is not None and inside < 0.0:
        return (
            None,
            check,
            f"the written program, run by the controller emulation, comes {-inside:.1f} mm "
            "inside the cell's margin (its via points do not follow the plan closely enough); not written",
            layout,
        )
    if not check["within_tolerances"]:
        if write_anyway:
            return _mark_unfaithful(text, check), check, None, layout
        return None, check, _unfaithful_reason(check), layout
    return text, check, None, layout


OPTIMIZED_TASK = "optimized_task"
"""The folder a task of several modules is written into (every module, the changed ones edited)."""
TASK_MARK = "WRITTEN_BY_JOULEPATH.txt"


def _write_task(folder: Path, files: tuple[tuple[str, bytes], ...]) -> Path:
    """Every module under its path relative to the modules' common folder, and a note saying whose."""
    paths = [Path(p).resolve() for p, _ in files]
    common = Path(os.path.commonpath([str(p.parent) for p in paths])) if len(paths) > 1 else paths[0].parent
    make_folder(folder)
    for (_, data), p in zip(files, paths, strict=True):
        dest = folder / p.relative_to(common)
        dest.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(dest, data)
    atomic_write_text(
        folder / TASK_MARK,
        "The task as written, with the controller's levers (AccSet, speed data, zones) where joulepath "
        "changed them; every other byte of every module as it was. See ../cycle.json (rapid_levers).\n",
    )
    return folder


def _levers_json(levers: Any) -> dict[str, Any]:
    return {
        "executed_cycle_s": levers.cycle_s,
        "taught_cycle_s": levers.taught_cycle_s,
        "executed_energy_J": levers.energy_J,
        "default_energy_J": levers.default_energy_J,
        "executed_saved_pct": levers.saved_pct,
        "energy_measure": levers.energy_measure,
        "moves_changed": levers.n_changed,
        "reads_back": levers.reads_back,
        "plans_searched": levers.n_evaluations,
        "wall_s": levers.wall_s,
        "moves": [
            {"line": m.line, "label": m.label, "taught": asdict(m.taught), "chosen": asdict(m.chosen)}
            for m in levers.moves
            if m.changed
        ],
    }


def _via_levers_json(via: Any) -> dict[str, Any]:
    out: dict[str, Any] = {
        "note": via.note,
        "via_points_executed_cycle_s": via.via_cycle_s,
        "via_points_executed_energy_J": via.via_energy_J,
        "tool0_from_taught_path_mm": via.deviation_mm,
        "cell_clearance_mm": via.clearance_mm,
        "optimized_moves_kept_as_taught": via.taught_units,
    }
    if via.levers is not None:
        out.update(_levers_json(via.levers))
    return out


def _export_choice(
    egm: str, written_from: str | None, rapid_saved: float | None, plan: float, stream: bool, name: str
) -> str:
    """One sentence: what was written and why, with the RAPID module's executed and the EGM plan's saving."""
    egm_part = f"the EGM plan saves {plan:.1f} % (planned)"
    if written_from is None:
        return f"no RAPID module runs as planned; {egm_part}" + ("; egm.mod written" if stream else "")
    rapid_part = f"{name} ({written_from}) saves {rapid_saved:.1f} % as executed"
    if egm == "fallback" and stream:
        return f"{rapid_part}, less than half of what {egm_part}: egm.mod written too, the stream recommended"
    if egm == "fallback":
        return f"{rapid_part}, at least half of what {egm_part}: RAPID written, no PC in the loop"
    return f"{rapid_part}; {egm_part}"


RAPID_FOLLOWS_NOTE = (
    "which plan optimized.mod's via points follow: the plan, or (where the controller emulation does "
    "not run it as the checks ask) the plan for via points: only the units from rest to rest of joint "
    "moves, planned within 3/(2π) of the acceleration limit (rapid_plan_saved_pct: its planned saving); "
    "cycle_path.csv and --export egm always stream the plan"
)
"""``cycle.json``'s ``rapid_follows_note``."""


def _via_point_module(
    result: CycleResult, cell: Cell | None, write_rapid: bool, write_anyway: bool
) -> tuple[str | None, dict[str, Any] | None, str | None, Any, str | None]:
    """The via-point module of the first plan the controller emulation runs as the checks ask (the
    plan, else the plan for via points; ``write_anyway``: the last written all the same): its text,
    check, why it was refused, layout, and which plan it follows (all None where none is written)."""
    text = refused = check = layout = None
    follows = None
    if write_rapid and result.spec.module is None:
        why = result.spec.static_note or "is not a RAPID module"
        refused = (
            "the via-point RAPID writer edits a program of one module whose cycle is fully known; "
            f"this one {why}; the planned cycle is written for EGM instead"
        )
        write_rapid = False
    if write_rapid:
        plans = [
            (
                "the plan"
                if result.unretimed is None
                else "the plan before its MoveL segments were re-timed along their path",
                result,
            )
        ]
        if result.rapid_plan is not None and result.limits_ok:
            plans.append(
                (
                    "the plan for via points (its units from rest to rest of joint moves only, within "
                    "3/(2π) of the acceleration limit)",
                    result.rapid_plan,
                )
            )
        for k, (name, plan) in enumerate(plans):
            text, check, refused, layout = _rapid_attempt(plan, cell, write_anyway and k == len(plans) - 1)
            if text is not None:
                follows = name
                break
    return text, check, refused, layout, follows


def _chosen_levers(result: CycleResult, levers: Any | None, via_levers: Any | None) -> Any | None:
    """The program with levers that saves most of those offered (the controller's own levers where
    they read back, change something and save within the taught cycle time; the via-point module's
    levers), or None; none where the plan breaks a limit."""
    lever_ok = (
        levers is not None
        and levers.reads_back is None
        and levers.n_changed > 0
        and levers.energy_J < levers.default_energy_J
        and levers.cycle_s <= levers.taught_cycle_s + 1e-9
        and result.limits_ok
    )
    offered: list[Any] = [levers] if lever_ok else []
    if via_levers is not None and via_levers.levers is not None and result.limits_ok:
        offered.append(via_levers.levers)
    return max(offered, key=lambda lv: lv.saved_pct, default=None)


def _levers_check(chosen: Any, levers_of_via: bool) -> dict[str, Any]:
    """``cycle.json``'s check of a program written with levers (as the controller emulation ran it)."""
    return {
        "emulated_cycle_s": chosen.cycle_s,
        "emulated_energy_J": chosen.energy_J,
        "emulated_energy_lab_J": chosen.energy_lab_J,
        "within_tolerances": True,
        "written_by": (
            "via points + levers: the plan's via-point module with the controller's levers of its via "
            "points (AccSet, \\T, zones), searched on the controller emulation; the written text read "
            "again by the RAPID interpreter and run again by the emulation"
            if levers_of_via
            else "levers: the controller's own plan of the written program (AccSet, speed data, "
            "zones), read back and run by the controller emulation"
        ),
    }


def _remove_written_task(task_dir: Path) -> None:
    """Remove a task folder joulepath wrote here before (marked by :data:`TASK_MARK`)."""
    if task_dir.is_dir() and not task_dir.is_symlink() and (task_dir / TASK_MARK).is_file():
        for old in sorted(task_dir.rglob("*"), reverse=True):
            if old.is_file() or old.is_symlink():
                old.unlink()
            else:
                old.rmdir()
        task_dir.rmdir()


def write_cycle_run(
    out: Path,
    result: CycleResult,
    *,
    pareto: list[ParetoPoint] | None,
    write_rapid: bool,
    cell: Cell | None = None,
    write_anyway: bool = False,
    egm: str = "never",
    levers: Any | None = None,
    via_levers: Any | None = None,
) -> dict[str, Path]:
    """Write the run folder; the module only when every limit holds, the controller emulation
    runs it as the checks ask (:data:`CHECK_TOLERANCES`; ``write_anyway``: written all the same,
    with a warning in its header) and, with a cell, its emulated motion keeps the margin
    (else cycle.json says why). Always ``cycle_path.csv`` (the planned cycle); ``egm``
    "always", or "fallback": also ``egm.mod`` and ``EGM_SETUP.md`` to stream it (``joulepath
    stream``) where no RAPID module is written or the written one saves, as executed, less than
    half of what the EGM plan saves; "never": not.

    ``levers`` (a :class:`~joulepath.program.LeverResult`): the program with the controller's own
    levers (``AccSet``, speed data, zones), read back and run by the controller emulation;
    ``via_levers`` (a :class:`~joulepath.program.ViaLevers`): the plan's via-point module with the
    levers of its via points, searched on the controller emulation. The RAPID module written is
    the best of them and the via-point module kept to the plan, as executed."""
    if egm not in ("always", "fallback", "never"):
        raise ValueError(f"egm must be always, fallback or never, got {egm!r}")
    files: dict[str, Path] = {}
    text, check, refused, layout, follows = _via_point_module(result, cell, write_rapid, write_anyway)
    via_saved = None
    if text is not None and check is not None and result.default_energy_J > 0:
        via_saved = 100.0 * (1.0 - check["emulated_energy_J"] / result.default_energy_J)
    written_from = None if text is None else "via points"
    data_bytes: bytes | None = None
    task_files: tuple[tuple[str, bytes], ...] = ()
    chosen = _chosen_levers(result, levers, via_levers)
    if chosen is not None and (via_saved is None or chosen.saved_pct > via_saved):
        levers_of_via = chosen.base == "via points"
        written_from = "via points + levers" if levers_of_via else "levers"
        if chosen.written_files:
            task_files = chosen.written_files
        else:
            data_bytes = chosen.written_bytes()
        check = _levers_check(chosen, levers_of_via)
        layout = None
    make_folder(out)
    stale = out / "optimized.mod"
    task_dir = out / OPTIMIZED_TASK
    _remove_written_task(task_dir)
    if task_files:
        files[OPTIMIZED_TASK] = _write_task(task_dir, task_files)
    if data_bytes is not None:
        files["optimized.mod"] = atomic_write_bytes(stale, data_bytes)
    elif text is not None:
        files["optimized.mod"] = atomic_write_text(stale, text)
    elif stale.is_file() and not stale.is_symlink():
        remove_output(stale)
    written_name = OPTIMIZED_TASK if task_files else "optimized.mod"
    rapid_saved = via_saved
    if written_from in ("levers", "via points + levers") and result.default_energy_J > 0:
        assert chosen is not None  # on the same basis as the via points': the taught cycle as emulated
        rapid_saved = 100.0 * (1.0 - chosen.energy_J / result.default_energy_J)
    files["optimized_cycle.csv"] = atomic_write_text(out / "optimized_cycle.csv", optimized_cycle_csv(result))
    files["cycle_path.csv"] = atomic_write_text(out / "cycle_path.csv", cycle_path_csv(result))
    half_of_plan = rapid_saved is not None and rapid_saved < 0.5 * result.saved_pct
    stream = egm == "always" or (egm == "fallback" and (written_from is None or half_of_plan))
    egm_files = egm_cycle_files(result) if stream else {}
    for name in ("egm.mod", "EGM_SETUP.md"):
        old = out / name
        if name not in egm_files and old.is_file() and not old.is_symlink():
            remove_output(old)
    for name, body in egm_files.items():
        files[name] = atomic_write_text(out / name, body)
    if pareto is not None:
        default = (result.default_cycle_s, result.default_energy_J, result.default_lab_J)
        files["pareto.csv"] = atomic_write_text(out / "pareto.csv", pareto_csv(pareto, default))
        files["pareto.png"] = pareto_plot(pareto, default, out / "pareto.png")
    data = cycle_json(result, pareto, written_name if written_from is not None else None, refused, check)
    if written_from in ("levers", "via points + levers"):
        assert chosen is not None
        data["executed_saved_lab_pct"] = (
            100.0 * (1.0 - chosen.energy_lab_J / chosen.default_lab_J) if chosen.default_lab_J else None
        )
        data["executed_note"] = (
            f"optimized.mod (written from: {written_from}) as the controller emulation runs it, "
            "against the taught program run by the same emulation, both on energy_measure (the lab robot's "
            "on the same measure)"
        )
    data["rapid_written_from"] = written_from
    data["rapid_via_points_executed_saved_pct"] = via_saved
    data["rapid_levers"] = None if levers is None else _levers_json(levers)
    data["rapid_via_levers"] = None if via_levers is None else _via_levers_json(via_levers)
    data["egm_plan_saved_pct"] = result.saved_pct
    data["export_choice"] = _export_choice(
        egm,
        written_from,
        rapid_saved,
        result.saved_pct,
        stream,
        f"{written_name}/" if task_files else written_name,
    )
    data["rapid_follows"] = follows
    data["rapid_plan_saved_pct"] = None if result.rapid_plan is None else result.rapid_plan.saved_pct
    data["rapid_follows_note"] = RAPID_FOLLOWS_NOTE
    data["rapid_structure"] = None if layout is None or text is None else layout.summary()
    files["cycle.json"] = atomic_write_text(
        out / "cycle.json", json.dumps(finite_json(data), indent=2, allow_nan=False)
    )
    return files
