"""Rotation conversions, vectorized over any leading batch shape."""

from __future__ import annotations

import numpy as np

from joulepath._typing import FloatArray


def axis_angle_matrix(axis: FloatArray, angle: FloatArray) -> FloatArray:
    """Rodrigues: rotation by ``angle`` (shape ``(...)``) about a fixed unit ``axis`` (3,).

    Returns
    -------
    ndarray of shape (..., 3, 3)
    """
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s = np.sin(angle)[..., None, None]
    c = np.cos(angle)[..., None, None]
    out: FloatArray = np.eye(3) + s * k + (1.0 - c) * (k @ k)
    return out


def rotation_to_quaternion(rot: FloatArray) -> FloatArray:
    """Unit quaternion ``(w, x, y, z)`` (ABB's q1..q4 order) of rotation matrices.

    The sign is chosen so that ``w >= 0``, as the ABB controller reports it.

    Parameters
    ----------
    rot : ndarray of shape (..., 3, 3)

    Returns
    -------
    ndarray of shape (..., 4)

    Examples
    --------
    >>> rotation_to_quaternion(np.eye(3))
    array([1., 0., 0., 0.])
    """
    r = np.asarray(rot, dtype=float)
    m00, m11, m22 = r[..., 0, 0], r[..., 1, 1], r[..., 2, 2]
    # four candidate formulas; choose per element the numerically best one
    t = np.stack(
        [1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22],
        axis=-1,
    )
    best = np.argmax(t, axis=-1)
    s = np.sqrt(np.maximum(np.take_along_axis(t, best[..., None], axis=-1)[..., 0], 1e-300))
    q = np.empty(r.shape[:-2] + (4,))
    d21 = r[..., 2, 1] - r[..., 1, 2]
    d02 = r[..., 0, 2] - r[..., 2, 0]
    d10 = r[..., 1, 0] - r[..., 0, 1]
    s21 = r[..., 2, 1] + r[..., 1, 2]
    s02 = r[..., 0, 2] + r[..., 2, 0]
    s10 = r[..., 1, 0] + r[..., 0, 1]
    cand = np.stack(
        [
            np.stack([s * s, d21, d02, d10], axis=-1),
            np.stack([d21, s * s, s10, s02], axis=-1),
            np.stack([d02, s10, s * s, s21], axis=-1),
            np.stack([d10, s02, s21, s * s], axis=-1),
        ],
        axis=-2,
    )
    q = np.take_along_axis(cand, best[..., None, None], axis=-2)[..., 0, :] / (2.0 * s[..., None])
    q *= np.where(q[..., :1] < 0.0, -1.0, 1.0)
    out: FloatArray = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return out


def quaternion_to_rotation(quat: FloatArray) -> FloatArray:
    """Rotation matrices of quaternions ``(w, x, y, z)``, shape ``(..., 4) -> (..., 3, 3)``."""
    q = np.asarray(quat, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    rows = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def rotation_to_euler_zyx(rot: FloatArray) -> FloatArray:
    """ZYX Euler angles ``(z, y, x)`` in rad with ``R = Rz(z) @ Ry(y) @ Rx(x)``.

    These are RAPID's ``EulerZYX(\\Z, ...)``, ``(\\Y, ...)``, ``(\\X, ...)``; y lies in
    [-pi/2, pi/2]. At the singularity ``|y| = pi/2`` the split between z and x is
    arbitrary; x is then set to 0.

    Parameters
    ----------
    rot : ndarray of shape (..., 3, 3)

    Returns
    -------
    ndarray of shape (..., 3)
    """
    r = np.asarray(rot, dtype=float)
    sy = np.clip(-r[..., 2, 0], -1.0, 1.0)
    y = np.arcsin(sy)
    cy = np.hypot(r[..., 0, 0], r[..., 1, 0])
    regular = cy > 1e-9
    z = np.where(regular, np.arctan2(r[..., 1, 0], r[..., 0, 0]), np.arctan2(-r[..., 0, 1], r[..., 1, 1]))
    x = np.where(regular, np.arctan2(r[..., 2, 1], r[..., 2, 2]), 0.0)
    return np.stack([z, y, x], axis=-1)


def euler_zyx_to_rotation(angles: FloatArray) -> FloatArray:
    """Inverse of :func:`rotation_to_euler_zyx`: ``(..., 3)`` of (z, y, x) rad to ``(..., 3, 3)``."""
    a = np.asarray(angles, dtype=float)
    rz = axis_angle_matrix(np.array([0.0, 0.0, 1.0]), a[..., 0])
    ry = axis_angle_matrix(np.array([0.0, 1.0, 0.0]), a[..., 1])
    rx = axis_angle_matrix(np.array([1.0, 0.0, 0.0]), a[..., 2])
    return rz @ ry @ rx
