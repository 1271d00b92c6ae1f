"""Per-joint energy bases: a least-squares model of each joint's energy, summed (family ``bases``).

A joint's energy over a row is ``|tau_i qd_i| dt``. Two limits of it are linear in a few
robot-free bases of the joint's own motion:

* a torque that keeps one sign (a joint that holds a weight): ``|tau| |qd| dt`` with
  ``tau = g + J qdd + f_c sgn(qd) + ...``, so ``|qd| dt``, ``|qd| qdd dt`` and ``qd dt``;
* a torque that follows the motion (inertia and friction): ``tau qd dt``, so
  ``qd qdd dt``, ``|qd| dt`` and ``qd dt``.

:class:`JointEnergyBases` fits each joint's energy (``E1 .. En``, the table's per-joint
targets) by least squares on the four bases ``|qd_i| dt``, ``qd_i dt``, ``qd_i qdd_i dt``
and ``|qd_i| qdd_i dt`` of that joint (plus, with the grey-box physics inputs, the
nominal model's ``|tau_i qd_i| dt`` and ``tau_i qd_i dt`` of the joint), clips each
joint's prediction at zero (an energy is never negative) and sums them for ``E``. On the
real logs of an arm joulepath does not know (the KUKA KR300 logs, each run held out in
turn) it predicted the held-out moves' energies with R² 0.96-0.99, where the quick MLP
on the same inputs reached 0.53-0.88 (``benchmarks/unknown_arm.py``): it cannot leave the
span of the bases, so it does not extrapolate into poses the training runs never visited.

Fitted with the per-joint targets as a 2-D ``y`` (``(n_rows, n_joints)``; its
prediction is their sum), or with one joint's target (``joint`` set), or with ``E``
alone (1-D ``y``, ``joint`` None: one least squares on every joint's bases).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from joulepath._typing import FloatArray
from joulepath.data import joints_in

N_KINEMATIC_BASES = 4
"""Bases per joint from its own motion: ``|qd| dt``, ``qd dt``, ``qd qdd dt``, ``|qd| qdd dt``."""


def joint_bases(Z: FloatArray, columns: tuple[str, ...], inputs: str, joint: int) -> FloatArray:
    """The bases of joint ``joint`` (1-based) from a pipeline's transformed rows ``Z``.

    ``Z`` holds the input ``columns`` first, then (``inputs="physics"``) the physics
    terms of :func:`joulepath.learn.physics_transform` or (``"kinematic"``) those of
    :func:`joulepath.learn.kinematic_transform`.

    Examples
    --------
    >>> Z = np.array([[-2.0, 3.0, 0.5]])
    >>> joint_bases(Z, ("dq1", "ddq1", "dt"), "thesis", 1).tolist()
    [[1.0, -1.0, -3.0, 3.0]]
    """
    n_in = len(columns)
    qd = Z[:, columns.index(f"dq{joint}")]
    qdd = Z[:, columns.index(f"ddq{joint}")]
    dt = Z[:, columns.index("dt")]
    out = [np.abs(qd) * dt, qd * dt, qd * qdd * dt, np.abs(qd) * qdd * dt]
    if inputs == "physics":
        n = joints_in(columns)
        out += [Z[:, n_in + joint - 1], Z[:, n_in + n + 1 + joint - 1]]  # |tau qd| dt, tau qd dt
    return np.column_stack(out)


def _lstsq(B: FloatArray, y: FloatArray, alpha: float) -> FloatArray:
    """Ridge least squares on bases scaled to unit RMS (``alpha`` relative to that scale)."""
    scale = np.sqrt(np.mean(B * B, axis=0))
    scale[scale <= 0] = 1.0
    Bs = B / scale
    if alpha > 0:
        k = Bs.shape[1]
        Bs = np.vstack([Bs, np.sqrt(alpha * len(y)) * np.eye(k)])
        y = np.concatenate([y, np.zeros(k)])
    w, *_ = np.linalg.lstsq(Bs, y, rcond=None)
    out: FloatArray = w / scale
    return out


class JointEnergyBases(RegressorMixin, BaseEstimator):  # type: ignore[misc]
    """Each joint's energy by least squares on its energy bases; the sum for ``E``.

    Parameters
    ----------
    columns : tuple of str or None
        The input columns (before any physics or kinematic terms), in order; must hold
        ``dq{i}``, ``ddq{i}`` and ``dt``.
    inputs : {"thesis", "physics", "kinematic"}
        The inputs of the pipeline this model ends (``physics``: the nominal model's
        per-joint energies join the bases).
    joint : int or None
        Fit and predict one joint's energy (1-based); None: every joint's (2-D ``y``) or,
        with a 1-D ``y``, the total on all joints' bases.
    alpha : float
        Ridge penalty on the bases scaled to unit RMS (0: plain least squares).

    Attributes
    ----------
    coef_ : ndarray of shape (n_fits, n_bases)
        One row per fitted joint (or one row for a total fitted on all bases, flattened).
    joints_ : ndarray of int
        The joints of the rows of ``coef_`` (1-based); ``[0]`` for a total.
    """

    def __init__(
        self,
        columns: tuple[str, ...] | None = None,
        inputs: str = "kinematic",
        joint: int | None = None,
        alpha: float = 0.0,
    ) -> None:
        self.columns = columns
        self.inputs = inputs
        self.joint = joint
        self.alpha = alpha

    def _columns(self) -> tuple[str, ...]:
        if self.columns is None:
            raise ValueError("JointEnergyBases needs the input columns; give columns=(...)")
        cols = tuple(self.columns)
        n = joints_in(cols)
        need = [f"{p}{i}" for p in ("dq", "ddq") for i in range(1, n + 1)] + ["dt"]
        missing = [c for c in need if c not in cols]
        if not n or missing:
            raise ValueError(
                f"the bases family needs columns {missing or need} among its inputs (dt comes with "
                "the kinematic or physics inputs)"
            )
        return cols

    def fit(self, X: Any, y: Any) -> JointEnergyBases:
        cols = self._columns()
        X = validate_data(self, X, reset=True, dtype=np.float64)
        Y = np.asarray(y, dtype=np.float64)
        n = joints_in(cols)
        if Y.ndim == 2:
            if Y.shape[1] != n or self.joint is not None:
                raise ValueError(f"y holds {Y.shape[1]} columns; give one per joint ({n}) and no joint")
            joints = list(range(1, n + 1))
            self.coef_ = np.vstack(
                [_lstsq(joint_bases(X, cols, self.inputs, j), Y[:, j - 1], self.alpha) for j in joints]
            )
            self.joints_ = np.asarray(joints)
        elif self.joint is not None:
            if not 1 <= int(self.joint) <= n:
                raise ValueError(f"joint {self.joint} is not one of the {n} joints of the inputs")
            B = joint_bases(X, cols, self.inputs, int(self.joint))
            self.coef_ = _lstsq(B, Y, self.alpha)[None, :]
            self.joints_ = np.asarray([int(self.joint)])
        else:
            B = np.hstack([joint_bases(X, cols, self.inputs, j) for j in range(1, n + 1)])
            self.coef_ = _lstsq(B, Y, self.alpha)[None, :]
            self.joints_ = np.asarray([0])
        return self

    def predict(self, X: Any) -> FloatArray:
        check_is_fitted(self, "coef_")
        cols = self._columns()
        X = validate_data(self, X, reset=False, dtype=np.float64)
        if int(self.joints_[0]) == 0:
            B = np.hstack([joint_bases(X, cols, self.inputs, j) for j in range(1, joints_in(cols) + 1)])
            total: FloatArray = np.maximum(B @ self.coef_[0], 0.0)
            return total
        out = np.zeros(X.shape[0])
        for w, j in zip(self.coef_, self.joints_, strict=True):
            out += np.maximum(joint_bases(X, cols, self.inputs, int(j)) @ w, 0.0)
        return out

    def __sklearn_tags__(self) -> Any:
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.target_tags.multi_output = True
        return tags
