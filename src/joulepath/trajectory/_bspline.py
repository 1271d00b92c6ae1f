"""Rest-to-rest B-spline shape: the representation the gradient optimizer searches.

Joint ``j`` follows the minimum-jerk move plus a clamped B-spline of degree ``k``
(default 5) on uniform knots about ``knot_spacing`` apart (default 0.05 s)::

    q_j(t) = q0_j (1 - s(t/T)) + qf_j s(t/T)  +  Σ_m c_mj N_m(t)

Only the interior control points are free: a clamped spline's value, first and
second derivative at each end depend on its first (last) three control points
alone, and those are held at zero, so every coefficient vector starts and ends at
rest exactly. The all-zero vector is the minimum-jerk move. With ``n`` intervals
there are ``n - 1`` free coefficients per joint (local support: each one bends the
path over ``k + 1`` intervals only).

The map from coefficients to ``q, qd, qdd`` on any time grid is linear: one
:class:`SplineBasis` holds its matrices, so a path, its derivatives and their
gradients with respect to the coefficients are matrix products.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.interpolate import BSpline

from joulepath._typing import ArrayLike, FloatArray
from joulepath.errors import InvalidInput
from joulepath.trajectory._minimum_jerk import Trajectory, minimum_jerk, sample_times
from joulepath.units import SAMPLE_PERIOD

DEFAULT_KNOT_SPACING = 0.05
"""s between knots of the shape spline (two 25 ms samples per interval)."""


@dataclass(frozen=True, slots=True)
class GridBasis:
    """``q = B c``, ``qd = Bd c``, ``qdd = Bdd c`` for the shape term on one time grid.

    ``t`` has shape (n_steps,); each matrix (n_steps, n_free).
    """

    t: FloatArray
    B: FloatArray
    Bd: FloatArray
    Bdd: FloatArray


@dataclass(frozen=True, eq=False)
class SplineBasis:
    """The rest-to-rest spline shape of one move's duration.

    Parameters
    ----------
    duration : float
        s, a whole number of samples ``dt``.
    knot_spacing : float
        Target s between knots; the duration is split into ``max(2, round(T / spacing))``
        equal intervals.
    degree : int
        3 to 7; 5 (default) keeps jerk continuous.
    dt : float
        Sample period of the paths it builds (default 0.025 s).

    Examples
    --------
    >>> import numpy as np
    >>> basis = SplineBasis(1.6, knot_spacing=0.1)
    >>> basis.n_intervals, basis.n_free
    (16, 15)
    >>> q0, qf = np.zeros(6), np.ones(6)
    >>> tr = basis.trajectory(np.zeros((basis.n_free, 6)), q0, qf)
    >>> bool(np.allclose(tr.q, minimum_jerk(q0, qf, 1.6).q))
    True
    """

    duration: float
    knot_spacing: float = DEFAULT_KNOT_SPACING
    degree: int = 5
    dt: float = SAMPLE_PERIOD

    def __post_init__(self) -> None:
        sample_times(self.duration, self.dt)  # validates duration and dt
        if not (np.isfinite(self.knot_spacing) and self.knot_spacing > 0):
            raise InvalidInput(f"knot_spacing must be a positive number of seconds, got {self.knot_spacing}")
        if not 3 <= self.degree <= 7:
            raise InvalidInput(f"degree must be 3..7, got {self.degree}")

    @property
    def n_intervals(self) -> int:
        return max(2, round(self.duration / self.knot_spacing))

    @property
    def n_free(self) -> int:
        """Free coefficients per joint."""
        return self.n_intervals + self.degree - 6

    @cached_property
    def knots(self) -> FloatArray:
        k = self.degree
        inner = np.linspace(0.0, self.duration, self.n_intervals + 1)
        return np.concatenate([np.zeros(k), inner, np.full(k, self.duration)])

    def grid(self, dt: float | None = None) -> GridBasis:
        """Basis matrices on the grid ``0, dt, ..., T`` (default: the sample period)."""
        step = self.dt if dt is None else dt
        t = sample_times(self.duration, step)
        n_ctrl = self.knots.size - self.degree - 1
        spline = BSpline(self.knots, np.eye(n_ctrl), self.degree, extrapolate=False)
        x = np.clip(t, 0.0, self.duration)
        mats = []
        for order in range(3):
            sp = spline if order == 0 else spline.derivative(order)
            m = np.nan_to_num(sp(x))
            mats.append(np.ascontiguousarray(m[:, 3 : n_ctrl - 3]))
        return GridBasis(t=t, B=mats[0], Bd=mats[1], Bdd=mats[2])

    def free_basis(self, times: ArrayLike, order: int = 0) -> FloatArray:
        """Rows of the shape term's ``order``-th derivative at arbitrary ``times`` in [0, T]: (k, n_free)."""
        t = np.asarray(times, dtype=float).ravel()
        if np.any(~np.isfinite(t)) or np.any(t < 0.0) or np.any(t > self.duration):
            raise InvalidInput(f"times must lie in [0, {self.duration:g}] s")
        n_ctrl = self.knots.size - self.degree - 1
        spline = BSpline(self.knots, np.eye(n_ctrl), self.degree, extrapolate=False)
        sp = spline if order == 0 else spline.derivative(order)
        return np.ascontiguousarray(np.nan_to_num(sp(t))[:, 3 : n_ctrl - 3])

    @cached_property
    def control_maps(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Linear maps from the free coefficients to the control points of q, qd and qdd.

        A B-spline lies in the convex hull of its control points (its basis is
        non-negative and sums to one), and its derivative is a B-spline of one degree
        less whose control points are differences of the original's. Bounding these
        control points therefore bounds ``q``, ``qd`` and ``qdd`` at every instant,
        not only on a grid. Shapes: (n_ctrl, n_free), (n_ctrl - 1, n_free),
        (n_ctrl - 2, n_free).
        """
        k, t = self.degree, self.knots
        n_ctrl = t.size - k - 1
        pad = np.zeros((n_ctrl, self.n_free))
        pad[3 : n_ctrl - 3] = np.eye(self.n_free)
        maps = [pad]
        current, deg, knots = pad, k, t
        for _ in range(2):
            rows = knots.size - deg - 2
            D = np.zeros((rows, rows + 1))
            for j in range(rows):
                span = knots[j + deg + 1] - knots[j + 1]
                D[j, j], D[j, j + 1] = -deg / span, deg / span
            current = D @ current
            maps.append(current)
            deg, knots = deg - 1, knots[1:-1]
        return maps[0], maps[1], maps[2]

    def minimum_jerk_control(self, q_start: ArrayLike, q_end: ArrayLike) -> tuple[FloatArray, ...]:
        """Control points of the minimum-jerk move's q, qd and qdd on this spline's knots.

        A quintic is exactly a B-spline of degree ≥ 5 on any knots; its control points
        come from a least-squares fit on a fine grid (exact to rounding).
        """
        if self.degree < 5:
            raise InvalidInput("the minimum-jerk move is a quintic: its control points need degree ≥ 5")
        t = sample_times(self.duration, self.duration / (8 * (self.n_intervals + self.degree)))
        n_ctrl = self.knots.size - self.degree - 1
        N = np.nan_to_num(BSpline(self.knots, np.eye(n_ctrl), self.degree, extrapolate=False)(t))
        mj = minimum_jerk(q_start, q_end, self.duration, dt=float(t[1]))
        P = np.linalg.lstsq(N, mj.q, rcond=None)[0]
        out = [P]
        deg, knots, cur = self.degree, self.knots, P
        for _ in range(2):
            rows = knots.size - deg - 2
            span = knots[deg + 1 : deg + 1 + rows] - knots[1 : 1 + rows]
            cur = deg * np.diff(cur, axis=0) / span[:, None]
            out.append(cur)
            deg, knots = deg - 1, knots[1:-1]
        return tuple(out)

    @cached_property
    def samples(self) -> GridBasis:
        """Basis on the sample grid (the one energies are summed over)."""
        return self.grid()

    def trajectory(
        self,
        coefficients: ArrayLike,
        q_start: ArrayLike,
        q_end: ArrayLike,
        *,
        dt: float | None = None,
    ) -> Trajectory:
        """The path of coefficients (n_free, n_joints) — or a population (P, n_free, n_joints)."""
        c = np.asarray(coefficients, dtype=float)
        if c.ndim not in (2, 3) or c.shape[-2] != self.n_free:
            raise InvalidInput(f"coefficients must have shape (..., {self.n_free}, n_joints), got {c.shape}")
        if not np.all(np.isfinite(c)):
            raise InvalidInput("coefficients must be finite")
        grid = self.samples if dt is None else self.grid(dt)
        base = minimum_jerk(q_start, q_end, self.duration, dt=self.dt if dt is None else dt)
        if base.q.shape[-1] != c.shape[-1]:
            raise InvalidInput(
                f"coefficients are for {c.shape[-1]} joints but the move has {base.q.shape[-1]}"
            )
        q = base.q + grid.B @ c
        qd = base.qd + grid.Bd @ c
        qdd = base.qdd + grid.Bdd @ c
        return Trajectory(t=grid.t, q=q, qd=qd, qdd=qdd)
