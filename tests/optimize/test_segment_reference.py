"""The cycle optimum over whole segments (MoveL included): agreement with cycle_optimum, the line kept,
and never above the taught motion it starts from."""

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("casadi")

from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.errors import InvalidInput  # noqa: E402
from joulepath.optimize import (  # noqa: E402
    ACCEL_TIME,
    JERK_TIME,
    CycleLeg,
    CycleSegment,
    SegmentMove,
    acceleration_limit,
    cycle_optimum,
    jerk_limit,
    plan_segments,
    segment_optimum,
)
from joulepath.optimize._verify import energy_on_samples  # noqa: E402
from joulepath.program import CycleSettings, read_cycle_program  # noqa: E402
from joulepath.sim import plan_cycle  # noqa: E402

QA = np.array([0.2, -0.1, 0.1, 0.4, -0.3, 0.5])
QB = np.array([-0.3, 0.2, -0.1, -0.2, 0.3, -0.3])
QC = np.array([0.4, 0.3, 0.2, 0.2, -0.2, 0.3])
N = 6  # intervals per piece: few, for speed
N_LINE = 4  # the MoveL segment's: at 6, IPOPT took 20 times as long here
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def limits(irb120):
    return acceleration_limit(irb120, ACCEL_TIME), jerk_limit(irb120, ACCEL_TIME, JERK_TIME)


@pytest.fixture(scope="module")
def pick_and_place(irb120):
    """The bundled example's first segment: a MoveJ blended (z50) into a MoveL down to the pick."""
    spec, _ = read_cycle_program(EXAMPLES / "pick_and_place.mod", irb120)
    plan = plan_cycle(spec, CycleSettings().controller)
    return plan, plan_segments(plan)


def test_segment_optimum_of_joint_moves_reproduces_cycle_optimum(irb120, limits):
    zone = np.full(6, 0.05)
    leg = cycle_optimum(
        irb120,
        [CycleLeg(QA, QC, via=(QB,), via_radius=(zone,))],
        1.2,
        acceleration_limit=limits[0],
        jerk_limit=limits[1],
        intervals=N,
    )
    seg = segment_optimum(
        irb120,
        [CycleSegment(QA, (SegmentMove(QB, zone=zone), SegmentMove(QC)))],
        1.2,
        acceleration_limit=limits[0],
        jerk_limit=limits[1],
        intervals=N,
    )
    assert leg.feasible and seg.feasible, (leg.status, seg.status)
    assert seg.energy_J == pytest.approx(leg.energy_J, rel=1e-6)
    np.testing.assert_allclose(seg.paths[0].q, leg.paths[0].q, atol=1e-6)


def test_plan_segments_cover_the_cycle_and_its_taught_energy(irb120, pick_and_place):
    plan, segs = pick_and_place
    assert [j for s in segs for j in s.moves] == [m.index for m in plan.moves if m.profile.duration > 0]
    for s in segs:  # each segment starts and ends at rest, at its moves' ends
        np.testing.assert_allclose(s.taught.qd[[0, -1]], 0.0, atol=1e-9)
        np.testing.assert_allclose(s.taught.q[0], s.segment.q_start, atol=1e-9)
        np.testing.assert_allclose(s.taught.q[-1], s.segment.moves[-1].q_end, atol=1e-9)
    kinds = [m.line is not None for m in segs[0].segment.moves]
    assert kinds == [False, True]  # MoveJ, then MoveL
    assert segs[0].segment.moves[1].blend_in > 0  # the MoveJ's zone reaches into the line


def test_segment_optimum_keeps_the_line_its_speed_and_saves_on_the_taught_motion(
    irb120, limits, pick_and_place
):
    plan, segs = pick_and_place
    s = segs[0]
    res = segment_optimum(
        s.robot,
        [s.segment],
        s.span,
        acceleration_limit=limits[0],
        jerk_limit=limits[1],
        intervals=N_LINE,
        initial=[s.taught],
    )
    assert res.feasible, (res.status, [w for r in res.limits for w in r.worst if w.excess > 1e-4])
    assert res.durations[0] <= s.span + 1e-6
    taught = energy_on_samples(s.robot, s.taught, friction=NOMINAL_FRICTION)
    assert res.energy_J <= taught  # the taught motion is inside the relaxation, and its start
    move = next(m for m in plan.moves if m.index == s.moves[1])
    robot, tcp = move.step.robot, move.step.tcp

    def tcp_at(q):
        pose = robot.fk(q)
        return pose.position_m + np.einsum("...ij,j->...i", pose.rotation, tcp[:3, 3])

    p0, p1 = tcp_at(move.path.q0[None, :])[0], tcp_at(move.path.q1[None, :])[0]
    ((t_line, _),) = res.lines_s[0]
    path = res.paths[0]
    inside = np.isin(path.t, t_line)
    p = tcp_at(path.q[inside])
    u = (p1 - p0) / np.linalg.norm(p1 - p0)
    off_line = np.linalg.norm((p - p0) - np.outer((p - p0) @ u, u), axis=1)
    assert off_line.max() <= 0.5e-3  # m: on the straight line, within 0.5 mm
    speed = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(path.t[inside])
    assert speed.max() <= move.step.speed.v_tcp / 1000.0 * (1 + 1e-3)


@pytest.mark.parametrize(
    ("segments", "budget", "match"),
    [
        ([CycleSegment(QA, (SegmentMove(QB),))], -1.0, "budget must be a positive"),
        ([], 1.0, "segments is empty"),
        ([CycleSegment(QA, ())], 1.0, "has no moves"),
        ([CycleSegment(QA[:5], (SegmentMove(QB),))], 1.0, "must be a finite vector of 6 joint values"),
        ([CycleSegment(QA, (SegmentMove(QB, zone=-1.0), SegmentMove(QC)))], 1.0, "zone must be ≥ 0"),
    ],
)
def test_segment_optimum_invalid_input(irb120, segments, budget, match):
    with pytest.raises(InvalidInput, match=match) as err:
        segment_optimum(irb120, segments, budget)
    assert "\n" not in str(err.value)


def test_plan_segments_window_of_a_line_retraced_by_the_next_ends_where_it_turns(irb120):
    """payload_tool lifts the gripper with a MoveL (z50) and, after a MoveJ to where it already is,
    lowers it along the same line: the taught motion stays on the first line's path throughout,
    so its window must end where it turns back, not at the segment's end (else the relaxation
    lets both lines be skipped)."""
    from joulepath.optimize._reference import _casadi
    from joulepath.optimize._segment_reference import _Line, _pieces, _widened, _windows

    spec, _ = read_cycle_program(EXAMPLES / "payload_tool.mod", irb120)
    segs = plan_segments(plan_cycle(spec, CycleSettings().controller))
    seg = next(s for s in segs if [m.line is not None for m in s.segment.moves] == [True, True])
    pieces = _pieces(_casadi(), seg.segment, irb120.n_joints, "segment")
    windows = _windows(pieces, seg.taught)
    lines = [(p, w) for p, w in zip(pieces, windows, strict=True) if isinstance(p, _Line)]
    (first, (a0, b0)), (second, (a1, b1)) = lines
    assert a0 == 0 and b0 <= a1 < b1 == seg.taught.t.size - 1
    assert seg.taught.t[b0] < 0.75 * seg.span  # it turns back well before the segment ends
    for p, q in zip(pieces, _widened(pieces, seg.taught, windows), strict=True):
        if isinstance(p, _Line):  # the taught motion turns within the zone: nothing to widen
            assert (q.s0, q.s1) == (p.s0, p.s1)
