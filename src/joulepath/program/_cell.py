"""The robot cell: obstacles from a small TOML file, and clearance by coal distance queries.

A cell file (mm, base frame)::

    margin_mm = 20                       # every move must clear every obstacle by this much
    [robot]                              # optional: radii of the robot's capsules
    arm_radius_mm = 55
    wrist_radius_mm = 40
    tool_radius_mm = 25
    [[box]]
    name = "table"
    center_mm = [300, 0, -20]
    size_mm = [1200, 1400, 40]
    [[cylinder]]                         # axis along z
    name = "post"
    center_mm = [-350, -350, 500]
    radius_mm = 40
    length_mm = 1000

The robot is approximated by capsules along its links: lower arm (joint 2 to 3), the
elbow offset and upper arm (joint 3 to the wrist centre), the wrist (to the flange)
and the tool (flange to TCP). The base and the first link (which turn about the
vertical axis near the base) are not checked: the robot stands on the cell. The
distances are coal's (Pinocchio's collision library) between those capsules and the
obstacles.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, MissingDependency
from joulepath.kinematics import link_frames


@dataclass(frozen=True, slots=True)
class Obstacle:
    """A box (``size`` = full edge lengths) or a z-axis cylinder (``size`` = radius, radius, length); m."""

    name: str
    kind: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Cell:
    """Obstacles, the clearance margin (m) and the robot's capsule radii (m)."""

    obstacles: tuple[Obstacle, ...]
    margin: float
    arm_radius: float = 0.055
    wrist_radius: float = 0.04
    tool_radius: float = 0.025
    source: str = ""


def _vec(value: object, where: str, n: int = 3) -> tuple[float, float, float]:
    if (
        not isinstance(value, list)
        or len(value) != n
        or not all(isinstance(v, int | float) and np.isfinite(v) for v in value)
    ):
        raise InvalidInput(f"{where}: needs a list of {n} numbers (mm)")
    return (float(value[0]) / 1000, float(value[1]) / 1000, float(value[2]) / 1000)


def _positive(value: object, where: str) -> float:
    if not isinstance(value, int | float) or not (np.isfinite(value) and value > 0):
        raise InvalidInput(f"{where}: needs a positive number of mm")
    return float(value) / 1000


def read_cell(path: str | Path) -> Cell:
    """Read a cell file (TOML); one ``InvalidInput`` line naming the file and entry otherwise."""
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as err:
        raise InvalidInput(f"{p}: cannot be read ({err}); give a TOML cell file") from err
    except tomllib.TOMLDecodeError as err:
        raise InvalidInput(f"{p}: not valid TOML ({err})") from err
    unknown = set(data) - {"margin_mm", "robot", "box", "cylinder"}
    if unknown:
        raise InvalidInput(
            f"{p}: unknown key(s) {sorted(unknown)}; use margin_mm, [robot], [[box]], [[cylinder]]"
        )
    margin = data.get("margin_mm", 20)
    if not isinstance(margin, int | float) or not 0 <= margin <= 1000:
        raise InvalidInput(f"{p}: margin_mm must be a number of mm in [0, 1000]")
    radii = {"arm_radius_mm": 0.055, "wrist_radius_mm": 0.04, "tool_radius_mm": 0.025}
    robot = data.get("robot", {})
    if not isinstance(robot, dict) or set(robot) - set(radii):
        raise InvalidInput(f"{p}: [robot] takes {', '.join(radii)}")
    for key in robot:
        radii[key] = _positive(robot[key], f"{p}: [robot] {key}")
    obstacles: list[Obstacle] = []
    for kind, keys in (
        ("box", {"name", "center_mm", "size_mm"}),
        ("cylinder", {"name", "center_mm", "radius_mm", "length_mm"}),
    ):
        items = data.get(kind, [])
        if not isinstance(items, list):
            raise InvalidInput(f"{p}: {kind} must be an array of tables ([[{kind}]])")
        for k, item in enumerate(items, start=1):
            where = f"{p}: {kind} {k}"
            if not isinstance(item, dict) or set(item) != keys:
                raise InvalidInput(f"{where}: needs exactly {sorted(keys)}")
            name = item["name"]
            if not isinstance(name, str) or not name:
                raise InvalidInput(f"{where}: name must be a text")
            center = _vec(item["center_mm"], f"{where} center_mm")
            if kind == "box":
                size = _vec(item["size_mm"], f"{where} size_mm")
                if min(size) <= 0:
                    raise InvalidInput(f"{where}: size_mm must be positive")
            else:
                r = _positive(item["radius_mm"], f"{where} radius_mm")
                size = (r, r, _positive(item["length_mm"], f"{where} length_mm"))
            obstacles.append(Obstacle(name, kind, center, size))
    if not obstacles:
        raise InvalidInput(f"{p}: no obstacle; add [[box]] or [[cylinder]] tables")
    return Cell(
        tuple(obstacles),
        float(margin) / 1000,
        radii["arm_radius_mm"],
        radii["wrist_radius_mm"],
        radii["tool_radius_mm"],
        str(p),
    )


def _coal() -> Any:
    try:
        import coal
    except ImportError as err:  # pragma: no cover - coal comes with pin
        raise MissingDependency("collision checks need coal (installed with the 'pin' package)") from err
    return coal


def _segments(robot: Robot, q: FloatArray, tcp: FloatArray) -> list[tuple[FloatArray, FloatArray]]:
    """Capsule axes (start, end), each (K, 3): lower arm, upper arm, wrist, tool."""
    frames = link_frames(robot.chain, q)
    origin = frames[..., :3, 3]
    tool0 = frames[..., -1, :, :] @ robot.chain.tool
    tip = tool0[..., :3, 3] + np.einsum("kij,j->ki", tool0[..., :3, :3], tcp[:3, 3])
    wrist = origin[..., 4, :]
    return [
        (origin[..., 1, :], origin[..., 2, :]),
        (origin[..., 2, :], origin[..., 3, :]),
        (origin[..., 3, :], wrist),
        (wrist, tool0[..., :3, 3]),
        (tool0[..., :3, 3], tip),
    ]


def _frame(a: FloatArray, b: FloatArray) -> tuple[FloatArray, FloatArray, float]:
    d = b - a
    length = float(np.linalg.norm(d))
    z = d / length if length > 1e-12 else np.array([0.0, 0.0, 1.0])
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z]), 0.5 * (a + b), length


@dataclass(frozen=True, slots=True)
class Clearance:
    """The smallest distance (m) from the robot to an obstacle along a motion, where, and to what."""

    distance: float
    obstacle: str
    sample: int


def clearance(cell: Cell, robot: Robot, q: FloatArray, tcp: FloatArray) -> Clearance:
    """Smallest capsule-obstacle distance over the configurations ``q`` (K, n); negative: penetration."""
    coal = _coal()
    shapes = []
    for ob in cell.obstacles:
        geom = coal.Box(*ob.size) if ob.kind == "box" else coal.Cylinder(ob.size[0], ob.size[2])
        shapes.append((ob.name, geom, coal.Transform3s(np.eye(3), np.asarray(ob.center))))
    radii = (cell.arm_radius, cell.arm_radius, cell.arm_radius, cell.wrist_radius, cell.tool_radius)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    segs = _segments(robot, q, tcp)
    req = coal.DistanceRequest()
    res = coal.DistanceResult()
    best = Clearance(np.inf, "", -1)
    for k in range(q.shape[0]):
        for (a, b), r in zip(segs, radii, strict=True):
            rot, mid, length = _frame(a[k], b[k])
            cap = coal.Capsule(r, length)
            tf = coal.Transform3s(rot, mid)
            for name, geom, gtf in shapes:
                res.clear()
                d = float(coal.distance(cap, tf, geom, gtf, req, res))
                if d < best.distance:
                    best = Clearance(d, name, k)
    return best
