"""Training: every family's quick grid learns the lab energy; reports and honest splits."""

import json

import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.learn import FAMILIES, TrainConfig, best_model, load_models


def test_quick_grid_of_each_family_reaches_r2_on_held_out_moves(trained):
    res = trained.results.set_index("family")
    assert set(res.index) == set(FAMILIES)
    for family in FAMILIES:
        assert res.loc[family, "test_r2"] >= 0.95, (family, res.loc[family, "test_r2"])


def test_grouped_cv_is_the_honest_headline(trained):
    res = trained.results
    # shuffled row folds leak neighbouring rows of the same move: never less optimistic
    assert (res["cv_shuffled_r2"] >= res["cv_grouped_r2"] - 0.01).all()
    assert res["path_p95_pct"].notna().all() and (res["path_median_pct"] >= 0).all()


def test_reports_and_files(trained):
    out = trained.out_dir
    assert (out / "results.csv").exists() and (out / "test_scores_E.png").exists()
    report = json.loads((out / "report.json").read_text())
    assert "par" in report["substitutions"] and "SGDRegressor" in report["substitutions"]["par"]
    assert report["robot_source"] == "irb120"  # the table's robot "IRB 120", by its bundled name
    labels = [b["label"] for b in report["baselines"]]
    assert labels == ["dynamics model, no friction", "dynamics model + nominal friction"]
    for family in FAMILIES:
        card = json.loads((out / f"{family}-E" / "card.json").read_text())
        assert card["input_columns"][:2] == ["q1", "dq1"] and card["target"] == "E"
        assert len(card["training_data_sha256"]) == 64
        assert set(card["cv_grouped"]) == {"r2_mean", "r2_std", "mae_mean", "mae_std", "folds", "groups"}
        assert card["cv_grouped"]["groups"] == "move"  # one log: its moves are the groups
        assert "scikit-learn" in card["versions"]


def test_load_models_and_best_model(trained):
    models = load_models(trained.out_dir)
    assert set(models) == {f"{f}-E" for f in FAMILIES}
    best = best_model(trained.out_dir, "E")
    assert best.card["cv_grouped"]["r2_mean"] == max(m.card["cv_grouped"]["r2_mean"] for m in models.values())


def test_physics_baseline_gains_from_friction(trained):
    no_fr, with_fr = trained.baselines
    assert with_fr["scores"]["E"]["r2"] > no_fr["scores"]["E"]["r2"]
    assert with_fr["latency_per_row_s_batch"] < 1e-3


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"families": ("knn",)}, "families"),
        ({"targets": ("F",)}, "targets"),
        ({"grid": "huge"}, "grid must be one of"),
        ({"inputs": "raw"}, "inputs must be one of"),
        ({"cv": 1}, "cv"),
    ],
)
def test_train_config_validation(kwargs, pattern):
    with pytest.raises(InvalidInput, match=pattern):
        TrainConfig(**kwargs)


def test_thesis_grid_sizes():
    from sklearn.model_selection import ParameterGrid

    from joulepath.learn import THESIS_GRIDS

    sizes = {f: len(ParameterGrid(g)) for f, g in THESIS_GRIDS.items()}
    assert sizes == {"mlp": 3456, "svr": 384, "par": 192, "xgb": 58320, "bases": 3}  # bases: not thesis
    assert np.prod([len(v) for v in THESIS_GRIDS["xgb"].values()]) == 58320


def test_training_again_leaves_only_this_runs_models(lab_tables, tmp_path):
    """A folder trained with par and xgb, then with par alone, holds par alone: best_model cannot pick xgb."""
    from joulepath.learn import best_model, load_models, train

    train(*lab_tables, TrainConfig(families=("par", "xgb"), targets=("E",), cv=2, seed=0), tmp_path)
    assert {"par-E", "xgb-E"} <= set(load_models(tmp_path))
    train(*lab_tables, TrainConfig(families=("par",), targets=("E",), cv=2, seed=0), tmp_path)
    assert set(load_models(tmp_path)) == {"par-E"}
    assert best_model(tmp_path, "E").family == "par"


SEVEN_LINK = (
    '<link name="l{i}"><inertial><mass value="{m}"/><origin xyz="0 0 0.1"/>'
    '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>'
)
SEVEN_JOINT = (
    '<joint name="joint_{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>'
    '<origin xyz="0 0 0.15" rpy="{rpy}"/><axis xyz="0 0 1"/>'
    '<limit lower="-3" upper="3" effort="150" velocity="3"/></joint>'
)


@pytest.fixture(scope="module")
def seven_joint_tables(tmp_path_factory):
    """Small train/test tables of a 7-joint URDF arm (its name, "arm7", is no bundled robot's)."""
    import joulepath
    from joulepath.data import ingest
    from joulepath.sim import simulate

    folder = tmp_path_factory.mktemp("arm7")
    body = SEVEN_LINK.format(i=0, m=4.0)
    for i in range(1, 8):
        rpy = "1.5708 0 0" if i % 2 == 0 else "0 0 0"
        body += SEVEN_LINK.format(i=i, m=3.0 - 0.3 * i) + SEVEN_JOINT.format(i=i, p=i - 1, rpy=rpy)
    path = folder / "arm7.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="arm7">{body}</robot>')
    robot = joulepath.load_robot(path)
    tables = [
        ingest([simulate(folder / f"{name}.csv", robot=str(path), n_moves=n, seed=s).log], robot=robot)
        for name, n, s in (("train", 8, 1), ("test", 4, 2))
    ]
    return path, *tables


def test_default_inputs_train_on_a_seven_joint_table(seven_joint_tables, tmp_path):
    """Grey-box (physics) inputs take the table's 7-joint robot, never the 6-joint default."""
    from joulepath.learn import train

    path, train_table, test_table = seven_joint_tables
    assert train_table.n_joints == 7 and TrainConfig().inputs is None  # physics: the robot is known
    config = TrainConfig(families=("par",), targets=("E",), cv=2, seed=0, robot=str(path))
    report = train(train_table, test_table, config, tmp_path / "m")
    card = json.loads((tmp_path / "m" / "par-E" / "card.json").read_text())
    assert (
        card["inputs"] == "physics" and card["robot_source"] == str(path) and "ddq7" in card["input_columns"]
    )
    assert card["inputs_reason"] == "default: robot known"
    assert np.isfinite(report.results["test_r2"]).all()
    assert [b["label"] for b in report.baselines] == ["dynamics model, no friction"]


@pytest.mark.parametrize(
    ("robot", "pattern"),
    [(None, "'arm7' is not a bundled robot or named arm; give its description"), ("irb120", "has 6 joints")],
)
def test_train_refuses_a_robot_it_cannot_take_from_the_table(seven_joint_tables, tmp_path, robot, pattern):
    from joulepath.learn import train

    _, train_table, test_table = seven_joint_tables
    with pytest.raises(InvalidInput, match=pattern):
        train(train_table, test_table, TrainConfig(families=("par",), cv=2, robot=robot), tmp_path / "m")
    assert not (tmp_path / "m").exists()  # refused before anything was written


def test_train_refuses_a_table_without_robot_for_physics_inputs(seven_joint_tables, tmp_path):
    from dataclasses import replace

    from joulepath.learn import train

    _, train_table, test_table = seven_joint_tables
    bare = replace(train_table, robot=None)
    config = TrainConfig(families=("par",), cv=2, inputs="physics")
    with pytest.raises(InvalidInput, match=r"names none .* \(--robot, .*\(--inputs thesis\)"):
        train(bare, test_table, config, tmp_path / "m")
    assert not (tmp_path / "m").exists()


def test_train_without_robot_defaults_to_the_kinematic_inputs(seven_joint_tables, tmp_path):
    """No robot known: the raw inputs and robot-free energy bases, said in one progress line and
    recorded on the card."""
    from dataclasses import replace

    from joulepath.learn import NO_ROBOT_NOTE, train

    _, train_table, test_table = seven_joint_tables
    bare, bare_test = replace(train_table, robot=None), replace(test_table, robot=None)
    said: list[str] = []
    config = TrainConfig(families=("par",), cv=2)
    report = train(bare, bare_test, config, tmp_path / "m", progress=said.append)
    assert said.count(NO_ROBOT_NOTE) == 1
    card = json.loads((tmp_path / "m" / "par-E" / "card.json").read_text())
    assert card["robot_source"] is None and report.baselines == []
    assert card["inputs"] == "kinematic" and card["inputs_reason"] == "default: no robot known"
    assert card["input_columns"][-1] == "dt" and "ddq7" in card["input_columns"]
