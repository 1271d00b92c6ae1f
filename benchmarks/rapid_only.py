"""RAPID-only cells: the six bundled programs through `joulepath cycle`, as a user runs it.

Per program, one `--export rapid` run and one `--export auto` run (each its own process, the CLI's
defaults, one BLAS thread): the executed saving of each RAPID candidate, as the controller emulation
runs it against the taught program run by it (via points kept to the plan, where the emulation runs
them as the checks ask, else why not; the controller's levers of the taught program; the plan's via
points with the levers of its via points, searched on the emulation), which one was written, the EGM
plan's saving beside them, what `--export auto` wrote, and each process's wall and CPU time.

Run: ``.venv/bin/python benchmarks/rapid_only.py [PROGRAM ...]``; writes the ``rapid_only`` section
of BENCHMARKS.md (all six) and prints it.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, write_section  # noqa: E402

EXAMPLES = ROOT / "examples"


def run(program: Path, export: str) -> dict[str, object]:
    out = Path(tempfile.mkdtemp(prefix="jp-rapid-only-")) / "run"
    argv = [sys.executable, "-m", "joulepath", "cycle", str(program), "--export", export, "--out", str(out)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, env=env, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    c = json.loads((out / "cycle.json").read_text())
    lev = c.get("rapid_levers") or {}
    via = c.get("rapid_via_levers") or {}
    return {
        "program": program.stem,
        "export": export,
        "exit": done.returncode,
        "via_points_pct": c.get("rapid_via_points_executed_saved_pct"),
        "via_points_refused": c.get("rapid_refused"),
        "levers_pct": lev.get("executed_saved_pct"),
        "levers_changed": lev.get("moves_changed"),
        "via_levers_pct": via.get("executed_saved_pct"),
        "via_levers_note": via.get("note"),
        "via_levers_kept": via.get("optimized_moves_kept_as_taught"),
        "via_levers_dev_mm": via.get("tool0_from_taught_path_mm"),
        "written": c.get("rapid_written_from"),
        "executed_pct": c.get("executed_saved_pct"),
        "executed_cycle_s": c.get("executed_cycle_s"),
        "taught_cycle_s": c.get("default_cycle_s"),
        "egm_plan_pct": c.get("egm_plan_saved_pct"),
        "files": sorted(p.name for p in out.iterdir()),
        "wall_s": wall,
        "cpu_s": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
    }


def _pct(v: object) -> str:
    return "" if v is None else f"{float(v):.1f}"  # type: ignore[arg-type]


def main() -> None:
    names = sys.argv[1:]
    programs = [EXAMPLES / f"{n}.mod" for n in names] if names else sorted(EXAMPLES.glob("*.mod"))
    start = datetime.now(UTC)
    load = [os.getloadavg()[0]]
    commit = subprocess.run(
        ["git", "rev-parse", "--short=10", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=False
    ).stdout.strip()
    rows = []
    for p in programs:
        rapid, auto = run(p, "rapid"), run(p, "auto")
        rows.append((rapid, auto))
        print(json.dumps(rapid), json.dumps(auto), file=sys.stderr, flush=True)
    load.append(os.getloadavg()[0])
    lines = []
    met = 0
    auto_rapid = 0
    for r, a in rows:
        via = _pct(r["via_points_pct"]) or "not written"
        share = (
            None
            if r["executed_pct"] is None or not r["egm_plan_pct"]
            else (
                100 * float(r["executed_pct"]) / float(r["egm_plan_pct"])  # type: ignore[arg-type]
            )
        )
        met += share is not None and share >= 60.0
        wrote = "RAPID" if "optimized.mod" in a["files"] else "no RAPID"  # type: ignore[operator]
        if "egm.mod" in a["files"]:  # type: ignore[operator]
            wrote += " + EGM (RAPID saves less than half of the plan)"
        else:
            auto_rapid += "optimized.mod" in a["files"]  # type: ignore[operator]
        vl = _pct(r["via_levers_pct"]) or f"not written: {r['via_levers_note']}"
        if r["via_levers_pct"] is not None and r["via_levers_kept"]:
            vl += f" ({r['via_levers_kept']} move(s) kept as taught)"
        lines.append(
            f"| {r['program']} | {via} | {_pct(r['levers_pct'])} ({r['levers_changed']}) | {vl} | "
            f"{_pct(r['via_levers_dev_mm'])} | {r['written']} | {_pct(r['executed_pct'])} | "
            f"{_pct(r['egm_plan_pct'])} | {'' if share is None else f'{share:.0f} %'} | {wrote} | "
            f"{float(r['wall_s']):.0f} / {float(a['wall_s']):.0f} | "  # type: ignore[arg-type]
            f"{float(r['cpu_s']):.0f} / {float(a['cpu_s']):.0f} |"  # type: ignore[arg-type]
        )
    end = datetime.now(UTC)
    table = "\n".join(lines)
    body = f"""## RAPID-only cells: the six programs with `--export rapid` and `--export auto` (benchmarks/rapid_only.py)

Machine: {machine()}; each run its own `joulepath cycle` process with the CLI's defaults, one BLAS
thread; load average {load[0]:.1f} at the start and {load[1]:.1f} at the end (the 2 cores shared with
other work: CPU time is the measure). Code: commit {commit} (run {start:%Y-%m-%d %H:%M} to {end:%H:%M} UTC).

Each RAPID candidate as the controller emulation runs it, against the taught program run by it, on
the thesis energy (the CLI's default), at the program's own cycle time:

- *via points*: the plan's via-point module, written only where the emulation keeps the plan (5 mm,
  the planned time), else not written;
- *levers*: the controller's levers (AccSet, speed data or \\T, zones) of the taught program;
- *via points + levers*: the plan's via-point module run as the controller runs it (fitted into the
  taught cycle time where needed), with the levers of its via points searched on the emulation
  (`joulepath.program.via_levers`); "from taught path": the largest distance of its tool0 from the
  taught cycle's tool0 path (the corridor is 100 mm, as the plan keeps it for tool0).

The written module is the best of them; "RAPID / EGM": its executed saving over the EGM plan's
planned saving. `--export auto` writes EGM too where RAPID saves less than half of the plan.

| program | via points, executed % | levers, executed % (moves changed) | via points + levers, executed % | from taught path, mm | written | RAPID executed % | EGM plan % | RAPID / EGM | `--export auto` writes | wall s (rapid / auto) | CPU s (rapid / auto) |
|---|---|---|---|---|---|---|---|---|---|---|---|
{table}

Against the issue's asks: executed saving at least 60 % of the EGM plan's for {met} of {len(rows)}
programs; `--export auto` writes RAPID alone (no EGM recommended) for {auto_rapid} of {len(rows)}.
"""
    if not names:
        write_section("rapid_only", body)
    print(body)


if __name__ == "__main__":
    main()
