"""``evaluate``: a model scored on a generated log of a plant with current output and a known drive model."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pandas as pd
import pytest

import joulepath
from joulepath.cli import main
from joulepath.data import generic_log_text
from joulepath.description import preset_path
from joulepath.errors import InvalidInput
from joulepath.identify import (
    DriveGains,
    EvaluateConfig,
    drives_path,
    evaluate_model,
    r2_per_joint,
    read_drive_gains,
    write_evaluation,
)

K = np.array([45.0, 45.0, 45.0, 27.0, 27.0, 22.5])
"""The plant's joint-side torque constants, N·m/A."""


def _plant_log(robot, *, n_moves=5, rate=100.0, rest_s=0.5, move_s=1.2, noise=0.02, seed=0):
    """Quintic moves between random poses with rests; tau = model + friction, i = tau / K, both noisy.

    The noise of each joint's signal is ``noise`` times that signal's standard deviation.
    """
    rng = np.random.default_rng(seed)
    mid, half = (robot.lower + robot.upper) / 2, 0.3 * (robot.upper - robot.lower)
    poses = mid + rng.uniform(-1, 1, (n_moves + 1, robot.n_joints)) * half
    s = np.arange(int(move_s * rate)) / (move_s * rate)
    shape = (10 * s**3 - 15 * s**4 + 6 * s**5, (30 * s**2 - 60 * s**3 + 30 * s**4) / move_s)
    accel = (60 * s - 180 * s**2 + 120 * s**3) / move_s**2
    n_rest = int(rest_s * rate)
    q, qd, qdd = [], [], []
    for a, b in zip(poses[:-1], poses[1:], strict=True):
        q += [np.repeat(a[None], n_rest, 0), a + np.outer(shape[0], b - a)]
        qd += [np.zeros((n_rest, a.size)), np.outer(shape[1], b - a)]
        qdd += [np.zeros((n_rest, a.size)), np.outer(accel, b - a)]
    q += [np.repeat(poses[-1][None], n_rest, 0)]
    qd += [np.zeros((n_rest, poses.shape[1]))]
    qdd += [np.zeros((n_rest, poses.shape[1]))]
    q, qd, qdd = (np.concatenate(x) for x in (q, qd, qdd))
    t = np.arange(q.shape[0]) / rate
    tau = robot.inverse_dynamics(q, qd, qdd, friction=robot.friction)
    current = tau / K
    tau = tau + rng.normal(size=tau.shape) * noise * tau.std(axis=0)
    current = current + rng.normal(size=current.shape) * noise * current.std(axis=0)
    return t, q, qd, tau, current


@pytest.fixture(scope="module")
def plant(tmp_path_factory):
    """Logs with torques and currents and with currents only; an IRB 120 file with drives beside it."""
    folder = tmp_path_factory.mktemp("plant")
    robot = joulepath.load_robot("irb120")
    t, q, qd, tau, current = _plant_log(robot)
    both, only = folder / "both.csv", folder / "currents.csv"
    both.write_text(generic_log_text(t, q, qd, tau, current=current))
    only.write_text(generic_log_text(t, q, qd, None, current=current))
    model = folder / "model" / "irb120.irml"
    model.parent.mkdir()
    shutil.copy(preset_path("irb120"), model)
    drives = model.with_name("irb120.drives.toml")
    drives.write_text(  # a whole drives file (joulepath.energy's format); evaluate reads torque_constant
        f"torque_constant = {K.tolist()}\nresistance = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]\n"
        'drive_efficiency = 0.95\nbus = "bleeder"\n[sources]\ntorque_constant = "the test plant"\n'
    )
    return {"robot": robot, "both": both, "only": only, "model": model, "drives": drives}


def _gains(plant):
    return read_drive_gains(plant["drives"], 6)


def test_r2_per_joint_agrees_with_scikit_learn():
    from sklearn.metrics import r2_score

    rng = np.random.default_rng(1)
    measured = rng.normal(size=(50, 3))
    predicted = measured + rng.normal(scale=0.3, size=(50, 3))
    np.testing.assert_allclose(
        r2_per_joint(measured, predicted), r2_score(measured, predicted, multioutput="raw_values")
    )
    assert np.isnan(r2_per_joint(np.ones((4, 1)), np.zeros((4, 1)))[0])  # nothing to explain


def test_true_model_fits_torque_current_energy_and_holding(plant):
    ev = evaluate_model(plant["both"], plant["robot"], robot_source="irb120", drives=_gains(plant))
    assert min(ev.torque_r2) > 0.99 and min(ev.current_r2) > 0.99
    s = ev.summary()
    assert s["drives"]["source"] == "the test plant" and s["energy"]["measured_from"] == "tau"
    assert s["energy"]["n_moves"] == 5 and s["energy"]["median_error_pct"] < 2.0
    assert s["holding"]["n_poses"] == 6  # the rests before, between and after the five moves
    assert min(s["holding"]["current"]["share_of_poses_predicted"]) == 1.0
    assert ev.notes == ()


def test_a_perturbed_model_scores_lower(plant):
    gains = _gains(plant)
    true = evaluate_model(plant["both"], plant["robot"], robot_source="irb120", drives=gains)
    heavy = plant["robot"].with_payload(3.0, com=(0.0, 0.0, 0.05))
    wrong = evaluate_model(plant["both"], heavy, robot_source="irb120 + 3 kg", drives=gains)
    assert np.mean(wrong.current_r2) < np.mean(true.current_r2) - 0.05
    assert np.mean(wrong.torque_r2) < np.mean(true.torque_r2) - 0.05
    err = wrong.summary()["energy"]["median_error_pct"]
    assert err > true.summary()["energy"]["median_error_pct"] + 5.0
    # wrong torque constants: torque R² unchanged, current R² lower
    halved = DriveGains(torque_constant=tuple(K / 2), origin="halved")
    off = evaluate_model(plant["both"], plant["robot"], robot_source="irb120", drives=halved)
    assert off.torque_r2 == true.torque_r2 and np.mean(off.current_r2) < 0.5


def test_currents_only_log(plant):
    ev = evaluate_model(plant["only"], plant["robot"], robot_source="irb120", drives=_gains(plant))
    assert ev.torque_r2 is None and min(ev.current_r2) > 0.99 and ev.energy_from == "k*i"
    assert any("no torques" in n for n in ev.notes)
    bare = evaluate_model(plant["only"], plant["robot"], robot_source="irb120")
    assert bare.current_r2 is None and bare.energy_from == "" and bare.moves == []
    assert any("current R² not computable: no drive model; give" in n for n in bare.notes)
    s = bare.summary()
    assert s["current"] is None and s["energy"] is None and s["holding"]["current"] is None


def test_drives_path_beside_the_description_and_in_a_twin(plant, tmp_path):
    robot = joulepath.load_robot(plant["model"])
    assert drives_path(str(plant["model"]), robot) == plant["drives"]
    assert drives_path(str(tmp_path), robot) == tmp_path / "drives.toml"


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ("resistance = [1.0]\n", "no torque_constant; give torque_constant"),
        ("torque_constant = [1.0, 2.0]\n", r"torque_constant is \[1.0, 2.0\]; give .* 6 numbers > 0"),
        ("torque_constant = [1, 1, 1, 1, 1, -1]\n", "torque_constant is"),
        ("torque_constant = [1, 1, 1, 1, 1, true]\n", "torque_constant is"),
        ("torque_constant = \n", "not a TOML drives file"),
    ],
)
def test_read_drive_gains_refuses(tmp_path, text, pattern):
    p = tmp_path / "x.drives.toml"
    p.write_text(text)
    with pytest.raises(InvalidInput, match=pattern):
        read_drive_gains(p, 6)


def test_evaluate_config_validation():
    with pytest.raises(InvalidInput, match="hold_rel"):
        EvaluateConfig(hold_rel=-0.1)
    with pytest.raises(InvalidInput, match="min_rest_samples"):
        EvaluateConfig(min_rest_samples=0)


def test_write_evaluation_files(plant, tmp_path):
    ev = evaluate_model(plant["both"], plant["robot"], robot_source="irb120", drives=_gains(plant))
    files = write_evaluation(ev, tmp_path / "ev")
    assert set(files) == {
        "evaluate.json",
        "predictions.csv",
        "moves.csv",
        "holding.csv",
        "fit.png",
        "energy.png",
    }
    pred = pd.read_csv(tmp_path / "ev" / "predictions.csv")
    assert list(pred.columns[:5]) == ["t", "tau1_measured", "tau1_predicted", "i1_measured", "i1_predicted"]
    assert len(pred) == ev.t.size and pred.shape[1] == 1 + 4 * 6
    np.testing.assert_allclose(pred["i2_predicted"], ev.i_predicted[:, 1], rtol=1e-5)
    moves = pd.read_csv(tmp_path / "ev" / "moves.csv")
    assert len(moves) == 5 and (moves["energy_measured_J"] > 0).all()
    assert json.loads((tmp_path / "ev" / "evaluate.json").read_text())["n_joints"] == 6


def test_cli_evaluate_reads_the_drives_file_beside_the_model(plant, tmp_path, capsys):
    out = tmp_path / "ev"
    assert main(["evaluate", str(plant["only"]), "--robot", str(plant["model"]), "--out", str(out)]) == 0
    summary = json.loads((out / "evaluate.json").read_text())
    assert summary["drives"]["file"] == str(plant["drives"]) and summary["current"]["r2_mean"] > 0.99
    assert "current R²" in capsys.readouterr().out
    pred = pd.read_csv(out / "predictions.csv")
    assert "tau1_measured" not in pred.columns and "i6_measured" in pred.columns


def test_cli_evaluate_without_drives_says_what_to_provide(plant, tmp_path, capsys):
    out, model = tmp_path / "ev", tmp_path / "irb120.irml"
    shutil.copy(plant["model"], model)  # no drives file beside this copy
    assert main(["evaluate", str(plant["both"]), "--robot", str(model), "--out", str(out)]) == 0
    summary = json.loads((out / "evaluate.json").read_text())
    assert summary["current"] is None and summary["torque"]["r2_mean"] > 0.99
    assert "torque_constant" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("case", "pattern"),
    [
        ("seven", "the log has 6 joints but robot"),
        ("bad-drives", "torque_constant is"),
        ("missing-drives", "no-such.toml"),
        ("no-log", "no-such.csv"),
    ],
)
def test_cli_evaluate_refusals_are_one_line_and_write_nothing(plant, tmp_path, capsys, case, pattern):
    out = tmp_path / "ev"
    args = ["evaluate", str(plant["both"]), "--robot", "irb120", "--out", str(out)]
    if case == "seven":
        urdf = tmp_path / "arm7.urdf"
        link = (
            '<link name="l{i}"><inertial><mass value="2"/><origin xyz="0 0 0.1"/>'
            '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>'
        )
        joint = (
            '<joint name="j{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>'
            '<origin xyz="0 0 0.15"/><axis xyz="0 1 0"/>'
            '<limit lower="-3" upper="3" effort="150" velocity="3"/></joint>'
        )
        body = link.format(i=0) + "".join(link.format(i=i) + joint.format(i=i, p=i - 1) for i in range(1, 8))
        urdf.write_text(f'<?xml version="1.0"?><robot name="arm7">{body}</robot>')
        args[3] = str(urdf)
    elif case == "bad-drives":
        bad = tmp_path / "bad.toml"
        bad.write_text("torque_constant = [1.0]\n")
        args += ["--drives", str(bad)]
    elif case == "missing-drives":
        args += ["--drives", str(tmp_path / "no-such.toml")]
    else:
        args[1] = str(tmp_path / "no-such.csv")
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and pattern in err, err
    assert not out.exists()


def test_controller_log_scores_torque_and_says_it_has_no_currents(tmp_path):
    from joulepath.sim import simulate

    log = simulate(tmp_path / "lab.csv", plant="lab", n_moves=4, seed=3).log
    robot = joulepath.load_robot("irb120")
    ev = evaluate_model(
        log, robot, robot_source="irb120", drives=DriveGains(torque_constant=tuple(K), origin="k")
    )
    assert ev.current_r2 is None and ev.i_measured is None and ev.i_predicted is not None
    assert any("the log has no motor currents i1..i6" in n for n in ev.notes)
    assert len(ev.torque_r2) == 6 and ev.energy_from == "tau" and len(ev.moves) >= 4
    s = ev.summary()
    assert s["holding"]["current"] is None and s["holding"]["torque"] is not None
