"""The ``bases`` family: each joint's energy by least squares on energy bases of its motion."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from joulepath.data import ingest
from joulepath.learn import (
    JointEnergyBases,
    TrainConfig,
    best_model,
    input_columns,
    joint_bases,
    make_pipeline,
    train,
)
from joulepath.learn._search import cross_validate_candidate, make_splits

COLS = input_columns("joint", "kinematic", 3)


def _rows(rng, n=400):
    X = rng.normal(size=(n, len(COLS)))
    X[:, COLS.index("dt")] = rng.uniform(0.002, 0.01, n)
    return X


def _energies(X, coef):
    """Per-joint energies that are exactly the bases times ``coef``, clipped at zero."""
    return np.column_stack(
        [np.maximum(joint_bases(X, COLS, "kinematic", j) @ coef[j - 1], 0.0) for j in (1, 2, 3)]
    )


def test_joint_bases_are_the_two_limits_of_a_joints_power():
    # qd = -2, qdd = 3, dt = 0.5: |qd| dt, qd dt, qd qdd dt, |qd| qdd dt
    Z = np.array([[-2.0, 3.0, 0.5, 99.0]])
    assert joint_bases(Z, ("dq1", "ddq1", "dt"), "kinematic", 1).tolist() == [[1.0, -1.0, -3.0, 3.0]]


def test_per_joint_fit_recovers_each_joints_coefficients(rng):
    X = _rows(rng)
    coef = np.array([[5.0, 1.0, 0.5, 0.2], [30.0, -4.0, 2.0, -1.0], [8.0, 0.0, 1.0, 0.0]])
    bases = np.column_stack([joint_bases(X, COLS, "kinematic", j) @ coef[j - 1] for j in (1, 2, 3)])
    assert (bases > 0).all()  # a constant torque's term dominates: nothing is clipped, exact recovery
    model = JointEnergyBases(columns=COLS, inputs="kinematic").fit(X, bases)
    np.testing.assert_allclose(model.coef_, coef, rtol=1e-9, atol=1e-9)
    assert model.joints_.tolist() == [1, 2, 3]
    np.testing.assert_allclose(model.predict(X), bases.sum(axis=1), rtol=1e-9)
    # one joint's target gives that joint's row
    one = JointEnergyBases(columns=COLS, inputs="kinematic", joint=2).fit(X, bases[:, 1])
    np.testing.assert_allclose(one.coef_[0], coef[1], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(one.predict(X), bases[:, 1], rtol=1e-9)


def test_predictions_are_never_negative_and_ridge_shrinks(rng):
    X = _rows(rng)
    Y = _energies(X, np.array([[0.0, 3.0, 1.0, 0.0]] * 3))  # signed terms: clipped half the time
    model = JointEnergyBases(columns=COLS, inputs="kinematic").fit(X, Y)
    assert (model.predict(_rows(rng)) >= 0).all()
    plain = np.abs(JointEnergyBases(columns=COLS).fit(X, Y).coef_).sum()
    shrunk = np.abs(JointEnergyBases(columns=COLS, alpha=10.0).fit(X, Y).coef_).sum()
    assert shrunk < 0.5 * plain


def test_bases_refuse_inputs_without_dt_and_wrong_targets(rng):
    X = _rows(rng, 20)
    with pytest.raises(ValueError, match="needs columns"):
        JointEnergyBases(columns=COLS[:-1]).fit(X[:, :-1], X[:, 0])
    with pytest.raises(ValueError, match="one per joint"):
        JointEnergyBases(columns=COLS).fit(X, X[:, :2])
    with pytest.raises(ValueError, match="joint 4"):
        JointEnergyBases(columns=COLS, joint=4).fit(X, X[:, 0])


def test_cv_of_per_joint_targets_scores_their_sum(rng):
    """The grid search scores a 2-D target (per-joint energies) on E, the sum the model predicts."""
    X = _rows(rng)
    Y = _energies(X, np.array([[5.0, 1.0, 0.5, 0.2], [30.0, -4.0, 2.0, -1.0], [8.0, 0.0, 1.0, 0.0]]))
    Y += rng.normal(scale=0.01 * Y.std(), size=Y.shape)
    pipe = make_pipeline("bases", seed=0, inputs="kinematic", columns=COLS)
    splits = make_splits(len(Y), np.arange(len(Y)) // 20, split="grouped", n_splits=4, seed=0)
    r2, mae, _ = cross_validate_candidate(pipe, {"model__alpha": 0.0}, X, Y, splits)
    E = Y.sum(axis=1)
    for (a, b), r in zip(splits, r2, strict=True):
        pred = JointEnergyBases(columns=COLS, inputs="kinematic").fit(X[a], Y[a]).predict(X[b])
        assert r == pytest.approx(1 - np.sum((E[b] - pred) ** 2) / np.sum((E[b] - E[b].mean()) ** 2))
    assert min(r2) > 0.99


KUKA = Path(__file__).parents[3] / "shared" / "datasets" / "kuka-kr300-weigand"


@pytest.mark.skipif(not KUKA.exists(), reason="../shared/datasets not present")
def test_default_on_real_logs_of_an_unknown_arm_takes_bases_by_cv_and_generalizes(tmp_path):
    """KUKA KR300 (Weigand et al., MIT): runs B and C train, run A is held out. The CV by run spans
    ranks bases above the quick MLP, and bases predicts the held-out moves' energies with R² >= 0.95
    (measured 0.973; the MLP 0.731: benchmarks/unknown_arm.py)."""
    pytest.importorskip("scipy.io")
    sys.path.insert(0, str(Path(__file__).parents[2] / "benchmarks"))
    try:
        from unknown_arm import write_generic_log
    finally:
        sys.path.pop(0)
    logs = {r: write_generic_log(KUKA / f"recorded_FF_{r}.mat", tmp_path / f"kr300_{r}.csv") for r in "ABC"}
    train_table, test_table = ingest([logs["B"], logs["C"]]), ingest([logs["A"]])
    report = train(train_table, test_table, TrainConfig(families=("mlp", "bases"), cv=5), tmp_path / "m")
    res = report.results.set_index("family")
    assert (res["cv_groups"] == "run spans").all()
    assert res.loc["bases", "cv_grouped_r2"] > res.loc["mlp", "cv_grouped_r2"]
    chosen = best_model(tmp_path / "m", "E")
    assert chosen.family == "bases"
    f = test_table.frame
    moves = pd.DataFrame({"m": f["move_id"], "y": f["E"], "p": chosen.predict(f)}).groupby("m").sum()
    r2 = 1 - ((moves.p - moves.y) ** 2).sum() / ((moves.y - moves.y.mean()) ** 2).sum()
    assert r2 >= 0.95, r2
    side = chosen.card["cv_vs_held_out"]
    assert side["cv_groups"] == "run spans"
    assert side["held_out_r2"] == pytest.approx(res.loc["bases", "test_r2"])
