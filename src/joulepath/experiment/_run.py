"""Run an experiment stage by stage, skipping stages whose inputs and settings have not changed.

Stages, each in its own folder of the run: ``data`` (simulate on a plant or ingest
logs), ``synth`` (optional), ``models`` (train), ``importance``, ``optimize``,
``bench`` (optional), ``identify`` (optional), ``cycle`` (optional); then
``report.html`` is rendered from what they wrote.

Each stage writes its outputs, then a ``stage.json`` holding a hash of its settings,
of the stages it reads (so a stage whose inputs changed runs again, and so do the
stages after it), of the robot file's content and of joulepath's version. A stage
whose ``stage.json`` holds the same hash is skipped.

A stage's folder holds only what the current settings produce: a stage runs in a
fresh hidden sibling (``.models.partial``), which replaces the stage's folder once
its ``stage.json`` is written. So a model family dropped from ``[train] families``
leaves no model behind, a refused ``path.mod`` leaves no older one, and an
interrupted stage leaves the previous complete folder as it was (and runs again
next time). The only things carried from one run of a stage to the next are
content-keyed caches (the grid search's per-candidate results, ``.gridcache``), so an
interrupted training resumes where it stopped. The folder of a stage that is no
longer in the plan is removed, and so are ``summary.json`` and ``report.html`` as
soon as any stage's folder is replaced (they are written again at the end). Every
file is written atomically (temporary file, then rename).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from joulepath._io import atomic_write_text
from joulepath.errors import InvalidInput
from joulepath.experiment._config import Experiment, resolve_logs

Progress = Callable[[str, int, int], None]
"""``progress(label, done, total)``: called as a long stage advances."""

COMPACT_CONFIGURATIONS = (
    "GA random P(C)=0.95 P(M)=0.05",
    "GA average P(C)=0.9 P(M)=0.05",
    "GA differential P(C)=0.95 P(M)=0.05 F=0.05",
    "DE rand/1/bin",
    "MA random local search",
    "MA informed local search",
)


def _hash(*parts: Any) -> str:
    """Key of a stage: its settings, the keys of what it reads, and joulepath's version."""
    from joulepath import __version__

    text = json.dumps([__version__, *parts], sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def _file_hash(path: str) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


@dataclass(frozen=True, slots=True)
class _Context:
    exp: Experiment
    root: Path
    tell: Callable[[str], None]
    progress: Progress


#: Folders inside a stage's folder that are caches keyed by their content, carried
#: from one run of the stage to the next (the grid search's per-candidate results).
CACHES = (".gridcache",)


def _robot_key(robot: str) -> list[str]:
    """The robot as a stage key sees it: its name or path, and the file's content if it is one."""
    from joulepath.description import PRESETS

    path = Path(robot)
    if robot not in PRESETS and path.is_file():
        return [robot, _file_hash(robot)]
    return [robot]


def _carry_caches(sources: list[Path], work: Path) -> None:
    """Move the content-keyed cache files of ``sources`` (first one wins) into ``work``."""
    for name in CACHES:
        for source in sources:
            src = source / name
            if not src.is_dir():
                continue
            for f in sorted(src.rglob("*")):
                target = work / name / f.relative_to(src)
                if f.is_file() and not target.exists():
                    target.parent.mkdir(parents=True, exist_ok=True)
                    os.replace(f, target)


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif path.exists() or path.is_symlink():
        path.unlink()


def _drop_stage(ctx: _Context, name: str, folder: str) -> None:
    """Remove the folder of a stage that is no longer in the plan (and its leftovers)."""
    path = ctx.root / folder
    for leftover in (ctx.root / f".{folder}.partial", ctx.root / f".{folder}.old"):
        _remove(leftover)
    if path.exists():
        _remove(path)
        _forget_results(ctx)
        ctx.tell(f"{name}: no longer in the experiment; its folder {folder}/ was removed")


def _forget_results(ctx: _Context) -> None:
    """Remove the run's summary and report: they describe stage folders that are being replaced."""
    for stale in ("summary.json", "report.html"):
        (ctx.root / stale).unlink(missing_ok=True)


def _stage(
    ctx: _Context, name: str, folder: str, key: str, body: Callable[[Path], dict[str, Any]]
) -> dict[str, Any]:
    """Run ``body(folder)`` unless the folder's ``stage.json`` holds ``key``; return its record.

    ``body`` writes into a fresh sibling folder, which replaces ``folder`` when
    ``body`` has finished and ``stage.json`` is written; only :data:`CACHES` are carried over.
    """
    path = ctx.root / folder
    marker = path / "stage.json"
    if marker.exists():
        record: dict[str, Any] = json.loads(marker.read_text(encoding="utf-8"))
        if record.get("key") == key:
            ctx.tell(f"{name}: unchanged, skipped")
            return record
    work = ctx.root / f".{folder}.partial"
    old = ctx.root / f".{folder}.old"
    if work.exists():  # an interrupted run of this stage: keep its caches only
        stale = ctx.root / f".{folder}.stale"
        _remove(stale)
        work.rename(stale)
        work.mkdir()
        _carry_caches([stale, path, old], work)
        _remove(stale)
    else:
        work.mkdir()
        _carry_caches([path, old], work)
    t0 = time.perf_counter()
    extra = body(work)
    record = {"key": key, "stage": name, "wall_s": round(time.perf_counter() - t0, 3), **extra}
    atomic_write_text(work / "stage.json", json.dumps(record, indent=2, default=str))
    _forget_results(ctx)
    _remove(old)
    if path.exists():
        path.rename(old)
    work.rename(path)
    _remove(old)
    ctx.tell(f"{name}: done in {record['wall_s']:.1f} s")
    return record


def run_experiment(
    exp: Experiment,
    out: str | os.PathLike[str],
    *,
    say: Callable[[str], None] = print,
    progress: Progress | None = None,
    scheduler: str | None = None,
) -> dict[str, Any]:
    """Run every stage of ``exp`` into the folder ``out``; returns the summary (``summary.json``).

    Parameters
    ----------
    exp : Experiment
        From :func:`joulepath.experiment.load_experiment`.
    out : path
        The run folder. Running again into the same folder skips unchanged stages.
    say : callable
        Receives one line per event (also appended to ``<out>/run.log``).
    progress : callable, optional
        ``progress(label, done, total)`` as long stages advance (progress bars).
    scheduler : str, optional
        Dask scheduler address overriding the file's ``scheduler`` (grid search, benchmark).
    """
    from joulepath.report import render_report

    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)

    def tell(text: str) -> None:
        with (root / "run.log").open("a", encoding="utf-8") as fh:
            fh.write(time.strftime("%Y-%m-%d %H:%M:%S ") + text + "\n")
        say(text)

    if scheduler:
        from dataclasses import replace

        exp = replace(exp, scheduler=scheduler)
    ctx = _Context(exp, root, tell, progress or (lambda _l, _d, _t: None))
    tell(f"run {exp.name} ({exp.source or 'in memory'}) into {root}")
    t_start = time.perf_counter()
    stages: dict[str, dict[str, Any]] = {}
    stages["data"] = _data_stage(ctx)
    keys = {"data": stages["data"]["key"]}
    if exp.synth.methods:
        stages["synth"] = _synth_stage(ctx, keys["data"])
    else:
        _drop_stage(ctx, "synth", "synth")
    if exp.train.families:
        stages["train"] = _train_stage(ctx, keys["data"])
    else:
        _drop_stage(ctx, "train", "models")
    stages["importance"] = _importance_stage(ctx, keys["data"])
    model_key = stages["train"]["key"] if "train" in stages else ""
    stages["optimize"] = _optimize_stage(ctx, model_key, stages["importance"]["key"])
    if exp.bench.tasks:
        stages["bench"] = _bench_stage(ctx, model_key, stages["importance"]["key"])
    else:
        _drop_stage(ctx, "bench", "bench")
    if exp.identify.enabled:
        synth_key = stages["synth"]["key"] if "synth" in stages else ""
        stages["identify"] = _identify_stage(ctx, keys["data"], synth_key, model_key)
    else:
        _drop_stage(ctx, "identify", "identify")
    if exp.cycle.program:
        stages["cycle"] = _cycle_stage(ctx)
    else:
        _drop_stage(ctx, "cycle", "cycle")
    tasks = pd.read_csv(root / "optimize" / "tasks.csv")
    ok = tasks[tasks["limits_ok"].astype(bool)] if len(tasks) else tasks
    summary: dict[str, Any] = {
        "name": exp.name,
        "source": exp.source,
        "robot": exp.robot,
        "seed": exp.seed,
        "experiment": asdict(exp),
        "stages": stages,
        # every task is feasible (its default move respects the limits); a refused result counts 0
        "mean_saved_pct": float(tasks["saved_pct"].mean()) if len(tasks) else None,
        "mean_saved_lab_pct": float(tasks["saved_lab_pct"].mean()) if len(tasks) else None,
        "mean_optimum_saved_pct": float(tasks["optimum_saved_pct"].mean())
        if "optimum_saved_pct" in tasks
        else None,
        "mean_share_of_optimum_pct": float(tasks["share_of_optimum_pct"].mean())
        if "share_of_optimum_pct" in tasks
        else None,
        "tasks_within_limits": int(len(ok)),
        "tasks": int(len(tasks)),
        "wall_s": round(time.perf_counter() - t_start, 3),
    }
    atomic_write_text(root / "summary.json", json.dumps(summary, indent=2, default=str))
    report = render_report(root)
    summary["report"] = str(report)
    saved = summary["mean_saved_pct"]
    tell(
        (
            f"done: mean saving {saved:.1f} % on physics at equal cycle time "
            if saved is not None
            else "done: "
        )
        + f"({summary['tasks_within_limits']}/{summary['tasks']} tasks within the limits); "
        f"report: {report}"
    )
    return summary


# ----------------------------------------------------------------------------- data
def _data_stage(ctx: _Context) -> dict[str, Any]:
    from joulepath.data import ingest, save_table
    from joulepath.dynamics import load_robot
    from joulepath.sim import simulate

    exp, d = ctx.exp, ctx.exp.data
    logs = {
        "train": resolve_logs(exp, d.train_logs),
        "test": resolve_logs(exp, d.test_logs),
    }
    key = _hash(
        "data",
        _robot_key(exp.robot),
        exp.seed,
        asdict(d),
        [_file_hash(p) for p in (*logs["train"], *logs["test"])],
    )

    def body(folder: Path) -> dict[str, Any]:
        robot = load_robot(exp.robot)
        children = np.random.SeedSequence(exp.seed).spawn(4)
        plan = [
            ("train", d.train_moves, d.plant, children[0]),
            ("test", d.test_moves, d.plant, children[1]),
            ("micro", d.micro_moves, d.plant, children[2]),
            ("sim", d.sim_moves, "sim", children[3]),
        ]
        sets: dict[str, Any] = {}
        for k, (name, n, plant, seed) in enumerate(plan):
            ctx.progress("data", k, len(plan))
            if name in logs and logs[name]:
                paths, origin = logs[name], "logs"
            elif n:
                sim = simulate(
                    folder / "logs" / f"{name}.csv",
                    plant=plant,
                    n_moves=n,
                    seed=seed,
                    robot=exp.robot,
                    range_set=d.range_set,
                )
                paths, origin = [str(sim.log)], f"simulated on the {plant} plant"
                if sim.range_set != d.range_set:
                    origin += f", nominal ranges ({robot.name} has no {d.range_set!r} range set)"
            else:
                (folder / f"{name}.parquet").unlink(missing_ok=True)
                continue
            table = ingest(paths, robot=robot)
            save_table(table, folder / f"{name}.parquet")
            sets[name] = {"rows": len(table.frame), "moves": table.n_moves, "origin": origin}
            ctx.tell(f"data: {name} {len(table.frame):,} rows, {table.n_moves} moves ({origin})")
        ctx.progress("data", len(plan), len(plan))
        return {"datasets": sets}

    return _stage(ctx, "data", "data", key, body)


def _table(ctx: _Context, name: str) -> Any:
    from joulepath.data import load_table

    return load_table(ctx.root / "data" / f"{name}.parquet")


# ----------------------------------------------------------------------------- synth
def _synth_stage(ctx: _Context, data_key: str) -> dict[str, Any]:
    exp, s = ctx.exp, ctx.exp.synth
    key = _hash("synth", data_key, asdict(s), exp.seed)

    def body(folder: Path) -> dict[str, Any]:
        from joulepath.data import save_table
        from joulepath.dynamics import load_robot
        from joulepath.synth import (
            SynthConfig,
            Synthesizer,
            compare,
            kinematic_consistency,
            quality_report,
            repair_kinematics,
            utility,
        )

        robot = load_robot(exp.robot)
        source = _table(ctx, s.source)
        train, test = _table(ctx, "train"), _table(ctx, "test")
        rows: list[dict[str, Any]] = []
        tables: dict[str, Any] = {}
        for k, method in enumerate(s.methods):
            ctx.progress("synth", k, len(s.methods))
            t0 = time.perf_counter()
            cfg = SynthConfig(method=method, epochs=s.epochs, batch_size=s.batch_size, seed=exp.seed)
            table = Synthesizer(cfg).fit(source).sample(s.rows)
            fit_s = time.perf_counter() - t0
            consistent_raw = kinematic_consistency(table, robot) if table.feature_set == "full40" else None
            if s.repair:
                table = repair_kinematics(table, robot)
            save_table(table, folder / f"{method}.parquet")
            quality = quality_report(source, table)
            use = utility(table, test, seed=exp.seed)
            study_r2, study_mae = _study_utility(exp, table, test)
            tables[method] = table
            rows.append(
                {
                    "method": method,
                    "rows": len(table.frame),
                    "column_shapes": quality["column_shapes"],
                    "column_pair_trends": quality["column_pair_trends"],
                    "overall": quality["overall"],
                    "utility_test_r2": use.r2,
                    "utility_test_mae": use.mae,
                    "study_mlp_test_r2": study_r2,
                    "study_mlp_test_mae": study_mae,
                    "tcp_consistent_share": consistent_raw,
                    "repaired": s.repair,
                    "wall_s": fit_s,
                }
            )
            ctx.tell(
                f"synth: {method}: column shapes {quality['column_shapes']:.3f}, pair trends "
                f"{quality['column_pair_trends']:.3f}; trained on it, tested on real moves: fixed MLP R² "
                f"{use.r2:.3f}, the study's MLP R² {study_r2:.3f}"
            )
        ctx.progress("synth", len(s.methods), len(s.methods))
        baselines = []
        for name in ("train", "micro", "sim"):
            if (ctx.root / "data" / f"{name}.parquet").exists():
                real = _table(ctx, name)
                use = utility(real, test, seed=exp.seed)
                study_r2, study_mae = _study_utility(exp, real, test)
                baselines.append(
                    {
                        "train_on": name,
                        "test_r2": use.r2,
                        "test_mae": use.mae,
                        "study_mlp_test_r2": study_r2,
                        "study_mlp_test_mae": study_mae,
                    }
                )
        scores = pd.DataFrame(rows)
        atomic_write_text(folder / "scores.csv", scores.to_csv(index=False))
        atomic_write_text(folder / "utility_baselines.csv", pd.DataFrame(baselines).to_csv(index=False))
        best = str(scores.sort_values("column_shapes", ascending=False)["method"].iloc[0])
        shown: dict[str, Any] = {"real (train)": train}
        if (ctx.root / "data" / "sim.parquet").exists():
            shown["simulated"] = _table(ctx, "sim")
        shown[f"synthetic ({best})"] = tables[best]
        comparison = compare(shown, out_dir=folder / "plots")
        atomic_write_text(folder / "statistics.csv", comparison.statistics.to_csv())
        _plot_quality(scores, folder / "quality.png")
        _plot_statistics(comparison.statistics, folder / "statistics.png")
        return {"best_method": best}

    return _stage(ctx, "synth", "synth", key, body)


def _study_utility(exp: Experiment, train: Any, test: Any) -> tuple[float, float]:
    """Train-on-``train``, test-on-real with the study's own inputs (``[train] inputs``).

    The synth package's :func:`~joulepath.synth.utility` is a fixed raw-input MLP, comparable
    across studies; this one is the MLP of the quick grid (50 ReLU units, alpha 0.1) on the
    inputs the study's models use, so that H2 is judged with the model the study would train.
    """
    import warnings

    from sklearn.exceptions import ConvergenceWarning
    from sklearn.metrics import mean_absolute_error, r2_score

    from joulepath.learn import input_columns, make_pipeline

    cols = list(input_columns(train.feature_set, exp.train.inputs, train.n_joints))
    pipe = make_pipeline("mlp", seed=exp.seed, inputs=exp.train.inputs, columns=tuple(cols), robot=exp.robot)
    pipe.set_params(model__hidden_layer_sizes=(50,), model__activation="relu", model__alpha=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        pipe.fit(train.frame[cols].to_numpy(dtype=float), train.frame["E"].to_numpy(dtype=float))
    predicted = pipe.predict(test.frame[cols].to_numpy(dtype=float))
    measured = test.frame["E"].to_numpy(dtype=float)
    return float(r2_score(measured, predicted)), float(mean_absolute_error(measured, predicted))


def _plot_quality(scores: pd.DataFrame, path: Path) -> None:
    """Quality and utility per method (thesis Fig 4.3)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 3.5))
    ax1, ax2 = fig.subplots(1, 2)
    x = np.arange(len(scores))
    ax1.bar(x - 0.2, scores["column_shapes"], 0.4, label="column shapes")
    ax1.bar(x + 0.2, scores["column_pair_trends"], 0.4, label="column pair trends")
    ax1.set_xticks(x, scores["method"])
    ax1.set_ylim(0, 1)
    ax1.set_title("SDMetrics quality")
    ax1.legend(fontsize="small", loc="lower right")
    low = -0.5
    for offset, column, label in (
        (-0.2, "utility_test_r2", "fixed raw-input MLP"),
        (0.2, "study_mlp_test_r2", "the study's MLP"),
    ):
        values = scores[column].to_numpy(dtype=float)
        ax2.bar(x + offset, np.clip(values, low, None), 0.4, label=label)
        for xi, v in zip(x + offset, values, strict=True):
            ax2.annotate(f"{v:.2f}", (xi, max(v, low)), ha="center", va="bottom", fontsize=8)
    ax2.axhline(0, color="k", lw=0.5)
    ax2.set_xticks(x, scores["method"])
    ax2.set_ylim(low, 1.05)
    ax2.legend(fontsize="small", loc="lower right")
    ax2.set_title(f"trained on synthetic, tested on real:\nR²(E), bars clipped at {low}", fontsize="medium")
    fig.tight_layout()
    _save(fig, path)


def _plot_statistics(stats: pd.DataFrame, path: Path) -> None:
    """Each table's statistics relative to the real table's, per column (thesis Fig 4.10)."""
    from matplotlib.figure import Figure

    tables = list(dict.fromkeys(stats.index.get_level_values("table")))
    columns = list(dict.fromkeys(stats.index.get_level_values("column")))
    names = [c for c in ("mean", "std", "min", "max") if c in stats.columns]
    fig = Figure(figsize=(11, 2.3 * len(names)))
    axes = fig.subplots(len(names), 1, squeeze=False)[:, 0]
    real = tables[0]
    scale = stats.xs(real, level="table")["std"].replace(0, 1.0).abs()
    markers = ["o", "+", "x", "s"]
    for ax, stat in zip(axes, names, strict=True):
        for m, name in enumerate(tables):
            values = stats.xs(name, level="table")[stat].reindex(columns)
            ref = stats.xs(real, level="table")[stat].reindex(columns)
            ax.plot(
                np.arange(len(columns)),
                (values - ref) / scale.reindex(columns),
                markers[m % 4],
                label=name,
                ms=4,
            )
        ax.axhline(0, color="k", lw=0.5)
        ax.set_ylabel(f"Δ{stat} / σ(real)", fontsize=8)
    axes[-1].set_xticks(np.arange(len(columns)), columns, rotation=90, fontsize=6)
    for ax in axes[:-1]:
        ax.set_xticks([])
    axes[0].legend(fontsize="small", ncol=len(tables))
    fig.tight_layout()
    _save(fig, path)


def _save(fig: Any, path: Path) -> None:
    import io

    from joulepath._io import atomic_write_bytes

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    atomic_write_bytes(path, buf.getvalue())


# ----------------------------------------------------------------------------- train
def _train_stage(ctx: _Context, data_key: str) -> dict[str, Any]:
    exp, t = ctx.exp, ctx.exp.train
    key = _hash("train", data_key, asdict(t), exp.seed)

    def body(folder: Path) -> dict[str, Any]:
        from joulepath.learn import TrainConfig, train

        report = train(
            _table(ctx, "train"),
            _table(ctx, "test"),
            TrainConfig(
                families=t.families,
                targets=t.targets,
                grid=t.grid,
                cv=t.cv,
                inputs=t.inputs,
                seed=exp.seed,
                n_jobs=exp.jobs,
                scheduler=exp.scheduler or None,
                robot=exp.robot,
            ),
            folder,
            on_search=lambda family, target, done, total: ctx.progress(
                f"train {family} {target}", done, total
            ),
        )
        for r in report.results.itertuples():
            ctx.tell(
                f"train: {r.family} {r.target}: grouped CV R² {r.cv_grouped_r2:.4f}, test R² {r.test_r2:.4f}"
            )
        if "E" in t.targets:
            _compare_with_physics(ctx, folder)
        return {}

    return _stage(ctx, "train", "models", key, body)


def _compare_with_physics(ctx: _Context, folder: Path) -> None:
    """The best model of E against the analytical model on a section of the test data (Fig 4.18),
    and both models' prediction times (thesis §4.4)."""
    from matplotlib.figure import Figure

    from joulepath.data import EnergyTable
    from joulepath.dynamics import load_robot
    from joulepath.learn import best_model, physics_predict

    robot = load_robot(ctx.exp.robot)
    test = _table(ctx, "test")
    model = best_model(folder, "E")
    frame = test.frame
    section = EnergyTable(frame=frame.iloc[: min(len(frame), 480)], feature_set=test.feature_set)
    measured = section.frame["E"].to_numpy()
    learned = model.predict(section.frame)
    physics = physics_predict(section, robot, friction=robot.friction)["E"]
    fig = Figure(figsize=(10, 3.4))
    ax = fig.subplots()
    ax.plot(measured, "k-", lw=1.2, label="measured")
    ax.plot(learned, "-", lw=0.9, label=f"learned ({model.family})")
    ax.plot(
        physics,
        "--",
        lw=0.9,
        label="dynamics model + nominal friction" if robot.friction else "dynamics model (rigid body)",
    )
    ax.set_xlabel("test row (25 ms each)")
    ax.set_ylabel("E per row (J)")
    ax.legend(fontsize="small")
    fig.tight_layout()
    _save(fig, folder / "comparison.png")

    def timed(fn: Callable[[], Any], repeat: int) -> float:
        best = float("inf")
        for _ in range(repeat):
            t0 = time.perf_counter()
            fn()
            best = min(best, time.perf_counter() - t0)
        return best

    one = EnergyTable(frame=frame.iloc[:1], feature_set=test.feature_set)
    size = sum(p.stat().st_size for p in (folder / f"{model.family}-E").iterdir() if p.is_file())
    latency = {
        "model": f"{model.family}-E",
        "rows": len(frame),
        "learned_batch_per_row_s": timed(lambda: model.predict(frame), 3) / len(frame),
        "learned_single_s": timed(lambda: model.predict(one.frame), 20),
        "learned_size_bytes": size,
        "physics_batch_per_row_s": timed(lambda: physics_predict(test, robot, friction=robot.friction), 3)
        / len(frame),
        "physics_single_s": timed(lambda: physics_predict(one, robot, friction=robot.friction), 20),
    }
    atomic_write_text(folder / "latency.json", json.dumps(latency, indent=2))


# ----------------------------------------------------------------------------- importance
def _importance_stage(ctx: _Context, data_key: str) -> dict[str, Any]:
    exp, imp = ctx.exp, ctx.exp.importance
    key = _hash("importance", data_key, asdict(imp), exp.seed)

    def body(folder: Path) -> dict[str, Any]:
        from joulepath.learn import feature_importance, plot_importance, rank_joints

        table = _table(ctx, "train")
        targets = [x for x in imp.targets if x in table.frame.columns]
        means: dict[str, pd.Series] = {}
        first: pd.DataFrame | None = None
        for k, target in enumerate(targets):
            ctx.progress("importance", k, len(targets))
            result = feature_importance(table, target, max_rows=imp.max_rows, seed=exp.seed)
            atomic_write_text(folder / f"importance_{target}.csv", result.to_csv())
            means[target] = result["mean"]
            if first is None or target == "E":
                first = result
        ctx.progress("importance", len(targets), len(targets))
        assert first is not None
        ranked_on = "E" if "E" in means else targets[0]
        plot_importance(
            first, folder / f"importance_{ranked_on}.png", title=f"Feature importance for {ranked_on}"
        )
        joints = rank_joints(first)
        atomic_write_text(
            folder / "joints.json", json.dumps({"target": ranked_on, "joints_by_influence": joints})
        )
        _plot_heatmap(pd.DataFrame(means), folder / "heatmap.png")
        ctx.tell(f"importance: joints by influence on {ranked_on}: {joints}")
        return {"joints_by_influence": joints}

    return _stage(ctx, "importance", "importance", key, body)


def _plot_heatmap(means: pd.DataFrame, path: Path) -> None:
    """Mean importance of every input (rows) for every target (columns) (thesis Figs 4.1–4.2)."""
    from matplotlib.figure import Figure

    order = means.mean(axis=1).sort_values(ascending=False).index
    data = means.loc[order]
    fig = Figure(figsize=(1.2 + 0.7 * data.shape[1], max(4.0, 0.2 * len(data))))
    ax = fig.subplots()
    image = ax.imshow(data.to_numpy(), aspect="auto", cmap="viridis")
    ax.set_xticks(np.arange(data.shape[1]), data.columns)
    ax.set_yticks(np.arange(len(data)), data.index, fontsize=7)
    ax.set_title("feature importance (mean of 5 methods)")
    fig.colorbar(image, ax=ax, fraction=0.05)
    fig.tight_layout()
    _save(fig, path)


# ----------------------------------------------------------------------------- optimize
def _models_for(ctx: _Context, fitness: str, n_joints: int = 6) -> tuple[Any, ...]:
    from joulepath.learn import best_model

    if fitness == "surrogate":
        return (best_model(ctx.root / "models", "E"),)
    if fitness == "surrogate-joints":
        return tuple(best_model(ctx.root / "models", f"E{i}") for i in range(1, n_joints + 1))
    return ()


def _joints(ctx: _Context, n_joints: int) -> tuple[int, ...]:
    from joulepath.learn import read_joints_json

    return read_joints_json(ctx.root / "importance" / "joints.json", n_joints)


def _optimize_stage(ctx: _Context, model_key: str, importance_key: str) -> dict[str, Any]:
    exp, o = ctx.exp, ctx.exp.optimize
    uses_models = o.fitness != "physics"
    key = _hash(
        "optimize",
        model_key if uses_models else "",
        importance_key,
        _robot_key(exp.robot),
        asdict(o),
        exp.seed,
    )

    def body(folder: Path) -> dict[str, Any]:
        import shutil

        from joulepath.dynamics import load_robot
        from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks, write_run

        for old in folder.glob("task-*"):
            shutil.rmtree(old)
        robot = load_robot(exp.robot)
        models = _models_for(ctx, o.fitness, robot.n_joints)
        joints = _joints(ctx, robot.n_joints)
        rows = []
        tasks = random_tasks(robot, o.tasks, seed=exp.seed, range_set=o.range_set)
        if robot.ranges_for(o.range_set)[0] != o.range_set:
            ctx.tell(
                f"optimize: {robot.name} has no {o.range_set!r} range set; tasks drawn in its nominal ranges"
            )
        seeds = np.random.SeedSequence(exp.seed).spawn(len(tasks))
        for k, (q0, qf, T) in enumerate(tasks):
            ctx.progress("optimize", k, len(tasks))
            cfg = OptimizeConfig(
                algorithm=o.algorithm,
                fitness=o.fitness,
                max_gen=o.generations,
                pop_size=o.population,
                seed=int(seeds[k].generate_state(1)[0]),
                energy=o.energy,
            )
            res = optimize_move(robot, q0, qf, T, cfg, models=models, joints_ranked=joints)
            write_run(res, robot, folder / f"task-{k:03d}", export=o.export or None)
            s = res.summary
            optimum = _optimum(robot, res) if o.reference else None
            rows.append(
                {
                    "task": k,
                    "q_start_deg": " ".join(f"{v:.1f}" for v in np.degrees(q0)),
                    "q_end_deg": " ".join(f"{v:.1f}" for v in np.degrees(qf)),
                    "duration_s": T,
                    "algorithm": s.algorithm,
                    "default_J": s.energy_default_J,
                    "optimized_J": s.energy_optimized_J,
                    "saved_pct": s.saved_pct if s.limits_ok else 0.0,
                    "saved_lab_pct": s.saved_lab_pct if s.limits_ok else 0.0,
                    "saved_vs_initial_pct": s.saved_vs_initial_best_pct,
                    "limits_ok": s.limits_ok,
                    "max_tcp_deviation_mm": s.max_tcp_deviation_mm,
                    "iterations": s.iterations,
                    "wall_s": s.wall_s,
                    **(optimum or {}),
                }
            )
            verdict = (
                f"{s.saved_pct:.1f} % saved on physics, {s.saved_lab_pct or 0.0:.1f} % on the lab robot"
                if s.limits_ok
                else "REFUSED (breaks a limit: " + "; ".join(s.limit_excess) + "), no saving claimed"
            )
            ctx.tell(f"optimize: task {k} ({T:g} s, {s.algorithm}): {verdict}")
        ctx.progress("optimize", len(tasks), len(tasks))
        frame = pd.DataFrame(rows) if rows else pd.DataFrame(columns=list(TASK_COLUMNS))
        atomic_write_text(folder / "tasks.csv", frame.to_csv(index=False))
        if len(frame):
            _plot_tasks(frame, folder / "tasks.png")
        return {}

    return _stage(ctx, "optimize", "optimize", key, body)


TASK_COLUMNS = (
    "task",
    "q_start_deg",
    "q_end_deg",
    "duration_s",
    "algorithm",
    "default_J",
    "optimized_J",
    "saved_pct",
    "saved_lab_pct",
    "saved_vs_initial_pct",
    "limits_ok",
    "max_tcp_deviation_mm",
    "iterations",
    "wall_s",
)
"""The columns of ``optimize/tasks.csv`` (with ``reference``, also those of the optimum); a header
only when ``[optimize] tasks = 0``."""


def _optimum(robot: Any, res: Any) -> dict[str, Any]:
    """The reference optimum of a task (CasADi + IPOPT) and the share of its saving reached.

    Energies on the fine grid (the integral), where the reference is optimized; the
    reference starts from the minimum-jerk move (``benchmarks/optimizer_peers.py`` also
    starts it from the optimized path and keeps the better of the two).
    """
    from joulepath.optimize import acceleration_limit, jerk_limit, reference_optimum

    s = res.summary
    amax = acceleration_limit(robot, s.config["accel_time"])
    jmax = jerk_limit(robot, s.config["accel_time"], s.config["jerk_time"])
    q0, qf = np.asarray(s.start_rad), np.asarray(s.end_rad)
    solves = [
        reference_optimum(
            robot,
            q0,
            qf,
            s.duration_s,
            friction=robot.friction,
            acceleration_limit=amax,
            jerk_limit=jmax,
        )
    ]
    ok = [r for r in solves if r.max_violation < 1e-6]
    best = min(ok or solves, key=lambda r: r.energy_fine_J)
    possible = s.energy_default_fine_J - best.energy_fine_J
    reached = s.energy_default_fine_J - s.energy_optimized_fine_J if s.limits_ok else 0.0
    return {
        "optimum_J": best.energy_fine_J,
        "optimum_saved_pct": 100 * possible / s.energy_default_fine_J,
        "share_of_optimum_pct": 100 * reached / possible if possible > 0 else 100.0,
        "optimum_wall_s": sum(r.wall_s for r in solves),
    }


def _plot_tasks(frame: pd.DataFrame, path: Path) -> None:
    """Energy of the default and the optimized move per task (thesis Table 4.7)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(max(5.0, 0.8 * len(frame) + 2), 3.2))
    ax = fig.subplots()
    x = np.arange(len(frame))
    ax.bar(x - 0.2, frame["default_J"], 0.4, label="default (minimum jerk, same duration)")
    ax.bar(x + 0.2, frame["optimized_J"], 0.4, label="optimized")
    for xi, (e, pct) in enumerate(zip(frame["optimized_J"], frame["saved_pct"], strict=True)):
        ax.annotate(f"{pct:.1f} %", (xi + 0.2, e), ha="center", va="bottom", fontsize=8)
    ax.set_xticks(x, [f"task {k}" for k in frame["task"]])
    ax.set_ylabel("energy on the physics model (J)")
    ax.legend(fontsize="small")
    fig.tight_layout()
    _save(fig, path)


# ----------------------------------------------------------------------------- bench
def _load_robot(name: str) -> Any:
    from joulepath.dynamics import load_robot

    return load_robot(name)


def _bench_stage(ctx: _Context, model_key: str, importance_key: str) -> dict[str, Any]:
    exp, b = ctx.exp, ctx.exp.bench
    uses_models = b.fitness != "physics"
    key = _hash(
        "bench", model_key if uses_models else "", importance_key, _robot_key(exp.robot), asdict(b), exp.seed
    )

    def body(folder: Path) -> dict[str, Any]:
        from joulepath.optimize import (
            bench_optimizers,
            default_configuration,
            summarize_bench,
            thesis_configurations,
        )

        configs = thesis_configurations(b.fitness)
        if b.configurations == "compact":
            configs = [c for c in configs if c[0] in COMPACT_CONFIGURATIONS]
        configs = [default_configuration(b.fitness), *configs]
        runs = bench_optimizers(
            robot=exp.robot,
            n_tasks=b.tasks,
            generations=b.generations,
            population=b.population,
            fitness=b.fitness,
            models=_models_for(ctx, b.fitness),
            joints=_joints(ctx, _load_robot(exp.robot).n_joints),
            configurations=configs,
            seed=exp.seed,
            n_jobs=exp.jobs,
            scheduler=exp.scheduler or None,
            progress=lambda done, total: ctx.progress("bench", done, total),
            per_run=True,
        )
        table = summarize_bench(runs)
        atomic_write_text(folder / "runs.csv", runs.to_csv(index=False))
        atomic_write_text(folder / "table.csv", table.to_csv(index=False))
        _plot_bench(table, folder / "improvement.png")
        best = table.sort_values("vs_default_mean", ascending=False).iloc[0]
        ctx.tell(
            f"bench: best at equal cycle time: {best['configuration']} "
            f"{best['vs_default_mean']:.1f} % vs the default move"
            + (
                f" ({best['vs_initial_mean']:.1f} % by the thesis' metric)"
                if np.isfinite(best["vs_initial_mean"])
                else ""
            )
        )
        return {}

    return _stage(ctx, "bench", "bench", key, body)


# ----------------------------------------------------------------------------- identify
def _identify_stage(ctx: _Context, data_key: str, synth_key: str, model_key: str) -> dict[str, Any]:
    """A twin from the training logs, the loop closed on it, and five models side by side.

    The work is :func:`joulepath.experiment._identify.run_identify`; it reads the synth
    stage's rows and the train stage's best model of E when they exist (their keys are
    in this stage's key).
    """
    from joulepath._runfolder import IDENTIFY_STAGE
    from joulepath.experiment._identify import HELD_OUT, NOMINAL, TWIN, run_identify, write_identify

    exp, st = ctx.exp, ctx.exp.identify
    key = _hash("identify", data_key, synth_key, model_key, _robot_key(exp.robot), asdict(st), exp.seed)

    def logs(name: str, given: tuple[str, ...]) -> list[str]:
        paths = resolve_logs(exp, given) or [str(ctx.root / "data" / "logs" / f"{name}.csv")]
        missing = [p for p in paths if not Path(p).is_file()]
        if missing:
            raise InvalidInput(
                f"[identify] needs the {name} logs; {missing[0]} is missing (run the data stage)"
            )
        return paths

    def body(folder: Path) -> dict[str, Any]:
        result = run_identify(
            exp,
            ctx.root,
            folder,
            train_logs=logs("train", exp.data.train_logs),
            test_logs=logs("test", exp.data.test_logs),
            progress=lambda done, total: ctx.progress("identify", done, total),
        )
        write_identify(result, folder)
        twin, nominal = result.score(TWIN, HELD_OUT), result.score(NOMINAL, HELD_OUT)
        frame = result.loop_frame()
        gap = (
            float((frame["predicted_saved_pct"] - frame["realized_saved_lab_pct"]).abs().median())
            if len(frame)
            else None
        )
        for note in result.notes:
            ctx.tell(f"identify: {note}")
        ctx.tell(
            f"identify: twin energy R² {twin.energy_r2:.4f} on the held-out moves (nominal physics "
            f"{nominal.energy_r2:.4f}); gear efficiency {result.gear_efficiency:.3f}"
            + (
                f"; predicted vs realized saving: median gap {gap:.2f} pp over {len(frame)} tasks"
                if gap is not None
                else ""
            )
        )
        return {
            "condition_number": result.condition_number,
            "gear_efficiency": result.gear_efficiency,
            "twin_energy_r2": twin.energy_r2,
            "nominal_energy_r2": nominal.energy_r2,
            "loop_median_gap_pp": gap,
            "learned_model": result.learned,
        }

    return _stage(ctx, "identify", IDENTIFY_STAGE, key, body)


def _plot_bench(table: pd.DataFrame, path: Path) -> None:
    """Both improvement metrics per configuration (thesis Tables 4.5–4.6, Fig 4.19)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 0.32 * len(table) + 1.6))
    ax = fig.subplots()
    y = np.arange(len(table))
    ax.barh(
        y + 0.2,
        table["vs_initial_mean"],
        0.4,
        xerr=table["vs_initial_std"].fillna(0),
        label="vs best initial individual (thesis)",
    )
    ax.barh(
        y - 0.2,
        table["vs_default_mean"],
        0.4,
        xerr=table["vs_default_std"].fillna(0),
        label="vs default move (honest)",
    )
    ax.set_yticks(y, table["configuration"], fontsize=7)
    ax.axvline(0, color="k", lw=0.5)
    ax.invert_yaxis()
    ax.set_xlabel("energy saved (%)")
    ax.legend(fontsize="small")
    fig.tight_layout()
    _save(fig, path)


# ----------------------------------------------------------------------------- cycle
def _cycle_stage(ctx: _Context) -> dict[str, Any]:
    """A robot program's whole cycle, as ``joulepath cycle`` runs it, into the ``cycle`` folder.

    Its key holds the program's and the cell file's content (and its meshes'), so editing any
    runs it again.
    """
    from joulepath._runfolder import CYCLE_STAGE
    from joulepath.dynamics import load_robot
    from joulepath.program import CycleSettings, ProgramSettings, optimize_program, read_cell

    exp, st = ctx.exp, ctx.exp.cycle
    program = Path(resolve_logs(exp, (st.program,))[0])
    cell = Path(resolve_logs(exp, (st.cell,))[0]) if st.cell else None
    cell_data = read_cell(cell) if cell is not None else None
    key = _hash(
        "cycle",
        _robot_key(exp.robot),
        asdict(st),
        exp.seed,
        _file_hash(str(program)),
        _file_hash(str(cell)) if cell is not None else "",
        *(_file_hash(f) for f in (cell_data.files if cell_data is not None else ())),
    )

    def body(folder: Path) -> dict[str, Any]:
        robot = load_robot(exp.robot)
        settings = ProgramSettings(
            cycle=CycleSettings(
                cycle_time=st.cycle_time or None,
                use_waits=st.use_waits,
                fly_by=st.fly_by,
                corridor_mm=st.corridor_mm or None,
                seed=exp.seed,
            ),
            export="rapid",  # the study's plan and its via-point module, no EGM files
            lever_plans=0,  # the study compares the plan: no search of the controller's levers
            write_anyway=st.write_anyway,
            pareto_points=st.pareto_points,
        )
        ctx.progress("cycle", 0, 1)
        done = optimize_program(program, robot, folder, settings, cell=cell_data)
        result, files, rapid = done.cycle, done.files, done.rapid
        ctx.progress("cycle", 1, 1)
        check = done.summary.get("written_program_check")
        written = "optimized.mod" in files or not rapid
        ctx.tell(
            f"{CYCLE_STAGE}: cycle {result.default_cycle_s:.3f} s -> {result.optimized_cycle_s:.3f} s, "
            f"{result.saved_pct:.1f} % saved on physics ({result.saved_lab_pct:.1f} % on the lab plant)"
            + ("" if result.limits_ok else "; REFUSED: a result breaks a limit, no program written")
            + ("" if written or not result.limits_ok else "; optimized.mod not written (see cycle.json)")
        )
        return {
            "program": st.program,
            "default_cycle_s": result.default_cycle_s,
            "optimized_cycle_s": result.optimized_cycle_s,
            "saved_pct": result.saved_pct if result.limits_ok else 0.0,
            "saved_lab_pct": result.saved_lab_pct if result.limits_ok else 0.0,
            "limits_ok": bool(result.limits_ok),
            "program_written": bool(written and result.limits_ok),
            "written_program_matches_plan": None if check is None else bool(check["within_tolerances"]),
        }

    return _stage(ctx, "cycle", CYCLE_STAGE, key, body)
