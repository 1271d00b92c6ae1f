"""Published RAPID programs through `joulepath cycle`, as a new user runs them (issue 47, item 8).

The programs are real ones from public GitHub repositories, none written for joulepath. They stay
outside this repository: ``benchmarks/public_programs.toml`` names each one (repository, commit,
paths) and ``--extract`` copies them from fetched snapshots into the programs' folder (default
``/work/public_programs``), one folder per program (a task's modules together, with its EIO.cfg and
MOC.cfg where published).

Each program runs as its own ``joulepath cycle FOLDER --out TMP`` process (one BLAS thread, the
CLI's defaults plus ``--export``/``--robot`` when given), one after another unless ``--jobs`` says
otherwise, stopped (its whole process group) after ``--timeout`` s. Recorded per program: exit
code, wall time, CPU time (user + system of the child, from ``getrusage``), the last line of stderr,
whether a cycle was obtained (exit 0 or 1 with ``cycle.json``), whether a program was written
(``optimized.mod``/``optimized_task`` or ``egm.mod``), the planned saving from ``cycle.json``, and
the class of the refusal, read from the error line only (never from a file's name or text).

Output: a Markdown table by program id (repository and folder name, never the programs' text) with
the counts per class, printed and written to ``OUT/public_programs.md``; the per-program results with
the error lines in ``OUT/public_programs.json`` (OUT defaults to ``/work/public_programs_results``,
outside the repository, as the error lines quote names from the programs).

Run: ``.venv/bin/python benchmarks/public_programs.py [FOLDER] [--export egm] [--jobs 1]
[--timeout 120] [--only SUBSTRING ...]``; ``--extract [MIRRORS]`` first copies the manifest's
programs out of ``MIRRORS/OWNER+REPO/repo`` (``git show COMMIT:PATH``).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from datetime import UTC, datetime
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MANIFEST = Path(__file__).with_suffix(".toml")
PROGRAMS = Path("/work/public_programs")
RESULTS = Path("/work/public_programs_results")

# The class of a refusal, from its error line (and, for a traceback, the whole stderr). First match wins.
CLASSES: list[tuple[str, str, re.Pattern[str]]] = [
    ("traceback", "a Python traceback", re.compile(r"Traceback \(most recent call last\)")),
    (
        "no-plannable-move",
        "no move of the cycle can be planned: its targets are unknown (declared nowhere, or from outside)",
        re.compile(r"no move of the cycle can be planned"),
    ),
    (
        "runtime-targets",
        "targets or routine names that arrive at run time (taken as zeros, or an empty name)",
        re.compile(
            r"out of (the robot's )?reach at \[\s*-?0(\.0+)?,\s*-?0(\.0+)?,|procedure\s{2,}is declared nowhere"
        ),
    ),
    (
        "unknown-routine",
        "a routine declared nowhere and not an instruction joulepath knows (standard RAPID, an option's, "
        "or a module not published)",
        re.compile(
            r"(procedure|function|routine|instruction) \S+ is declared nowhere|not a RAPID instruction|"
            r"unknown (instruction|function|routine)|is not supported"
        ),
    ),
    (
        "incomplete",
        "incomplete task: a data name (tool, work object, signal, constant) declared nowhere",
        re.compile(r"declared nowhere|not declared|undeclared"),
    ),
    (
        "runtime-loop",
        "driven at run time: a loop or wait that never ends with the stand-in values",
        re.compile(r"runs more than|never ends|step budget"),
    ),
    (
        "confdata",
        "confdata that matches no joint solution exactly, or a MoveL that ends in another configuration",
        re.compile(r"confdata", re.I),
    ),
    (
        "linear-path",
        "a MoveL whose straight line leaves the reachable space or passes a singularity",
        re.compile(r"straight line leaves|singularity"),
    ),
    (
        "size-limit",
        "a fixed limit of size or duration",
        re.compile(r"over the limit|limit of \d|at most \d+|too (long|many|large)"),
    ),
    (
        "out-of-reach",
        "out of the IRB 120's reach or joint range (probably a program for another robot)",
        re.compile(
            r"out of (the robot's |this arm's )?reach|unreachable|cannot reach|outside (its|this robot's) range|joint limit|"
            r"beyond its reach|a larger arm"
        ),
    ),
    (
        "duplicate",
        "two modules or routines of one name",
        re.compile(
            r"two modules|also declared|is also in|declared twice|already declared|duplicate|"
            r"more than one (module|routine)",
            re.I,
        ),
    ),
    ("payload", "a tool heavier than the robot's rated payload", re.compile(r"rated payload")),
    ("no-main", "no main routine", re.compile(r"no (routine )?`?main|--routine")),
    (
        "syntax",
        "not read as RAPID: syntax, placeholders (<SMT>), an encrypted module, argument lists",
        re.compile(
            r"syntax|ends without|expected|unexpected|is not RAPID|is an? (FUNC|PROC)|not valid RAPID|binary file|needs an? |"
            r"cannot be assigned|"
            r"placeholder",
            re.I,
        ),
    ),
    (
        "no-motion",
        "no motion in the cycle",
        re.compile(r"holds no move|no move|no motion|does not move the arm"),
    ),
]
TIMEOUT_CLASS = "timeout"


def classify(code: int | None, err: str, got_cycle: bool) -> str:
    """The class of a run, from its exit code and error text only."""
    if code is None:
        return TIMEOUT_CLASS
    if "Traceback (most recent call last)" in err:
        return "traceback"
    if got_cycle:
        return "cycle"
    line = last_line(err)
    for name, _, pattern in CLASSES[1:]:
        if pattern.search(line):
            return name
    return "other"


def last_line(err: str) -> str:
    lines = [ln.strip() for ln in err.strip().splitlines() if ln.strip()]
    return lines[-1] if lines else ""


def load_manifest(path: Path = MANIFEST) -> list[dict[str, object]]:
    return list(tomllib.loads(path.read_text(encoding="utf-8"))["program"])


def extract(manifest: list[dict[str, object]], mirrors: Path, dest: Path) -> None:
    """Copy each program's files from a fetched snapshot (``MIRRORS/OWNER+REPO/repo``) into ``dest/ID``."""
    for p in manifest:
        repo, commit = str(p["repository"]), str(p["commit"])
        base = mirrors / repo.replace("/", "+") / "repo"
        git_dir = base / ".git" if (base / ".git").is_dir() else base
        target = dest / str(p["id"])
        if target.exists():
            shutil.rmtree(target)
        for path in p["paths"]:  # type: ignore[union-attr]
            listing = subprocess.run(
                ["git", f"--git-dir={git_dir}", "ls-tree", "-r", "-z", "--name-only", commit, "--", path],
                capture_output=True,
                check=True,
            ).stdout.decode()
            for name in filter(None, listing.split("\0")):
                rel = (
                    Path(name).name if name == path else Path(Path(path).name) / Path(name).relative_to(path)
                )
                out = target / rel
                out.parent.mkdir(parents=True, exist_ok=True)
                blob = subprocess.run(
                    ["git", f"--git-dir={git_dir}", "show", f"{commit}:{name}"],
                    capture_output=True,
                    check=True,
                )
                out.write_bytes(blob.stdout)
        print(f"extracted {p['id']}", file=sys.stderr)


LARGER_ARMS = ("irb140", "irb1200", "irb1600", "irb2400", "irb2600", "irb4600", "irb6700")
"""The bundled ABB families, smallest first: ``--larger`` retries a program refused as out of reach on
each in turn, and records the first that reads it (the smallest bundled arm its targets fit)."""


def run_one(folder: Path, args: argparse.Namespace) -> dict[str, object]:
    row = _run_one(folder, args, args.robot)
    if getattr(args, "larger", False) and row["class"] == "out-of-reach":
        for arm in LARGER_ARMS:
            again = _run_one(folder, args, arm)
            if again["class"] != "out-of-reach":
                row.update({f"larger_{k}": v for k, v in again.items()}, larger_robot=arm)
                break
    return row


def _run_one(folder: Path, args: argparse.Namespace, robot: str | None) -> dict[str, object]:
    out = Path(tempfile.mkdtemp(prefix="jp-public-")) / "run"
    argv = [sys.executable, "-m", "joulepath", "cycle", str(folder), "--out", str(out)]
    if args.export:
        argv += ["--export", args.export]
    if robot:
        argv += ["--robot", robot]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    started = datetime.now(UTC).strftime("%Y-%m-%d %H:%M")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, start_new_session=True
    )
    try:
        _, err = proc.communicate(timeout=args.timeout)
        code: int | None = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        code, err = None, (err or "") + f"\nstopped after {args.timeout:.0f} s"
    wall = time.perf_counter() - t0
    # CPU time of the children reaped meanwhile: the program's own with --jobs 1 (shared with --jobs > 1).
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    cycle_file = out / "cycle.json"
    got_cycle = code in (0, 1) and cycle_file.is_file()
    row: dict[str, object] = {
        "started": started,
        "exit": code,
        "wall_s": round(wall, 2),
        "cpu_s": round(cpu, 2),
        "cycle": got_cycle,
        "error": last_line(err)[:300] if not got_cycle or code != 0 else "",
        "error_chars": len(last_line(err)),
        "class": classify(code, err, got_cycle),
    }
    if got_cycle:
        try:
            c = json.loads(cycle_file.read_text())
            moves = c.get("moves", [])
            row.update(
                moves=len(moves),
                optimized=sum(bool(m.get("optimized")) for m in moves),
                kept=len(c.get("kept_moves", [])),
                open_pct=c.get("open_to_optimization_pct"),
                saved_pct=c.get("saved_pct"),
                rapid_executed_pct=c.get("executed_saved_pct"),
                assumed=len(c.get("assumed", []) or []),
            )
        except (OSError, ValueError) as exc:
            row["cycle_json_error"] = str(exc)[:120]
    row["written"] = _written(out)
    shutil.rmtree(out.parent, ignore_errors=True)
    return row


def _written(out: Path) -> str:
    parts = []
    if (out / "optimized.mod").is_file() or (out / "optimized_task").is_dir():
        parts.append("RAPID")
    if (out / "egm.mod").is_file():
        parts.append("EGM")
    return " + ".join(parts) or "none"


def commit_of_code() -> str:
    """The code measured: ``JOULEPATH_CODE`` where set (an exported tree), else the git commit of its source."""
    if os.environ.get("JOULEPATH_CODE"):
        return os.environ["JOULEPATH_CODE"]
    try:
        import joulepath

        src = Path(joulepath.__file__).resolve().parent
        head = subprocess.run(
            ["git", "-C", str(src), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        )
        dirty = subprocess.run(
            ["git", "-C", str(src), "status", "--porcelain", "."], capture_output=True, text=True
        )
        return (head.stdout.strip() or "unknown") + (" (with local changes)" if dirty.stdout.strip() else "")
    except Exception:  # noqa: BLE001 - a label only
        return "unknown"


def report(rows: list[dict[str, object]], args: argparse.Namespace) -> str:
    n = len(rows)
    repos = {str(r["repository"]) for r in rows}
    cycles = sum(bool(r["cycle"]) for r in rows)
    written = sum(r["written"] != "none" for r in rows)
    times = sorted(str(r["started"]) for r in rows if r.get("started"))
    when = f"{times[0]} to {times[-1][-5:]}" if times else "not recorded"
    out = [
        f"Date: {when} UTC. Machine: {machine()}; load shared with other work, "
        f"programs run one at a time under `nice`, so CPU s is the measure. Code: joulepath {commit_of_code()}. "
        f"Options: `--export {args.export or 'auto (default)'}`"
        + (f" `--robot {args.robot}`" if args.robot else "")
        + f", stopped after {args.timeout:.0f} s.",
        "",
        f"{n} programs from {len(repos)} repositories: a cycle for **{cycles}** ({100 * cycles / max(n, 1):.0f} %), "
        f"a program written (RAPID or EGM) for **{written}** ({100 * written / max(n, 1):.0f} %).",
        "",
        "| class | programs | IRB 120-sized | larger / unknown | what it is |",
        "|---|---|---|---|---|",
    ]
    described = {name: what for name, what, _ in CLASSES}
    described.update(
        cycle="a cycle (exit 0, or exit 1 with cycle.json)", timeout="no answer in time", other="other"
    )
    counts: dict[str, list[dict[str, object]]] = {}
    for r in rows:
        counts.setdefault(str(r["class"]), []).append(r)
    for cls, members in sorted(counts.items(), key=lambda kv: (kv[0] != "cycle", -len(kv[1]), kv[0])):
        small = sum(str(m["arm"]) == "irb120" for m in members)
        out.append(
            f"| {cls} | {len(members)} | {small} | {len(members) - small} | {described.get(cls, '')} |"
        )
    retried = [r for r in rows if r.get("larger_robot")]
    if retried:
        fit = [r for r in retried if r.get("larger_cycle")]
        arms = ", ".join(f"{r['larger_robot']}" for r in fit)
        out += [
            "",
            f"Out of the IRB 120's reach, retried on the bundled ABB families (smallest first, `--larger`): "
            f"{len(retried)} read by a larger arm, **{len(fit)} get a cycle** with `--robot` named ({arms}); "
            "the others: "
            + (
                ", ".join(sorted({str(r["larger_class"]) for r in retried if not r.get("larger_cycle")}))
                or "none"
            )
            + ".",
        ]
    cpu = [float(r["cpu_s"]) for r in rows if r.get("cpu_s") is not None]
    if cpu:
        out += ["", f"CPU s per program: median {statistics.median(cpu):.1f}, max {max(cpu):.1f}."]
    out += [
        "",
        "| program (repository/folder) | arm (guess) | exit | class | moves | saved % (plan) | written | CPU s | wall s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        saved = "" if r.get("saved_pct") is None else f"{float(r['saved_pct']):.1f}"
        out.append(
            f"| {r['id']} | {r['arm']} | {r['exit'] if r['exit'] is not None else '-'} | {r['class']} | "
            f"{r.get('moves', '')} | {saved} | {r['written']} | "
            f"{'' if r.get('cpu_s') is None else format(float(r['cpu_s']), '.1f')} | {float(r['wall_s']):.1f} |"
        )
    return "\n".join(out) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", nargs="?", type=Path, default=PROGRAMS, help="the programs' folder (ID/...)")
    ap.add_argument("--export", default=None, help="egm, rapid or auto (passed to joulepath cycle)")
    ap.add_argument("--robot", default=None, help="passed to joulepath cycle")
    ap.add_argument(
        "--larger",
        action="store_true",
        help="retry a program refused as out of reach on each bundled ABB family, smallest first",
    )
    ap.add_argument("--timeout", type=float, default=300.0, help="s per program (default 300)")
    ap.add_argument("--jobs", type=int, default=1, help="programs at once (default 1)")
    ap.add_argument("--only", nargs="*", default=[], help="run the programs whose id holds one of these")
    ap.add_argument(
        "--out", type=Path, default=RESULTS, help="folder for the .md and .json (outside the repo)"
    )
    ap.add_argument("--manifest", type=Path, default=MANIFEST)
    ap.add_argument(
        "--extract",
        nargs="?",
        const=Path("/work/.mirror"),
        type=Path,
        default=None,
        help="copy from snapshots first",
    )
    ap.add_argument(
        "--from-json",
        type=Path,
        default=None,
        help="write the report again from a run's JSON (classes from its error lines, arms from the manifest)",
    )
    args = ap.parse_args()
    manifest = load_manifest(args.manifest)
    if args.from_json is not None:
        rows = json.loads(args.from_json.read_text())
        arms = {str(p["id"]): p.get("arm", "unknown") for p in manifest}
        for r in rows:
            r["arm"] = arms.get(str(r["id"]), r.get("arm", "unknown"))
            if r["class"] not in (TIMEOUT_CLASS, "traceback"):
                r["class"] = classify(r["exit"], str(r.get("error", "")), bool(r["cycle"]))
        args.out.mkdir(parents=True, exist_ok=True)
        text = report(rows, args)
        (args.out / "public_programs.md").write_text(text)
        (args.out / "public_programs.json").write_text(json.dumps(rows, indent=1))
        print(text)
        return
    if args.extract is not None:
        extract(manifest, args.extract, args.folder)
    todo = [p for p in manifest if not args.only or any(s in str(p["id"]) for s in args.only)]
    missing = [str(p["id"]) for p in todo if not (args.folder / str(p["id"])).is_dir()]
    if missing:
        sys.exit(
            f"{len(missing)} programs are not in {args.folder} (run with --extract): {', '.join(missing[:5])}"
        )

    def one(p: dict[str, object]) -> dict[str, object]:
        row = {"id": p["id"], "repository": p["repository"], "arm": p.get("arm", "unknown")}
        row.update(run_one(args.folder / str(p["id"]), args))
        print(json.dumps(row), file=sys.stderr, flush=True)
        return row

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        rows = list(pool.map(one, todo))
    args.out.mkdir(parents=True, exist_ok=True)
    text = report(rows, args)
    (args.out / "public_programs.md").write_text(text)
    (args.out / "public_programs.json").write_text(json.dumps(rows, indent=1))
    print(text)


if __name__ == "__main__":
    main()
