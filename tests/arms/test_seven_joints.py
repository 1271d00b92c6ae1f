"""A 7-joint arm end to end: its generic CSV log ingests and trains; chromosomes have 6·n genes."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import joulepath
from joulepath.cli import main
from joulepath.data import feature_columns, load_table, read_log, target_columns
from joulepath.optimize import TrajectoryProblem

LINK = (
    '<link name="l{i}"><inertial><mass value="{m}"/><origin xyz="0 0 0.1"/>'
    '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>'
)
JOINT = (
    '<joint name="joint_{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>'
    '<origin xyz="0 0 0.15" rpy="{rpy}"/><axis xyz="0 0 1"/>'
    '<limit lower="-3" upper="3" effort="150" velocity="3"/></joint>'
)


@pytest.fixture(scope="module")
def arm7(tmp_path_factory):
    folder = tmp_path_factory.mktemp("arm7")
    body = LINK.format(i=0, m=4.0)
    for i in range(1, 8):
        rpy = "1.5708 0 0" if i % 2 == 0 else "0 0 0"
        body += LINK.format(i=i, m=3.0 - 0.3 * i) + JOINT.format(i=i, p=i - 1, rpy=rpy)
    path = folder / "arm7.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="arm7">{body}</robot>')
    return path


def test_schema_columns_follow_the_joint_count():
    assert len(feature_columns("full40", 6)) == 40
    assert len(feature_columns("full40", 7)) == 43 and feature_columns("full40", 7)[12:14] == ("q7", "dq7")
    assert feature_columns("joint", 5) == (
        *(f"{p}{i}" for i in range(1, 6) for p in ("q", "dq")),
        "ddq1",
        "ddq2",
        "ddq3",
        "ddq4",
        "ddq5",
    )
    assert target_columns(7) == ("E1", "E2", "E3", "E4", "E5", "E6", "E7", "E")


def test_thesis_chromosomes_have_six_coefficients_per_joint(arm7):
    robot = joulepath.load_robot(arm7)
    problem = TrajectoryProblem(robot=robot, q_start=np.zeros(7), q_end=np.full(7, 0.3), duration=1.0)
    assert problem.n_var == 42 and problem.xl.shape == (42,)
    x = np.zeros((3, 42))
    traj = problem.trajectory(x)
    assert traj.q.shape[-1] == 7
    np.testing.assert_allclose(traj.q[:, -1], np.full((3, 7), 0.3), atol=1e-12)
    assert np.all(np.isfinite(problem.evaluate(x)))


def test_generic_seven_joint_log_ingests_and_trains(arm7, tmp_path, capsys):
    train_log, test_log = tmp_path / "train.csv", tmp_path / "test.csv"
    assert (
        main(["simulate", "--robot", str(arm7), "--moves", "10", "--seed", "1", "--out", str(train_log)]) == 0
    )
    assert (
        main(["simulate", "--robot", str(arm7), "--moves", "5", "--seed", "2", "--out", str(test_log)]) == 0
    )
    log = read_log(train_log)
    assert log.kind == "generic" and log.q.shape[1] == 7
    header = train_log.read_text().splitlines()[0].split(",")
    assert header[-3:] == ["q7", "dq7", "tau7"]
    tables = []
    for name in ("train", "test"):
        out = tmp_path / f"{name}.parquet"
        assert main(["ingest", str(tmp_path / f"{name}.csv"), "--robot", str(arm7), "--out", str(out)]) == 0
        tables.append(load_table(out))
    assert tables[0].n_joints == 7 and len(tables[0].features) == 43 and tables[0].targets[-2:] == ("E7", "E")
    frame = tables[0].frame
    np.testing.assert_allclose(frame[[f"E{i}" for i in range(1, 8)]].sum(axis=1), frame["E"], rtol=1e-12)
    assert main(["ingest", str(test_log), "--out", str(tmp_path / "joint.parquet")]) == 0
    assert load_table(tmp_path / "joint.parquet").features[-1] == "ddq7"
    capsys.readouterr()
    models = tmp_path / "models"
    args = ["train", "--data", str(tmp_path / "train.parquet"), "--test", str(tmp_path / "test.parquet")]
    args += ["--family", "par", "--target", "E,E7", "--cv", "2", "--robot", str(arm7), "--out", str(models)]
    assert main(args) == 0
    results = pd.read_csv(models / "results.csv")
    assert set(results["target"]) == {"E", "E7"} and results["test_r2"].notna().all()
    card = json.loads((models / "par-E" / "card.json").read_text())
    assert card["robot"] == "arm7" and "q7" in card["input_columns"] and "ddq7" in card["input_columns"]
    args[args.index("E,E7")] = "E8"
    assert main(args) == 2
    assert "E8" in capsys.readouterr().err
