"""Closed-form IK of the IRB 120 against FK, and ABB's confdata on hand-checked poses."""

import numpy as np
import pytest

import joulepath
from joulepath.errors import InvalidInput
from joulepath.kinematics._ik import check_layout, confdata, ik_branches, pose_error, solve_ik, solve_ik_along


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


def test_fk_of_ik_on_5000_random_poses(robot):
    lo, hi = robot.joint_ranges()
    q = lo + np.random.default_rng(7).random((5000, 6)) * (hi - lo)
    pose = robot.fk(q).homogeneous
    qs, valid = ik_branches(robot.chain, pose)
    dp, da = pose_error(robot.chain, qs, pose[:, None])
    assert valid.any(axis=1).all()
    assert dp[valid].max() <= 1e-6 and da[valid].max() <= 1e-6
    # the branch the original configuration's confdata names gives back that configuration
    conf = confdata(robot.chain, q)
    away = np.abs(np.sin(q[:, 4])) > 1e-3  # off the wrist singularity
    for k in np.flatnonzero(away)[:400]:
        sol = solve_ik(robot.chain, pose[k], tuple(conf[k]), lower=lo, upper=hi)
        assert sol is not None and np.abs(sol - q[k]).max() < 1e-6


def test_every_valid_branch_has_its_own_cfx(robot):
    q = np.radians([30, 20, -10, 40, 50, 60])
    qs, valid = ik_branches(robot.chain, robot.fk(q).homogeneous)
    cfx = confdata(robot.chain, qs)[valid, 3]
    assert sorted(cfx.tolist()) == list(range(8))


def _wrist_centre(robot, q):
    pose = robot.fk(q)
    return pose.position_m - 0.072 * pose.rotation[:, 2]


@pytest.mark.parametrize(
    ("q_deg", "conf"),
    [
        ([0, 0, 0, 0, 30, 0], [0, 0, 0, 0]),  # home: every quadrant 0, front, front, axis 5 positive
        ([0, 0, 0, 0, -30, 0], [0, 0, 0, 1]),  # axis 5 negative
        ([100, 0, 0, 0, 30, 0], [1, 0, 0, 0]),  # axis 1 in its second quadrant
        ([-10, 0, 0, 0, 30, 0], [-1, 0, 0, 0]),
        ([0, 0, 0, -100, 30, 0], [0, -2, 0, 0]),
        ([0, 0, 0, 0, 30, 300], [0, 0, 3, 0]),  # axis 6 beyond one turn
        ([0, 0, 0, 0, 30, -200], [0, 0, -3, 0]),
    ],
)
def test_confdata_hand_checked(robot, q_deg, conf):
    assert confdata(robot.chain, np.radians(q_deg)).tolist() == conf


def test_wrist_behind_axis_1_and_elbow(robot):
    # lower arm tilted far back, upper arm forward of it:
    # wrist centre behind axis 1, in front of the lower arm
    q = np.radians([0, -100, 40, 0, 30, 0])
    assert _wrist_centre(robot, q)[0] < 0
    assert confdata(robot.chain, q)[3] == 4
    # lower arm tilted forward, upper arm raised back over it: in front of axis 1, behind the lower arm
    q = np.radians([0, 60, -100, 0, 30, 0])
    assert _wrist_centre(robot, q)[0] > 0 and confdata(robot.chain, q)[3] == 2
    # lower arm upright, upper arm raised back: behind both; axis 5 negative adds 1
    q = np.radians([0, 0, -100, 0, -30, 0])
    assert _wrist_centre(robot, q)[0] < 0 and confdata(robot.chain, q)[3] == 7


def test_conf_not_reachable_returns_none(robot):
    lo, hi = robot.joint_ranges()
    pose = robot.fk(np.radians([0, 0, 0, 0, 30, 0])).homogeneous
    assert solve_ik(robot.chain, pose, (0, 0, 0, 0), lower=lo, upper=hi) is not None
    assert solve_ik(robot.chain, pose, (2, 0, 0, 0), lower=lo, upper=hi) is None


def test_other_layout_refused(robot):
    from dataclasses import replace

    chain = replace(robot.chain, axes=np.roll(robot.chain.axes, 1, axis=1))
    with pytest.raises(InvalidInput, match="IRB 120 layout"):
        check_layout(chain)


def test_ik_along_a_path_agrees_with_solve_ik_pose_by_pose(robot):
    """:func:`solve_ik_along` (the branches of every pose at once) picks, pose after pose, what
    :func:`solve_ik` picks nearest the solution before; it ends at the first pose out of reach."""
    lo, hi = robot.joint_ranges()
    q0 = np.radians([10, 20, -10, 30, 40, 50])
    q1 = np.radians([-60, 35, 5, -40, 70, 120])
    s = np.linspace(0.0, 1.0, 40)[1:, None]
    poses = robot.fk(q0 + s * (q1 - q0)).homogeneous
    along = solve_ik_along(robot.chain, poses, lower=lo, upper=hi, start=q0)
    near = q0
    assert len(along) == len(poses)
    for pose, q in zip(poses, along, strict=True):
        ref = solve_ik(robot.chain, pose, None, lower=lo, upper=hi, near=near)
        assert q is not None and ref is not None and np.abs(q - ref).max() < 1e-12
        near = ref
    assert np.abs(along[-1] - q1).max() < 1e-6
    far = poses.copy()
    far[5:, :3, 3] *= 10.0  # out of reach from the sixth pose on
    cut = solve_ik_along(robot.chain, far, lower=lo, upper=hi, start=q0)
    assert len(cut) == 6 and cut[-1] is None and all(q is not None for q in cut[:-1])
