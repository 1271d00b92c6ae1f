"""Joint coupling of a parallel-linkage arm: the controller's axis values against the serial model's.

The IRB 2400 turns its forearm through a parallelogram: the controller's axis 3 (what RAPID
jointtargets hold) is the forearm's angle against link 1, ``axis3 = q2 + q3`` of the serial chain
that the dynamics integrates (ros-industrial/abb_driver ``linkage_transform``; Obal & Gierlak
2025, theta_3 = q3 - q2). A description says so with a ``<joint-coupling>`` entry; these two
functions convert, and are the identity for an arm without one.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from joulepath._typing import FloatArray
from joulepath.description._model import RobotDescription


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
