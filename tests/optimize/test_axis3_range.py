"""The IRB 2400's axis 3 is coupled to axis 2 (a parallel linkage): its controller limits axis 3 =
joint 2 + joint 3, which no joint's own range states. The optimizer keeps it, and the limit check
refuses a path beyond it."""

from __future__ import annotations

import numpy as np
import pytest

import joulepath
from joulepath.optimize import (
    ACCEL_TIME,
    GRID_SEARCH,
    MOVE_SEARCH,
    GradientSettings,
    acceleration_limit,
    check_limits,
)
from joulepath.optimize._gradient import solve_move
from joulepath.trajectory import minimum_jerk


@pytest.fixture(scope="module")
def irb2400():
    return joulepath.load_robot("irb2400")


@pytest.mark.parametrize("settings", [MOVE_SEARCH, GRID_SEARCH], ids=["move", "cycle"])
@pytest.mark.parametrize("axis3_deg", [63.0, -58.0])
def test_an_optimized_move_keeps_the_coupled_axis_3_in_its_range(irb2400, settings, axis3_deg):
    """Both ends 2 degrees inside the range, the joints far from theirs: the energy-optimal path
    leans into the coupled limit (measured before the rows: axis 3 went to 164 deg from 63)."""
    lo, hi = irb2400.axis3_range
    a3 = np.radians(axis3_deg)
    q0 = irb2400.axes_to_joints([-0.8, -0.4, a3, 0.3, 0.5, 0.0])
    q1 = irb2400.axes_to_joints([0.9, 0.6, a3, -0.4, -0.3, 1.0])
    res, problem = solve_move(
        irb2400,
        q0,
        q1,
        2.5,
        friction=irb2400.friction,
        settings=GradientSettings(**settings),
        rng=np.random.default_rng(0),
        acceleration_limit=acceleration_limit(irb2400, ACCEL_TIME),
    )
    fine = problem.path(res.coefficients.ravel(), fine=True)
    axis3 = irb2400.joints_to_axes(fine.q)[:, 2]
    assert lo - 1e-6 <= axis3.min() and axis3.max() <= hi + 1e-6
    assert check_limits(irb2400, fine, friction=irb2400.friction).ok


def test_the_limit_check_refuses_a_path_beyond_the_coupled_axis_3(irb2400):
    lo, hi = irb2400.axis3_range
    q0 = irb2400.axes_to_joints([0.0, 0.0, hi - 0.2, 0.0, 0.3, 0.0])
    q1 = irb2400.axes_to_joints([0.0, 0.0, hi + 0.1, 0.0, 0.3, 0.0])  # each joint inside its own range
    path = minimum_jerk(q0, q1, 2.0, dt=0.004)
    joint_lo, joint_hi = irb2400.joint_ranges()
    assert np.all(path.q >= joint_lo) and np.all(path.q <= joint_hi)
    report = check_limits(irb2400, path, friction=irb2400.friction)
    assert not report.ok and report.range_rad > 0
    worst = report.worst[0]
    assert worst.kind == "axis-3 range" and worst.joint == 3
    assert worst.value == pytest.approx(hi + 0.1, abs=1e-6) and worst.limit == pytest.approx(hi)
