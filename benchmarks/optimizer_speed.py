"""The single-move search's speed and quality with jerk limits on: the default against the search before (issue 36).

On the fixed task of issue 11 and the random tasks of ``benchmarks/optimizer_peers.py`` (seed 11,
lab ranges, T in [1, 3] s; a task whose minimum-jerk move breaks the jerk limit is skipped, as
there), each method runs ``optimize_move`` with ``OptimizeConfig(seed=11, algorithm=...)`` on one
BLAS thread, in the same process, one after the other on each task:

* ``gradient`` — the default search (hull rows for the acceleration and jerk limits,
  preconditioned SLSQP: :class:`joulepath.optimize.GradientSettings`);
* ``gradient-fast`` — the same search on one level of knots twice as wide (``--algo gradient-fast``);
* ``gradient-grid`` — the search before (the same search with a row per point of the fine grid,
  SLSQP in the plain coefficients, ``max_iter`` 200, ``ftol`` 1e-7): the yardstick of the speed-up.

Each result's path on the 10x grid is rebuilt from its coefficients, its energy is measured there
(nominal friction) and its limits are checked there (``check_limits``, acceleration and jerk limits
included). The share of the optimum is ``(E_default_move - E) / (E_default_move - E_optimum)`` on
that grid, with ``E_optimum`` the jerk-limited reference optimum of the same task stored by
``benchmarks/optimizer_peers.py`` (``--reference-csv``; the reference is not rerun here: 70 s of
CPU per task).

Usage:
    python benchmarks/optimizer_speed.py --tasks 20 --fixed
    python benchmarks/optimizer_speed.py --tasks 3 --no-report      # a quick look
"""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

from optimizer_peers import FIXED_TASK, fine_path_of  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

import joulepath  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.errors import LimitViolation  # noqa: E402
from joulepath.optimize import (  # noqa: E402
    ACCEL_TIME,
    FINE_FACTOR,
    JERK_TIME,
    OptimizeConfig,
    acceleration_limit,
    check_default_feasible,
    check_limits,
    jerk_limit,
    optimize_move,
    random_tasks,
)
from joulepath.optimize._verify import energy_on_samples  # noqa: E402
from joulepath.trajectory import minimum_jerk  # noqa: E402
from joulepath.units import SAMPLE_PERIOD  # noqa: E402

SECTION = "optimizer_speed"
METHODS = ("gradient", "gradient-before", "gradient-fast", "gradient-grid")
LABELS = {
    "gradient": "default (`gradient`: hull rows, preconditioned SLSQP)",
    "gradient-before": "the default before (`gradient` of the code given by `--before`, run back to back)",
    "gradient-fast": "`gradient-fast` (`--algo gradient-fast`: one level of knots 0.1 s apart)",
    "gradient-grid": "the search before (`gradient-grid`: fine-grid rows, plain SLSQP)",
}
REFERENCE_CSV = (
    ROOT
    / "benchmarks"
    / "results"
    / "optimizer_peers_jerk_nominal_jerk0.125_fixed_00-19_default-reference.csv"
)
FIELDS = (
    "task",
    "T_s",
    "method",
    "energy_fine_J",
    "energy_default_fine_J",
    "energy_optimum_fine_J",
    "share_of_optimum",
    "limits_ok",
    "package_limits_ok",
    "iterations",
    "evaluations",
    "cpu_s",
    "wall_s",
    "load1",
)


def stored_optima(path: Path) -> dict[str, float]:
    """The jerk-limited reference optimum (fine-grid J) of each task, as optimizer_peers.py stored it."""
    out: dict[str, float] = {}
    with path.open() as fh:
        for r in csv.DictReader(fh):
            if r.get("energy_optimum_fine_J"):
                out[r["task"]] = float(r["energy_optimum_fine_J"])
    return out


def run(args: argparse.Namespace) -> Path:
    robot = joulepath.load_robot("irb120")
    amax = acceleration_limit(robot, ACCEL_TIME)
    jmax = jerk_limit(robot, ACCEL_TIME, JERK_TIME)
    optima = stored_optima(args.reference_csv)
    tasks = random_tasks(robot, args.tasks, seed=args.seed, range_set="lab", jerk_time=0)
    todo = ([("fixed", *FIXED_TASK)] if args.fixed else []) + [(str(k), *t) for k, t in enumerate(tasks)]
    out_csv = args.out / f"optimizer_speed_{time.strftime('%Y%m%d-%H%M')}.csv"
    with out_csv.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=FIELDS)
        writer.writeheader()
        for name, q0, qf, T in todo:
            try:
                check_default_feasible(robot, q0, qf, T, jerk_time=JERK_TIME)
            except LimitViolation:
                print(f"task {name}: skipped (its minimum-jerk move breaks the jerk limit)", flush=True)
                continue
            fine_default = minimum_jerk(q0, qf, T, dt=SAMPLE_PERIOD / FINE_FACTOR)
            e_def = energy_on_samples(robot, fine_default, friction=NOMINAL_FRICTION)
            for method in args.methods.split(","):
                cfg = OptimizeConfig(seed=args.seed, algorithm=method)
                with threadpool_limits(limits=1):
                    w0, c0 = time.perf_counter(), time.process_time()
                    res = optimize_move(robot, q0, qf, T, cfg)
                    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
                fine = fine_path_of(res, q0, qf, T)
                if fine is None:
                    raise RuntimeError(f"task {name}, {method}: the fine path could not be rebuilt")
                e = energy_on_samples(robot, fine, friction=NOMINAL_FRICTION)
                ok = check_limits(
                    robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=jmax
                ).ok
                opt = optima.get(name, float("nan"))
                gap = e_def - opt
                row = {
                    "task": name,
                    "T_s": round(float(T), 3),
                    "method": method,
                    "energy_fine_J": e,
                    "energy_default_fine_J": e_def,
                    "energy_optimum_fine_J": opt,
                    "share_of_optimum": (e_def - e) / gap if gap > 0 else float("nan"),
                    "limits_ok": ok,
                    "package_limits_ok": res.summary.limits_ok,
                    "iterations": res.summary.iterations,
                    "evaluations": res.summary.evaluations,
                    "cpu_s": cpu,
                    "wall_s": wall,
                    "load1": os.getloadavg()[0],
                }
                writer.writerow(row)
                fh.flush()
                print(
                    f"task {name} T={T:.2f} {method}: cpu {cpu:.2f} s share {row['share_of_optimum']:.3f} "
                    f"limits {'ok' if ok else 'BROKEN'}",
                    flush=True,
                )
    return out_csv


def _rows(path: Path, before: Path | None = None) -> list[dict[str, str]]:
    """A run's rows; with ``before``, that run's ``gradient`` rows too, as ``gradient-before``."""
    with path.open() as fh:
        rows = list(csv.DictReader(fh))
    if before is not None:
        with before.open() as fh:
            rows += [
                {**r, "method": "gradient-before"} for r in csv.DictReader(fh) if r["method"] == "gradient"
            ]
    return rows


def _table(path: Path, before: Path | None = None) -> tuple[list[str], list[float], int]:
    """The summary table of one run (its methods against the first one's CPU), its loads and task count."""
    rows = _rows(path, before)
    by: dict[str, dict[str, dict[str, Any]]] = {}
    for r in rows:
        by.setdefault(r["task"], {})[r["method"]] = r
    methods = [m for m in METHODS if all(m in by[t] for t in by)]
    tasks = list(by)
    base = next(m for m in ("gradient-before", "gradient-grid", methods[0]) if m in methods)
    lines = [
        f"Run `{_name(path)}`"
        + ("" if before is None else f" with the before run `{_name(before)}`")
        + f" ({len(tasks)} tasks):",
        "",
        "| method | tasks | median CPU per move | mean CPU | max CPU | mean share of the optimum | "
        f"min share | within limits (10x grid) | median of CPU / {base}'s on the same task |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for m in methods:
        cpu = [float(by[t][m]["cpu_s"]) for t in tasks]
        share = [float(by[t][m]["share_of_optimum"]) for t in tasks]
        ok = [by[t][m]["limits_ok"] == "True" for t in tasks]
        ratio = statistics.median(float(by[t][m]["cpu_s"]) / float(by[t][base]["cpu_s"]) for t in tasks)
        lines.append(
            f"| {LABELS[m]} | {len(tasks)} | {statistics.median(cpu):.2f} s | {statistics.mean(cpu):.2f} s | "
            f"{max(cpu):.2f} s | {100 * statistics.mean(share):.1f} % | {100 * min(share):.1f} % | "
            f"{100 * sum(ok) / len(ok):.0f} % | {ratio:.2f}x |"
        )
    lines += ["", "| task | T s | " + " | ".join(f"{m} CPU s, share" for m in methods) + " |"]
    lines.append("|---|---|" + "---|" * len(methods))
    for t in tasks:
        cells = [
            f"{float(by[t][m]['cpu_s']):.2f}, {100 * float(by[t][m]['share_of_optimum']):.1f} %"
            for m in methods
        ]
        lines.append(f"| {t} | {by[t][methods[0]]['T_s']} | " + " | ".join(cells) + " |")
    return lines, [float(r["load1"]) for r in rows], len(tasks)


def _name(path: Path) -> str:
    return str(path.relative_to(ROOT) if path.is_relative_to(ROOT) else path)


def report(paths: list[Path], before: Path | None = None) -> str:
    lines = [
        "## One move, jerk limits on: the default search against the search before (issue 36)",
        "",
    ]
    loads: list[float] = []
    tables: list[str] = []
    for k, path in enumerate(paths):
        table, load, _ = _table(path, before if k == 0 else None)
        loads += load
        tables += [*table, ""]
    with paths[0].open() as fh:
        first = [r for r in csv.DictReader(fh) if r["method"] == "gradient"]
    med = statistics.median(float(r["cpu_s"]) for r in first)
    share = 100 * statistics.mean(float(r["share_of_optimum"]) for r in first)
    ok = 100 * sum(r["limits_ok"] == "True" for r in first) / len(first)
    lines += [
        f"Against issue 36's targets (first run): median CPU per move {med:.2f} s (target at most 1.0 s: "
        f"{'met' if med <= 1.0 else 'not met'}); mean share of the jerk-limited optimum {share:.1f} % (target at "
        f"least 97 %: {'met' if share >= 97.0 else 'not met'}); within every limit on the 10x grid {ok:.0f} % "
        f"(target 100 %: {'met' if ok == 100 else 'not met'}).",
        "",
    ]
    if before is not None:
        lines += [
            f"The before run (`{before.name}`): this script's `gradient` on the source of the code before "
            "the change (`PYTHONPATH=<its src>`, the commit in the file's name), at the same time as the first "
            "run (the same load), its rows joined to the first run's table as `gradient-before`.",
            "",
        ]
    lines += [
        f"Machine: {machine()}; one BLAS/OpenMP thread; CPU time of the process during `optimize_move` "
        "(`time.process_time`). The machine was shared with other jobs (1-minute load average "
        f"{min(loads):.1f} to {max(loads):.1f}, median {statistics.median(loads):.1f}, on 2 logical CPUs), so wall "
        "times were several times the CPU times; CPU times are what the search itself used, and they too "
        "run somewhat longer on a loaded machine (shared caches). Script: `benchmarks/optimizer_speed.py`.",
        "",
        "Tasks: the fixed task of issue 11 and the random tasks 0-19 of `benchmarks/optimizer_peers.py` "
        "(seed 11; all 21 keep the jerk limit on their minimum-jerk move). Each run has its methods one after "
        "the other on each task, in one process. Share of the optimum = (E_default_move - E) / "
        "(E_default_move - E_optimum) on the 10x grid, E_optimum the jerk-limited reference optimum of the "
        f"same task stored by `benchmarks/optimizer_peers.py` (`{REFERENCE_CSV.name}`; the reference, 70 s "
        "of CPU per task, was not rerun). Limits: `check_limits` on the 10x grid (ranges, speeds, "
        "accelerations, jerks, efforts).",
        "",
        *tables,
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--tasks", type=int, default=20, help="random tasks to draw (from the first)")
    parser.add_argument("--seed", type=int, default=11, help="seed of the task draw and of every search")
    parser.add_argument("--fixed", action="store_true", help="run the issue's fixed task first")
    parser.add_argument("--methods", default="gradient,gradient-grid")
    parser.add_argument("--reference-csv", type=Path, default=REFERENCE_CSV)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    parser.add_argument("--no-report", action="store_true")
    parser.add_argument("--report-only", type=Path, nargs="+", default=None, help="CSVs of earlier runs")
    parser.add_argument(
        "--before",
        type=Path,
        default=None,
        help="CSV of a run of the code before a change (PYTHONPATH=<its src>), on the same tasks: its "
        "gradient rows join the first run's table as gradient-before, the yardstick of the CPU ratio",
    )
    args = parser.parse_args()
    paths = args.report_only if args.report_only is not None else [run(args)]
    if not args.no_report:
        write_section(SECTION, report(paths, args.before))


if __name__ == "__main__":
    main()
