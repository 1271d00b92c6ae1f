"""What ``joulepath cycle`` writes: the optimized module, cycle.json, the trade-off (CSV + plot)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from joulepath import __version__
from joulepath._io import atomic_write_text, finite_json, make_folder, remove_output, save_figure
from joulepath.abb import EXTERNAL_AXES_UNUSED, VIA_ZONE_MM
from joulepath.errors import LimitViolation
from joulepath.program._cell import Cell, clearance
from joulepath.program._cycle import CycleResult, ParetoPoint, Solved
from joulepath.program._model import Move, WaitTime
from joulepath.program._write import _num, format_move, write_module

CYCLE_FILES = (
    "cycle.json",
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
    "energy: sum over joints and 2.5 ms samples of |tau * qd| * dt, physics = nominal rigid body with the "
    "tool's load and NOMINAL_FRICTION; lab = the emulated lab robot's drive torque on the same motion",
    "default: the emulated controller (jerk-limited profile, speeddata, joint limits, accel = vmax/0.25 s, "
    "zones blended by superposition, 48 ms dwell at stop points; a move before WaitTime stops)",
    "units: the default cycle is cut where the robot stands still; a segment of MoveJ/MoveAbsJ only (each "
    "occurring once) is one unit, optimized by the single-move gradient optimizer as one move through its "
    "fly-by targets (each passed within its zone: the zone radius reduced to half of either move's TCP "
    "length, as a joint box; or exactly with --exact-targets), with its taught motion kept as a candidate "
    "at its taught duration, so the taught cycle time is always reachable (at worst 0 % saved); written as "
    "MoveAbsJ via points with \\T in z200 zones, the last via point of a unit keeps its stop (fine)",
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


def _jt(q_deg: np.ndarray) -> str:
    ext = ", ".join([EXTERNAL_AXES_UNUSED] * 6)
    return "[[" + ", ".join(_num(float(v)) for v in q_deg) + f"], [{ext}]]"


def optimized_module(result: CycleResult, check: dict[str, Any] | None = None) -> str:
    """The module with each optimized move replaced by its via points; refused outside a limit.

    The header states the saving of the module as the controller emulation runs it
    (``check``, from :func:`check_written`), else that of the plan, named as such.
    """
    spec = result.spec
    module = spec.module
    assert module is not None
    if not result.limits_ok:
        bad = "; ".join(e for m in result.moves for e in m.limit_excess)
        raise LimitViolation(
            f"the optimized cycle breaks a limit or the cell's margin ({bad or 'clearance'}); "
            "the program is not written"
        )
    again = sorted({spec.steps[i].line for i in result.paths if spec.steps[i].repeated})
    if again:
        raise LimitViolation(
            f"line(s) {', '.join(map(str, again))}: a move that runs more than once in the cycle "
            "(a procedure called more than once) is optimized in each call, which one statement's "
            "via points cannot hold; the program is not written (the streamed cycle, --export egm, runs it)"
        )
    replace: dict[int, list[str]] = {}
    decls: list[str] = []
    through = {j for chain in result.chains.values() for j in chain[:-1]} | set(result.open_ends)
    for i, solved in result.paths.items():
        step = spec.steps[i]
        move = step.statement
        assert isinstance(move, Move) and step.robot is not None
        # a target inside a fly-by chain keeps the program's own zone; a move's last point stops
        own = move.zone + ("" if move.z_tcp is None else f" \\Z:={_num(move.z_tcp)}")
        end = own if i in through else "fine" if step.zone_mm is None else "z1"
        lines, names = _via_lines(move, solved, result.vias[i], end, step.robot)
        replace[move.line] = lines
        decls.extend(names)
    for wline, before, after in result.waits:
        if after != before:
            replace[wline] = [
                f"! joulepath: WaitTime {_num(before)} s spent on the moves (--use-waits)",
                f"WaitTime {_num(after)};",
            ]
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
    # every replaced statement must be a move or WaitTime of the module (never a verbatim one)
    for line in replace:
        stmt = next(
            (s.statement for s in spec.steps if s.statement is not None and s.statement.line == line), None
        )
        assert isinstance(stmt, Move | WaitTime)
    return write_module(module, replace=replace, declarations=decls, header=header)


def _via_lines(
    move: Move, solved: Solved, idx: Sequence[int], end: str, robot: Any
) -> tuple[list[str], list[str]]:
    samples = solved.fine
    lo, hi = robot.joint_ranges()
    q = samples.q[list(idx)]
    if np.any(q < lo - 1e-9) or np.any(q > hi + 1e-9):
        raise LimitViolation(
            f"line {move.line}: a via point leaves a joint range; the program is not written"
        )
    times = np.diff([0.0, *samples.t[list(idx)]])
    prev = np.vstack([samples.q[0], q[:-1]])
    speed = np.abs(q - prev) / times[:, None]
    if np.any(speed > robot.velocity_limit * (1 + 1e-9)):
        raise LimitViolation(f"line {move.line}: a via segment exceeds a joint speed limit; not written")
    names = []
    lines = [f"! joulepath: {format_move(move)} reshaped: {len(idx)} via points in {solved.duration:.3f} s"]
    for k, (qk, tk) in enumerate(zip(q, times, strict=True), start=1):
        name = f"jpL{move.line}_{k}"
        names.append(f"CONST jointtarget {name} := {_jt(np.degrees(qk))};")
        zone = end if k == len(idx) else VIA_ZONE
        lines.append(f"MoveAbsJ {name}, v7000 \\T:={_num(float(tk))}, {zone}, {move.tool};")
    return lines, names


VIA_ZONE = f"z{VIA_ZONE_MM:.0f}"
"""Zone of the via points inside an optimized move (:data:`joulepath.abb.VIA_ZONE_MM`)."""

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

    from joulepath.program._cycle import _energy
    from joulepath.program._parse import parse_module
    from joulepath.program._resolve import resolve_module
    from joulepath.sim import ControllerConfig, make_plant
    from joulepath.sim._timing import FINE_DT, _tcp, evaluate_cycle, plan_cycle

    spec = result.spec
    config = ControllerConfig()
    written = parse_module(text, path=f"{spec.source} (optimized)")
    plan = plan_cycle(resolve_module(written, spec.robot), config)
    n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
    traj = evaluate_cycle(plan, np.linspace(0.0, plan.cycle_time, n))
    first = plan.moves[0].step
    assert first.robot is not None and first.tcp is not None
    energy, energy_lab = _energy(first.robot, make_plant("lab", first.robot), traj)
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
        "source": result.spec.source,
        "robot": result.spec.robot.name,
        "choices": list(result.spec.choices),
        "taught_units": list(result.taught_units),
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
        "breakdown": {
            "default_J": b.default_J,
            "shapes_at_default_proportions_J": b.shape_J,
            "reallocated_durations_J": b.allocation_J,
            "waits_spent_J": b.waits_J,
            "saved_by_shape_pct": b.by_shape_pct,
            "saved_by_time_allocation_pct": b.by_allocation_pct,
            "saved_by_waits_pct": b.by_waits_pct,
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
    from joulepath.export._egm import render_egm

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


def _rapid_attempt(
    result: CycleResult, cell: Cell | None, write_anyway: bool
) -> tuple[str | None, dict[str, Any] | None, str | None]:
    """The module of ``result`` and its check, or None and why it is not written."""
    try:
        text: str | None = optimized_module(result)
    except LimitViolation as err:
        return None, None, str(err)
    assert text is not None
    check = check_written(result, text, cell)
    text = optimized_module(result, check)  # the header states what the emulation measured
    inside = check["cell_clearance_mm"]
    if inside is not None and inside < 0.0:
        return (
            None,
            check,
            f"the written program, run by the controller emulation, comes {-inside:.1f} mm "
            "inside the cell's margin (its via points do not follow the plan closely enough); not written",
        )
    if not check["within_tolerances"]:
        if write_anyway:
            return _mark_unfaithful(text, check), check, None
        return None, check, _unfaithful_reason(check)
    return text, check, None


def write_cycle_run(
    out: Path,
    result: CycleResult,
    *,
    pareto: list[ParetoPoint] | None,
    write_rapid: bool,
    cell: Cell | None = None,
    write_anyway: bool = False,
    egm: str = "never",
) -> dict[str, Path]:
    """Write the run folder; the module only when every limit holds, the controller emulation
    runs it as the checks ask (:data:`CHECK_TOLERANCES`; ``write_anyway``: written all the same,
    with a warning in its header) and, with a cell, its emulated motion keeps the margin
    (else cycle.json says why). Always ``cycle_path.csv`` (the planned cycle); ``egm``
    "always", or "fallback" when no module is written: also ``egm.mod`` and ``EGM_SETUP.md``
    to stream it (``joulepath stream``); "never": not."""
    if egm not in ("always", "fallback", "never"):
        raise ValueError(f"egm must be always, fallback or never, got {egm!r}")
    files: dict[str, Path] = {}
    text = refused = check = None
    follows = None
    if write_rapid:
        plans = [("the plan", result)]
        if result.rapid_plan is not None and result.limits_ok:
            plans.append(
                (
                    "the plan for via points (its units from rest to rest of joint moves only, within "
                    "3/(2π) of the acceleration limit)",
                    result.rapid_plan,
                )
            )
        for k, (name, plan) in enumerate(plans):
            text, check, refused = _rapid_attempt(plan, cell, write_anyway and k == len(plans) - 1)
            if text is not None:
                follows = name
                break
    make_folder(out)
    stale = out / "optimized.mod"
    if text is not None:
        files["optimized.mod"] = atomic_write_text(stale, text)
    elif stale.is_file() and not stale.is_symlink():
        remove_output(stale)
    files["optimized_cycle.csv"] = atomic_write_text(out / "optimized_cycle.csv", optimized_cycle_csv(result))
    files["cycle_path.csv"] = atomic_write_text(out / "cycle_path.csv", cycle_path_csv(result))
    stream = egm == "always" or (egm == "fallback" and text is None)
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
    data = cycle_json(result, pareto, "optimized.mod" if text is not None else None, refused, check)
    data["rapid_follows"] = follows
    data["rapid_plan_saved_pct"] = None if result.rapid_plan is None else result.rapid_plan.saved_pct
    data["rapid_follows_note"] = (
        "which plan optimized.mod's via points follow: the plan, or (where the controller emulation does "
        "not run it as the checks ask) the plan for via points: only the units from rest to rest of joint "
        "moves, planned within 3/(2π) of the acceleration limit (rapid_plan_saved_pct: its planned saving); "
        "cycle_path.csv and --export egm always stream the plan"
    )
    files["cycle.json"] = atomic_write_text(
        out / "cycle.json", json.dumps(finite_json(data), indent=2, allow_nan=False)
    )
    return files
