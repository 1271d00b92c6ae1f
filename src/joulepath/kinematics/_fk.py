"""Forward kinematics and the geometric Jacobian of a :class:`~joulepath.description.Chain`.

All functions take ``q`` of shape ``(..., n)`` (any batch shape) in rad and
return arrays with the same leading shape.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import ArrayLike, FloatArray
from joulepath.description import Chain
from joulepath.errors import InvalidInput
from joulepath.kinematics._rotations import (
    axis_angle_matrix,
    rotation_to_euler_zyx,
    rotation_to_quaternion,
)


def check_q(q: ArrayLike, n: int, name: str = "q") -> FloatArray:
    """``q`` as a float array of shape ``(..., n)``; a clear error otherwise."""
    arr = np.asarray(q, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != n:
        raise InvalidInput(
            f"{name} has shape {arr.shape}, but the robot has {n} joints: expected shape (..., {n})"
        )
    if not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{name} contains NaN or infinite values")
    return arr


def link_frames(chain: Chain, q: FloatArray) -> FloatArray:
    """World transforms of the joint frames ``F_1 .. F_n``.

    Parameters
    ----------
    chain : Chain
    q : ndarray of shape (..., n)

    Returns
    -------
    ndarray of shape (..., n, 4, 4)
    """
    batch = q.shape[:-1]
    frames = np.empty(batch + (chain.n_joints, 4, 4))
    current = np.broadcast_to(np.eye(4), batch + (4, 4))
    joint = np.zeros(batch + (4, 4))
    joint[..., 3, 3] = 1.0
    for i in range(chain.n_joints):
        joint[..., :3, :3] = axis_angle_matrix(chain.axes[i], q[..., i])
        current = current @ chain.placements[i] @ joint
        frames[..., i, :, :] = current
    return frames


@dataclass(frozen=True, slots=True)
class Pose:
    """Tool (tool0) pose for a batch of configurations.

    Attributes
    ----------
    position_m : ndarray of shape (..., 3)
    rotation : ndarray of shape (..., 3, 3)
    """

    position_m: FloatArray
    rotation: FloatArray

    @property
    def position_mm(self) -> FloatArray:
        """Position in mm, the controller's unit."""
        return self.position_m * 1000.0

    @property
    def quaternion(self) -> FloatArray:
        """Orientation as ``(w, x, y, z)`` (ABB ``q1..q4``), ``w >= 0``; shape (..., 4)."""
        return rotation_to_quaternion(self.rotation)

    @property
    def euler_zyx(self) -> FloatArray:
        """RAPID ``EulerZYX`` angles ``(z, y, x)`` in rad; shape (..., 3)."""
        return rotation_to_euler_zyx(self.rotation)

    @property
    def euler_zyx_deg(self) -> FloatArray:
        """RAPID ``EulerZYX`` angles ``(z, y, x)`` in deg (the log's phi, theta, psi)."""
        return np.degrees(self.euler_zyx)

    @property
    def homogeneous(self) -> FloatArray:
        """4x4 transforms, shape (..., 4, 4)."""
        out = np.zeros(self.position_m.shape[:-1] + (4, 4))
        out[..., :3, :3] = self.rotation
        out[..., :3, 3] = self.position_m
        out[..., 3, 3] = 1.0
        return out


def forward_kinematics(chain: Chain, q: ArrayLike) -> Pose:
    """Tool pose for joint positions ``q`` of shape ``(..., n)`` (rad)."""
    qa = check_q(q, chain.n_joints)
    tool = link_frames(chain, qa)[..., -1, :, :] @ chain.tool
    return Pose(position_m=tool[..., :3, 3].copy(), rotation=tool[..., :3, :3].copy())


def geometric_jacobian(chain: Chain, q: ArrayLike) -> FloatArray:
    """Geometric Jacobian of the tool frame origin, in the base frame.

    Rows 0–2 map joint speeds to the tool's linear velocity (m/s), rows 3–5 to
    its angular velocity (rad/s).

    Returns
    -------
    ndarray of shape (..., 6, n)
    """
    return position_and_jacobian(chain, q)[1]


def position_and_jacobian(chain: Chain, q: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Tool frame origin (m, shape (..., 3)) and its :func:`geometric_jacobian` (shape (..., 6, n))
    from one pass over the chain (a caller that needs both computes the link frames once)."""
    qa = check_q(q, chain.n_joints)
    frames = link_frames(chain, qa)
    tool = frames[..., -1, :, :] @ chain.tool
    z = np.einsum("...iab,ib->...ia", frames[..., :3, :3], chain.axes)
    origins = frames[..., :3, 3]
    position = tool[..., :3, 3]
    lin = np.cross(z, position[..., None, :] - origins)
    jac = np.concatenate([np.swapaxes(lin, -1, -2), np.swapaxes(z, -1, -2)], axis=-2)
    return position.copy(), jac
