"""Regressors linear in the dynamic parameters, and the identifiable base set.

Rigid body: Pinocchio's ``computeJointTorqueRegressor`` gives ``tau = Y(q, qd, qdd) phi``
with ``phi`` the 10 inertial parameters of each link in Pinocchio's order
``[m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz]`` (inertia about the
joint frame's origin, joint-frame axes).

Base parameters (Gautier & Khalil): the columns of ``Y`` are not independent (a
link's parameters that never move the joints, sums that always act together). A QR
decomposition with column pivoting of ``Y`` stacked over random configurations,
speeds and accelerations (structural, independent of the data) splits the columns
into ``r`` independent ones and the rest, ``Y[:, dep] = Y[:, indep] K``; the base
parameters are ``beta = phi[indep] + K phi[dep]`` and ``Y phi = Y[:, indep] beta``
for every motion. A column counts as independent when its pivot exceeds
:data:`RANK_TOLERANCE` times the largest one.

Armature (optional, ``armature=True``): per joint ``i`` one more parameter, the drive's
rotating inertia reflected to the joint (:attr:`joulepath.description.Chain.armature`), whose
column is ``qdd_i`` in joint ``i``'s row and 0 elsewhere; the full parameters are then ``10 n +
n``: ``[phi, armature]``. On a joint whose axis never turns (a first joint about the vertical)
the armature acts exactly as the link's inertia about that axis: the base set regroups the two
(structurally, as any other dependent column).

Friction: per joint, the columns ``s``, ``qd``, ``|s|`` and (optionally)
``exp(-(qd/v_s)²) s`` with ``s = tanh(qd / smoothing)`` (see
:class:`joulepath.dynamics.IdentifiedFriction`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
import scipy.linalg

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot

RANK_TOLERANCE = 1e-8
"""A pivot of the structural QR below this share of the largest one marks a dependent column."""

PARAMETER_NAMES = ("m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
FRICTION_TERMS = ("coulomb", "viscous", "offset", "stribeck")


def inertial_regressor(robot: Robot, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
    """``Y`` of shape ``(N, n, 10 n)`` with ``tau[k] = Y[k] @ phi`` (Pinocchio's joint torque regressor)."""
    import pinocchio as pin

    model = robot.pinocchio_model
    data = model.createData()
    n = robot.n_joints
    out = np.empty((q.shape[0], n, 10 * n))
    for k in range(q.shape[0]):
        out[k] = pin.computeJointTorqueRegressor(model, data, q[k], qd[k], qdd[k])
    return out


def armature_regressor(qdd: FloatArray) -> FloatArray:
    """Armature columns ``(N, n, n)``: ``tau[k, i] += armature[i] * qdd[k, i]``."""
    N, n = qdd.shape
    out = np.zeros((N, n, n))
    idx = np.arange(n)
    out[:, idx, idx] = qdd
    return out


def dynamic_regressor(
    robot: Robot, q: FloatArray, qd: FloatArray, qdd: FloatArray, *, armature: bool
) -> FloatArray:
    """The rigid-body regressor (:func:`inertial_regressor`), followed by the armature columns
    (:func:`armature_regressor`) when ``armature``: ``(N, n, 10 n [+ n])``."""
    Y = inertial_regressor(robot, q, qd, qdd)
    if not armature:
        return Y
    return np.concatenate([Y, armature_regressor(qdd)], axis=2)


def true_parameters(robot: Robot, *, armature: bool = False) -> FloatArray:
    """The robot's own parameters in the regressor's order: ``phi`` (``10 n``), followed by its
    armature (:attr:`joulepath.description.Chain.armature`, ``n``) when ``armature``."""
    model = robot.pinocchio_model
    phi = np.concatenate([model.inertias[i + 1].toDynamicParameters() for i in range(robot.n_joints)])
    if not armature:
        return phi
    return np.concatenate([phi, robot.chain.joint_armature])


def friction_regressor(
    qd: FloatArray,
    *,
    smoothing: float,
    offset: bool,
    stribeck_speed: float | None,
    viscous_offset: bool = False,
) -> tuple[FloatArray, tuple[str, ...]]:
    """Friction columns ``(N, n, n_terms * n)`` and the term of each block of ``n`` columns.

    The terms of :class:`joulepath.dynamics.IdentifiedFriction`: ``coulomb``, ``viscous``,
    then as asked ``offset``, ``stribeck`` and ``viscous_offset`` (``qd * tanh(qd /
    smoothing)``, the viscous level's direction asymmetry).
    """
    s = np.tanh(qd / smoothing)
    cols = [s, qd]
    terms = ["coulomb", "viscous"]
    if offset:
        cols.append(np.abs(s))
        terms.append("offset")
    if stribeck_speed is not None:
        cols.append(np.exp(-((qd / stribeck_speed) ** 2)) * s)
        terms.append("stribeck")
    if viscous_offset:
        cols.append(qd * s)
        terms.append("viscous_offset")
    N, n = qd.shape
    out = np.zeros((N, n, len(cols) * n))
    idx = np.arange(n)
    for t, c in enumerate(cols):
        out[:, idx, t * n + idx] = c
    return out, tuple(terms)


@dataclass(frozen=True, slots=True, eq=False)
class BaseParameters:
    """The identifiable base set of a robot's inertial parameters.

    Attributes
    ----------
    independent : ndarray of int, shape (r,)
        Columns of ``Y`` kept: base parameter ``k`` is ``phi[independent[k]]`` plus ...
    dependent : ndarray of int
        ... the columns regrouped into it ...
    combination : ndarray of shape (r, p - r)
        ... with these weights: ``beta = phi[independent] + combination @ phi[dependent]``.
    names : tuple of str
        ``link<i>.<parameter>`` of each base parameter's leading column.
    """

    independent: np.ndarray
    dependent: np.ndarray
    combination: FloatArray
    names: tuple[str, ...]

    @property
    def n(self) -> int:
        return int(self.independent.size)

    def project(self, phi: FloatArray) -> FloatArray:
        """Base parameters of full parameters ``phi`` (``(..., p)`` -> ``(..., r)``; ``p`` is ``10 n``,
        or ``11 n`` with the armature)."""
        out: FloatArray = phi[..., self.independent] + phi[..., self.dependent] @ self.combination.T
        return out

    def matrix(self) -> FloatArray:
        """``B`` of shape ``(r, p)`` with ``beta = B @ phi``."""
        n_phi = self.independent.size + self.dependent.size
        B = np.zeros((self.n, n_phi))
        B[np.arange(self.n), self.independent] = 1.0
        B[:, self.dependent] = self.combination
        return B


def parameter_names(n_joints: int, *, armature: bool = False) -> tuple[str, ...]:
    """``link<i>.<parameter>`` of the ``10 n`` inertial parameters, then ``joint<i>.armature``."""
    links = tuple(f"link{i + 1}.{p}" for i in range(n_joints) for p in PARAMETER_NAMES)
    return links + (tuple(f"joint{i + 1}.armature" for i in range(n_joints)) if armature else ())


def base_parameters(
    robot: Robot, *, armature: bool = False, samples: int = 40, seed: int = 0
) -> BaseParameters:
    """The base set of ``robot`` (structural: from random motions, cached per robot chain), of the
    inertial parameters and, when ``armature``, the armature (:func:`dynamic_regressor`)."""
    return _base_cached(_ChainKey(robot), samples, seed, armature)


class _ChainKey:
    """Hashable by the chain's geometry (base sets depend on kinematics, not on mass values)."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        c = robot.chain
        self._key = (c.placements.tobytes(), c.axes.tobytes(), c.gravity.tobytes())

    def __hash__(self) -> int:
        return hash(self._key)

    def __eq__(self, other: Any) -> bool:
        return isinstance(other, _ChainKey) and self._key == other._key


@cache
def _base_cached(key: _ChainKey, samples: int, seed: int, armature: bool) -> BaseParameters:
    robot = key.robot
    n = robot.n_joints
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (samples, n))
    qd = rng.normal(0.0, 2.0, (samples, n))
    qdd = rng.normal(0.0, 5.0, (samples, n))
    Y = dynamic_regressor(robot, q, qd, qdd, armature=armature)
    W = Y.reshape(-1, Y.shape[2])
    _, R, piv = scipy.linalg.qr(W, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    r = int(np.sum(d > RANK_TOLERANCE * d[0]))
    independent, dependent = piv[:r], piv[r:]
    K = scipy.linalg.solve_triangular(R[:r, :r], R[:r, r:])
    K[np.abs(K) < 1e-12] = 0.0
    names = parameter_names(n, armature=armature)
    return BaseParameters(
        independent=np.asarray(independent),
        dependent=np.asarray(dependent),
        combination=K,
        names=tuple(names[i] for i in independent),
    )


__all__ = [
    "BaseParameters",
    "FRICTION_TERMS",
    "PARAMETER_NAMES",
    "RANK_TOLERANCE",
    "armature_regressor",
    "base_parameters",
    "dynamic_regressor",
    "friction_regressor",
    "inertial_regressor",
    "parameter_names",
    "true_parameters",
]
