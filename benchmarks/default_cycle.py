"""The default `joulepath cycle` as a user runs it (issue 48): CPU time, the written RAPID's executed
saving and the EGM plan's saving on the six bundled examples, this code beside the code before.

Each program runs as ``joulepath cycle examples/NAME.mod --out TMP`` (the default ``--export auto``,
everything it does by default, written and checked) in a child process; its CPU time (user + system,
children's rusage) is the measure, so a busy machine slows the wall time but not the comparison.
``--before SRC`` also runs the code before a change (``SRC``: a source folder, e.g. ``git archive
a65d0d4 src | tar -x -C /tmp/before`` then ``/tmp/before/src``) right after each program's run, under
the same load. Extra arguments after ``--`` go to both runs (e.g. ``-- --lever-plans 200``).

Usage: ``.venv/bin/python benchmarks/default_cycle.py [--before SRC] [--programs A B] [--repeat N]``
Writes the table to stdout and to BENCHMARKS.md (section ``default_cycle``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, write_section  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = (
    "approach_depart",
    "inspection",
    "machine_tending",
    "palletizing",
    "payload_tool",
    "pick_and_place",
)


def run(program: str, src: Path | None, extra: list[str]) -> dict:
    """One `joulepath cycle` in a child process: CPU s, wall s and the figures of its cycle.json."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "joulepath",
                "cycle",
                str(ROOT / "examples" / f"{program}.mod"),
                "--out",
                str(out),
            ]
            + extra,
            env=env,
            capture_output=True,
            text=True,
            check=False,
        )
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        data = json.loads((out / "cycle.json").read_text()) if (out / "cycle.json").exists() else {}
        written = sorted(p.name for p in out.iterdir()) if out.exists() else []
    return {
        "exit": proc.returncode,
        "cpu_s": cpu,
        "wall_s": wall,
        "executed_saved_pct": data.get("executed_saved_pct"),
        "plan_saved_pct": data.get("saved_pct"),
        "from": data.get("rapid_written_from"),
        "written": "optimized.mod"
        if "optimized.mod" in written
        else "egm.mod"
        if "egm.mod" in written
        else "-",
        "error": proc.stderr.strip().splitlines()[-1][:160] if proc.returncode not in (0, 1) else "",
    }


def _pct(v: float | None) -> str:
    return "-" if v is None else f"{v:.1f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", type=Path, help="a source folder of the code before (PYTHONPATH)")
    ap.add_argument("--programs", nargs="*", default=list(EXAMPLES))
    ap.add_argument("--repeat", type=int, default=1, help="runs per program and code (the median is given)")
    args, extra = ap.parse_known_args()
    extra = [a for a in extra if a != "--"]
    rows = []
    for name in args.programs:
        now = [run(name, None, extra) for _ in range(args.repeat)]
        old = [run(name, args.before, extra) for _ in range(args.repeat)] if args.before else []
        row = {"program": name, "now": now, "before": old}
        rows.append(row)
        med = statistics.median(r["cpu_s"] for r in now)
        print(
            f"{name}: {med:.1f} s CPU, executed {_pct(now[0]['executed_saved_pct'])} %, plan "
            f"{_pct(now[0]['plan_saved_pct'])} %"
            + (
                f"; before {statistics.median(r['cpu_s'] for r in old):.1f} s CPU, "
                f"executed {_pct(old[0]['executed_saved_pct'])} %"
                if old
                else ""
            ),
            flush=True,
        )
    head = "| program | CPU s (now) | executed RAPID saving % | EGM plan saving % | written |"
    sep = "|---|---|---|---|---|"
    if args.before:
        head += " CPU s (before) | ratio | executed % (before) | plan % (before) |"
        sep += "---|---|---|---|"
    lines = [head, sep]
    for row in rows:
        n, o = row["now"], row["before"]
        cpu = statistics.median(r["cpu_s"] for r in n)
        line = (
            f"| {row['program']} | {cpu:.1f} | {_pct(n[0]['executed_saved_pct'])} | {_pct(n[0]['plan_saved_pct'])} | "
            f"{n[0]['written']} ({n[0]['from'] or '-'}) |"
        )
        if o:
            cpu_o = statistics.median(r["cpu_s"] for r in o)
            line += (
                f" {cpu_o:.1f} | {cpu / cpu_o:.2f} | {_pct(o[0]['executed_saved_pct'])} | "
                f"{_pct(o[0]['plan_saved_pct'])} |"
            )
        lines.append(line)
    body = (
        f"Machine: {machine()}. Date: {time.strftime('%Y-%m-%d %H:%M')} UTC. Median of {args.repeat} run(s) per "
        f"program and code; CPU = user + system of the `joulepath cycle` process. Extra options: "
        f"{' '.join(extra) or '(none: the defaults)'}.\n\n" + "\n".join(lines)
    )
    print(body)
    write_section("default_cycle", body)


if __name__ == "__main__":
    main()
