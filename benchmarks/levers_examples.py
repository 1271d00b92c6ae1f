"""The controller's own levers (AccSet, speed data or \\T, zones) on the bundled example programs.

For each program in examples/: the taught cycle as the controller emulation runs it (the
baseline, measured in the same run), and the program written with the levers that
:func:`joulepath.program._levers.levers_module` finds within the taught cycle time, read back
and run again by the emulation (its executed cycle time and energy on the thesis measure, and
the emulated lab robot's on the same motion). Two search budgets (cycle plans), and, where the
program declares idle waits, the larger budget with them spent on the moves (``use_waits``).
CPU and wall time of each search (one process, one BLAS thread, on a machine shared with other
work: CPU time is the measure).

Run: ``.venv/bin/python benchmarks/levers_examples.py [PROGRAM ...]`` (about 10 minutes of CPU).
Writes the table to stdout and the section "RAPID levers (issue 39)" of BENCHMARKS.md.
"""

from __future__ import annotations

import subprocess
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_core, write_section  # noqa: E402

single_core()

from joulepath import load_robot  # noqa: E402
from joulepath.program import read_cycle_program  # noqa: E402
from joulepath.program._levers import levers_module  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PROGRAMS = (
    "pick_and_place",
    "palletizing",
    "machine_tending",
    "inspection",
    "approach_depart",
    "payload_tool",
)
BUDGETS = (300, 1500)
MEASURE = "thesis"


def main(argv: list[str]) -> int:
    names = argv or list(PROGRAMS)
    robot = load_robot("irb120")
    started = datetime.now(UTC)
    rows = []
    for name in names:
        spec, _ = read_cycle_program(EXAMPLES / f"{name}.mod", robot)
        idle = any(s.kind == "wait" and s.idle for s in spec.steps)
        runs = [(b, False) for b in BUDGETS] + ([(BUDGETS[-1], True)] if idle else [])
        for budget, waits in runs:
            cpu0, wall0 = time.process_time(), time.perf_counter()
            r = levers_module(spec, robot, energy=MEASURE, max_evaluations=budget, use_waits=waits)
            cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
            lab = 100.0 * (1.0 - r.energy_lab_J / r.default_lab_J)
            row = (
                f"| {name} | {budget}{' + idle waits' if waits else ''} | {r.taught_cycle_s:.3f} → {r.cycle_s:.3f} "
                f"| {r.default_energy_J:.2f} → {r.energy_J:.2f} | {r.saved_pct:.1f} % | {lab:.1f} % "
                f"| {r.n_changed}/{len(r.moves)} | {r.n_evaluations} | {'yes' if r.reads_back is None else 'no'} "
                f"| {cpu:.1f} | {wall:.1f} |"
            )
            print(row, flush=True)
            rows.append(row)
    ended = datetime.now(UTC)
    commit = subprocess.run(
        ["git", "rev-parse", "--short=10", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    body = "\n".join(
        [
            "## RAPID levers (issue 39)",
            "",
            f"Machine: {machine()}; one process, one BLAS/OpenMP thread, shared with other work (CPU time is "
            f"the measure). Code: commit {commit} (run {started:%Y-%m-%d %H:%M} to {ended:%Y-%m-%d %H:%M} UTC).",
            "",
            "The controller's own levers, per move statement: `AccSet Acc, Ramp` (Acc 100/70/50/35/25 %, Ramp "
            "100/50/25 %), the speed data (the predefined v-list within two steps; a MoveL never faster than "
            "taught) or a `\\T` stretching the move, and the zone of each fly-by target (the predefined z-list up "
            "to z50); searched by coordinate descent with exchanges on the controller emulation "
            "(`joulepath.program._levers.levers_module`, `benchmarks/levers_examples.py`), never slower than the "
            "taught cycle. Every figure is the written program read back and run again by the emulation "
            f"(its own motion) against the taught program run by the same emulation, energy on the {MEASURE} "
            "measure (lab: the emulated lab robot's torque on the same motion). Budget: the most cycle plans "
            "the search makes; + idle waits: the waits marked `! joulepath: idle` spent on the moves and "
            "shortened by as much. Reads back: the written module gives the same targets and waits with the "
            "chosen settings.",
            "",
            "| program | budget | cycle s (taught → levers) | J (taught → levers) | saved | saved, lab "
            "| moves changed | plans | reads back | CPU s | wall s |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    if not argv:
        write_section("levers_examples", body)
    print(body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
