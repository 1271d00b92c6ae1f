"""load_robot's physical check on load: every command gets it; checked=False is the expert's way out."""

import numpy as np
import pytest

import joulepath
from joulepath.description import preset_path
from joulepath.errors import InvalidRobotDescription

URDF = preset_path("irb120", fmt="urdf").read_text()
IRML = preset_path("irb120").read_text()


def _edit(text, old, new):
    assert old in text, old
    return text.replace(old, new, 1)


# (id, format, edit, fragment the refusal must name)
BROKEN = [
    (
        "urdf-negative-mass",
        "urdf",
        lambda t: _edit(t, '<mass value="3.909"/>', '<mass value="-3.909"/>'),
        "mass -3.909 kg is not positive",
    ),
    (
        "urdf-not-positive-definite",
        "urdf",
        lambda t: _edit(t, 'ixx="0.0142175"', 'ixx="-0.0142175"'),
        "is not positive definite",
    ),
    (
        "urdf-triangle-inequality",
        "urdf",
        lambda t: _edit(t, 'izz="0.0104533"', 'izz="0.1"'),
        "violates the triangle inequality",
    ),
    ("urdf-zero-axis", "urdf", lambda t: _edit(t, '<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>'), "is zero"),
    (
        "urdf-no-speed-limit",
        "urdf",
        lambda t: _edit(t, 'upper="2.87979" velocity="4.36332"', 'upper="2.87979" velocity="0"'),
        "joint 'joint_1' <limit>: no speed limit",
    ),
    (
        "urdf-no-range",
        "urdf",
        lambda t: _edit(t, 'lower="-2.87979" upper="2.87979" ', ""),
        "lower 0 ≥ upper 0 rad: the range is empty",
    ),
    (
        "irml-negative-mass",
        "irml",
        lambda t: _edit(t, "<link-mass>3.067</link-mass>", "<link-mass>-3.067</link-mass>"),
        "joint 1 <dynamics> <link-mass>: mass -3.067 kg is not positive",
    ),
    (
        "irml-no-speed-limit",
        "irml",
        lambda t: _edit(t, "<velocity>4.363323129985824</velocity>", ""),
        "joint 1 <limits>: no speed limit",
    ),
    (
        "irml-no-range",
        "irml",
        lambda t: _edit(t, "<lower>-11*pi/12</lower>", ""),
        "joint 1 <limits>: no lower range limit",
    ),
]


def _broken_file(tmp_path, fmt, edit):
    path = tmp_path / f"broken.{fmt}"
    path.write_text(edit(URDF if fmt == "urdf" else IRML), encoding="utf-8")
    return path


@pytest.mark.parametrize(("fmt", "edit", "fragment"), [c[1:] for c in BROKEN], ids=[c[0] for c in BROKEN])
def test_load_robot_refuses_a_robot_that_fails_the_physical_check(tmp_path, fmt, edit, fragment):
    path = _broken_file(tmp_path, fmt, edit)
    with pytest.raises(InvalidRobotDescription, match="fails the physical check") as info:
        joulepath.load_robot(path)
    message = str(info.value)
    assert fragment in message and "\n" not in message
    assert "--unchecked" in message and str(path) in message
    robot = joulepath.load_robot(path, checked=False)  # the expert's way
    assert any(fragment in f"{f.where}: {f.message}" for f in robot.check_physical() if f.severity == "error")


@pytest.mark.parametrize("name", ["irb120", str(preset_path("irb120", fmt="urdf"))])
def test_load_robot_bundled_robots_pass_the_check(name):
    robot = joulepath.load_robot(name)
    assert [f for f in robot.check_physical() if f.severity == "error"] == []


def test_check_physical_missing_torque_limits_is_one_warning(irb120):
    (warning,) = [f for f in irb120.check_physical() if "torque" in f.message]
    assert warning.severity == "warning" and warning.where == "every joint <limits>"
    assert np.isnan(irb120.effort_limit).all()


def test_check_physical_given_torque_limits_are_used(tmp_path):
    text = IRML.replace("</velocity>", "</velocity>\n      <effort>50</effort>")
    path = tmp_path / "with_effort.irml"
    path.write_text(text, encoding="utf-8")
    robot = joulepath.load_robot(path)
    assert np.array_equal(robot.effort_limit, np.full(6, 50.0))
    assert not any("torque" in f.message for f in robot.check_physical())
    assert "      50.0" in robot.summary()


def test_summary_shows_torque_limits_column(irb120):
    lines = irb120.summary().splitlines()
    assert "torque N·m" in lines[1]
    assert all("not given" in line for line in lines[2:8])


def test_drives_come_from_a_file_beside_the_description(tmp_path):
    import shutil

    urdf = tmp_path / "arm.urdf"
    shutil.copy(preset_path("irb120", fmt="urdf"), urdf)
    bare = joulepath.load_robot(urdf)
    assert bare.drives is None and "no arm.drives.toml beside the description" in bare.drives_note
    assert bare.drivetrain.gear_efficiency is None
    (tmp_path / "arm.drives.toml").write_text(
        'torque_constant = 20.0\nresistance = 1.0\ndrive_efficiency = 0.9\nbus = "bleeder"\n'
        'gear_efficiency = 0.7\n[sources]\ngear_efficiency = "bench test"\n'
    )
    robot = joulepath.load_robot(urdf)
    assert robot.drives is not None and robot.drives.torque_constant == (20.0,) * robot.n_joints
    assert "arm.drives.toml" in robot.drives_note
    assert robot.drivetrain.gear_efficiency == (0.7,) * robot.n_joints
    assert "bench test" in robot.drivetrain.gear_source


def test_bundled_irb120_drives_are_a_labelled_estimate(irb120):
    drives = irb120.drives
    assert drives is not None and drives.n_joints == irb120.n_joints
    assert all(drives.source(k).startswith("assumed (estimate)") for k in ("torque_constant", "standby_W"))
    assert "every value assumed" in irb120.drivetrain.drives_source
