"""Closed-form inverse kinematics of the ABB layout and ABB's ``confdata``.

The layout (checked on the chain before any solve, :func:`check_layout`): six
revolute joints about their frame's z axis; joint 1 at the base; joint 2 on axis 1
(the IRB 120, IRB 1200) or offset from it by ``a1`` in the arm plane (the shoulder
offset of the IRB 140, 1600, 2600, 4600, 6700); the lower arm in the plane that
joint 1 turns; joints 2 and 3 parallel; a spherical wrist (axes 4, 5 and 6 meet at
the wrist centre). The wrist centre fixes joints 1–3 (shoulder in front of or
behind axis 1, elbow up or down), the orientation fixes joints 4–6 (a ZYZ Euler
decomposition, axis 5 positive or negative): eight branches, plus whole turns of a
joint whose range spans more than one revolution (joint 6 of the IRB 120).

``confdata`` ``[cf1, cf4, cf6, cfx]`` (ABB, RAPID reference "confdata"): ``cf1``,
``cf4`` and ``cf6`` are the quadrants of joints 1, 4 and 6 (``floor(q / 90°)``: 0 for
0..90°, -1 for -90..0°); ``cfx`` numbers the branch of a serial arm:

====  ==========================  ============================  ============
cfx   wrist centre vs. axis 1     wrist centre vs. lower arm     axis 5
====  ==========================  ============================  ============
0     in front of                 in front of                    positive
1     in front of                 in front of                    negative
2     in front of                 behind                         positive
3     in front of                 behind                         negative
4     behind                      in front of                    positive
5     behind                      in front of                    negative
6     behind                      behind                         positive
7     behind                      behind                         negative
====  ==========================  ============================  ============

At the home pose every joint is 0 and ``confdata`` is ``[0, 0, 0, 0]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.description import Chain
from joulepath.errors import InvalidInput
from joulepath.kinematics._fk import forward_kinematics, link_frames

QUADRANT = np.pi / 2
QUADRANT_TOLERANCE = 1e-3
"""rad: a joint this close to a quadrant boundary matches the quadrants on both sides."""
_RX_P90 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
_RX_M90 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
_PLANE = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
_RZ_PI = np.diag([-1.0, -1.0, 1.0])


@dataclass(frozen=True, slots=True)
class Layout:
    """The lengths (m) of the ABB layout read from a chain."""

    d1: float  # base to the shoulder (joint 2), along z
    a2: float  # lower arm, joint 2 to joint 3
    g: tuple[float, float]  # joint 3 to the wrist centre in the arm plane (along, across)
    a1: float = 0.0  # shoulder offset: axis 1 to joint 2, along the arm plane (0 for the IRB 120)


_Z_AXES = np.tile([0.0, 0.0, 1.0], (6, 1))
_LAYOUT = np.concatenate([
    np.eye(4).ravel(), _PLANE.ravel(), np.zeros(1), np.eye(3).ravel(), np.zeros(2),
    _RX_M90.ravel(), np.zeros(2), _RX_P90.ravel(), np.zeros(2), (_RX_M90 @ _RZ_PI).ravel(), np.zeros(3),
])  # fmt: skip
"""The IRB 120 layout's frames as :func:`check_layout` compares them (rotations, and the parts of
the translations that are zero)."""
_LAYOUT_TOL = np.concatenate([
    np.full(16, 1e-9), np.full(9, 1e-9), np.full(1, 1e-12), np.full(9, 1e-9), np.full(2, 1e-12),
    np.full(9, 1e-9), np.full(2, 1e-12), np.full(9, 1e-9), np.full(2, 1e-12),
    np.full(9, 1e-9), np.full(3, 1e-12),
]) + 1e-5 * np.abs(_LAYOUT)  # fmt: skip
"""Tolerances of :data:`_LAYOUT`: absolute 1e-9 (rotations) and 1e-12 (translations), plus 1e-5 of
the expected value (``np.allclose``'s)."""


def check_layout(chain: Chain) -> Layout:
    """The chain's lengths when it has the ABB layout; ``InvalidInput`` otherwise."""
    how = (
        "closed-form inverse kinematics (robtargets, MoveL) supports the IRB 120 layout only, with or "
        "without a shoulder offset (ABB's serial arms: 6 revolute joints, parallel joints 2 and 3, "
        "spherical wrist); use jointtargets (MoveAbsJ)"
    )
    if chain.n_joints != 6 or not np.all(np.abs(np.asarray(chain.axes) - _Z_AXES) <= 1e-8 + 1e-5 * _Z_AXES):
        raise InvalidInput(f"{how}: the chain has {chain.n_joints} joints or axes other than z")
    p = chain.placements
    rot = [x[:3, :3] for x in p]
    tr = [x[:3, 3] for x in p]
    # one comparison of every frame against the layout (np.allclose per part costs more than the
    # closed form itself, and the check runs on every pose solved)
    got = np.concatenate([
        p[0].ravel(), rot[1].ravel(), tr[1][1:2], rot[2].ravel(), tr[2][1:], rot[3].ravel(), tr[3][1:],
        rot[4].ravel(), tr[4][:2], rot[5].ravel(), tr[5],
    ])  # fmt: skip
    expected = bool(np.all(np.abs(got - _LAYOUT) <= _LAYOUT_TOL))
    if not expected:
        raise InvalidInput(f"{how}: this chain's joint frames differ")
    return Layout(
        d1=float(tr[1][2]), a2=float(tr[2][0]), g=(float(tr[3][0]), float(tr[4][2])), a1=float(tr[1][0])
    )


def _wrap(a: FloatArray) -> FloatArray:
    out: FloatArray = (a + np.pi) % (2 * np.pi) - np.pi
    return out


def ik_branches(chain: Chain, pose: FloatArray) -> tuple[FloatArray, FloatArray]:
    """All eight closed-form branches for tool0 poses ``pose`` (..., 4, 4).

    Returns
    -------
    q : ndarray of shape (..., 8, 6)
        Joint values (rad, each wrapped to [-pi, pi)), valid branches first, in order of ``cfx``.
    valid : ndarray of bool, shape (..., 8)
        False where the branch does not reach the pose (wrist centre out of reach).
    """
    lay = check_layout(chain)
    pose = np.asarray(pose, dtype=float)
    batch = pose.shape[:-2]
    flange = pose @ np.linalg.inv(chain.tool)
    wc = flange[..., :3, 3]
    rot = flange[..., :3, :3]
    gx, gy = lay.g
    L = np.hypot(gx, gy)
    phi = np.arctan2(gy, gx)
    q = np.zeros(batch + (8, 6))
    valid = np.ones(batch + (8,), dtype=bool)
    rho = np.hypot(wc[..., 0], wc[..., 1])
    base = np.arctan2(wc[..., 1], wc[..., 0])
    for shoulder in (0, 1):  # 0: wrist centre in front of axis 1
        r = (rho if shoulder == 0 else -rho) - lay.a1  # from joint 2, in the arm plane
        q1 = base if shoulder == 0 else _wrap(base + np.pi)
        x = wc[..., 2] - lay.d1
        c = (x * x + r * r - lay.a2**2 - L**2) / (2 * lay.a2 * L)
        ok = np.abs(c) <= 1.0 + 1e-12
        beta = np.arccos(np.clip(c, -1.0, 1.0))
        for elbow in (0, 1):
            q3 = _wrap((beta if elbow == 0 else -beta) - phi)
            hx = lay.a2 + gx * np.cos(q3) - gy * np.sin(q3)
            hy = gx * np.sin(q3) + gy * np.cos(q3)
            q2 = _wrap(np.arctan2(r, x) - np.arctan2(hy, hx))
            arm = np.stack([q1, q2, q3, np.zeros_like(q1), np.zeros_like(q1), np.zeros_like(q1)], -1)
            r3 = link_frames(chain, arm)[..., 2, :3, :3] @ chain.placements[3][:3, :3]
            m = np.swapaxes(r3, -1, -2) @ rot  # = Rz(q4) Ry(-q5) Rz(q6 + pi)
            sb = np.hypot(m[..., 0, 2], m[..., 1, 2])
            b = np.arctan2(sb, m[..., 2, 2])
            singular = sb < 1e-12
            for wrist in (0, 1):  # 0: axis 5 positive (beta <= 0)
                sign = -1.0 if wrist == 0 else 1.0
                a4 = np.arctan2(sign * m[..., 1, 2], sign * m[..., 0, 2])
                g6 = np.arctan2(sign * m[..., 2, 1], -sign * m[..., 2, 0])
                a4 = np.where(singular, 0.0, a4)
                g6 = np.where(singular, np.arctan2(m[..., 1, 0], m[..., 0, 0]), g6)
                k = 4 * shoulder + 2 * elbow + wrist
                q[..., k, 0] = q1
                q[..., k, 1] = q2
                q[..., k, 2] = q3
                q[..., k, 3] = _wrap(a4)
                q[..., k, 4] = -sign * b
                q[..., k, 5] = _wrap(g6 - np.pi)
                valid[..., k] = ok
    # which side of the lower arm the elbow branch puts the wrist centre on depends on
    # the geometry; relabel each branch by the cfx its joints really have
    cfx = branch_cfx(chain, q)
    order = np.argsort(cfx + 8 * ~valid, axis=-1, kind="stable")
    q = np.take_along_axis(q, order[..., None], axis=-2)
    valid = np.take_along_axis(valid, order, axis=-1)
    return q, valid


def branch_cfx(chain: Chain, q: FloatArray) -> FloatArray:
    """ABB's ``cfx`` (0..7) of joint values ``q`` (..., 6) of the ABB layout (int array)."""
    lay = check_layout(chain)
    q = np.asarray(q, dtype=float)
    frames = link_frames(chain, q)
    wc = frames[..., 4, :3, 3]
    # the arm plane's forward direction (x of frame 1) and coordinates in it
    fwd = np.stack([np.cos(q[..., 0]), np.sin(q[..., 0])], axis=-1)
    radial = (wc[..., :2] * fwd).sum(-1)
    height = wc[..., 2] - lay.d1
    behind_axis1 = radial < 0
    # lower arm from joint 2 to joint 3 in the (radial, height) plane
    j3 = frames[..., 2, :3, 3]
    arm_r = (j3[..., :2] * fwd).sum(-1) - lay.a1  # joint 3 and the wrist centre seen from joint 2
    arm_h = j3[..., 2] - lay.d1
    cross = arm_r * height - arm_h * (radial - lay.a1)  # > 0: wrist centre behind the lower arm
    behind_arm = cross > 0
    negative5 = q[..., 4] < 0
    out: FloatArray = 4 * behind_axis1 + 2 * behind_arm + 1 * negative5
    return out.astype(int)


def confdata(chain: Chain, q: FloatArray) -> FloatArray:
    """ABB ``[cf1, cf4, cf6, cfx]`` of joint values ``q`` (..., 6); int array (..., 4)."""
    q = np.asarray(q, dtype=float)
    quad = np.floor(q[..., [0, 3, 5]] / QUADRANT).astype(int)
    out: FloatArray = np.concatenate([quad, branch_cfx(chain, q)[..., None]], axis=-1)
    return out


def _in_quadrant(q: FloatArray, cf: int) -> bool:
    lo, hi = cf * QUADRANT - QUADRANT_TOLERANCE, (cf + 1) * QUADRANT + QUADRANT_TOLERANCE
    return bool(lo <= q <= hi)


def solve_ik(
    chain: Chain,
    pose: FloatArray,
    conf: tuple[int, int, int, int] | None,
    *,
    lower: FloatArray,
    upper: FloatArray,
    near: FloatArray | None = None,
) -> FloatArray | None:
    """The joint values (rad) that reach tool0 pose ``pose`` (4, 4) with ``confdata`` ``conf``.

    With ``conf`` the branch is the one whose ``cfx`` it names and each of joints 1,
    4 and 6 is shifted by whole turns into the quadrant it names, as the controller
    does (ConfJ/ConfL on); with ``conf=None`` the solution nearest ``near`` (within
    the ranges) is returned. ``None`` when no solution within ``[lower, upper]``
    matches.
    """
    qs, valid = ik_branches(chain, np.asarray(pose, dtype=float))
    return _pick(qs, valid, branch_cfx(chain, qs), conf, lower=lower, upper=upper, near=near)


def solve_ik_along(
    chain: Chain, poses: FloatArray, *, lower: FloatArray, upper: FloatArray, start: FloatArray
) -> list[FloatArray | None]:
    """The joint values along tool0 poses ``poses`` (N, 4, 4), each the solution nearest the one
    before (the first: nearest ``start``) within the ranges: :func:`solve_ik` with ``conf=None`` and
    ``near`` the previous solution, pose after pose, its branches computed for every pose at once.
    The list ends at the first pose without a solution (None)."""
    qs, valid = ik_branches(chain, np.asarray(poses, dtype=float))
    cfx = branch_cfx(chain, qs)
    out: list[FloatArray | None] = []
    near = start
    for k in range(qs.shape[0]):
        q = _pick(qs[k], valid[k], cfx[k], None, lower=lower, upper=upper, near=near)
        out.append(q)
        if q is None:
            break
        near = q
    return out


def _pick(
    qs: FloatArray,
    valid: FloatArray,
    cfx: FloatArray,
    conf: tuple[int, int, int, int] | None,
    *,
    lower: FloatArray,
    upper: FloatArray,
    near: FloatArray | None,
) -> FloatArray | None:
    """:func:`solve_ik`'s choice among the branches ``qs`` (8, 6) of one pose."""
    best: FloatArray | None = None
    best_d = np.inf
    for k in range(8):
        if not valid[k]:
            continue
        if conf is not None and int(cfx[k]) != conf[3]:
            continue
        for cand in _turns(qs[k], lower, upper):
            if conf is not None and not all(
                _in_quadrant(cand[j], c) for j, c in zip((0, 3, 5), conf[:3], strict=True)
            ):
                continue
            d = 0.0 if near is None else float(np.abs(cand - near).max())
            if conf is not None and near is None:
                return cand
            if d < best_d:
                best, best_d = cand, d
    return best


def _turns(q: FloatArray, lower: FloatArray, upper: FloatArray) -> list[FloatArray]:
    """``q`` with whole turns added to any joint, every combination within the ranges."""
    options = []
    for j in range(q.size):
        ks = range(
            int(np.floor((lower[j] - q[j]) / (2 * np.pi))), int(np.ceil((upper[j] - q[j]) / (2 * np.pi))) + 1
        )
        vals = [
            q[j] + 2 * np.pi * k for k in ks if lower[j] - 1e-9 <= q[j] + 2 * np.pi * k <= upper[j] + 1e-9
        ]
        if not vals:
            return []
        options.append(vals)
    grids = np.meshgrid(*options, indexing="ij")
    return [row for row in np.stack([g.ravel() for g in grids], axis=-1)]


def pose_error(chain: Chain, q: FloatArray, pose: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Position error (m) and rotation error (rad) of ``fk(q)`` against ``pose``."""
    got = forward_kinematics(chain, q)
    dp = np.linalg.norm(got.position_m - pose[..., :3, 3], axis=-1)
    rel = np.swapaxes(got.rotation, -1, -2) @ pose[..., :3, :3]
    tr = np.clip((np.trace(rel, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    # arccos is ill-conditioned near 0: use the skew part for small angles
    skew = np.stack(
        [rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0], rel[..., 1, 0] - rel[..., 0, 1]],
        -1,
    )
    angle = np.arctan2(0.5 * np.linalg.norm(skew, axis=-1), tr)
    return dp, angle
