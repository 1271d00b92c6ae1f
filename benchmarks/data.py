"""Ingestion and simulation throughput (issue: datasets, item 7).

* ingestion of a ~75k-row controller log (the size of the thesis' 1000-move real set),
  end to end (parse, validate, segment, features, targets) and the parse+validate step
  alone; baseline in the same run: ``pandas.read_csv`` of the same file (parse only);
  target >= 500,000 rows/s;
* simulation: moves per second of the lab and sim plants (plan, plant, log text).

Usage: python benchmarks/data.py [--repeats N]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, median_time, single_core, write_section  # noqa: E402

single_core()

import pandas as pd  # noqa: E402

import joulepath  # noqa: E402
from joulepath.data import ingest, read_log  # noqa: E402
from joulepath.sim import simulate  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    robot = joulepath.load_robot("irb120")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = simulate(Path(tmp) / "real.csv", plant="lab", n_moves=1000, seed=0)
        sim_lab = time.perf_counter() - t0
        t0 = time.perf_counter()
        simulate(Path(tmp) / "sim.csv", plant="sim", n_moves=1000, seed=1)
        sim_sim = time.perf_counter() - t0
        rows = res.n_rows
        t_ingest = median_time(lambda: ingest([res.log]), repeats=args.repeats, warmup=1)
        t_ingest_fk = median_time(lambda: ingest([res.log], robot=robot), repeats=args.repeats, warmup=1)
        t_read = median_time(lambda: read_log(res.log), repeats=args.repeats, warmup=1)
        t_pandas = median_time(lambda: pd.read_csv(res.log), repeats=args.repeats, warmup=1)
        size_mb = res.log.stat().st_size / 1e6
    lines = [
        "## Ingestion and simulation (benchmarks/data.py)",
        "",
        f"Machine: {machine()}; one thread.",
        f"Log: {rows:,} rows ({size_mb:.1f} MB), 1000 simulated lab moves. Target: >= 500,000 rows/s.",
        "",
        "| step | median time | rows/s | vs pandas.read_csv |",
        "|---|---|---|---|",
    ]
    for name, t in (
        ("pandas.read_csv, parse only (baseline)", t_pandas),
        ("read_log: parse + validate", t_read),
        ("ingest: parse, validate, segment, 40 features, targets", t_ingest),
        ("ingest with the robot's TCP check (FK)", t_ingest_fk),
    ):
        lines.append(f"| {name} | {t * 1e3:.1f} ms | {rows / t:,.0f} | {t_pandas / t:.2f}x |")
    lines += [
        "",
        "| simulation (1000 random moves, plan + plant + log text) | wall time | moves/s |",
        "|---|---|---|",
        f"| lab plant (tracking filter, noise) | {sim_lab:.2f} s | {1000 / sim_lab:,.0f} |",
        f"| sim plant | {sim_sim:.2f} s | {1000 / sim_sim:,.0f} |",
        "",
        f"Ingestion end to end: {rows / t_ingest:,.0f} rows/s "
        f"({'meets' if rows / t_ingest >= 5e5 else 'MISSES'} the 500,000 target).",
    ]
    text = "\n".join(lines)
    print(text)
    write_section("data", text)


if __name__ == "__main__":
    main()
