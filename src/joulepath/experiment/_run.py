"""Run an experiment stage by stage, skipping stages whose inputs and settings have not changed.

Each stage writes its outputs under the run folder, then a ``stage.json`` holding a
hash of its settings and of the stages it reads. A stage whose ``stage.json`` holds
the same hash is skipped; an interrupted stage has no ``stage.json`` (it is written
last) and runs again. Every file is written atomically.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from joulepath._io import atomic_write_text
from joulepath.experiment._config import Experiment


def _hash(*parts: Any) -> str:
    return hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode()).hexdigest()[:24]


def _file_hash(path: str) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _cached(folder: Path, key: str) -> bool:
    marker = folder / "stage.json"
    return marker.exists() and json.loads(marker.read_text()).get("key") == key


def _done(folder: Path, key: str, started: float, extra: dict[str, Any]) -> None:
    atomic_write_text(
        folder / "stage.json", json.dumps({"key": key, "wall_s": time.perf_counter() - started, **extra})
    )


def run_experiment(
    exp: Experiment, out: str | os.PathLike[str], *, say: Callable[[str], None] = print
) -> dict[str, Any]:
    """Run data -> train -> optimize for ``exp`` into ``out``; returns a summary dict."""
    from joulepath.data import ingest, load_table, save_table
    from joulepath.dynamics import load_robot
    from joulepath.learn import TrainConfig, best_model, train
    from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks, write_run
    from joulepath.sim import simulate

    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)
    log_lines: list[str] = []

    def tell(text: str) -> None:
        log_lines.append(text)
        with (root / "run.log").open("a", encoding="utf-8") as fh:
            fh.write(time.strftime("%Y-%m-%d %H:%M:%S ") + text + "\n")
        say(text)

    robot = load_robot(exp.robot)
    summary: dict[str, Any] = {"name": exp.name, "source": exp.source, "stages": {}}
    # -- data
    d = exp.data
    logs = [_file_hash(p) for p in (*d.train_logs, *d.test_logs)]
    data_key = _hash("data", exp.robot, exp.seed, asdict(d), logs)
    data_dir = root / "data"
    if _cached(data_dir, data_key):
        tell("data: unchanged, skipped")
    else:
        t0 = time.perf_counter()
        data_dir.mkdir(parents=True, exist_ok=True)
        children = np.random.SeedSequence(exp.seed).spawn(2)
        for name, n, given, seed in (
            ("train", d.train_moves, d.train_logs, children[0]),
            ("test", d.test_moves, d.test_logs, children[1]),
        ):
            paths = list(given) or [
                str(
                    simulate(
                        data_dir / "logs" / f"{name}.csv",
                        plant=d.plant,
                        n_moves=n,
                        seed=seed,
                        robot=exp.robot,
                    ).log
                )
            ]
            table = ingest(paths, robot=robot)
            save_table(table, data_dir / f"{name}.parquet")
            tell(f"data: {name} {len(table.frame):,} rows, {table.n_moves} moves")
        _done(data_dir, data_key, t0, {})
    train_table, test_table = load_table(data_dir / "train.parquet"), load_table(data_dir / "test.parquet")
    # -- train
    t = exp.train
    train_key = _hash("train", data_key, asdict(t), exp.seed)
    model_dir = root / "models"
    if t.families and not _cached(model_dir, train_key):
        t0 = time.perf_counter()
        report = train(
            train_table,
            test_table,
            TrainConfig(
                families=t.families,
                targets=t.targets,
                grid=t.grid,
                cv=t.cv,
                inputs=t.inputs,
                seed=exp.seed,
                n_jobs=t.jobs,
                scheduler=t.scheduler or None,
                robot=exp.robot,
            ),
            model_dir,
            progress=lambda m: None,
        )
        for r in report.results.itertuples():
            tell(
                f"train: {r.family} {r.target}: grouped CV R² {r.cv_grouped_r2:.4f}, test R² {r.test_r2:.4f}"
            )
        _done(model_dir, train_key, t0, {})
    else:
        tell("train: unchanged, skipped")
    # -- optimize
    o = exp.optimize
    opt_key = _hash("optimize", train_key, asdict(o), exp.seed)
    opt_dir = root / "optimize"
    if _cached(opt_dir, opt_key):
        tell("optimize: unchanged, skipped")
    else:
        t0 = time.perf_counter()
        models: tuple[Any, ...] = ()
        if o.fitness == "surrogate":
            models = (best_model(model_dir, "E"),)
        elif o.fitness == "surrogate-joints":
            models = tuple(best_model(model_dir, f"E{i}") for i in range(1, 7))
        joints = None
        jf = model_dir / "joints.json"
        if jf.exists():
            joints = tuple(json.loads(jf.read_text())["joints_by_influence"])
        rows = []
        for k, (q0, qf, T) in enumerate(random_tasks(robot, o.tasks, seed=exp.seed, range_set=o.range_set)):
            cfg = OptimizeConfig(
                algorithm=o.algorithm,
                fitness=o.fitness,
                max_gen=o.generations,
                pop_size=o.population,
                seed=exp.seed + k,
            )
            res = optimize_move(robot, q0, qf, T, cfg, models=models, joints_ranked=joints)
            write_run(res, robot, opt_dir / f"task-{k:03d}")
            s = res.summary
            rows.append(
                {
                    "task": k,
                    "duration_s": T,
                    "default_J": s["energy_default_physics_J"],
                    "optimized_J": s["energy_optimized_physics_J"],
                    "saved_pct": s["improvement_physics_pct"],
                    "saved_lab_pct": s["improvement_lab_pct"],
                    "limits_ok": s["limits_ok"],
                    "generations": s["generations"],
                    "wall_s": s["wall_s"],
                }
            )
            tell(
                f"optimize: task {k} ({T:g} s): {s['improvement_physics_pct']:.1f} % saved on physics, "
                f"limits ok {s['limits_ok']}"
            )
        atomic_write_text(opt_dir / "tasks.csv", pd.DataFrame(rows).to_csv(index=False))
        _done(opt_dir, opt_key, t0, {})
    tasks = pd.read_csv(opt_dir / "tasks.csv")
    summary["stages"] = {"data": data_key, "train": train_key, "optimize": opt_key}
    summary["mean_saved_pct"] = float(tasks["saved_pct"].mean()) if len(tasks) else None
    atomic_write_text(root / "summary.json", json.dumps(summary, indent=2))
    tell(
        f"done: mean saving {summary['mean_saved_pct']:.1f} % on physics at equal cycle time; "
        f"outputs in {root}"
    )
    return summary
