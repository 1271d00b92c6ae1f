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


_CONTINUOUS = {
    "JointModelRUBX": (1.0, 0.0, 0.0),
    "JointModelRUBY": (0.0, 1.0, 0.0),
    "JointModelRUBZ": (0.0, 0.0, 1.0),
}
MIN_JOINTS, MAX_JOINTS = 5, 7
"""Actuated joints of the arms joulepath takes (after locking)."""
CONTINUOUS_RANGE = 2 * np.pi
"""rad each way given to a continuous joint (the URDF gives it no range)."""
_GRIPPER_LIKE = re.compile(r"grip|finger|jaw|hand|claw|tool_?changer", re.I)


def _kind(short: str) -> str:
    """A Pinocchio joint model's short name in URDF words."""
    if short in _AXES or short == "JointModelRevoluteUnaligned":
        return "revolute"
    if short in _CONTINUOUS or short == "JointModelRevoluteUnboundedUnaligned":
        return "continuous"
    if short.startswith("JointModelP") and not short.startswith("JointModelPlanar"):
        return "prismatic"
    if short == "JointModelFreeFlyer":
        return "floating"
    if short == "JointModelPlanar":
        return "planar"
    if short == "JointModelMimic":
        return "mimic"
    return short.removeprefix("JointModel").lower()


def _vec(el: ET.Element | None, attr: str, default: str) -> np.ndarray:
    raw = el.get(attr) if el is not None else None
    return np.array([float(v) for v in (raw or default).split()])


MAX_LOCK_ANGLE = 2 * np.pi
"""rad: the largest lock value of a joint without a range (a continuous one): one turn either way."""
MAX_LOCK_TRAVEL = 10.0
"""m: the largest lock value of a prismatic joint without a range."""


def _check_lock_value(el: Any, name: str, value: float, p: Path) -> None:
    """Refuse a lock value outside the joint's ``<limit>`` range (or one turn, 10 m without one)."""
    unit = "m" if el.get("type") == "prismatic" else "rad"
    limit = el.find("limit")
    lo = hi = None
    if el.get("type") != "continuous" and limit is not None:
        try:
            lo, hi = float(limit.get("lower", "nan")), float(limit.get("upper", "nan"))
        except ValueError:
            lo = hi = None
    if lo is not None and hi is not None and np.isfinite(lo) and np.isfinite(hi) and lo <= hi:
        if not lo - 1e-9 <= value <= hi + 1e-9:
            raise InvalidRobotDescription(
                f"{p}: the lock value {value:g} {unit} of joint {name!r} is outside its range "
                f"[{lo:g}, {hi:g}] {unit}; lock it within the range"
            )
        return
    bound = MAX_LOCK_TRAVEL if unit == "m" else MAX_LOCK_ANGLE
    if not abs(value) <= bound:
        raise InvalidRobotDescription(
            f"{p}: the lock value {value:g} {unit} of joint {name!r} is beyond ±{bound:g} {unit}; "
            "give a value within one turn (or 10 m)"
        )


def _lock_in_urdf(data: bytes, lock: dict[str, float], p: Path) -> str:
    """The URDF text with the joints of ``lock`` made fixed at the given values (rad, or m).

    A locked joint becomes ``type="fixed"`` with its origin moved by the value about
    (or along) its axis, so Pinocchio merges the links beyond it into the arm.
    """
    pin = _pin()
    root = DET.fromstring(data, forbid_dtd=True)
    joints = {(el.get("name") or "").strip(): el for el in root.findall("joint")}
    movable = [n for n, el in joints.items() if el.get("type") != "fixed"]
    for name, value in lock.items():
        el = joints.get(name)
        if el is None or el.get("type") == "fixed":
            raise InvalidRobotDescription(
                f"{p}: has no movable joint {name!r} to lock; its movable joints: {', '.join(movable)}"
            )
        if not np.isfinite(value):
            raise InvalidRobotDescription(f"{p}: the lock value of joint {name!r} is not a finite number")
        kind = el.get("type")
        if kind not in ("revolute", "continuous", "prismatic"):
            raise InvalidRobotDescription(f"{p}: joint {name!r} is {kind}; only a 1-axis joint can be locked")
        _check_lock_value(el, name, value, p)
        origin = el.find("origin")
        xyz, rpy = _vec(origin, "xyz", "0 0 0"), _vec(origin, "rpy", "0 0 0")
        axis = _vec(el.find("axis"), "xyz", "1 0 0")
        if not np.linalg.norm(axis) > 0:
            raise InvalidRobotDescription(f"{p}: joint {name!r} has a zero axis")
        axis = axis / np.linalg.norm(axis)
        placement = pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)
        if kind == "prismatic":
            motion = pin.SE3(np.eye(3), axis * value)
        else:
            motion = pin.SE3(pin.AngleAxis(value, axis).toRotationMatrix(), np.zeros(3))
        moved = placement * motion
        if origin is None:
            origin = ET.SubElement(el, "origin")
        origin.set("xyz", " ".join(repr(float(v)) for v in moved.translation))
        origin.set("rpy", " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(moved.rotation)))
        el.set("type", "fixed")
        for tag in ("axis", "limit", "mimic", "dynamics", "safety_controller", "calibration"):
            for child in el.findall(tag):
                el.remove(child)
    for el in root.findall("joint"):  # a joint mimicking a locked one can no longer follow it
        mimic = el.find("mimic")
        if mimic is not None and mimic.get("joint") in lock:
            el.remove(mimic)
    return ET.tostring(root, encoding="unicode")


def chain_from_urdf(
    path: str | os.PathLike[str],
    *,
    tool_frame: str | None = None,
    lock: dict[str, float] | None = None,
    name: str | None = None,
) -> Chain:
    """Read a URDF of a serial arm of 5 to 7 revolute joints through Pinocchio's parser.

    The tool frame is ``tool_frame`` when given, else the first of
    ``tool0, flange, ee_link, tool, end_effector`` present, else the last link.
    Masses of fixed links are merged into their parent joint's body by Pinocchio.
    ``lock`` fixes joints at the given values first (``{"panda_finger_joint1": 0.0}``;
    rad, or m for a prismatic joint): the way to use an arm whose URDF carries a
    gripper, mimic joints or a branch. A continuous joint is taken as revolute with
    the range ±360° (:data:`CONTINUOUS_RANGE`, noted on the chain); a joint named like
    a gripper or finger gives a warning (:attr:`Chain.notes`).

    Raises
    ------
    InvalidRobotDescription
        Unreadable or malformed file (the message names the element); a prismatic,
        floating or other non-revolute joint; a tree-shaped robot; fewer than 5 or
        more than 7 movable joints. Each message names the joints and how to fix it.
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
    if lock:
        text = _lock_in_urdf(data, dict(lock), p)
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
    hint = "lock it (--lock NAME=VALUE, or load_robot(..., lock={...})) or make it fixed in the URDF"
    for i in range(1, n + 1):
        kind = _kind(model.joints[i].shortname())
        if kind not in ("revolute", "continuous"):
            raise InvalidRobotDescription(
                f"{p}: joint {model.names[i]!r} is {kind}; joulepath takes arms of revolute joints only: "
                + hint.replace("NAME", model.names[i])
            )
    for i in range(1, n + 1):
        if model.parents[i] != i - 1:
            parent = model.parents[i]
            siblings = [model.names[k] for k in range(1, n + 1) if model.parents[k] == parent]
            after = repr(model.names[parent]) if parent else "the base"
            raise InvalidRobotDescription(
                f"{p}: is tree-shaped: joints {', '.join(map(repr, siblings))} all follow {after}; "
                f"joulepath takes one serial chain: {hint} for every joint off the arm"
            )
    names_all = [model.names[i] for i in range(1, n + 1)]
    if not MIN_JOINTS <= n <= MAX_JOINTS:
        raise InvalidRobotDescription(
            f"{p}: has {n} movable joint{'s' if n != 1 else ''} ({', '.join(names_all)}); joulepath takes "
            f"serial arms of {MIN_JOINTS} to {MAX_JOINTS} revolute joints"
            + (
                "; lock the extra ones (--lock NAME=VALUE) or make them fixed in the URDF"
                if n > MAX_JOINTS
                else ""
            )
        )
    axes = np.empty((n, 3))
    lower, upper = np.empty(n), np.empty(n)
    velocity, effort = np.empty(n), np.empty(n)
    notes: list[tuple[str, str]] = []
    raw_lo = _limit(model.lowerPositionLimit, positive=False)
    raw_hi = _limit(model.upperPositionLimit, positive=False)
    raw_v = _limit(model.velocityLimit, positive=True)
    raw_e = _limit(model.effortLimit, positive=True)
    for i in range(1, n + 1):
        jm = model.joints[i]
        short = jm.shortname()
        jname = model.names[i]
        if short in _AXES:
            axes[i - 1] = _AXES[short]
        elif short in _CONTINUOUS:
            axes[i - 1] = _CONTINUOUS[short]
        else:
            axes[i - 1] = np.asarray(jm.extract().axis, dtype=float)
        if _kind(short) == "continuous":
            lower[i - 1], upper[i - 1] = -CONTINUOUS_RANGE, CONTINUOUS_RANGE
            notes.append(
                (
                    f"joint {jname!r}",
                    "is continuous (no range in the URDF): joulepath gives it ±360°; give it "
                    'type="revolute" with <limit lower upper> if the arm allows less',
                )
            )
        else:
            lower[i - 1], upper[i - 1] = raw_lo[jm.idx_q], raw_hi[jm.idx_q]
        velocity[i - 1], effort[i - 1] = raw_v[jm.idx_v], raw_e[jm.idx_v]
        if _GRIPPER_LIKE.search(jname):
            notes.append(
                (
                    f"joint {jname!r}",
                    "is named like a gripper or finger but counted as a joint of the arm; lock it "
                    f"(--lock {jname}=VALUE) if it is not one",
                )
            )
    frame_names = [f.name for f in model.frames]
    wanted = (tool_frame,) if tool_frame else _TOOL_FRAMES
    fid = next((model.getFrameId(w) for w in wanted if w in frame_names), None)
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
        name=name or model.name or p.stem,
        joint_names=tuple(names_all),
        placements=np.array([model.jointPlacements[i].homogeneous for i in range(1, n + 1)]),
        axes=axes,
        masses=np.array([x.mass for x in inert]),
        coms=np.array([np.asarray(x.lever) for x in inert]),
        inertias=np.array([np.asarray(x.inertia) for x in inert]),
        tool=tool,
        lower=lower,
        upper=upper,
        velocity=velocity,
        effort=effort,
        gravity=np.array([0.0, 0.0, -9.80665]),
        notes=tuple(notes),
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
    if chain.armature is not None:
        model.armature = chain.joint_armature  # in RNEA, CRBA and ABA: armature * qdd, diag of M
    return model
