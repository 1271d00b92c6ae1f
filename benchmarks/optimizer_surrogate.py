"""Speed and physics-verified saving of ``--fitness surrogate`` (issue 11: learned model, <= 5 s per move).

Trains learned energy models the way a user would (docs/how-to/python.md): simulated
lab-plant logs (``--train-moves`` training moves, ``--test-moves`` test moves on another
seed), ``ingest``, ``train(..., TrainConfig(targets=("E",), cv=3, inputs="physics"))`` once
per family (MLP, and the linear ``par`` family), ``best_model(dir, "E")``. Then, on the
issue's fixed task and ``--tasks`` random feasible tasks (``random_tasks(robot, N, seed=11,
range_set="lab")``), runs in the same process:

* ``physics default``: ``OptimizeConfig(seed=11)`` (``auto`` -> ``gradient`` on physics),
  the comparison;
* ``surrogate <family> <algo>``: ``OptimizeConfig(fitness="surrogate", algorithm=algo,
  seed=11)`` with that model, for each ``--algo`` (``auto`` resolves to ``cmaes`` for a
  learned model; other names from ``ALGORITHMS`` that accept the surrogate fitness).

Every result is verified on physics by ``optimize_move`` itself (``result.summary``):
energy of the default and of the optimized path on the physics model (25 ms samples),
limits on the 10x finer grid, evaluations, and the search's wall time. Around each call
the script measures wall (``perf_counter``) and process CPU time (``process_time``),
because the machine may be shared. One BLAS thread (``threadpool_limits(1)``).

Writes ``benchmarks/results/optimizer_surrogate.csv`` (one row per task and method) and
the BENCHMARKS.md section ``optimizer_surrogate``.

Usage:
    OMP_NUM_THREADS=1 python benchmarks/optimizer_surrogate.py                 # 20 tasks + fixed, auto, ga and de
    python benchmarks/optimizer_surrogate.py --tasks 5 --algo auto --family mlp --no-report
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

import joulepath  # noqa: E402
from joulepath.data import ingest  # noqa: E402
from joulepath.learn import TrainConfig, best_model, train  # noqa: E402
from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks  # noqa: E402
from joulepath.optimize._search import ALGORITHMS, resolve_algorithm  # noqa: E402
from joulepath.sim import simulate  # noqa: E402

SECTION = "optimizer_surrogate"
SEED = 11
FIXED = (np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0]), np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5]), 1.6)
GOAL_LEARNED_S = 5.0
GOAL_PHYSICS_S = 2.0
TIE = 1e-9
"""Relative energy difference below which a result counts as the default path (rounding)."""
CSV_PATH = ROOT / "benchmarks" / "results" / "optimizer_surrogate.csv"


def train_models(families: list[str], n_train: int, n_test: int, robot: joulepath.Robot, tmp: Path):
    """One best model for E per family, trained as docs/how-to/python.md shows; with its card's scores."""
    t0 = time.perf_counter()
    tr = ingest([simulate(tmp / "tr.csv", plant="lab", n_moves=n_train, seed=SEED).log], robot=robot)
    te = ingest([simulate(tmp / "te.csv", plant="lab", n_moves=n_test, seed=SEED + 1).log], robot=robot)
    data_s = time.perf_counter() - t0
    models = {}
    for fam in families:
        t0 = time.perf_counter()
        train(tr, te, TrainConfig(families=(fam,), targets=("E",), cv=3, inputs="physics"), tmp / fam)
        model = best_model(tmp / fam, "E")
        models[fam] = (model, time.perf_counter() - t0)
        print(
            f"{fam}: test R² {model.card['test']['r2']:.4f}, grouped CV R² "
            f"{model.card['cv_grouped']['r2_mean']:.4f}, {models[fam][1]:.0f} s",
            flush=True,
        )
    sizes = (len(tr.frame), tr.n_moves, len(te.frame), te.n_moves, data_s)
    return models, sizes


def is_default(row: dict) -> bool:
    """The search returned the default path (its physics energy within rounding of the default's)."""
    return abs(row["saved_J"]) <= TIE * row["energy_default_J"]


def median(values: list[float]) -> float:
    return statistics.median(values) if values else float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--tasks", type=int, default=20, help="random tasks besides the fixed one")
    parser.add_argument(
        "--algo",
        action="append",
        default=[],
        help="search for the surrogate (repeatable; default: auto, ga and de)",
    )
    parser.add_argument(
        "--family", action="append", default=[], help="model family (repeatable; default: mlp and par)"
    )
    parser.add_argument("--train-moves", type=int, default=150)
    parser.add_argument("--test-moves", type=int, default=30)
    parser.add_argument(
        "--no-report", action="store_true", help="print only; leave BENCHMARKS.md and the CSV"
    )
    args = parser.parse_args()
    algos = args.algo or ["auto", "ga", "de"]
    families = args.family or ["mlp", "par"]
    for a in algos:
        resolve_algorithm(a, "surrogate")  # refuses a search that cannot use a learned model
    surrogate_algos = [name for name, spec in ALGORITHMS.items() if "surrogate" in spec.fitness]

    robot = joulepath.load_robot("irb120")
    tasks = [("fixed", *FIXED)] + [
        (str(k), q0, qf, T)
        for k, (q0, qf, T) in enumerate(random_tasks(robot, args.tasks, seed=SEED, range_set="lab"))
    ]
    with tempfile.TemporaryDirectory() as tmpdir:
        models, (n_tr_rows, n_tr_moves, n_te_rows, n_te_moves, data_s) = train_models(
            families, args.train_moves, args.test_moves, robot, Path(tmpdir)
        )
        methods: list[tuple[str, OptimizeConfig, tuple]] = [
            ("physics default", OptimizeConfig(seed=SEED), ())
        ]
        for fam in families:
            # The MLP with the package default first, then the other searches; the linear model with auto only.
            for a in algos if fam == families[0] else algos[:1]:
                cfg = OptimizeConfig(fitness="surrogate", algorithm=a, seed=SEED)
                label = f"surrogate {fam} {a}" + (f" (-> {cfg.search.name})" if a == "auto" else "")
                methods.append((label, cfg, (models[fam][0],)))

        rows = []
        for name, q0, qf, T in tasks:
            for label, cfg, mods in methods:
                w0, c0 = time.perf_counter(), time.process_time()
                with threadpool_limits(limits=1):
                    res = optimize_move(robot, q0, qf, float(T), cfg, models=mods)
                wall, cpu = time.perf_counter() - w0, time.process_time() - c0
                s = res.summary
                saved = s.energy_default_J - s.energy_optimized_J
                rows.append(
                    {
                        "task": name,
                        "duration_s": float(T),
                        "method": label,
                        "algorithm": s.algorithm,
                        "family": mods[0].family if mods else "",
                        "call_wall_s": wall,
                        "call_cpu_s": cpu,
                        "search_wall_s": s.wall_s,
                        "energy_default_J": s.energy_default_J,
                        "energy_optimized_J": s.energy_optimized_J,
                        "saved_J": saved,
                        "saved_pct": s.saved_pct,
                        "energy_default_surrogate_J": s.energy_default_surrogate_J,
                        "energy_optimized_surrogate_J": s.energy_optimized_surrogate_J,
                        "saved_surrogate_pct": (
                            100
                            * (s.energy_default_surrogate_J - s.energy_optimized_surrogate_J)
                            / s.energy_default_surrogate_J
                            if s.energy_default_surrogate_J
                            else None
                        ),
                        "limits_ok": s.limits_ok,
                        "limit_excess": "; ".join(s.limit_excess),
                        "evaluations": s.evaluations,
                        "iterations": s.iterations,
                    }
                )
                print(
                    f"{name:>5} {label:<32} saved {s.saved_pct:6.2f} % (physics) "
                    f"limits {'ok' if s.limits_ok else 'VIOLATED'} call {wall:5.2f} s cpu {cpu:5.2f} s "
                    f"search {s.wall_s:5.2f} s evals {s.evaluations}",
                    flush=True,
                )

    phys = {r["task"]: r for r in rows if r["method"] == "physics default"}
    lines = [
        f"Machine: {machine()}; one BLAS thread; run {time.strftime('%Y-%m-%d')}. "
        "The machine was shared with other jobs: CPU time per call (process_time) is given beside the wall.",
        "",
        f'Learned models (trained as in docs/how-to/python.md, `inputs="physics"`, target E, cv=3, quick grid): '
        f"simulated lab-plant logs, {n_tr_moves} training moves ({n_tr_rows:,} rows, seed {SEED}), "
        f"{n_te_moves} test moves ({n_te_rows:,} rows, seed {SEED + 1}); simulating and ingesting took {data_s:.0f} s.",
        "",
        "| family | test R² (E) | grouped CV R² | training wall s |",
        "|---|---|---|---|",
    ]
    for fam, (model, tsec) in models.items():
        lines.append(
            f"| {fam} | {model.card['test']['r2']:.4f} | {model.card['cv_grouped']['r2_mean']:.4f} | {tsec:.0f} |"
        )
    lines += [
        "",
        f"Tasks: the issue's fixed task (T = {FIXED[2]} s) and {args.tasks} random feasible tasks "
        f'(`random_tasks(robot, {args.tasks}, seed={SEED}, range_set="lab")`, T in [1, 3] s); every method '
        f"on every task, seed {SEED}, in one process. `auto` resolves to `{OptimizeConfig(fitness='surrogate').search.name}` "
        f"for a learned model and to `{OptimizeConfig().search.name}` for physics. Searches that accept the surrogate "
        f"fitness: {', '.join(surrogate_algos)}. Saving: energy on the physics model (25 ms samples) of the "
        "minimum-jerk default minus that of the optimized path, as `optimize_move` verifies it; share: that saving "
        "over the physics default's saving on the same task, mean over tasks where the physics default saves > 0. "
        "Returned the default path: the search kept the minimum-jerk move (saving 0 within rounding).",
        "",
        "| method | tasks | median wall s/move (call) | median CPU s/move (call) | median wall s (search) "
        "| median saving % | mean saving % | min saving % | mean share of physics default's saving "
        "| within limits | returned the default path | median evaluations | median saving predicted by the model % |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    summary = {}
    for label, _, _ in methods:
        rs = [r for r in rows if r["method"] == label]
        shares = [r["saved_J"] / phys[r["task"]]["saved_J"] for r in rs if phys[r["task"]]["saved_J"] > 0]
        ok = sum(bool(r["limits_ok"]) for r in rs)
        walls = [r["call_wall_s"] for r in rs]
        predicted = [r["saved_surrogate_pct"] for r in rs if r["saved_surrogate_pct"] is not None]
        pred = f"{median(predicted):.2f}" if predicted else "-"
        summary[label] = (median(walls), median([r["call_cpu_s"] for r in rs]))
        lines.append(
            f"| {label} | {len(rs)} | {median(walls):.2f} | {summary[label][1]:.2f} "
            f"| {median([r['search_wall_s'] for r in rs]):.2f} "
            f"| {median([r['saved_pct'] for r in rs]):.2f} | {np.mean([r['saved_pct'] for r in rs]):.2f} "
            f"| {min(r['saved_pct'] for r in rs):.2f} "
            f"| {100 * np.mean(shares):.1f} % | {ok}/{len(rs)} ({100 * ok / len(rs):.0f} %) "
            f"| {sum(is_default(r) for r in rs)}/{len(rs)} "
            f"| {median([r['evaluations'] for r in rs]):.0f} "
            f"| {pred} |"
        )
    lost = [
        r for r in rows if r["method"] != "physics default" and r["saved_J"] < -TIE * r["energy_default_J"]
    ]
    failed = [r for r in rows if not r["limits_ok"]]
    lines += [""]
    goals = []
    for label, (wall, cpu) in summary.items():
        goal = GOAL_PHYSICS_S if label == "physics default" else GOAL_LEARNED_S
        goals.append(
            f"{label}: median {wall:.2f} s wall / {cpu:.2f} s CPU per move, "
            f"{'within' if wall <= goal else 'over'} the issue's <= {goal:g} s by wall, "
            f"{'within' if cpu <= goal else 'over'} by CPU"
        )
    lines.append(
        "Against the issue's goals (physics <= 2 s, learned model <= 5 s per move, one core): "
        + "; ".join(goals)
        + "."
    )
    lines.append(
        "Surrogate paths that use more physics energy than the default (beyond rounding, "
        f"{TIE:g} relative): {len(lost)} of "
        f"{sum(r['method'] != 'physics default' for r in rows)}"
        + (f" ({', '.join(sorted({r['method'] for r in lost}))})" if lost else "")
        + f"; results outside a limit (any method): {len(failed)}"
        + (f" ({', '.join(sorted({r['method'] for r in failed}))})" if failed else "")
        + "."
    )
    for r in failed:
        lines.append(f"- task {r['task']}, {r['method']}: {r['limit_excess']}")
    lines.append("")
    lines.append(f"Per task and method: `benchmarks/results/{CSV_PATH.name}`.")
    text = "\n".join(lines)
    print(text)
    if not args.no_report:
        CSV_PATH.parent.mkdir(parents=True, exist_ok=True)
        with CSV_PATH.open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        write_section(
            SECTION,
            "## Optimizer: learned-model fitness, speed and physics-verified saving "
            "(benchmarks/optimizer_surrogate.py)\n\n" + text,
        )


if __name__ == "__main__":
    main()
