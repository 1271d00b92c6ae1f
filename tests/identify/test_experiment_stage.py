"""The experiment's ``[identify]`` stage: a twin from the training logs, scored, and the loop closed."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from joulepath.cli import main
from joulepath.dynamics import load_robot

STUDY = """
name = "identify"
robot = "irb120"
seed = 3
jobs = 1

[data]
plant = "lab"
train_moves = 25
test_moves = 6

[train]
families = []

[importance]
targets = ["E"]
max_rows = 300

[optimize]
tasks = 1

[identify]
enabled = true
loop_tasks = 1
"""


def _twin_row_energy_r2(twin_folder, test_log):
    """The twin's row energy R² on the test log, recomputed from the written twin folder."""
    from sklearn.metrics import r2_score

    from joulepath.data import ingest
    from joulepath.energy import joint_energy

    twin = load_robot(twin_folder)
    frame = ingest([test_log], robot=twin).frame
    q, qd, qdd = (frame[[f"{p}{i}" for i in range(1, 7)]].to_numpy() for p in ("q", "dq", "ddq"))
    tau = twin.calibration.motor_torque(twin.inverse_dynamics(q, qd, qdd, friction=twin.friction), qd)
    return r2_score(frame["E"], joint_energy(tau, qd, frame["dt"].to_numpy()).sum(axis=1))


def test_identify_stage_writes_a_twin_the_model_comparison_and_the_loop(tmp_path):
    from joulepath.experiment._identify import (
        HELD_OUT,
        LEARNED_REAL,
        LEARNED_SDV,
        LEARNED_TWIN,
        NOMINAL,
        OPTIMIZED,
        TWIN,
    )
    from joulepath.identify import data_from_logs, identify, score_prediction

    toml = tmp_path / "study.toml"
    toml.write_text(STUDY)
    out = tmp_path / "run"
    assert main(["run", str(toml), "--out", str(out), "--quiet"]) == 0
    folder = out / "identify"
    robot = load_robot(folder / "twin")
    assert robot.calibration is not None and robot.calibration.twin_of == "irb120"
    scores = pd.read_csv(folder / "scores.csv")
    models = (TWIN, NOMINAL, LEARNED_REAL, LEARNED_TWIN, LEARNED_SDV)
    sets = list(dict.fromkeys(scores["test_set"]))
    # every model on every test set: the held-out moves, another range set, the optimized paths
    assert sets[0] == HELD_OUT and OPTIMIZED in sets and len(sets) == 3
    assert sorted(zip(scores["model"], scores["test_set"], strict=True)) == sorted(
        (m, t) for m in models for t in sets
    )
    table = scores.set_index(["model", "test_set"])
    for t in sets:
        twin, nominal = table.loc[(TWIN, t)], table.loc[(NOMINAL, t)]
        # on the lab plant the twin beats the nominal physics on every test set and every measure
        assert twin["energy_r2"] > nominal["energy_r2"]
        assert twin["torque_r2_worst_joint"] > nominal["torque_r2_worst_joint"]
        assert twin["path_error_median_pct"] < nominal["path_error_median_pct"]
        # the learned models predict energy only: no torque score
        for m in (LEARNED_REAL, LEARNED_TWIN, LEARNED_SDV):
            assert np.isnan(table.loc[(m, t), "torque_r2_worst_joint"])
            assert np.isfinite(table.loc[(m, t), "energy_r2"])
        assert table.loc[(TWIN, t), "moves"] == table.loc[(LEARNED_SDV, t), "moves"]
    assert table.loc[(TWIN, OPTIMIZED), "moves"] == 1  # loop_tasks = 1: one path, one move

    # the table's twin scores agree with independent recomputations on the test log
    test_log = out / "data" / "logs" / "test.csv"
    held = table.loc[(TWIN, HELD_OUT)]
    assert held["energy_r2"] == pytest.approx(_twin_row_energy_r2(folder / "twin", test_log), abs=1e-6)
    base = load_robot("irb120")
    ident = identify(data_from_logs([out / "data" / "logs" / "train.csv"], base), base)
    data = data_from_logs([test_log], base)
    sc = score_prediction(ident.motor_torque(base, data.q, data.qd, data.qdd), data)
    assert held["torque_r2_worst_joint"] == pytest.approx(min(sc.torque_r2), rel=1e-9)

    loop = pd.read_csv(folder / "loop.csv")
    assert len(loop) == 1 and loop["realized_saved_lab_pct"].notna().all()
    summary = json.loads((out / "summary.json").read_text())
    # the stage's record holds the table's held-out numbers (read back from CSV: to the last bits)
    assert summary["stages"]["identify"]["twin_energy_r2"] == pytest.approx(held["energy_r2"], rel=1e-12)
    assert summary["stages"]["identify"]["nominal_energy_r2"] == pytest.approx(
        table.loc[(NOMINAL, HELD_OUT), "energy_r2"], rel=1e-12
    )
    # the report shows the stage: one comparison table and the loop, not the "not run" note
    page = (out / "report.html").read_text()
    section = page.split('data-section="identify"', 1)[1].split("</section>", 1)[0]
    for name in (*models, *sets, "realized_saved_lab_pct", "path_error_median_pct"):
        assert name in section, name
    assert "was not run" not in section
