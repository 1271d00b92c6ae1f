"""The experiment's ``[identify]`` stage: a twin from the training logs, scored, and the loop closed."""

from __future__ import annotations

import json

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


def test_identify_stage_writes_a_twin_scores_and_the_loop(tmp_path):
    toml = tmp_path / "study.toml"
    toml.write_text(STUDY)
    out = tmp_path / "run"
    assert main(["run", str(toml), "--out", str(out), "--quiet"]) == 0
    folder = out / "identify"
    robot = load_robot(folder / "twin")
    assert robot.calibration is not None and robot.calibration.twin_of == "irb120"
    scores = pd.read_csv(folder / "scores.csv").set_index("model")
    # the twin fits the lab robot's held-out logs better than the nominal physics
    assert scores.loc["twin", "energy_r2"] > scores.loc["nominal physics + nominal friction", "energy_r2"]
    loop = pd.read_csv(folder / "loop.csv")
    assert len(loop) == 1 and loop["realized_saved_lab_pct"].notna().all()
    summary = json.loads((out / "summary.json").read_text())
    r2 = scores.loc["twin", "energy_r2"]  # read back from CSV: equal to the last bits
    assert summary["stages"]["identify"]["twin_energy_r2"] == pytest.approx(r2, rel=1e-12)
    # the report shows the stage: the scores and the loop, not the "not run" note
    page = (out / "report.html").read_text()
    section = page.split('data-section="identify"', 1)[1].split("</section>", 1)[0]
    assert "nominal physics + nominal friction" in section and "realized_saved_lab_pct" in section
    assert "was not run" not in section
