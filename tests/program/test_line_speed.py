"""The speed data of a program's MoveL lines, as a written module must keep them.

Invariants: the controller emulation runs a taught program within its own speed data; a line run back
over the same points is another MoveL (its own speed data); a MoveL made faster is caught on its line,
by as much as it was made faster; a chord on a line takes at least its length at the line's speed; a
timed chain whose segment lies on a line is timed no faster than the line allows; the via points next
to a taught blend are kept clear of it.
"""

import numpy as np
import pytest

from joulepath.optimize._retime import tcp_velocity
from joulepath.program import parse_module, resolve_module
from joulepath.program._levers import _Evaluator, cycle_motion
from joulepath.program._line_speed import SPEED_TOL, LineSpeed, chord_floor, fastest_on_lines, line_speeds
from joulepath.program._via_timing import MARGIN, _Chain, _clear_of_blends, _fastest, chain_runs
from joulepath.sim import ControllerConfig, tcp_pose

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
PROGRAM = f"""MODULE Lines
    ! down to a part at v200, back up at v500, over the same points
    CONST robtarget pAbove := [[350, 0, 400], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    CONST robtarget pPart := [[350, 0, 250], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    CONST jointtarget jH := [[0, 0, 0, 0, 30, 0], {EXT}];
    PROC main()
        MoveAbsJ jH, v1000, fine, tool0;
        MoveJ pAbove, v1000, z20, tool0;
        MoveL pPart, v200, fine, tool0;
        WaitTime 0.2;
        MoveL pAbove, v500, z20, tool0;
        MoveAbsJ jH, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""
CONFIG = ControllerConfig()
DOWN, UP = (
    PROGRAM.splitlines().index(f"        {s}") + 1
    for s in ("MoveL pPart, v200, fine, tool0;", "MoveL pAbove, v500, z20, tool0;")
)


def _run(text: str, robot):
    spec = resolve_module(parse_module(text, path="lines.mod"), robot)
    plan, _, _ = _Evaluator(spec, [], "thesis", CONFIG)(())
    traj = cycle_motion(plan)
    first = plan.moves[0].step
    pos, _ = tcp_pose(robot, traj.q, first.tcp)
    return plan, pos, tcp_velocity(robot, traj.q, traj.qd, first.tcp)


@pytest.fixture(scope="module")
def taught(irb120):
    return _run(PROGRAM, irb120)


def test_the_taught_program_keeps_its_speed_data_and_each_line_is_its_own(taught):
    plan, pos, vel = taught
    lines = line_speeds(plan)
    assert [(ln.line, ln.speed_mm_s) for ln in lines] == [(DOWN, 200.0), (UP, 500.0)]
    down, up = lines
    assert np.allclose(down.a, up.b, atol=0.03) and np.allclose(down.b, up.a, atol=1e-3)  # the same points
    ratio, _ = fastest_on_lines(lines, pos, vel)
    assert ratio <= 1.0 + SPEED_TOL
    # the way up runs at 500 mm/s over the points of the way down: counted on its own line only
    speed = np.linalg.norm(vel, axis=1)
    assert speed.max() > 2.0 * down.v
    assert fastest_on_lines((down,), pos, vel)[0] <= 1.0 + SPEED_TOL


def test_a_movel_made_faster_is_caught_on_its_line(irb120, taught):
    lines = line_speeds(taught[0])
    _, pos, vel = _run(PROGRAM.replace("MoveL pPart, v200", "MoveL pPart, v400"), irb120)
    ratio, line = fastest_on_lines(lines, pos, vel)
    assert line is not None and line.line == DOWN
    assert ratio == pytest.approx(2.0, rel=0.02)


def test_a_chord_on_a_line_takes_its_length_at_the_lines_speed():
    line = LineSpeed(7, np.array([0.3, 0.0, 0.4]), np.array([0.3, 0.0, 0.2]), 0.2, 200.0)
    p0, p1 = np.array([0.3, 0.0, 0.35]), np.array([0.3, 0.0, 0.30])
    assert chord_floor((line,), p0, p1) == pytest.approx(0.05 / 0.2)
    assert chord_floor((line,), p1, p0) == 0.0  # the other way: not this MoveL
    assert chord_floor((line,), p0, p1 + np.array([0.01, 0.0, 0.0])) == 0.0  # off the line


def test_a_timed_chain_on_a_line_is_no_faster_than_the_line(irb120):
    text = f"""MODULE Chain
    CONST jointtarget j0 := [[0, 0, 0, 0, 30, 0], {EXT}];
    CONST jointtarget j1 := [[10, 5, 0, 0, 25, 0], {EXT}];
    CONST jointtarget j2 := [[20, 10, 0, 0, 20, 0], {EXT}];
    CONST jointtarget j3 := [[30, 15, 0, 0, 15, 0], {EXT}];
    PROC main()
        MoveAbsJ j0, v1000, fine, tool0;
        jp_opt_main_1;
    ENDPROC
    PROC jp_opt_main_1()
        MoveAbsJ j1, v7000 \\T:=0.2, z200, tool0;
        MoveAbsJ j2, v7000 \\T:=0.2, z200, tool0;
        MoveAbsJ j3, v7000 \\T:=0.2, fine, tool0;
    ENDPROC
ENDMODULE
"""
    spec = resolve_module(parse_module(text, path="chain.mod"), irb120)
    added = set(range(11, 16))
    (run,) = chain_runs(spec, added)
    free = _Chain(spec, run, "thesis", CONFIG)
    T0 = np.array([spec.steps[i].time_s for i in run.steps])
    fast = _fastest(free, T0)
    assert fast is not None
    # a line through the middle segment's ends, slow enough that the segment binds
    qs = np.array([spec.steps[i].q for i in run.steps])
    tcp = spec.steps[run.steps[0]].tcp
    pos, _ = tcp_pose(irb120, qs, tcp)
    length = float(np.linalg.norm(pos[2] - pos[1]))
    v = 0.5 * length / fast[2]
    slow = LineSpeed(99, pos[1], pos[2], v, 1000.0 * v)
    bound = _Chain(spec, run, "thesis", CONFIG, (slow,))
    assert bound.floor[2] == pytest.approx((1.0 + MARGIN) * length / v)
    assert bound.floor[0] == 0.0 and bound.floor[1] == 0.0
    timed = _fastest(bound, T0)
    assert timed is not None and timed[2] >= bound.floor[2] * (1.0 - 1e-9)
    assert timed.sum() > fast.sum()


def test_via_points_next_to_a_taught_blend_are_kept_clear_of_it():
    t = np.arange(0.0, 1.0001, 0.0025)
    idx = list(range(20, t.size, 20))
    kept = _clear_of_blends(t, idx, 0.2, 0.3)
    assert kept[-1] == t.size - 1
    assert all(0.2 - 1e-9 <= t[k] <= 0.7 + 1e-9 for k in kept[:-1])
    assert set(kept[:-1]) == {k for k in idx[:-1] if 0.2 - 1e-9 <= t[k] <= 0.7 + 1e-9}
    assert _clear_of_blends(t, idx, 0.0, 0.0) == tuple(idx)
