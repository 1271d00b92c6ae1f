"""Whole cycles of the bundled example programs at their own cycle time: what `joulepath cycle` plans
and writes, against the cycle optimum, and its wall time on one core.

For each program in examples/: the taught cycle (the controller emulation), the plan
(``optimize_cycle`` with the CLI's defaults), what is written (``optimized.mod`` where the
emulation runs it as the checks ask, with its emulated saving; else ``egm.mod`` streaming the
plan), and the cycle optimum: every segment of the taught cycle between two stops of the robot
(:func:`joulepath.optimize.plan_segments`), MoveL included, solved by IPOPT through CasADi
(:func:`joulepath.optimize.segment_optimum`) within the time the taught program gives it, from
the taught motion, on the robot with the segment's tool and load. The optimum's saving is on the
whole cycle's taught energy; the share is the plan's saving over the optimum's. For
pick_and_place, the segments also share the taught cycle's movable time: each solved at 95, 100
and 105 % of its span, the best combination within the sum (``SHARED=0`` skips it).

Run: ``.venv/bin/python benchmarks/cycle_examples.py [PROGRAM ...]`` (one BLAS thread; about 25
minutes on a shared 2-core machine, 16 of them the optimum's 13 segments of palletizing;
``OPTIMUM=0``: the plans only, about 2 minutes; ``FAST=1``: the preset for interactive use;
``GRADIENT=hull``: the plans with the single move's
default search in place of the cycle's, ``joulepath.optimize._gradient.GRID_SEARCH``).
Writes the table to stdout; BENCHMARKS.md holds a copy with the machine.

``--chain``: also the long fly-by chain of issue 36 (``benchmarks/fly_by_chain.mod``: 8 ``MoveJ``
back and forth, ``z10``, a stop once per cycle, about 5.4 s on the IRB 120; its target there is
60 s of CPU), planned and timed as the examples are (``OPTIMUM=0`` for the plan alone).

``--before SRC``: the code before a change beside it, in the same run (issue 36): ``SRC`` a source
folder of it (e.g. ``git archive <commit> src | tar -x -C /tmp/before``, then ``/tmp/before/src``).
Each program's plan is also made by that code, in a child process (``PYTHONPATH=SRC``) started at
the same time as this process's own plan (the same load on the machine), and its CPU time and
saving join a second table beside this code's: CPU before and after, their ratio, both savings.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from joulepath import load_robot  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.optimize._verify import energy_on_samples  # noqa: E402
from joulepath.program import CycleSettings, optimize_cycle, read_cycle_program, write_cycle_run  # noqa: E402
from joulepath.program._cycle import CycleOptimizer  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CHAIN = Path(__file__).resolve().with_name("fly_by_chain.mod")
"""The long fly-by chain of issue 36 (``--chain``)."""
INTERVALS = 8
"""Transcription intervals per piece of the cycle optimum (per line piece, per sub-leg of a joint
piece; 8 agree with the single-move reference within 0.05 %, tests/optimize/test_cycle_reference.py)."""
CONTINUATION = (0.1, 0.03)
"""Smoothing stages of |tau qd| (shares of the mean power): the third stage of the reference (0.01)
changed pick_and_place's LJJJ segment by 0.08 % and took 5 times as long as the first two."""
SEGMENT_LIMIT_S = 300.0
"""IPOPT's wall-time limit per segment (s)."""
PROGRAMS = (
    "pick_and_place",
    "palletizing",
    "machine_tending",
    "inspection",
    "approach_depart",
    "payload_tool",
)


def cycle_optimum_of(opt) -> tuple[float, float, list[str], float]:
    """The optimum over every segment of the taught cycle, each in its taught time.

    (taught J, optimum J, per-segment notes, wall s). A segment whose solve does not end
    feasible counts at its taught energy (0 % saved there): the figure is then a lower
    bound of the optimum's saving, and the note says so.
    """
    from joulepath.optimize import plan_segments, segment_optimum

    taught_J, best_J, notes = 0.0, 0.0, []
    w0 = time.perf_counter()
    for k, seg in enumerate(plan_segments(opt.plan)):
        e0 = energy_on_samples(seg.robot, seg.taught, friction=NOMINAL_FRICTION)
        taught_J += e0
        kinds = "".join("L" if m.line is not None else "J" for m in seg.segment.moves)
        tries = []
        for intervals in (INTERVALS, 2 * INTERVALS):  # a nearly time-optimal taught motion needs finer steps
            res = segment_optimum(
                seg.robot,
                [seg.segment],
                seg.span,
                acceleration_limit=opt.units.amax(seg.robot),
                jerk_limit=opt.units.jmax(seg.robot),
                friction=NOMINAL_FRICTION,
                intervals=intervals,
                initial=[seg.taught],
                continuation=CONTINUATION,
                time_limit_s=SEGMENT_LIMIT_S,
            )
            tries.append(f"{res.wall_s:.0f} s at {intervals}" + ("" if res.feasible else f" ({res.status})"))
            if res.feasible:
                break
        if res.feasible:
            best_J += res.energy_J
            notes.append(f"{k}:{kinds} {100 * (1 - res.energy_J / e0):.1f} %, " + ", ".join(tries))
        else:
            best_J += e0
            notes.append(f"{k}:{kinds} not solved, counted as taught: " + ", ".join(tries))
        print(f"  segment {notes[-1]} (taught {e0:.2f} J, {seg.span:.3f} s)", flush=True)
    return taught_J, best_J, notes, time.perf_counter() - w0


SHARES = (0.95, 1.0, 1.05)
"""Durations tried per segment for the shared-time optimum, as shares of its taught span."""


def shared_optimum(opt) -> tuple[float, float, str, float]:
    """The optimum with the segments sharing the taught cycle's movable time: each segment solved
    at ``SHARES`` of its taught span, the best combination with Σ durations ≤ Σ spans (a lower
    bound of the shared optimum's saving, at least the per-segment one). (taught J, optimum J,
    chosen shares, wall s)."""
    import itertools

    from joulepath.optimize import plan_segments, segment_optimum

    w0 = time.perf_counter()
    segs = plan_segments(opt.plan)
    table: list[dict[float, float]] = []
    for seg in segs:
        row = {}
        for share in SHARES:
            res = segment_optimum(
                seg.robot,
                [seg.segment],
                share * seg.span,
                acceleration_limit=opt.units.amax(seg.robot),
                jerk_limit=opt.units.jmax(seg.robot),
                friction=NOMINAL_FRICTION,
                intervals=INTERVALS,
                initial=[seg.taught],
                continuation=CONTINUATION,
                time_limit_s=SEGMENT_LIMIT_S,
            )
            if res.feasible:
                row[share] = res.energy_J
        table.append(row)
    total = sum(seg.span for seg in segs)
    best, chosen = float("inf"), ()
    for combo in itertools.product(*(sorted(r) for r in table)):
        if sum(c * seg.span for c, seg in zip(combo, segs, strict=True)) <= total + 1e-9:
            e = sum(r[c] for r, c in zip(table, combo, strict=True))
            if e < best:
                best, chosen = e, combo
    taught = sum(energy_on_samples(s.robot, s.taught, friction=NOMINAL_FRICTION) for s in segs)
    return taught, best, "shares " + ", ".join(f"{c:g}" for c in chosen), time.perf_counter() - w0


def plan_settings() -> CycleSettings:
    """The CLI's defaults; ``GRADIENT=hull``: with the single move's default search (hull rows,
    preconditioned SLSQP; issue 36) in place of the cycle's (``GRID_SEARCH``); ``FAST=1``: the
    preset for interactive use (``joulepath.program.FAST_CYCLE``)."""
    if os.environ.get("FAST", "") == "1":
        from joulepath.program import FAST_CYCLE

        return CycleSettings(**FAST_CYCLE)
    if os.environ.get("GRADIENT", "") == "hull":
        from joulepath.optimize import GradientSettings

        return CycleSettings(gradient=GradientSettings())
    return CycleSettings()


def program_path(name: str) -> Path:
    """The RAPID module of a program: one of examples/, or the chain (``fly_by_chain``)."""
    return CHAIN if name == CHAIN.stem else EXAMPLES / f"{name}.mod"


def plan_only(name: str) -> None:
    """The plan of one program, as the table times it; prints {cpu_s, wall_s, saved_pct} (JSON).
    The child process of ``--before``: it runs on whatever ``joulepath`` its PYTHONPATH gives."""
    spec, _ = read_cycle_program(program_path(name), load_robot("irb120"))
    t0, w0 = time.process_time(), time.perf_counter()
    result = optimize_cycle(spec, plan_settings())
    if isinstance(result, tuple):  # the code before issue 46 returned (result, optimizer)
        result = result[0]
    cpu, wall = time.process_time() - t0, time.perf_counter() - w0
    print(json.dumps({"cpu_s": cpu, "wall_s": wall, "saved_pct": result.saved_pct}))


def start_before(name: str, src: Path) -> subprocess.Popen[str]:
    """The plan of ``name`` by the code in ``src``, in a child process (one BLAS thread)."""
    env = {**os.environ, "PYTHONPATH": str(src), "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.Popen(
        [sys.executable, __file__, "--plan-only", name], env=env, stdout=subprocess.PIPE, text=True
    )


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("programs", nargs="*", help="programs of examples/ (default: all six)")
    ap.add_argument("--before", type=Path, help="source folder of the code before (see the docstring)")
    ap.add_argument("--chain", action="store_true", help="also the long fly-by chain (fly_by_chain.mod)")
    ap.add_argument("--plan-only", metavar="PROGRAM", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.plan_only:
        plan_only(args.plan_only)
        return
    names = (tuple(args.programs) or PROGRAMS) + ((CHAIN.stem,) if args.chain else ())
    robot = load_robot("irb120")
    rows = []
    before: dict[str, dict[str, float]] = {}
    for name in names:
        spec, rapid = read_cycle_program(program_path(name), robot)
        child = None if args.before is None else start_before(name, args.before.resolve())
        t0 = time.process_time()
        w0 = time.perf_counter()
        result = optimize_cycle(spec, plan_settings())
        cpu = time.process_time() - t0
        wall = time.perf_counter() - w0
        if child is not None:
            out, _ = child.communicate()
            if child.returncode:
                raise SystemExit(f"{name}: the plan of the code before failed ({child.returncode})")
            before[name] = json.loads(out.strip().splitlines()[-1])
            print(
                f"{name}: before {before[name]['saved_pct']:.2f} % in {before[name]['cpu_s']:.1f} s CPU, "
                f"after {result.saved_pct:.2f} % in {cpu:.1f} s CPU",
                flush=True,
            )
        with tempfile.TemporaryDirectory() as tmp:
            files = write_cycle_run(Path(tmp), result, pareto=None, write_rapid=rapid, egm="fallback")
            data = json.loads(files["cycle.json"].read_text())
        if "optimized.mod" in files:
            written = f"RAPID, emulated {data['executed_saved_pct']:.1f} %"
        else:
            written = f"EGM, {result.saved_pct:.1f} %"
        along = result.breakdown.by_path_retiming_pct
        print(
            f"{name}: {result.saved_pct:.1f} %, {wall:.1f} s"
            + ("" if along is None else f" (of it, segments re-timed along their path: {along:.1f} points)"),
            flush=True,
        )
        n_moves = sum(1 for s in spec.steps if s.kind == "move")
        if os.environ.get("OPTIMUM", "1") == "0":  # the plan only (the optimum does not depend on it)
            rows.append((name, n_moves, result, written, None, None, None, None, [], wall, cpu, None))
            continue
        taught_J, best_J, notes, opt_wall = cycle_optimum_of(CycleOptimizer(spec, CycleSettings()))
        opt_pct = 100 * (taught_J - best_J) / taught_J
        plan_saved = result.default_energy_J - result.optimized_energy_J
        share = 100 * plan_saved / (result.default_energy_J * opt_pct / 100) if opt_pct > 0 else None
        rows.append(
            (name, n_moves, result, written, taught_J, best_J, opt_pct, share, notes, wall, cpu, opt_wall)
        )
        print(
            f"  optimum {opt_pct:.1f} % (taught {taught_J:.2f} J), share {share} , {opt_wall:.0f} s",
            flush=True,
        )
        if name == "pick_and_place" and os.environ.get("SHARED", "1") == "1":
            s_taught, s_best, status, s_wall = shared_optimum(CycleOptimizer(spec, CycleSettings()))
            print(
                f"  shared time: optimum {100 * (s_taught - s_best) / s_taught:.1f} % ({status}), {s_wall:.0f} s",
                flush=True,
            )
    print()
    print(f"Machine: {platform.machine()}, {platform.processor() or platform.platform()}, one BLAS thread")
    print()
    print(
        "| program | moves | cycle taught → planned (s) | energy taught → planned (J) | saved (plan) | written | "
        "optimum (J, saved) | share of it | plan wall / CPU (s) | optimum wall (s) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, n_moves, r, written, _, best_J, opt_pct, share, _, wall, cpu, opt_wall in rows:
        share_txt = "—" if share is None else f"{share:.0f} %"
        best_txt = "not run" if best_J is None else f"{best_J:.2f}, {opt_pct:.1f} %"
        wall_txt = "—" if opt_wall is None else f"{opt_wall:.0f}"
        print(
            f"| {name} | {n_moves} | {r.default_cycle_s:.3f} → {r.optimized_cycle_s:.3f} | "
            f"{r.default_energy_J:.2f} → {r.optimized_energy_J:.2f} | {r.saved_pct:.1f} % | {written} | "
            f"{best_txt} | {share_txt} | {wall:.1f} / {cpu:.1f} | {wall_txt} |"
        )
    print()
    for name, *_, notes, _, _, _ in rows:
        print(f"- {name}: " + "; ".join(notes))
    if before:
        print()
        print(f"The code before: `{args.before}`, each plan in a child process beside this code's.")
        print()
        print("| program | CPU before (s) | CPU after (s) | after / before | saved before | saved after |")
        print("|---|---|---|---|---|---|")
        for name, _, r, *_, cpu, _ in rows:
            b = before[name]
            print(
                f"| {name} | {b['cpu_s']:.1f} | {cpu:.1f} | {cpu / b['cpu_s']:.2f}x | "
                f"{b['saved_pct']:.2f} % | {r.saved_pct:.2f} % |"
            )


if __name__ == "__main__":
    main(sys.argv[1:])
