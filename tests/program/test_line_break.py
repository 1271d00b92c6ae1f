"""A MoveL whose joints break off on the way says why, with the fix: an axis that must pass its range
(the line is out of this arm's reach), or the wrist singularity (axis 5 through 0).

The two programs are built from joint values: each target is the forward kinematics of joints within
the ranges, with their own confdata, so the targets themselves are reachable and only the straight
line between them is not."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from joulepath.errors import InvalidInput
from joulepath.kinematics import confdata
from joulepath.program import parse_module, resolve_module
from joulepath.program._levers import _Evaluator
from joulepath.sim import ControllerConfig, tcp_pose

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"


def _robtarget(robot, q_deg: list[float]) -> str:
    q = np.radians(np.array(q_deg))
    pos, rot = tcp_pose(robot, q[None], np.eye(4))
    x, y, z, w = Rotation.from_matrix(rot[0]).as_quat()
    p = pos[0] * 1000.0
    cf = ", ".join(str(int(c)) for c in confdata(robot.chain, q))
    return f"[[{p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f}], [{w:.9f}, {x:.9f}, {y:.9f}, {z:.9f}], [{cf}], {EXT}]"


def _plan(robot, start: list[float], end: list[float]) -> None:
    text = f"""MODULE Lines
    CONST jointtarget jA := [[{", ".join(map(str, start))}], {EXT}];
    CONST robtarget pB := {_robtarget(robot, end)};
    PROC main()
        MoveAbsJ jA, v1000, fine, tool0;
        MoveL pB, v200, fine, tool0;
    ENDPROC
ENDMODULE
"""
    spec = resolve_module(parse_module(text, path="lines.mod"), robot)
    _Evaluator(spec, [], "thesis", ControllerConfig())(())


def test_a_line_that_needs_axis_4_past_its_range_says_so(irb120):
    # axis 4 from 150 to -150 deg: the tool turns 60 deg the short way, through axis 4 at 180
    lo, hi = np.degrees(irb120.joint_ranges()[0][3]), np.degrees(irb120.joint_ranges()[1][3])
    assert hi < 180.0 and lo > -180.0
    with pytest.raises(InvalidInput) as err:
        _plan(irb120, [0, 20, 10, 150, 60, 0], [0, 20, 10, -150, 60, 0])
    line = str(err.value)
    assert line.startswith("lines.mod:6: MoveL pB: the straight line needs axis 4 past its range")
    assert f"({lo:.0f} to {hi:.0f} deg)" in line and "--robot" in line and "MoveJ" in line
    assert "singular" not in line


def test_a_line_through_the_wrist_singularity_says_so(irb120):
    # axis 5 from 30 to -30 deg with axis 1 turning: the line passes axis 5 at 0
    wrist = r"lines\.mod:6: MoveL pB: the straight line passes the wrist singularity"
    with pytest.raises(InvalidInput, match=wrist):
        _plan(irb120, [0, 20, 10, 0, 30, 0], [10, 20, 10, 0, -30, 0])


def test_the_same_line_the_other_way_within_the_ranges_plans(irb120):
    # the control: axis 4 from 150 to 100 deg stays inside its range, and the line plans
    _plan(irb120, [0, 20, 10, 150, 60, 0], [0, 20, 10, 100, 60, 0])
