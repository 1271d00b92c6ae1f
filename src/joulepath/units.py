"""Units used by joulepath, in one place.

Inside the library everything is SI:

=================  ==========  ================================================
quantity           unit        notes
=================  ==========  ================================================
joint position     rad         ``q``; ABB's zero (q = 0 is the home pose)
joint velocity     rad/s       ``qd``
joint acceleration rad/s^2     ``qdd``
joint torque       N·m         ``tau``, what the drive must deliver
length, position   m           TCP position ``position_m``
mass               kg
inertia            kg·m^2      about the centre of mass
power              W           ``tau * qd`` per joint
energy             J           ``|tau * qd| * dt`` per sample and joint
time               s
=================  ==========  ================================================

The ABB controller's units (deg, deg/s, mm, quaternion with w first, EulerZYX in
deg) appear only at the boundary: controller logs and RAPID programs. The helpers
below are the only conversions the rest of the code uses.
"""

from __future__ import annotations

import math

DEG = math.pi / 180.0
"""One degree in radians: ``angle_rad = angle_deg * DEG``."""

MM = 1e-3
"""One millimetre in metres: ``length_m = length_mm * MM``."""

GRAVITY = 9.80665
"""Standard gravity in m/s^2 (acts along -z of the robot base frame)."""

SAMPLE_PERIOD = 0.025
"""Sampling period of the thesis' controller logs in s (40 Hz, ``WaitTime 0.025``)."""
