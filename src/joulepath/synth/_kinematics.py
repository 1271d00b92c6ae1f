"""Physical consistency of synthetic rows: TCP columns against the forward kinematics of q.

In a real row the TCP pose is a function of the joint positions; a synthesizer
learns the columns separately and need not keep that function.
:func:`kinematic_consistency` measures how often it does, and
:func:`repair_kinematics` makes it so.

What :func:`repair_kinematics` recomputes from a row's ``q``, ``dq``, ``ddq``:

* ``x, y, z`` and ``qw, qx, qy, qz`` and ``yaw, pitch, roll``: the forward
  kinematics of ``q`` (quaternion with ``qw >= 0``, angles wrapped to (-pi, pi]),
  exactly as ingestion derives them from a generic log;
* ``dx, dy, dz``: the TCP linear velocity ``J_v(q) @ dq`` (geometric Jacobian);
* ``dphi, dtheta, dpsi`` (rates of yaw, pitch, roll): the angular velocity
  ``J_w(q) @ dq`` mapped to ZYX Euler-angle rates; undefined at the gimbal lock
  ``|pitch| = pi/2``, where the sampled values are kept;
* ``ddx, ddy, ddz`` and ``ddphi, ddtheta, ddpsi``: a synthetic row is a single
  instant, so nothing can be differenced across rows. The row's own joint state
  defines a local motion ``q(s) = q + dq s + ddq s^2 / 2``, and the second
  derivatives of its TCP position and Euler angles at ``s = 0`` are taken by a
  central difference with ``s = +-1 ms`` (this equals ``J ddq + dJ/dt dq`` up to
  ~1e-6 relative error, without forming ``dJ/dt``).

Left as sampled: the joint columns ``q, dq, ddq``, the energies (they need the
torques, which the table does not hold), ``dt``, ``t`` and ``move_id``. Real
tables take their derivative columns by finite differences over 25 ms samples
and carry sensor noise, so repaired derivative columns are smoother than real
ones; the position and orientation columns are exact.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from joulepath._typing import FloatArray
from joulepath.data import EnergyTable
from joulepath.description import DEFAULT_ROBOT
from joulepath.errors import InvalidInput

if TYPE_CHECKING:
    from joulepath.dynamics import Robot

TCP_TOLERANCE_M = 0.005
"""A row is kinematically consistent when its TCP position is within this distance of FK(q), m."""

"""Robot used when none is given."""

LOCAL_STEP_S = 1e-3
"""Half-width of the central difference along a row's local motion, s."""

_Q = tuple(f"q{i}" for i in range(1, 7))
_QD = tuple(f"dq{i}" for i in range(1, 7))
_QDD = tuple(f"ddq{i}" for i in range(1, 7))


def resolve_robot(robot: Robot | str | None) -> Robot:
    """The robot itself, the robot of that name, or :data:`DEFAULT_ROBOT` for None."""
    from joulepath.dynamics import Robot, load_robot

    if robot is None:
        return load_robot(DEFAULT_ROBOT)
    if isinstance(robot, str):
        return load_robot(robot)
    if not isinstance(robot, Robot):
        raise InvalidInput(f"robot must be a joulepath Robot or a robot name, got {type(robot).__name__}")
    return robot


def _check(table: EnergyTable, robot: Robot, *, where: str) -> None:
    if not isinstance(table, EnergyTable):
        raise InvalidInput(f"{where} expects an EnergyTable, got {type(table).__name__}")
    if table.feature_set != "full40":
        raise InvalidInput(
            f"{where}: the table has feature set {table.feature_set!r}, which has no TCP columns; "
            "only 'full40' tables can be checked or repaired"
        )
    if robot.n_joints != 6:
        raise InvalidInput(f"{where}: energy tables hold 6 joints, but {robot.name} has {robot.n_joints}")
    if table.robot is not None and table.robot != robot.name:
        raise InvalidInput(
            f"{where}: the table was recorded on {table.robot!r}, but the robot given is {robot.name!r}; "
            "pass the table's robot"
        )


def _joints(table: EnergyTable, names: tuple[str, ...]) -> FloatArray:
    out: FloatArray = table.frame[list(names)].to_numpy(dtype=float)
    return out


def tcp_error(table: EnergyTable, robot: Robot | str | None = None) -> FloatArray:
    """Distance between each row's TCP position ``(x, y, z)`` and ``FK(q)``.

    Parameters
    ----------
    table : EnergyTable
        A ``full40`` table.
    robot : Robot or str, optional
        The robot (or its name); default ``irb120``.

    Returns
    -------
    ndarray of shape (n_rows,)
        m.

    Raises
    ------
    InvalidInput
        A table without TCP columns, or recorded on another robot.
    """
    r = resolve_robot(robot)
    _check(table, r, where="tcp_error")
    pos = r.fk(_joints(table, _Q)).position_m
    logged = table.frame[["x", "y", "z"]].to_numpy(dtype=float)
    out: FloatArray = np.linalg.norm(pos - logged, axis=1)
    return out


def kinematic_consistency(
    table: EnergyTable, robot: Robot | str | None = None, *, tolerance_m: float = TCP_TOLERANCE_M
) -> float:
    """Share of rows whose TCP position is within ``tolerance_m`` of ``FK(q)``.

    Parameters
    ----------
    table : EnergyTable
        A ``full40`` table.
    robot : Robot or str, optional
        Default ``irb120``.
    tolerance_m : float
        Default 5 mm.

    Returns
    -------
    float in [0, 1]
        1.0 for real (ingested) tables, whose TCP columns come from the same pose.

    Raises
    ------
    InvalidInput
        As :func:`tcp_error`, or a tolerance that is not positive.
    """
    if not tolerance_m > 0:
        raise InvalidInput(f"tolerance_m must be > 0 (m), got {tolerance_m!r}")
    err = tcp_error(table, robot)
    return float(np.mean(err <= tolerance_m)) if err.size else float("nan")


def euler_zyx_rates(euler: FloatArray, omega: FloatArray) -> FloatArray:
    """ZYX Euler-angle rates from the angular velocity in the base frame.

    With ``R = Rz(a) Ry(b) Rx(c)`` the angular velocity is
    ``w = a' e_z + b' Rz(a) e_y + c' Rz(a) Ry(b) e_x``; this inverts that map.

    Parameters
    ----------
    euler : ndarray of shape (n, 3)
        ``(a, b, c)`` = (yaw about z, pitch about y, roll about x), rad.
    omega : ndarray of shape (n, 3)
        Angular velocity in the base frame, rad/s.

    Returns
    -------
    ndarray of shape (n, 3)
        ``(a', b', c')`` rad/s; NaN where ``cos b`` is below 1e-9 (gimbal lock).

    Examples
    --------
    >>> euler_zyx_rates(np.zeros((1, 3)), np.array([[0.1, 0.2, 0.3]])).round(6).tolist()
    [[0.3, 0.2, 0.1]]
    """
    a, b = euler[:, 0], euler[:, 1]
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    wx, wy, wz = omega[:, 0], omega[:, 1], omega[:, 2]
    ok = np.abs(cb) > 1e-9
    c_rate = np.where(ok, (ca * wx + sa * wy) / np.where(ok, cb, 1.0), np.nan)
    b_rate = -sa * wx + ca * wy
    a_rate = wz + sb * c_rate
    return np.stack([a_rate, b_rate, c_rate], axis=1)


def _wrap(angle: FloatArray) -> FloatArray:
    out: FloatArray = (angle + np.pi) % (2 * np.pi) - np.pi
    return out


def repair_kinematics(table: EnergyTable, robot: Robot | str | None = None) -> EnergyTable:
    """Recompute a table's TCP columns from its joint columns (see the module docstring).

    Parameters
    ----------
    table : EnergyTable
        A ``full40`` table, typically synthetic.
    robot : Robot or str, optional
        Default ``irb120``.

    Returns
    -------
    EnergyTable
        A new table (the input is not changed) whose rows all pass
        :func:`kinematic_consistency`; ``sources`` records the repair.

    Raises
    ------
    InvalidInput
        A table without TCP columns, or recorded on another robot.
    """
    r = resolve_robot(robot)
    _check(table, r, where="repair_kinematics")
    q, qd, qdd = (_joints(table, names) for names in (_Q, _QD, _QDD))
    frame = table.frame.copy()
    if len(frame) == 0:
        return EnergyTable(
            frame=frame, feature_set=table.feature_set, robot=table.robot, sources=table.sources
        )
    pose = r.fk(q)
    euler = pose.euler_zyx
    jac = r.jacobian(q)
    lin = np.einsum("nij,nj->ni", jac[:, :3, :], qd)
    omega = np.einsum("nij,nj->ni", jac[:, 3:, :], qd)
    rates = euler_zyx_rates(euler, omega)
    h = LOCAL_STEP_S
    ahead = r.fk(q + qd * h + qdd * (h * h / 2))
    behind = r.fk(q - qd * h + qdd * (h * h / 2))
    acc = (ahead.position_m - 2 * pose.position_m + behind.position_m) / (h * h)
    rate_acc = (_wrap(ahead.euler_zyx - euler) + _wrap(behind.euler_zyx - euler)) / (h * h)
    wrapped = _wrap(euler)
    for k, name in enumerate(("x", "y", "z")):
        frame[name] = pose.position_m[:, k]
        frame[f"d{name}"] = lin[:, k]
        frame[f"dd{name}"] = acc[:, k]
    quat = pose.quaternion
    for k, name in enumerate(("qw", "qx", "qy", "qz")):
        frame[name] = quat[:, k]
    for k, (name, dname) in enumerate((("yaw", "phi"), ("pitch", "theta"), ("roll", "psi"))):
        frame[name] = wrapped[:, k]
        sampled = frame[f"d{dname}"].to_numpy(dtype=float)
        frame[f"d{dname}"] = np.where(np.isfinite(rates[:, k]), rates[:, k], sampled)
        frame[f"dd{dname}"] = rate_acc[:, k]
    source = {"repaired_kinematics": r.name, "local_step_s": h}
    return EnergyTable(
        frame=frame, feature_set=table.feature_set, robot=table.robot, sources=(*table.sources, source)
    )


__all__ = [
    "DEFAULT_ROBOT",
    "TCP_TOLERANCE_M",
    "euler_zyx_rates",
    "kinematic_consistency",
    "repair_kinematics",
    "tcp_error",
]
