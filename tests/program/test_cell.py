"""The cell: reading it, coal's clearance against an independent distance, and going around an obstacle."""

import numpy as np
import pytest

import joulepath
from joulepath.errors import InvalidInput
from joulepath.optimize import GradientSettings
from joulepath.program import CycleSettings, parse_module, resolve_module
from joulepath.program._cell import Cell, Obstacle, clearance, read_cell
from joulepath.program._cycle import CycleOptimizer, _optimize_cycle

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
        ('[[cone]]\nname = "s"\n', "unknown key"),
        ('[[sphere]]\nname = "s"\n', "needs exactly"),
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
    i = free.units.optimizable[0]
    m = free.units.by_index[i]
    T = free.solver.t_lo[i] + 0.3
    s = free.solver.solve(i, T)
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
        if CycleOptimizer(spec, CycleSettings(gradient=FAST, cell=trial)).units.default_clearance[i] >= 0:
            cell = trial
            break
    assert cell is not None
    assert clearance(cell, robot, s.fine.q, tcp).distance < 0  # the free optimum hits it
    settings = CycleSettings(gradient=FAST, table_points=2, corridor_mm=None, cell=cell, use_waits=True)
    result, opt = _optimize_cycle(spec, settings)
    assert opt.units.default_clearance[i] >= 0  # the taught move clears it
    moved = next(mo for mo in result.moves if mo.line == m.step.line)
    assert moved.optimized and moved.optimized_clearance_mm >= 0.0
    assert result.limits_ok
    # checked independently on the written move's 2.5 ms grid
    written = result.paths[i]
    assert clearance(cell, robot, written.fine.q, tcp).distance >= cell.margin - 1e-9
    # at the duration where the free optimum hits the block, the cell's result goes around it
    around = opt.solver.solve(i, T)
    assert around.usable and around.corridor_used_mm is not None
    assert clearance(cell, robot, around.fine.q, tcp).distance >= cell.margin - 1e-9


# ----------------------------------------------------------------------------- meshes and URDF cells
CUBE_V = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
# the 12 triangles of the cube's 6 faces (vertex k has bits x, y, z = k >> 2, k >> 1, k)
CUBE_F = [
    (0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5),  # x = -0.5, x = +0.5
    (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),  # y = -0.5, y = +0.5
    (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3),  # z = -0.5, z = +0.5
]  # fmt: skip


def _cube_obj(path):
    lines = [f"v {x} {y} {z}" for x, y, z in CUBE_V] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in CUBE_F]
    path.write_text("\n".join(lines) + "\n")
    return path


def _cube_stl(path):
    """The same cube as a binary STL (80-byte header, count, 50 bytes per triangle)."""
    v = np.array(CUBE_V, dtype="<f4")
    body = b"".join(np.zeros(3, "<f4").tobytes() + v[[a, b, c]].tobytes() + b"\0\0" for a, b, c in CUBE_F)
    path.write_bytes(b"\0" * 80 + np.uint32(len(CUBE_F)).tobytes() + body)
    return path


def _configs():
    return np.radians(
        [[20, 30, 10, 0, 50, 0], [0, 20, 20, 0, 40, 30], [35, 40, 0, 20, 60, 0], [10, 10, 30, 0, 30, 0]]
    )


def _near_tip(robot, q, tcp, below=0.15):
    pose = robot.fk(q)
    tip = pose.position_m + pose.rotation @ tcp[:3, 3]
    return 1000 * (tip + np.array([0.0, 0.0, -below]))


def _per_obstacle(cell, robot, qs, tcp):
    return [
        [clearance(Cell((ob,), 0.0, source="t"), robot, q[None], tcp).distance for q in qs]
        for ob in cell.obstacles
    ]


@pytest.mark.parametrize("writer", [_cube_obj, _cube_stl])
def test_mesh_cube_gives_the_distances_of_the_equivalent_box(robot, tmp_path, writer):
    tcp = np.eye(4)
    tcp[2, 3] = 0.1
    qs = _configs()
    c = _near_tip(robot, qs[0], tcp)
    writer(tmp_path / ("cube" + (".obj" if writer is _cube_obj else ".stl")))
    name = next(tmp_path.glob("cube.*")).name
    centre = ", ".join(f"{v:.3f}" for v in c)
    (tmp_path / "mesh.toml").write_text(
        f'[[mesh]]\nname = "m"\nfile = "{name}"\ncenter_mm = [{centre}]\n'
        "rpy_deg = [10, -20, 30]\nscale = [0.12, 0.08, 0.05]\n"
    )
    (tmp_path / "box.toml").write_text(
        f'[[box]]\nname = "m"\ncenter_mm = [{centre}]\nsize_mm = [120, 80, 50]\nrpy_deg = [10, -20, 30]\n'
    )
    mesh, box = read_cell(tmp_path / "mesh.toml"), read_cell(tmp_path / "box.toml")
    assert mesh.obstacles[0].kind == "mesh" and mesh.obstacles[0].mesh.num_tris == 12
    assert mesh.files == (str(tmp_path / name),)
    dm, db = np.array(_per_obstacle(mesh, robot, qs, tcp)), np.array(_per_obstacle(box, robot, qs, tcp))
    assert (db > 0).all() and db.min() < 0.15  # outside the box (a mesh is a surface), and close
    assert np.ptp(db) > 0.01  # the configurations differ
    np.testing.assert_allclose(dm, db, atol=1e-6)


URDF = """<?xml version="1.0"?>
<robot name="cell">
  <link name="base"/>
  <link name="table"><collision><origin xyz="0 0 -0.01"/><geometry><box size="1.2 1.4 0.02"/></geometry>
    </collision><visual><geometry><box size="1 1 1"/></geometry></visual></link>
  <link name="post"><collision><origin xyz="0.1 0 0.5"/><geometry><cylinder radius="0.04" length="1.0"/>
    </geometry></collision></link>
  <link name="rack"/>
  <link name="shelf">
    <collision name="board"><origin xyz="0 0 0.05"/>
      <geometry><box size="0.2 0.1 0.05"/></geometry></collision>
    <collision name="ball"><origin xyz="0.05 0 0"/><geometry><sphere radius="0.06"/></geometry></collision>
  </link>
  <link name="fixture"><collision><origin xyz="0 0 0.1" rpy="0 0 0.3"/>
    <geometry><mesh filename="cube.obj" scale="0.1 0.2 0.05"/></geometry></collision></link>
  <joint name="j_table" type="fixed"><parent link="base"/><child link="table"/>
    <origin xyz="0.3 0 -0.01"/></joint>
  <joint name="j_post" type="fixed"><parent link="base"/><child link="post"/>
    <origin xyz="-0.35 -0.35 0" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="j_rack" type="fixed"><parent link="base"/><child link="rack"/>
    <origin xyz="0.4 0.1 0.3" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="j_shelf" type="fixed"><parent link="rack"/><child link="shelf"/><origin xyz="0 0 0.1"/></joint>
  <joint name="j_fix" type="fixed"><parent link="base"/><child link="fixture"/>
    <origin xyz="0.35 -0.25 0.2"/></joint>
</robot>
"""

# the same cell by hand: the 90 deg turn about z swaps the shelf's x and y edges and moves
# the post's and the ball's offsets from x to y
TOML = """
[[box]]
name = "table"
center_mm = [300, 0, -20]
size_mm = [1200, 1400, 20]
[[box]]
name = "board"
center_mm = [400, 100, 450]
size_mm = [100, 200, 50]
[[cylinder]]
name = "post"
center_mm = [-350, -250, 500]
radius_mm = 40
length_mm = 1000
[[sphere]]
name = "ball"
center_mm = [400, 150, 400]
radius_mm = 60
[[mesh]]
name = "fixture"
file = "cube.obj"
center_mm = [350, -250, 300]
rpy_deg = [0, 0, 17.188733853924695]
scale = [0.1, 0.2, 0.05]
"""


def test_urdf_cell_gives_the_distances_of_the_equivalent_toml_cell(robot, tmp_path):
    _cube_obj(tmp_path / "cube.obj")
    (tmp_path / "cell.urdf").write_text(URDF)
    (tmp_path / "cell.toml").write_text(TOML)
    urdf, toml = read_cell(tmp_path / "cell.urdf"), read_cell(tmp_path / "cell.toml")
    assert urdf.margin == toml.margin == pytest.approx(0.02)  # the TOML default
    by_name = {ob.name: ob for ob in toml.obstacles}
    assert sorted(by_name) == sorted(ob.name for ob in urdf.obstacles)
    ordered = Cell(tuple(by_name[ob.name] for ob in urdf.obstacles), 0.0)
    tcp = np.eye(4)
    tcp[2, 3] = 0.1
    qs = np.radians(
        [[0, 30, 10, 0, 50, 0], [-60, 40, 0, 0, 60, 0], [90, 20, 20, 0, 40, 0], [-130, 50, 10, 0, 40, 0]]
    )
    du = np.array(_per_obstacle(urdf, robot, qs, tcp))
    dt = np.array(_per_obstacle(ordered, robot, qs, tcp))
    assert np.ptp(dt, axis=1).min() > 0.005  # each obstacle's distance changes with the configuration
    np.testing.assert_allclose(du, dt, atol=1e-6)
    whole_u = [clearance(urdf, robot, q[None], tcp) for q in qs]
    whole_t = [clearance(toml, robot, q[None], tcp) for q in qs]
    assert [c.obstacle for c in whole_u] == [c.obstacle for c in whole_t]


def _bad(tmp_path, name, text):
    f = tmp_path / name
    f.write_text(text)
    return f


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        (
            "a.toml",
            '[[mesh]]\nname = "m"\nfile = "nope.stl"\ncenter_mm = [0, 0, 0]\n',
            r"mesh 1: mesh .*nope\.stl does not exist",
        ),
        (
            "a.toml",
            '[[mesh]]\nname = "m"\nfile = "garbage.obj"\ncenter_mm = [0, 0, 0]\n',
            r"garbage\.obj cannot be read",
        ),
        (
            "a.toml",
            '[[mesh]]\nname = "m"\nfile = "empty.stl"\ncenter_mm = [0, 0, 0]\n',
            r"empty\.stl is empty",
        ),
        ("a.toml", '[[mesh]]\nname = "m"\nfile = "cube.ply"\ncenter_mm = [0, 0, 0]\n', r"not \.stl or \.obj"),
        ("a.toml", '[[mesh]]\nname = "m"\nfile = "sub"\ncenter_mm = [0, 0, 0]\n', r"not \.stl or \.obj"),
        ("a.toml", '[[mesh]]\nname = "m"\nfile = "dir.obj"\ncenter_mm = [0, 0, 0]\n', r"not a regular file"),
        ("a.toml", '[[mesh]]\nname = "m"\nfile = "cube.obj"\ncenter_mm = [0, 0, 0]\nscale = -1\n', "scale"),
        (
            "a.toml",
            '[[box]]\nname = "b"\ncenter_mm = [0, 0, 0]\nsize_mm = [1, 1, 1]\nrpy_deg = [0, 0]\n',
            "rpy_deg",
        ),
        (
            "c.urdf",
            URDF.replace('name="j_post" type="fixed"', 'name="j_post" type="revolute"'),
            r"joint 'j_post' is 'revolute'; a cell is static",
        ),
        ("c.urdf", URDF.replace("</robot>", ""), r"not well-formed XML at line"),
        (
            "c.urdf",
            URDF.replace('filename="cube.obj"', 'filename="package://cell/cube.obj"'),
            r"link 'fixture' collision 1: .*package:// paths are not resolved",
        ),
        (
            "c.urdf",
            URDF.replace('filename="cube.obj"', 'filename="missing.stl"'),
            r"link 'fixture' collision 1: mesh .*missing\.stl does not exist",
        ),
        (
            "c.urdf",
            URDF.replace('<box size="0.2 0.1 0.05"/>', '<box size="0.2 0.1"/>'),
            r"link 'shelf' collision 1: size='0.2 0.1' must be 3",
        ),
        (
            "c.urdf",
            '<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY a "b">]>\n<robot name="r"><link name="a"/></robot>',
            "DTDs and entities",
        ),
        ("c.urdf", '<robot name="r"><link name="a"/></robot>', "no <collision> geometry"),
    ],
)
def test_read_cell_refuses_bad_meshes_and_urdfs(tmp_path, name, text, match):
    _cube_obj(tmp_path / "cube.obj")
    (tmp_path / "garbage.obj").write_text("this is not\na mesh\n")
    (tmp_path / "empty.stl").write_bytes(b"")
    (tmp_path / "dir.obj").mkdir()
    with pytest.raises(InvalidInput, match=match) as err:
        read_cell(_bad(tmp_path, name, text))
    assert "\n" not in str(err.value) and str(tmp_path / name) in str(err.value)


def test_rpy_matrix_is_urdfs_convention():
    """Against Pinocchio's rpyToMatrix (URDF: R = Rz(yaw) Ry(pitch) Rx(roll))."""
    pin = pytest.importorskip("pinocchio")
    from joulepath.program._cell import rpy_matrix

    for rpy in ([0.1, -0.4, 2.0], [1.2, 0.3, -0.7], [0.0, 1.5, 0.0]):
        np.testing.assert_allclose(rpy_matrix(rpy), pin.rpy.rpyToMatrix(*rpy), atol=1e-12)


def test_read_cell_refuses_a_mesh_over_the_limits(tmp_path, monkeypatch):
    from joulepath.program import _cell

    _cube_obj(tmp_path / "cube.obj")
    f = _bad(tmp_path, "a.toml", '[[mesh]]\nname = "m"\nfile = "cube.obj"\ncenter_mm = [0, 0, 0]\n')
    assert read_cell(f).obstacles[0].mesh.num_tris == 12
    monkeypatch.setattr(_cell, "MAX_MESH_TRIANGLES", 11)
    with pytest.raises(InvalidInput, match="12 triangles, over 11; simplify it"):
        read_cell(f)
    monkeypatch.setattr(_cell, "MAX_MESH_BYTES", 100)
    with pytest.raises(InvalidInput, match=r"cube\.obj has .* MiB, over"):
        read_cell(f)
