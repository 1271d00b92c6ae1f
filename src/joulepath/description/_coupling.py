"""Joint coupling of a parallel-linkage arm: the controller's axis values against the serial model's.

The IRB 2400 turns its forearm through a parallelogram: the controller's axis 3 (what RAPID
jointtargets hold) is the forearm's angle against link 1, ``axis3 = q2 + q3`` of the serial chain
that the dynamics integrates (ros-industrial/abb_driver ``linkage_transform``; Obal & Gierlak
2025, theta_3 = q3 - q2). A description says so with a ``<joint-coupling>`` entry; these two
functions convert positions (and, the map being linear, speeds and accelerations), two more the
torques (by the transposed map, which keeps the power), and all are the identity for an arm
without one. The controller's own axis-3 range (which no box on the serial joints states) is its
``<axis3-range-deg>`` entry, :func:`axis3_range`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from joulepath._typing import FloatArray
from joulepath.description._model import RobotDescription
from joulepath.errors import InvalidRobotDescription


def has_axis3_coupling(desc: RobotDescription) -> bool:
    """Whether the description's axis 3 is coupled to axis 2 (``<joint-coupling>`` present)."""
    return desc.info_value("joint-coupling") is not None


def joints_to_axes(desc: RobotDescription, q: ArrayLike) -> FloatArray:
    """The controller's axis values (rad) for serial joint angles ``q`` of shape ``(..., n)``.

    >>> from joulepath.description import preset_description
    >>> joints_to_axes(preset_description("irb2400"), [0, 0.2, 0.1, 0, 0, 0]).round(3).tolist()
    [0.0, 0.2, 0.3, 0.0, 0.0, 0.0]
    """
    out = np.array(q, dtype=float)
    if has_axis3_coupling(desc):
        out[..., 2] = out[..., 2] + out[..., 1]
    return out


def axes_to_joints(desc: RobotDescription, axes: ArrayLike) -> FloatArray:
    """The serial joint angles (rad) for the controller's axis values, shape ``(..., n)``.

    >>> from joulepath.description import preset_description
    >>> axes_to_joints(preset_description("irb2400"), [0, 0.2, 0.3, 0, 0, 0]).round(3).tolist()
    [0.0, 0.2, 0.1, 0.0, 0.0, 0.0]
    """
    out = np.array(axes, dtype=float)
    if has_axis3_coupling(desc):
        out[..., 2] = out[..., 2] - out[..., 1]
    return out


def joint_torques_to_axes(desc: RobotDescription, tau: ArrayLike) -> FloatArray:
    """The controller's axis torques (N·m) for serial joint torques ``tau`` of shape ``(..., n)``.

    The transpose of the joint map keeps the power: ``tau_axes . axes' = tau . q'``, so axis 2
    carries ``tau2 - tau3`` and axis 3 ``tau3``.

    >>> from joulepath.description import preset_description
    >>> joint_torques_to_axes(preset_description("irb2400"), [0, 5.0, 2.0, 0, 0, 0]).tolist()
    [0.0, 3.0, 2.0, 0.0, 0.0, 0.0]
    """
    out = np.array(tau, dtype=float)
    if has_axis3_coupling(desc):
        out[..., 1] = out[..., 1] - out[..., 2]
    return out


def axis_torques_to_joints(desc: RobotDescription, tau_axes: ArrayLike) -> FloatArray:
    """The serial joint torques (N·m) for the controller's axis torques (the inverse map)."""
    out = np.array(tau_axes, dtype=float)
    if has_axis3_coupling(desc):
        out[..., 1] = out[..., 1] + out[..., 2]
    return out


def axis3_range(desc: RobotDescription) -> tuple[float, float] | None:
    """The controller's axis-3 range (rad) of a coupled arm, from ``<axis3-range-deg>`` ("lo hi"), or None.

    >>> from joulepath.description import preset_description
    >>> tuple(round(math.degrees(v)) for v in axis3_range(preset_description("irb2400")))
    (-60, 65)
    """
    text = desc.info_value("axis3-range-deg")
    if text is None or not has_axis3_coupling(desc):
        return None
    try:
        lo, hi = (float(v) for v in text.split())
    except ValueError as err:
        raise InvalidRobotDescription(
            f"{desc.name}: <axis3-range-deg> is {text!r}; it needs two numbers, the lower and upper "
            "limit of the controller's axis 3 in degrees (e.g. '-60 65')"
        ) from err
    if not lo < hi:
        raise InvalidRobotDescription(
            f"{desc.name}: <axis3-range-deg> is {text!r}; the lower limit must be below the upper one"
        )
    return math.radians(lo), math.radians(hi)
