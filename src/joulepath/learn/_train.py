"""Train, tune and test energy models (thesis §4.3): ``joulepath train`` in library form."""

from __future__ import annotations

import io
import json
import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from sklearn.exceptions import ConvergenceWarning
from sklearn.model_selection import ParameterGrid

from joulepath._io import atomic_write_bytes, atomic_write_text, make_folder, remove_output
from joulepath.data import MAX_JOINTS, EnergyTable, target_columns
from joulepath.errors import InvalidInput, InvalidModel
from joulepath.learn._evaluate import physics_baseline, score
from joulepath.learn._families import FAMILIES, GRIDS, SUBSTITUTIONS, grid_for, make_pipeline
from joulepath.learn._features import INPUTS, PHYSICS_VERSION, input_columns
from joulepath.learn._model import EnergyModel, library_versions
from joulepath.learn._search import (
    connect_scheduler,
    cross_validate_candidate,
    estimate_fit_seconds,
    grid_search,
    make_splits,
    pending_candidates,
)
from joulepath.learn._svr import KERNEL_SVR_MAX_ROWS, SubsampleWarning

if TYPE_CHECKING:
    from joulepath.dynamics import Robot


@dataclass(frozen=True, slots=True, kw_only=True)
class TrainConfig:
    """Settings of :func:`train`.

    Attributes
    ----------
    families : tuple of {"mlp", "svr", "par", "xgb", "bases"}
        ``bases``: each joint's energy by least squares on energy bases of its motion
        (:class:`~joulepath.learn.JointEnergyBases`).
    targets : tuple of {"E", "E1", ..., "E6"}
    grid : {"quick", "thesis"}
        Hyperparameter grids (``thesis``: Tables 2.2–2.5).
    cv : int
        Folds.
    inputs : {"physics", "thesis"} or None
        Raw table features (``thesis``) or raw plus the nominal model's energy terms.
        None (the default): ``physics`` when the robot of the data is known (``robot``
        given, or the table names one), else ``thesis`` (:func:`choose_inputs`).
    seed : int
    n_jobs : int
        Local processes for the grid search.
    scheduler : str or None
        Dask scheduler address; the grid search then runs on that cluster.
    robot : str or None
        Robot of the data (for ``inputs="physics"`` and the physics baselines): a
        bundled robot, a named arm, a robot file or a twin folder. None: the robot the
        training table was ingested with (never a default robot).
    """

    families: tuple[str, ...] = FAMILIES
    targets: tuple[str, ...] = ("E",)
    grid: str = "quick"
    cv: int = 5
    inputs: str | None = None
    seed: int = 0
    n_jobs: int = 1
    scheduler: str | None = None
    robot: str | None = None

    def __post_init__(self) -> None:
        bad = [f for f in self.families if f not in FAMILIES]
        if bad or not self.families:
            raise InvalidInput(f"families {bad or '()'} unknown; use any of {', '.join(FAMILIES)} or all")
        known = target_columns(MAX_JOINTS)
        badt = [t for t in self.targets if t not in known]
        if badt or not self.targets:
            raise InvalidInput(f"targets {badt or '()'} unknown; use any of {', '.join(known)}")
        if self.grid not in GRIDS:
            raise InvalidInput(f"grid must be one of {GRIDS}, got {self.grid!r}")
        if self.inputs is not None and self.inputs not in INPUTS:
            raise InvalidInput(f"inputs must be one of {INPUTS}, got {self.inputs!r}")
        if self.cv < 2:
            raise InvalidInput(f"cv needs at least 2 folds, got {self.cv}")


@dataclass(frozen=True, slots=True)
class TrainingReport:
    """What :func:`train` produced: one row per (family, target), baselines, files."""

    results: pd.DataFrame
    baselines: list[dict[str, Any]]
    out_dir: Path
    models: dict[str, Path] = field(default_factory=dict)


NO_ROBOT_NOTE = (
    "no robot known (none given, the table names none): training on the raw inputs plus robot-free "
    "energy bases (kinematic inputs); give --robot for the grey-box physics inputs and the physics "
    "baselines"
)
"""The one line said when :func:`choose_inputs` takes the kinematic inputs for want of a robot."""


def choose_inputs(inputs: str | None, table: EnergyTable, robot: str | None = None) -> tuple[str, str]:
    """The inputs a training uses, and why, as ``(inputs, reason)``.

    Parameters
    ----------
    inputs : {"physics", "thesis", "kinematic"} or None
        The inputs asked for; None chooses: ``physics`` (raw plus the nominal
        model's energy terms) when the robot of the data is known, ``kinematic`` (raw
        plus robot-free energy bases) when it is not. On the real logs of an arm
        joulepath does not know (KUKA KR300, a run held out) the kinematic inputs
        predicted every held-out run better than the raw ones (``benchmarks/unknown_arm.py``);
        choosing between the two by CV over two 10 s runs picked the raw inputs once
        and lost (held-out R² -0.17 against 0.73).
    table : EnergyTable
        The training table (:attr:`EnergyTable.robot` names its robot, if any).
    robot : str or None
        The robot given for the data.

    Returns
    -------
    inputs : {"physics", "thesis", "kinematic"}
    reason : str
        ``"asked"``, ``"default: robot known"`` or ``"default: no robot known"``
        (recorded on the model card as ``inputs_reason``).

    Examples
    --------
    >>> import pandas as pd
    >>> from joulepath.data import EnergyTable
    >>> table = EnergyTable(frame=pd.DataFrame(), feature_set="joint")
    >>> choose_inputs(None, table)
    ('kinematic', 'default: no robot known')
    >>> choose_inputs(None, table, "irb120")
    ('physics', 'default: robot known')
    """
    if inputs is not None:
        return inputs, "asked"
    if robot is not None or table.robot is not None:
        return "physics", "default: robot known"
    return "kinematic", "default: no robot known"


def run_ids(table: EnergyTable) -> np.ndarray | None:
    """The run (the log it was ingested from) of each row, from the table's sources; None if unknown.

    Examples
    --------
    >>> import pandas as pd
    >>> from joulepath.data import EnergyTable
    >>> frame = pd.DataFrame({"move_id": [0, 0, 1, 2, 2]})
    >>> sources = ({"first_move_id": 0, "moves": 2}, {"first_move_id": 2, "moves": 1})
    >>> run_ids(EnergyTable(frame=frame, feature_set="joint", sources=sources)).tolist()
    [0, 0, 0, 1, 1]
    """
    spans = []
    for source in table.sources:
        first, n = source.get("first_move_id"), source.get("moves")
        if not (isinstance(first, int) and isinstance(n, int)):
            return None
        spans.append((first, n))
    if not spans:
        return None
    moves = table.frame["move_id"].to_numpy()
    out = np.full(moves.shape, -1, dtype=np.int64)
    for k, (first, n) in enumerate(spans):
        out[(moves >= first) & (moves < first + n)] = k
    return None if np.any(out < 0) else out


def cv_groups(table: EnergyTable, n_splits: int = 5) -> tuple[np.ndarray, str]:
    """The groups the grid search's CV keeps together, and their name.

    * ``"run"``: each log the table was ingested from, when the table holds at least
      ``n_splits`` of them. Moves of one run follow one another and share its
      trajectory, so folds by move leak: on the KUKA KR300 logs the CV by move said R²
      0.86-0.93 for models that reached -0.17 to 0.86 on a run held out
      (``benchmarks/unknown_arm.py``).
    * ``"run spans"``: with two or more runs but fewer than ``n_splits``, each run cut
      into contiguous spans of its moves (``ceil(n_splits / runs)`` a run, never a move
      split). Holding out whole runs would leave each fold a run or two to learn from
      (on those logs the CV by run said -0.20 to 0.78 for models that reached 0.73 to
      0.86); spans keep every fold's training data from every run while no fold holds a
      neighbouring move of its validation moves' span.
    * ``"move"``: a table of one log, or of runs the table cannot tell apart.

    Examples
    --------
    >>> import pandas as pd
    >>> from joulepath.data import EnergyTable
    >>> frame = pd.DataFrame({"move_id": [0, 1, 2, 3, 4, 5, 6, 7]})
    >>> sources = ({"first_move_id": 0, "moves": 4}, {"first_move_id": 4, "moves": 4})
    >>> groups, kind = cv_groups(EnergyTable(frame=frame, feature_set="joint", sources=sources), 4)
    >>> groups.tolist(), kind
    ([0, 0, 1, 1, 2, 2, 3, 3], 'run spans')
    """
    moves = table.frame["move_id"].to_numpy()
    runs = run_ids(table)
    if runs is None or np.unique(runs).size < 2:
        return moves, "move"
    n_runs = int(np.unique(runs).size)
    if n_runs >= n_splits:
        return runs, "run"
    per_run = -(-n_splits // n_runs)
    groups = np.empty(moves.shape, dtype=np.int64)
    for k in np.unique(runs):
        rows = runs == k
        ids, rank = np.unique(moves[rows], return_inverse=True)
        spans = min(per_run, ids.size)
        groups[rows] = k * per_run + rank * spans // ids.size
    return groups, "run spans"


def training_range(table: EnergyTable) -> dict[str, Any]:
    """What the training data cover: per joint positions, speeds and accelerations, move durations.

    Written on the model card (``training_range``); :meth:`EnergyModel.outside_training_range`
    flags rows beyond it. The table holds no payload: the loads are those of the logged runs,
    not recorded.
    """
    f = table.frame
    n = table.n_joints
    q = f[[f"q{i}" for i in range(1, n + 1)]].to_numpy()
    qd = np.abs(f[[f"dq{i}" for i in range(1, n + 1)]].to_numpy())
    qdd = np.abs(f[[f"ddq{i}" for i in range(1, n + 1)]].to_numpy())
    span = f.groupby("move_id")["t"].agg(lambda t: float(t.max() - t.min()))
    energy = f.groupby("move_id")["E"].sum()
    return {
        "q_min_rad": q.min(axis=0).tolist(),
        "q_max_rad": q.max(axis=0).tolist(),
        "speed_max_rad_s": qd.max(axis=0).tolist(),
        "acceleration_max_rad_s2": qdd.max(axis=0).tolist(),
        "move_duration_s": [float(span.min()), float(span.max())],
        "move_energy_J": [float(energy.min()), float(energy.max())],
        "payload": "not in the table: the loads of the logged runs",
    }


def _table_robot(
    table: EnergyTable, robot: str | None = None, *, inputs: str = "thesis"
) -> tuple[str, Robot]:
    """The robot of a table's data, as ``(source, robot)``: ``robot`` if given, else the table's own.

    A table names the robot it was ingested with (:attr:`EnergyTable.robot`, the
    robot's name). That name is loaded when it is a bundled robot's or a named arm's
    (``"irb120"``'s robot is named ``"IRB 120"``); any other robot (a file of one's
    own) must be given. Never falls back to a default robot.

    Raises
    ------
    InvalidInput
        The table names no robot and none is given, the table's robot is not a
        bundled one, or the robot has another number of joints than the table.
    """
    from joulepath.description import NAMED_ARMS, PRESETS
    from joulepath.dynamics import load_robot

    source = robot
    if source is None:
        if table.robot is None and inputs == "physics":
            raise InvalidInput(
                "the physics inputs need the robot of the data, but the table names none (it was "
                f"ingested without --robot) and none was given; give it (--robot, e.g. {PRESETS[0]} "
                "or a .urdf/.irml file), or train on the raw inputs (--inputs thesis)"
            )
        if table.robot is None:
            raise InvalidInput(
                f"the table names no robot (it was ingested without --robot) and no robot was given; "
                f"give the robot of the data (--robot), e.g. {PRESETS[0]} or a .urdf/.irml file"
            )
        by_name = {load_robot(p).name: p for p in PRESETS}
        source = table.robot if table.robot in (*PRESETS, *NAMED_ARMS) else by_name.get(table.robot)
        if source is None:
            raise InvalidInput(
                f"the table's robot {table.robot!r} is not a bundled robot or named arm; give its "
                "description (--robot path/to/robot.urdf or .irml)"
                + (", or train on the raw inputs (--inputs thesis)" if inputs == "physics" else "")
            )
    loaded = load_robot(source)
    if loaded.n_joints != table.n_joints:
        raise InvalidInput(
            f"robot {source!r} has {loaded.n_joints} joints, but the table holds a {table.n_joints}-joint "
            "arm; give the robot of the data (--robot)"
        )
    return source, loaded


def _fit_target(table: EnergyTable, family: str, target: str, pipeline: Any) -> np.ndarray:
    """What a family is fitted to for ``target``: the column, or for ``bases`` and ``E`` the joints'.

    The ``bases`` family fits each joint's energy on its own bases (``E1 .. En`` as a 2-D
    target; it predicts their sum, scored as ``E``), and one joint's for ``E{i}``.
    """
    names: str | list[str] = target
    if family == "bases" and target == "E":
        names = [f"E{i}" for i in range(1, table.n_joints + 1)]
    elif family == "bases":
        pipeline.set_params(model__joint=int(target[1:]))
    out: np.ndarray = np.asarray(table.frame[names].to_numpy(dtype=np.float64))
    return out


def _duration(seconds: float) -> str:
    """``"45 s"``, ``"3 min"``, ``"2.5 h"``: a rough duration for progress lines."""
    if seconds < 90:
        return f"{max(seconds, 1):.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _progress(
    say: Callable[[str], None],
    family: str,
    target: str,
    on_search: Callable[[str, str, int, int], None] | None,
) -> Callable[[int, int], None]:
    """A grid-search progress callback that says done/total, time spent and time left."""
    start = time.perf_counter()
    first: list[int] = []

    def report(done: int, total: int) -> None:
        if on_search is not None:
            on_search(family, target, done, total)
        if not first:
            first.append(done)
            cached = f" ({done} from the cache)" if done else ""
            say(f"{family} {target}: {done}/{total} candidates{cached}")
            return
        spent = time.perf_counter() - start
        fitted = done - first[0]
        left = spent / fitted * (total - done) if fitted else float("nan")
        eta = f", about {_duration(left)} left" if done < total and np.isfinite(left) else ""
        say(f"{family} {target}: {done}/{total} candidates, {_duration(spent)} spent{eta}")

    return report


def _announce(
    say: Callable[[str], None],
    family: str,
    target: str,
    pipeline: Any,
    grid: dict[str, list[Any]],
    X: np.ndarray,
    y: np.ndarray,
    groups: np.ndarray,
    config: TrainConfig,
    cache_dir: Path,
    n_splits: int,
) -> None:
    """Say how many fits the search, the shuffled CV and the refit need and roughly how long."""
    n_points = len(ParameterGrid(grid))
    label = f"{family} {target}"
    pending = pending_candidates(
        grid, X, y, groups, family=family, n_splits=n_splits, seed=config.seed, cache_dir=cache_dir
    )
    fold_rows = round(len(y) * (n_splits - 1) / n_splits)
    n_fits = pending * n_splits + config.cv + 1
    if (
        family == "svr"
        and fold_rows > KERNEL_SVR_MAX_ROWS
        and any(k != "linear" for k in grid.get("model__kernel", ["rbf"]))
    ):
        say(
            f"{label}: kernel SVR candidates fit on a random {KERNEL_SVR_MAX_ROWS:,} of the ~{fold_rows:,} "
            "rows of each fold (KERNEL_SVR_MAX_ROWS); the linear kernel uses all rows"
        )
    per_fit, trial = estimate_fit_seconds(pipeline, grid, X, y, n_rows=fold_rows, seed=config.seed)
    workers = max(1, min(config.n_jobs, pending)) if config.scheduler is None else max(1, pending)
    total = per_fit * (np.ceil(pending / workers) * n_splits + config.cv + config.cv / (config.cv - 1))
    par = f" on {workers} processes" if workers > 1 and config.scheduler is None else ""
    say(
        f"{label}: {n_fits} fits ({pending} of {n_points} candidates x {n_splits} folds{par}, "
        f"{config.cv} shuffled folds, 1 refit) on ~{fold_rows:,} rows; roughly {_duration(total)} "
        f"(extrapolated from trial fits on up to {trial:,} rows)"
    )


def _fmt_params(params: dict[str, Any]) -> str:
    return ", ".join(f"{k.removeprefix('model__')}={v}" for k, v in sorted(params.items()))


def train(
    train_table: EnergyTable,
    test_table: EnergyTable,
    config: TrainConfig,
    out_dir: str | os.PathLike[str],
    *,
    progress: Callable[[str], None] | None = None,
    on_search: Callable[[str, str, int, int], None] | None = None,
) -> TrainingReport:
    """Grid-search, cross-validate, refit and test every (family, target); save models and reports.

    Writes ``<out>/<family>-<target>/`` (model + card), ``results.csv`` (thesis
    Tables 4.1–4.4 layout plus the honest metrics), ``report.json`` and bar plots
    of the test scores (thesis Figs 4.11–4.17).

    Parameters
    ----------
    train_table, test_table : EnergyTable
        Non-empty, of one feature set.
    config : TrainConfig
    out_dir : path
    progress : callable(message), optional
        Receives one-line messages for people: before each search the number of
        fits and a rough time, then candidates done, time spent and time left.
    on_search : callable(family, target, done, total), optional
        Receives the grid search's progress as numbers (for progress bars; no
        need to parse ``progress`` messages).
    """
    for name, table in (("training", train_table), ("test", test_table)):
        if len(table.frame) == 0:
            raise InvalidInput(
                f"the {name} table has no rows; ingest logs with at least one move for the {name} table"
            )
    if train_table.feature_set != test_table.feature_set:
        raise InvalidInput(
            f"train table has feature set {train_table.feature_set!r}, test table "
            f"{test_table.feature_set!r}; ingest both the same way"
        )
    if train_table.n_joints != test_table.n_joints:
        raise InvalidInput(
            f"the training table holds a {train_table.n_joints}-joint arm, the test table a "
            f"{test_table.n_joints}-joint arm; give tables of one robot"
        )
    beyond = [t for t in config.targets if t not in train_table.targets]
    if beyond:
        raise InvalidInput(
            f"targets {', '.join(beyond)} name joints the {train_table.n_joints}-joint arm of the table "
            f"does not have; use any of {', '.join(train_table.targets)}"
        )
    say = progress or (lambda _msg: None)
    inputs, inputs_reason = choose_inputs(config.inputs, train_table, config.robot)
    robot_source: str | None = None
    robot: Robot | None = None
    if inputs == "physics" or config.robot is not None or train_table.robot is not None:
        robot_source, robot = _table_robot(train_table, config.robot, inputs=inputs)
    elif inputs_reason == "asked":
        say("no robot given and the table names none: the physics baselines are left out")
    else:
        say(NO_ROBOT_NOTE)
    if config.scheduler is not None:  # an unreachable scheduler fails before anything is written
        connect_scheduler(config.scheduler).close()
    out = Path(out_dir)
    make_folder(out)
    groups, group_kind = cv_groups(train_table, config.cv)
    moves = train_table.frame["move_id"].to_numpy()
    n_splits = min(config.cv, int(np.unique(groups).size))
    covered = training_range(train_table)
    rows: list[dict[str, Any]] = []
    saved: dict[str, Path] = {}
    for family in config.families:
        cols = input_columns(train_table.feature_set, inputs, train_table.n_joints, family)
        X = train_table.frame[list(cols)].to_numpy(dtype=np.float64)
        for target in config.targets:
            pipeline = make_pipeline(
                family, seed=config.seed, inputs=inputs, columns=cols, robot=robot_source
            )
            y = _fit_target(train_table, family, target, pipeline)
            grid = grid_for(family, config.grid)
            cache_dir = out / ".gridcache" / f"{family}-{target}"
            _announce(say, family, target, pipeline, grid, X, y, groups, config, cache_dir, n_splits)
            t0 = time.perf_counter()
            search = grid_search(
                pipeline,
                grid,
                X,
                y,
                groups,
                family=family,
                split="grouped",
                n_splits=n_splits,
                seed=config.seed,
                cache_dir=cache_dir,
                n_jobs=config.n_jobs,
                scheduler=config.scheduler,
                progress=_progress(say, family, target, on_search),
            )
            best = search.best
            say(f"{family} {target}: shuffled-fold CV of the best candidate ({config.cv} fits)")
            shuffled = make_splits(len(y), moves, split="shuffled", n_splits=config.cv, seed=config.seed)
            r2_s, mae_s, _ = cross_validate_candidate(pipeline, best.params, X, y, shuffled)
            model_pipe = pipeline.set_params(**best.params)

            say(f"{family} {target}: refitting the best candidate on all {len(y):,} rows")
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ConvergenceWarning)
                warnings.simplefilter("ignore", SubsampleWarning)  # said before the search
                model_pipe.fit(X, y)
            card = {
                "family": family,
                "target": target,
                "feature_set": train_table.feature_set,
                "inputs": inputs,
                "inputs_reason": inputs_reason,
                "physics_version": PHYSICS_VERSION,
                "input_columns": list(cols),
                "robot": train_table.robot,
                "robot_source": robot_source,
                "units": {"inputs": "SI (rad, rad/s, rad/s^2, m, m/s, s)", "target": "J per row"},
                "training_data_sha256": train_table.fingerprint(),
                "training_rows": len(y),
                "training_moves": int(np.unique(moves).size),
                "training_range": covered,
                "grid": config.grid,
                "best_params": {k: repr(v) for k, v in best.params.items()},
                "cv_grouped": {
                    "r2_mean": best.r2_mean,
                    "r2_std": best.r2_std,
                    "mae_mean": best.mae_mean,
                    "mae_std": best.mae_std,
                    "folds": n_splits,
                    "groups": group_kind,
                },
                "cv_shuffled": {
                    "r2_mean": float(np.mean(r2_s)),
                    "r2_std": float(np.std(r2_s)),
                    "mae_mean": float(np.mean(mae_s)),
                    "mae_std": float(np.std(mae_s)),
                },
                "seed": config.seed,
                "versions": library_versions(),
            }
            if family in SUBSTITUTIONS:
                card["substitution"] = SUBSTITUTIONS[family]
            fit_rows = getattr(model_pipe.steps[-1][1], "n_fit_rows_", len(y))
            if fit_rows != len(y):
                card["fit_rows"] = int(fit_rows)
            model = EnergyModel(model_pipe, card)
            test_scores = score(test_table, target, model.predict(test_table.frame))
            outside = model.outside_training_range(test_table.frame)
            card["test"] = {
                **test_scores.as_dict(),
                "outside_training_range_pct": 100.0 * float(outside.mean()),
            }
            card["cv_vs_held_out"] = {
                "cv_r2": best.r2_mean,
                "cv_groups": group_kind,
                "held_out_r2": test_scores.r2,
                "held_out_moves": test_scores.n_moves,
            }
            model.card = card
            folder = model.save(out / f"{family}-{target}")
            saved[f"{family}-{target}"] = folder
            rows.append(
                {
                    "family": family,
                    "target": target,
                    "inputs": inputs,
                    "cv_groups": group_kind,
                    "cv_grouped_r2": best.r2_mean,
                    "cv_grouped_r2_std": best.r2_std,
                    "cv_grouped_mae": best.mae_mean,
                    "cv_grouped_mae_std": best.mae_std,
                    "cv_shuffled_r2": float(np.mean(r2_s)),
                    "cv_shuffled_r2_std": float(np.std(r2_s)),
                    "cv_shuffled_mae": float(np.mean(mae_s)),
                    "cv_shuffled_mae_std": float(np.std(mae_s)),
                    "test_r2": test_scores.r2,
                    "test_mae": test_scores.mae,
                    "test_outside_range_pct": 100.0 * float(outside.mean()),
                    "path_median_pct": test_scores.path_median_pct,
                    "path_p95_pct": test_scores.path_p95_pct,
                    "best_params": _fmt_params(best.params),
                    "candidates": len(search.candidates),
                    "fitted_now": search.n_fitted,
                    "search_s": time.perf_counter() - t0,
                }
            )
            say(f"{family} {target}: grouped CV R² {best.r2_mean:.4f}, test R² {test_scores.r2:.4f}")
    from joulepath.learn._importance import feature_importance, plot_importance, rank_joints

    say("feature importance on 5,000 training rows")
    imp = feature_importance(train_table, "E", max_rows=5000, seed=config.seed)
    atomic_write_text(out / "importance_E.csv", imp.to_csv())
    plot_importance(imp, out / "importance_E.png", title="Feature importance for E (training data)")
    joints = rank_joints(imp)
    atomic_write_text(out / "joints.json", json.dumps({"target": "E", "joints_by_influence": joints}))
    baselines = (
        []
        if robot is None
        else [physics_baseline(test_table, robot, friction=None, label="dynamics model, no friction")]
    )
    if robot is not None and robot.friction is not None:
        baselines.append(
            physics_baseline(
                test_table, robot, friction=robot.friction, label="dynamics model + nominal friction"
            )
        )
    results = pd.DataFrame(rows)
    atomic_write_text(out / "results.csv", results.to_csv(index=False))
    report = {
        "config": asdict(config),
        "inputs": inputs,
        "inputs_reason": inputs_reason,
        "robot_source": robot_source,
        "train": {
            "rows": len(train_table.frame),
            "moves": train_table.n_moves,
            "sha256": train_table.fingerprint(),
        },
        "test": {"rows": len(test_table.frame), "moves": test_table.n_moves},
        "results": rows,
        "baselines": baselines,
        "substitutions": {f: SUBSTITUTIONS[f] for f in config.families if f in SUBSTITUTIONS},
        "joints_by_influence": joints,
    }
    atomic_write_text(out / "report.json", json.dumps(report, indent=2, default=str))
    plot_test_scores(results, baselines, out)
    _remove_stale_models(out, set(saved))
    return TrainingReport(results=results, baselines=baselines, out_dir=out, models=saved)


def _remove_stale_models(out: Path, kept: set[str]) -> None:
    """Remove model folders (a ``card.json`` inside) of an earlier run that this run did not produce.

    ``results.csv`` and ``report.json`` describe this run only, so a model left from an
    earlier one would otherwise still be found by :func:`best_model`.
    """
    for card in out.glob("*/card.json"):
        folder = card.parent
        if folder.name not in kept and folder.is_dir() and not folder.is_symlink():
            remove_output(folder)


def plot_test_scores(results: pd.DataFrame, baselines: Sequence[dict[str, Any]], out: Path) -> list[Path]:
    """Bar plots of test R² and MAE per family for each target (thesis Figs 4.11–4.17)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    for target, group in results.groupby("target"):
        fig, axes = plt.subplots(1, 2, figsize=(8, 3.2))
        labels = list(group["family"]) + ["physics", "physics+fr"][: len(baselines)]
        r2 = list(group["test_r2"]) + [b["scores"][target]["r2"] for b in baselines]
        mae = list(group["test_mae"]) + [b["scores"][target]["mae"] for b in baselines]
        axes[0].bar(labels, r2, color="tab:blue")
        axes[0].set_ylabel("R² (test moves)")
        axes[0].set_ylim(min(0.0, min(r2)), 1.0)
        axes[1].bar(labels, mae, color="tab:orange")
        axes[1].set_ylabel("MAE (J per row)")
        fig.suptitle(f"Test scores for {target}")
        fig.tight_layout()
        path = out / f"test_scores_{target}.png"
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110)
        plt.close(fig)
        paths.append(atomic_write_bytes(path, buf.getvalue()))
    return paths


def load_models(folder: str | os.PathLike[str]) -> dict[str, EnergyModel]:
    """All models of a training output folder, keyed ``<family>-<target>``."""
    root = Path(folder)
    if not root.is_dir():
        raise InvalidModel(f"{root}: no such folder; give the --out folder of `joulepath train`")
    if (root / "card.json").is_file():
        raise InvalidModel(
            f"{root}: is the folder of one model; give the folder above it (the --out of `joulepath train`)"
        )
    found = {p.parent.name: EnergyModel.load(p.parent) for p in sorted(root.glob("*/card.json"))}
    if not found:
        raise InvalidModel(f"{root}: no models (folders with card.json); run `joulepath train` first")
    return found


def best_model(
    folder: str | os.PathLike[str], target: str = "E", *, family: str | None = None
) -> EnergyModel:
    """The model for ``target`` with the best grouped-CV R² (optionally of one family)."""
    models = [
        m
        for m in load_models(folder).values()
        if m.target == target and (family is None or m.family == family)
    ]
    if not models:
        raise InvalidModel(
            f"{folder}: no model for target {target!r}"
            + (f" of family {family!r}" if family else "")
            + f"; train one with `joulepath train --target {target}"
            + (f" --family {family}`" if family else "`")
        )
    return max(models, key=lambda m: float(m.card["cv_grouped"]["r2_mean"]))
