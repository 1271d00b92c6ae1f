"""The emulated controller's joint limits beyond the robot's own: acceleration and jerk.

ABB publishes joint speed limits but no acceleration or jerk limits. The emulated
controller (:mod:`joulepath.sim._controller`), the optimizer's constraints, the cycle's
plan and the written-program check all take theirs from here:

* acceleration limit ``a_max = v_max / accel_time`` (rad/s²): ``accel_time`` is the time
  a joint would take to reach its speed limit at full acceleration;
* jerk limit ``j_max = a_max / jerk_time`` (rad/s³): ``jerk_time`` is the time the
  acceleration would take to build up to its limit at full jerk.

Basis of the default ``JERK_TIME`` (the emulation's own ramps): the controller ramps
the speed with a sin² profile (:mod:`joulepath.sim._profile`), whose peak jerk is the
peak acceleration times ``pi / ta`` for a ramp of ``ta`` s. A joint that ramps to its
speed limit at its acceleration limit takes ``ta = pi v_max / (2 a_max) = pi accel_time / 2``,
so its peak jerk is ``a_max pi / ta = 2 a_max / accel_time``: ``jerk_time = accel_time / 2``
(0.125 s) is exactly the emulation's full-speed ramp. Shorter or slower moves would
reach the acceleration limit in a shorter ramp and jerk harder; the emulation stretches
those ramps to stay within ``j_max`` (:func:`joulepath.sim._profile.plan_profile`), so a
move's own profile never exceeds it (moves blended in a zone add up and may).
"""

from __future__ import annotations

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot

ACCEL_TIME = 0.25
"""s for a joint to reach its speed limit at full acceleration (``a_max = v_max / ACCEL_TIME``)."""

JERK_TIME = ACCEL_TIME / 2
"""s for a joint's acceleration to reach its limit at full jerk (``j_max = a_max / JERK_TIME``):
the peak jerk of the emulated controller's sin² ramp to full speed (module docstring)."""


def acceleration_limit(robot: Robot, accel_time: float) -> FloatArray | None:
    """``v_max / accel_time`` per joint (rad/s²), or None when ``accel_time`` is 0 (no limit).

    Examples
    --------
    >>> import joulepath
    >>> robot = joulepath.load_robot("irb120")
    >>> bool(np.allclose(acceleration_limit(robot, 0.25), robot.velocity_limit / 0.25))
    True
    >>> acceleration_limit(robot, 0.0) is None
    True
    """
    if accel_time <= 0:
        return None
    out: FloatArray = np.asarray(robot.velocity_limit, dtype=float) / accel_time
    return out


def jerk_limit(robot: Robot, accel_time: float, jerk_time: float) -> FloatArray | None:
    """``a_max / jerk_time`` per joint (rad/s³), or None when either time is 0 (no jerk limit).

    Without an acceleration limit there is no ramp for the jerk limit to shape, so
    ``accel_time = 0`` disables both.

    Examples
    --------
    >>> import joulepath
    >>> robot = joulepath.load_robot("irb120")
    >>> bool(np.allclose(jerk_limit(robot, 0.25, 0.125), robot.velocity_limit / 0.25 / 0.125))
    True
    >>> jerk_limit(robot, 0.25, 0.0) is None
    True
    """
    amax = acceleration_limit(robot, accel_time)
    if amax is None or jerk_time <= 0:
        return None
    out: FloatArray = amax / jerk_time
    return out
