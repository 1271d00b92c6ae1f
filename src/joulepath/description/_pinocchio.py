"""The bridge to Pinocchio: URDF parsing into a :class:`Chain`, and a Chain into a ``pin.Model``."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from joulepath.description._model import Chain
from joulepath.errors import InvalidRobotDescription

_AXES = {
    "JointModelRX": (1.0, 0.0, 0.0),
    "JointModelRY": (0.0, 1.0, 0.0),
    "JointModelRZ": (0.0, 0.0, 1.0),
}
_TOOL_FRAMES = ("tool0", "flange", "ee_link", "tool", "end_effector")


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
        Unreadable file, not six joints, a joint that is not a single revolute
        axis (prismatic, continuous, floating), or a branching tree.
    """
    pin = _pin()
    p = Path(path)
    if not p.is_file():
        raise InvalidRobotDescription(f"{p}: no such URDF file")
    try:
        model = pin.buildModelFromUrdf(str(p))
    except (ValueError, RuntimeError) as err:
        raise InvalidRobotDescription(f"{p}: Pinocchio cannot parse it as URDF ({err})") from err
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
