"""Jerk limits: what they cost the default optimizer, and the share of the jerk-limited optimum it reaches.

Tasks: the issue's fixed task and the first ``--tasks`` random tasks of ``optimizer_peers.py``'s draw
(``random_tasks(robot, N, seed=11, range_set="lab", jerk_time=0)``: the draw as it was before jerk
limits, T in [1, 3] s); a task whose minimum-jerk move breaks the jerk limit is skipped and counted.
On each task, in this order, in one process on one BLAS/OpenMP thread:

* ``jerk`` — ``optimize_move`` with ``OptimizeConfig(seed=11)``: the default, jerk limits
  ``v_max / ACCEL_TIME / JERK_TIME``;
* ``no-jerk`` — the same with ``jerk_time=0`` (the optimizer as it was before jerk limits);
* ``reference-mj`` and ``reference-ours`` — the reference transcription (IPOPT) with the same
  acceleration and jerk limits, from the minimum-jerk move and from the ``jerk`` path (smoothing
  stages as in ``optimizer_peers.py``); the optimum is the better valid one.

Every path is checked with ``check_limits`` on the 10x grid with the jerk limit; energies and savings
on that grid. Rows go to ``benchmarks/results/optimizer_jerk_*.csv`` as each finishes, so a run
stopped by ``--deadline`` keeps its results; ``--report-only`` writes the BENCHMARKS.md section.

Usage:
    python benchmarks/optimizer_jerk.py --tasks 12 --deadline-utc 09:05
    python benchmarks/optimizer_jerk.py --first 12 --tasks 10 --skip-reference   # more tasks, defaults only
    python benchmarks/optimizer_jerk.py --report-only
"""

from __future__ import annotations

import argparse
import csv
import datetime as dt
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
from optimizer_peers import (  # noqa: E402
    FIXED_TASK,
    REF_CONTINUATION,
    REF_VALID_EXCESS,
    REF_WARM_CONTINUATION,
    fine_path_of,
    load1,
    reference_fine,
    run_timed,
    worst_excess,
)

import joulepath  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.errors import LimitViolation  # noqa: E402
from joulepath.optimize import (  # noqa: E402
    ACCEL_TIME,
    FINE_FACTOR,
    JERK_TIME,
    OptimizeConfig,
    acceleration_limit,
    check_default_feasible,
    check_limits,
    jerk_limit,
    optimize_move,
    path_jerk,
    random_tasks,
)
from joulepath.optimize._reference import reference_optimum  # noqa: E402
from joulepath.optimize._verify import energy_on_samples  # noqa: E402
from joulepath.trajectory import minimum_jerk  # noqa: E402
from joulepath.units import SAMPLE_PERIOD  # noqa: E402

SECTION = "optimizer_jerk"
SEED = 11
FIELDS = (
    "task",
    "T_s",
    "method",
    "energy_J",
    "energy_fine_J",
    "energy_default_J",
    "energy_default_fine_J",
    "saved_pct",
    "saved_fine_pct",
    "limits_ok",
    "max_excess",
    "max_jerk_rad_s3",
    "max_jerk_share",
    "wall_s",
    "cpu_s",
    "load1",
    "status",
)
LABELS = {
    "jerk": f"default with jerk limits (jerk_time {JERK_TIME} s)",
    "no-jerk": "default without jerk limits (jerk_time 0)",
    "reference-mj": "reference with jerk limits, from the minimum-jerk move",
    "reference-ours": "reference with jerk limits, from the jerk-limited default's path",
}


def _task(
    robot: Any,
    name: str,
    q0: np.ndarray,
    qf: np.ndarray,
    T: float,
    amax: np.ndarray,
    jmax: np.ndarray,
    writer: Any,
    fh: Any,
    *,
    skip_reference: bool,
) -> None:
    """Run the four methods on one task; one CSV row each."""
    e_def = energy_on_samples(robot, minimum_jerk(q0, qf, T), friction=NOMINAL_FRICTION)
    e_def_f = energy_on_samples(
        robot, minimum_jerk(q0, qf, T, dt=SAMPLE_PERIOD / FINE_FACTOR), friction=NOMINAL_FRICTION
    )

    def row(method: str, path: Any, fine: Any, wall: float, cpu: float, status: str = "") -> None:
        e = energy_on_samples(robot, path, friction=NOMINAL_FRICTION)
        ef = energy_on_samples(robot, fine, friction=NOMINAL_FRICTION)
        rep = check_limits(robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=jmax)
        jerk = np.abs(path_jerk(fine)[1])
        r = {
            "task": name,
            "T_s": round(T, 3),
            "method": method,
            "energy_J": e,
            "energy_fine_J": ef,
            "energy_default_J": e_def,
            "energy_default_fine_J": e_def_f,
            "saved_pct": 100 * (e_def - e) / e_def,
            "saved_fine_pct": 100 * (e_def_f - ef) / e_def_f,
            "limits_ok": rep.ok,
            "max_excess": worst_excess(rep),
            "max_jerk_rad_s3": float(jerk.max()),
            "max_jerk_share": float((jerk / jmax).max()),
            "wall_s": wall,
            "cpu_s": cpu,
            "load1": load1(),
            "status": status,
        }
        writer.writerow(r)
        fh.flush()
        print(
            f"  {name:>5} {method:<15} fine {ef:8.4f} J saved {r['saved_fine_pct']:5.1f} % ok {rep.ok} "
            f"jerk {r['max_jerk_rad_s3']:8.1f} wall {wall:7.2f} s",
            flush=True,
        )

    print(f"task {name}: T = {T:.3f} s", flush=True)
    jerk_path = None
    for method, cfg in (
        ("jerk", OptimizeConfig(seed=SEED)),
        ("no-jerk", OptimizeConfig(seed=SEED, jerk_time=0)),
    ):
        res, wall, cpu = run_timed(lambda c=cfg: optimize_move(robot, q0, qf, T, c))
        fine = fine_path_of(res, q0, qf, T)
        if fine is None:
            raise RuntimeError(f"task {name} {method}: could not rebuild the fine path")
        row(method, res.optimized, fine, wall, cpu)
        if method == "jerk":
            jerk_path = res.optimized
    if not skip_reference:
        for method, kw in (
            ("reference-mj", {"continuation": REF_CONTINUATION}),
            ("reference-ours", {"initial": jerk_path, "continuation": REF_WARM_CONTINUATION}),
        ):
            ref, wall, cpu = run_timed(
                lambda kw=kw: reference_optimum(
                    robot,
                    q0,
                    qf,
                    T,
                    friction=NOMINAL_FRICTION,
                    acceleration_limit=amax,
                    jerk_limit=jmax,
                    substeps=4,
                    **kw,
                )
            )
            row(method, ref.path, reference_fine(ref.path, T), wall, cpu, ref.status)


def run(args: argparse.Namespace) -> None:
    robot = joulepath.load_robot("irb120")
    amax = acceleration_limit(robot, ACCEL_TIME)
    jmax = jerk_limit(robot, ACCEL_TIME, JERK_TIME)
    assert amax is not None and jmax is not None
    draw = random_tasks(robot, args.first + args.tasks, seed=SEED, range_set="lab", jerk_time=0)
    todo = [("fixed", *FIXED_TASK)] if args.first == 0 else []
    todo += [(str(k), *draw[k]) for k in range(args.first, args.first + args.tasks)]
    stamp = time.strftime("%Y%m%d-%H%M", time.gmtime())
    out = args.out / f"optimizer_jerk_{stamp}.csv"
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    dirty = subprocess.run(
        ["git", "status", "--porcelain", "src"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    meta: dict[str, Any] = {
        "commit": commit.strip(),
        "src_dirty": dirty,
        "machine": machine(),
        "nproc": os.cpu_count(),
        "started_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
        "load_at_start": os.getloadavg(),
        "tasks_asked": args.tasks,
        "first": args.first,
        "reference": not args.skip_reference,
        "skipped_jerk_infeasible": [],
    }
    meta_path = out.with_suffix(".json")
    meta_path.write_text(json.dumps(meta, indent=2))
    fh = out.open("w", newline="")
    writer = csv.DictWriter(fh, fieldnames=FIELDS)
    writer.writeheader()
    longest = 0.0
    for name, q0, qf, T in todo:
        if args.deadline is not None and time.time() + longest > args.deadline:
            print(f"deadline: stopping before task {name}", flush=True)
            break
        try:
            check_default_feasible(robot, q0, qf, T)
        except LimitViolation as err:
            meta["skipped_jerk_infeasible"].append(name)
            print(f"task {name}: skipped ({err})", flush=True)
            continue
        t_task = time.time()
        _task(robot, name, q0, qf, T, amax, jmax, writer, fh, skip_reference=args.skip_reference)
        longest = max(longest, time.time() - t_task)
    fh.close()
    meta.update(finished_utc=time.strftime("%Y-%m-%d %H:%M", time.gmtime()), load_at_end=os.getloadavg())
    meta_path.write_text(json.dumps(meta, indent=2))


def _rows(folder: Path) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    rows, metas = [], []
    for f in sorted(folder.glob("optimizer_jerk_*.csv")):
        metas.append(json.loads(f.with_suffix(".json").read_text()))
        with f.open() as fh:
            for r in csv.DictReader(fh):
                for k in FIELDS:
                    if k not in ("task", "method", "status", "limits_ok"):
                        r[k] = float(r[k]) if r[k] != "" else float("nan")
                r["limits_ok"] = r["limits_ok"] == "True"
                rows.append(r)
    return rows, metas


def _med(values: list[float], spec: str = ".2f") -> str:
    return format(statistics.median(values), spec) if values else "-"


def report(folder: Path) -> str:
    rows, metas = _rows(folder)
    by: dict[str, dict[str, dict[str, Any]]] = {}
    for r in rows:
        by.setdefault(r["task"], {})[r["method"]] = r
    robot = joulepath.load_robot("irb120")
    jmax = jerk_limit(robot, ACCEL_TIME, JERK_TIME)
    assert jmax is not None
    loads = [r["load1"] for r in rows]
    lines = [
        "## Jerk limits (benchmarks/optimizer_jerk.py)",
        "",
        f"Machine: {machine()}; one process, one BLAS/OpenMP thread (`threadpool_limits(1)`, "
        f"`OMP_NUM_THREADS=1`), shared with other work: 1-minute load average {min(loads):.1f} to "
        f"{max(loads):.1f} (median {statistics.median(loads):.1f}) on 2 logical CPUs, so wall times are "
        "longer than on an idle core (CPU time beside them). Code: "
        + "; ".join(
            f"commit {m['commit'][:10]} (run {m['started_utc']} to {m.get('finished_utc', '?')} UTC"
            + (", uncommitted changes in src" if m["src_dirty"] else "")
            + ")"
            for m in metas
        )
        + ".",
        "",
        f"Jerk limit: j_max = v_max / ACCEL_TIME / JERK_TIME = v_max / {ACCEL_TIME} s / {JERK_TIME} s "
        f"({', '.join(f'{j:.0f}' for j in jmax)} rad/s³ for the IRB 120's joints 1-6), the peak jerk of "
        "the emulated controller's sin² ramp to full speed (`joulepath.sim._limits`). Every path checked "
        f"with `check_limits` on the {FINE_FACTOR}x grid (jerk: each 2.5 ms step's mean, `path_jerk`); "
        "savings against the minimum-jerk move, on that grid. Share of the optimum = (E_default_move - "
        "E_method) / (E_default_move - E_optimum), the optimum being the better valid IPOPT solve of the "
        "reference transcription with the same acceleration and jerk limits (from the minimum-jerk move, "
        f"stages {REF_CONTINUATION}, and from the jerk-limited default's path, stages "
        f"{REF_WARM_CONTINUATION}; valid: worst excess on the 10x grid below {REF_VALID_EXCESS}). "
        "Wall and CPU times: the whole `optimize_move` call, or the reference's solve.",
        "",
    ]
    fixed = by.get("fixed", {})
    if "jerk" in fixed and "no-jerk" in fixed:
        lines += [
            "**Fixed task of the issue** (start (0.3, 0.2, -0.4, 0.5, -0.6, 1.0) rad -> end "
            "(-0.9, 0.6, 0.3, -1.2, 0.8, -1.5) rad, T = 1.6 s, with friction):",
            "",
            "| path | energy (samples) | energy (10x grid) | saving (10x grid) | largest jerk (10x grid) "
            "| within every limit, jerk included | wall | CPU |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for m in ("jerk", "no-jerk", "reference-mj", "reference-ours"):
            if m in fixed:
                r = fixed[m]
                lines.append(
                    f"| {LABELS[m]} | {r['energy_J']:.3f} J | {r['energy_fine_J']:.3f} J "
                    f"| {r['saved_fine_pct']:.1f} % | {r['max_jerk_rad_s3']:,.0f} rad/s³ "
                    f"({100 * r['max_jerk_share']:.0f} % of its joint's limit) | {'yes' if r['limits_ok'] else 'no'} "
                    f"| {r['wall_s']:.1f} s | {r['cpu_s']:.1f} s |"
                )
        lines.append("")
    pairs = [m for t, m in by.items() if t != "fixed" and "jerk" in m and "no-jerk" in m]
    if pairs:
        sj = [m["jerk"]["saved_fine_pct"] for m in pairs]
        sn = [m["no-jerk"]["saved_fine_pct"] for m in pairs]
        wj = [m["jerk"]["wall_s"] for m in pairs]
        wn = [m["no-jerk"]["wall_s"] for m in pairs]
        cj = [m["jerk"]["cpu_s"] for m in pairs]
        cn = [m["no-jerk"]["cpu_s"] for m in pairs]
        ratio_s = [a / b for a, b in zip(sj, sn, strict=True) if b > 0]
        ratio_w = [a / b for a, b in zip(wj, wn, strict=True)]
        okj = sum(m["jerk"]["limits_ok"] for m in pairs)
        okn = sum(m["no-jerk"]["limits_ok"] for m in pairs)
        lines += [
            f"**Random tasks: {len(pairs)}** (the first of the seed-{SEED} draw that fit the run's time; "
            f"skipped as jerk-infeasible: {sum(len(m['skipped_jerk_infeasible']) for m in metas)}), with "
            "and without jerk limits, measured in the same run on the same tasks:",
            "",
            "| | with jerk limits | without | ratio (with / without) |",
            "|---|---|---|---|",
            f"| median saving (10x grid) | {_med(sj, '.1f')} % | {_med(sn, '.1f')} % | {_med(sj, '.1f')} / "
            f"{_med(sn, '.1f')} = {statistics.median(sj) / statistics.median(sn):.2f}; per task: median "
            f"{_med(ratio_s)}, min {min(ratio_s):.2f}, max {max(ratio_s):.2f} |",
            f"| mean saving (10x grid) | {statistics.mean(sj):.1f} % | {statistics.mean(sn):.1f} % | "
            f"{statistics.mean(sj) / statistics.mean(sn):.2f} |",
            f"| median wall per move | {_med(wj)} s | {_med(wn)} s | per task: median {_med(ratio_w)}x, "
            f"min {min(ratio_w):.2f}x, max {max(ratio_w):.2f}x |",
            f"| median CPU per move | {_med(cj)} s | {_med(cn)} s | {statistics.median(cj) / statistics.median(cn):.2f}x |",
            f"| median largest jerk (10x grid) | {_med([m['jerk']['max_jerk_rad_s3'] for m in pairs], ',.0f')} "
            f"rad/s³ | {_med([m['no-jerk']['max_jerk_rad_s3'] for m in pairs], ',.0f')} rad/s³ | - |",
            f"| within every limit, jerk included | {okj} of {len(pairs)} | {okn} of {len(pairs)} | - |",
            "",
        ]
        better = [
            (t, m["jerk"]["saved_fine_pct"], m["no-jerk"]["saved_fine_pct"])
            for t, m in by.items()
            if t != "fixed"
            and "jerk" in m
            and "no-jerk" in m
            and m["jerk"]["saved_fine_pct"] > m["no-jerk"]["saved_fine_pct"]
        ]
        if better:
            lines += [
                "A constraint cannot lower the optimum, but both are local searches: on "
                + ", ".join(f"task {t} ({a:.1f} % with, {b:.1f} % without)" for t, a, b in better)
                + " the search without jerk limits ended in a worse local minimum than the one with them.",
                "",
            ]
    shares, worse = [], []
    for t, m in by.items():
        refs = [
            m[k]
            for k in ("reference-mj", "reference-ours")
            if k in m and m[k]["max_excess"] <= REF_VALID_EXCESS
        ]
        if "jerk" not in m or not refs:
            continue
        opt = min(refs, key=lambda r: r["energy_fine_J"])
        gap = opt["energy_default_fine_J"] - opt["energy_fine_J"]
        if gap <= 0:
            continue
        shares.append((t, (m["jerk"]["energy_default_fine_J"] - m["jerk"]["energy_fine_J"]) / gap))
        if opt["energy_fine_J"] > m["jerk"]["energy_fine_J"]:
            worse.append(t)
    n_ref = sum(1 for m in by.values() if "reference-mj" in m)
    if shares:
        vals = [s for _, s in shares]
        low = min(shares, key=lambda x: x[1])
        lines += [
            f"**Share of the jerk-limited optimum** reached by the default with jerk limits: mean "
            f"{100 * statistics.mean(vals):.1f} %, median {100 * statistics.median(vals):.1f} %, lowest "
            f"{100 * low[1]:.1f} % (task {low[0]}), over {len(vals)} tasks"
            + (" (fixed task included)" if "fixed" in dict(shares) else "")
            + f"; the reference ran on {n_ref} tasks"
            + (
                f"; on {len(worse)} of them ({', '.join(worse)}) the best reference ended above the default's "
                "own result (the share there is above 100 %)"
                if worse
                else ""
            )
            + ".",
            "",
        ]
    ref_wall = [m[k]["wall_s"] for m in by.values() for k in ("reference-mj", "reference-ours") if k in m]
    if ref_wall:
        lines.append(f"Reference solves: median {_med(ref_wall, '.0f')} s each (max {max(ref_wall):.0f} s).")
        lines.append("")
    lines.append(f"Raw rows: `benchmarks/results/optimizer_jerk_*.csv` ({len(rows)} rows).")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--tasks", type=int, default=12, help="random tasks of the draw (after the fixed task)"
    )
    parser.add_argument("--first", type=int, default=0, help="first random task (above 0: no fixed task)")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    parser.add_argument(
        "--deadline-utc", default=None, help="HH:MM today (UTC): start no task that may end after it"
    )
    parser.add_argument("--skip-reference", action="store_true")
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    args.deadline = None
    if args.deadline_utc:
        hh, mm = (int(v) for v in args.deadline_utc.split(":"))
        now = dt.datetime.now(dt.UTC)
        args.deadline = now.replace(hour=hh, minute=mm, second=0, microsecond=0).timestamp()
    args.out.mkdir(parents=True, exist_ok=True)
    if not args.report_only:
        run(args)
    text = report(args.out)
    write_section(SECTION, text)
    print(text)


if __name__ == "__main__":
    main()
