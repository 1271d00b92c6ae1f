"""Energy measures against each other (issue 24): the thesis' optimum measured electrically, and back.

On ``--tasks`` random feasible tasks of the IRB 120 (``random_tasks(robot, N, seed=24,
range_set="lab")``) the default gradient search runs twice, ``OptimizeConfig(energy="thesis")``
and ``OptimizeConfig(energy="electrical")``; each result reports every measure
(``result.summary.energies``), so each optimum is measured on both:

* how far the thesis-optimal path is from the electrical optimum, measured electrically:
  ``E_el(thesis optimum) / E_el(electrical optimum) - 1``, on the motion part and at the meter
  (standby over the move included);
* how far the electrical optimum is from the thesis optimum on the thesis' metric:
  ``E_th(electrical optimum) / E_th(thesis optimum) - 1``.

Then the share of standby in a cycle's meter-level energy: each bundled example program's
taught cycle (the emulated controller's motion, 2.5 ms grid) measured electrically.

The IRB 120's drive data are the bundled estimate (every value assumed, see
``description/presets/irb120.drives.toml``); the numbers are as good as that estimate.

Writes ``benchmarks/results/energy_measures.csv`` and the BENCHMARKS.md section ``energy_measures``.

Usage:
    OMP_NUM_THREADS=1 python benchmarks/energy_measures.py --tasks 10
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402

import joulepath  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.energy import measure_energy  # noqa: E402
from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks  # noqa: E402
from joulepath.program import read_cycle_program  # noqa: E402
from joulepath.sim import ControllerConfig  # noqa: E402
from joulepath.sim._timing import FINE_DT, evaluate_cycle, plan_cycle  # noqa: E402

SECTION = "energy_measures"
SEED = 24


def _pct(a: float, b: float) -> float:
    return 100.0 * (a / b - 1.0)


def tasks_rows(
    robot: joulepath.Robot, n: int, done: Callable[[list[dict[str, float]]], None]
) -> list[dict[str, float]]:
    rows: list[dict[str, float]] = []
    for k, (q0, qf, T) in enumerate(random_tasks(robot, n, seed=SEED, range_set="lab")):
        t0 = time.perf_counter()
        by = {}
        for measure in ("thesis", "electrical"):
            s = optimize_move(robot, q0, qf, T, OptimizeConfig(energy=measure, seed=SEED)).summary
            by[measure] = {m.measure: m for m in s.energies}
            by[measure]["ok"] = s.limits_ok  # type: ignore[assignment]
        th, el = by["thesis"], by["electrical"]
        e_th, e_el = el["electrical"], th["electrical"]  # electrical figures of each optimum
        standby = e_th.standby_J
        row = {
            "task": k,
            "duration_s": float(T),
            "limits_ok": bool(th["ok"] and el["ok"]),
            "thesis_default_J": th["thesis"].default_J,
            "thesis_of_thesis_opt_J": th["thesis"].optimized_J,
            "thesis_of_electrical_opt_J": el["thesis"].optimized_J,
            "electrical_default_J": th["electrical"].default_J,
            "electrical_of_thesis_opt_J": e_el.optimized_J,
            "electrical_of_electrical_opt_J": e_th.optimized_J,
            "standby_J": standby,
            "thesis_opt_vs_electrical_opt_electrical_motion_pct": _pct(
                e_el.optimized_J - standby, e_th.optimized_J - standby
            ),
            "thesis_opt_vs_electrical_opt_electrical_meter_pct": _pct(e_el.optimized_J, e_th.optimized_J),
            "electrical_opt_vs_thesis_opt_thesis_pct": _pct(
                el["thesis"].optimized_J, th["thesis"].optimized_J
            ),
            "electrical_saved_by_thesis_opt_pct": e_el.saved_pct,
            "electrical_saved_by_electrical_opt_pct": e_th.saved_pct,
            "standby_share_of_move_pct": 100.0 * standby / th["electrical"].default_J,
            "wall_s": time.perf_counter() - t0,
        }
        rows.append(row)
        print(
            f"task {k}: T={T:.3f} s, electrical motion: thesis optimum {row['thesis_opt_vs_electrical_opt_electrical_motion_pct']:+.1f} % "
            f"vs the electrical optimum; thesis metric: electrical optimum "
            f"{row['electrical_opt_vs_thesis_opt_thesis_pct']:+.1f} % vs the thesis optimum ({row['wall_s']:.0f} s)",
            flush=True,
        )
        done(rows)
    return rows


def twin_rows(n_moves: int, n_tasks: int) -> tuple[list[dict[str, float]], str]:
    """A twin identified from ``n_moves`` lab moves (``joulepath identify``), optimized on with
    ``optimize --robot twin/`` on ``n_tasks`` random tasks; its predicted energies against the lab's."""
    import json
    import tempfile

    from joulepath.cli import main as cli
    from joulepath.sim import simulate

    folder = Path(tempfile.mkdtemp())
    log = simulate(folder / "lab.csv", plant="lab", n_moves=n_moves, seed=7).log
    if cli(["identify", str(log), "--robot", "irb120", "--out", str(folder / "twin")]) != 0:
        raise SystemExit("identify failed")
    card = json.loads((folder / "twin" / "card.json").read_text())
    rows = []
    robot = joulepath.load_robot("irb120")
    for k, (q0, qf, T) in enumerate(random_tasks(robot, n_tasks, seed=5, range_set="lab")):
        out = folder / f"task-{k}"
        q = [",".join(f"{v:.12g}" for v in x) for x in (q0, qf)]
        args = ["optimize", "--start", q[0], "--end", q[1], "--duration", f"{T:g}", "--export", "egm"]
        cli([*args, "--robot", str(folder / "twin"), "--out", str(out)])
        r = json.loads((out / "result.json").read_text())
        m = r["energies"]["mechanical"]
        figures = r["energy_figures"]  # the headline keys, as a user reads them: one measure
        assert figures["planned"]["measure"] == figures["lab"]["measure"] == r["energy_measure"]
        rows.append(
            {
                "task": k,
                "duration_s": float(T),
                "limits_ok": bool(r["limits_ok"]),
                "headline_default_error_pct": _pct(r["planned_default_J"], r["lab_default_J"]),
                "headline_optimized_error_pct": _pct(r["planned_optimized_J"], r["lab_optimized_J"]),
                "headline_saving_difference_points": r["planned_saved_pct"] - r["lab_saved_pct"],
                "mechanical_default_error_pct": _pct(m["default_J"], m["lab_default_J"]),
                "mechanical_optimized_error_pct": _pct(m["optimized_J"], m["lab_optimized_J"]),
                "saving_difference_points": m["saved_pct"] - m["lab_saved_pct"],
                "joint_side_vs_lab_logged_default_pct": _pct(
                    r["energy_default_J"], r["energy_default_lab_J"]
                ),
            }
        )
        print(f"twin task {k}: {rows[-1]}", flush=True)
    note = (
        f"twin from {n_moves} lab moves ({card['fit']['n_samples']:,} samples fitted), identified gear "
        f"efficiency {card['gear_efficiency']:.4f} (lab plant: 0.88)"
    )
    return rows, note


def cycle_rows(robot: joulepath.Robot) -> list[dict[str, object]]:
    rows = []
    for path in sorted((ROOT / "examples").glob("*.mod")):
        spec, _ = read_cycle_program(path, robot)
        plan = plan_cycle(spec, ControllerConfig())
        n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
        traj = evaluate_cycle(plan, np.linspace(0.0, plan.cycle_time, n))
        arm = plan.moves[0].step.robot or robot
        tau = arm.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
        w = np.append(np.diff(traj.t), 0.0)
        e = measure_energy("electrical", tau, traj.qd, w, arm.drivetrain, duration=plan.cycle_time)
        th = measure_energy("thesis", tau, traj.qd, w)
        rows.append(
            {
                "program": path.name,
                "cycle_s": plan.cycle_time,
                "thesis_J": th.total_J,
                "electrical_motion_J": e.motion_J,
                "standby_J": e.standby_J,
                "standby_share_pct": 100.0 * e.standby_J / e.total_J,
            }
        )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tasks", type=int, default=10)
    ap.add_argument("--twin-moves", type=int, default=100, help="lab moves the twin is identified from")
    ap.add_argument("--twin-tasks", type=int, default=0, help="tasks optimized on the twin (0: none)")
    ap.add_argument("--no-report", action="store_true")
    args = ap.parse_args()
    if args.twin_tasks:
        twin(args.twin_moves, args.twin_tasks, write=not args.no_report)
    if not args.tasks:
        return
    robot = joulepath.load_robot("irb120")
    t0 = time.perf_counter()
    cycles = cycle_rows(robot)

    def report(rows: list[dict[str, float]]) -> None:  # after every task: a long run leaves its rows
        _report(robot, rows, cycles, args.tasks, time.perf_counter() - t0, write=not args.no_report)

    tasks_rows(robot, args.tasks, report)


def _report(
    robot: joulepath.Robot,
    rows: list[dict[str, float]],
    cycles: list[dict[str, object]],
    n_tasks: int,
    wall: float,
    *,
    write: bool,
) -> None:
    med = {k: statistics.median(float(r[k]) for r in rows) for k in rows[0] if k not in ("task", "limits_ok")}
    drives = robot.drives
    assert drives is not None
    text = (
        f"Machine: {machine()}. {len(rows)} of {n_tasks} random feasible IRB 120 tasks (seed {SEED}, lab ranges), the "
        "default gradient search on the thesis' and on the electrical measure, each optimum measured on "
        f"both; wall {wall:.0f} s in all (a shared machine). Drive data: the bundled IRB 120 estimate "
        f"(every value assumed: k = {', '.join(f'{v:g}' for v in drives.torque_constant)} N·m/A, "
        f"R = {drives.resistance[0]:g} Ω, drive efficiency {drives.drive_efficiency[0]:g}, gear efficiency "
        f"{drives.gear_efficiency[0] if drives.gear_efficiency else 'none'}, {drives.bus} bus, standby "
        f"{drives.standby_W:g} W). Every result within its limits: "
        f"{all(bool(r['limits_ok']) for r in rows)}.\n\n"
        "| median over the tasks | value |\n|---|---|\n"
        f"| thesis optimum vs electrical optimum, electrical motion energy | "
        f"{med['thesis_opt_vs_electrical_opt_electrical_motion_pct']:+.1f} % |\n"
        f"| same, at the meter (standby over the move included) | "
        f"{med['thesis_opt_vs_electrical_opt_electrical_meter_pct']:+.2f} % |\n"
        f"| electrical optimum vs thesis optimum, thesis' metric | "
        f"{med['electrical_opt_vs_thesis_opt_thesis_pct']:+.1f} % |\n"
        f"| electrical saving (meter) of the thesis optimum | {med['electrical_saved_by_thesis_opt_pct']:+.2f} % |\n"
        f"| electrical saving (meter) of the electrical optimum | "
        f"{med['electrical_saved_by_electrical_opt_pct']:+.2f} % |\n"
        f"| standby share of a move's meter-level energy (default path) | {med['standby_share_of_move_pct']:.1f} % |\n"
        f"| wall time per task (both searches) | {med['wall_s']:.1f} s |\n\n"
        "Standby share of the bundled example programs' taught cycles at the meter (electrical measure, "
        "the emulated controller's motion):\n\n"
        "| program | cycle s | thesis J | electrical motion J | standby J | standby share |\n|---|---|---|---|---|---|\n"
        + "".join(
            f"| {c['program']} | {c['cycle_s']:.3f} | {c['thesis_J']:.1f} | {c['electrical_motion_J']:.1f} | "
            f"{c['standby_J']:.1f} | {c['standby_share_pct']:.1f} % |\n"
            for c in cycles
        )
        + f"\nPer-task rows: `benchmarks/results/{SECTION}.csv`.\n"
    )
    print(text, flush=True)
    if write:
        out = ROOT / "benchmarks" / "results" / f"{SECTION}.csv"
        out.parent.mkdir(parents=True, exist_ok=True)
        with out.open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        write_section(
            SECTION,
            "## Energy measures against each other (benchmarks/energy_measures.py, issue 24)\n\n" + text,
        )


def twin(n_moves: int, n_tasks: int, *, write: bool) -> None:
    t0 = time.perf_counter()
    rows, note = twin_rows(n_moves, n_tasks)
    worst = {
        k: max(abs(float(r[k])) for r in rows)
        for k in rows[0]
        if k not in ("task", "limits_ok", "duration_s")
    }
    text = (
        f"Machine: {machine()}. {note}; `optimize --robot twin/` on {n_tasks} random feasible tasks "
        f"(seed 5, lab ranges; wall {time.perf_counter() - t0:.0f} s in all). The twin's predicted energy on the "
        "lab's logged measure (`energies.mechanical` of `result.json`: its identified gear efficiency "
        "included) against the lab plant's, and, for comparison, the joint-side energy against the lab's "
        "logged one (what `energy_default_J` against `energy_default_lab_J` compared before the measures "
        "were named). The headline rows read `result.json` as a user does: `planned_*_J` against "
        "`lab_*_J` and `planned_saved_pct` against `lab_saved_pct`, both on the run's `energy_measure` "
        "(the default, `thesis`: joint side). Every result within its limits: "
        f"{all(bool(r['limits_ok']) for r in rows)}.\n\n"
        "| largest over the tasks (absolute) | value | goal |\n|---|---|---|\n"
        f"| headline (thesis): default path, planned on the twin against lab | {worst['headline_default_error_pct']:.2f} % | 2 % |\n"
        f"| headline (thesis): optimized path, planned on the twin against lab | {worst['headline_optimized_error_pct']:.2f} % | 2 % |\n"
        f"| headline (thesis): saving, twin against lab | {worst['headline_saving_difference_points']:.2f} points | 1 point |\n"
        f"| mechanical: default path, twin against lab | {worst['mechanical_default_error_pct']:.2f} % | 2 % |\n"
        f"| mechanical: optimized path, twin against lab | {worst['mechanical_optimized_error_pct']:.2f} % | 2 % |\n"
        f"| saving, twin against lab | {worst['saving_difference_points']:.2f} points | 1 point |\n"
        f"| joint-side twin against the lab's logged (mixed measures) | {worst['joint_side_vs_lab_logged_default_pct']:.1f} % | |\n"
    )
    print(text, flush=True)
    if write:
        write_section(
            SECTION + "_twin",
            "## A twin predicts the lab's energy on the same measure (benchmarks/energy_measures.py "
            "--twin-tasks, issue 24)\n\n" + text,
        )


if __name__ == "__main__":
    main()
