"""The bridge to Pinocchio: URDF parsing into a :class:`Chain`, and a Chain into a ``pin.Model``.

A URDF is first read with defusedxml and checked in Python (well-formed, no DTD or
entities, named and unique links and joints, known joint types, parents and children
that exist, one tree, finite numbers), so that Pinocchio's C++ parser (urdfdom) only
sees a file it can read. What urdfdom still reports on stderr is captured and turned
into the error message: a URDF it complains about is refused, never half-read.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import defusedxml
import defusedxml.ElementTree as DET
import numpy as np

from joulepath.description._model import Chain
from joulepath.errors import InvalidRobotDescription

_AXES = {
    "JointModelRX": (1.0, 0.0, 0.0),
    "JointModelRY": (0.0, 1.0, 0.0),
    "JointModelRZ": (0.0, 0.0, 1.0),
}
_TOOL_FRAMES = ("tool0", "flange", "ee_link", "tool", "end_effector")
MAX_URDF_BYTES = 16 << 20
"""Largest URDF read (16 MiB); meshes live in other files."""
_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_URDFDOM_WHERE = re.compile(r"\s+at line \d+ in \S+$")


def _short(text: str, n: int = 40) -> str:
    return repr(text if len(text) <= n else text[:n] + "…")


def _numbers(el: ET.Element, attr: str, n: int, where: str, fail: Any) -> None:
    """Check that attribute ``attr`` of ``el`` (when present) holds ``n`` finite numbers."""
    raw = el.get(attr)
    if raw is None:
        return
    parts = raw.split()
    if len(parts) != n or not all(_NUMBER.fullmatch(x) and np.isfinite(float(x)) for x in parts):
        what = f"{n} finite numbers" if n > 1 else "a finite number"
        raise fail(f"{where} <{el.tag} {attr}={_short(raw)}>: expected {what}")


def _check_urdf(data: bytes, p: Path) -> None:
    """Refuse, with one line, a URDF that is not a well-formed tree of named links and joints."""

    def fail(problem: str) -> InvalidRobotDescription:
        return InvalidRobotDescription(f"{p}: {problem}")

    try:
        root = DET.fromstring(data, forbid_dtd=True)
    except defusedxml.DefusedXmlException as err:
        raise fail(
            f"refused ({type(err).__name__}): DTDs and entities are not allowed; remove the <!DOCTYPE>"
        ) from err
    except ET.ParseError as err:
        line, col = err.position
        raise fail(
            f"cannot parse it as URDF: line {line}, column {col}: not well-formed XML ({err})"
        ) from err
    except (LookupError, ValueError) as err:
        raise fail(f"cannot be decoded as XML ({err}); save it as UTF-8") from err
    if root.tag != "robot":
        raise fail(f"the root element is <{str(root.tag)[:40]}>; a URDF starts with <robot name=...>")
    if not (root.get("name") or "").strip():
        raise fail('<robot> has no name; write <robot name="my_arm">')
    links: list[str] = []
    for el in root.findall("link"):
        name = (el.get("name") or "").strip()
        if not name:
            raise fail('a <link> has no name; write <link name="link_1">')
        if name in links:
            raise fail(f"link {_short(name)} appears twice; give each link its own name")
        links.append(name)
        for inertial in el.findall("inertial"):
            where = f"link {_short(name)} <inertial>"
            masses = inertial.findall("mass")
            if len(masses) != 1 or masses[0].get("value") is None:
                raise fail(f'{where}: needs one <mass value="..."/>')
            _numbers(masses[0], "value", 1, where, fail)
            for inertia in inertial.findall("inertia"):
                for attr in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                    if inertia.get(attr) is None:
                        raise fail(f"{where} <inertia>: missing {attr}")
                    _numbers(inertia, attr, 1, where, fail)
            for origin in inertial.findall("origin"):
                _numbers(origin, "xyz", 3, where, fail)
                _numbers(origin, "rpy", 3, where, fail)
    if not links:
        raise fail("has no <link>; a URDF describes links joined by joints")
    joints: list[str] = []
    parent_of: dict[str, str] = {}
    children: dict[str, list[str]] = {}
    for el in root.findall("joint"):
        name = (el.get("name") or "").strip()
        if not name:
            raise fail('a <joint> has no name; write <joint name="joint_1" type="revolute">')
        where = f"joint {_short(name)}"
        if name in joints:
            raise fail(f"{where} appears twice; give each joint its own name")
        joints.append(name)
        jtype = el.get("type")
        if jtype not in _JOINT_TYPES:
            raise fail(f"{where} has type {_short(jtype or '')}; use one of {', '.join(_JOINT_TYPES)}")
        ends = {}
        for end in ("parent", "child"):
            found = el.findall(end)
            link = (found[0].get("link") or "").strip() if len(found) == 1 else ""
            if not link:
                raise fail(f'{where} needs one <{end} link="..."/>')
            if link not in links:
                raise fail(f"{where}: {end} link {_short(link)} is not a <link> of this file")
            ends[end] = link
        if ends["child"] in parent_of:
            raise fail(f"{where}: link {_short(ends['child'])} is the child of two joints; a URDF is a tree")
        if ends["child"] == ends["parent"]:
            raise fail(f"{where}: joins link {_short(ends['child'])} to itself")
        parent_of[ends["child"]] = ends["parent"]
        children.setdefault(ends["parent"], []).append(ends["child"])
        for origin in el.findall("origin"):
            _numbers(origin, "xyz", 3, where, fail)
            _numbers(origin, "rpy", 3, where, fail)
        for axis in el.findall("axis"):
            _numbers(axis, "xyz", 3, where, fail)
        limits = el.findall("limit")
        if jtype in ("revolute", "prismatic") and not limits:
            raise fail(
                f'{where} is {jtype} but has no <limit lower=".." upper=".." velocity=".." effort=".."/>'
            )
        for limit in limits:
            for attr in ("lower", "upper", "velocity", "effort"):
                _numbers(limit, attr, 1, where, fail)
    roots = [link for link in links if link not in parent_of]
    if len(roots) != 1:
        shown = ", ".join(_short(r) for r in roots[:3])
        raise fail(f"has {len(roots)} root links ({shown}); the links must form one tree")
    seen, todo = {roots[0]}, [roots[0]]
    while todo:
        for child in children.get(todo.pop(), []):
            if child not in seen:
                seen.add(child)
                todo.append(child)
    if len(seen) != len(links):
        lost = next(link for link in links if link not in seen)
        raise fail(f"link {_short(lost)} is not connected to the root {_short(roots[0])} (a cycle?)")


@contextmanager
def _stderr_fd_captured() -> Iterator[list[str]]:
    """Redirect file descriptor 2 (where urdfdom writes) to an anonymous file; yield its text after."""
    sys.stderr.flush()
    saved = os.dup(2)
    box: list[str] = []
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield box
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            box.append(tmp.read(1 << 16).decode("utf-8", "replace"))


def _urdfdom_errors(text: str) -> list[str]:
    """``Error:`` lines urdfdom printed, without their C++ source location."""
    out = []
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("Error:"):
            out.append(_URDFDOM_WHERE.sub("", line[len("Error:") :].strip()))
    return out


def _pin() -> Any:
    import pinocchio  # the project's core dependency (package "pin")

    return pinocchio


def _limit(values: Any, *, positive: bool) -> np.ndarray:
    arr = np.array(values, dtype=float)
    bad = ~np.isfinite(arr) | (np.abs(arr) >= 1e10)
    if positive:
        bad |= arr <= 0.0
    arr[bad] = np.nan
    return arr


def chain_from_urdf(path: str | os.PathLike[str], *, tool_frame: str | None = None) -> Chain:
    """Read a URDF of a serial arm with six revolute joints through Pinocchio's parser.

    The tool frame is ``tool_frame`` when given, else the first of
    ``tool0, flange, ee_link, tool, end_effector`` present, else the last link.
    Masses of fixed links are merged into their parent joint's body by Pinocchio.

    Raises
    ------
    InvalidRobotDescription
        Unreadable or malformed file (the message names the element), not six
        joints, a joint that is not a single revolute axis (prismatic, continuous,
        floating), or a branching tree.
    """
    pin = _pin()
    p = Path(path)
    if not p.is_file():
        what = "is a folder" if p.is_dir() else "is not a regular file" if p.exists() else "no such URDF file"
        raise InvalidRobotDescription(f"{p}: {what}; give the path of a .urdf file")
    try:
        if p.stat().st_size > MAX_URDF_BYTES:
            raise InvalidRobotDescription(f"{p}: is larger than {MAX_URDF_BYTES >> 20} MiB; is it a URDF?")
        data = p.read_bytes()
    except OSError as err:
        raise InvalidRobotDescription(f"{p}: cannot be read ({err.strerror})") from err
    _check_urdf(data, p)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise InvalidRobotDescription(f"{p}: not UTF-8 text ({err.reason}); save it as UTF-8") from err
    try:
        with _stderr_fd_captured() as said:
            model = pin.buildModelFromXML(text)
    except (ValueError, RuntimeError) as err:
        errors = _urdfdom_errors(said[0] if said else "")
        why = errors[0] if errors else str(err)
        raise InvalidRobotDescription(f"{p}: Pinocchio cannot parse it as URDF ({why})") from err
    errors = _urdfdom_errors(said[0])
    if errors:  # urdfdom skips an element it cannot read (e.g. a link's <inertial>) and goes on
        raise InvalidRobotDescription(f"{p}: Pinocchio's URDF parser refused part of it ({errors[0]})")
    n = model.njoints - 1
    if n != 6:
        raise InvalidRobotDescription(
            f"{p}: has {n} movable joints; joulepath needs a serial arm with 6 revolute joints "
            '(fix the other joints, type="fixed")'
        )
    axes = np.empty((n, 3))
    for i in range(1, n + 1):
        jm = model.joints[i]
        short = jm.shortname()
        name = model.names[i]
        if short in _AXES:
            axes[i - 1] = _AXES[short]
        elif short == "JointModelRevoluteUnaligned":
            axes[i - 1] = np.asarray(jm.extract().axis, dtype=float)
        else:
            raise InvalidRobotDescription(
                f"{p}: joint {name!r} is {short}, not a single-axis revolute joint with limits; "
                'use type="revolute"'
            )
        if model.parents[i] != i - 1:
            raise InvalidRobotDescription(
                f"{p}: joint {name!r} does not follow joint {model.names[i - 1]!r}: "
                "only serial chains are supported"
            )
    names = [f.name for f in model.frames]
    wanted = (tool_frame,) if tool_frame else _TOOL_FRAMES
    fid = next((model.getFrameId(w) for w in wanted if w in names), None)
    if fid is None:
        if tool_frame:
            raise InvalidRobotDescription(f"{p}: has no frame named {tool_frame!r}")
        fid = max(k for k, f in enumerate(model.frames) if f.parentJoint == n)
    frame = model.frames[fid]
    tool = frame.placement.homogeneous.copy()
    if frame.parentJoint != n:
        raise InvalidRobotDescription(f"{p}: tool frame {frame.name!r} is not on the last joint")
    inert = [model.inertias[i] for i in range(1, n + 1)]
    return Chain(
        name=model.name or p.stem,
        joint_names=tuple(model.names[i] for i in range(1, n + 1)),
        placements=np.array([model.jointPlacements[i].homogeneous for i in range(1, n + 1)]),
        axes=axes,
        masses=np.array([x.mass for x in inert]),
        coms=np.array([np.asarray(x.lever) for x in inert]),
        inertias=np.array([np.asarray(x.inertia) for x in inert]),
        tool=tool,
        lower=_limit(model.lowerPositionLimit, positive=False),
        upper=_limit(model.upperPositionLimit, positive=False),
        velocity=_limit(model.velocityLimit, positive=True),
        effort=_limit(model.effortLimit, positive=True),
        gravity=np.array([0.0, 0.0, -9.80665]),
    )


def pinocchio_model(chain: Chain) -> Any:
    """Build a ``pinocchio.Model`` (joints, bodies, a ``tool0`` frame) from a Chain."""
    pin = _pin()
    model = pin.Model()
    model.name = chain.name
    parent = 0
    for i in range(chain.n_joints):
        placement = pin.SE3(chain.placements[i][:3, :3].copy(), chain.placements[i][:3, 3].copy())
        axis = chain.axes[i]
        short = next((k for k, v in _AXES.items() if np.allclose(axis, v, atol=0.0)), None)
        jm = getattr(pin, short)() if short else pin.JointModelRevoluteUnaligned(axis.copy())
        parent = model.addJoint(parent, jm, placement, chain.joint_names[i])
        body = pin.Inertia(float(chain.masses[i]), chain.coms[i].copy(), chain.inertias[i].copy())
        model.appendBodyToJoint(parent, body, pin.SE3.Identity())
    tool = pin.SE3(chain.tool[:3, :3].copy(), chain.tool[:3, 3].copy())
    model.addFrame(pin.Frame("tool0", parent, tool, pin.FrameType.OP_FRAME))
    model.gravity = pin.Motion(np.concatenate([chain.gravity, np.zeros(3)]))
    return model
