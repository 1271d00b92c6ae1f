"""The RAPID corpus through `joulepath cycle`, as a user runs it: moves, optimized, kept (and why),
saving, what was written, and the time each took.

Each program of tests/fixtures/rapid_corpus (and examples/cell_task) runs as its own
``joulepath cycle`` process with the corpus's scenario (``expect.toml``: modules, ``io``,
``routine``), the CLI's defaults and one BLAS thread; the CPU time is the process's own (user +
system, from ``getrusage``), the wall time is measured around it. A refused program is listed with
its exit code and one line. Per program ``--max-time`` is not set: the issue asks each to finish
within 120 s on one core; a run past ``LIMIT`` s (default 600) is stopped and reported as such.

Run: ``.venv/bin/python benchmarks/rapid_corpus.py [NAME ...]`` (the names of corpus folders; all
by default). Prints a Markdown table; BENCHMARKS.md holds a copy with the machine.
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
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT / "tests" / "fixtures" / "rapid_corpus"
LIMIT = float(os.environ.get("LIMIT", "600"))


def cases() -> list[tuple[str, list[Path], dict[str, object], str | None, str]]:
    out = []
    for d in sorted(p for p in CORPUS.iterdir() if p.is_dir()):
        e = tomllib.loads((d / "expect.toml").read_text(encoding="utf-8"))
        out.append(
            (d.name, [d / p for p in e["program"]], dict(e.get("io", {})), e.get("routine"), e["outcome"])
        )
    task = ROOT / "examples" / "cell_task"
    out.append(("examples/cell_task (diBigPart=1)", [task], {"diBigPart": 1, "diPartPresent": 1}, None, "ok"))
    return out


def run(name: str, paths: list[Path], io: dict[str, object], routine: str | None) -> dict[str, object]:
    out = Path(tempfile.mkdtemp(prefix="jp-corpus-")) / "run"
    argv = [sys.executable, "-m", "joulepath", "cycle", *map(str, paths), "--out", str(out)]
    for k, v in io.items():
        argv += ["--io", f"{k}={v}"]
    if routine:
        argv += ["--routine", routine]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    try:
        done = subprocess.run(argv, capture_output=True, text=True, timeout=LIMIT, env=env, check=False)
        code, err = done.returncode, done.stderr
    except subprocess.TimeoutExpired:
        code, err = None, f"stopped after {LIMIT:.0f} s"
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    row: dict[str, object] = {"name": name, "exit": code, "wall_s": wall, "cpu_s": cpu}
    cycle = out / "cycle.json"
    if code == 0 and cycle.is_file():
        c = json.loads(cycle.read_text())
        moves = c["moves"]
        row.update(
            moves=len(moves),
            optimized=sum(bool(m["optimized"]) for m in moves),
            kept_runtime=len(c["kept_moves"]),
            kept_why=sorted({k["why"].split(": ", 1)[-1].split(" (")[0][:60] for k in c["kept_moves"]}),
            open_pct=c["open_to_optimization_pct"],
            saved_pct=c["saved_pct"] if "saved_pct" in c else None,
            default_J=c.get("energy_default_J"),
            optimized_J=c.get("energy_optimized_J"),
            written=_written(out, c),
            rapid_executed_pct=c.get("executed_saved_pct"),
        )
    else:
        row["error"] = (err.strip().splitlines() or [""])[-1][:160]
    return row


def _written(out: Path, c: dict[str, object]) -> str:
    parts = []
    if (out / "optimized.mod").is_file() or (out / "optimized_task").is_dir():
        parts.append(f"RAPID ({c.get('rapid_written_from')})")
    if (out / "egm.mod").is_file():
        parts.append("EGM")
    return " + ".join(parts) or "none"


def main() -> None:
    wanted = set(sys.argv[1:])
    rows = []
    for name, paths, io, routine, outcome in cases():
        if wanted and name not in wanted:
            continue
        row = run(name, paths, io, routine)
        row["expected"] = outcome
        rows.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)
    print(f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}\n")
    print(
        "| program | exit | moves | optimized | kept (run time) | open % | saved % (EGM plan) "
        "| RAPID saved % (executed) | written | CPU s | wall s |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r.get("moves") is None:
            print(
                f"| {r['name']} | {r['exit']} | refused: {r.get('error', '')} | | | | | | | {r['cpu_s']:.1f} | {r['wall_s']:.1f} |"
            )
            continue
        saved = "" if r["saved_pct"] is None else f"{r['saved_pct']:.1f}"
        executed = "" if r.get("rapid_executed_pct") is None else f"{r['rapid_executed_pct']:.1f}"
        print(
            f"| {r['name']} | {r['exit']} | {r['moves']} | {r['optimized']} | {r['kept_runtime']} | "
            f"{r['open_pct']:.0f} | {saved} | {executed} | {r['written']} | {r['cpu_s']:.1f} | {r['wall_s']:.1f} |"
        )


if __name__ == "__main__":
    main()
