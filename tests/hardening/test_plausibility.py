"""Physical plausibility of every model that enters (issue 25, item 3), through the real CLI.

Friction that pushes instead of resisting, or of absurd size; a twin whose ``twin_of``
is another arm; a tool far over the arm's rating; logs without torque information; a
cycle step faster than the arm; a lock outside the joint's range: each is refused with
exit 2 and one line, and nothing is written.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import joulepath
from joulepath.cli import main
from joulepath.description import preset_path
from joulepath.dynamics import TWIN_FRICTION_FILE
from joulepath.errors import InvalidInput, InvalidRobotDescription
from joulepath.sim import simulate

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MOVE = ["--start", "0,0,0,0,0,0", "--end", "0.5,0,0,0,0,0", "--duration", "1"]


@pytest.fixture(scope="module")
def lab_log(tmp_path_factory):
    return simulate(tmp_path_factory.mktemp("lab") / "lab.csv", plant="lab", n_moves=30, seed=3).log


@pytest.fixture(scope="module")
def twin(lab_log, tmp_path_factory):
    out = tmp_path_factory.mktemp("twin") / "twin"
    assert main(["identify", str(lab_log), "--out", str(out)]) == 0
    return out


def _refused(capsys, args, fragment):
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert fragment in err, err
    return err


def _edited_twin(twin: Path, folder: Path, edit) -> Path:
    out = folder / "edited"
    shutil.copytree(twin, out)
    data = json.loads((out / TWIN_FRICTION_FILE).read_text())
    edit(data)
    (out / TWIN_FRICTION_FILE).write_text(json.dumps(data))
    return out


def _set(path: str, value):
    def edit(data):
        *keys, last = path.split(".")
        node = data
        for k in keys:
            node = node[k]
        if isinstance(last, str) and last.isdigit():
            node[int(last)] = value
        else:
            node[last] = value

    return edit


# --------------------------------------------------------------------------- friction and drives


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda d: d["friction"]["coulomb"].__setitem__(1, -0.5), "coulomb friction of joint 2 is -0.5"),
        (lambda d: d["friction"]["viscous"].__setitem__(0, -0.1), "viscous friction of joint 1 is -0.1"),
        (lambda d: d["friction"]["stribeck"].__setitem__(5, -1.0), "stribeck friction of joint 6 is -1"),
        (
            lambda d: d["friction"]["coulomb"].__setitem__(1, 1e300),
            "friction.coulomb: expected a list of 6 finite numbers of magnitude at most 1e12",
        ),
        (lambda d: d["friction"]["offset"].__setitem__(2, -1e6), "friction torque of joint 3 is 1e+06 N·m"),
        (lambda d: d["friction"]["viscous"].__setitem__(3, 1e5), "viscous friction torque of joint 4"),
        (lambda d: d.__setitem__("gear_efficiency", 0.0), "gear_efficiency must be a number in (0, 1]"),
        (lambda d: d.__setitem__("gear_efficiency", 1.5), "gear_efficiency must be a number in (0, 1]"),
    ],
)
def test_implausible_friction_in_a_twin_is_refused(twin, tmp_path, capsys, edit, fragment):
    bad = _edited_twin(twin, tmp_path, edit)
    out = tmp_path / "run"
    _refused(capsys, ["optimize", *MOVE, "--robot", str(bad), "--out", str(out)], fragment)
    assert not out.exists()


def test_the_twin_as_identified_passes_and_its_friction_dissipates(twin):
    robot = joulepath.load_robot(twin)
    qd = np.linspace(-3, 3, 61)[:, None] * np.ones(robot.n_joints)
    power = (robot.friction.torque(qd) * qd)[np.abs(qd[:, 0]) > 0.2]
    assert np.all(power >= 0)  # friction takes power at any speed above the offset's reach


def test_a_friction_file_beside_a_description_is_checked(tmp_path, capsys):
    urdf = tmp_path / "arm.urdf"
    shutil.copy(preset_path("irb120", fmt="urdf"), urdf)
    (tmp_path / "arm.friction.toml").write_text(
        "coulomb = [1, 1, 1, 1, 1, 1e300]\nviscous = [0, 0, 0, 0, 0, 0]\n"
    )
    _refused(capsys, ["robot", "fk", str(urdf), "--q", "0,0,0,0,0,0"], "friction torque of joint 6 is 1e+300")
    (tmp_path / "arm.friction.toml").write_text(
        "coulomb = [1, 1, 1, 1, 1, 1]\nviscous = [0, 0, 0, 0, 0, 0]\n"
    )
    assert main(["robot", "fk", str(urdf), "--q", "0,0,0,0,0,0"]) == 0


# --------------------------------------------------------------------------- twin_of


def test_twin_of_another_arm_is_refused(twin, tmp_path, capsys):
    bad = _edited_twin(twin, tmp_path, _set("twin_of", "ur5"))
    out = tmp_path / "run"
    _refused(
        capsys,
        ["simulate", "--plant", str(bad), "--moves", "2", "--out", str(out / "l.csv")],
        "twin_of = 'ur5'",
    )
    assert not out.exists()


@pytest.mark.parametrize(
    ("twin_of", "fragment"), [("no-such-robot", "cannot be loaded"), (".", "is a folder")]
)
def test_twin_of_that_names_no_robot_is_refused(twin, tmp_path, twin_of, fragment):
    bad = _edited_twin(twin, tmp_path, _set("twin_of", twin_of))
    with pytest.raises(InvalidRobotDescription, match=fragment):
        joulepath.load_robot(bad)


def test_twin_of_the_same_kinematics_in_a_file_is_accepted(twin, tmp_path):
    irml = tmp_path / "nominal.irml"
    shutil.copy(preset_path("irb120"), irml)
    good = _edited_twin(twin, tmp_path, _set("twin_of", str(irml)))
    assert joulepath.load_robot(good).calibration.twin_of == str(irml)


# --------------------------------------------------------------------------- payload


def test_a_tool_far_over_the_rating_is_refused_at_its_line(tmp_path, capsys):
    program = tmp_path / "heavy.mod"
    program.write_text(
        (EXAMPLES / "payload_tool.mod").read_text().replace("[1.5, [10, 0, 60]", "[1000000, [10, 0, 60]")
    )
    out = tmp_path / "run"
    err = _refused(
        capsys, ["cycle", str(program), "--out", str(out)], "tool tGripper2: 1e+06 kg is more than 2 times"
    )
    assert "rated payload of 3 kg" in err and "heavy.mod:" in err and "--robot" in err
    assert not out.exists()


def test_a_tool_somewhat_over_the_rating_runs_and_says_so(tmp_path):
    """A program's loaddata a little over the rated payload runs as the controller runs it, with a
    line that names the load, and its dynamics carry that load."""
    from joulepath.program import read_cycle_program

    irb = joulepath.load_robot("irb120")
    program = tmp_path / "heavier.mod"
    text = (EXAMPLES / "payload_tool.mod").read_text()
    assert "[1.5, [10, 0, 60]" in text
    program.write_text(text.replace("[1.5, [10, 0, 60]", "[3.6, [10, 0, 60]"))
    spec, _ = read_cycle_program(program, irb)
    lines = [c for c in spec.choices if "rated payload" in c]
    assert len(lines) == 1 and "tool tGripper2: 3.6 kg, above the IRB 120's rated payload of 3 kg" in lines[0]
    assert lines[0].startswith(str(program))
    loads = {
        round(s.robot.payload.mass, 9) for s in spec.steps if s.kind == "move" and s.robot.payload is not None
    }
    assert 3.6 in loads


def test_payload_rating_and_fallback():
    irb = joulepath.load_robot("irb120")
    assert irb.rated_payload_kg == 3.0
    assert irb.with_payload(3.0).payload.mass == 3.0
    with pytest.raises(InvalidInput, match="rated payload of 3 kg"):
        irb.with_payload(3.5)
    urdf = joulepath.load_robot(preset_path("irb120", fmt="urdf"))  # no rating: its own links bound it
    assert urdf.rated_payload_kg is None
    own = float(urdf.chain.masses.sum())
    assert urdf.with_payload(0.9 * own).payload is not None
    with pytest.raises(InvalidInput, match="heavier than the .* own moving links"):
        urdf.with_payload(1.1 * own)
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(InvalidInput, match="not a finite number"):
            irb.with_payload(bad)


# --------------------------------------------------------------------------- identification


def test_identify_refuses_logs_without_torque_variance(lab_log, tmp_path, capsys):
    frame = pd.read_csv(lab_log)
    for j in range(1, 7):
        frame[f"tau{j}"] = 0.0
    log = tmp_path / "zero.csv"
    frame.to_csv(log, index=False)
    out = tmp_path / "twin"
    err = _refused(capsys, ["identify", str(log), "--out", str(out)], "never varies")
    assert "joint(s) 1, 2, 3, 4, 5, 6" in err
    frame = pd.read_csv(lab_log)
    frame["tau4"] = 2.5  # one joint logged as a constant
    frame.to_csv(log, index=False)
    _refused(capsys, ["identify", str(log), "--out", str(out)], "joint(s) 4 never varies (joint 4: 2.5 N·m")
    assert not out.exists()


# --------------------------------------------------------------------------- cycle files, locks


def test_a_cycle_step_faster_than_the_arm_is_refused(tmp_path, capsys):
    program = tmp_path / "c.toml"
    program.write_text(
        "[[step]]\njoints_deg = [60, 20, 10, 0, 40, 0]\nduration_s = 0.05\n"
        "[[step]]\njoints_deg = [0, 0, 0, 0, 30, 0]\nduration_s = 0.9\n"
    )
    out = tmp_path / "run"
    err = _refused(
        capsys, ["cycle", str(program), "--out", str(out)], "step 1: duration_s = 0.05 s is shorter"
    )
    assert "give duration_s ≥ 0.6" in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("locks", "fragment"),
    [
        (["joint_6=1e308"], "lock value 1e+308 rad of joint 'joint_6' is outside its range"),
        (["joint_6=0", "joint_6=0.5"], "joint 'joint_6' is locked twice (0 and 0.5)"),
    ],
)
def test_a_lock_outside_the_range_or_twice_is_refused(capsys, locks, fragment):
    urdf = str(preset_path("irb120", fmt="urdf"))
    args = ["robot", "fk", urdf, "--q", "0,0,0,0,0"]
    for lock in locks:
        args += ["--lock", lock]
    _refused(capsys, args, fragment)


def test_a_lock_within_the_range_works(capsys):
    urdf = str(preset_path("irb120", fmt="urdf"))
    assert main(["robot", "fk", urdf, "--q", "0,0,0,0,0", "--lock", "joint_6=0.5"]) == 0
