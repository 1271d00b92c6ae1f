"""The ``[identify]`` stage's work: a twin, the loop closed on it, and the models side by side.

:func:`run_identify` identifies a twin from the training logs, optimizes tasks on it
(the saving it predicts against the one realized on the plant), and scores five
models on the same test sets (issue 13, item 3):

* the identified twin and the nominal physics (+ nominal friction): torque and energy;
* a learned model of ``E`` (the train stage's best, else the study's MLP) trained on
  the real training rows, the same model (same family and hyperparameters, refitted)
  trained on rows simulated on the twin, and trained on SDV rows: energy only.

Test sets: the held-out test moves; moves of another kind (the robot's nominal, i.e.
widest, joint ranges instead of the data's range set) simulated on the data's plant;
and the loop's optimized paths, played on the same plant and logged like any move.
Every test set is a log, read by :func:`joulepath.data.ingest` (rows: row energy R²,
per-move path-energy error) and :func:`joulepath.identify.data_from_logs` (torque R²).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from joulepath._io import atomic_write_text
from joulepath._runfolder import IDENTIFY_LOOP, IDENTIFY_SCORE_COLUMNS, IDENTIFY_SCORES, IDENTIFY_TWIN
from joulepath._typing import FloatArray
from joulepath.data import EnergyTable
from joulepath.dynamics import Robot
from joulepath.identify import IdentificationData
from joulepath.trajectory import Trajectory


@dataclass(frozen=True, slots=True)
class ModelScore:
    """One model measured on one test set (a row of ``identify/scores.csv``).

    ``torque_r2_worst_joint`` is None for a model that predicts energy only; the path
    error is the median over the test set's moves of ``|ΣE_pred − ΣE| / ΣE`` (%).
    """

    model: str
    trained_on: str
    test_set: str
    moves: int
    rows: int
    torque_r2_worst_joint: float | None
    energy_r2: float
    path_error_median_pct: float


@dataclass(frozen=True, slots=True)
class LoopTask:
    """A task optimized on the twin: predicted (twin, motor side) against realized (plant) saving."""

    task: int
    duration_s: float
    limits_ok: bool
    predicted_saved_pct: float
    realized_saved_lab_pct: float | None
    energy_default_lab_J: float | None
    energy_optimized_lab_J: float | None


@dataclass(frozen=True, slots=True)
class IdentifyResult:
    """What the stage found (its ``stage.json`` record holds the scalars)."""

    condition_number: float
    gear_efficiency: float
    scores: tuple[ModelScore, ...]
    loop: tuple[LoopTask, ...]
    learned: str
    notes: tuple[str, ...]

    def score(self, model: str, test_set: str) -> ModelScore:
        return next(s for s in self.scores if s.model == model and s.test_set == test_set)

    def scores_frame(self) -> pd.DataFrame:
        return pd.DataFrame([asdict(s) for s in self.scores], columns=list(IDENTIFY_SCORE_COLUMNS))

    def loop_frame(self) -> pd.DataFrame:
        return pd.DataFrame([asdict(t) for t in self.loop])


TWIN = "identified twin"
NOMINAL = "nominal physics + nominal friction"
LEARNED_REAL = "learned, real rows"
LEARNED_TWIN = "learned, twin rows"
LEARNED_SDV = "learned, SDV rows"
HELD_OUT = "held-out moves"
OPTIMIZED = "optimized paths"


@dataclass(frozen=True, slots=True)
class _TestSet:
    name: str
    table: EnergyTable
    data: IdentificationData


@dataclass(frozen=True, slots=True)
class _Candidate:
    model: str
    trained_on: str
    torque: Callable[[IdentificationData], FloatArray] | None
    rows: Callable[[EnergyTable], FloatArray]


def _score(c: _Candidate, ts: _TestSet) -> ModelScore:
    from sklearn.metrics import r2_score

    from joulepath.identify import score_prediction
    from joulepath.learn import path_errors

    torque = None
    if c.torque is not None:
        torque = min(score_prediction(c.torque(ts.data), ts.data).torque_r2)
    frame = ts.table.frame
    y = frame["E"].to_numpy(dtype=float)
    p = np.asarray(c.rows(ts.table), dtype=float)
    errors = path_errors(frame["move_id"].to_numpy(), y, p)
    return ModelScore(
        model=c.model,
        trained_on=c.trained_on,
        test_set=ts.name,
        moves=int(frame["move_id"].nunique()),
        rows=len(frame),
        torque_r2_worst_joint=torque,
        energy_r2=float(r2_score(y, p)),
        path_error_median_pct=100.0 * float(np.median(errors)) if errors.size else float("nan"),
    )


def _joint_arrays(table: EnergyTable) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    f = table.frame
    j = range(1, table.n_joints + 1)
    q = f[[f"q{i}" for i in j]].to_numpy(dtype=float)
    qd = f[[f"dq{i}" for i in j]].to_numpy(dtype=float)
    qdd = f[[f"ddq{i}" for i in j]].to_numpy(dtype=float)
    return q, qd, qdd, f["dt"].to_numpy(dtype=float)


def _torque_rows(
    torque: Callable[[FloatArray, FloatArray, FloatArray], FloatArray],
) -> Callable[[EnergyTable], FloatArray]:
    """Row energies ``E`` of a torque model on a table's rows (:func:`joulepath.energy.joint_energy`)."""
    from joulepath.energy import joint_energy

    def rows(table: EnergyTable) -> FloatArray:
        q, qd, qdd, dt = _joint_arrays(table)
        out: FloatArray = joint_energy(torque(q, qd, qdd), qd, dt).sum(axis=1)
        return out

    return rows


@dataclass(frozen=True, slots=True)
class _Played:
    """A planned path played from rest after ``delay`` s and held at its ends.

    A :class:`joulepath.sim.Commanded` motion.

    Between the path's samples ``q``, ``qd`` and ``qdd`` are interpolated linearly.
    """

    path: Trajectory
    delay: float

    def evaluate(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        s = np.asarray(t, dtype=float) - self.delay
        inside = ((s >= 0) & (s <= self.path.t[-1]))[:, None]

        def at(x: FloatArray) -> FloatArray:
            return np.column_stack([np.interp(s, self.path.t, x[:, j]) for j in range(x.shape[1])])

        return at(self.path.q), at(self.path.qd) * inside, at(self.path.qdd) * inside


def play_paths(
    paths: Sequence[Trajectory], robot: Robot, plant: str, folder: Path, *, seed: np.random.SeedSequence
) -> list[str]:
    """Run planned paths on a plant (tracking, noise) and write one controller log per path."""
    from joulepath._io import make_folder
    from joulepath.data import write_controller_log
    from joulepath.sim import ControllerConfig, log_text, log_times, make_plant, run_plant

    config = ControllerConfig()
    plant_model = make_plant(plant, robot)
    make_folder(folder)
    out = []
    for k, (path, child) in enumerate(zip(paths, seed.spawn(len(paths)), strict=True)):
        rng = np.random.default_rng(child)
        t = log_times(float(path.t[-1]) + 2 * config.idle, config, rng=rng)
        measured = run_plant(plant_model, _Played(path, config.idle), t, rng=rng)
        log = folder / f"path-{k:03d}.csv"
        write_controller_log(log, log_text(robot, measured))
        out.append(str(log))
    return out


def _one_move_per_log(logs: Sequence[str], robot: Robot) -> EnergyTable:
    """The logs' rows, each log one move (a played path is one move, whatever its speed profile)."""
    from joulepath.data import ingest

    tables = [ingest([log], robot=robot) for log in logs]
    frames = [t.frame.assign(move_id=k) for k, t in enumerate(tables)]
    return EnergyTable(frame=pd.concat(frames, ignore_index=True), feature_set=tables[0].feature_set)


def _learned_model(models: Path, train: EnergyTable, exp: Any) -> tuple[Any, tuple[str, ...], str]:
    """The learned model of E on real rows: the train stage's best, else XGBoost fitted here.

    (The study's small MLP of ``_study_utility`` is no stand-in: on a few dozen moves
    with physics inputs its test R² can be far below zero.)
    """
    from joulepath.learn import best_model, input_columns, make_pipeline

    if models.is_dir():
        try:
            m = best_model(models, "E")
        except Exception:  # no model of E (other targets only): fall back below
            m = None
        if m is not None:
            label = f"{m.family}, {m.card['inputs']} inputs, the train stage's best model of E"
            return m.pipeline, m.input_columns, label
    cols = input_columns(train.feature_set, exp.train.inputs, train.n_joints)
    pipe = make_pipeline("xgb", seed=exp.seed, inputs=exp.train.inputs, columns=cols, robot=exp.robot)
    _fit(pipe, train, cols)
    label = f"xgb (default hyperparameters), {exp.train.inputs} inputs, fitted here (no train stage)"
    return pipe, cols, label


def _fit(pipe: Any, table: EnergyTable, cols: tuple[str, ...]) -> None:
    from sklearn.exceptions import ConvergenceWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        pipe.fit(table.frame[list(cols)].to_numpy(dtype=float), table.frame["E"].to_numpy(dtype=float))


def _rows_of(pipe: Any, cols: tuple[str, ...]) -> Callable[[EnergyTable], FloatArray]:
    def rows(table: EnergyTable) -> FloatArray:
        out: FloatArray = pipe.predict(table.frame[list(cols)].to_numpy(dtype=float))
        return out

    return rows


def run_identify(
    exp: Any,
    root: Path,
    folder: Path,
    *,
    train_logs: list[str],
    test_logs: list[str],
    progress: Callable[[int, int], None],
) -> IdentifyResult:
    """Identify a twin in ``folder``, close the loop on it and score the models (see the module)."""
    from sklearn.base import clone

    from joulepath.data import ingest, load_table
    from joulepath.dynamics import NOMINAL_FRICTION, load_robot
    from joulepath.errors import InvalidInput
    from joulepath.identify import IdentifyOptions, data_from_logs, identify, twin_robot, write_twin
    from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks
    from joulepath.sim import simulate

    st, d = exp.identify, exp.data
    steps = 5 + st.loop_tasks
    robot = load_robot(exp.robot)
    progress(0, steps)
    ident = identify(data_from_logs(train_logs, robot), robot, IdentifyOptions())
    write_twin(ident, robot, folder / IDENTIFY_TWIN)
    twin = twin_robot(robot, ident)
    progress(1, steps)

    children = np.random.SeedSequence(exp.seed).spawn(9)
    seed = int(children[5].generate_state(1)[0])
    loop: list[LoopTask] = []
    optimized: list[Trajectory] = []
    for k, (q0, qf, T) in enumerate(random_tasks(robot, st.loop_tasks, seed=seed, range_set=st.range_set)):
        res = optimize_move(twin, q0, qf, T, OptimizeConfig(seed=exp.seed))
        s = res.summary
        # the twin's prediction on the lab's logged measure: its identified gears included
        mech = s.measure(s.energy_lab_measure)
        if mech is None:  # a twin always has its gear efficiency
            raise InvalidInput(f"the twin has no {s.energy_lab_measure} energy: {s.energies_unavailable}")
        e_def, e_opt = mech.default_J, mech.optimized_J
        optimized.append(res.optimized)
        loop.append(
            LoopTask(
                task=k,
                duration_s=float(T),
                limits_ok=bool(s.limits_ok),
                predicted_saved_pct=100 * (e_def - e_opt) / e_def,
                realized_saved_lab_pct=s.saved_lab_pct,
                energy_default_lab_J=s.energy_default_lab_J,
                energy_optimized_lab_J=s.energy_optimized_lab_J,
            )
        )
        progress(2 + k, steps)

    # ------------------------------------------------------------ test sets
    notes: list[str] = []
    sets = [_TestSet(HELD_OUT, ingest(test_logs, robot=robot), data_from_logs(test_logs, robot))]
    if d.train_logs:
        notes.append("moves of another kind and optimized paths need a plant to run on: logs were given")
    else:
        used = robot.ranges_for(d.range_set)[0]
        other = next((n for n in robot.range_set_names if n != used), None)
        if other is not None:
            log = simulate(
                folder / "logs" / "other-ranges.csv",
                plant=d.plant,
                n_moves=d.test_moves,
                seed=children[7],
                robot=exp.robot,
                range_set=other,
            ).log
            sets.append(
                _TestSet(
                    f"held-out moves, {other} ranges",
                    ingest([log], robot=robot),
                    data_from_logs([log], robot),
                )
            )
        if optimized:
            logs = play_paths(optimized, robot, d.plant, folder / "logs" / "optimized", seed=children[8])
            sets.append(_TestSet(OPTIMIZED, _one_move_per_log(logs, robot), data_from_logs(logs, robot)))
    progress(2 + st.loop_tasks, steps)

    # ------------------------------------------------------------ models
    train = load_table(root / "data" / "train.parquet")
    base, cols, learned = _learned_model(root / "models", train, exp)
    twin_log = simulate(
        folder / "logs" / "twin-rows.csv",
        plant=str(folder / IDENTIFY_TWIN),
        n_moves=d.train_moves,
        seed=children[6],
        robot=exp.robot,
        range_set=d.range_set,
    ).log
    twin_table = ingest([twin_log], robot=robot)
    on_twin = clone(base)
    _fit(on_twin, twin_table, cols)
    sdv_table, sdv_from = _sdv_rows(exp, root, train)
    on_sdv = clone(base)
    _fit(on_sdv, sdv_table, cols)
    progress(3 + st.loop_tasks, steps)

    def nominal_torque(q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
        out: FloatArray = robot.inverse_dynamics(q, qd, qdd, friction=NOMINAL_FRICTION)
        return out

    def twin_torque(q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
        return ident.motor_torque(robot, q, qd, qdd)

    candidates = [
        _Candidate(
            TWIN,
            f"{len(train_logs)} training log(s), {ident.fit.n_samples:,} samples",
            lambda x: twin_torque(x.q, x.qd, x.qdd),
            _torque_rows(twin_torque),
        ),
        _Candidate(
            NOMINAL,
            "nothing (the robot's nominal description)",
            lambda x: nominal_torque(x.q, x.qd, x.qdd),
            _torque_rows(nominal_torque),
        ),
        _Candidate(
            LEARNED_REAL,
            f"{len(train.frame):,} rows, {train.n_moves} moves of the train set",
            None,
            _rows_of(base, cols),
        ),
        _Candidate(
            LEARNED_TWIN,
            f"{len(twin_table.frame):,} rows, {twin_table.n_moves} moves simulated on the twin",
            None,
            _rows_of(on_twin, cols),
        ),
        _Candidate(LEARNED_SDV, f"{len(sdv_table.frame):,} rows, {sdv_from}", None, _rows_of(on_sdv, cols)),
    ]
    scores = tuple(_score(c, ts) for ts in sets for c in candidates)
    progress(steps, steps)
    return IdentifyResult(
        condition_number=float(ident.condition_number),
        gear_efficiency=float(ident.gear_efficiency),
        scores=scores,
        loop=tuple(loop),
        learned=learned,
        notes=tuple(notes),
    )


def _sdv_rows(exp: Any, root: Path, train: EnergyTable) -> tuple[EnergyTable, str]:
    """The synth stage's rows of its best method, else GaussianCopula rows grown here from ``train``."""
    import json

    from joulepath.data import load_table

    synth = root / "synth"
    record = synth / "stage.json"
    if record.is_file():
        best = json.loads(record.read_text(encoding="utf-8")).get("best_method")
        if best and (synth / f"{best}.parquet").is_file():
            s = exp.synth
            epochs = "" if best == "copula" else f", {s.epochs} epochs"
            origin = f"{best} from the synth stage ({s.source} rows{epochs})"
            return load_table(synth / f"{best}.parquet"), origin
    from joulepath.synth import SynthConfig, Synthesizer

    table = Synthesizer(SynthConfig(method="copula", seed=exp.seed)).fit(train).sample(len(train.frame))
    return table, "copula grown here from the train rows (no synth stage)"


def write_identify(result: IdentifyResult, folder: Path) -> None:
    """The stage's tables into its folder (names declared in :mod:`joulepath._runfolder`)."""
    atomic_write_text(folder / IDENTIFY_SCORES, result.scores_frame().to_csv(index=False))
    atomic_write_text(folder / IDENTIFY_LOOP, result.loop_frame().to_csv(index=False))
