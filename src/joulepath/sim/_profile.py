"""Jerk-limited point-to-point profile of a normalised path parameter s: 0 -> 1.

Velocity ramps are sin² shaped (acceleration continuous, jerk bounded), with a
constant-speed cruise between them::

    ds/dt = v sin²(pi tau / (2 ta))        0 <= tau < ta         (accelerate)
    ds/dt = v                              ta <= tau < ta + tc   (cruise)
    symmetric deceleration;                T = 2 ta + tc

The peak acceleration is ``pi v / (2 ta)`` and the peak jerk ``pi² v / (2 ta²)``
(the peak acceleration times ``pi / ta``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray


@dataclass(frozen=True, slots=True)
class Profile:
    """Ramp time ``ta``, cruise time ``tc`` and cruise speed ``v`` (1/s) of a unit move."""

    ta: float
    tc: float
    v: float

    @property
    def duration(self) -> float:
        return 2.0 * self.ta + self.tc


def plan_profile(v_max: float, a_max: float, j_max: float = np.inf) -> Profile:
    """Fastest profile with ``ds/dt <= v_max``, ``d²s/dt² <= a_max`` and ``d³s/dt³ <= j_max``.

    A ramp to speed ``v`` needs ``ta ≥ pi v / (2 a_max)`` (acceleration) and
    ``ta ≥ pi sqrt(v / (2 j_max))`` (jerk). Without room to cruise, the move is two
    ramps (``v ta = 1``) at the highest speed both allow.
    """
    ta = max(np.pi * v_max / (2.0 * a_max), np.pi * np.sqrt(v_max / (2.0 * j_max)))
    if v_max * ta <= 1.0:
        return Profile(ta=float(ta), tc=float(1.0 / v_max - ta), v=v_max)
    v = min(np.sqrt(2.0 * a_max / np.pi), np.cbrt(2.0 * j_max / np.pi**2))
    return Profile(ta=float(1.0 / v), tc=0.0, v=float(v))


def evaluate_profile(p: Profile, tau: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``s, ds/dt, d²s/dt²`` at times ``tau`` (clipped to [0, T]).

    A profile of no duration (a move to where the arm already is) is done at once:
    ``s = 1`` and no speed or acceleration at every time.
    """
    T = p.duration
    if not p.ta > 0.0:
        none = np.zeros_like(tau, dtype=float)
        return none + 1.0, none, none.copy()
    tau = np.clip(tau, 0.0, T)
    s = np.empty_like(tau)
    sd = np.empty_like(tau)
    sdd = np.empty_like(tau)
    w = np.pi / p.ta
    acc = tau < p.ta
    dec = tau > p.ta + p.tc
    cru = ~(acc | dec)
    x = tau[acc]
    s[acc] = p.v * (x / 2 - np.sin(w * x) / (2 * w))
    sd[acc] = p.v * np.sin(w * x / 2) ** 2
    sdd[acc] = p.v * w / 2 * np.sin(w * x)
    s[cru] = p.v * (p.ta / 2 + (tau[cru] - p.ta))
    sd[cru] = p.v
    sdd[cru] = 0.0
    y = T - tau[dec]
    s[dec] = 1.0 - p.v * (y / 2 - np.sin(w * y) / (2 * w))
    sd[dec] = p.v * np.sin(w * y / 2) ** 2
    sdd[dec] = -p.v * w / 2 * np.sin(w * y)
    return s, sd, sdd


def time_at_fraction(p: Profile, fraction: float) -> float:
    """The time at which ``s`` reaches ``fraction`` (bisection; s is monotone)."""
    lo, hi = 0.0, p.duration
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        s, _, _ = evaluate_profile(p, np.array([mid]))
        if s[0] < fraction:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
