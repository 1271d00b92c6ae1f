"""RAPID-only cells: the six bundled programs through `joulepath cycle --export rapid`, as a user runs it.

Per program: the executed saving of each RAPID module (via points, where the controller emulation
runs them as the checks ask, else why not; the controller's levers, read back and run again), which
one was written, the EGM plan's saving beside them, and the process's wall and CPU time. One BLAS
thread, the CLI's defaults.

Run: ``.venv/bin/python benchmarks/rapid_only.py [PROGRAM ...]``. Prints a Markdown table.
"""

from __future__ import annotations

import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(program: Path) -> dict[str, object]:
    out = Path(tempfile.mkdtemp(prefix="jp-rapid-only-")) / "run"
    argv = [sys.executable, "-m", "joulepath", "cycle", str(program), "--export", "rapid", "--out", str(out)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, env=env, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    c = json.loads((out / "cycle.json").read_text())
    lev = c.get("rapid_levers") or {}
    return {
        "program": program.stem,
        "exit": done.returncode,
        "via_points_pct": c.get("rapid_via_points_executed_saved_pct"),
        "via_points_refused": c.get("rapid_refused"),
        "levers_pct": lev.get("executed_saved_pct"),
        "levers_changed": lev.get("moves_changed"),
        "written": c.get("rapid_written_from"),
        "executed_pct": c.get("executed_saved_pct"),
        "egm_plan_pct": c.get("egm_plan_saved_pct"),
        "wall_s": wall,
        "cpu_s": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
    }


def _pct(v: object) -> str:
    return "" if v is None else f"{float(v):.1f}"  # type: ignore[arg-type]


def main() -> None:
    names = sys.argv[1:]
    programs = [EXAMPLES / f"{n}.mod" for n in names] if names else sorted(EXAMPLES.glob("*.mod"))
    rows = []
    for p in programs:
        row = run(p)
        rows.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)
    print(f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}\n")
    print(
        "| program | via points, executed % | levers, executed % (moves changed) | written | "
        "EGM plan % | RAPID / EGM | wall s | CPU s |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        via = _pct(r["via_points_pct"]) or "not written"
        share = (
            ""
            if r["executed_pct"] is None or not r["egm_plan_pct"]
            else f"{100 * float(r['executed_pct']) / float(r['egm_plan_pct']):.0f} %"  # type: ignore[arg-type]
        )
        print(
            f"| {r['program']} | {via} | {_pct(r['levers_pct'])} ({r['levers_changed']}) | {r['written']} | "
            f"{_pct(r['egm_plan_pct'])} | {share} | {float(r['wall_s']):.0f} | {float(r['cpu_s']):.0f} |"  # type: ignore[arg-type]
        )


if __name__ == "__main__":
    main()
