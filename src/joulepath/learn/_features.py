"""Model inputs: the thesis' raw features, or raw features plus the nominal physics.

``inputs="thesis"`` feeds a model the table's feature set (the 40 inputs of
Appendix F, or the 18 joint-only ones) unchanged. ``inputs="physics"`` (grey box)
adds, through :class:`PhysicsFeatures`, the per-joint mechanical energy the
*nominal* model predicts for the row (``|tau_i qd_i| dt``, their sum, ``tau_i qd_i
dt``, with ``tau = RNEA(q, qd, qdd)`` plus the nominal friction of
:data:`joulepath.dynamics.NOMINAL_FRICTION`) and the friction bases ``|qd_i| dt``,
``qd_i² dt``: the learned
model then only has to learn how the real robot departs from its nominal model
(friction, gear losses, mass errors). ``dt`` becomes an input in that case.

``inputs="kinematic"`` is for arms whose dynamics are unknown (no robot given): it adds,
through :class:`KinematicFeatures`, robot-free energy bases per joint: ``|qd_i| dt``
(Coulomb friction and gravity work at a constant torque), ``qd_i² dt`` (viscous
friction) and ``|qd_i qdd_i| dt`` (the power of accelerating an inertia); ``dt`` is an
input too. The raw inputs alone make a model learn ``|tau qd| dt``, a product of a
joint's torque and speed, from scratch; on real logs of an arm joulepath does not know
(the KUKA KR300 logs, runs held out) these bases generalize markedly better
(``benchmarks/learn_unknown_arm.py``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from joulepath._typing import FloatArray
from joulepath.data import feature_columns, joints_in
from joulepath.energy import joint_energy

INPUTS = ("thesis", "physics", "kinematic")
PHYSICS_VERSION = 2
"""Version of the physics inputs; a model card records it and loading refuses another."""


def n_physics_terms(n_joints: int) -> int:
    """Columns :func:`physics_transform` appends.

    Per-joint energy, its sum, signed energy, ``|qd| dt`` and ``qd² dt``.
    """
    return 4 * n_joints + 1


def n_kinematic_terms(n_joints: int) -> int:
    """Columns :func:`kinematic_transform` appends: ``|qd| dt``, ``qd² dt``, ``|qd qdd| dt`` per joint."""
    return 3 * n_joints


def input_columns(feature_set: str, inputs: str, n_joints: int, family: str | None = None) -> tuple[str, ...]:
    """Table columns a model reads, in order (a ``bases`` model reads ``dt`` on any inputs)."""
    base = feature_columns(feature_set, n_joints)
    return (*base, "dt") if inputs in ("physics", "kinematic") or family == "bases" else base


class PhysicsFeatures(TransformerMixin, BaseEstimator):  # type: ignore[misc]
    """Append the nominal model's per-joint energy terms to the raw inputs.

    Parameters
    ----------
    robot : str or None, default=None
        The robot of the data: a bundled robot's name, a named arm, a path to an
        .irml/.urdf file or a twin folder. Required: ``fit`` refuses None rather than
        guess a robot (another arm's dynamics would make meaningless inputs).
    columns : tuple of str or None
        Names of the input columns, in order; must contain ``q{i}``, ``dq{i}``,
        ``ddq{i}`` for i = 1..n and ``dt``, with n the robot's joint count. None: the
        physics inputs of ``full40`` for the robot's joint count.

    Raises
    ------
    ValueError
        From ``fit``: no robot, columns that do not match X, or columns of another
        number of joints than the robot has.
    """

    def __init__(self, robot: str | None = None, columns: tuple[str, ...] | None = None) -> None:
        self.robot = robot
        self.columns = columns

    def fit(self, X: Any, y: Any = None) -> PhysicsFeatures:
        X = validate_data(self, X, reset=True, dtype=np.float64)
        n = self._robot().n_joints
        cols = self.columns if self.columns is not None else input_columns("full40", "physics", n)
        if len(cols) != X.shape[1]:
            raise ValueError(f"X has {X.shape[1]} columns but `columns` names {len(cols)}")
        if joints_in(cols) != n:
            raise ValueError(
                f"the columns name {joints_in(cols)} joints, but robot {self.robot!r} has {n}; "
                "give the robot of the data"
            )
        need = [f"{p}{i}" for p in ("q", "dq", "ddq") for i in range(1, n + 1)] + ["dt"]
        missing = [c for c in need if c not in cols]
        if missing:
            raise ValueError(f"PhysicsFeatures needs columns {missing} among its inputs")
        self.index_ = {c: cols.index(c) for c in need}
        return self

    def _robot(self) -> Any:
        robot = getattr(self, "_robot_cache", None)
        if robot is None:
            from joulepath.dynamics import load_robot

            if self.robot is None:
                raise ValueError("PhysicsFeatures needs the robot of the data; give robot=<name or path>")
            robot = load_robot(self.robot)
            self._robot_cache = robot
        return robot

    def transform(self, X: Any) -> FloatArray:
        check_is_fitted(self, "index_")
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return physics_transform(np.asarray(X), self.index_, self._robot())

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state.pop("_robot_cache", None)
        return state

    def __sklearn_tags__(self) -> Any:
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        return tags


def physics_transform(X: FloatArray, index: dict[str, int], robot: Any) -> FloatArray:
    """The pure function behind :class:`PhysicsFeatures` (X of shape (n, n_inputs))."""
    j = range(1, joints_in(index) + 1)
    q = X[:, [index[f"q{i}"] for i in j]]
    qd = X[:, [index[f"dq{i}"] for i in j]]
    qdd = X[:, [index[f"ddq{i}"] for i in j]]
    dt = X[:, index["dt"]][:, None]
    tau = robot.inverse_dynamics(q, qd, qdd, friction=robot.friction)
    energy = joint_energy(tau, qd, dt[:, 0])  # the one definition: |tau_i qd_i| dt
    signed = joint_energy(tau, qd, dt[:, 0], mode="signed")
    out: FloatArray = np.concatenate(
        [X, energy, energy.sum(axis=1, keepdims=True), signed, np.abs(qd) * dt, qd * qd * dt],
        axis=1,
    )
    return out


def kinematic_transform(X: FloatArray, index: dict[str, int]) -> FloatArray:
    """The pure function behind :class:`KinematicFeatures` (X of shape (n, n_inputs)).

    Examples
    --------
    >>> X = np.array([[2.0, -3.0, 0.5]])
    >>> kinematic_transform(X, {"dq1": 0, "ddq1": 1, "dt": 2}).tolist()
    [[2.0, -3.0, 0.5, 1.0, 2.0, 3.0]]
    """
    j = range(1, sum(1 for name in index if name.startswith("dq")) + 1)
    qd = X[:, [index[f"dq{i}"] for i in j]]
    qdd = X[:, [index[f"ddq{i}"] for i in j]]
    dt = X[:, [index["dt"]]]
    out: FloatArray = np.concatenate([X, np.abs(qd) * dt, qd * qd * dt, np.abs(qd * qdd) * dt], axis=1)
    return out


class KinematicFeatures(TransformerMixin, BaseEstimator):  # type: ignore[misc]
    """Append robot-free energy bases per joint: ``|qd_i| dt``, ``qd_i² dt``, ``|qd_i qdd_i| dt``.

    For arms whose dynamics are unknown (see the module docstring).

    Parameters
    ----------
    columns : tuple of str or None
        Names of the input columns, in order; must contain ``dq{i}`` and ``ddq{i}``
        for i = 1..n and ``dt``. None: the kinematic inputs of the ``joint`` feature
        set of a six-joint arm.

    Raises
    ------
    ValueError
        From ``fit``: columns that do not match X, or that lack a speed, an
        acceleration or ``dt``.
    """

    def __init__(self, columns: tuple[str, ...] | None = None) -> None:
        self.columns = columns

    def fit(self, X: Any, y: Any = None) -> KinematicFeatures:
        X = validate_data(self, X, reset=True, dtype=np.float64)
        cols = self.columns if self.columns is not None else input_columns("joint", "kinematic", 6)
        if len(cols) != X.shape[1]:
            raise ValueError(f"X has {X.shape[1]} columns but `columns` names {len(cols)}")
        n = joints_in(cols)
        need = [f"{p}{i}" for p in ("dq", "ddq") for i in range(1, n + 1)] + ["dt"]
        missing = [c for c in need if c not in cols]
        if not n or missing:
            raise ValueError(f"KinematicFeatures needs columns {missing or need} among its inputs")
        self.index_ = {c: cols.index(c) for c in need}
        return self

    def transform(self, X: Any) -> FloatArray:
        check_is_fitted(self, "index_")
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return kinematic_transform(np.asarray(X), self.index_)

    def __sklearn_tags__(self) -> Any:
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        return tags
