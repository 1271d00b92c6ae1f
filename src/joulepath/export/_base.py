"""Exporters as plug-ins: one interface, one registry, the controller a robot declares.

An exporter turns a verified joint path into the files a robot controller runs::

    render(robot, trajectory, duration) -> {file name: text}

It checks the path against the robot's limits first and raises
:class:`~joulepath.errors.LimitViolation` instead of writing a program the robot
must not run. Adding an exporter takes two files: its module, and one
:func:`register_exporter` line in ``export/__init__.py``.

Which exporter a robot gets unless told otherwise is the controller it declares
(:func:`declared_controller`): ABB arms RAPID, Universal Robots URScript, any other
arm a ROS 2 ``JointTrajectory``. Asking for the program of another vendor's
controller (RAPID for a UR5) needs the exporter's name given explicitly and gives
a warning (:func:`select_exporter`).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.trajectory import Trajectory

Render = Callable[[Robot, Trajectory, float], dict[str, str]]


@dataclass(frozen=True, slots=True)
class Exporter:
    """A registered exporter.

    Attributes
    ----------
    name : str
        What ``--export`` takes.
    vendor : str
        The controller family it writes for (``"ABB"``, ``"Universal Robots"``) or
        ``"any"`` for a vendor-neutral format (ROS 2).
    files : tuple of str
        The file names :attr:`render` returns (fixed per exporter).
    description : str
        One line for the CLI help and the run's ``result.json``.
    render : callable
        ``render(robot, trajectory, duration) -> {file name: text}``; raises
        ``LimitViolation`` for a path outside the robot's limits.
    follows : {"samples", "via-points"}
        How the controller runs the program: ``"samples"``, it follows the given samples
        one by one (servoj, a JointTrajectory, a stream); ``"via-points"``, it plans its own
        motion through the samples it is given as via points (RAPID ``MoveAbsJ``), so the
        caller passes the via points the controller follows (:mod:`joulepath.optimize._execute`).
    """

    name: str
    vendor: str
    files: tuple[str, ...]
    description: str
    render: Render
    follows: str = "samples"


EXPORTERS: dict[str, Exporter] = {}
"""Every registered exporter by name (filled by ``export/__init__.py``)."""


def register_exporter(exporter: Exporter) -> Exporter:
    """Add an exporter to :data:`EXPORTERS` (a name is registered once)."""
    if exporter.name in EXPORTERS:
        raise InvalidInput(f"exporter {exporter.name!r} is registered twice")
    EXPORTERS[exporter.name] = exporter
    return exporter


def get_exporter(name: str) -> Exporter:
    """The exporter registered as ``name``; InvalidInput naming the registered ones otherwise."""
    try:
        return EXPORTERS[name]
    except KeyError:
        raise InvalidInput(f"unknown exporter {name!r}; use one of {', '.join(sorted(EXPORTERS))}") from None


_VENDOR_BY_NAME = (
    (re.compile(r"^(abb[_ -]?)?irb[_ -]?\d", re.I), "ABB"),
    (re.compile(r"^ur\d+e?($|[_ -])", re.I), "Universal Robots"),
    (re.compile(r"^(franka[_ -]?)?panda", re.I), "Franka Emika"),
)
_CONTROLLER_BY_VENDOR = {"ABB": "rapid", "Universal Robots": "urscript"}
DEFAULT_CONTROLLER = "ros2"
"""What an arm of a vendor without an exporter of its own gets."""


def robot_vendor(robot: Robot) -> str | None:
    """The robot's maker: its description's ``manufacturer``, else recognised from its name."""
    if robot.description is not None and robot.description.manufacturer:
        return robot.description.manufacturer.strip()
    for pattern, vendor in _VENDOR_BY_NAME:
        if pattern.search(robot.name):
            return vendor
    return None


def declared_controller(robot: Robot) -> str:
    """The exporter a robot's own controller runs: ``rapid`` (ABB), ``urscript`` (UR), else ``ros2``."""
    return _CONTROLLER_BY_VENDOR.get(robot_vendor(robot) or "", DEFAULT_CONTROLLER)


def select_exporter(robot: Robot, name: str | None = None) -> tuple[Exporter, str | None]:
    """The exporter for a robot and a warning to show, or None.

    ``name`` None: the robot's declared controller. An explicit ``name`` written
    for another vendor's controller is allowed, with a warning that says so.
    """
    chosen = get_exporter(name or declared_controller(robot))
    vendor = robot_vendor(robot)
    if chosen.vendor in ("any", vendor):
        return chosen, None
    return chosen, (
        f"{chosen.name} writes programs for {chosen.vendor} controllers, but {robot.name} is "
        f"{'made by ' + vendor if vendor else 'of an unknown make'}; its own controller takes "
        f"--export {declared_controller(robot)}"
    )


def refuse_foreign(robot: Robot, exporter: str, *, explicit: bool) -> str | None:
    """For a command that only writes ``exporter`` programs: refuse another vendor's robot.

    Returns the warning to print when ``explicit`` (the user named the exporter),
    raises InvalidInput otherwise.
    """
    _, warning = select_exporter(robot, exporter)
    if warning is not None and not explicit:
        raise InvalidInput(f"{warning}; pass --export {exporter} to write {exporter} programs for it anyway")
    return warning


def check_path(robot: Robot, q: FloatArray, qd: FloatArray | None, *, what: str) -> None:
    """Refuse (LimitViolation) a sampled path outside the joint ranges (and a coupled axis 3's own
    range, :meth:`~joulepath.dynamics.Robot.axes_outside`) or over a speed limit.

    ``q`` and ``qd`` have shape (n_steps, n); ``what`` names the file not written.
    """
    n = robot.n_joints
    if q.ndim != 2 or q.shape[1] != n or q.shape[0] < 2:
        raise InvalidInput(f"path must have shape (n_steps >= 2, {n}), got {q.shape}")
    if not np.all(np.isfinite(q)) or (qd is not None and not np.all(np.isfinite(qd))):
        raise InvalidInput(f"the path holds a value that is not a finite number; {what} is not written")
    lo, hi = robot.joint_ranges()
    bad = np.nonzero((q < lo - 1e-9) | (q > hi + 1e-9))
    if bad[0].size:
        k, j = int(bad[0][0]), int(bad[1][0])
        raise LimitViolation(
            f"sample {k}: joint {j + 1} at {np.degrees(q[k, j]):.2f} deg leaves its range "
            f"[{np.degrees(lo[j]):.1f}, {np.degrees(hi[j]):.1f}] deg; {what} is not written"
        )
    if robot.axis3_range is not None:  # a coupled axis 3 has a range of its own on the controller
        axes = robot.joints_to_axes(q)
        (lo3, hi3), a3 = robot.axis3_range, axes[:, 2]
        out = np.nonzero((a3 < lo3 - 1e-9) | (a3 > hi3 + 1e-9))[0]
        if out.size:
            k = int(out[0])
            raise LimitViolation(f"sample {k}: {robot.axes_outside(axes[k])}; {what} is not written")
    if qd is None:
        return
    vmax = robot.velocity_limit
    over = np.nonzero(np.abs(qd) > vmax * (1 + 1e-9))
    if over[0].size:
        k, j = int(over[0][0]), int(over[1][0])
        raise LimitViolation(
            f"sample {k}: joint {j + 1} speed {np.degrees(abs(qd[k, j])):.1f} deg/s exceeds its limit "
            f"{np.degrees(vmax[j]):.1f} deg/s; {what} is not written"
        )
