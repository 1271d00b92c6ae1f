"""Facts about the ABB controller used at the log and RAPID boundary (foundation).

Standard ``speeddata`` (TCP speed in mm/s, reorientation speed in deg/s) and
``zonedata`` (TCP zone radius in mm; ``fine`` is a stop point) as predefined in
RobotWare, restricted to the values the thesis' collection program uses
(Appendix D.1: 17 speeds, 14 zones).
"""

from __future__ import annotations

SPEEDS: dict[str, float] = {
    f"v{v}": float(v)
    for v in (
        100,
        150,
        200,
        300,
        400,
        500,
        600,
        800,
        1000,
        1500,
        2000,
        2500,
        3000,
        4000,
        5000,
        6000,
        7000,
    )
}
"""speeddata name -> v_tcp in mm/s."""

V_ORI_DEG_S = 500.0
"""Reorientation speed of the predefined speeddata v100..v7000, deg/s."""

ZONES: dict[str, float | None] = {
    "fine": None,
    "z0": 0.3,
    "z1": 1.0,
    "z5": 5.0,
    "z10": 10.0,
    "z20": 20.0,
    "z30": 30.0,
    "z40": 40.0,
    "z50": 50.0,
    "z60": 60.0,
    "z80": 80.0,
    "z100": 100.0,
    "z150": 150.0,
    "z200": 200.0,
}
"""zonedata name -> pzone_tcp in mm (None: a fine point, the robot stops)."""

EXTERNAL_AXES_UNUSED = "9E9"
"""The value RAPID uses for external axes that do not exist."""

VIA_ZONE_MM = 200.0
"""Zone (mm) of the via points joulepath writes inside an optimized move (``z200``): large, so
that the controller reduces it to half the distance to the neighbouring via points and keeps
speed through them (:mod:`joulepath.sim._via`)."""
