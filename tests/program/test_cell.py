"""The cell: reading it, coal's clearance against an independent distance, and going around an obstacle."""

import numpy as np
import pytest

import joulepath
from joulepath.errors import InvalidInput
from joulepath.optimize import GradientSettings
from joulepath.program import CycleSettings, optimize_cycle, parse_module, resolve_module
from joulepath.program._cell import Cell, Obstacle, clearance, read_cell
from joulepath.program._cycle import CycleOptimizer

pytest.importorskip("coal")

FAST = GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), max_iter=60, coarse_factor=1)

TWO = """MODULE Two
    CONST jointtarget jA := [[-60, 10, 20, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget jB := [[60, 30, -10, 0, 50, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PERS tooldata tLong := [TRUE, [[0, 0, 200], [1, 0, 0, 0]], [0, [0, 0, 0], [1, 0, 0, 0], 0, 0, 0]];
    PROC main()
        WHILE TRUE DO
            MoveAbsJ jA, v1000, fine, tLong;
            WaitTime 0.5;
            MoveAbsJ jB, v1000, fine, tLong;
            WaitTime 0.5;
        ENDWHILE
    ENDPROC
ENDMODULE
"""


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


def test_read_cell_and_errors(tmp_path):
    f = tmp_path / "cell.toml"
    f.write_text('margin_mm = 15\n[[box]]\nname = "t"\ncenter_mm = [0, 0, -10]\nsize_mm = [100, 100, 20]\n')
    cell = read_cell(f)
    assert cell.margin == pytest.approx(0.015) and cell.obstacles[0].size == pytest.approx((0.1, 0.1, 0.02))
    for bad, match in (
        ('[[box]]\nname = "t"\ncenter_mm = [0, 0]\nsize_mm = [1, 1, 1]\n', "center_mm"),
        ('[[box]]\nname = "t"\ncenter_mm = [0, 0, 0]\nsize_mm = [1, -1, 1]\n', "size_mm"),
        ("margin_mm = 5\n", "no obstacle"),
        ('[[sphere]]\nname = "s"\n', "unknown key"),
    ):
        f.write_text(bad)
        with pytest.raises(InvalidInput, match=match):
            read_cell(f)


def test_clearance_agrees_with_a_point_sampled_distance(robot):
    """coal's capsule-box distance against sampling the capsule axis and the box's analytic distance."""
    q = np.radians([20, 30, 10, 0, 50, 0])
    tcp = np.eye(4)
    tcp[2, 3] = 0.1
    pose = robot.fk(q)
    tip = pose.position_m + pose.rotation[:, 2] * 0.1
    centre = tip + np.array([0.0, 0.0, -0.15])
    half = np.array([0.05, 0.05, 0.02])
    cell = Cell((Obstacle("b", "box", tuple(centre), tuple(2 * half)),), 0.0, 0.055, 0.04, 0.025)
    got = clearance(cell, robot, q[None], tcp)
    # independent: the tool capsule (flange -> tip, radius 25 mm) is the closest part here
    s = np.linspace(0.0, 1.0, 2001)[:, None]
    pts = pose.position_m + s * (tip - pose.position_m)
    d = np.linalg.norm(np.maximum(np.abs(pts - centre) - half, 0.0), axis=1).min() - 0.025
    assert got.obstacle == "b"
    assert got.distance == pytest.approx(d, abs=1e-5)


def test_result_goes_around_an_obstacle_on_the_free_optimum(robot):
    spec = resolve_module(parse_module(TWO, path="two.mod"), robot)
    free = CycleOptimizer(spec, CycleSettings(gradient=FAST, corridor_mm=None))
    i = free.optimizable[0]
    m = free.by_index[i]
    T = free.t_lo[i] + 0.3
    s = free.solve(i, T)
    # the sample where the free optimum's tool0 is farthest from the taught (joint-interpolated) move
    from joulepath.trajectory import minimum_jerk

    taught = minimum_jerk(m.path.q0, m.path.q1, s.duration, dt=s.samples.dt)
    tcp = m.step.tcp

    def tip(q):
        pose = robot.fk(q)
        return pose.position_m + pose.rotation @ tcp[:3, 3]

    a, b = tip(s.samples.q), tip(taught.q)
    # geometric distance of each free-optimum point from the taught path (any instant)
    dev = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2).min(axis=1)
    assert dev.max() > 0.06  # the free optimum's tool tip leaves the taught path by > 60 mm
    # a 10 mm block on the free optimum's path, where the taught move clears it by the margin
    cell = None
    for k in np.argsort(-dev)[:10]:
        box = Obstacle("block", "box", tuple(a[k]), (0.01, 0.01, 0.01))
        trial = Cell((box,), 0.01, 0.055, 0.04, 0.025, "test")
        if CycleOptimizer(spec, CycleSettings(gradient=FAST, cell=trial)).default_clearance[i] >= 0:
            cell = trial
            break
    assert cell is not None
    assert clearance(cell, robot, s.fine.q, tcp).distance < 0  # the free optimum hits it
    settings = CycleSettings(gradient=FAST, table_points=2, corridor_mm=None, cell=cell, use_waits=True)
    result, opt = optimize_cycle(spec, settings)
    assert opt.default_clearance[i] >= 0  # the taught move clears it
    moved = next(mo for mo in result.moves if mo.line == m.step.line)
    assert moved.optimized and moved.optimized_clearance_mm >= 0.0
    assert result.limits_ok
    # checked independently on the written move's 2.5 ms grid
    written = result.paths[i]
    assert clearance(cell, robot, written.fine.q, tcp).distance >= cell.margin - 1e-9
    # at the duration where the free optimum hits the block, the cell's result goes around it
    around = opt.solve(i, T)
    assert around.usable and around.corridor_used_mm is not None
    assert clearance(cell, robot, around.fine.q, tcp).distance >= cell.margin - 1e-9
