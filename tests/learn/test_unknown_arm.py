"""Energy models of an arm joulepath does not know: robot-free inputs, CV by run, the trained range."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from joulepath.data import EnergyTable
from joulepath.energy import joint_energy
from joulepath.learn import (
    EnergyModel,
    KinematicFeatures,
    TrainConfig,
    cv_groups,
    input_columns,
    kinematic_transform,
    run_ids,
    train,
    training_range,
)


@pytest.fixture(scope="module")
def two_run_tables(lab_tables):
    """The lab tables without their robot; the training table is two runs (logs) of the lab robot."""
    train_table, test_table = lab_tables
    frame = train_table.frame
    moves = np.sort(frame["move_id"].unique())
    half = int(moves[len(moves) // 2])
    sources = (
        {"file": "run1.csv", "first_move_id": int(moves[0]), "moves": half - int(moves[0])},
        {"file": "run2.csv", "first_move_id": half, "moves": int(moves[-1]) + 1 - half},
    )
    return replace(train_table, robot=None, sources=sources), replace(test_table, robot=None)


def test_kinematic_transform_adds_the_energy_bases_of_each_joint(rng):
    cols = input_columns("joint", "kinematic", 6)
    X = rng.normal(size=(7, len(cols)))
    X[:, cols.index("dt")] = rng.uniform(0.001, 0.02, 7)
    out = KinematicFeatures(columns=cols).fit(X).transform(X)
    assert out.shape == (7, len(cols) + 18)
    np.testing.assert_array_equal(out[:, : len(cols)], X)
    qd = X[:, [cols.index(f"dq{i}") for i in range(1, 7)]]
    qdd = X[:, [cols.index(f"ddq{i}") for i in range(1, 7)]]
    dt = X[:, cols.index("dt")]
    # |qd| dt is the energy of a unit torque through joulepath.energy's one definition
    np.testing.assert_allclose(out[:, len(cols) : len(cols) + 6], joint_energy(np.ones_like(qd), qd, dt))
    np.testing.assert_allclose(out[:, len(cols) + 6 : len(cols) + 12], joint_energy(qd, qd, dt))
    np.testing.assert_allclose(out[:, len(cols) + 12 :], joint_energy(qdd, qd, dt))
    # one row or many: the same rows
    index = KinematicFeatures(columns=cols).fit(X).index_
    np.testing.assert_array_equal(kinematic_transform(X[:1], index), out[:1])


def test_kinematic_features_refuse_columns_without_speeds(rng):
    with pytest.raises(ValueError, match="needs columns"):
        KinematicFeatures(columns=("q1", "dt")).fit(rng.normal(size=(3, 2)))
    with pytest.raises(ValueError, match="X has 3 columns"):
        KinematicFeatures(columns=("q1", "dq1")).fit(rng.normal(size=(3, 3)))


def test_cv_groups_are_the_runs_of_a_table_of_several_logs(two_run_tables, lab_tables):
    table = two_run_tables[0]
    groups, kind = cv_groups(table, 2)
    assert kind == "run" and set(np.unique(groups)) == {0, 1}
    runs = run_ids(table)
    # fewer runs than folds: each run cut into contiguous spans of whole moves
    spans, kind = cv_groups(table, 5)
    assert kind == "run spans" and np.unique(spans).size == 6
    moves = table.frame["move_id"].to_numpy()
    for g in np.unique(spans):
        in_span = np.unique(moves[spans == g])
        assert np.unique(runs[spans == g]).size == 1  # a span lies in one run
        assert np.array_equal(in_span, np.arange(in_span.min(), in_span.max() + 1))  # contiguous
        assert not np.isin(in_span, moves[spans != g]).any()  # no move split between spans
    # every move lies in one run, and the runs follow the moves' order
    per_move = pd.Series(runs).groupby(table.frame["move_id"].to_numpy()).nunique()
    assert (per_move == 1).all() and np.all(np.diff(runs) >= 0)
    assert cv_groups(lab_tables[0])[1] == "move"  # one log: by move
    broken = replace(table, sources=({"file": "x.csv"},))
    assert run_ids(broken) is None and cv_groups(broken)[1] == "move"


def test_default_training_of_an_unknown_arm_is_cross_validated_by_run(two_run_tables, tmp_path):
    """Kinematic inputs, the grid search's folds by run; the card keeps the CV estimate beside the
    held-out figure and the range of the training data."""
    train_table, test_table = two_run_tables
    report = train(train_table, test_table, TrainConfig(families=("par",), cv=5), tmp_path / "m")
    card = json.loads((tmp_path / "m" / "par-E" / "card.json").read_text())
    assert card["cv_grouped"]["groups"] == "run spans" and card["cv_grouped"]["folds"] == 5
    assert card["inputs"] == "kinematic" and card["inputs_reason"] == "default: no robot known"
    row = report.results.iloc[0]
    assert row["inputs"] == card["inputs"] and row["cv_groups"] == "run spans"
    side = card["cv_vs_held_out"]
    assert side == {
        "cv_r2": card["cv_grouped"]["r2_mean"],
        "cv_groups": "run spans",
        "held_out_r2": card["test"]["r2"],
        "held_out_moves": card["test"]["n_moves"],
    }
    covered = card["training_range"]
    speeds = np.abs(train_table.frame[[f"dq{i}" for i in range(1, 7)]].to_numpy()).max(axis=0)
    np.testing.assert_allclose(covered["speed_max_rad_s"], speeds)
    assert covered["move_duration_s"][0] <= covered["move_duration_s"][1]
    # the saved model loads back and predicts what it predicted before
    model = EnergyModel.load(tmp_path / "m" / "par-E")
    before = report.results.iloc[0]["test_r2"]
    from joulepath.learn import score

    assert score(test_table, "E", model.predict(test_table.frame)).r2 == pytest.approx(before, abs=1e-12)


@pytest.mark.parametrize("family", ["par", "xgb"])
def test_a_model_on_kinematic_inputs_round_trips_through_its_files(two_run_tables, tmp_path, family):
    pytest.importorskip("xgboost") if family == "xgb" else None
    train_table, test_table = two_run_tables
    config = TrainConfig(families=(family,), cv=2, inputs="kinematic")
    report = train(train_table, test_table, config, tmp_path / "m")
    model = EnergyModel.load(report.models[f"{family}-E"])
    assert model.card["inputs"] == "kinematic" and model.card["inputs_reason"] == "asked"
    rows = test_table.frame[list(model.input_columns)].to_numpy()
    np.testing.assert_allclose(model.predict_rows(rows), model.pipeline.predict(rows), rtol=1e-9, atol=1e-12)


def test_outside_training_range_flags_rows_beyond_the_training_data(two_run_tables):
    train_table, _ = two_run_tables
    card = {"training_range": training_range(train_table)}
    model = EnergyModel.__new__(EnergyModel)  # only the card is read
    model.card = card
    frame = train_table.frame
    assert not model.outside_training_range(frame).any()
    faster = frame.copy()
    speed = np.abs(frame["dq2"].to_numpy())
    fast = speed >= 0.5 * speed.max()  # three times these is beyond the fastest trained on
    faster.loc[fast, "dq2"] *= 3.0
    np.testing.assert_array_equal(model.outside_training_range(faster), fast)
    longer = frame.copy()
    first = longer["move_id"] == longer["move_id"].iloc[0]
    t = longer.loc[first, "t"]
    longest = card["training_range"]["move_duration_s"][1]
    longer.loc[first, "t"] = t.min() + (t - t.min()) * 2.0 * longest / (t.max() - t.min())
    assert model.outside_training_range(longer)[first.to_numpy()].all()
    # a card without a range flags nothing
    model.card = {}
    assert not model.outside_training_range(faster).any()


def test_training_range_of_a_table(two_run_tables):
    table: EnergyTable = two_run_tables[0]
    covered = training_range(table)
    q = table.frame[[f"q{i}" for i in range(1, 7)]].to_numpy()
    np.testing.assert_allclose(covered["q_min_rad"], q.min(axis=0))
    np.testing.assert_allclose(covered["q_max_rad"], q.max(axis=0))
    energy = table.frame.groupby("move_id")["E"].sum()
    assert covered["move_energy_J"] == [energy.min(), energy.max()]


def test_the_optimizer_states_the_share_of_a_path_outside_the_models_training_range():
    """optimize_move's summary flags a learned model's extrapolation on the optimized path."""
    from joulepath.optimize._run import outside_training_range_pct
    from joulepath.trajectory import Trajectory

    covered = {
        "q_min_rad": [-1.0] * 6,
        "q_max_rad": [1.0] * 6,
        "speed_max_rad_s": [1.0] * 6,
        "acceleration_max_rad_s2": [5.0] * 6,
        "move_duration_s": [0.5, 2.0],
    }
    model = EnergyModel.__new__(EnergyModel)  # only the card is read
    model.card = {"training_range": covered}
    t = np.arange(41) * 0.025  # a 1 s move: within the trained durations
    q = np.zeros((41, 6))
    qd = np.zeros((41, 6))
    qd[:10, 2] = 1.5  # a quarter of the samples faster than any trained on
    path = Trajectory(t=t, q=q, qd=qd, qdd=np.zeros((41, 6)))
    assert outside_training_range_pct([model], path) == pytest.approx(100.0 * 10 / 41)
    longer = Trajectory(t=3.0 * t, q=q, qd=np.zeros((41, 6)), qdd=np.zeros((41, 6)))  # a 3 s move
    assert outside_training_range_pct([model], longer) == 100.0
    inside = Trajectory(t=t, q=q, qd=np.zeros((41, 6)), qdd=np.zeros((41, 6)))
    assert outside_training_range_pct([model], inside) == 0.0
    bare = EnergyModel.__new__(EnergyModel)
    bare.card = {}
    assert outside_training_range_pct([bare], path) is None
