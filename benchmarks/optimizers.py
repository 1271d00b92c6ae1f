"""Optimizer cost per generation and the thesis' optimizer benchmark (issue: optimizer, items 6 and 8).

1. One generation of population 100 (T = 1 s: 41 samples per path) with the
   learned fitness (an MLP trained on simulated lab data, raw and physics inputs)
   and with the physics fitness; target <= 10 ms (learned) and <= 20 ms (physics)
   on one core. Baseline measured in the same run: the thesis' way of evaluating
   (one Python call per individual).
2. bench-optimizers on random tasks (physics fitness, and the surrogate when
   trained models are at hand), improvement % both ways beside the thesis' figures.

Usage: python benchmarks/optimizers.py [--tasks N] [--generations N]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, median_time, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402

import joulepath  # noqa: E402
from joulepath.data import ingest  # noqa: E402
from joulepath.learn import TrainConfig, best_model, train  # noqa: E402
from joulepath.optimize import TrajectoryProblem, bench_optimizers, thesis_configurations  # noqa: E402
from joulepath.sim import simulate  # noqa: E402

THESIS = {
    "GA random P(C)=0.95 P(M)=0.05": "51.96 ± 0.21 (best GA, Table 4.5)",
    "MA random local search": "52.59 ± 0.21 (20.12 s)",
    "MA informed local search": "59.79 ± 0.18 (9.56 s)",
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--tasks", type=int, default=20)
    parser.add_argument("--generations", type=int, default=60)
    args = parser.parse_args()
    robot = joulepath.load_robot("irb120")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        tr = ingest([simulate(d / "tr.csv", plant="lab", n_moves=150, seed=11).log], robot=robot)
        te = ingest([simulate(d / "te.csv", plant="lab", n_moves=30, seed=12).log], robot=robot)
        models = {}
        for inputs in ("thesis", "physics"):
            train(tr, te, TrainConfig(families=("mlp",), targets=("E",), cv=3, inputs=inputs), d / inputs)
            models[inputs] = best_model(d / inputs, "E")
        q0, qf = np.radians([-60, 10, -30, 40, 20, 0]), np.radians([70, 30, 10, -50, -40, 90])
        X = np.random.default_rng(0).uniform(-2, 2, size=(100, 36))
        rows = []
        problems = {
            "learned (MLP, raw 40 inputs)": TrajectoryProblem(
                robot=robot,
                q_start=q0,
                q_end=qf,
                duration=1.0,
                fitness="surrogate",
                models=(models["thesis"],),
            ),
            "learned (MLP, physics inputs)": TrajectoryProblem(
                robot=robot,
                q_start=q0,
                q_end=qf,
                duration=1.0,
                fitness="surrogate",
                models=(models["physics"],),
            ),
            "physics (RNEA + nominal friction)": TrajectoryProblem(
                robot=robot, q_start=q0, q_end=qf, duration=1.0
            ),
        }
        for name, prob in problems.items():
            t_batch = median_time(lambda p=prob: p.evaluate(X), repeats=15)
            t_loop = median_time(lambda p=prob: [p.evaluate(X[i : i + 1]) for i in range(100)], repeats=3)
            rows.append((name, t_batch, t_loop))
        lines = [
            "## Optimizer: cost per generation and benchmark (benchmarks/optimizers.py)",
            "",
            f"Machine: {machine()}; one thread.",
            "Population 100, T = 1 s (41 samples per path, 4,100 model rows). Targets: learned <= 10 ms, "
            "physics <= 20 ms per generation. Baseline (same run): one evaluate call per individual, "
            "as the thesis' fitness loop did.",
            "",
            "| fitness | one generation (batched) | evaluations/s | per-individual loop (baseline) | speed vs baseline |",
            "|---|---|---|---|---|",
        ]
        for name, tb, tl in rows:
            lines.append(
                f"| {name} | {tb * 1e3:.2f} ms | {100 / tb:,.0f} | {tl * 1e3:.1f} ms | {tl / tb:.1f}x |"
            )
        lines += ["", "The thesis needed 9.35 s for 10 generations x 100 individuals (single objective).", ""]
        for label, fitness, mods in (
            ("physics fitness", "physics", ()),
            ("surrogate fitness (MLP, physics inputs)", "surrogate", (models["physics"],)),
        ):
            frame = bench_optimizers(
                n_tasks=args.tasks,
                generations=args.generations,
                population=100,
                fitness=fitness,
                models=mods,
                configurations=thesis_configurations(fitness),
                n_jobs=2,
            )
            lines += [
                f"### bench-optimizers, {label}: {args.tasks} random tasks (lab ranges, T in [1, 3] s), "
                f"population 100, at most {args.generations} generations (stop after 10 without improvement)",
                "",
                "| configuration | vs best initial (thesis metric) % | vs default path on physics % | "
                "wall s per run | limits ok | thesis (vs initial) |",
                "|---|---|---|---|---|---|",
            ]
            for r in frame.itertuples():
                lines.append(
                    f"| {r.configuration} | {r.vs_initial_mean:.2f} ± {r.vs_initial_std:.2f} | "
                    f"{r.vs_default_mean:.2f} ± {r.vs_default_std:.2f} | {r.wall_s_mean:.2f} | "
                    f"{r.limits_ok_share:.0%} | {THESIS.get(r.configuration, '')} |"
                )
            lines.append("")
    text = "\n".join(lines)
    print(text)
    write_section("optimizers", text)


if __name__ == "__main__":
    main()
