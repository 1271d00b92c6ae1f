"""Hostile and long-but-legal inputs of issue 25 under a 6 GiB memory bound: outcome, time, peak memory.

Every case runs the real CLI (``python -m joulepath ...``) in its own process, with its address
space capped by ``resource.setrlimit(RLIMIT_AS, 6 GiB)`` and a wall-clock timeout. Recorded per
case: exit code, the first line of stderr, the number of stderr lines, wall time and the peak
resident memory (``os.wait4``'s ``ru_maxrss`` of that process).

Two sets:

* ``corpus``: every case of the hostile-input corpus of the newer readers
  (``tests/hardening/test_corpus_readers.py``: /dev/zero and FIFO cells, 3 GiB sparse files, tiny
  speeds, ``\\T:=600``, ``WaitTime 3600`` with ``--use-waits``, 10,000 moves and cycle-TOML
  steps, 20,000 boxes, a 900k-triangle STL, 30 doubly-calling procedures, a 1 MB statement, deep
  nesting, 5,000-digit integers, ...), with the same inputs. Expected: its exit code, and for
  exit 2 exactly one line on stderr.
* ``legal``: inputs at the default work limits (``joulepath._work``), which must finish with valid
  output (exit 0 or 1, no traceback), showing progress on stderr while they run.

Usage: python benchmarks/hostile_bounds.py [--timeout S] [--only TEXT] [--set corpus|legal|all]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import re
import resource
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402

_PROGRESS = re.compile(r"\[\d+ s\] ")
SLOW_S = 60.0
"""Cases slower than this are named in the report."""
MEMORY_BOUND = 6 << 30
"""The issue's bound: 6 GiB of address space per command."""
RESULTS = ROOT / "benchmarks" / "results" / "hostile_bounds.json"


@dataclass(frozen=True, slots=True)
class Case:
    """One command: its argv template ({in}, {out}), expected exit codes and how to write its inputs."""

    name: str
    kind: str  # "corpus" or "legal"
    argv: str
    expected: tuple[int, ...]
    write: Callable[[Path], None]
    env: dict[str, str] = field(default_factory=dict)
    what: str = ""


@dataclass(frozen=True, slots=True)
class Outcome:
    """What one run did."""

    name: str
    kind: str
    what: str
    rc: int | None  # None: killed at the timeout
    expected: tuple[int, ...]
    stderr_lines: int
    error_lines: int  # lines of stderr that are not progress lines ("[N s] ...")
    first_stderr: str
    last_stderr: str
    traceback: bool
    wall_s: float
    peak_rss_mib: float

    @property
    def ok(self) -> bool:
        """Ended as expected: its exit code, no traceback, and exit 2 with one error line on stderr
        (after the progress lines of work that ran longer than the progress interval)."""
        if self.rc is None or self.rc not in self.expected or self.traceback:
            return False
        return self.rc != 2 or (self.error_lines == 1 and self.last_stderr.startswith("error: "))


# --------------------------------------------------------------------------- the corpus
def _corpus() -> list[Case]:
    """The hostile-input corpus of the newer readers, as the tests hold it (one definition)."""
    path = ROOT / "tests" / "hardening" / "test_corpus_readers.py"
    spec = importlib.util.spec_from_file_location("_corpus_readers", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    cases = []
    for param in module.CASES:
        template, rc, needle, files = param.values

        def write(folder: Path, files: dict[str, str] = files) -> None:
            module._write_inputs(files, folder)

        cases.append(Case(str(param.id), "corpus", template, (int(rc),), write, what=f"needs {needle!r}"))
    return cases


# --------------------------------------------------------------------------- legal, at the limits
_HEAD = (
    "MODULE Long\n"
    "    PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.6, [0, 0, 45], [1, 0, 0, 0], 0, 0, 0]];\n"
    "    CONST robtarget pA := [[380, 175, 310], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];\n"
    "    CONST robtarget pB := [[380, 185, 310], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];\n"
    "    CONST robtarget pPick := [[175, -375, 140], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];\n"
    "    CONST robtarget pVia := [[350, -130, 500], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];\n"
    "    PROC main()\n"
)


CHAIN = 12
"""Moves of the fly-by chain case (about 3 s in all: within the 10 s limit of one move to optimize)."""


def _module(lines: list[str], decl: str = "") -> str:
    return (
        _HEAD.replace("    PROC main()", decl + "    PROC main()")
        + "".join(f"        {line}\n" for line in lines)
        + "    ENDPROC\nENDMODULE\n"
    )


TWO_STEPS = (
    "[[step]]\njoints_deg = [10, 0, 0, 0, 30, 0]\nduration_s = 1.0\n"
    "[[step]]\njoints_deg = [0, 0, 0, 0, 30, 0]\nduration_s = 1.0\n"
)


def _boxes(n: int) -> str:
    """``n`` small boxes in a grid beyond the robot's reach."""
    return "".join(
        f'[[box]]\nname = "b{i}"\ncenter_mm = [{1500 + (i % 100) * 10}, {(i // 100) * 10}, 0]\n'
        "size_mm = [5, 5, 5]\n"
        for i in range(n)
    )


def _stl(path: Path, n: int) -> None:
    """A binary STL of ``n`` small random triangles 1.5 m from the base (beyond reach)."""
    rng = np.random.default_rng(25)
    rec = np.zeros(n, dtype=[("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
    centres = rng.uniform(-0.1, 0.1, (n, 1, 3)) + np.array([1.5, 0.0, 0.3])
    rec["vertices"] = (centres + rng.uniform(-0.005, 0.005, (n, 3, 3))).astype("<f4")
    path.write_bytes(b"joulepath hostile_bounds".ljust(80) + n.to_bytes(4, "little") + rec.tobytes())


def _files(**files: str | Callable[[Path], None]) -> Callable[[Path], None]:
    def write(folder: Path) -> None:
        for name, data in files.items():
            if isinstance(data, str):
                (folder / name).write_text(data)
            else:
                data(folder / name)

    return write


def _legal() -> list[Case]:
    movel = [f"MoveL {'pB' if k % 2 else 'pA'}, v1000, fine, tGripper;" for k in range(1000)]
    movel_500 = movel[:500]  # 117 s of motion: at the motion limit
    via = "".join(
        f"    CONST robtarget c{k} := [[{175 + 20 * k}, -200, {300 + 10 * (k % 2)}], [0, 0, 1, 0], "
        "[-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];\n"
        for k in range(CHAIN)
    )
    chain = [f"MoveJ c{k}, v1000, {'fine' if k == CHAIN - 1 else 'z10'}, tGripper;" for k in range(CHAIN)]
    steps = "".join(
        f"[[step]]\njoints_deg = [{2 * (k % 2)}, 0, 0, 0, 30, 0]\nduration_s = 0.3\n" for k in range(330)
    )
    mesh = '[[mesh]]\nname = "m"\nfile = "m.stl"\ncenter_mm = [0, 0, 0]\n'
    return [
        Case(
            "legal-cell-1000-boxes",
            "legal",
            "cycle {in}/c.toml --cell {in}/cell.toml --out {out}",
            (0, 1),
            _files(**{"c.toml": TWO_STEPS, "cell.toml": _boxes(1000)}),
            what="a 2-move cycle in a cell of 1,000 boxes (the obstacle limit)",
        ),
        Case(
            "legal-cell-mesh-200k-triangles",
            "legal",
            "cycle {in}/c.toml --cell {in}/cell.toml --out {out}",
            (0, 1),
            _files(**{"c.toml": TWO_STEPS, "cell.toml": mesh, "m.stl": lambda p: _stl(p, 200_000)}),
            what="a 2-move cycle in a cell of one 200,000-triangle STL (the triangle limit)",
        ),
        Case(
            "legal-cycle-toml-330-steps",
            "legal",
            "cycle {in}/c.toml --out {out} --max-time 60",
            (0, 1),
            _files(**{"c.toml": steps}),
            what="330 cycle-TOML steps of 2° in 0.3 s (115 s of motion: the motion limit), --max-time 60",
        ),
        Case(
            "legal-rapid-500-movel",
            "legal",
            "cycle {in}/p.mod --out {out} --max-time 60",
            (0, 1),
            _files(**{"p.mod": _module(movel_500)}),
            what="500 MoveL of 10 mm (117 s of motion: the motion limit), --max-time 60",
        ),
        Case(
            "legal-simulate-500-movel",
            "legal",
            "simulate --program {in}/p.mod --out {out}/a.csv",
            (0,),
            _files(**{"p.mod": _module(movel_500)}),
            what="the same 500 MoveL run on the emulated controller and the lab plant",
        ),
        Case(
            "over-rapid-1000-movel",
            "legal",
            "cycle {in}/p.mod --out {out} --max-time 60",
            (2,),
            _files(**{"p.mod": _module(movel)}),
            what="1,000 MoveL of 10 mm (the moves limit, but 234 s of motion): refused once planned",
        ),
        Case(
            f"legal-rapid-{CHAIN}-movej-fly-by-chain",
            "legal",
            "cycle {in}/p.mod --out {out} --max-time 60",
            (0, 1),
            _files(**{"p.mod": _module(chain, via)}),
            what=f"{CHAIN} MoveJ joined by z10 zones: one fly-by chain, --max-time 60",
        ),
    ]


# --------------------------------------------------------------------------- running
def _limit_memory() -> None:  # in the child, before exec
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_BOUND, MEMORY_BOUND))


def run_case(case: Case, timeout: float) -> Outcome:
    """Run one case in a fresh folder and process; the outcome."""
    import subprocess

    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
        root = Path(tmp)
        inp, out = root / "in", root / "out"
        inp.mkdir()
        case.write(inp)
        argv = [a.replace("{in}", str(inp)).replace("{out}", str(out)) for a in case.argv.split()]
        env = {**os.environ, **case.env, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
        env.pop("JOULEPATH_PROGRESS_S", None)  # the default: at most one progress line per second
        with (root / "stdout").open("wb") as so, (root / "stderr").open("wb") as se:
            t0 = time.perf_counter()
            proc = subprocess.Popen(
                [sys.executable, "-m", "joulepath", *argv],
                cwd=root,
                env=env,
                stdin=subprocess.DEVNULL,
                stdout=so,
                stderr=se,
                preexec_fn=_limit_memory,
                start_new_session=True,
            )
            killed = threading.Event()

            def kill() -> None:
                killed.set()
                os.killpg(proc.pid, signal.SIGKILL)

            timer = threading.Timer(timeout, kill)
            timer.start()
            _, status, usage = os.wait4(proc.pid, 0)
            wall = time.perf_counter() - t0
            timer.cancel()
            proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
        err = (root / "stderr").read_text(errors="replace").replace(f"{root}/", "").splitlines()
    return Outcome(
        name=case.name,
        kind=case.kind,
        what=case.what,
        rc=None if killed.is_set() else proc.returncode,
        expected=case.expected,
        stderr_lines=len(err),
        error_lines=sum(not _PROGRESS.match(line) for line in err),
        first_stderr=err[0][:300] if err else "",
        last_stderr=err[-1][:300] if err else "",
        traceback=any(line.startswith("Traceback") for line in err),
        wall_s=wall,
        peak_rss_mib=usage.ru_maxrss / 1024,  # KiB on Linux
    )


def _cut(text: str, n: int = 150) -> str:
    return text[:n] + ("…" if len(text) > n else "")


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("`", "'")


def report(outcomes: list[Outcome], timeout: float, wall: float, load: tuple[float, float, float]) -> str:
    ok = sum(o.ok for o in outcomes)
    worst_t = max(outcomes, key=lambda o: o.wall_s)
    worst_m = max(outcomes, key=lambda o: o.peak_rss_mib)
    lines = [
        "## Hostile inputs under a 6 GiB memory bound (issue 25)",
        "",
        f"Machine: {machine()}; {_memory_gib():.0f} GiB RAM; load average {load[0]:.1f} at the start "
        f"(shared with other jobs). Script: `benchmarks/hostile_bounds.py` (run {time.strftime('%Y-%m-%d')}, "
        f"{wall / 60:.1f} min).",
        "",
        "Each case is `python -m joulepath ...` in its own process under `RLIMIT_AS` = 6 GiB and a "
        f"{timeout:g} s timeout; peak memory is that process's `ru_maxrss` (`os.wait4`). "
        "`corpus`: every case of `tests/hardening/test_corpus_readers.py`, with its inputs; `legal`: inputs "
        "at the default work limits, which must end with valid output. OK: the expected exit code, no "
        "traceback, and exit 2 with exactly one error line on stderr (progress lines, `[N s] ...`, come "
        "before it only after one second of work; on a terminal they are a transient status instead).",
        "",
        f"**{ok} of {len(outcomes)} as expected.** Slowest: {worst_t.name}, {worst_t.wall_s:.1f} s. "
        f"Most memory: {worst_m.name}, {worst_m.peak_rss_mib:,.0f} MiB (bound: 6,144 MiB).",
        "",
    ]
    slow = [o for o in outcomes if o.wall_s > SLOW_S]
    if slow:
        lines += [
            f"Over {SLOW_S:g} s: "
            + "; ".join(f"{o.name} ({o.wall_s:.0f} s, exit {o.rc})" for o in slow)
            + ". Each showed progress on stderr while it ran; `--max-time` bounds only the optimization, "
            "not the planning of the taught cycle, the set-up of each unit or the check of the written "
            "program, which for MoveL solve the inverse kinematics along every line.",
            "",
        ]
    for kind in ("corpus", "legal"):
        rows = [o for o in outcomes if o.kind == kind]
        if not rows:
            continue
        slow = max(rows, key=lambda o: o.wall_s)
        big = max(rows, key=lambda o: o.peak_rss_mib)
        lines += [
            f"### {kind} ({len(rows)} cases; slowest {slow.wall_s:.1f} s, largest {big.peak_rss_mib:,.0f} MiB)",
            "",
            "| case | exit | OK | stderr lines | wall s | peak MiB | first (and last) stderr line |",
            "|---|---|---|---|---|---|---|",
        ]
        for o in rows:
            rc = "timeout" if o.rc is None else str(o.rc)
            first = _cell(_cut(o.first_stderr))
            if o.stderr_lines > 1:
                first += f" … (last:) {_cell(_cut(o.last_stderr))}"
            name = o.name if not o.what or kind == "corpus" else f"{o.name}: {o.what}"
            lines.append(
                f"| {_cell(name)} | {rc} | {'yes' if o.ok else '**no**'} | {o.stderr_lines} | "
                f"{o.wall_s:.1f} | {o.peak_rss_mib:,.0f} | {first} |"
            )
        lines.append("")
    return "\n".join(lines)


def _memory_gib() -> float:
    for line in Path("/proc/meminfo").read_text().splitlines():
        if line.startswith("MemTotal:"):
            return int(line.split()[1]) / 2**20
    return float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timeout", type=float, default=600.0, help="s per case (default 600)")
    parser.add_argument("--only", default="", help="run only the cases whose name holds this text")
    parser.add_argument("--set", choices=("corpus", "legal", "all"), default="all")
    parser.add_argument("--no-write", action="store_true", help="print, do not write BENCHMARKS.md")
    args = parser.parse_args()
    cases = (_corpus() if args.set != "legal" else []) + (_legal() if args.set != "corpus" else [])
    cases = [c for c in cases if args.only in c.name]
    load = os.getloadavg()
    t0 = time.perf_counter()
    outcomes = []
    for case in cases:
        o = run_case(case, args.timeout)
        outcomes.append(o)
        print(
            f"{o.name}: rc={o.rc} ok={o.ok} {o.wall_s:.1f} s {o.peak_rss_mib:,.0f} MiB "
            f"{o.stderr_lines} line(s), last: {o.last_stderr[:100]}",
            flush=True,
        )
    text = report(outcomes, args.timeout, time.perf_counter() - t0, load)
    print(text)
    if not args.no_write and not args.only and args.set == "all":
        RESULTS.parent.mkdir(parents=True, exist_ok=True)
        data: list[dict[str, Any]] = [{**asdict(o), "ok": o.ok} for o in outcomes]
        RESULTS.write_text(json.dumps(data, indent=1) + "\n")
        write_section("hostile_bounds", text)


if __name__ == "__main__":
    main()
