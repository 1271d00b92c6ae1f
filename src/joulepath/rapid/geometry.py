"""Poses of RAPID's records as 4x4 transforms (m) and back; RAPID's orient is (q1..q4) = (w, x, y, z)."""

from __future__ import annotations

import math

import numpy as np

from joulepath._typing import FloatArray
from joulepath.rapid.values import Record, make_orient, make_pos, num, pos_values


def quat_to_matrix(q: tuple[float, float, float, float]) -> FloatArray:
    w, x, y, z = q
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if norm < 1e-12:
        raise ValueError("an orient of zero length: normalise it (NOrient) or give a unit quaternion")
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(r: FloatArray) -> tuple[float, float, float, float]:
    """A rotation matrix as (w, x, y, z), w >= 0."""
    t = float(np.trace(r))
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = (0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s)
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2
        q = ((r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s)
    elif r[1, 1] > r[2, 2]:
        s = math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2
        q = ((r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s)
    else:
        s = math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2
        q = ((r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s)
    if q[0] < 0:
        q = (-q[0], -q[1], -q[2], -q[3])
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def orient_values(rec: object) -> tuple[float, float, float, float]:
    assert isinstance(rec, Record)
    return (num(rec.values[0]), num(rec.values[1]), num(rec.values[2]), num(rec.values[3]))


def frame(trans_mm: tuple[float, float, float], q: tuple[float, float, float, float]) -> FloatArray:
    """A transform (m) from a translation (mm) and a quaternion (w first)."""
    out = np.eye(4)
    out[:3, :3] = quat_to_matrix(q)
    out[:3, 3] = np.asarray(trans_mm, dtype=float) / 1000.0
    return out


def pose_matrix(rec: Record) -> FloatArray:
    """A ``pose`` or ``robtarget`` record (its ``trans`` and ``rot``) as a transform, m."""
    return frame(pos_values(rec.values[0]), orient_values(rec.values[1]))


def with_pose(rec: Record, m: FloatArray) -> Record:
    """``rec`` (a pose or robtarget) with its ``trans`` and ``rot`` set from the transform ``m`` (m)."""
    p = m[:3, 3] * 1000.0
    out = rec.replace("trans", make_pos(float(p[0]), float(p[1]), float(p[2])))
    return out.replace("rot", make_orient(matrix_to_quat(m[:3, :3])))


def rotation(axis: int, deg: float) -> FloatArray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out = np.eye(4)
    out[i, i], out[i, j], out[j, i], out[j, j] = c, -s, s, c
    return out


def euler_zyx_deg(r: FloatArray) -> tuple[float, float, float]:
    """(z, y, x) angles (deg) of a rotation ``Rz(z) Ry(y) Rx(x)``."""
    y = math.degrees(math.asin(max(-1.0, min(1.0, -float(r[2, 0])))))
    z = math.degrees(math.atan2(float(r[1, 0]), float(r[0, 0])))
    x = math.degrees(math.atan2(float(r[2, 1]), float(r[2, 2])))
    return z, y, x


def orient_zyx(z: float, y: float, x: float) -> tuple[float, float, float, float]:
    m = rotation(2, z) @ rotation(1, y) @ rotation(0, x)
    return matrix_to_quat(m[:3, :3])


def quat_mult(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    )
