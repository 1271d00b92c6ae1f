"""The plan a stream follows: a run folder's sampled path, interpolated for the controller's 4 ms ticks.

A run folder of ``joulepath optimize`` holds ``path.csv``; one of ``joulepath cycle``
holds ``cycle_path.csv`` with the same columns: ``t, q1..qn, qd1..qdn, qdd1..qdn``
(s, rad, rad/s, rad/s²; 25 ms samples). Between samples the plan is a quintic
Hermite interpolant of (q, qd, qdd): positions, speeds and accelerations are those of
the samples at the samples, and continuous in between, so references at any
controller time are smooth.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot, load_robot
from joulepath.errors import InvalidInput, InvalidRobotDescription, LimitViolation

PLAN_FILES = ("path.csv", "cycle_path.csv")
"""The plan files a run folder may hold, in the order they are looked for."""
RESULT_FILE = "result.json"
"""The optimize run's summary: ``robot``, ``energy_default_J``, ``energy_optimized_J``, ``saved_pct``."""
CYCLE_RESULT_FILE = "cycle.json"
"""A cycle run's summary (``joulepath cycle``), read where there is no ``result.json``."""
CHECK_PERIOD = 0.004
"""s between the instants at which the interpolated plan is checked against the limits (EGM's 4 ms)."""


@dataclass(frozen=True, slots=True)
class Plan:
    """A sampled joint path, ``t`` from 0, with its quintic Hermite interpolant (:meth:`at`).

    Attributes
    ----------
    t : ndarray of shape (n_steps,)
        s, strictly increasing, ``t[0] == 0``.
    q, qd, qdd : ndarray of shape (n_steps, n)
        rad, rad/s, rad/s².
    source : str
        The file it was read from ("" when built in memory).
    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    source: str = ""

    @property
    def duration(self) -> float:
        """s from the first to the last sample."""
        return float(self.t[-1])

    @property
    def n_joints(self) -> int:
        """Joints per sample."""
        return int(self.q.shape[1])

    @property
    def start(self) -> FloatArray:
        """The first configuration, rad."""
        out: FloatArray = self.q[0]
        return out

    @property
    def end(self) -> FloatArray:
        """The last configuration, rad."""
        out: FloatArray = self.q[-1]
        return out

    @property
    def closed(self) -> bool:
        """Whether it ends where it starts (a cycle): repetitions need no return move."""
        return bool(np.allclose(self.start, self.end, rtol=0.0, atol=1e-9))

    def at(self, s: float | FloatArray) -> tuple[FloatArray, FloatArray]:
        """Position (rad) and speed (rad/s) at plan times ``s``, clamped to [0, duration].

        ``s`` scalar gives arrays of shape (n,); ``s`` of shape (m,) gives (m, n).
        """
        return hermite5(self.t, self.q, self.qd, self.qdd, s)

    def reversed(self) -> Plan:
        """The same path run backwards, from its end to its start in the same time."""
        return Plan(
            t=self.t[-1] - self.t[::-1],
            q=self.q[::-1].copy(),
            qd=-self.qd[::-1],
            qdd=self.qdd[::-1].copy(),
            source=f"{self.source} (reversed)" if self.source else "reversed",
        )


def hermite5(
    t: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray, s: float | FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Quintic Hermite interpolation of samples (t, q, qd, qdd) at ``s``: position and speed.

    On each interval of length h, with u in [0, 1], the interpolant matches q, qd and
    qdd at both ends (the six quintic Hermite basis functions). ``s`` outside
    ``[t[0], t[-1]]`` is clamped.

    Examples
    --------
    >>> t = np.array([0.0, 1.0]); q = np.array([[0.0], [1.0]]); z = np.zeros((2, 1))
    >>> pos, vel = hermite5(t, q, z, z, 0.5)
    >>> float(pos[0]), float(vel[0])
    (0.5, 1.875)
    """
    scalar = np.ndim(s) == 0
    x = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), t[0], t[-1])
    k = np.clip(np.searchsorted(t, x, side="right") - 1, 0, t.size - 2)
    h = (t[k + 1] - t[k])[:, None]
    u = ((x - t[k]) / h[:, 0])[:, None]
    u2, u3 = u * u, u * u * u
    u4, u5 = u3 * u, u3 * u2
    p0, p1 = q[k], q[k + 1]
    v0, v1 = qd[k] * h, qd[k + 1] * h
    a0, a1 = qdd[k] * h * h, qdd[k + 1] * h * h
    h00 = 1 - 10 * u3 + 15 * u4 - 6 * u5
    h10 = u - 6 * u3 + 8 * u4 - 3 * u5
    h20 = 0.5 * u2 - 1.5 * u3 + 1.5 * u4 - 0.5 * u5
    h21 = 0.5 * u3 - u4 + 0.5 * u5
    h11 = -4 * u3 + 7 * u4 - 3 * u5
    h01 = 10 * u3 - 15 * u4 + 6 * u5
    pos = h00 * p0 + h10 * v0 + h20 * a0 + h21 * a1 + h11 * v1 + h01 * p1
    d00 = -30 * u2 + 60 * u3 - 30 * u4
    d10 = 1 - 18 * u2 + 32 * u3 - 15 * u4
    d20 = u - 4.5 * u2 + 6 * u3 - 2.5 * u4
    d21 = 1.5 * u2 - 4 * u3 + 2.5 * u4
    d11 = -12 * u2 + 28 * u3 - 15 * u4
    d01 = 30 * u2 - 60 * u3 + 30 * u4
    vel = (d00 * p0 + d10 * v0 + d20 * a0 + d21 * a1 + d11 * v1 + d01 * p1) / h
    if scalar:
        return pos[0], vel[0]
    return pos, vel


def plan_file(folder: str | os.PathLike[str]) -> Path:
    """The plan file of a run folder (:data:`PLAN_FILES`).

    Raises
    ------
    InvalidInput
        ``folder`` is not a folder, or holds none of the plan files.
    """
    p = Path(folder)
    if not p.is_dir():
        raise InvalidInput(
            f"{p}: not a folder; give a run folder of `joulepath optimize` or `joulepath cycle`"
        )
    for name in PLAN_FILES:
        if (p / name).is_file():
            return p / name
    raise InvalidInput(
        f"{p}: holds neither {' nor '.join(PLAN_FILES)}; give a run folder of `joulepath optimize --out` "
        "or `joulepath cycle --out`"
    )


def read_plan(path: str | os.PathLike[str]) -> Plan:
    """Read a plan file (columns ``t, q1..qn, qd1..qdn, qdd1..qdn``).

    Raises
    ------
    InvalidInput
        Unreadable file, other columns, fewer than 2 rows, a value that is not a
        finite number, times that do not start at 0 or do not increase.
    """
    p = Path(path)
    try:
        lines = p.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as err:
        raise InvalidInput(f"{p}: cannot be read ({err})") from err
    if not lines:
        raise InvalidInput(f"{p}: is empty; expected a header t,q1..qn,qd1..qdn,qdd1..qdn and rows")
    head = [c.strip() for c in lines[0].split(",")]
    n = (len(head) - 1) // 3
    expected = ["t", *(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, n + 1))]
    if n < 1 or head != expected:
        raise InvalidInput(f"{p}: header {','.join(head)!r}; expected {','.join(expected)!r}")
    rows = [line for line in lines[1:] if line.strip()]
    try:
        data = np.array([[float(v) for v in row.split(",")] for row in rows], dtype=float)
    except ValueError as err:
        raise InvalidInput(f"{p}: a value is not a number ({err})") from err
    if data.ndim != 2 or data.shape[0] < 2 or data.shape[1] != len(head):
        raise InvalidInput(f"{p}: expected at least 2 rows of {len(head)} values each")
    if not np.all(np.isfinite(data)):
        row = int(np.nonzero(~np.all(np.isfinite(data), axis=1))[0][0])
        raise InvalidInput(f"{p}: row {row + 2} holds a value that is not a finite number")
    t = data[:, 0]
    if abs(t[0]) > 1e-9 or not np.all(np.diff(t) > 0):
        raise InvalidInput(f"{p}: times must start at 0 and increase row by row")
    return Plan(
        t=t - t[0],
        q=data[:, 1 : 1 + n],
        qd=data[:, 1 + n : 1 + 2 * n],
        qdd=data[:, 1 + 2 * n :],
        source=str(p),
    )


def read_run_result(folder: str | os.PathLike[str]) -> dict[str, Any]:
    """The run folder's ``result.json`` (or a cycle folder's ``cycle.json``) as a dict, or ``{}``
    when it has neither.

    Raises
    ------
    InvalidInput
        ``result.json`` exists but is not a JSON object.
    """
    p = Path(folder) / RESULT_FILE
    if not p.is_file():
        p = Path(folder) / CYCLE_RESULT_FILE
    if not p.is_file():
        return {}
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError) as err:
        raise InvalidInput(f"{p}: cannot be read as JSON ({err})") from err
    if not isinstance(data, dict):
        raise InvalidInput(f"{p}: expected a JSON object")
    return data


def run_robot(folder_robot: str | None, given: str | None) -> Robot:
    """The robot a stream checks its references against.

    ``given`` (the ``--robot`` argument) is loaded when set; ``folder_robot`` (the
    ``robot`` of ``result.json``: a robot's name, e.g. ``"IRB 120"``, or what
    :func:`~joulepath.dynamics.load_robot` takes) must then name the same robot.
    Without ``given`` the folder's robot is loaded: by what ``load_robot`` takes, else
    the bundled robot of that name.

    Raises
    ------
    InvalidInput
        Neither names a robot, the folder's robot is unknown, or the two disagree.
    """
    from joulepath.description import PRESETS

    if given:
        robot = load_robot(given)
        if folder_robot and folder_robot not in (given, robot.name):
            raise InvalidInput(
                f"the run folder's result.json is for robot {folder_robot!r}, but --robot {given} is "
                f"{robot.name!r}; stream a plan on the robot it was made for"
            )
        return robot
    if not folder_robot:
        raise InvalidInput(
            "the run folder names no robot (no result.json with a 'robot' key); name it with --robot"
        )
    if folder_robot in PRESETS:
        return load_robot(folder_robot)
    for name in PRESETS:
        robot = load_robot(name)
        if robot.name == folder_robot:
            return robot
    try:
        return load_robot(folder_robot)
    except InvalidRobotDescription as err:
        raise InvalidInput(f"the run folder's robot: {err}; name it with --robot") from err


def check_plan(plan: Plan, robot: Robot, *, period: float = CHECK_PERIOD) -> None:
    """Refuse a plan whose interpolated references leave a joint range or exceed a speed limit.

    Checked at every ``period`` of the plan and at its samples, before any reference
    is sent.

    Raises
    ------
    InvalidInput
        The plan has another joint count than the robot.
    LimitViolation
        A reference outside a joint's range or over its speed limit.
    """
    n = robot.n_joints
    if plan.n_joints != n:
        raise InvalidInput(f"{plan.source}: the plan has {plan.n_joints} joints, but {robot.name} has {n}")
    s = np.union1d(np.arange(0.0, plan.duration, period), plan.t)
    q, qd = plan.at(s)
    lo, hi = robot.joint_ranges()
    bad = np.nonzero((q < lo - 1e-9) | (q > hi + 1e-9))
    if bad[0].size:
        k, j = int(bad[0][0]), int(bad[1][0])
        raise LimitViolation(
            f"{plan.source}: at t = {s[k]:.3f} s joint {j + 1} would be at {math.degrees(q[k, j]):.2f} deg, "
            f"outside its range [{math.degrees(lo[j]):.1f}, {math.degrees(hi[j]):.1f}] deg; nothing is sent"
        )
    vmax = robot.velocity_limit
    over = np.nonzero(np.abs(qd) > vmax * (1 + 1e-9))
    if over[0].size:
        k, j = int(over[0][0]), int(over[1][0])
        raise LimitViolation(
            f"{plan.source}: at t = {s[k]:.3f} s joint {j + 1} would move at "
            f"{math.degrees(abs(qd[k, j])):.1f} deg/s, over its limit {math.degrees(vmax[j]):.1f} deg/s; "
            "nothing is sent"
        )
