"""Whole cycles of the bundled example programs at their own cycle time: what `joulepath cycle` plans
and writes, against the cycle optimum, and its wall time on one core.

For each program in examples/: the taught cycle (the controller emulation), the plan
(``optimize_cycle`` with the CLI's defaults), what is written (``optimized.mod`` where the
emulation runs it as the checks ask, with its emulated saving; else ``egm.mod`` streaming the
plan), and the cycle optimum: one IPOPT transcription (CasADi) of the cycle's units from rest to
rest of joint moves, with the same zones and the time the plan gives them
(:func:`joulepath.optimize._cycle_reference.cycle_optimum`, where installed), on the robot with
each move's tool and load as the plan has it (units with different tools: one optimum per tool,
each within the time the plan gives its units). The share is the
plan's saving on those units over the optimum's. Units inside MoveL segments and re-timed MoveL
are not in the optimum (their ends or path are fixed); the share covers the units it holds.

Run: ``.venv/bin/python benchmarks/cycle_examples.py`` (one BLAS thread; about 7 minutes, 5 of
them the cycle optimum on inspection, which stops at its 300 s limit).
Writes the table to stdout; BENCHMARKS.md holds a copy with the machine.
"""

from __future__ import annotations

import json
import os
import platform
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from joulepath import load_robot  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.program import CycleSettings, optimize_cycle, read_cycle_program, write_cycle_run  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
INTERVALS = 16
"""Transcription intervals per sub-leg of the cycle optimum (8 agree with the single-move
reference within 0.05 %, tests/optimize/test_cycle_reference.py)."""
PROGRAMS = (
    "pick_and_place",
    "palletizing",
    "machine_tending",
    "inspection",
    "approach_depart",
    "payload_tool",
)


def optimum_share(result, opt) -> tuple[float | None, float | None, str]:
    """(optimum's saving on the legs %, share of it reached %, note) for the units from rest to rest."""
    try:
        from joulepath.optimize._cycle_reference import CycleLeg, cycle_optimum
    except ImportError:
        return None, None, "no cycle optimum (module not installed)"
    groups: dict[int, tuple[object, list, list[float]]] = {}  # by robot (tool and load): legs, budget
    ours, taught = 0.0, 0.0
    for i in opt.optimizable:
        if i in opt.within or i in opt.linear:
            continue
        members = opt.chains[i]
        first, last = opt.by_index[i], opt.by_index[members[-1]]
        radius = opt.zone_radius(i)
        robot = first.step.robot  # the robot with the move's tool and load, as the plan has it
        _, legs, budget = groups.setdefault(id(robot), (robot, [], [0.0]))
        legs.append(
            CycleLeg(
                q_start=first.path.q0,
                q_end=last.path.q1,
                via=tuple(opt.by_index[j].path.q1 for j in members[:-1]),
                via_radius=tuple(radius),
            )
        )
        t_entry = opt.taught(i)
        taught += t_entry.energy_J
        piece = [result.paths[j] for j in members if j in result.paths]
        if piece:
            ours += sum(p.energy_J for p in piece)
            budget[0] += sum(p.duration for p in piece)
        else:
            ours += t_entry.energy_J
            budget[0] += t_entry.duration
    if not groups:
        return None, None, "no unit from rest to rest of joint moves"
    best_J = 0.0
    for robot, legs, budget in groups.values():
        best = cycle_optimum(
            robot,
            legs,
            budget[0],
            acceleration_limit=opt._amax(robot),
            jerk_limit=opt._jmax(robot),
            friction=NOMINAL_FRICTION,
            intervals=INTERVALS,
            time_limit_s=300.0,
        )
        if not best.feasible:
            return None, None, f"optimum: {best.status}"
        best_J += best.energy_J
    if taught - best_J <= 1e-9:
        return None, None, "optimum: saves nothing"
    opt_pct = 100 * (taught - best_J) / taught
    share = 100 * (taught - ours) / (taught - best_J)
    n = sum(len(legs) for _, legs, _ in groups.values())
    return opt_pct, share, f"{n} unit(s)"


def main() -> None:
    robot = load_robot("irb120")
    rows = []
    for name in PROGRAMS:
        spec, rapid = read_cycle_program(EXAMPLES / f"{name}.mod", robot)
        t0 = time.process_time()
        w0 = time.perf_counter()
        result, opt = optimize_cycle(spec, CycleSettings())
        cpu = time.process_time() - t0
        wall = time.perf_counter() - w0
        with tempfile.TemporaryDirectory() as tmp:
            files = write_cycle_run(Path(tmp), result, pareto=None, write_rapid=rapid, egm="fallback")
            data = json.loads(files["cycle.json"].read_text())
        if "optimized.mod" in files:
            written = f"RAPID, emulated {data['executed_saved_pct']:.1f} %"
        else:
            via = data["rapid_plan_saved_pct"]
            written = f"EGM, {result.saved_pct:.1f} % (the plan); via-point plan: " + (
                "none saves" if via is None else f"{via:.1f} %, refused"
            )
        opt_pct, share, note = optimum_share(result, opt)
        n_moves = sum(1 for s in spec.steps if s.kind == "move")
        rows.append(
            (
                name,
                n_moves,
                result.default_cycle_s,
                result.optimized_cycle_s,
                result.default_energy_J,
                result.optimized_energy_J,
                result.saved_pct,
                written,
                opt_pct,
                share,
                note,
                wall,
                cpu,
            )
        )
        print(f"{name}: {result.saved_pct:.1f} %, {wall:.1f} s", flush=True)
    print()
    print(f"Machine: {platform.machine()}, {platform.processor() or platform.platform()}, one BLAS thread")
    print()
    print(
        "| program | moves | cycle taught → planned (s) | energy taught → planned (J) | saved (plan) | written | "
        "optimum on its units | share of it | wall / CPU (s) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        opt_txt = "—" if r[8] is None else f"{r[8]:.1f} % ({r[10]})"
        share_txt = "—" if r[9] is None else f"{r[9]:.0f} %"
        if r[8] is None:
            opt_txt = f"— ({r[10]})"
        print(
            f"| {r[0]} | {r[1]} | {r[2]:.3f} → {r[3]:.3f} | {r[4]:.2f} → {r[5]:.2f} | {r[6]:.1f} % | {r[7]} | "
            f"{opt_txt} | {share_txt} | {r[11]:.1f} / {r[12]:.1f} |"
        )


if __name__ == "__main__":
    main()
