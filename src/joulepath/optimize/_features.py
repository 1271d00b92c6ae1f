"""Model inputs for whole populations of sampled paths, computed like ingestion computes them."""

from __future__ import annotations

import numpy as np

from joulepath._typing import FloatArray
from joulepath.data import FEATURES_FULL, FEATURES_JOINT, tcp_columns
from joulepath.dynamics import Robot
from joulepath.trajectory import Trajectory

_TCP = frozenset(FEATURES_FULL) - frozenset(FEATURES_JOINT)
"""The inputs that need the TCP pose (forward kinematics)."""


def _time_derivative(values: FloatArray, dt: float) -> FloatArray:
    """d/dt along axis 1 (time) of (P, n, k): central inside, one-sided at both ends."""
    out = np.empty_like(values)
    out[:, 1:-1] = (values[:, 2:] - values[:, :-2]) / (2 * dt)
    out[:, 0] = (values[:, 1] - values[:, 0]) / dt
    out[:, -1] = (values[:, -1] - values[:, -2]) / dt
    return out


def path_features(robot: Robot, traj: Trajectory, columns: tuple[str, ...]) -> FloatArray:
    """Rows of model inputs for every sample of every path.

    Joint signals come from the trajectory (analytic); TCP pose from forward
    kinematics; TCP velocities and accelerations, like the energy table's, are
    finite differences along each path at the sample period.

    Parameters
    ----------
    robot : Robot
    traj : Trajectory
        q, qd, qdd of shape (P, n_steps, n).
    columns : tuple of str
        Input names in the model's order (see ``EnergyModel.input_columns``).

    Returns
    -------
    ndarray of shape (P * n_steps, len(columns))
    """
    q, qd, qdd = traj.q, traj.qd, traj.qdd
    if q.ndim == 2:
        q, qd, qdd = q[None], qd[None], qdd[None]
    P, n, _ = q.shape
    dt = traj.dt
    cols: dict[str, FloatArray] = {"dt": np.full((P, n), dt)}
    for i in range(q.shape[-1]):
        cols[f"q{i + 1}"] = q[..., i]
        cols[f"dq{i + 1}"] = qd[..., i]
        cols[f"ddq{i + 1}"] = qdd[..., i]
    if _TCP.intersection(columns):
        pose = robot.fk(q)
        cols.update(
            tcp_columns(
                pose.position_m,
                pose.quaternion,
                np.unwrap(pose.euler_zyx, axis=1),
                lambda v: _time_derivative(v, dt),
            )
        )
    return np.stack([cols[c] for c in columns], axis=-1).reshape(P * n, len(columns))
