"""Plant throughput with 1 and 2 workers, and the client's peak memory on a plant of 1,000 cells.

Throughput: a generated plant of ``N_THROUGHPUT`` small cells (two short MoveJ from rest to
rest and two waits each, their targets a few mm apart so that every cell has its own input
hash; the electrical measure, 2 table points, 0.2 s knots, one plan) is run by
:func:`joulepath.plant.run_plant` on a local Dask cluster of 1 and then 2 worker processes
(one thread each), each into a fresh folder. Reported: the wall time of the whole run
(cluster start included), and the steady rate: cells finished per second from the first
result to the last (each worker's start, imports and first-call warm-up excluded).

Memory: the client's resident memory (it also hosts the local cluster's scheduler), sampled
every 0.2 s from /proc, against its value just before the run, with 2 workers, on a generated plant
of ``--n-memory`` (1,000) small cells of the same kind, each optimized by the real task:
1,000 futures submitted, 1,000 results streamed back and stored as they finish.

Usage: python benchmarks/plant_throughput.py [--n-throughput 48] [--n-memory 1000]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from datetime import UTC, datetime
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

from joulepath.plant import read_plant, run_plant  # noqa: E402

TOOL = (
    "PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.6, [0, 0, 45], [1, 0, 0, 0], 0, 0, 0]];"
)
FRONT = "[0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
HEAD = """[plant]
name = "{name}"
hours_per_year = 6000
tariff_eur_per_kwh = 0.2
co2_kg_per_kwh = 0.35
[defaults]
energy = "electrical"
rapid_plan = false
retime_segments = false
{extra}
"""


def _program(k: int, zone: str) -> str:
    y = 90 + (k % 40)
    z = 200 + (k // 40) % 25
    return f"""MODULE Cell{k}
    {TOOL}
    CONST robtarget pA := [[380, 175, {z}], {FRONT}];
    CONST robtarget pB := [[380, {y}, 240], {FRONT}];
    PROC main()
        WHILE TRUE DO
            MoveJ pA, v1000, {zone}, tGripper;
            WaitTime 0.8;
            MoveJ pB, v1000, {zone}, tGripper;
            WaitTime 0.6;
        ENDWHILE
    ENDPROC
ENDMODULE
"""


def make_plant(folder: Path, n: int) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    extra = "table_points = 2\nknot_spacing = 0.2\npass_search = 0"
    parts = [HEAD.format(name=f"{n} generated cells", extra=extra)]
    for k in range(n):
        (folder / f"c{k:04d}.mod").write_text(_program(k, "fine"), encoding="utf-8")
        parts.append(f'[[cell]]\nname = "c{k:04d}"\nprogram = "c{k:04d}.mod"\n')
    path = folder / "plant.toml"
    path.write_text("\n".join(parts), encoding="utf-8")
    return path


def _rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def throughput(plant_file: Path, jobs: int, out: Path) -> dict[str, float]:
    plant = read_plant(plant_file)
    finished: list[float] = []
    t0 = time.perf_counter()
    run = run_plant(
        plant, out, jobs=jobs, progress=lambda p: p.cell is not None and finished.append(time.perf_counter())
    )
    wall = time.perf_counter() - t0
    steady = (len(finished) - 1) / (finished[-1] - finished[0]) if len(finished) > 1 else float("nan")
    statuses = [json.loads(p.read_text())["status"] for p in out.glob("cache/*/result.json")]
    return {
        "jobs": jobs,
        "cells": run.n_cells,
        "wall_s": wall,
        "cells_per_s": run.n_cells / wall,
        "steady_cells_per_s": steady,
        "ok": statuses.count("ok"),
    }


def memory(plant_file: Path, out: Path) -> dict[str, float]:
    plant = read_plant(plant_file)
    before = _rss_mib()
    peak = [before]
    stop = threading.Event()

    def sample() -> None:
        while not stop.is_set():
            peak[0] = max(peak[0], _rss_mib())
            time.sleep(0.2)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    t0 = time.perf_counter()
    run = run_plant(plant, out, jobs=2)
    wall = time.perf_counter() - t0
    stop.set()
    sampler.join()
    sizes = [p.stat().st_size for p in out.glob("cache/*/result.json")]
    statuses = [json.loads(p.read_text())["status"] for p in out.glob("cache/*/result.json")]
    return {
        "cells": run.n_cells,
        "ok": statuses.count("ok"),
        "wall_s": wall,
        "rss_before_MiB": before,
        "rss_peak_MiB": max(peak[0], _rss_mib()),
        "result_json_KiB": sum(sizes) / len(sizes) / 1024 if sizes else float("nan"),
    }


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--n-throughput", type=int, default=48)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--n-memory", type=int, default=1000)
    args = parser.parse_args()
    start = datetime.now(UTC)
    load = [os.getloadavg()[0]]
    commit = subprocess.run(
        ["git", "rev-parse", "--short=10", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=False
    ).stdout.strip()
    runs: dict[int, list[dict[str, float]]] = {1: [], 2: []}
    with tempfile.TemporaryDirectory(prefix="plant-bench-") as tmp:
        base = Path(tmp)
        small = make_plant(base / "small", args.n_throughput)
        for rep in range(args.repeats):  # interleaved, so that a change of load hits both
            for jobs in (1, 2):
                row = throughput(small, jobs, base / f"run{jobs}-{rep}")
                runs[jobs].append(row)
                print(row, flush=True)
        load.append(os.getloadavg()[0])
        mem = memory(make_plant(base / "big", args.n_memory), base / "big-run")
        print(mem, flush=True)
    load.append(os.getloadavg()[0])

    def med(jobs: int, key: str) -> float:
        return float(statistics.median(r[key] for r in runs[jobs]))

    ratio_wall = med(2, "cells_per_s") / med(1, "cells_per_s")
    ratio_steady = med(2, "steady_cells_per_s") / med(1, "steady_cells_per_s")
    end = datetime.now(UTC)
    table = "\n".join(
        f"| {jobs} | {rep + 1} | {r['cells']} | {r['wall_s']:.1f} | {r['cells_per_s']:.3f} | "
        f"{r['steady_cells_per_s']:.3f} | {r['ok']} |"
        for rep in range(args.repeats)
        for jobs in (1, 2)
        for r in [runs[jobs][rep]]
    )
    body = f"""## A plant on Dask: throughput with 1 and 2 workers, client memory (benchmarks/plant_throughput.py)

Machine: {machine()}; worker processes pinned to one BLAS/OpenMP thread; load average {load[0]:.1f} at the
start, {load[1]:.1f} after the throughput runs, {load[2]:.1f} at the end. Code: commit {commit}
(run {start:%Y-%m-%d %H:%M} to {end:%H:%M} UTC).

Throughput: a generated plant of {args.n_throughput} small cells (two short MoveJ from rest to rest, two
waits, targets a few mm apart so that each cell has its own input hash; electrical measure, 2 table
points, 0.2 s knots, one plan; each optimized, checked and written by the real task), `run_plant` on a
local cluster of 1 and of 2 worker processes, each run into a fresh folder, {args.repeats} runs each,
interleaved. Steady rate: cells finished per second from the first result to the last (each worker's
start and first-call warm-up excluded).

| workers | run | cells | wall s (cluster start included) | cells/s | steady cells/s | optimized |
|---|---|---|---|---|---|---|
{table}

Medians, 2 workers / 1 worker: **{ratio_wall:.2f}x** on the whole run (cluster start and the last
task's tail included), **{ratio_steady:.2f}x** steady.

Client memory, 2 workers, a generated plant of {mem["cells"]} small cells of the same kind, each
optimized, checked and written by the real task ({mem["ok"]} with status ok). The client's resident memory (it hosts the local
cluster's scheduler too) just before the run and at its peak, sampled every 0.2 s.

| cells | wall s | RSS before MiB | RSS peak MiB | growth MiB | result.json KiB/cell |
|---|---|---|---|---|---|
| {mem["cells"]} | {mem["wall_s"]:.0f} | {mem["rss_before_MiB"]:.0f} | {mem["rss_peak_MiB"]:.0f} | **{mem["rss_peak_MiB"] - mem["rss_before_MiB"]:.0f}** | {mem["result_json_KiB"]:.1f} |

Results stream back one at a time and are written as they come; no cycle's samples reach the client (a
result carries energies, times, the moves and its cycle.json text).
"""
    write_section("plant_throughput", body)
    print(body)


if __name__ == "__main__":
    main()
