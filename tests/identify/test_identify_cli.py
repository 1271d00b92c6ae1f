"""``joulepath identify`` -> twin folder -> ``--robot twin/`` round trip, and its refusals."""

from __future__ import annotations

import json

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.dynamics import TWIN_CARD_FILE, TWIN_FRICTION_FILE, TWIN_ROBOT_FILE, IdentifiedFriction
from joulepath.sim import simulate

TASK = ["--start", "0,0,0,0,0,0", "--end", "40,20,-10,30,20,60", "--degrees", "--duration", "1.5"]


@pytest.fixture(scope="module")
def lab_log(tmp_path_factory):
    folder = tmp_path_factory.mktemp("logs")
    return simulate(folder / "lab.csv", plant="lab", n_moves=30, seed=3).log


@pytest.fixture(scope="module")
def twin(lab_log, tmp_path_factory):
    out = tmp_path_factory.mktemp("twin") / "twin"
    assert main(["identify", str(lab_log), "--robot", "irb120", "--out", str(out)]) == 0
    return out


def test_identify_writes_a_twin_that_loads_with_its_friction(twin, lab_log):
    assert sorted(p.name for p in twin.iterdir()) == sorted(
        [TWIN_ROBOT_FILE, TWIN_FRICTION_FILE, TWIN_CARD_FILE]
    )
    card = json.loads((twin / TWIN_CARD_FILE).read_text())
    assert card["twin_of"] == "irb120"
    assert card["data_sha256"] and card["condition_number"] > 1
    assert card["held_out"]["n_samples"] > 0 and card["physically_consistent"]
    robot = joulepath.load_robot(twin)
    assert isinstance(robot.friction, IdentifiedFriction)
    assert robot.calibration is not None and 0.5 <= robot.calibration.gear_efficiency <= 1.0
    # a payload keeps the calibration
    assert robot.with_payload(0.5).calibration is robot.calibration
    # the twin's physics differ from the nominal robot's (it was identified on the lab robot)
    nominal = joulepath.load_robot("irb120")
    q = np.full((1, 6), 0.3)
    assert not np.allclose(robot.gravity_torque(q), nominal.gravity_torque(q))


def test_optimize_on_the_twin_is_verified_on_the_lab_robot(twin, tmp_path, capsys):
    # fewer knots (measured 29 s -> 3 s): the checks are on the default path's energies and on the
    # twin's result being within the limits and verified on the lab robot, at any knot spacing
    quick = ["--knot-spacing", "0.1"]
    assert main(["optimize", *TASK, *quick, "--robot", str(twin), "--out", str(tmp_path / "t")]) == 0
    assert main(["optimize", *TASK, *quick, "--out", str(tmp_path / "n")]) == 0
    on_twin = json.loads((tmp_path / "t" / "result.json").read_text())
    on_nominal = json.loads((tmp_path / "n" / "result.json").read_text())
    assert on_twin["limits_ok"] and "identified twin of irb120" in on_twin["physics_model"]
    # same lab robot: the default path costs the same there, whichever model planned it
    assert on_twin["energy_default_lab_J"] == pytest.approx(on_nominal["energy_default_lab_J"], rel=1e-12)
    assert on_twin["energy_optimized_lab_J"] is not None
    # the twin's physics energy of the default path is not the nominal model's
    assert on_twin["energy_default_J"] != pytest.approx(on_nominal["energy_default_J"], rel=1e-3)
    # predicted and logged energy are the same quantity: the lab's logged energy is named, and the
    # twin's energy on that measure includes its identified gear efficiency
    assert on_twin["energy_lab_measure"] == "mechanical"
    mech = on_twin["energies"]["mechanical"]
    assert mech["stage"] == "gear" and "identified" in mech["source"]
    assert mech["lab_default_J"] == pytest.approx(on_twin["energy_default_lab_J"], rel=1e-12)
    assert mech["lab_optimized_J"] == pytest.approx(on_twin["energy_optimized_lab_J"], rel=1e-12)
    like_for_like = abs(mech["default_J"] / mech["lab_default_J"] - 1)
    mixed = abs(on_twin["energy_default_J"] / on_twin["energy_default_lab_J"] - 1)
    assert like_for_like < mixed
    assert set(on_twin["energies"]) == {"thesis", "mechanical", "electrical"}
    assert "drives" in on_twin["energies"]["electrical"]["source"]
    # read as a user reads result.json: the headline pairs are all on the run's measure, and the
    # twin's planned energies compare with the lab robot's on it (the mixed pair is deprecated)
    assert_paired(on_twin)
    assert "mechanical" in on_twin["deprecated_keys"]["energy_default_lab_J"]
    vs = on_twin["energy_figures"]["planned_vs_lab"]
    assert vs["measure"] == on_twin["energy_measure"] == "thesis"
    assert abs(on_twin["planned_default_J"] / on_twin["lab_default_J"] - 1) <= 0.02
    assert abs(on_twin["planned_optimized_J"] / on_twin["lab_optimized_J"] - 1) <= 0.02
    assert abs(on_twin["planned_saved_pct"] - on_twin["lab_saved_pct"]) <= 1.0
    assert vs["saved_points"] == pytest.approx(on_twin["planned_saved_pct"] - on_twin["lab_saved_pct"])


def assert_paired(result):
    """Every figure of result.json's energy blocks is one stage on one named measure."""
    m = result["energy_measure"]
    figures = result["energy_figures"]
    assert figures["measure"] == m
    for stage in ("planned", "lab", "executed"):
        block = figures[stage]
        if block is None:
            continue
        assert block["measure"] == m and block["on"]
        for key in ("default_J", "optimized_J", "saved_pct"):
            assert result[f"{stage}_{key}"] == pytest.approx(block[key])  # the headline keys, same figures
    # the planned and lab stages are the per-measure block of the run's measure, model and lab alike
    per_measure = result["energies"][m]
    assert result["planned_default_J"] == pytest.approx(per_measure["default_J"])
    assert result["lab_default_J"] == pytest.approx(per_measure["lab_default_J"])
    assert result["lab_optimized_J"] == pytest.approx(per_measure["lab_optimized_J"])


def test_identify_refuses_without_writing(twin, lab_log, tmp_path, capsys):
    # an existing twin is not replaced silently
    assert main(["identify", str(lab_log), "--out", str(twin)]) == 2
    assert "--force" in capsys.readouterr().err
    # a malformed log: one line, nothing written
    bad = tmp_path / "bad.csv"
    bad.write_text("t,q1,dq1\n0,1,2\n")
    out = tmp_path / "out"
    assert main(["identify", str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1
    assert not out.exists()
    # logs that cannot excite the model
    refuse = ["--unexcited", "refuse"]
    assert main(["identify", str(lab_log), "--max-condition", "2", *refuse, "--out", str(out)]) == 2
    assert "least excited" in capsys.readouterr().err
    assert not out.exists()
    # by default the least excited parameters keep their priors, but never more than a quarter of them
    assert main(["identify", str(lab_log), "--max-condition", "2", "--out", str(out)]) == 2
    assert "at most 25 %" in capsys.readouterr().err
    assert not out.exists()
    assert main(["identify", str(lab_log), "--unexcited", "sometimes", "--out", str(out)]) == 2
    assert "unexcited must be one of" in capsys.readouterr().err


def test_simulate_on_the_twin_plant_gives_data_that_identify_the_twin_again(twin, tmp_path):
    log = tmp_path / "twin.csv"
    assert main(["simulate", "--plant", str(twin), "--moves", "15", "--seed", "4", "--out", str(log)]) == 0
    again = tmp_path / "again"
    assert main(["identify", str(log), "--out", str(again)]) == 0
    first = json.loads((twin / TWIN_FRICTION_FILE).read_text())
    second = json.loads((again / TWIN_FRICTION_FILE).read_text())
    # the twin's own data are noise-free: the gear efficiency comes back (accelerations are differenced)
    assert second["gear_efficiency"] == pytest.approx(first["gear_efficiency"], abs=5e-3)
    card = json.loads((again / TWIN_CARD_FILE).read_text())
    assert min(card["fit"]["torque_r2"]) > 0.99


def test_a_twins_plants_are_its_own_physics_and_the_lab_robot_it_twins(twin, rng):
    from joulepath.dynamics import motor_torque
    from joulepath.sim import make_plant

    robot = joulepath.load_robot(twin)
    nominal = joulepath.load_robot("irb120")
    q, qd, qdd = rng.normal(scale=0.5, size=(3, 20, 6))
    lab_of_twin = make_plant("lab", robot).drive_torque(q, qd, qdd)
    np.testing.assert_array_equal(lab_of_twin, make_plant("lab", nominal).drive_torque(q, qd, qdd))
    own = motor_torque(
        robot.inverse_dynamics(q, qd, qdd, friction=robot.friction), qd, robot.calibration.gear_efficiency
    )
    np.testing.assert_allclose(make_plant("sim", robot).drive_torque(q, qd, qdd), own, rtol=1e-12)
    np.testing.assert_allclose(make_plant(str(twin), nominal).drive_torque(q, qd, qdd), own, rtol=1e-12)
