"""The via-point plan's search: planned and executed saving and CPU of candidate searches (issue 36).

A plan for RAPID (``follow="via-points"``: within ``RAPID_ACCEL_SHARE`` of the acceleration limit
and the jerk limit) is written as ``MoveAbsJ`` via points that the controller plans its own motion
through, so what a search saves on the plan is not what the robot saves: the written module is run
by the controller emulation (:func:`joulepath.optimize.rapid_execution`, what ``write_run`` does
before it writes ``path.mod``) against the controller's own ``MoveAbsJ \\T`` at the same duration.
For each task (the fixed task, the README's move, random tasks of the IRB 120) every candidate
search plans the move in this process, one after the other, and its plan is run on the emulation:

* ``grid`` — ``SEARCH_BEFORE_HULL`` (fine-grid rate rows, plain SLSQP), the via-point search of main
  before this benchmark (``--algo gradient-grid`` with ``follow="via-points"``);
* ``hull`` — the single move's default (hull rows, preconditioned SLSQP) on the 0.05 s knots;
* ``hull-wide`` — the same on knots twice as wide (0.1 s; 0.2 s for the coarse level): the via-point
  search since this benchmark (:func:`joulepath.optimize._search.via_point_settings`);
* ``grid-wide`` — ``SEARCH_BEFORE_HULL`` on knots twice as wide.

CPU: ``time.process_time`` of ``optimize_move`` (the search and its verification), one BLAS thread.
Rows: ``benchmarks/results/via_point_search_<stamp>.csv``; the table: BENCHMARKS.md.

Usage: python benchmarks/via_point_search.py [N_RANDOM] [CANDIDATES (comma-separated)]
"""

from __future__ import annotations

import csv
import statistics
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_core, write_section  # noqa: E402
from _tasks import NAMED_TASKS  # noqa: E402

single_core()


import joulepath  # noqa: E402
from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks, rapid_execution  # noqa: E402
from joulepath.optimize._gradient import SEARCH_BEFORE_HULL  # noqa: E402
from joulepath.optimize._search import (  # noqa: E402
    ALGORITHMS,
    AlgorithmSpec,
    _gradient_with,
    via_point_settings,
)

RESULTS = Path(__file__).resolve().parent / "results"
TASKS = NAMED_TASKS
CANDIDATES: dict[str, tuple[str, Any]] = {
    "grid": (
        "SEARCH_BEFORE_HULL on the 0.05 s knots (main's via-point search)",
        lambda c: dict(SEARCH_BEFORE_HULL),
    ),
    "hull": ("hull rows, preconditioned (the single move's default), 0.05 s knots", lambda c: {}),
    "hull-wide": ("hull rows, preconditioned, 0.1 s knots (`via_point_settings`)", via_point_settings),
    "grid-wide": (
        "SEARCH_BEFORE_HULL on 0.1 s knots",
        lambda c: {**SEARCH_BEFORE_HULL, "knot_spacing": 2 * c.knot_spacing},
    ),
}


def register(name: str) -> str:
    """Register candidate ``name`` as a search (``bench-via-<name>``) and return its algorithm name."""
    what, overrides = CANDIDATES[name]
    algo = f"bench-via-{name}"
    ALGORITHMS[algo] = AlgorithmSpec(
        algo,
        "gradient",
        ("physics",),
        what,
        lambda task, config, rng, o=overrides: _gradient_with(task, config, rng, o(config)),
    )
    return algo


def main() -> None:
    n_random = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    names = sys.argv[2].split(",") if len(sys.argv) > 2 else list(CANDIDATES)
    robot = joulepath.load_robot("irb120")
    tasks = list(TASKS)
    for k, (q0, qf, T) in enumerate(random_tasks(robot, n_random, seed=21)):
        tasks.append((f"random {k}", q0, qf, T))
    stamp = time.strftime("%Y%m%d-%H%M")
    RESULTS.mkdir(exist_ok=True)
    out_csv = RESULTS / f"via_point_search_{stamp}.csv"
    rows: list[dict[str, Any]] = []
    loads: list[float] = []
    for task, q0, qf, T in tasks:
        for name in names:
            config = OptimizeConfig(algorithm=register(name), follow="via-points")
            loads.append(_load())
            t0 = time.process_time()
            result = optimize_move(robot, q0, qf, T, config)
            cpu = time.process_time() - t0
            s = result.summary
            ex = None
            if s.limits_ok:
                ex, _ = rapid_execution(
                    robot, result.optimized, s.energy_optimized_fine_J, measure=s.energy_measure
                )
            row = {
                "task": task,
                "duration_s": T,
                "search": name,
                "cpu_s": round(cpu, 3),
                "planned_saved_pct": round(s.saved_pct, 3),
                "limits_ok": s.limits_ok,
                "executed_saved_pct": None if ex is None else round(ex.executed_saved_pct, 3),
                "executed_lab_saved_pct": None if ex is None else round(ex.executed_saved_lab_pct, 3),
                "executed_vs_plan_pct": None if ex is None else round(ex.executed_energy_vs_plan_pct, 3),
                "written": ex is not None and ex.refusal() is None,
            }
            rows.append(row)
            print(row, flush=True)
            with out_csv.open("w", newline="") as f:
                w = csv.DictWriter(f, fieldnames=list(row))
                w.writeheader()
                w.writerows(rows)
    write_section("via_point_search", report(rows, names, len(tasks), out_csv.name, loads))


def _load() -> float:
    try:
        return float(Path("/proc/loadavg").read_text().split()[0])
    except OSError:
        return float("nan")


def _executed(r: dict[str, Any], key: str = "executed_saved_pct") -> float:
    """The executed saving of a plan, 0 where no module is written (the robot runs its own move)."""
    return float(r[key]) if r["written"] else 0.0


def report(
    rows: list[dict[str, Any]], names: list[str], n_tasks: int, csv_name: str, loads: list[float]
) -> str:
    by = {(r["task"], r["search"]): r for r in rows}
    tasks = list(dict.fromkeys(r["task"] for r in rows))
    base = names[0]
    lines = [
        "## The via-point plan's search: planned and executed saving, CPU (benchmarks/via_point_search.py, issue 36)",
        "",
        f"Machine: {machine()}; one BLAS thread; 1-minute load average {min(loads):.1f} to {max(loads):.1f} "
        f"(median {statistics.median(loads):.1f}) during the run. CPU: `time.process_time` of `optimize_move` "
        "(search and verification). Executed: the plan written as via points and run by the controller "
        "emulation against the controller's own `MoveAbsJ \\T` (0 where the module would be refused), on "
        "the planning model and on the emulated lab robot as its servo tracks the commanded motion. "
        f"{n_tasks} tasks: the fixed task, the README's move, random tasks 0-{n_tasks - 3} (seed 21, as "
        f"benchmarks/rapid_execution.py). Rows: `benchmarks/results/{csv_name}`.",
        "",
        f"| search | what | median CPU | mean CPU | mean planned | mean executed | executed - {base}'s: mean ± s.e. "
        f"| tasks lower by > 0.5 points | executed, lab | lab - {base}'s | written |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name in names:
        rs = [by[(t, name)] for t in tasks if (t, name) in by]
        cpu = [r["cpu_s"] for r in rs]
        diff = [
            _executed(by[(t, name)]) - _executed(by[(t, base)])
            for t in tasks
            if (t, name) in by and (t, base) in by
        ]
        se = statistics.stdev(diff) / len(diff) ** 0.5 if len(diff) > 1 else 0.0
        lower = sum(d < -0.5 for d in diff)
        key = "executed_lab_saved_pct"
        lab = [
            _executed(by[(t, name)], key) - _executed(by[(t, base)], key) for t in tasks if (t, name) in by
        ]
        lab_se = statistics.stdev(lab) / len(lab) ** 0.5 if len(lab) > 1 else 0.0
        lines.append(
            f"| `{name}` | {CANDIDATES[name][0]} | {statistics.median(cpu):.2f} s | {statistics.mean(cpu):.2f} s | "
            f"{statistics.mean(r['planned_saved_pct'] for r in rs):.2f} % | "
            f"{statistics.mean(_executed(r) for r in rs):.2f} % | "
            f"{statistics.mean(diff):+.2f} ± {se:.2f} points | {lower} of {len(diff)} | "
            f"{statistics.mean(_executed(r, key) for r in rs):.2f} % | {statistics.mean(lab):+.2f} ± {lab_se:.2f} points | "
            f"{sum(r['written'] for r in rs)} of {len(rs)} |"
        )
    lines += [
        "",
        "| task | T | " + " | ".join(f"{n}: CPU, planned, executed" for n in names) + " |",
        "|---|---|" + "---|" * len(names),
    ]
    for t in tasks:
        cells = []
        for n in names:
            r = by.get((t, n))
            cells.append(
                "-"
                if r is None
                else f"{r['cpu_s']:.2f} s, {r['planned_saved_pct']:.1f} %, "
                + (f"{r['executed_saved_pct']:.1f} %" if r["written"] else "refused")
            )
        lines.append(f"| {t} | {by[(t, names[0])]['duration_s']:g} s | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
