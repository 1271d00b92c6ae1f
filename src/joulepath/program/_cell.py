"""The robot cell: obstacles from a small TOML file or a URDF, and clearance by coal distance queries.

A cell file (TOML; mm and degrees, in the robot's base frame)::

    margin_mm = 20                       # every move must clear every obstacle by this much
    [robot]                              # optional: radii of the robot's capsules
    arm_radius_mm = 55
    wrist_radius_mm = 40
    tool_radius_mm = 25
    [[box]]
    name = "table"
    center_mm = [300, 0, -20]
    size_mm = [1200, 1400, 40]           # full edge lengths
    [[cylinder]]                         # axis along z (before rpy_deg)
    name = "post"
    center_mm = [-350, -350, 500]
    radius_mm = 40
    length_mm = 1000
    [[sphere]]
    name = "lamp"
    center_mm = [0, 600, 900]
    radius_mm = 100
    [[mesh]]                             # a triangle mesh: STL or OBJ
    name = "fixture"
    file = "fixture.stl"                 # relative to the cell file
    center_mm = [450, 200, 0]            # where the mesh's origin goes
    rpy_deg = [0, 0, 90]                 # optional
    scale = 0.001                        # optional: one number or three; 0.001 for a mesh in mm

Every obstacle may carry ``rpy_deg`` (roll, pitch, yaw about the fixed x, y, z axes, as in
URDF: ``R = Rz(yaw) Ry(pitch) Rx(roll)``); the shape is rotated about its ``center_mm``.
Mesh coordinates are read as metres (as in URDF), times ``scale``. A mesh is read with
coal's loader (assimp; nothing in it is executed): a missing, non-regular, empty or
malformed file, one over 50 MB or over 1e6 triangles is refused. A mesh is a surface:
distances are to its triangles, so a robot part wholly inside a closed mesh is not seen.

A URDF cell (``.urdf``) is read with defusedxml (no DTD, no entities). Every link's
``<collision>`` geometry (``box``, ``cylinder``, ``sphere``, ``mesh``) becomes an obstacle,
placed by the chain of joints from the root link, whose frame is the robot's base frame,
and by the collision's own ``<origin>``. Every joint must be ``fixed`` (a cell is static).
Mesh file names are relative to the URDF (or ``file://`` absolute); ``package://`` is
refused. A URDF cell has the TOML format's default margin (20 mm) and capsule radii.

The robot is approximated by capsules along its links: lower arm (joint 2 to 3), the
elbow offset and upper arm (joint 3 to the wrist centre), the wrist (to the flange)
and the tool (flange to TCP). The base and the first link (which turn about the
vertical axis near the base) are not checked: the robot stands on the cell. The
distances are coal's (Pinocchio's collision library) between those capsules and the
obstacles.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import defusedxml
import defusedxml.ElementTree as DET
import numpy as np

from joulepath._io import finite_number, load_toml, read_capped
from joulepath._typing import FloatArray
from joulepath._work import check_work
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, MissingDependency
from joulepath.kinematics import link_frames

DEFAULT_MARGIN_MM = 20.0
"""Clearance margin of a TOML cell without ``margin_mm`` and of every URDF cell."""
MAX_MESH_BYTES = 50 << 20
"""Largest mesh file read (50 MiB)."""
MAX_MESH_TRIANGLES = 1_000_000
"""Most triangles in one mesh."""
MAX_URDF_BYTES = 16 << 20
"""Largest URDF cell read (16 MiB); meshes live in other files."""
MAX_CELL_FILE_BYTES = 4 << 20
"""Largest TOML cell file read."""
_FEWER_TRIANGLES = "simplify the meshes (a cell needs coarse hulls: a few thousand triangles each)"
_MESH_SUFFIXES = (".stl", ".obj")
_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
Rotation = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]
Progress = Callable[[str], None]
"""A progress callback: told what is being done now (the caller decides whether and how to show it)."""


def _quiet(message: str) -> None:
    """The progress callback of a caller that gave none."""


@dataclass(frozen=True, slots=True)
class Obstacle:
    """One obstacle, placed at ``center`` (m) with ``rotation`` (3x3, rows), in the base frame.

    ``size``: a box's full edge lengths; a cylinder's (radius, radius, length), axis along
    its z; a sphere's (radius, radius, radius); a mesh's scale factors. ``mesh`` holds a
    mesh's coal ``BVHModel`` (scaled, in its own frame) and ``file`` its path.
    """

    name: str
    kind: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]
    rotation: Rotation = _IDENTITY
    mesh: Any = field(default=None, compare=False, repr=False)
    file: str = ""


@dataclass(frozen=True, slots=True)
class Cell:
    """Obstacles, the clearance margin (m) and the robot's capsule radii (m)."""

    obstacles: tuple[Obstacle, ...]
    margin: float
    arm_radius: float = 0.055
    wrist_radius: float = 0.04
    tool_radius: float = 0.025
    source: str = ""

    @property
    def files(self) -> tuple[str, ...]:
        """The mesh files the cell reads, besides its own file."""
        return tuple(dict.fromkeys(ob.file for ob in self.obstacles if ob.file))


MAX_CELL_MM = 1e6
"""Largest coordinate or size in a cell file, mm (a kilometre: anything beyond is a typo)."""


def _is_number(value: object, bound: float = MAX_CELL_MM) -> bool:
    """A TOML number (never ``true``/``false``), finite and within ``±bound``."""
    return isinstance(value, int | float) and not isinstance(value, bool) and abs(value) <= bound


def _vec(value: object, where: str, n: int = 3) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) != n or not all(_is_number(v) for v in value):
        raise InvalidInput(f"{where}: needs a list of {n} numbers (mm, within ±{MAX_CELL_MM:g})")
    return (float(value[0]) / 1000, float(value[1]) / 1000, float(value[2]) / 1000)


def _positive(value: object, where: str) -> float:
    if not _is_number(value) or not value > 0:  # type: ignore[operator]
        raise InvalidInput(f"{where}: needs a positive number of mm (at most {MAX_CELL_MM:g})")
    return float(value) / 1000  # type: ignore[arg-type]


def rpy_matrix(rpy: tuple[float, float, float] | FloatArray) -> FloatArray:
    """URDF's rotation ``Rz(yaw) @ Ry(pitch) @ Rx(roll)`` for ``rpy`` = (roll, pitch, yaw), rad."""
    r, p, y = (float(v) for v in rpy)
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _rotation(matrix: FloatArray) -> Rotation:
    rows = [(float(a), float(b), float(c)) for a, b, c in np.asarray(matrix, dtype=float)]
    return (rows[0], rows[1], rows[2])


def _scale(value: object, where: str) -> tuple[float, float, float]:
    values: list[Any] = [value] * 3 if not isinstance(value, list) else value
    if len(values) != 3 or not all(_is_number(v, 1e6) and v > 0 for v in values):
        raise InvalidInput(f"{where}: scale must be a positive number or a list of 3 positive numbers")
    return (float(values[0]), float(values[1]), float(values[2]))


def _coal_message(err: Exception) -> str:
    """The ``message:`` part of a coal/assimp error, on one line."""
    text = str(err)
    if "message:" in text:
        text = text.split("message:", 1)[1]
    return " ".join(text.split())[:200]


_STL_RECORD = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
_TEXT_VERTEX = re.compile(rb"^[ \t]*(?:vertex|v)[ \t]+(\S+)[ \t]+(\S+)[ \t]+(\S+)", re.MULTILINE)


def _refuse_nonfinite_vertices(path: Path, where: str) -> None:
    """Refuse a mesh with a NaN or infinite vertex coordinate (binary STL, ASCII STL or OBJ).

    Coordinates that are not numbers at all are left to coal's loader, which refuses them.
    """
    data = path.read_bytes()  # size checked by the caller
    n = int(np.frombuffer(data[80:84], "<u4")[0]) if len(data) >= 84 else -1
    if n >= 0 and len(data) == 84 + 50 * n:  # binary STL
        coords = np.frombuffer(data, _STL_RECORD, count=n, offset=84)["vertices"].astype(float)
    else:
        rows = _TEXT_VERTEX.findall(data)
        try:
            coords = np.asarray(rows, dtype=bytes).astype(float)
        except ValueError:  # a coordinate that is no number: coal refuses the file
            coords = np.empty(0)
    if coords.size and not np.isfinite(coords).all():
        raise InvalidInput(
            f"{where}: mesh {path} has vertices that are not finite numbers (NaN or infinity); "
            "export the mesh again"
        )


def load_mesh(
    path: Path, scale: tuple[float, float, float], where: str, *, progress: Progress = _quiet
) -> Any:
    """A mesh file (STL or OBJ) as a coal ``BVHModel``, scaled; ``InvalidInput`` if it cannot be used.

    ``progress`` is told when the file is checked and when coal reads it and builds its
    bounding-volume hierarchy (the collision model; seconds for 10⁵ triangles).
    """
    if path.suffix.lower() not in _MESH_SUFFIXES:
        raise InvalidInput(f"{where}: mesh {path} is not .stl or .obj; export it as STL or OBJ")
    if not path.exists():
        raise InvalidInput(f"{where}: mesh {path} does not exist (paths are relative to the cell file)")
    if not path.is_file():
        raise InvalidInput(f"{where}: mesh {path} is not a regular file")
    try:
        n_bytes = path.stat().st_size
        with path.open("rb") as fh:
            head = fh.read(84)
    except OSError as err:
        raise InvalidInput(f"{where}: mesh {path} cannot be read ({err.strerror})") from err
    if n_bytes == 0:
        raise InvalidInput(f"{where}: mesh {path} is empty")
    if n_bytes > MAX_MESH_BYTES:
        raise InvalidInput(
            f"{where}: mesh {path} has {n_bytes / 2**20:.1f} MiB, over {MAX_MESH_BYTES / 2**20:g} MiB; "
            "simplify it (a cell needs a coarse hull)"
        )
    n_binary = int.from_bytes(head[80:84], "little") if len(head) == 84 else -1
    binary = path.suffix.lower() == ".stl" and n_bytes == 84 + 50 * n_binary
    if binary:  # a binary STL: counted unread
        check_work("triangles", n_binary, f"{where}: mesh {path}", _FEWER_TRIANGLES)
    size = f"{n_binary:,} triangles" if binary else f"{n_bytes / 2**20:.1f} MiB"
    progress(f"{where}: checking the vertices of mesh {path.name} ({size})")
    _refuse_nonfinite_vertices(path, where)  # before coal: its OBB fit chokes (and prints) on NaN
    progress(f"{where}: building the collision model of mesh {path.name} ({size})")
    coal = _coal()
    try:
        model = coal.MeshLoader().load(str(path), np.asarray(scale, dtype=float))
    except (ValueError, RuntimeError) as err:
        raise InvalidInput(f"{where}: mesh {path} cannot be read: {_coal_message(err)}") from err
    n_tris = int(model.num_tris)
    if n_tris == 0:
        raise InvalidInput(f"{where}: mesh {path} has no triangles")
    check_work("triangles", n_tris, f"{where}: mesh {path}", _FEWER_TRIANGLES)
    if n_tris > MAX_MESH_TRIANGLES:
        raise InvalidInput(
            f"{where}: mesh {path} has {n_tris} triangles, over {MAX_MESH_TRIANGLES}; simplify it"
        )
    if not np.isfinite(np.asarray(model.vertices())).all():
        raise InvalidInput(f"{where}: mesh {path} has vertices that are not finite numbers")
    return model


_KINDS: dict[str, tuple[set[str], set[str]]] = {
    # kind: (required keys, optional keys)
    "box": ({"name", "center_mm", "size_mm"}, {"rpy_deg"}),
    "cylinder": ({"name", "center_mm", "radius_mm", "length_mm"}, {"rpy_deg"}),
    "sphere": ({"name", "center_mm", "radius_mm"}, set()),
    "mesh": ({"name", "file", "center_mm"}, {"rpy_deg", "scale"}),
}


def _toml_obstacle(
    kind: str, item: dict[str, Any], where: str, base: Path, progress: Progress = _quiet
) -> Obstacle:
    name = item["name"]
    if not isinstance(name, str) or not name:
        raise InvalidInput(f"{where}: name must be a text")
    center = _vec(item["center_mm"], f"{where} center_mm")
    rotation = _IDENTITY
    if "rpy_deg" in item:
        rpy = item["rpy_deg"]
        if not isinstance(rpy, list) or len(rpy) != 3 or not all(_is_number(v) for v in rpy):
            raise InvalidInput(f"{where} rpy_deg: needs a list of 3 numbers (degrees)")
        rotation = _rotation(rpy_matrix(np.radians(rpy)))
    if kind == "box":
        size = _vec(item["size_mm"], f"{where} size_mm")
        if min(size) <= 0:
            raise InvalidInput(f"{where}: size_mm must be positive")
        return Obstacle(name, kind, center, size, rotation)
    if kind == "cylinder":
        r = _positive(item["radius_mm"], f"{where} radius_mm")
        return Obstacle(
            name, kind, center, (r, r, _positive(item["length_mm"], f"{where} length_mm")), rotation
        )
    if kind == "sphere":
        r = _positive(item["radius_mm"], f"{where} radius_mm")
        return Obstacle(name, kind, center, (r, r, r))
    file = item["file"]
    if not isinstance(file, str) or not file:
        raise InvalidInput(f"{where}: file must be a text (a path relative to the cell file)")
    scale = _scale(item.get("scale", 1.0), where)
    path = base / file
    mesh = load_mesh(path, scale, where, progress=progress)
    return Obstacle(name, kind, center, scale, rotation, mesh, str(path))


def read_cell(path: str | Path, *, progress: Progress | None = None) -> Cell:
    """Read a cell file: TOML, or a URDF for ``.urdf``.

    ``progress`` (optional) is told each obstacle read and each mesh loaded, once the
    file's size, obstacle count and triangle counts are within their limits.
    A file that cannot be used raises ``InvalidInput``: one line naming the file and entry.
    """
    p = Path(path)
    say = progress or _quiet
    if p.suffix.lower() == ".urdf":
        return read_urdf_cell(p, progress=say)
    data = load_toml(p, max_bytes=MAX_CELL_FILE_BYTES, what="a TOML cell file")
    allowed = {"margin_mm", "robot", *_KINDS}
    unknown = set(data) - allowed
    if unknown:
        raise InvalidInput(
            f"{p}: unknown key(s) {sorted(unknown)}; use margin_mm, [robot], "
            + ", ".join(f"[[{k}]]" for k in _KINDS)
        )
    margin = finite_number(
        data.get("margin_mm", DEFAULT_MARGIN_MM), f"{p}: margin_mm", lo=0, hi=1000, unit="mm"
    )
    radii = {"arm_radius_mm": 0.055, "wrist_radius_mm": 0.04, "tool_radius_mm": 0.025}
    robot = data.get("robot", {})
    if not isinstance(robot, dict) or set(robot) - set(radii):
        raise InvalidInput(f"{p}: [robot] takes {', '.join(radii)}")
    for key in robot:
        radii[key] = _positive(robot[key], f"{p}: [robot] {key}")
    obstacles: list[Obstacle] = []
    for kind, (required, optional) in _KINDS.items():
        items = data.get(kind, [])
        if not isinstance(items, list):
            raise InvalidInput(f"{p}: {kind} must be an array of tables ([[{kind}]])")
        check_work(
            "obstacles",
            len(obstacles) + len(items),
            str(p),
            "merge neighbouring obstacles into one box, or cover the area with one coarse mesh",
        )
        for k, item in enumerate(items, start=1):
            where = f"{p}: {kind} {k}"
            if not isinstance(item, dict) or not required <= set(item) <= required | optional:
                extra = f" (optional: {sorted(optional)})" if optional else ""
                raise InvalidInput(f"{where}: needs exactly {sorted(required)}{extra}")
            say(f"reading the cell: {kind} {k}/{len(items)}")
            obstacles.append(_toml_obstacle(kind, item, where, p.parent, say))
    if not obstacles:
        raise InvalidInput(f"{p}: no obstacle; add " + ", ".join(f"[[{k}]]" for k in _KINDS) + " tables")
    check_work(
        "triangles",
        sum(int(o.mesh.num_tris) for o in obstacles if o.mesh is not None),
        str(p),
        _FEWER_TRIANGLES,
    )
    return Cell(
        tuple(obstacles),
        float(margin) / 1000,
        radii["arm_radius_mm"],
        radii["wrist_radius_mm"],
        radii["tool_radius_mm"],
        str(p),
    )


# ----------------------------------------------------------------------------- URDF cells
def _floats(el: ET.Element | None, attr: str, n: int, default: str | None, where: str) -> FloatArray:
    raw = el.get(attr) if el is not None else None
    if raw is None:
        if default is None:
            tag = el.tag if el is not None else "?"
            raise InvalidInput(f'{where}: <{tag}> needs {attr}="..." ({n} number{"s" if n > 1 else ""})')
        raw = default
    try:
        values = np.array([float(v) for v in raw.split()])
    except ValueError:
        values = np.array([])
    if values.shape != (n,) or not np.isfinite(values).all():
        shown = raw if len(raw) <= 40 else raw[:40] + "…"
        raise InvalidInput(f"{where}: {attr}={shown!r} must be {n} finite number{'s' if n > 1 else ''}")
    return values


def _origin(el: ET.Element, where: str) -> FloatArray:
    """The 4x4 transform of ``el``'s ``<origin xyz rpy>`` (identity without one)."""
    origins = el.findall("origin")
    if len(origins) > 1:
        raise InvalidInput(f"{where}: more than one <origin>")
    o = origins[0] if origins else None
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(_floats(o, "rpy", 3, "0 0 0", where))
    T[:3, 3] = _floats(o, "xyz", 3, "0 0 0", where)
    return T


def _urdf_geometry(
    col: ET.Element, name: str, T: FloatArray, where: str, base: Path, progress: Progress = _quiet
) -> Obstacle:
    geoms = col.findall("geometry")
    shapes = [s for g in geoms for s in g]
    if len(geoms) != 1 or len(shapes) != 1:
        raise InvalidInput(f"{where}: needs one <geometry> holding one box, cylinder, sphere or mesh")
    s = shapes[0]
    center = (float(T[0, 3]), float(T[1, 3]), float(T[2, 3]))
    rotation = _rotation(T[:3, :3])
    kind = s.tag
    if kind == "box":
        size = _floats(s, "size", 3, None, where)
        if (size <= 0).any():
            raise InvalidInput(f"{where}: <box size> must be positive")
        return Obstacle(name, "box", center, (size[0], size[1], size[2]), rotation)
    if kind in ("cylinder", "sphere"):
        r = float(_floats(s, "radius", 1, None, where)[0])
        length = float(_floats(s, "length", 1, None, where)[0]) if kind == "cylinder" else r
        if r <= 0 or length <= 0:
            raise InvalidInput(f"{where}: <{kind}> radius and length must be positive")
        return Obstacle(name, kind, center, (r, r, length), rotation)
    if kind == "mesh":
        filename = (s.get("filename") or "").strip()
        if not filename:
            raise InvalidInput(f'{where}: <mesh> needs filename="..." (relative to the URDF)')
        if filename.startswith("package://"):
            raise InvalidInput(
                f"{where}: mesh {filename!r}: package:// paths are not resolved (no ROS here); "
                "give the file relative to the URDF"
            )
        if filename.startswith("file://"):
            filename = filename[len("file://") :]
        elif "://" in filename:
            raise InvalidInput(f"{where}: mesh {filename!r}: only files relative to the URDF are read")
        f = _floats(s, "scale", 3, "1 1 1", where)
        if (f <= 0).any():
            raise InvalidInput(f"{where}: <mesh scale> must be positive")
        scale = (float(f[0]), float(f[1]), float(f[2]))
        path = base / filename
        mesh = load_mesh(path, scale, where, progress=progress)
        return Obstacle(name, "mesh", center, scale, rotation, mesh, str(path))
    raise InvalidInput(f"{where}: <{str(kind)[:20]}> is not a box, cylinder, sphere or mesh")


def read_urdf_cell(path: str | Path, *, progress: Progress | None = None) -> Cell:
    """Read a URDF of the cell: every link's collision geometry, placed by fixed joints from the root.

    The root link's frame is the robot's base frame; the margin is ``DEFAULT_MARGIN_MM``.
    ``progress`` (optional) is told each collision geometry read and each mesh loaded.
    """
    say = progress or _quiet
    p = Path(path)
    data = read_capped(p, max_bytes=MAX_URDF_BYTES, what="a URDF or TOML cell file")
    try:
        root = DET.fromstring(data, forbid_dtd=True)
    except defusedxml.DefusedXmlException as err:
        raise InvalidInput(f"{p}: refused ({type(err).__name__}): DTDs and entities are not allowed") from err
    except ET.ParseError as err:
        line, col = err.position
        raise InvalidInput(f"{p}: not well-formed XML at line {line}, column {col} ({err})") from err
    except (LookupError, ValueError) as err:
        raise InvalidInput(f"{p}: cannot be decoded as XML ({err}); save it as UTF-8") from err
    if root.tag != "robot":
        raise InvalidInput(f"{p}: the root element is <{str(root.tag)[:40]}>; a URDF starts with <robot>")
    links: dict[str, ET.Element] = {}
    for el in root.findall("link"):
        name = (el.get("name") or "").strip()
        if not name or name in links:
            raise InvalidInput(f"{p}: a <link> has no name or a name used twice ({name!r})")
        links[name] = el
    children: dict[str, list[tuple[str, FloatArray]]] = {}
    parent_of: dict[str, str] = {}
    for el in root.findall("joint"):
        name = (el.get("name") or "").strip()
        where = f"{p}: joint {name!r}"
        jtype = el.get("type")
        if jtype != "fixed":
            raise InvalidInput(
                f'{where} is {jtype!r}; a cell is static: make every joint fixed (type="fixed")'
            )
        ends = []
        for end in ("parent", "child"):
            found = el.findall(end)
            link = (found[0].get("link") or "").strip() if len(found) == 1 else ""
            if link not in links:
                raise InvalidInput(f'{where}: needs one <{end} link="..."/> naming a <link> of this file')
            ends.append(link)
        parent, child = ends
        if child in parent_of or child == parent:
            raise InvalidInput(f"{where}: link {child!r} has two parents (or itself); a URDF is a tree")
        parent_of[child] = parent
        children.setdefault(parent, []).append((child, _origin(el, where)))
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        raise InvalidInput(f"{p}: has {len(roots)} root links; the links must form one tree")
    pose = {roots[0]: np.eye(4)}
    todo = [roots[0]]
    while todo:
        link = todo.pop()
        for child, T in children.get(link, []):
            if child not in pose:
                pose[child] = pose[link] @ T
                todo.append(child)
    if len(pose) != len(links):
        lost = next(name for name in links if name not in pose)
        raise InvalidInput(f"{p}: link {lost!r} is not connected to the root {roots[0]!r}")
    obstacles: list[Obstacle] = []
    n_collisions = sum(len(el.findall("collision")) for el in links.values())
    check_work(
        "obstacles",
        n_collisions,
        str(p),
        "merge neighbouring collision shapes into one box, or cover the area with one coarse mesh",
    )
    for name, el in links.items():
        cols = el.findall("collision")
        for n, collision in enumerate(cols, start=1):
            label = collision.get("name") or (name if len(cols) == 1 else f"{name}/{n}")
            at = f"{p}: link {name!r} collision {n}"
            T = pose[name] @ _origin(collision, at)
            say(f"reading the cell: collision {len(obstacles) + 1}/{n_collisions}")
            obstacles.append(_urdf_geometry(collision, label, T, at, p.parent, say))
    if not obstacles:
        raise InvalidInput(f"{p}: no <collision> geometry in any link; a cell needs obstacles")
    check_work(
        "triangles",
        sum(int(o.mesh.num_tris) for o in obstacles if o.mesh is not None),
        str(p),
        _FEWER_TRIANGLES,
    )
    return Cell(tuple(obstacles), DEFAULT_MARGIN_MM / 1000, source=str(p))


def _coal() -> Any:
    try:
        import coal
    except ImportError as err:  # pragma: no cover - coal comes with pin
        raise MissingDependency("collision checks need coal (installed with the 'pin' package)") from err
    return coal


def _geometry(coal: Any, ob: Obstacle) -> Any:
    """The coal shape of an obstacle, in its own frame."""
    if ob.kind == "box":
        return coal.Box(*ob.size)
    if ob.kind == "cylinder":
        return coal.Cylinder(ob.size[0], ob.size[2])
    if ob.kind == "sphere":
        return coal.Sphere(ob.size[0])
    if ob.kind == "mesh" and ob.mesh is not None:
        return ob.mesh
    raise InvalidInput(f"obstacle {ob.name!r}: unknown kind {ob.kind!r} (or a mesh without its model)")


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
    shapes = [
        (ob.name, _geometry(coal, ob), coal.Transform3s(np.asarray(ob.rotation), np.asarray(ob.center)))
        for ob in cell.obstacles
    ]
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
