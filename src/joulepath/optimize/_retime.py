"""Energy-optimal re-timing of a move along its fixed joint path (a ``MoveL`` keeps its line).

A move's geometry is a joint path ``q(s)``, ``s`` in [0, 1] (for a ``MoveL``: the TCP on
the straight line, the orientation by slerp; :class:`joulepath.sim.SegmentPath`). Only
its timing ``s(t)`` is chosen here; the speeddata's TCP speed is a bound, not a target.

Formulation (:func:`retime_on_path`)
------------------------------------
``s(t)`` is a clamped quintic B-spline on ``[0, T]`` (``N_COEFFICIENTS`` free control
points, uniform knots). Rest to rest fixes the first and last three control points
(0 and 1), so ``s``, ``ds/dt`` and ``d²s/dt²`` are 0 / 1, 0, 0 at the ends; the free
ones are kept non-decreasing (linear constraints), which makes ``s`` monotone. The
duration is exact by construction. Quintic: the joint jerk is continuous, so a jerk
limit can be kept on the 2.5 ms grid. Chain rule: ``qd = q'(s) ṡ``,
``qdd = q''(s) ṡ² + q'(s) s̈``.

The path dynamics are tabulated once along ``s`` (``TABLE_POINTS`` points): with
``q(s)`` fixed, the rigid-body torque is ``tau = m(s) s̈ + c(s) ṡ² + g(s)`` (``m = M q'``,
``c = M q'' + C(q, q') q'``, ``g`` the gravity), plus friction of ``q'(s) ṡ``. The energy
``Σ |tau · qd| dt`` on the 2.5 ms grid (a smoothed absolute value) and the limits
(joint speed, acceleration, jerk as the grid's own difference of accelerations, TCP
speed) are then cheap functions of ``(s, ṡ, s̈)`` at the grid points, which are linear
in the control points; their gradients are analytic. SciPy's SLSQP minimizes. The
start is the controller's own jerk-limited sin² profile (:mod:`joulepath.sim._profile`)
stretched to ``T``, fitted by the spline.

Whatever the search returns is measured anew: the joints from ``path.at(s)``, the
energy with :func:`joulepath.optimize._verify.energy_on_samples` on the fine grid and
the limits with :func:`check_limits` (and the TCP speed from the Jacobian). The result is
the better of the optimized timing and the sin² start (a feasible one before an
infeasible one), so it is never worse than the controller's profile at that duration.

Why this and not a convex ``b = ṡ²`` formulation over ``s``: the energy with |·| and
friction is not convex anyway, and piecewise-linear ``b(s)`` has a piecewise-constant
``s̈``, whose jumps break any jerk limit on the fine grid; the smooth spline keeps it.

The time-optimal bound (:func:`shortest_on_path`) is TOPP-RA (``toppra``, the
``motion`` extra), with joint speed and acceleration constraints and the TCP speed as
a bound on ``ṡ``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from scipy.interpolate import BSpline, CubicSpline
from scipy.optimize import minimize

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Friction, Robot, friction_derivative
from joulepath.energy import DEFAULT_MEASURE, Drivetrain, SmoothPower, check_measure, measure_power
from joulepath.errors import InvalidInput
from joulepath.optimize._verify import check_limits, energy_on_samples
from joulepath.sim import Profile, evaluate_profile, plan_profile
from joulepath.trajectory import Trajectory

FINE_DT = 0.0025
"""s, the longest step of the grid on which energy and limits are computed (the cycle's)."""
SAMPLE_DT = 0.025
"""s, the longest step of :attr:`Retimed.samples` (the logs' 40 Hz)."""
N_COEFFICIENTS = 12
"""Free control points of the timing spline ``s(t)`` (at least, with ``start="identity"``)."""
IDENTITY_KNOT_S = 0.05
"""s per free control point, at most, of the timing of a long path with ``start="identity"``."""
COARSE_FACTOR = 4
"""With ``start="identity"``: the first search's grid is this many times coarser than the fine one."""
COARSE_MARGIN = 0.01
"""... and keeps its limits this fraction below the checked ones (between its points they may rise)."""
COARSE_ITERATIONS = 40
"""SLSQP iterations, at most, of that first search (each round of new rows). Past them it mostly
crawled to its tolerance: measured on the bundled examples' re-timed segments (issue 36), 200 ->
40 took palletizing's 13 from 6.5 to 3.6 s of CPU and pick_and_place's 2 from 2.6 to 0.9 s, their
energy after the polish 153.164 -> 153.147 J and 37.0046 J both (20: 153.88 J; 30: 153.23 J; 60:
153.145 J in 4.3 s; preconditioning it as :mod:`joulepath.optimize._gradient` does took twice as long)."""
POLISH_ITERATIONS = 30
"""SLSQP iterations, at most, of the polish of that search on the fine grid."""
RESCUE_KNOT_S = 0.1
"""s per free control point of the fine-grid search that follows an infeasible polish."""
DEGREE = 5
"""Degree of the timing spline (quintic: continuous jerk)."""
TABLE_POINTS = 513
"""Points along ``s`` at which the path and its dynamics are tabulated for the search."""
TOPPRA_GRIDPOINTS = 401
"""Grid points along ``s`` of the TOPP-RA problem."""
MAX_ITERATIONS = 200
"""SLSQP iterations at most."""
MAX_STRETCHES = 8
"""With a jerk limit, :func:`shortest_on_path` stretches the sin² duration by 25 % this often at most."""
SCREEN_BAND = 0.5
"""A limit row enters the search's solve when its relative margin is below this (:func:`_search`)."""
MAX_ROUNDS = 4
"""Solves of :func:`_search`, at most, each with the rows the last one broke or neared added."""
FTOL = 1e-9
"""SLSQP's tolerance on the relative change of the energy (from the start's) that ends a search."""
FIRST_STEP = 0.01
"""The length of SLSQP's first step (its Hessian estimate starts as the identity) in the free control
points, to which :func:`_search` scales its objective (at the energy's own scale the steps were far
too long: SLSQP's first iterate had up to 5 times the start's energy, each round of new rows started so
again, and 4 of palletizing's 13 polishes ended infeasible and took the rescue search). Measured on
the bundled examples' re-timed segments (issue 36): palletizing's 13, CPU 17.5 -> 8.1 s, their
energy 153.29 -> 153.16 J, no rescue; 0.003 and 0.02 within 0.05 J of it, 0.001 slower."""
_EPS_POWER = 1e-3  # W: smoothing of |P| in the search's objective only
_MARGIN = 1e-3  # the search keeps its limits this fraction below the checked ones
_TCP_TOLERANCE = 1e-7  # relative excess of the TCP speed that still counts as held
_BOUND_STEP = 1e-6  # step along s of the central difference of a TCP speed bound per point


class JointPath(Protocol):
    """A joint path ``q(s)``, ``s`` in [0, 1]: ``at(s)`` (n,) -> ``q, dq/ds, d²q/ds²`` (n, joints)."""

    def at(self, s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]: ...


PathLike = JointPath | Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]
SpeedBound = float | Callable[[FloatArray], FloatArray]
"""A TCP speed bound (m/s): one number, or one per path point (``s`` (n,) -> (n,); ``inf`` where none)."""
STARTS = ("controller", "identity")
"""Where the search starts: the controller's sin² profile stretched to the duration, or ``s = t / T``
(the path's own timing, for a path that is itself a motion in ``T``)."""


@dataclass(frozen=True, slots=True)
class Retimed:
    """A move re-timed along its path.

    Attributes
    ----------
    duration : float
        s, exactly the one asked for.
    energy_J : float
        The motion energy on the measure asked for (``thesis``: ``Σ |tau · qd| dt``) on
        :attr:`fine` (J).
    fine : Trajectory
        The motion on a grid of at most 2.5 ms, its last sample at the end.
    samples : Trajectory
        The same motion on a grid of at most 25 ms.
    s : ndarray of shape (n_fine,)
        The path parameter at the times of :attr:`fine`.
    feasible : bool
        Every limit holds on :attr:`fine`.
    limit_excess : tuple of str
        The worst excess of each violated kind of limit, in words (empty when feasible).
    optimized : bool
        Whether the optimized timing was kept (False: the start was better).
    start_energy_J : float
        The energy of the start (``start``: the controller's sin² profile stretched to
        ``duration``, or the path's own timing).
    """

    duration: float
    energy_J: float
    fine: Trajectory
    samples: Trajectory
    s: FloatArray
    feasible: bool
    limit_excess: tuple[str, ...]
    optimized: bool
    start_energy_J: float


# --------------------------------------------------------------------------- path helpers
def _path_function(path: PathLike) -> Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]:
    at = getattr(path, "at", None)
    if callable(at):
        return at  # type: ignore[no-any-return]
    if callable(path):
        return path
    raise InvalidInput(
        f"path must have .at(s) -> (q, dq/ds, d²q/ds²) (like joulepath.sim SegmentPath) or be such a "
        f"callable, got {type(path).__name__}"
    )


def _tcp_offset(tcp: FloatArray | None) -> FloatArray:
    if tcp is None:
        return np.zeros(3)
    t = np.asarray(tcp, dtype=float)
    if t.shape != (4, 4):
        raise InvalidInput(f"tcp must be a 4x4 flange-to-TCP transform, got shape {t.shape}")
    return t[:3, 3].copy()


def tcp_velocity(robot: Robot, q: FloatArray, qd: FloatArray, tcp: FloatArray | None = None) -> FloatArray:
    """The TCP's linear velocity (m/s) in the base frame, (n_steps, n) -> (n_steps, 3).

    ``v = J_v qd + w x (R r)``: the geometric Jacobian at tool0 and the TCP offset ``r``.
    """
    offset = _tcp_offset(tcp)
    jac = robot.jacobian(q)
    v = np.einsum("kij,kj->ki", jac[:, :3], qd)
    w = np.einsum("kij,kj->ki", jac[:, 3:], qd)
    r = np.einsum("kij,j->ki", robot.fk(q).rotation, offset)
    out: FloatArray = v + np.cross(w, r)
    return out


@dataclass(frozen=True, slots=True, eq=False)
class _Table:
    """The path and its dynamics along ``s``, as one spline of columns (see the module docstring)."""

    spline: CubicSpline  # columns: q' | q'' | m | c | g | |dp/ds|
    n: int

    def eval(self, s: FloatArray) -> tuple[FloatArray, FloatArray]:
        return self.spline(s), self.spline(s, 1)


def _table(robot: Robot, at: Callable[..., Any], tcp: FloatArray | None) -> _Table:
    s = np.linspace(0.0, 1.0, TABLE_POINTS)
    q, q1, q2 = (np.asarray(a, dtype=float) for a in at(s))
    n = q.shape[1]
    zero = np.zeros_like(q)
    g = robot.inverse_dynamics(q, zero, zero)
    m = robot.inverse_dynamics(q, zero, q1) - g
    c = robot.inverse_dynamics(q, q1, q2) - g
    p1 = np.linalg.norm(tcp_velocity(robot, q, q1, tcp), axis=1)
    cols = np.concatenate([q1, q2, m, c, g, p1[:, None]], axis=1)
    return _Table(CubicSpline(s, cols, axis=0), n)


Law = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]
"""A timing: times (n,) -> ``s, ṡ, s̈`` (n,)."""


@dataclass(frozen=True, slots=True, eq=False)
class _Limits:
    """What a timing is measured against (validated at the public edge)."""

    friction: Friction | None
    amax: FloatArray
    jmax: FloatArray | None
    tcp_speed: SpeedBound | None
    tcp: FloatArray | None
    measure: str = DEFAULT_MEASURE
    drivetrain: Drivetrain = field(default_factory=Drivetrain)


def _bound_at(bound: SpeedBound, s: FloatArray) -> FloatArray:
    """The TCP speed bound (m/s) at the path points ``s``."""
    if callable(bound):
        return np.broadcast_to(np.asarray(bound(s), dtype=float), s.shape)
    return np.full(s.shape, float(bound))


def _motion(
    at: Callable[..., Any], s: FloatArray, sd: FloatArray, sdd: FloatArray, t: FloatArray
) -> Trajectory:
    q, q1, q2 = (np.asarray(a, dtype=float) for a in at(s))
    return Trajectory(t=t, q=q, qd=q1 * sd[:, None], qdd=q2 * (sd * sd)[:, None] + q1 * sdd[:, None])


def _grid(duration: float, dt: float) -> FloatArray:
    return np.linspace(0.0, duration, max(2, int(np.ceil(duration / dt - 1e-9)) + 1))


def _check_limits_arg(name: str, value: FloatArray | None, n: int, *, required: bool) -> FloatArray | None:
    if value is None:
        if required:
            raise InvalidInput(f"{name} is required (rad/s², one per joint)")
        return None
    arr = np.asarray(value, dtype=float)
    if arr.shape != (n,) or np.any(~(arr > 0)):
        raise InvalidInput(
            f"{name} must be {n} positive values (one per joint), got {np.array2string(arr, precision=3)}"
        )
    return arr


# --------------------------------------------------------------------------- the sin² start
def _peak_speed(at: Callable[..., Any]) -> FloatArray:
    _, q1, _ = at(np.linspace(0.0, 1.0, 33))  # as the controller (sim._timing.fastest_profile)
    out: FloatArray = np.abs(np.asarray(q1, dtype=float)).max(axis=0)
    return out


def controller_profile(
    robot: Robot,
    path: PathLike,
    *,
    acceleration_limit: FloatArray,
    jerk_limit: FloatArray | None = None,
    tcp_speed_limit: float | None = None,
    tcp: FloatArray | None = None,
) -> Profile:
    """The controller's fastest sin² profile of ``s`` on this path (as :func:`joulepath.sim` plans a move).

    The speed bound is the joints' speed limits over the largest ``|dq/ds|`` and the TCP
    speed limit over the path's TCP length; acceleration and jerk bounds likewise.
    """
    at = _path_function(path)
    peak = _peak_speed(at)
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    moving = peak > 1e-9
    if not moving.any():
        raise InvalidInput("the path does not move (dq/ds is 0 everywhere); nothing to time")
    bounds = [float(np.min(vmax[moving] / peak[moving]))]
    if tcp_speed_limit is not None:
        s = np.linspace(0.0, 1.0, 129)
        q, q1, _ = at(s)
        speed = np.linalg.norm(tcp_velocity(robot, np.asarray(q), np.asarray(q1), tcp), axis=1)
        length = float(np.trapezoid(speed, s))
        if length > 1e-9:
            bounds.append(tcp_speed_limit / length)
    amax = np.asarray(acceleration_limit, dtype=float)
    jmax = np.full(peak.shape, np.inf) if jerk_limit is None else np.asarray(jerk_limit, dtype=float)
    return plan_profile(
        min(bounds), float(np.min(amax[moving] / peak[moving])), float(np.min(jmax[moving] / peak[moving]))
    )


def _stretched(profile: Profile, duration: float) -> Profile:
    k = duration / profile.duration
    return Profile(ta=profile.ta * k, tc=profile.tc * k, v=profile.v / k)


# --------------------------------------------------------------------------- the timing spline
@dataclass(frozen=True, slots=True, eq=False)
class _Timing:
    """``s(t) = B(t) c``: the basis (and its derivatives) on a grid, and the fixed control points."""

    knots: FloatArray
    n_ctrl: int
    lo_values: FloatArray  # the first control points (0 for a start at rest)
    hi_values: FloatArray  # the last ones (1 for an end at rest)

    @property
    def fixed_lo(self) -> int:
        return self.lo_values.size

    @property
    def fixed_hi(self) -> int:
        return self.hi_values.size

    @property
    def n_free(self) -> int:
        return self.n_ctrl - self.fixed_lo - self.fixed_hi

    def control(self, x: FloatArray) -> FloatArray:
        return np.concatenate([self.lo_values, x, self.hi_values])

    def fixed_part(self, basis: FloatArray) -> FloatArray:
        """The fixed control points' contribution to ``basis @ control`` (n_t,)."""
        out: FloatArray = (
            basis[:, : self.fixed_lo] @ self.lo_values
            + basis[:, self.n_ctrl - self.fixed_hi :] @ self.hi_values
        )
        return out

    def basis(self, t: FloatArray, nu: int) -> FloatArray:
        out: FloatArray = BSpline(self.knots, np.eye(self.n_ctrl), DEGREE)(t, nu)
        return out

    def evaluate(self, x: FloatArray, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        spl = BSpline(self.knots, self.control(x), DEGREE)
        return spl(t), spl(t, 1), spl(t, 2)


def _knots(duration: float, n_ctrl: int) -> FloatArray:
    n_inner = n_ctrl - DEGREE - 1
    inner = np.linspace(0.0, duration, n_inner + 2)[1:-1]
    return np.concatenate([np.zeros(DEGREE + 1), inner, np.full(DEGREE + 1, duration)])


def _timing(duration: float, start_at_rest: bool, end_at_rest: bool) -> _Timing:
    lo, hi = (3 if start_at_rest else 1), (3 if end_at_rest else 1)
    n_ctrl = N_COEFFICIENTS + lo + hi
    return _Timing(_knots(duration, n_ctrl), n_ctrl, np.zeros(lo), np.ones(hi))


def _identity_timing(duration: float, n_free: int, free: tuple[bool, bool] = (False, False)) -> _Timing:
    """``s(t)`` whose first and last three control points are those of ``s = t / duration`` (its
    Greville abscissae over ``duration``): ``s``, ``ṡ`` and ``s̈`` at both ends are the identity's.
    ``free``: at that end only ``s`` is fixed (a path at rest there stays at rest at any ``ṡ``)."""
    lo, hi = (1 if free[0] else 3), (1 if free[1] else 3)
    n_ctrl = n_free + lo + hi
    knots = _knots(duration, n_ctrl)
    greville = np.array([knots[k + 1 : k + DEGREE + 1].mean() for k in range(n_ctrl)]) / duration
    return _Timing(knots, n_ctrl, greville[:lo], greville[n_ctrl - hi :])


def _fit_start(timing: _Timing, t: FloatArray, s: FloatArray) -> FloatArray:
    """Least-squares control points of a given ``s(t)``, made non-decreasing within [0, 1]."""
    basis = timing.basis(t, 0)
    free = basis[:, timing.fixed_lo : timing.n_ctrl - timing.fixed_hi]
    rhs = s - timing.fixed_part(basis)
    x, *_ = np.linalg.lstsq(free, rhs, rcond=None)
    out: FloatArray = np.clip(np.maximum.accumulate(x), timing.lo_values[-1], timing.hi_values[0])
    return out


# --------------------------------------------------------------------------- the search's functions
@dataclass(frozen=True, slots=True, eq=False)
class _Search:
    """Energy and limits as functions of the free control points, with their gradients."""

    table: _Table
    friction: Friction | None
    dt: float
    b0: FloatArray  # basis and its derivatives at the grid, free columns only (n_t, n_free)
    b1: FloatArray
    b2: FloatArray
    off0: FloatArray  # the fixed control points' contribution (n_t,)
    off1: FloatArray
    off2: FloatArray
    vmax: FloatArray
    amax: FloatArray
    jmax: FloatArray | None
    tcp_speed: SpeedBound | None
    measure: str = DEFAULT_MEASURE
    drivetrain: Drivetrain = field(default_factory=Drivetrain)
    margin: float = _MARGIN  # the limits are kept this fraction below the checked ones
    # the last point's table values: SLSQP asks for the energy and the limits at each point apart
    _last: dict[bytes, dict[str, FloatArray]] = field(default_factory=dict)

    def state(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return self.b0 @ x + self.off0, self.b1 @ x + self.off1, self.b2 @ x + self.off2

    def _parts(self, x: FloatArray) -> dict[str, FloatArray]:
        key = np.asarray(x, dtype=float).tobytes()
        if key not in self._last:
            self._last.clear()
            self._last[key] = self._parts_at(x)
        return self._last[key]

    def _parts_at(self, x: FloatArray) -> dict[str, FloatArray]:
        s, sd, sdd = self.state(x)
        val, der = self.table.eval(np.clip(s, 0.0, 1.0))
        n = self.table.n
        cut = [val[:, k * n : (k + 1) * n] for k in range(5)]
        dcut = [der[:, k * n : (k + 1) * n] for k in range(5)]
        return {
            "s": s, "sd": sd, "sdd": sdd,
            "q1": cut[0], "q2": cut[1], "m": cut[2], "c": cut[3], "g": cut[4], "p1": val[:, 5 * n],
            "dq1": dcut[0], "dq2": dcut[1], "dm": dcut[2], "dc": dcut[3], "dg": dcut[4], "dp1": der[:, 5 * n],
        }  # fmt: skip

    def energy(self, x: FloatArray) -> tuple[float, FloatArray]:
        p = self._parts(x)
        sd, sdd = p["sd"][:, None], p["sdd"][:, None]
        qd = p["q1"] * sd
        tau = p["m"] * sdd + p["c"] * sd * sd + p["g"]
        fd = np.zeros_like(qd)
        if self.friction is not None:
            tau = tau + self.friction.torque(qd)
            fd = friction_derivative(self.friction, qd)
        # the measure's power (thesis: Σ |tau qd|), smoothed, and its derivatives
        power: SmoothPower = measure_power(self.measure, tau, qd, self.drivetrain, eps=_EPS_POWER)
        dqd_ds = p["dq1"] * sd
        dtau_ds = p["dm"] * sdd + p["dc"] * sd * sd + p["dg"] + fd * dqd_ds
        dtau_dsd = 2.0 * p["c"] * sd + fd * p["q1"]
        e_s = (power.d_tau * dtau_ds + power.d_qd * dqd_ds).sum(axis=1)
        e_sd = (power.d_tau * dtau_dsd + power.d_qd * p["q1"]).sum(axis=1)
        e_sdd = (power.d_tau * p["m"]).sum(axis=1)
        grad = self.dt * (e_s @ self.b0 + e_sd @ self.b1 + e_sdd @ self.b2)
        return float(self.dt * power.value.sum()), grad

    def _limit_blocks(self, x: FloatArray) -> list[_Block]:
        """The limit rows by block: (values, ∂/∂s, ∂/∂ṡ, ∂/∂s̈, lag), each (n_rows_t, k); a row's
        gradient in ``x`` is its partials times the basis rows at its point (``lag`` 1: a jerk row,
        the difference of that at its point and at the point before, the partials of both stacked
        (n_t, k) as the acceleration's, the values (n_t - 1, k))."""
        p = self._parts(x)
        sd, sdd = p["sd"][:, None], p["sdd"][:, None]
        lim = 1.0 - self.margin
        out: list[_Block] = []
        # joint speed: |q'| ṡ <= vmax (ṡ >= 0 by the monotone control points)
        a1 = np.abs(p["q1"]) / self.vmax
        zero = np.zeros_like(a1)
        out.append((lim - a1 * sd, -np.sign(p["q1"]) * p["dq1"] / self.vmax * sd, -a1, zero, 0))
        # acceleration: qdd = q'' ṡ² + q' s̈, both signs
        qdd = p["q2"] * sd * sd + p["q1"] * sdd
        d_s = p["dq2"] * sd * sd + p["dq1"] * sdd
        d_sd = 2.0 * p["q2"] * sd
        d_sdd = p["q1"]
        ja = (d_s / self.amax, d_sd / self.amax, d_sdd / self.amax)
        out.append((lim - qdd / self.amax, -ja[0], -ja[1], -ja[2], 0))
        out.append((lim + qdd / self.amax, ja[0], ja[1], ja[2], 0))
        if self.jmax is not None:  # the grid's own jerk: consecutive accelerations' difference / dt
            jerk = np.diff(qdd, axis=0) / self.dt / self.jmax
            c = self.dt * self.jmax
            jj = (d_s / c, d_sd / c, d_sdd / c)
            out.append((lim - jerk, -jj[0], -jj[1], -jj[2], 1))
            out.append((lim + jerk, jj[0], jj[1], jj[2], 1))
        if self.tcp_speed is not None:  # |dp/ds| ṡ <= bound(s)
            s = np.clip(p["s"], 0.0, 1.0)
            bound = _bound_at(self.tcp_speed, s)[:, None]
            v = p["p1"][:, None] / bound
            dv = p["dp1"][:, None] / bound
            if callable(self.tcp_speed):  # a bound per point: its slope along s by central differences
                lo, hi = np.clip(s - _BOUND_STEP, 0.0, 1.0), np.clip(s + _BOUND_STEP, 0.0, 1.0)
                slope = (_bound_at(self.tcp_speed, hi) - _bound_at(self.tcp_speed, lo)) / (hi - lo)
                dv = dv - v / bound * slope[:, None]
            out.append((lim - v * sd, -dv * sd, -v, np.zeros_like(v), 0))
        return out

    def constraints(self, x: FloatArray, rows: np.ndarray | None = None) -> tuple[FloatArray, FloatArray]:
        """``g(x) >= 0`` (relative margins to each limit) and its Jacobian: every row's value, and
        the Jacobian's rows ``rows`` (flat indices into ``g``; None: all)."""
        blocks = self._limit_blocks(x)
        g = _limit_values(blocks)
        return g, self.limit_jacobian(blocks, np.arange(g.size) if rows is None else rows)

    def limit_jacobian(self, blocks: list[_Block], rows: np.ndarray) -> FloatArray:
        """The Jacobian's rows ``rows`` (flat indices into the values) of :meth:`_limit_blocks`' rows:
        each row's partials times the basis at its point, not the whole grid's (a solve carries few
        of its rows)."""
        rows = np.asarray(rows, dtype=int)
        jac = np.empty((rows.size, self.b0.shape[1]))
        start = 0
        for val, ds, dsd, dsdd, lag in blocks:
            sel = (rows >= start) & (rows < start + val.size)
            if sel.any():
                t, k = np.divmod(rows[sel] - start, val.shape[1])
                at = t + lag  # a jerk row: the later point of its pair
                jac[sel] = (
                    ds[at, k][:, None] * self.b0[at]
                    + dsd[at, k][:, None] * self.b1[at]
                    + dsdd[at, k][:, None] * self.b2[at]
                )
                if lag:
                    jac[sel] -= (
                        ds[t, k][:, None] * self.b0[t]
                        + dsd[t, k][:, None] * self.b1[t]
                        + dsdd[t, k][:, None] * self.b2[t]
                    )
            start += val.size
        return jac


_Block = tuple[FloatArray, FloatArray, FloatArray, FloatArray, int]
"""A block of limit rows (:meth:`_Search._limit_blocks`): values, partials in s, ṡ, s̈, lag."""


def _limit_values(blocks: list[_Block]) -> FloatArray:
    return np.concatenate([b[0].ravel() for b in blocks])


def _stop_past(deadline: float) -> None:
    """SLSQP's callback: stop at the current iterate once ``deadline`` has passed."""
    if time.perf_counter() > deadline:
        raise StopIteration


def _problem(
    robot: Robot,
    at: Callable[..., Any],
    timing: _Timing,
    t: FloatArray,
    limits: _Limits,
    margin: float = _MARGIN,
) -> _Search:
    """The search's functions for ``timing`` on the grid ``t``."""
    lo, hi = timing.fixed_lo, timing.n_ctrl - timing.fixed_hi
    bases = [timing.basis(t, nu) for nu in range(3)]
    return _Search(
        table=_table(robot, at, limits.tcp),
        friction=limits.friction,
        dt=float(t[1] - t[0]),
        b0=bases[0][:, lo:hi],
        b1=bases[1][:, lo:hi],
        b2=bases[2][:, lo:hi],
        off0=timing.fixed_part(bases[0]),
        off1=timing.fixed_part(bases[1]),
        off2=timing.fixed_part(bases[2]),
        vmax=np.asarray(robot.velocity_limit, dtype=float),
        amax=limits.amax,
        jmax=limits.jmax,
        tcp_speed=limits.tcp_speed,
        measure=limits.measure,
        drivetrain=limits.drivetrain,
        margin=margin,
    )


def _search(
    robot: Robot,
    at: Callable[..., Any],
    timing: _Timing,
    t: FloatArray,
    x0: FloatArray,
    limits: _Limits,
    *,
    margin: float = _MARGIN,
    maxiter: int = MAX_ITERATIONS,
    deadline: float | None = None,
) -> FloatArray:
    """SLSQP from ``x0`` (past ``deadline``, a ``time.perf_counter()``, it stops at its iterate), the
    limit rows taken lazily (:data:`SCREEN_BAND`, at most :data:`MAX_ROUNDS` solves).

    On one BLAS thread, as :func:`joulepath.optimize.optimize_spline`: its small dense linear algebra
    runs slower on a pool that competes for the same cores (measured on palletizing's 13 re-timed
    segments without ``OMP_NUM_THREADS`` set, as ``joulepath cycle`` runs them on 2 logical CPUs:
    8.5 -> 3.6 s of CPU, the whole plan 15.7 -> 10.3 s; issue 36)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _search_on_one_thread(
            robot, at, timing, t, x0, limits, margin=margin, maxiter=maxiter, deadline=deadline
        )


def _search_on_one_thread(
    robot: Robot,
    at: Callable[..., Any],
    timing: _Timing,
    t: FloatArray,
    x0: FloatArray,
    limits: _Limits,
    *,
    margin: float,
    maxiter: int,
    deadline: float | None,
) -> FloatArray:
    problem = _problem(robot, at, timing, t, limits, margin)
    n = x0.size
    order = np.zeros((n + 1, n))  # x_0 >= lo, x_{i+1} - x_i >= 0, hi - x_{n-1} >= 0 (the fixed neighbours)
    order[0, 0] = 1.0
    order[np.arange(1, n), np.arange(1, n)] = 1.0
    order[np.arange(1, n), np.arange(0, n - 1)] = -1.0
    order[n, n - 1] = -1.0
    shift = np.zeros(n + 1)
    shift[0] = -float(timing.lo_values[-1])
    shift[n] = float(timing.hi_values[0])
    e0, g0 = problem.energy(x0)
    scale = max(e0, 1e-6)
    # SLSQP's Hessian estimate starts as the identity: its first steps go the (scaled) gradient's
    # length, which at the energy's own scale is far too long, and the iterations go to the way
    # back. The objective scaled to a first step of FIRST_STEP; the tolerance with it
    # (the same relative change of the energy ends the search)
    stretch = float(np.linalg.norm(g0)) / scale / FIRST_STEP
    if not stretch > 0:
        stretch = 1.0
    scale *= stretch
    ftol = FTOL / stretch
    last: dict[bytes, tuple[list[_Block], FloatArray]] = {}  # SLSQP asks for g and its Jacobian apart

    def blocks_at(x: FloatArray) -> tuple[list[_Block], FloatArray]:
        key = np.asarray(x, dtype=float).tobytes()
        if key not in last:
            last.clear()
            blocks = problem._limit_blocks(x)
            last[key] = (blocks, _limit_values(blocks))
        return last[key]

    def values_at(x: FloatArray) -> FloatArray:
        return blocks_at(x)[1]

    def jacobian_at(x: FloatArray, r: np.ndarray) -> FloatArray:
        return problem.limit_jacobian(blocks_at(x)[0], r)

    # the limit rows enter lazily: those within SCREEN_BAND of their limit at the start, then
    # those the solve's result breaks or nears, re-solved from there (SLSQP's dense QP grows with
    # the rows: a fine grid holds thousands, of which few bind)
    x = np.asarray(x0, dtype=float)
    rows = np.flatnonzero(values_at(x) < SCREEN_BAND)
    for _ in range(MAX_ROUNDS):
        chosen = rows
        result = minimize(
            lambda x: tuple(v / scale for v in problem.energy(x)),
            x,
            jac=True,
            method="SLSQP",
            bounds=[(0.0, 1.0)] * n,
            constraints=[{"type": "ineq", "fun": lambda x: order @ x + shift, "jac": lambda x: order}]
            + (
                [
                    {
                        "type": "ineq",
                        "fun": lambda x, r=chosen: values_at(x)[r],
                        "jac": lambda x, r=chosen: jacobian_at(x, r),
                    }
                ]
                if chosen.size
                else []
            ),
            options={"maxiter": maxiter, "ftol": ftol},
            callback=None if deadline is None else lambda _: _stop_past(deadline),
        )
        x = np.asarray(result.x, dtype=float)
        g = values_at(x)
        if g.min() >= -1e-9 or (deadline is not None and time.perf_counter() > deadline):
            break
        grown = np.union1d(rows, np.flatnonzero(g < SCREEN_BAND))
        if grown.size == rows.size:  # what it breaks it already had: another solve would not help
            break
        rows = grown
    out: FloatArray = np.clip(np.asarray(result.x, dtype=float), 0.0, 1.0)
    return np.maximum.accumulate(out)


# --------------------------------------------------------------------------- verification
def _measure(
    robot: Robot,
    at: Callable[..., Any],
    law: Law,
    duration: float,
    limits: _Limits,
) -> tuple[float, Trajectory, FloatArray, tuple[str, ...]]:
    """Energy, fine motion, ``s`` and the limits' excesses (in words) of a timing."""
    t = _grid(duration, FINE_DT)
    s, sd, sdd = law(t)
    fine = _motion(at, np.clip(s, 0.0, 1.0), sd, sdd, t)
    energy = energy_on_samples(robot, fine, friction=limits.friction, measure=limits.measure)
    report = check_limits(
        robot, fine, friction=limits.friction, acceleration_limit=limits.amax, jerk_limit=limits.jmax
    )
    tcp_speed_limit, tcp = limits.tcp_speed, limits.tcp
    excess = [w.describe() for w in report.worst]
    if np.any(np.diff(s) < -1e-12):
        excess.append(f"the path parameter goes back by {float(-np.diff(s).min()):.2e}")
    if tcp_speed_limit is not None:
        speed = np.linalg.norm(tcp_velocity(robot, fine.q, fine.qd, tcp), axis=1)
        bound = _bound_at(tcp_speed_limit, np.clip(s, 0.0, 1.0))
        k = int(np.argmax(speed / bound))
        if speed[k] > bound[k] * (1.0 + _TCP_TOLERANCE):
            excess.append(
                f"TCP speed {1000 * speed[k]:.1f} mm/s at t = {t[k]:.3f} s against its limit "
                f"{1000 * bound[k]:.1f} mm/s ({100 * (speed[k] / bound[k] - 1):.1f} % over)"
            )
    return energy, fine, s, tuple(excess)


def retime_on_path(
    robot: Robot,
    path: PathLike,
    duration: float,
    *,
    acceleration_limit: FloatArray,
    jerk_limit: FloatArray | None = None,
    tcp_speed_limit: SpeedBound | None = None,
    tcp: FloatArray | None = None,
    friction: Friction | None = NOMINAL_FRICTION,
    start_at_rest: bool = True,
    end_at_rest: bool = True,
    energy_measure: str = DEFAULT_MEASURE,
    start: str = "controller",
    free_ends: tuple[bool, bool] = (False, False),
    deadline: float | None = None,
) -> Retimed:
    """The least-energy timing ``s(t)`` of a fixed joint path in exactly ``duration`` s.

    Parameters
    ----------
    robot : Robot
    path : object with ``at(s)``, or a callable ``s -> (q, dq/ds, d²q/ds²)``
        ``s`` of shape (n,) in [0, 1] to arrays of shape (n, n_joints), e.g.
        :class:`joulepath.sim.SegmentPath` (a ``MoveL``'s straight line).
    duration : float
        s, positive.
    acceleration_limit : ndarray of shape (n_joints,)
        rad/s² (:func:`joulepath.sim.acceleration_limit`).
    jerk_limit : ndarray of shape (n_joints,), optional
        rad/s³, checked as the fine grid's difference of accelerations.
    tcp_speed_limit : float or callable, optional
        m/s, the move's speeddata ``v_tcp`` (a bound, not a target); or a function of ``s`` (n,)
        -> (n,), a bound per path point (``inf`` where there is none), e.g. for a path through
        lines and joint moves.
    tcp : ndarray of shape (4, 4), optional
        Flange-to-TCP transform (m) for the TCP speed; tool0 if None.
    friction : Friction or None
        Added to the rigid-body torque in the energy (default: the nominal friction).
    start_at_rest, end_at_rest : bool
        Zero ``ṡ`` and ``s̈`` at that end (else both are free there).
    energy_measure : str
        The energy minimized and reported (:data:`joulepath.energy.MEASURES`; its motion energy,
        standby excluded: at a fixed duration the standby is the same for every timing).
    start : str
        Where the search starts (:data:`STARTS`), and the timing kept where the search finds
        nothing better: ``"controller"``, the controller's sin² profile stretched to
        ``duration``; ``"identity"``, ``s = t / duration``: the path's own timing, for a path
        that is a motion of this duration, whose position, speed and acceleration at both ends
        the new timing keeps (``s``, ``ṡ``, ``s̈`` there are the identity's; ``start_at_rest``
        and ``end_at_rest`` are then ignored), so that it fits between the motion's neighbours.
        The result is never worse than this start on the measure, and feasible whenever the start
        is.
    free_ends : (bool, bool)
        With ``start="identity"``: at that end only ``s`` is kept, ``ṡ`` and ``s̈`` are free (for
        a path at rest there, ``dq/ds = d²q/ds² = 0``, which then stays at rest).
    deadline : float, optional
        ``time.perf_counter()`` past which the search stops at its current iterate (what it has
        is measured as always; no further search starts).

    Returns
    -------
    Retimed
        ``feasible`` only after the limits were checked on the fine grid.

    Raises
    ------
    InvalidInput
        A duration that is not positive, limits of the wrong shape, a path that does not move.

    Examples
    --------
    >>> import joulepath
    >>> from joulepath.sim import acceleration_limit
    >>> robot = joulepath.load_robot("irb120")
    >>> dq = np.array([0.6, -0.4, 0.5, 0.0, 0.3, 0.0])
    >>> def line(s):  # a joint-space line from the home pose
    ...     return robot.home + s[:, None] * dq, np.tile(dq, (s.size, 1)), np.zeros((s.size, 6))
    >>> r = retime_on_path(robot, line, 1.0, acceleration_limit=acceleration_limit(robot, 0.25))
    >>> r.feasible, r.energy_J <= r.start_energy_J, float(r.s[-1])
    (True, True, 1.0)
    """
    if not (np.isfinite(duration) and duration > 0):
        raise InvalidInput(f"duration must be a positive number of seconds, got {duration}")
    if start not in STARTS:
        raise InvalidInput(f"start must be one of {', '.join(STARTS)}, got {start!r}")
    if tcp_speed_limit is not None and not callable(tcp_speed_limit) and not tcp_speed_limit > 0:
        raise InvalidInput(f"tcp_speed_limit must be positive (m/s), got {tcp_speed_limit}")
    at = _path_function(path)
    n = robot.n_joints
    amax = _check_limits_arg("acceleration_limit", acceleration_limit, n, required=True)
    assert amax is not None
    jmax = _check_limits_arg("jerk_limit", jerk_limit, n, required=False)
    check_measure(energy_measure, robot.drivetrain)
    limits = _Limits(friction, amax, jmax, tcp_speed_limit, tcp, energy_measure, robot.drivetrain)
    t = _grid(duration, FINE_DT)
    controller: Law
    if start == "identity":

        def controller(tt: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
            return tt / duration, np.full(tt.shape, 1.0 / duration), np.zeros(tt.shape)

    else:
        if callable(tcp_speed_limit):
            raise InvalidInput("a TCP speed bound per path point needs start='identity'")
        fastest = controller_profile(
            robot, path, acceleration_limit=amax, jerk_limit=jmax, tcp_speed_limit=tcp_speed_limit, tcp=tcp
        )
        profile = _stretched(fastest, duration)

        def controller(tt: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
            return evaluate_profile(profile, tt)

    e0, fine0, s0, excess0 = _measure(robot, at, controller, duration, limits)
    best: tuple[Law, float, Trajectory, FloatArray, tuple[str, ...]] = (controller, e0, fine0, s0, excess0)
    for timing, x in _searched(
        robot, at, duration, t, controller, limits, start, free_ends, (start_at_rest, end_at_rest), deadline
    ):

        def optimized(
            tt: FloatArray, timing: _Timing = timing, x: FloatArray = x
        ) -> tuple[FloatArray, FloatArray, FloatArray]:
            return timing.evaluate(x, tt)

        e1, fine1, s1, excess1 = _measure(robot, at, optimized, duration, limits)
        if (not excess1, -e1) > (not best[4], -best[1]):
            best = (optimized, e1, fine1, s1, excess1)
        if not excess1:
            break  # (the next is a rescue of an infeasible search)
    law, energy, fine, s, excess = best
    take_new = law is not controller
    ts = _grid(duration, SAMPLE_DT)
    ss, sds, sdds = law(ts)
    samples = _motion(at, np.clip(ss, 0.0, 1.0), sds, sdds, ts)
    return Retimed(
        duration=float(duration),
        energy_J=energy,
        fine=fine,
        samples=samples,
        s=s,
        feasible=not excess,
        limit_excess=excess,
        optimized=take_new,
        start_energy_J=e0,
    )


def _searched(
    robot: Robot,
    at: Callable[..., Any],
    duration: float,
    t: FloatArray,
    start: Law,
    limits: _Limits,
    kind: str,
    free_ends: tuple[bool, bool],
    rest: tuple[bool, bool],
    deadline: float | None = None,
) -> Iterator[tuple[_Timing, FloatArray]]:
    """The searches' timings, in turn, each to be measured (the caller stops at a feasible one).

    From the controller's profile: one search on the fine grid. From a motion's own timing
    (``"identity"``): a control point per :data:`IDENTITY_KNOT_S`, searched on a grid
    :data:`COARSE_FACTOR` times coarser within :data:`COARSE_MARGIN` of the limits
    (:data:`COARSE_ITERATIONS`), then polished
    on the fine grid (:data:`POLISH_ITERATIONS`); where that is not feasible, a control point per
    :data:`RESCUE_KNOT_S` searched on the fine grid (SLSQP's dense QP grows with the rows times
    the variables squared, so the fine grid takes the coarser spline)."""
    if kind != "identity":
        timing = _timing(duration, *rest)
        yield (
            timing,
            _search(robot, at, timing, t, _fit_start(timing, t, start(t)[0]), limits, deadline=deadline),
        )
        return
    timing = _identity_timing(
        duration, max(N_COEFFICIENTS, int(np.ceil(duration / IDENTITY_KNOT_S))), free_ends
    )
    coarse = _grid(duration, COARSE_FACTOR * FINE_DT)
    x = _search(
        robot,
        at,
        timing,
        coarse,
        _fit_start(timing, coarse, start(coarse)[0]),
        limits,
        margin=COARSE_MARGIN,
        maxiter=COARSE_ITERATIONS,
        deadline=deadline,
    )
    yield timing, _search(robot, at, timing, t, x, limits, maxiter=POLISH_ITERATIONS, deadline=deadline)
    if deadline is not None and time.perf_counter() > deadline:
        return
    timing = _identity_timing(
        duration, max(N_COEFFICIENTS, int(np.ceil(duration / RESCUE_KNOT_S))), free_ends
    )
    yield timing, _search(robot, at, timing, t, _fit_start(timing, t, start(t)[0]), limits, deadline=deadline)


# --------------------------------------------------------------------------- time-optimal bound
def _toppra() -> Any:
    try:
        import toppra
    except ImportError as err:
        raise ImportError(
            "shortest_on_path needs toppra (TOPP-RA); install joulepath's 'motion' extra: "
            "pip install 'joulepath[motion]'"
        ) from err
    return toppra


def shortest_on_path(
    robot: Robot,
    path: PathLike,
    *,
    acceleration_limit: FloatArray,
    jerk_limit: FloatArray | None = None,
    tcp_speed_limit: float | None = None,
    tcp: FloatArray | None = None,
) -> float:
    """The time-optimal duration (s) of a rest-to-rest motion along the path (TOPP-RA).

    Joint speed and acceleration limits and the TCP speed limit (m/s, a bound on ``ṡ``
    from ``|dp/ds|``) on ``TOPPRA_GRIDPOINTS`` points along ``s``. TOPP-RA's problem is of
    second order: with a ``jerk_limit`` the returned value is the shortest duration at
    which :func:`retime_on_path` is feasible, searched upwards from TOPP-RA's bound
    (bisection to 0.5 %, up to the controller's sin² duration).

    Raises
    ------
    ImportError
        toppra is missing (the ``motion`` extra).
    InvalidInput
        Limits of the wrong shape; a path TOPP-RA cannot parametrize.
    """
    toppra = _toppra()
    from toppra.constraint.linear_constraint import LinearConstraint

    at = _path_function(path)
    n = robot.n_joints
    amax = _check_limits_arg("acceleration_limit", acceleration_limit, n, required=True)
    jmax = _check_limits_arg("jerk_limit", jerk_limit, n, required=False)
    vmax = np.asarray(robot.velocity_limit, dtype=float)

    geometric: Any = toppra.interpolator.AbstractGeometricPath
    linear: Any = LinearConstraint

    class _Path(geometric):  # type: ignore[misc]
        def __call__(self, ss: Any, order: int = 0) -> FloatArray:
            arr = np.atleast_1d(np.asarray(ss, dtype=float))
            out: FloatArray = np.asarray(at(arr)[order], dtype=float)
            return out if np.ndim(ss) else out[0]

        @property
        def dof(self) -> int:
            return n

        @property
        def path_interval(self) -> FloatArray:
            return np.array([0.0, 1.0])

    class _TcpSpeed(linear):  # type: ignore[misc]
        """``|dp/ds| ṡ <= v``: a bound on ``x = ṡ²``."""

        def __init__(self) -> None:
            super().__init__()
            self.dof = n

        def compute_constraint_params(self, geom: Any, gridpoints: FloatArray, *args: Any, **kw: Any) -> Any:
            q, q1 = geom(gridpoints, 0), geom(gridpoints, 1)
            speed = np.linalg.norm(tcp_velocity(robot, q, q1, tcp), axis=1)
            upper = np.where(speed > 1e-12, (tcp_speed_limit / np.maximum(speed, 1e-12)) ** 2, 1e12)
            xbound = np.stack([np.zeros_like(upper), upper], axis=1)
            return None, None, None, None, None, None, xbound

    constraints = [
        toppra.constraint.JointVelocityConstraint(vmax),
        toppra.constraint.JointAccelerationConstraint(
            amax, discretization_scheme=toppra.constraint.DiscretizationType.Interpolation
        ),
    ]
    if tcp_speed_limit is not None:
        constraints.append(_TcpSpeed())
    grid = np.linspace(0.0, 1.0, TOPPRA_GRIDPOINTS)
    algo = toppra.algorithm.TOPPRA(constraints, _Path(), gridpoints=grid, solver_wrapper="seidel")
    _, sd, _ = algo.compute_parameterization(0.0, 0.0)
    if sd is None or np.any(~np.isfinite(sd)):
        raise InvalidInput("TOPP-RA found no parametrization of this path within the limits")
    sd = np.asarray(sd, dtype=float)
    bound = float(np.sum(2.0 * np.diff(grid) / (sd[1:] + sd[:-1])))
    if jmax is None:
        return bound
    kwargs: dict[str, Any] = {
        "acceleration_limit": amax, "jerk_limit": jmax, "tcp_speed_limit": tcp_speed_limit, "tcp": tcp
    }  # fmt: skip
    hi = controller_profile(robot, path, **kwargs).duration
    if retime_on_path(robot, path, bound, **kwargs).feasible:
        return bound
    lo = bound
    for _ in range(MAX_STRETCHES):
        if retime_on_path(robot, path, hi, **kwargs).feasible:
            break
        lo, hi = hi, hi * 1.25
    else:
        raise InvalidInput(
            f"no feasible timing of this path up to {hi:.3f} s within the jerk limit; check the path "
            "against the joint ranges and limits"
        )
    while hi - lo > 0.005 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if retime_on_path(robot, path, mid, **kwargs).feasible else (mid, hi)
    return hi
