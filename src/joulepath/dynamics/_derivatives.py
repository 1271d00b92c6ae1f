"""Analytic derivatives of inverse dynamics (Pinocchio's ``computeRNEADerivatives``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics._friction import Friction, friction_derivative

if TYPE_CHECKING:
    from joulepath.dynamics._robot import Robot


@dataclass(frozen=True, slots=True)
class DynamicsDerivatives:
    """Torques and their partial derivatives at N states.

    ``tau`` (N, n) in N·m; ``dq``, ``dqd``, ``dqdd`` (N, n, n) with
    ``dq[k, i, j] = d tau_i / d q_j`` at state ``k`` (likewise for ``qd`` and ``qdd``;
    ``dqdd`` is the joint-space inertia matrix).
    """

    tau: FloatArray
    dq: FloatArray
    dqd: FloatArray
    dqdd: FloatArray


def inverse_dynamics_derivatives(
    robot: Robot,
    q: FloatArray,
    qd: FloatArray,
    qdd: FloatArray,
    *,
    friction: Friction | None = None,
) -> DynamicsDerivatives:
    """Torques and analytic derivatives for states of shape (N, n), friction included.

    Friction acts joint by joint on the speed, so it adds ``tau_f(qd)`` to ``tau`` and
    ``d tau_f / d qd`` to the diagonal of ``dqd``.

    Examples
    --------
    >>> import numpy as np
    >>> from joulepath import load_robot
    >>> robot = load_robot("irb120")
    >>> q, qd, qdd = np.zeros((1, 6)), np.full((1, 6), 0.5), np.ones((1, 6))
    >>> d = inverse_dynamics_derivatives(robot, q, qd, qdd)
    >>> bool(np.allclose(d.tau, robot.inverse_dynamics(q, qd, qdd)))
    True
    """
    import pinocchio as pin

    qa = np.ascontiguousarray(q, dtype=float)
    va = np.ascontiguousarray(qd, dtype=float)
    aa = np.ascontiguousarray(qdd, dtype=float)
    n_states, n = qa.shape
    model = robot.pinocchio_model
    data = model.createData()
    tau = np.empty((n_states, n))
    d_q = np.empty((n_states, n, n))
    d_v = np.empty((n_states, n, n))
    d_a = np.empty((n_states, n, n))
    for k in range(n_states):
        dq, dv, da = pin.computeRNEADerivatives(model, data, qa[k], va[k], aa[k])
        d_q[k] = dq
        d_v[k] = dv
        d_a[k] = da
        tau[k] = data.tau
    # Pinocchio's algorithm fills the inertia matrix's upper triangle (its Python binding
    # may already mirror it): mirror it here either way
    low_i, low_j = np.tril_indices(n, -1)
    d_a[:, low_i, low_j] = d_a[:, low_j, low_i]
    if friction is not None:
        tau = tau + friction.torque(va)
        idx = np.arange(n)
        d_v[:, idx, idx] += friction_derivative(friction, va)
    return DynamicsDerivatives(tau=tau, dq=d_q, dqd=d_v, dqdd=d_a)
