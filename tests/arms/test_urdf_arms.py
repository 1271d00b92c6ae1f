"""URDF arms of 5 to 7 joints: clear refusals, continuous and gripper joints, locking joints."""

from __future__ import annotations

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.errors import InvalidRobotDescription

LINK = (
    '<link name="{name}"><inertial><mass value="2"/><origin xyz="0 0 0.1"/>'
    '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>'
)


def joint(name, parent, child, kind="revolute", axis="0 0 1", rpy="0 0 0"):
    limit = '<limit lower="-2" upper="2" effort="100" velocity="2"/>'
    if kind == "continuous":
        limit = '<limit effort="100" velocity="2"/>'
    if kind == "prismatic":
        limit = '<limit lower="0" upper="0.04" effort="100" velocity="0.2"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0.05 0.2" rpy="{rpy}"/><axis xyz="{axis}"/>{limit}</joint>'
    )


def write(path, links, joints, name="arm"):
    body = "".join(LINK.format(name=n) for n in links) + "".join(joints)
    path.write_text(f'<?xml version="1.0"?><robot name="{name}">{body}</robot>')
    return path


def serial(path, n, kinds=None, names=None, extra_links=(), extra_joints=()):
    kinds = kinds or ["revolute"] * n
    names = names or [f"j{i}" for i in range(1, n + 1)]
    links = [f"l{i}" for i in range(n + 1)]
    joints = [
        joint(names[i - 1], f"l{i - 1}", f"l{i}", kinds[i - 1], rpy="1.5708 0 0" if i % 2 else "0 0 0")
        for i in range(1, n + 1)
    ]
    return write(path, [*links, *extra_links], [*joints, *extra_joints])


def one_line_exit_2(capsys, args, *needles):
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    for needle in needles:
        assert needle in err[0], err[0]


# --------------------------------------------------------------------------- refusals


def test_prismatic_joint_refused_with_the_lock_hint(tmp_path, capsys):
    p = serial(tmp_path / "p.urdf", 6, kinds=["revolute"] * 5 + ["prismatic"])
    one_line_exit_2(capsys, ["robot", "show", str(p)], "joint 'j6' is prismatic", "--lock j6=VALUE")


def test_tree_refused_naming_the_branches(tmp_path, capsys):
    extra = [joint("side", "l3", "s1")]
    p = serial(tmp_path / "t.urdf", 6, extra_links=["s1"], extra_joints=extra)
    one_line_exit_2(capsys, ["robot", "fk", str(p), "--q", "0,0,0,0,0,0"], "is tree-shaped", "'side'", "'j3'")


@pytest.mark.parametrize("n", [4, 8])
def test_joint_count_outside_5_to_7_refused(tmp_path, capsys, n):
    p = serial(tmp_path / f"a{n}.urdf", n)
    one_line_exit_2(capsys, ["robot", "show", str(p)], f"has {n} movable joints", "5 to 7 revolute joints")


def test_lock_of_an_unknown_joint_names_the_movable_ones(tmp_path, capsys):
    p = serial(tmp_path / "a.urdf", 6)
    one_line_exit_2(
        capsys, ["robot", "show", str(p), "--lock", "nope=0"], "no movable joint 'nope'", "j1, j2"
    )
    one_line_exit_2(capsys, ["robot", "show", str(p), "--lock", "j1"], "is not JOINT=VALUE")


# --------------------------------------------------------------------------- accepted, with words


@pytest.mark.parametrize("n", [5, 6, 7])
def test_five_to_seven_joints_accepted(tmp_path, n):
    robot = joulepath.load_robot(serial(tmp_path / f"a{n}.urdf", n))
    assert robot.n_joints == n and robot.home.shape == (n,)
    q = np.random.default_rng(n).uniform(-1, 1, (4, n))
    qd, qdd = np.ones((4, n)) * 0.3, np.ones((4, n)) * -0.7
    rnea = robot.inverse_dynamics(q, qd, qdd)
    le = robot.inverse_dynamics(q, qd, qdd, method="lagrange-euler")
    np.testing.assert_allclose(rnea, le, atol=1e-10)


def test_continuous_joint_named_as_such_and_given_a_full_turn(tmp_path, capsys):
    p = serial(tmp_path / "c.urdf", 6, kinds=["continuous"] + ["revolute"] * 5)
    robot = joulepath.load_robot(p)
    np.testing.assert_allclose([robot.lower[0], robot.upper[0]], [-2 * np.pi, 2 * np.pi])
    assert main(["robot", "fk", str(p), "--q", "3,0,0,0,0,0"]) == 0
    err = capsys.readouterr().err
    assert "'j1' is continuous" in err and "JointModel" not in err


def test_gripper_named_joint_warns(tmp_path, capsys):
    names = ["j1", "j2", "j3", "j4", "j5", "gripper_joint"]
    p = serial(tmp_path / "g.urdf", 6, names=names)
    assert main(["robot", "fk", str(p), "--q", "0,0,0,0,0,0"]) == 0
    assert "'gripper_joint' is named like a gripper or finger" in capsys.readouterr().err
    assert any("gripper" in f.where for f in joulepath.load_robot(p).check_physical())


def test_locked_joint_moves_the_tool_as_the_joint_would(tmp_path):
    """Locking joint 7 at v gives the 6-joint arm whose FK and dynamics are the 7-joint arm's at q7 = v."""
    p = serial(tmp_path / "a7.urdf", 7)
    full = joulepath.load_robot(p)
    locked = joulepath.load_robot(p, lock={"j7": 0.4})
    assert locked.n_joints == 6 and locked.joint_names == full.joint_names[:6]
    q6 = np.random.default_rng(3).uniform(-1, 1, (5, 6))
    q7 = np.column_stack([q6, np.full(5, 0.4)])
    full_tool = full.fk(q7).position_m
    lock_tool = locked.fk(q6).position_m
    np.testing.assert_allclose(lock_tool, full_tool, atol=1e-12)
    qd6 = np.full((5, 6), 0.2)
    qdd6 = np.full((5, 6), -0.5)
    tau_full = full.inverse_dynamics(q7, np.c_[qd6, np.zeros(5)], np.c_[qdd6, np.zeros(5)])
    np.testing.assert_allclose(locked.inverse_dynamics(q6, qd6, qdd6), tau_full[:, :6], atol=1e-10)


def test_lock_makes_an_arm_with_a_finger_usable(tmp_path, capsys):
    finger = [joint("finger_joint", "l6", "f1", "prismatic", axis="0 1 0")]
    p = serial(tmp_path / "f.urdf", 6, extra_links=["f1"], extra_joints=finger)
    with pytest.raises(InvalidRobotDescription, match="'finger_joint' is prismatic"):
        joulepath.load_robot(p)
    assert main(["robot", "show", str(p), "--lock", "finger_joint=0.01"]) == 0
    assert "6 revolute joints" in capsys.readouterr().out
