"""Robots without a lab description: friction per robot, nominal range fallback, the generic lab plant."""

from __future__ import annotations

import json

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.dynamics import NOMINAL_FRICTION, CoulombViscousFriction
from joulepath.errors import InvalidInput
from joulepath.sim import make_plant

LINK = (
    '<link name="l{i}"><inertial><mass value="{m}"/><origin xyz="0 0 0.1"/>'
    '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>'
)
JOINT = (
    '<joint name="joint_{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>'
    '<origin xyz="0 0 0.15" rpy="{rpy}"/><axis xyz="0 0 1"/>'
    '<limit lower="-3" upper="3" effort="150" velocity="3"/></joint>'
)


def arm(folder, name="cobot", n=6):
    body = LINK.format(i=0, m=4.0)
    for i in range(1, n + 1):
        rpy = "1.5708 0 0" if i % 2 == 0 else "0 0 0"
        body += LINK.format(i=i, m=3.0 - 0.3 * i) + JOINT.format(i=i, p=i - 1, rpy=rpy)
    path = folder / f"{name}.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="{name}">{body}</robot>')
    return path


# --------------------------------------------------------------------------- friction


def test_friction_file_beside_the_description_is_the_robots_friction(tmp_path):
    p = arm(tmp_path)
    (tmp_path / "cobot.friction.toml").write_text(
        "coulomb = [1.0, 2.0, 1.5, 0.4, 0.3, 0.2]\n"
        "viscous = [0.5, 0.6, 0.4, 0.1, 0.1, 0.05]\n"
        "smoothing = 0.01\n"
    )
    robot = joulepath.load_robot(p)
    assert "cobot.friction.toml" in robot.friction_note
    qd = np.linspace(-1, 1, 6)
    expected = CoulombViscousFriction(
        coulomb=(1.0, 2.0, 1.5, 0.4, 0.3, 0.2), viscous=(0.5, 0.6, 0.4, 0.1, 0.1, 0.05), smoothing=0.01
    )
    np.testing.assert_allclose(robot.friction.torque(qd), expected.torque(qd))
    assert make_plant("sim", robot).friction is robot.friction


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("coulomb = [1, 2]\nviscous = [0, 0, 0, 0, 0, 0]\n", "coulomb must be a list of 6 non-negative"),
        ("coulomb = [1, 1, 1, 1, 1, -1]\nviscous = [0, 0, 0, 0, 0, 0]\n", "coulomb must be"),
        (
            "coulomb = [1, 1, 1, 1, 1, 1]\nviscous = [0, 0, 0, 0, 0, 0]\nstribeck = 1\n",
            "unknown key 'stribeck'",
        ),
        ("coulomb = [", "not valid TOML"),
    ],
)
def test_bad_friction_file_is_one_line_and_exit_2(tmp_path, capsys, text, needle):
    p = arm(tmp_path)
    (tmp_path / "cobot.friction.toml").write_text(text)
    assert main(["robot", "show", str(p)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0] and "cobot.friction.toml" in err[0]


def test_no_friction_file_means_rigid_body_only_and_the_outputs_say_so(tmp_path, capsys):
    p = arm(tmp_path)
    robot = joulepath.load_robot(p)
    assert robot.friction is None and "rigid body only" in robot.friction_note
    q, qd, qdd = np.full(6, 0.1), np.full(6, 0.7), np.full(6, -0.3)
    plant = make_plant("sim", robot)
    np.testing.assert_allclose(plant.drive_torque(q, qd, qdd), robot.inverse_dynamics(q, qd, qdd))
    args = ["optimize", "--robot", str(p), "--start", "0,0.2,-0.2,0.3,0,0", "--end", "0.5,-0.3,0.4,0,0.3,0.2"]
    assert main([*args, "--duration", "1.5", "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out
    assert "no friction modelled for cobot" in out and "not an estimate of a real robot" in out
    summary = json.loads((tmp_path / "run" / "result.json").read_text())
    assert summary["physics_model"].startswith("nominal rigid body only, no friction")
    assert summary["algorithm"] == "gradient"  # auto: the gradient search, on the robot's own (no) friction
    assert summary["energy_optimized_J"] <= summary["energy_default_J"]
    assert "generic perturbation of the cobot model" in summary["lab_plant"]


def test_irb120_keeps_its_friction_and_its_emulated_lab_robot(irb120):
    assert irb120.friction is NOMINAL_FRICTION
    lab = make_plant("lab", irb120)
    assert lab.note.startswith("emulated IRB 120") and lab.torque_noise == (
        0.15,
        0.15,
        0.10,
        0.03,
        0.03,
        0.02,
    )


def test_generic_lab_plant_noise_follows_the_torque_limits(tmp_path):
    robot = joulepath.load_robot(arm(tmp_path))
    lab = make_plant("lab", robot)
    np.testing.assert_allclose(lab.torque_noise, 1e-3 * robot.effort_limit)
    assert "not an estimate of a real robot" in lab.note


# --------------------------------------------------------------------------- range sets


def test_missing_default_range_sets_fall_back_to_nominal(tmp_path, irb120):
    robot = joulepath.load_robot(arm(tmp_path))
    for name in ("lab", "collection"):
        used, lo, hi = robot.ranges_for(name)
        assert used == "nominal"
        np.testing.assert_allclose([lo, hi], [robot.lower, robot.upper])
    with pytest.raises(InvalidInput, match="has only the 'nominal' range set"):
        robot.ranges_for("workcell")
    assert irb120.ranges_for("lab")[0] == "lab"  # the IRB 120 keeps its lab ranges


def test_simulate_a_urdf_arm_with_range_set_option(tmp_path, capsys):
    p = arm(tmp_path)
    log = tmp_path / "lab.csv"
    assert main(["simulate", "--robot", str(p), "--moves", "3", "--out", str(log)]) == 0
    out = capsys.readouterr().out
    assert "has no 'collection' range set; the moves use its nominal ranges" in out
    assert "the lab plant is a generic perturbation of the cobot model" in out
    assert (
        main(["simulate", "--robot", str(p), "--moves", "3", "--range-set", "nominal", "--out", str(log)])
        == 0
    )
    assert "range set" not in capsys.readouterr().out
    assert (
        main(["simulate", "--robot", str(p), "--moves", "3", "--range-set", "cell", "--out", str(log)]) == 2
    )
    assert "has only the 'nominal' range set (asked for 'cell')" in capsys.readouterr().err
