"""Named arms of example-robot-data (the [robots] extra): the Panda, and a UR5 end to end through the CLI.

Skipped when the extra is not installed (the package has no Python module for
``pytest.importorskip``; its installed files are looked up instead).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import joulepath
from joulepath.cli import main
from joulepath.errors import MissingDependency
from joulepath.optimize import OptimizeConfig, optimize_move, write_run


def _named(name):
    from joulepath.description import named_arm_path

    try:
        named_arm_path(name)
    except MissingDependency:
        pytest.skip("example-robot-data (the [robots] extra) is not installed")
    return joulepath.load_robot(name)


@pytest.fixture(scope="module")
def panda():
    return _named("panda")


@pytest.fixture(scope="module")
def ur5():
    return _named("ur5")


def test_panda_is_a_seven_joint_arm_with_its_fingers_locked(panda, capsys):
    assert panda.n_joints == 7 and panda.joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    assert panda.friction is None
    assert main(["robot", "show", "panda"]) == 0
    out = capsys.readouterr().out
    assert "7 revolute joints" in out and "controller: ros2" in out and "rigid body only" in out
    assert main(["robot", "fk", "panda", "--q", "0,0,0,-1.5,0,1.5,0.7"]) == 0
    line = capsys.readouterr().out.splitlines()[0].split()
    expected = panda.fk([0, 0, 0, -1.5, 0, 1.5, 0.7]).position_mm
    np.testing.assert_allclose([float(v) for v in line[2:5]], expected, atol=5e-4)  # printed to 1 µm
    assert main(["robot", "fk", "panda", "--q", "0,0,0,0,0,0"]) == 2  # 6 values for 7 joints


def test_panda_lagrange_euler_and_rnea_agree(panda):
    rng = np.random.default_rng(7)
    q = rng.uniform(panda.lower, panda.upper, (20, 7))
    qd, qdd = rng.uniform(-2, 2, (20, 7)), rng.uniform(-5, 5, (20, 7))
    rnea = panda.inverse_dynamics(q, qd, qdd)
    le = panda.inverse_dynamics(q, qd, qdd, method="lagrange-euler")
    np.testing.assert_allclose(le, rnea, rtol=0, atol=1e-10)


def test_panda_physics_optimization_stays_within_limits_and_exports_ros2(panda, tmp_path):
    q0 = np.array([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0])
    qf = np.array([1.0, 0.5, 0.5, -1.0, 0.5, 2.0, 0.5])
    # CMA-ES keeps this test short; the default gradient search needs minutes on this frictionless
    # 7-joint move (docs/tutorials/urdf-ros2.md)
    result = optimize_move(panda, q0, qf, 2.0, OptimizeConfig(algorithm="cmaes", evaluations=400, seed=3))
    s = result.summary
    assert s.limits_ok and s.algorithm == "cmaes" and s.energy_optimized_J <= s.energy_default_J
    files = write_run(result, panda, tmp_path)
    assert {"trajectory.yaml", "trajectory.csv"} <= set(files) and "path.mod" not in files
    path = pd.read_csv(tmp_path / "path.csv")
    q = path[[f"q{i}" for i in range(1, 8)]].to_numpy()
    assert np.all(q >= panda.lower - 1e-9) and np.all(q <= panda.upper + 1e-9)


def test_ur5_end_to_end_through_the_cli(ur5, tmp_path, capsys):
    """simulate (nominal ranges), ingest, train (quick grid), optimize on the model: URScript, ROS 2."""
    for name, moves, seed in (("train", 12, 1), ("test", 5, 2)):
        log = tmp_path / f"{name}.csv"
        assert (
            main(
                ["simulate", "--robot", "ur5", "--moves", str(moves), "--seed", str(seed), "--out", str(log)]
            )
            == 0
        )
        assert "nominal ranges" in capsys.readouterr().out
        assert main(["ingest", str(log), "--robot", "ur5", "--out", str(tmp_path / f"{name}.parquet")]) == 0
    models = tmp_path / "models"
    args = ["train", "--data", str(tmp_path / "train.parquet"), "--test", str(tmp_path / "test.parquet")]
    assert main([*args, "--family", "par", "--cv", "2", "--robot", "ur5", "--out", str(models)]) == 0
    task = ["--robot", "ur5", "--start", "0,-1.57,1.57,0,0,0", "--end", "1,-1,1,0.5,0.5,0.5"]
    task += ["--duration", "3", "--knot-spacing", "0.1"]  # fewer knots for CMA-ES: nothing below needs more
    run = tmp_path / "run"
    assert main(["optimize", *task, "--fitness", "surrogate", "--model", str(models), "--out", str(run)]) == 0
    summary = json.loads((run / "result.json").read_text())
    assert summary["limits_ok"] and summary["export"] == "urscript" and summary["program"] == ["path.script"]
    # verified on physics: the energy in result.json is the rigid-body energy of path.csv
    path = pd.read_csv(run / "path.csv")
    cols = [[f"{p}{i}" for i in range(1, 7)] for p in ("q", "qd", "qdd")]
    e = ur5.path_energy(*(path[c].to_numpy() for c in cols), 0.025).total
    assert e == pytest.approx(summary["energy_optimized_J"], rel=1e-6)
    assert summary["energy_optimized_surrogate_J"] is not None
    assert 0.0 <= summary["surrogate_outside_range_pct"] <= 100.0  # the path against the model's range
    text = (run / "path.script").read_text()
    assert text.startswith("def joulepath_path():") and text.count("servoj(") == 1500
    ros = tmp_path / "ros"
    assert (
        main(
            [
                "optimize",
                *task,
                "--fitness",
                "surrogate",
                "--model",
                str(models),
                "--export",
                "ros2",
                "--out",
                str(ros),
            ]
        )
        == 0
    )
    assert (ros / "trajectory.yaml").is_file() and (ros / "trajectory.csv").is_file()
    card = models / "par-E" / "card.json"
    data = json.loads(card.read_text())
    data.pop("robot")
    data.pop("robot_source")
    card.write_text(json.dumps(data))
    assert (
        main(
            [
                "optimize",
                *task,
                "--fitness",
                "surrogate",
                "--model",
                str(models),
                "--out",
                str(tmp_path / "x"),
            ]
        )
        == 2
    )
    assert "names no robot" in capsys.readouterr().err
