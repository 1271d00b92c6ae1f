"""Physical consistency through the log-Cholesky parametrization (Rucker & Wensing, 2022).

A link's 10 inertial parameters are physically consistent (some mass density
realizes them: positive mass, positive definite inertia satisfying the triangle
inequalities) exactly when its 4x4 pseudo-inertia

    J = [[Sigma, h], [h^T, m]],   Sigma = tr(I_o)/2 * 1 - I_o,   h = m c

is positive definite. Writing ``J = U U^T`` with ``U`` upper triangular and

    U = exp(alpha) [[exp(d1), s12, s13, t1], [0, exp(d2), s23, t2], [0, 0, exp(d3), t3], [0, 0, 0, 1]]

maps any 10 real numbers ``(alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3)`` to a
consistent link, and every consistent link to exactly one such vector: an
unconstrained search over these numbers can only return consistent parameters.
"""

from __future__ import annotations

import numpy as np

from joulepath._typing import FloatArray


def pseudo_inertia(phi: FloatArray) -> FloatArray:
    """``J`` (4x4) of one link's ``[m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``."""
    m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = phi
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    J = np.empty((4, 4))
    J[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    J[:3, 3] = J[3, :3] = (hx, hy, hz)
    J[3, 3] = m
    return J


def parameters_of(J: FloatArray) -> FloatArray:
    """Inverse of :func:`pseudo_inertia`."""
    sigma = J[:3, :3]
    inertia = np.trace(sigma) * np.eye(3) - sigma
    return np.array(
        [
            J[3, 3],
            J[0, 3],
            J[1, 3],
            J[2, 3],
            inertia[0, 0],
            inertia[0, 1],
            inertia[1, 1],
            inertia[0, 2],
            inertia[1, 2],
            inertia[2, 2],
        ]
    )


def from_log_cholesky(theta: FloatArray) -> FloatArray:
    """Consistent link parameters (10) of log-Cholesky coordinates (10)."""
    alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3 = theta
    U = np.exp(alpha) * np.array(
        [
            [np.exp(d1), s12, s13, t1],
            [0.0, np.exp(d2), s23, t2],
            [0.0, 0.0, np.exp(d3), t3],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )
    return parameters_of(U @ U.T)


def to_log_cholesky(phi: FloatArray) -> FloatArray:
    """Log-Cholesky coordinates of consistent link parameters (raises LinAlgError if not consistent)."""
    J = pseudo_inertia(phi)
    rev = J[::-1, ::-1]
    L = np.linalg.cholesky(rev)  # rev = L L^T, so J = U U^T with U = reversed L (upper)
    U = L[::-1, ::-1]
    a = U[3, 3]
    V = U / a
    return np.array(
        [np.log(a), np.log(V[0, 0]), np.log(V[1, 1]), np.log(V[2, 2]), V[0, 1], V[1, 2], V[0, 2], *V[:3, 3]]
    )


def min_eigenvalues(phi: FloatArray) -> FloatArray:
    """Smallest eigenvalue of each link's pseudo-inertia (``phi``: ``(10 n,)``); > 0 iff consistent."""
    links = np.asarray(phi, dtype=float).reshape(-1, 10)
    return np.array([np.linalg.eigvalsh(pseudo_inertia(p))[0] for p in links])


def triangle_margins(phi: FloatArray) -> FloatArray:
    """Per link, the smallest of ``m`` and the triangle-inequality margins of the inertia about the COM."""
    out = []
    for p in np.asarray(phi, dtype=float).reshape(-1, 10):
        m = p[0]
        c = p[1:4] / m if m > 0 else np.zeros(3)
        J = pseudo_inertia(p)
        i_o = parameters_of(J)[4:]
        inertia = np.array([[i_o[0], i_o[1], i_o[3]], [i_o[1], i_o[2], i_o[4]], [i_o[3], i_o[4], i_o[5]]])
        i_c = inertia - m * (c @ c * np.eye(3) - np.outer(c, c))
        ev = np.linalg.eigvalsh(i_c)
        tri = [ev[0] + ev[1] - ev[2], ev[0] + ev[2] - ev[1], ev[1] + ev[2] - ev[0]]
        out.append(min(m, ev[0], *tri))
    return np.array(out)


__all__ = [
    "from_log_cholesky",
    "min_eigenvalues",
    "parameters_of",
    "pseudo_inertia",
    "to_log_cholesky",
    "triangle_margins",
]
