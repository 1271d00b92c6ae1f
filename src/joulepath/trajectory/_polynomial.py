"""Polynomial trajectories parametrized by a chromosome of coefficients (thesis §2.3, App. F).

A chromosome holds, per joint, six polynomial coefficients on the thesis' grid
(``GRID_LOW`` to ``GRID_HIGH`` in steps of ``GRID_STEP``). Two parametrizations map a
population of chromosomes onto joint paths between a fixed start and end configuration
over a fixed duration ``T``:

``rest_to_rest`` (the default)
    the minimum-jerk move plus a shape term that vanishes with its first two
    derivatives at both ends, so every chromosome starts and ends at rest exactly and
    the all-zero chromosome *is* the minimum-jerk ("default") path.
``thesis_quintic``
    the thesis' own parametrization: a quintic in ``t`` (seconds) per joint, affinely
    rescaled onto the start and end configuration, with velocities and accelerations
    rescaled consistently (the thesis rescaled positions only) and a documented rule
    for the degenerate rescale.

Both are vectorized over the population: one call returns ``q, qd, qdd`` of shape
``(n_pop, n_steps, n_joints)``.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BPoly

from joulepath._typing import ArrayLike, FloatArray
from joulepath.errors import InvalidInput
from joulepath.trajectory._minimum_jerk import Trajectory, sample_times
from joulepath.units import SAMPLE_PERIOD

GRID_LOW = -10.0
"""Smallest coefficient value of the thesis' search grid (§2.3.1)."""
GRID_HIGH = 10.0
"""Largest coefficient value of the thesis' search grid (§2.3.1)."""
GRID_STEP = 0.05
"""Spacing of the thesis' coefficient grid (§2.3.1): 401 values per coefficient."""

N_COEFFICIENTS = 6
"""Coefficients per joint (a quintic has six)."""

DEGENERATE_RTOL = 1e-6
"""``thesis_quintic`` treats a joint as degenerate when ``|p(T) - p(0)|`` is at most this
fraction of the polynomial's largest excursion ``max_t |p(t) - p(0)|``."""


def rest_to_rest(
    chromosomes: ArrayLike,
    q_start: ArrayLike,
    q_end: ArrayLike,
    duration: float,
    *,
    dt: float = SAMPLE_PERIOD,
    scale: float = 6.4,
) -> Trajectory:
    """Minimum-jerk move plus a rest-to-rest shape term set by the chromosome.

    With ``x = t / T`` and ``s(x) = 10x³ - 15x⁴ + 6x⁵`` (the minimum-jerk blend)::

        q_j(t) = q0_j (1 - s) + qf_j s  +  scale · x³(1 - x)³ · Σ_k c_jk x^k,   k = 0..5

    ``qd`` and ``qdd`` are the exact derivatives (chain rule with ``1/T`` and ``1/T²``).
    ``x³(1 - x)³`` and its first two derivatives vanish at ``x = 0`` and ``x = 1``, so
    every chromosome starts at ``q_start`` and ends at ``q_end`` with zero velocity and
    acceleration, exactly; the all-zero chromosome is the minimum-jerk path.

    Parameters
    ----------
    chromosomes : array_like of shape (n_pop, n_joints, 6) or (n_joints, 6)
        Coefficient ``c_jk`` of ``x^k`` for joint ``j``; any finite values (the optimizer
        keeps them on the grid ``GRID_LOW:GRID_STEP:GRID_HIGH``).
    q_start, q_end : array_like of shape (n_joints,)
        rad.
    duration : float
        ``T`` in s, a whole number of samples.
    dt : float
        Sample period in s (default 0.025, the logs' 40 Hz).
    scale : float
        rad per unit coefficient. ``x³(1 - x)³`` peaks at 1/64 at mid-time, so the
        default 6.4 makes a lone ``c_j0 = 10`` (the grid's edge) bend joint ``j`` by
        1 rad at ``t = T/2``, and one grid step (0.05) of ``c_j0`` moves it by 5 mrad.
        Random chromosomes on the grid give mid-time bulges of about 0.7 rad (s.d.).

    Returns
    -------
    Trajectory
        ``t`` of shape (n_steps,), ``q, qd, qdd`` of shape (n_pop, n_steps, n_joints),
        or (n_steps, n_joints) for a single chromosome.

    Raises
    ------
    InvalidInput
        On shapes that do not match, non-finite values, a non-positive ``scale`` or a
        duration that is not a whole number of samples.

    Examples
    --------
    >>> import numpy as np
    >>> tr = rest_to_rest(np.ones((4, 6, 6)), np.zeros(6), np.ones(6), 2.0)
    >>> tr.q.shape, float(tr.q[0, -1, 0]), float(tr.qd[0, -1, 0]), float(tr.qdd[3, 0, 5])
    ((4, 81, 6), 1.0, 0.0, 0.0)
    """
    if not (np.isfinite(scale) and scale > 0):
        raise InvalidInput(f"scale must be a positive number of rad per unit coefficient, got {scale}")
    c, q0, qf, single = _check_inputs("rest_to_rest", chromosomes, q_start, q_end)
    t = sample_times(duration, dt)
    x = _unit_time(t.size)
    s, ds, dds = _min_jerk_blend(x)

    # bump b(x) = u³ with u = x(1 - x): b' = 3u²u', b'' = 6u u'² + 3u² u'' (u' = 1 - 2x, u'' = -2)
    u = x * (1.0 - x)
    du = 1.0 - 2.0 * x
    b = (u**3)[:, None]
    db = (3.0 * u**2 * du)[:, None]
    ddb = (6.0 * u * du**2 - 6.0 * u**2)[:, None]
    xk, dxk, ddxk = (_power_basis(x, order) for order in (0, 1, 2))

    # q, qd, qdd are linear in (c_j0..c_j5, q0_j, qf_j): one basis of shape (3, n_steps, 8)
    # times the augmented chromosomes gives all three for every individual and joint
    basis = np.empty((3, x.size, N_COEFFICIENTS + 2))
    basis[0, :, :N_COEFFICIENTS] = scale * b * xk
    basis[1, :, :N_COEFFICIENTS] = (scale / duration) * (db * xk + b * dxk)
    basis[2, :, :N_COEFFICIENTS] = (scale / duration**2) * (ddb * xk + 2.0 * db * dxk + b * ddxk)
    basis[:, :, N_COEFFICIENTS] = np.stack([1.0 - s, -ds / duration, -dds / duration**2])
    basis[:, :, N_COEFFICIENTS + 1] = np.stack([s, ds / duration, dds / duration**2])
    q, qd, qdd = _evaluate(basis, _augment(c, q0, qf))
    return _trajectory(t, q, qd, qdd, single)


def thesis_quintic(
    chromosomes: ArrayLike,
    q_start: ArrayLike,
    q_end: ArrayLike,
    duration: float,
    *,
    dt: float = SAMPLE_PERIOD,
) -> Trajectory:
    """The thesis' quintic per joint, affinely rescaled onto start and end (App. F).

    Joint ``j`` follows ``p_j(t) = Σ_k a_jk t^k`` (``k = 0..5``) with ``t`` in **seconds**
    from 0 to ``T``, as the thesis' listing does (``x_values = np.linspace(0, time, 10)``),
    so a chromosome means what it meant in the thesis. The polynomial is mapped onto the
    move by the thesis' affine rescale, written as a blend so that both ends are exact::

        σ_j(t) = (p_j(t) - p_j(0)) / D_j,   D_j = p_j(T) - p_j(0)
        q_j    = q0_j (1 - σ_j) + qf_j σ_j
        qd_j   = p_j'(t)  (qf_j - q0_j) / D_j
        qdd_j  = p_j''(t) (qf_j - q0_j) / D_j

    Unlike the thesis listing, velocity and acceleration are rescaled with the position,
    so the three agree (THESIS_NOTES defect 1). Velocity and acceleration at the ends
    are whatever the polynomial gives: this parametrization does not start at rest.

    **Degenerate rescale.** When ``|D_j| <= 1e-6 · max_t |p_j(t) - p_j(0)|`` (this
    includes a constant polynomial, e.g. an all-zero row) the rescale would blow the path
    up by ``1e6`` or divide by zero. Such a joint instead keeps the polynomial's own
    excursion unscaled and covers the displacement with the minimum-jerk blend
    ``s(x) = 10x³ - 15x⁴ + 6x⁵``, ``x = t/T``::

        q_j = q0_j (1 - s) + qf_j s + (p_j(t) - p_j(0) - D_j s)

    which also hits ``q0_j`` and ``qf_j`` exactly; an all-zero row gives the
    minimum-jerk path.

    Parameters
    ----------
    chromosomes : array_like of shape (n_pop, n_joints, 6) or (n_joints, 6)
        ``a_jk``, the coefficient of ``t^k`` (t in s) for joint ``j``.
    q_start, q_end : array_like of shape (n_joints,)
        rad.
    duration : float
        ``T`` in s, a whole number of samples.
    dt : float
        Sample period in s (default 0.025).

    Returns
    -------
    Trajectory
        ``t`` of shape (n_steps,), ``q, qd, qdd`` of shape (n_pop, n_steps, n_joints),
        or (n_steps, n_joints) for a single chromosome.

    Raises
    ------
    InvalidInput
        On shapes that do not match, non-finite values or a duration that is not a
        whole number of samples.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.zeros((6, 6)); a[:, 1] = 1.0          # p(t) = t: a straight line
    >>> tr = thesis_quintic(a, np.zeros(6), np.full(6, 2.0), 1.0)
    >>> float(tr.q[20, 0]), float(tr.qd[0, 0]), float(tr.q[-1, 0])
    (1.0, 2.0, 2.0)
    """
    c, q0, qf, single = _check_inputs("thesis_quintic", chromosomes, q_start, q_end)
    t = sample_times(duration, dt)
    x = _unit_time(t.size)
    # t in seconds with exact end points, so that p(T) below is the same number as D's
    tau = x * duration
    basis = np.stack([_power_basis(tau, order) for order in (0, 1, 2)])
    p, dp, ddp = _evaluate(basis, c)  # each (n_pop, n_steps, n_joints), contiguous

    excursion = p - p[:, :1, :]  # p(t) - p(0)
    d = excursion[:, -1, :].copy()  # D = p(T) - p(0), shape (n_pop, n_joints)
    reach = np.abs(excursion).max(axis=1)
    degenerate = np.abs(d) <= DEGENERATE_RTOL * reach  # reach == 0 -> degenerate too
    d_safe = np.where(degenerate, 1.0, d)
    delta = qf - q0
    pop_idx, joint_idx = np.nonzero(degenerate)
    kept = [a[pop_idx, :, joint_idx].copy() for a in (excursion, dp, ddp)]  # (n_degenerate, n_steps)

    # q = q0 (1 - σ) + qf σ with σ = (p - p(0)) / D: exactly q0 and qf at the ends
    sigma = excursion
    sigma /= d_safe[:, None, :]
    q = qf * sigma
    np.subtract(1.0, sigma, out=sigma)
    sigma *= q0
    q += sigma
    ratio = (delta / d_safe)[:, None, :]
    qd = dp
    qd *= ratio
    qdd = ddp
    qdd *= ratio

    if pop_idx.size:
        s, ds, dds = _min_jerk_blend(x)
        exc, dp_k, ddp_k = kept
        d_k = d[pop_idx, joint_idx][:, None]
        gap = delta[joint_idx][:, None] - d_k
        q[pop_idx, :, joint_idx] = (
            q0[joint_idx][:, None] * (1.0 - s) + qf[joint_idx][:, None] * s + (exc - d_k * s)
        )
        qd[pop_idx, :, joint_idx] = gap * (ds / duration) + dp_k
        qdd[pop_idx, :, joint_idx] = gap * (dds / duration**2) + ddp_k
    return _trajectory(t, q, qd, qdd, single)


def _check_inputs(
    name: str, chromosomes: ArrayLike, q_start: ArrayLike, q_end: ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray, bool]:
    """Validate and return ``(c of shape (n_pop, n_joints, 6), q0, qf, single)``."""
    q0 = np.asarray(q_start, dtype=np.float64)
    qf = np.asarray(q_end, dtype=np.float64)
    if q0.ndim != 1 or q0.shape != qf.shape or q0.size == 0:
        raise InvalidInput(
            f"{name}: q_start {q0.shape} and q_end {qf.shape} must both have shape (n_joints,); "
            "pass one configuration each"
        )
    if not (np.all(np.isfinite(q0)) and np.all(np.isfinite(qf))):
        raise InvalidInput(f"{name}: q_start and q_end must be finite, got {q0} and {qf}")
    try:
        c = np.asarray(chromosomes, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise InvalidInput(f"{name}: chromosomes must be a numeric array, got {type(chromosomes)}") from err
    n = q0.size
    if c.ndim not in (2, 3) or c.shape[-2:] != (n, N_COEFFICIENTS):
        raise InvalidInput(
            f"{name}: chromosomes have shape {c.shape}, expected ({n}, {N_COEFFICIENTS}) for one "
            f"chromosome or (n_pop, {n}, {N_COEFFICIENTS}) for a population ({n} joints as in q_start)"
        )
    if not np.all(np.isfinite(c)):
        raise InvalidInput(f"{name}: chromosomes contain NaN or infinite coefficients")
    single = c.ndim == 2
    return (c[None] if single else c), q0, qf, single


def _unit_time(n_samples: int) -> FloatArray:
    """``x = t/T`` at the samples, exactly 0 and 1 at the ends."""
    return np.arange(n_samples, dtype=np.float64) / (n_samples - 1)


def _min_jerk_blend(x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``s(x) = 10x³ - 15x⁴ + 6x⁵`` and its first two x-derivatives (exactly 0 / 1 at the ends)."""
    s = x**3 * (10.0 - 15.0 * x + 6.0 * x**2)
    ds = 30.0 * x**2 * (1.0 - x) ** 2
    dds = 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x)
    return s, ds, dds


def _power_basis(x: FloatArray, order: int) -> FloatArray:
    """``d^order/dx^order`` of ``[1, x, ..., x^5]``, shape (n_steps, 6)."""
    k = np.arange(N_COEFFICIENTS)
    factor = np.ones(N_COEFFICIENTS)
    for i in range(order):
        factor = factor * (k - i)
    power = np.maximum(k - order, 0)
    out: FloatArray = factor * x[:, None] ** power
    return out


def _augment(c: FloatArray, q0: FloatArray, qf: FloatArray) -> FloatArray:
    """Chromosomes with ``q0_j`` and ``qf_j`` appended to each joint's coefficients."""
    n_pop, n_joints, _ = c.shape
    out = np.empty((n_pop, n_joints, N_COEFFICIENTS + 2))
    out[..., :N_COEFFICIENTS] = c
    out[..., N_COEFFICIENTS] = q0
    out[..., N_COEFFICIENTS + 1] = qf
    return out


def _evaluate(basis: FloatArray, coef: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``basis`` (3, n_steps, m) times ``coef`` (n_pop, n_joints, m) -> three (n_pop, n_steps, n_joints).

    One batched matrix product; each result is a contiguous block of one array.
    """
    out = np.matmul(basis[:, None], np.swapaxes(coef, -1, -2)[None])
    return out[0], out[1], out[2]


def _trajectory(t: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray, single: bool) -> Trajectory:
    if single:
        return Trajectory(t=t, q=q[0], qd=qd[0], qdd=qdd[0])
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd)


def quintic_hermite(t: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> BPoly:
    """The quintic Hermite interpolation of samples' positions, speeds and accelerations over ``t``
    (C², exact at the samples; its derivatives are the speeds and accelerations)."""
    return BPoly.from_derivatives(np.asarray(t, dtype=float), np.stack([q, qd, qdd], axis=1))
