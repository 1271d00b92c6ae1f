"""Inverse dynamics by the Lagrange–Euler formulation of thesis §2.1, written correctly.

For a batch of configurations::

    tau_i = sum_j D_ij(q) qdd_j + sum_kj C^i_kj(q) qd_k qd_j + h_i(q)

* ``D(q) = sum_k A_k^T m_k A_k + B_k^T D_k(q) B_k`` (eq. 2.20) from the link
  Jacobians: ``A_k`` maps joint speeds to the velocity of link k's centre of mass,
  ``B_k`` to its angular velocity, ``D_k = R_k I_k R_k^T`` is its inertia in the
  base frame (eq. 2.18).
* ``C^i_kj = dD_ij/dq_k - 1/2 dD_kj/dq_i`` (eq. 2.21). The derivatives of ``D``
  are analytic: for a revolute joint l, any vector fixed to a link after joint l
  turns as ``dv/dq_l = z_l x v``, which gives ``dA_k``, ``dB_k`` and ``dD_k``
  without finite differences.
* ``h_i = -sum_k m_k A_k[:, i] . g`` (eq. 2.22, with g the gravity vector).

This is an independent implementation of the dynamics (it shares only the chain's
geometry with Pinocchio's RNEA) and is used to cross-check it; it is O(n^4) per
sample and slower than RNEA.
"""

from __future__ import annotations

import numpy as np

from joulepath._typing import FloatArray
from joulepath.description import Chain
from joulepath.kinematics import link_frames


def _skew(v: FloatArray) -> FloatArray:
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def _jacobians(chain: Chain, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Per-link Jacobians for ``q`` of shape (N, n).

    Returns ``A`` (N, k, j, 3): column j of link k's COM Jacobian; ``B`` likewise
    for the angular part; ``z`` (N, n, 3) joint axes; ``Dw`` (N, n, 3, 3) link
    inertias in the base frame.
    """
    n = chain.n_joints
    frames = link_frames(chain, q)
    rot = frames[..., :3, :3]
    origins = frames[..., :3, 3]
    z = np.einsum("Niab,ib->Nia", rot, chain.axes)
    coms = origins + np.einsum("Niab,ib->Nia", rot, chain.coms)
    lower = np.tril(np.ones((n, n)))[None, :, :, None]  # j <= k
    arm = coms[:, :, None, :] - origins[:, None, :, :]
    a = np.cross(np.broadcast_to(z[:, None, :, :], arm.shape), arm) * lower
    b = np.broadcast_to(z[:, None, :, :], arm.shape) * lower
    dw = rot @ chain.inertias[None] @ np.swapaxes(rot, -1, -2)
    return a, b, z, dw


def mass_matrix_le(chain: Chain, q: FloatArray) -> FloatArray:
    """Joint-space inertia matrix ``D(q)`` (eq. 2.20), shape (N, n, n) for q (N, n)."""
    a, b, _, dw = _jacobians(chain, q)
    out: FloatArray = np.einsum("Nkia,Nkja,k->Nij", a, a, chain.masses) + np.einsum(
        "Nkia,Nkab,Nkjb->Nij", b, dw, b
    )
    out += np.diag(chain.joint_armature)  # the drives' reflected rotor inertia (Chain.armature)
    return out


def lagrange_euler(chain: Chain, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
    """Joint torques (N·m) for q, qd, qdd of shape (N, n), without friction."""
    n = chain.n_joints
    a, b, z, dw = _jacobians(chain, q)
    m = chain.masses
    mass = np.einsum("Nkia,Nkja,k->Nij", a, a, m) + np.einsum("Nkia,Nkab,Nkjb->Nij", b, dw, b)
    idx = np.arange(n)
    le_lj = (idx[:, None] <= idx[None, :]).astype(float)  # l <= j
    lt_lj = (idx[:, None] < idx[None, :]).astype(float)  # l < j
    # dA[N, l, k, j] = z_l x A[k, j] for l <= j ;  z_j x A[k, l] for j < l
    zl = z[:, :, None, None, :]
    d_a = np.cross(zl, a[:, None, :, :, :]) * le_lj[None, :, None, :, None]
    d_a += (
        np.cross(z[:, None, None, :, :], np.swapaxes(a, 1, 2)[:, :, :, None, :])
        * lt_lj.T[None, :, None, :, None]
    )
    # dB[N, l, k, j] = z_l x B[k, j] for l < j
    d_b = np.cross(zl, b[:, None, :, :, :]) * lt_lj[None, :, None, :, None]
    # dDw[N, l, k] = S(z_l) Dw_k - Dw_k S(z_l) for l <= k
    s = _skew(z)[:, :, None, :, :]
    d_dw = (s @ dw[:, None] - dw[:, None] @ s) * le_lj[None, :, :, None, None]
    d_mass = (
        np.einsum("Nlkia,Nkja,k->Nlij", d_a, a, m)
        + np.einsum("Nkia,Nlkja,k->Nlij", a, d_a, m)
        + np.einsum("Nlkia,Nkab,Nkjb->Nlij", d_b, dw, b)
        + np.einsum("Nkia,Nlkab,Nkjb->Nlij", b, d_dw, b)
        + np.einsum("Nkia,Nkab,Nlkjb->Nlij", b, dw, d_b)
    )
    # C^i_kj = dD_ij/dq_k - 1/2 dD_kj/dq_i ; d_mass[N, l, i, j] = dD_ij / dq_l
    coupling = np.einsum("Nkij,Nk,Nj->Ni", d_mass, qd, qd) - 0.5 * np.einsum("Nikj,Nk,Nj->Ni", d_mass, qd, qd)
    gravity = -np.einsum("Nkia,k,a->Ni", a, m, chain.gravity)
    out: FloatArray = np.einsum("Nij,Nj->Ni", mass, qdd) + coupling + gravity + chain.joint_armature * qdd
    return out
