# ruff: noqa: E501  (provenance and citation strings, kept whole so they read as one line each)
"""The planned saving per ABB arm of the bundled range, on the nominal model and over its uncertainty.

Per family (its default variant), two point-to-point moves (joint angles clipped to the
arm's ranges) at 1.25 times the shortest duration whose default (minimum-jerk) move
respects every limit of the controller model; three searches, seed 1: the default
(``OptimizeConfig()``), CMA-ES on the nominal model (``algorithm="cmaes"``, the like-for-like
baseline of the robust one) and ``--robust`` (CMA-ES on the expected energy over 16 sampled models,
:class:`joulepath.optimize.ExpectedEnergy`, on its own stream); the planned saving on the nominal model, and its median and 5th percentile over
64 models sampled within the model's stated uncertainty (seed 0); the CPU time of the
search and verification (``time.process_time``). Writes benchmarks/results/abb_range.csv
and prints a markdown table.

Run from the repository root: ``PYTHONPATH=src python scripts/bench_abb_range.py [--only FAMILY]``
(``--only irb2400``: that family's rows, in ``abb_range_irb2400.csv``).
"""

from __future__ import annotations

import csv
import math
import time
from pathlib import Path

import numpy as np

from joulepath import load_robot
from joulepath.description import FAMILY_DEFAULTS, has_axis3_coupling, joints_to_axes, provenance_beside
from joulepath.optimize import (
    ExpectedEnergy,
    OptimizeConfig,
    optimize_move,
    saving_over_uncertainty,
    shortest_feasible_duration,
)
from joulepath.sim import ACCEL_TIME, JERK_TIME, acceleration_limit, jerk_limit
from joulepath.units import SAMPLE_PERIOD

ROOT = Path(__file__).resolve().parents[1]
MOVES = {
    "A": ([-60.0, 10.0, -20.0, 30.0, 40.0, 0.0], [60.0, 40.0, -50.0, -30.0, 60.0, 90.0]),
    "B": ([0.0, -20.0, 20.0, 0.0, 45.0, 0.0], [90.0, 30.0, -10.0, 90.0, -45.0, 180.0]),
}


def main() -> None:
    import sys

    only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None  # e.g. --only irb2400
    rows = []
    for family, variant in FAMILY_DEFAULTS.items():
        if only is not None and family != only:
            continue
        robot = load_robot(variant)
        prov = provenance_beside(robot.source)
        assert prov is not None
        lo, hi = robot.joint_ranges()
        for move, (a, b) in MOVES.items():
            q0 = np.clip(np.radians(a), lo, hi)
            qf = np.clip(np.radians(b), lo, hi)
            shortest = shortest_feasible_duration(
                robot, q0, qf, dt=SAMPLE_PERIOD, friction=robot.friction,
                acceleration_limit=acceleration_limit(robot, ACCEL_TIME),
                jerk_limit=jerk_limit(robot, ACCEL_TIME, JERK_TIME),
            )  # fmt: skip
            assert shortest is not None
            duration = math.ceil(1.25 * shortest / SAMPLE_PERIOD - 1e-9) * SAMPLE_PERIOD
            searches = {
                "default": (OptimizeConfig(seed=1), ()),
                "cmaes": (OptimizeConfig(seed=1, algorithm="cmaes"), ()),
                "robust": (
                    OptimizeConfig(seed=1, algorithm="cmaes", fitness="surrogate"),
                    (
                        ExpectedEnergy(
                            robot,
                            prov.uncertainty,
                            rng=np.random.default_rng(np.random.SeedSequence(1).spawn(1)[0]),
                        ),
                    ),
                ),
            }
            for search, (config, models) in searches.items():
                cpu = time.process_time()
                result = optimize_move(robot, q0, qf, duration, config, models=models)
                cpu = time.process_time() - cpu
                s = result.summary
                desc = robot.description
                if desc is not None and has_axis3_coupling(
                    desc
                ):  # the controller's axis 3 (q2 + q3) in its range
                    axis3 = joints_to_axes(desc, result.optimized.q)[:, 2]
                    lo3, hi3 = np.radians(-60.0), np.radians(65.0)
                    print(
                        f"  axis 3 (q2 + q3) {np.degrees(axis3.min()):.1f}..{np.degrees(axis3.max()):.1f} deg, "
                        f"within -60..65: {bool(axis3.min() >= lo3 and axis3.max() <= hi3)}"
                    )
                stated = saving_over_uncertainty(
                    robot, result.default, result.optimized, prov.uncertainty, seed=0
                )
                rows.append(
                    {
                        "robot": variant, "move": move, "search": search, "duration_s": round(duration, 3),
                        "limits_ok": s.limits_ok, "default_J": round(s.energy_default_J, 1),
                        "optimized_J": round(s.energy_optimized_J, 1),
                        "nominal_pct": round(stated.nominal_pct, 1), "median_pct": round(stated.median_pct, 1),
                        "p5_pct": round(stated.p5_pct, 1), "cpu_s": round(cpu, 2),
                    }
                )  # fmt: skip
                print(rows[-1], flush=True)
    out = ROOT / "benchmarks" / "results" / (f"abb_range_{only}.csv" if only else "abb_range.csv")
    with out.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(
        "| arm | move | search | T s | default J | optimized J | saved (nominal) | median | 5th pct | CPU s |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['robot']} | {r['move']} | {r['search']} | {r['duration_s']:g} | {r['default_J']:g} | "
            f"{r['optimized_J']:g} | {r['nominal_pct']:.1f} % | {r['median_pct']:.1f} % | {r['p5_pct']:.1f} % | "
            f"{r['cpu_s']:.2f} |"
        )


if __name__ == "__main__":
    main()
