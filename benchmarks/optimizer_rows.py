"""Long moves: the default optimizer with the rate rows thinned to each bump's deepest samples
(``THIN_ROWS``) and the knots capped (``max_knots``), against the same search carrying every row
within the band and the knots at their spacing; same tasks, same run.

Only moves longer than ``max_knots`` knots (3.2 s at the default 0.05 s spacing) are solved this
way; shorter ones are unchanged. Tasks: the start and end of the fixed task of ``optimizer_peers.py``
and of the first ``--tasks`` of its seed-11 draw (``random_tasks(robot, N, seed=11,
range_set="lab")``), each at the ``--long`` durations. On each, in one process on one BLAS/OpenMP
thread, ``optimize_move(OptimizeConfig(seed=11))`` twice: as shipped (``thinned``: wider knots,
thinned rows), and as a short move is solved (``all rows``: every row within the band, knots at
their spacing). Every path is checked with ``check_limits`` on the 10x grid (jerk included);
energies and savings on that grid.

Usage:
    python benchmarks/optimizer_rows.py --tasks 3 --long 4 6
    python benchmarks/optimizer_rows.py --report-only
"""

from __future__ import annotations

import argparse
import csv
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
from optimizer_peers import FIXED_TASK, fine_path_of, load1, run_timed  # noqa: E402

import joulepath  # noqa: E402
import joulepath.optimize._gradient as gradient  # noqa: E402
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

SECTION = "optimizer_rows"
SEED = 11
FIELDS = ("task", "T_s", "method", "energy_fine_J", "saved_fine_pct", "limits_ok", "wall_s", "cpu_s", "load1")
SHIPPED = gradient.THIN_ROWS


def _one(robot: Any, q0: np.ndarray, qf: np.ndarray, T: float, thinned: bool) -> tuple[Any, float, float]:
    cfg = OptimizeConfig(seed=SEED)
    if thinned:
        return run_timed(lambda: optimize_move(robot, q0, qf, T, cfg))
    spacing, long = gradient.GradientSettings.spacing_for, gradient.GradientSettings.is_long
    gradient.GradientSettings.spacing_for = lambda self, duration: self.knot_spacing  # type: ignore[method-assign]
    gradient.GradientSettings.is_long = lambda self, duration: False  # type: ignore[method-assign]
    try:
        return run_timed(lambda: optimize_move(robot, q0, qf, T, cfg))
    finally:
        gradient.GradientSettings.spacing_for = spacing  # type: ignore[method-assign]
        gradient.GradientSettings.is_long = long  # type: ignore[method-assign]


def run(args: argparse.Namespace) -> None:
    robot = joulepath.load_robot("irb120")
    amax = acceleration_limit(robot, ACCEL_TIME)
    jmax = jerk_limit(robot, ACCEL_TIME, JERK_TIME)
    draw = random_tasks(robot, args.tasks, seed=SEED, range_set="lab")
    base = [("fixed", *FIXED_TASK[:2]), *((str(k), *draw[k][:2]) for k in range(args.tasks))]
    todo = [(f"{n} at {T:g} s", q0, qf, T) for n, q0, qf in base for T in args.long]
    stamp = time.strftime("%Y%m%d-%H%M", time.gmtime())
    out = args.out / f"optimizer_rows_{stamp}.csv"
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    dirty = subprocess.run(["git", "status", "--porcelain", "src"], cwd=ROOT, capture_output=True, text=True)
    meta = {
        "commit": commit.strip(),
        "src_dirty": dirty.stdout.strip(),
        "machine": machine(),
        "started_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    }
    with out.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=FIELDS)
        writer.writeheader()
        for name, q0, qf, T in todo:
            try:
                check_default_feasible(robot, q0, qf, T)
            except LimitViolation as err:
                print(f"task {name}: skipped ({err})", flush=True)
                continue
            e_def = energy_on_samples(
                robot, minimum_jerk(q0, qf, T, dt=SAMPLE_PERIOD / FINE_FACTOR), friction=NOMINAL_FRICTION
            )
            for method in ("thinned", "all rows"):
                res, wall, cpu = _one(robot, q0, qf, T, method == "thinned")
                fine = fine_path_of(res, q0, qf, T)
                if fine is None:
                    raise RuntimeError(f"task {name} {method}: could not rebuild the fine path")
                e = energy_on_samples(robot, fine, friction=NOMINAL_FRICTION)
                rep = check_limits(
                    robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=jmax
                )
                row = {
                    "task": name,
                    "T_s": round(float(T), 3),
                    "method": method,
                    "energy_fine_J": e,
                    "saved_fine_pct": 100 * (e_def - e) / e_def,
                    "limits_ok": rep.ok,
                    "wall_s": wall,
                    "cpu_s": cpu,
                    "load1": load1(),
                }
                writer.writerow(row)
                fh.flush()
                print(
                    f"{name:>9} {method:<9} {row['saved_fine_pct']:5.1f} % ok {rep.ok} cpu {cpu:6.1f} s",
                    flush=True,
                )
    meta["finished_utc"] = time.strftime("%Y-%m-%d %H:%M", time.gmtime())
    out.with_suffix(".json").write_text(json.dumps(meta, indent=2))


def report(folder: Path) -> str:
    files = sorted(folder.glob("optimizer_rows_*.csv"))
    if not files:
        raise SystemExit("no optimizer_rows_*.csv: run the benchmark first")
    f = files[-1]
    meta = json.loads(f.with_suffix(".json").read_text())
    by: dict[str, dict[str, dict[str, Any]]] = {}
    with f.open() as fh:
        for r in csv.DictReader(fh):
            by.setdefault(r["task"], {})[r["method"]] = r
    lines = [
        "## Long moves: thinned rate rows and capped knots (benchmarks/optimizer_rows.py)",
        "",
        f"Machine: {machine()}; one process, one BLAS/OpenMP thread, shared with other work (CPU time is "
        f"the measure). Code: commit {meta['commit'][:10]}"
        + (" with uncommitted changes in src" if meta["src_dirty"] else "")
        + f" (run {meta['started_utc']} to {meta.get('finished_utc', '?')} UTC).",
        "",
        "`optimize_move` as shipped (the rate rows of a solve thinned to each bump's deepest samples past "
        f"{SHIPPED} rows per variable; at most 64 knot intervals) against the same search with every row "
        "within the band and the knots at their spacing, as a short move is solved. Savings against the "
        "minimum-jerk move on the 10x grid; every path checked there, jerk included.",
        "",
        "| task | T | saving, thinned | saving, all rows | within limits (thinned / all) | CPU thinned | CPU all rows | CPU ratio |",
        "|---|---|---|---|---|---|---|---|",
    ]
    ratios, gaps = [], []
    for name, m in by.items():
        if "thinned" not in m or "all rows" not in m:
            continue
        a, b = m["thinned"], m["all rows"]
        ca, cb = float(a["cpu_s"]), float(b["cpu_s"])
        ratios.append(cb / ca)
        gaps.append(float(a["saved_fine_pct"]) - float(b["saved_fine_pct"]))
        lines.append(
            f"| {name} | {float(a['T_s']):.2f} s | {float(a['saved_fine_pct']):.1f} % | "
            f"{float(b['saved_fine_pct']):.1f} % | {a['limits_ok']} / {b['limits_ok']} | {ca:.1f} s | "
            f"{cb:.1f} s | {cb / ca:.2f}x |"
        )
    lines += [
        "",
        f"Median CPU ratio (all rows / thinned): {statistics.median(ratios):.2f}x (min {min(ratios):.2f}x, "
        f"max {max(ratios):.2f}x); saving thinned minus all rows: median {statistics.median(gaps):+.2f} "
        f"points (min {min(gaps):+.2f}, max {max(gaps):+.2f}), over {len(ratios)} tasks.",
        "",
        f"Raw rows: `benchmarks/results/{f.name}`.",
    ]
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tasks", type=int, default=6)
    p.add_argument("--long", type=float, nargs="+", default=[4.0, 6.0], help="s of the long moves")
    p.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    p.add_argument("--report-only", action="store_true")
    args = p.parse_args()
    if not args.report_only:
        run(args)
    write_section(SECTION, report(args.out))


if __name__ == "__main__":
    main()
