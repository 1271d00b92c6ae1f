"""The minimum-jerk (quintic, rest-to-rest) joint move: the controller-like default path."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import ArrayLike, FloatArray
from joulepath.errors import InvalidInput
from joulepath.units import SAMPLE_PERIOD


@dataclass(frozen=True, slots=True)
class Trajectory:
    """Sampled joint motion.

    Attributes
    ----------
    t : ndarray of shape (n_steps,)
        s, from 0 to the duration inclusive.
    q, qd, qdd : ndarray of shape (..., n_steps, n)
        rad, rad/s, rad/s².
    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.0


def sample_times(duration: float, dt: float = SAMPLE_PERIOD) -> FloatArray:
    """``0, dt, 2 dt, ..., duration`` (the last sample is exactly ``duration``).

    The duration must be a whole number of samples (to 1e-9 s) so that every
    sample has the same length ``dt``.
    """
    if not (np.isfinite(duration) and duration > 0):
        raise InvalidInput(f"duration must be a positive number of seconds, got {duration}")
    if not dt > 0:
        raise InvalidInput(f"dt must be positive, got {dt}")
    n = round(duration / dt)
    if n < 1 or abs(n * dt - duration) > 1e-9:
        raise InvalidInput(
            f"duration {duration} s is not a whole number of {dt} s samples; use e.g. {max(n, 1) * dt:.3f} s"
        )
    return np.arange(n + 1, dtype=np.float64) * float(dt)


def minimum_jerk(
    q_start: ArrayLike, q_end: ArrayLike, duration: float, *, dt: float = SAMPLE_PERIOD
) -> Trajectory:
    """Quintic rest-to-rest joint interpolation ``q0 + (qf - q0) s(t/T)``.

    ``s(x) = 10x³ - 15x⁴ + 6x⁵``: velocity and acceleration are zero at both ends.

    Parameters
    ----------
    q_start, q_end : array_like of shape (..., n)
    duration : float
        s, a whole number of samples.
    dt : float
        Sample period, s (default 0.025, the logs' 40 Hz).

    Examples
    --------
    >>> tr = minimum_jerk([0.0], [1.0], 1.0)
    >>> float(tr.q[-1, 0]), float(tr.qd[0, 0]), tr.q.shape
    (1.0, 0.0, (41, 1))
    """
    q0 = np.asarray(q_start, dtype=float)
    qf = np.asarray(q_end, dtype=float)
    if q0.shape != qf.shape or q0.ndim == 0:
        raise InvalidInput(f"q_start {q0.shape} and q_end {qf.shape} must have the same shape (..., n)")
    t = sample_times(duration, dt)
    x = t / duration
    s = x**3 * (10 - 15 * x + 6 * x**2)
    ds = 30 * x**2 * (1 - x) ** 2 / duration
    dds = 60 * x * (1 - x) * (1 - 2 * x) / duration**2
    delta = (qf - q0)[..., None, :]
    return Trajectory(
        t=t,
        q=q0[..., None, :] + delta * s[:, None],
        qd=delta * ds[:, None],
        qdd=delta * dds[:, None],
    )
