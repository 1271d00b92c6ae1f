"""Settings of the default gradient search against the stored reference optima (issue 11).

The reference optimum (IPOPT on a direct transcription) costs minutes per task, so this
benchmark reuses the optima that ``optimizer_peers.py`` stored in
``benchmarks/results/optimizer_peers_nominal*.csv`` (the fixed task and the random tasks
that have one) and runs only the default search, ``solve_move`` as ``optimize_move``
calls it (nominal friction, acceleration limits ``v_max / ACCEL_TIME``), once per
settings variant, in the same process and run. Reported per variant: the mean share of
the optimum's saving on the 10x finer grid, limits on that grid, and the median wall and
CPU time per move on one thread. The first variant is the baseline of the ratios.

Usage:
    python benchmarks/optimizer_settings.py     # the shipped default vs. coarse_stages=3 (all stages wide first)
    python benchmarks/optimizer_settings.py --variant "n_starts=2" --variant "coarse_factor=4"
"""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

import joulepath  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.optimize import random_tasks  # noqa: E402
from joulepath.optimize._gradient import GradientSettings, solve_move  # noqa: E402
from joulepath.optimize._run import ACCEL_TIME, acceleration_limit  # noqa: E402
from joulepath.optimize._verify import FINE_FACTOR, check_limits, energy_on_samples  # noqa: E402
from joulepath.trajectory import minimum_jerk  # noqa: E402
from joulepath.units import SAMPLE_PERIOD  # noqa: E402

SECTION = "optimizer_settings"
FIXED = (np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0]), np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5]), 1.6)
SEED = 11  # the draw and searches of optimizer_peers.py


def stored_optima(folder: Path) -> dict[str, float]:
    out: dict[str, float] = {}
    for f in sorted(folder.glob("optimizer_peers_nominal*.csv")):
        with f.open() as fh:
            for row in csv.DictReader(fh):
                if row.get("energy_optimum_fine_J"):
                    out[row["task"]] = float(row["energy_optimum_fine_J"])
    return out


def parse_variant(text: str) -> dict[str, object]:
    out: dict[str, object] = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        key, value = item.split("=")
        out[key.strip()] = float(value) if "." in value or "e" in value else int(value)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--variant", action="append", default=[], help="GradientSettings overrides, k=v,...")
    parser.add_argument("--no-report", action="store_true")
    args = parser.parse_args()
    variants = ["", "coarse_stages=3"] if not args.variant else args.variant
    robot = joulepath.load_robot("irb120")
    optima = stored_optima(ROOT / "benchmarks" / "results")
    numbered = [k for k in optima if k.isdigit()]
    draw = random_tasks(robot, max(int(k) for k in numbered) + 1, seed=SEED, range_set="lab")
    tasks = [("fixed", *FIXED)] if "fixed" in optima else []
    tasks += [(k, *draw[int(k)]) for k in sorted(numbered, key=int)]
    amax = acceleration_limit(robot, ACCEL_TIME)
    results = []
    load_start = os.getloadavg()[0]
    for text in variants:
        settings = replace(GradientSettings(), **parse_variant(text))  # type: ignore[arg-type]
        shares, walls, cpus, ok = [], [], [], 0
        for name, q0, qf, T in tasks:
            w0, c0 = time.perf_counter(), time.process_time()
            with threadpool_limits(limits=1):
                res, problem = solve_move(
                    robot,
                    q0,
                    qf,
                    float(T),
                    friction=NOMINAL_FRICTION,
                    settings=settings,
                    rng=np.random.default_rng(SEED),
                    acceleration_limit=amax,
                )
            walls.append(time.perf_counter() - w0)
            cpus.append(time.process_time() - c0)
            fine = problem.path(res.coefficients.ravel(), fine=True)
            e = energy_on_samples(robot, fine, friction=NOMINAL_FRICTION)
            e_def = energy_on_samples(
                robot,
                minimum_jerk(q0, qf, float(T), dt=SAMPLE_PERIOD / FINE_FACTOR),
                friction=NOMINAL_FRICTION,
            )
            shares.append((e_def - e) / (e_def - optima[name]))
            ok += check_limits(robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax).ok
            print(
                f"{text or 'default':<24} {name:>5} share {shares[-1]:.4f} wall {walls[-1]:.2f} s", flush=True
            )
        results.append((text or "shipped default", shares, walls, cpus, ok))
    base_wall = statistics.median(results[0][2])
    lines = [
        f"Machine: {machine()}; one BLAS thread; run {time.strftime('%Y-%m-%d')}. "
        f"{len(tasks)} tasks with a stored reference optimum (the issue's fixed task and random tasks of "
        f"`optimizer_peers.py`, seed {SEED}, nominal friction); each variant run once per task, in one process. "
        f"1-minute load average {load_start:.1f} at the start and {os.getloadavg()[0]:.1f} at the end on "
        f"{os.cpu_count()} cores (other work shares the machine when it is above 1; the CPU column is the "
        "process's own time).",
        "",
        "| settings | mean share of the optimum | min share | within limits (10x grid) "
        "| median wall s/move | median CPU s/move | wall vs first |",
        "|---|---|---|---|---|---|---|",
    ]
    for text, shares, walls, cpus, ok in results:
        lines.append(
            f"| {text} | {100 * np.mean(shares):.1f} % | {100 * min(shares):.1f} % | {ok}/{len(tasks)} "
            f"| {statistics.median(walls):.2f} | {statistics.median(cpus):.2f} "
            f"| {statistics.median(walls) / base_wall:.2f} |"
        )
    text = "\n".join(lines)
    print(text)
    if not args.no_report:
        write_section(
            SECTION,
            "## Optimizer: settings of the default search (benchmarks/optimizer_settings.py)\n\n" + text,
        )


if __name__ == "__main__":
    main()
