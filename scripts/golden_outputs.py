"""Outputs of `joulepath cycle` written by one version of the code and compared with another's (issue 46).

A refactor of the program path must leave what a user gets unchanged: the figures, the savings and the
files written (``optimized.mod``, ``egm.mod``, ``cycle.json`` ...). This script runs the same commands
with two source trees and compares what they wrote, byte for byte; in ``cycle.json`` only the keys that
depend on the clock (``wall_s``) are left out, and the figures are compared to 1e-9.

The targets: the six bundled examples and ``examples/cell_task`` with everything `cycle` does by default
(their lever searches are bounded by work, so both versions' searches end the same way); the
programs are named relative to the repository, which is the working folder of every run, so that two
checkouts write the same paths, and every
program of the RAPID corpus (``tests/fixtures/rapid_corpus``) with ``--lever-plans 40`` (its refusals
compared by exit code and line).

Usage::

    git archive BEFORE src | tar -x -C /tmp/before          # the code before the change
    python scripts/golden_outputs.py write /tmp/before/src /tmp/golden-before [--jobs 2]
    python scripts/golden_outputs.py write src /tmp/golden-after
    python scripts/golden_outputs.py compare /tmp/golden-before /tmp/golden-after
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = (
    "approach_depart",
    "inspection",
    "machine_tending",
    "palletizing",
    "payload_tool",
    "pick_and_place",
)
CORPUS = ROOT / "tests" / "fixtures" / "rapid_corpus"
CLOCK_KEYS = {"wall_s"}
REL_TOL = 1e-9


def targets() -> dict[str, list[str]]:
    """Each target's name and its `joulepath cycle` arguments (without ``--out``)."""
    out: dict[str, list[str]] = {name: [f"examples/{name}.mod"] for name in EXAMPLES}
    out["cell_task"] = ["examples/cell_task", "--io", "diBigPart=1"]
    for folder in sorted(p for p in CORPUS.iterdir() if (p / "expect.toml").is_file()):
        expect = tomllib.loads((folder / "expect.toml").read_text(encoding="utf-8"))
        args = [str((folder / p).relative_to(ROOT)) for p in expect["program"]]
        if "routine" in expect:
            args += ["--routine", expect["routine"]]
        for key, value in expect.get("io", {}).items():
            args += ["--io", f"{key}={value}"]
        out[f"corpus/{folder.name}"] = [*args, "--lever-plans", "40"]
    return out


def run_one(src: Path, name: str, args: list[str], dest: Path) -> None:
    out = dest / name
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=str(src.resolve()), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run(
        [sys.executable, "-m", "joulepath", "cycle", *args, "--out", str((out / "run").resolve())],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    # the last line that is not progress (progress lines come at most one a second: which are shown
    # depends on the machine's speed), where it wrote replaced: the paths of two runs differ
    lines = [line for line in proc.stderr.splitlines() if line.strip() and not _CLOCK.match(line)]
    last = lines[-1].replace(str(dest.resolve()), "<out>") if lines else ""
    (out / "exit.json").write_text(
        json.dumps({"rc": proc.returncode, "last_line": last}, indent=1),
        encoding="utf-8",
    )
    print(f"{name}: exit {proc.returncode}", flush=True)


def write(src: Path, dest: Path, jobs: int, only: list[str]) -> None:
    todo = {k: v for k, v in targets().items() if not only or any(o in k for o in only)}
    with ThreadPoolExecutor(jobs) as pool:
        for fut in [pool.submit(run_one, src, k, v, dest) for k, v in todo.items()]:
            fut.result()


_CLOCK = re.compile(r"\[\d+ s\] ")
_SOURCE = re.compile(r"\S*/src/joulepath/")


def _plain(text: str, dest: Path) -> str:
    """A string without what differs between two runs of the same code: the output folder, the
    source tree's location and the elapsed seconds of progress lines."""
    return _SOURCE.sub("src/joulepath/", _CLOCK.sub("", text.replace(str(dest.resolve()), "<out>")))


def _same_json(a: Any, b: Any, where: str, diffs: list[str], dests: tuple[Path, Path]) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if key in CLOCK_KEYS:
                continue
            if key not in a or key not in b:
                diffs.append(f"{where}.{key}: only in {'after' if key in b else 'before'}")
            else:
                _same_json(a[key], b[key], f"{where}.{key}", diffs, dests)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            diffs.append(f"{where}: {len(a)} items before, {len(b)} after")
        for i, (x, y) in enumerate(zip(a, b, strict=False)):
            _same_json(x, y, f"{where}[{i}]", diffs, dests)
    elif isinstance(a, float) and isinstance(b, float):
        if not math.isclose(a, b, rel_tol=REL_TOL, abs_tol=1e-12):
            diffs.append(f"{where}: {a!r} before, {b!r} after")
    elif isinstance(a, str) and isinstance(b, str):
        if where.endswith(".last_line") and (_CLOCK.match(a) or _CLOCK.match(b)):
            return  # a progress line (written before the last line was taken without them): not compared
        if _plain(a, dests[0]) != _plain(b, dests[1]):
            diffs.append(f"{where}: {a[:80]!r} before, {b[:80]!r} after")
    elif a != b:
        diffs.append(f"{where}: {str(a)[:80]!r} before, {str(b)[:80]!r} after")


def differences(before: Path, after: Path) -> list[str]:
    """What differs between the outputs of every target written under ``before`` and under ``after``
    (one line each; none: the same outputs)."""
    diffs: list[str] = []
    names = sorted({p.parent.relative_to(before) for p in before.rglob("exit.json")})
    for name in names:
        a, b = before / name, after / name
        if not (b / "exit.json").is_file():
            diffs.append(f"{name}: not run after")
            continue
        dests = (before, after)
        _same_json(
            json.loads((a / "exit.json").read_text()),
            json.loads((b / "exit.json").read_text()),
            str(name),
            diffs,
            dests,
        )
        files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
        files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
        for f in sorted(files_a ^ files_b):
            diffs.append(f"{name}/{f}: only {'after' if f in files_b else 'before'}")
        for f in sorted(files_a & files_b):
            if f.suffix == ".json":
                ja, jb = json.loads((a / f).read_text()), json.loads((b / f).read_text())
                _same_json(ja, jb, f"{name}/{f}", diffs, dests)
            elif (a / f).read_bytes() != (b / f).read_bytes():
                diffs.append(f"{name}/{f}: bytes differ")
    return diffs


def compare(before: Path, after: Path) -> int:
    diffs = differences(before, after)
    for d in diffs:
        print(d)
    names = {p.parent for p in before.rglob("exit.json")}
    print(f"{len(names)} targets compared, {len(diffs)} differences")
    return 1 if diffs else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("write", help="run every target with the code under SRC, into DEST")
    w.add_argument("src", type=Path)
    w.add_argument("dest", type=Path)
    w.add_argument("--jobs", type=int, default=1)
    w.add_argument("--only", nargs="*", default=[], help="targets whose name contains one of these")
    c = sub.add_parser("compare", help="compare two DESTs")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    ns = ap.parse_args()
    if ns.cmd == "write":
        write(ns.src, ns.dest, ns.jobs, ns.only)
        return 0
    return compare(ns.before, ns.after)


if __name__ == "__main__":
    raise SystemExit(main())
