"""The cycle optimum: several moves of one robot solved together by IPOPT, under one time budget.

The yardstick a cycle's optimized saving is measured against ("share of the optimum's
saving reached"). One direct transcription of every leg of the cycle, in the
representation of the single-move reference (:mod:`joulepath.optimize._reference`):
joint positions, speeds and accelerations at the nodes of each leg are the unknowns,
tied by a piecewise-constant jerk (an exact triple integrator, so the path between
nodes is a cubic), with the reference's CasADi inverse dynamics (``casadi_rnea``) and
friction. What the cycle adds:

* each leg is split at its vias into sub-legs of ``intervals`` intervals each, and each
  sub-leg's duration is an unknown: the time a via is passed is free, and the legs
  share the time budget (``Σ durations ≤ budget``, each leg within its own bounds);
* the nodes are shared at the vias, so position, speed, acceleration (the whole
  state of the transcription) are continuous there; a via is met exactly, or within
  a per-joint zone ``|q - via| ≤ radius``;
* every leg starts and ends at rest; joint ranges, speed, acceleration and jerk
  limits (when given) and effort limits (where the robot states them) hold at
  ``substeps`` points per interval, as in the single-move reference.

The objective is ``Σ |tau qd| dt`` with ``|p|`` smoothed as ``sqrt(p² + ε²) - ε``,
``ε`` driven towards zero by continuation.

Verified independently of the solve: each leg's cubic is resampled on a uniform grid
of at most ``FINE_DT`` (2.5 ms); the reported energy is :func:`energy_on_samples` of
that grid (the true, non-smooth metric, Pinocchio's inverse dynamics), and the limits
are :func:`check_limits` of it. ``feasible`` holds only when IPOPT converged and no
limit is exceeded on that grid by more than ``VERIFY_TOLERANCE``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Friction, Robot
from joulepath.errors import InvalidInput
from joulepath.optimize._reference import _casadi, _casadi_friction, casadi_rnea
from joulepath.optimize._verify import LimitReport, check_limits, energy_on_samples
from joulepath.trajectory import Trajectory

FINE_DT = 0.0025
"""s, the largest step of the grid each leg is verified on."""
VERIFY_TOLERANCE = 1e-4
"""Largest excess over a limit on the verification grid that still counts as held: relative
(speed, acceleration, jerk, effort) or rad (range). The solve enforces the limits at
``substeps`` points per interval; between them a speed may peak a sliver higher."""
SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
"""IPOPT's return statuses that count as converged."""
MIN_SUBLEG_S = 0.01
WARM_START: dict[str, Any] = {
    "warm_start_init_point": "yes",
    "mu_init": 1e-4,
    "warm_start_bound_push": 1e-6,
    "warm_start_mult_bound_push": 1e-6,
}
"""IPOPT options of each continuation stage after the first: start from the last stage's
point and multipliers (cuts the iterations of the late, sharp stages several times)."""
"""s, the shortest sub-leg the solve may choose (keeps the time steps positive)."""


@dataclass(frozen=True, slots=True)
class CycleLeg:
    """One move of the cycle: from rest at ``q_start`` through ``via`` (in order) to rest at ``q_end``.

    ``via_radius``: per via, per joint (rad, broadcast from a scalar), the zone the path
    passes the via in (``|q - via| ≤ radius`` at a free time; 0 = exactly). Empty: every
    via exactly. ``t_min``/``t_max``: bounds of the leg's duration (s).
    """

    q_start: FloatArray
    q_end: FloatArray
    via: tuple[FloatArray, ...] = ()
    via_radius: tuple[FloatArray, ...] = ()
    t_min: float = 0.0
    t_max: float = math.inf


@dataclass(frozen=True, slots=True)
class CycleOptimum:
    """The cycle's optimum, verified on a fine grid.

    ``energy_J`` and ``legs_energy_J``: ``Σ |tau qd| dt`` of ``paths`` (per leg, on a
    uniform grid of at most ``FINE_DT``); ``via_times_s``: per leg, the time (from the
    leg's start) each via is passed; ``limits``: per leg, :func:`check_limits` of its
    path; ``feasible``: IPOPT converged and every limit holds on ``paths`` (to
    ``VERIFY_TOLERANCE``); ``status``: IPOPT's last return status, or why it did not run.
    """

    durations: tuple[float, ...]
    energy_J: float
    legs_energy_J: tuple[float, ...]
    paths: tuple[Trajectory, ...]
    feasible: bool
    status: str
    wall_s: float
    via_times_s: tuple[tuple[float, ...], ...] = ()
    limits: tuple[LimitReport, ...] = ()


@dataclass(frozen=True, slots=True)
class _Leg:
    """A validated leg: its targets (start, vias, end) as rows, the via radii, the duration bounds."""

    targets: FloatArray  # (n_via + 2, n)
    radius: FloatArray  # (n_via, n)
    t_min: float
    t_max: float

    @property
    def n_sub(self) -> int:
        return int(self.targets.shape[0] - 1)


def _vector(value: Any, n: int, what: str) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise InvalidInput(f"{what} must be a finite vector of {n} joint values (rad), got shape {arr.shape}")
    return arr


def _check_legs(robot: Robot, legs: Sequence[CycleLeg], budget: float, intervals: int) -> list[_Leg]:
    n = robot.n_joints
    if not (isinstance(budget, (int, float)) and math.isfinite(budget) and budget > 0):
        raise InvalidInput(f"budget must be a positive, finite number of seconds, got {budget!r}")
    if not isinstance(intervals, int) or intervals < 1:
        raise InvalidInput(f"intervals must be a whole number ≥ 1, got {intervals!r}")
    if len(legs) == 0:
        raise InvalidInput("legs is empty; give at least one CycleLeg")
    out = []
    for i, leg in enumerate(legs):
        name = f"leg {i}"
        q0 = _vector(leg.q_start, n, f"{name} q_start")
        qf = _vector(leg.q_end, n, f"{name} q_end")
        via = [_vector(v, n, f"{name} via {k}") for k, v in enumerate(leg.via)]
        if leg.via_radius and len(leg.via_radius) != len(via):
            raise InvalidInput(
                f"{name} has {len(via)} vias but {len(leg.via_radius)} via_radius entries; "
                "give one per via or none"
            )
        radius = np.zeros((len(via), n))
        for k, r in enumerate(leg.via_radius):
            arr = np.asarray(r, dtype=float)
            if arr.ndim > 1 or arr.size not in (1, n) or not np.all(np.isfinite(arr)) or np.any(arr < 0):
                raise InvalidInput(
                    f"{name} via_radius {k} must be ≥ 0 rad, a scalar or one per joint ({n}), "
                    f"got {arr.tolist()}"
                )
            radius[k] = np.broadcast_to(arr, (n,))
        t_min, t_max = float(leg.t_min), float(leg.t_max)
        if not (math.isfinite(t_min) and t_min >= 0 and t_max > t_min):
            raise InvalidInput(f"{name} needs 0 ≤ t_min < t_max (s), got t_min={t_min}, t_max={t_max}")
        out.append(_Leg(targets=np.stack([q0, *via, qf]), radius=radius, t_min=t_min, t_max=t_max))
    return out


def _rest_to_rest_time(travel: float, v: float, a: float, j: float) -> float:
    """Shortest time of a rest-to-rest move of ``travel`` rad under speed, acceleration and jerk limits.

    The time-optimal profile of one joint (accelerate to a peak speed, cruise, brake
    symmetrically), ignoring the dynamics: a lower bound of any feasible duration.
    """
    if travel <= 0:
        return 0.0

    def ramp(vp: float) -> float:  # time to reach vp from rest under a and j
        if math.isinf(j):
            return vp / a if math.isfinite(a) else 0.0
        if math.isfinite(a) and vp >= a * a / j:
            return vp / a + a / j
        return 2.0 * math.sqrt(vp / j)

    if math.isinf(v):
        if math.isinf(a) and math.isinf(j):
            return 0.0
        v = 1e12
    if v * ramp(v) <= travel:  # reaches the speed limit: ramp, cruise, brake
        return 2.0 * ramp(v) + (travel - v * ramp(v)) / v
    lo, hi = 0.0, v  # the peak speed whose ramp up and down covers the travel
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid * ramp(mid) < travel else (lo, mid)
    return 2.0 * ramp(hi)


def leg_lower_bound(
    robot: Robot,
    leg: CycleLeg,
    *,
    acceleration_limit: FloatArray | None = None,
    jerk_limit: FloatArray | None = None,
) -> float:
    """A lower bound of the leg's duration (s): kinematics only, its ``t_min`` included.

    Per joint, the time-optimal rest-to-rest move from start to end, and the distance the
    joint must cover through the via zones at its speed limit; the largest over the joints.
    """
    n = robot.n_joints
    v = np.where(np.isfinite(robot.velocity_limit), np.asarray(robot.velocity_limit, dtype=float), np.inf)
    a = np.full(n, np.inf) if acceleration_limit is None else np.asarray(acceleration_limit, dtype=float)
    jk = np.full(n, np.inf) if jerk_limit is None else np.asarray(jerk_limit, dtype=float)
    pts = [
        np.asarray(leg.q_start, dtype=float),
        *map(np.asarray, leg.via),
        np.asarray(leg.q_end, dtype=float),
    ]
    radii = [np.broadcast_to(np.asarray(r, dtype=float), (n,)) for r in leg.via_radius] or [
        np.zeros(n) for _ in leg.via
    ]
    pad = [np.zeros(n), *radii, np.zeros(n)]
    # each joint's travel through the zones: at least |Δ| less both zones' radii, per sub-leg
    through = sum(
        np.maximum(np.abs(pts[k + 1] - pts[k]) - pad[k] - pad[k + 1], 0.0) for k in range(len(pts) - 1)
    )
    direct = np.abs(pts[-1] - pts[0])
    need = max(
        max(_rest_to_rest_time(float(direct[i]), v[i], a[i], jk[i]) for i in range(n)),
        float(np.max(np.asarray(through) / v)),
    )
    return max(need, float(leg.t_min))


def _minimum_jerk_nodes(
    q0: FloatArray, qf: FloatArray, duration: float, intervals: int
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The minimum-jerk rest-to-rest move at ``intervals + 1`` equally spaced nodes, (n, K) each."""
    x = np.linspace(0.0, 1.0, intervals + 1)
    s = x**3 * (10 - 15 * x + 6 * x**2)
    ds = 30 * x**2 * (1 - x) ** 2 / duration
    dds = 60 * x * (1 - x) * (1 - 2 * x) / duration**2
    d = (qf - q0)[:, None]
    return q0[:, None] + d * s, d * ds, d * dds


def _sub_bounds(robot: Robot, leg: _Leg, amax: FloatArray | None, jmax: FloatArray | None) -> FloatArray:
    """Per sub-leg, its rest-to-rest lower bound: the weights of the warm start's time split."""
    out = []
    for k in range(leg.n_sub):
        sub = CycleLeg(q_start=leg.targets[k], q_end=leg.targets[k + 1])
        out.append(leg_lower_bound(robot, sub, acceleration_limit=amax, jerk_limit=jmax))
    w: FloatArray = np.maximum(np.asarray(out, dtype=float), 1e-3)
    return w


def _warm_start(
    robot: Robot,
    legs: list[_Leg],
    budget: float,
    intervals: int,
    amax: FloatArray | None,
    jmax: FloatArray | None,
) -> list[tuple[FloatArray, FloatArray, FloatArray, FloatArray]]:
    """Per leg: node (Q, V, A) of shape (n, S·N + 1) and the sub-leg durations (S,).

    Each sub-leg is a minimum-jerk rest-to-rest move (stopping at the vias); the budget
    is split in proportion to each sub-leg's kinematic lower bound, each leg clipped to
    its own duration bounds.
    """
    weights = [_sub_bounds(robot, leg, amax, jmax) for leg in legs]
    total = float(sum(w.sum() for w in weights))
    out = []
    for leg, w in zip(legs, weights, strict=True):
        T = budget * w / total
        T = T * np.clip(T.sum(), leg.t_min, leg.t_max) / T.sum()
        T = np.maximum(T, 2 * MIN_SUBLEG_S)
        parts = [
            _minimum_jerk_nodes(leg.targets[k], leg.targets[k + 1], T[k], intervals) for k in range(leg.n_sub)
        ]
        Q = np.hstack([parts[0][0]] + [p[0][:, 1:] for p in parts[1:]])
        V = np.hstack([parts[0][1]] + [p[1][:, 1:] for p in parts[1:]])
        A = np.hstack([parts[0][2]] + [p[2][:, 1:] for p in parts[1:]])
        out.append((Q, V, A, T))
    return out


def _from_initial(
    leg: _Leg, path: Trajectory, intervals: int
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """A given path of the leg on the transcription's nodes; vias passed where it comes closest."""
    t = path.t
    q, qd, qdd = path.q, path.qd, path.qdd
    cuts = [0]
    for k in range(1, leg.n_sub):  # in order: the closest sample after the previous via
        lo = cuts[-1] + 1
        dist = np.max(np.abs(q[lo:] - leg.targets[k]), axis=1)
        cuts.append(lo + int(np.argmin(dist)) if dist.size else lo)
    cuts.append(t.size - 1)
    times = t[np.asarray(cuts)]
    T = np.maximum(np.diff(times), 2 * MIN_SUBLEG_S)
    nodes = np.concatenate(
        [
            times[k]
            + np.linspace(0.0, 1.0, intervals + 1)[: None if k == leg.n_sub - 1 else -1]
            * (times[k + 1] - times[k])
            for k in range(leg.n_sub)
        ]
    )
    interp = [np.stack([np.interp(nodes, t, m[:, i]) for i in range(m.shape[1])]) for m in (q, qd, qdd)]
    return interp[0], interp[1], interp[2], T


def _node_times(T: FloatArray, intervals: int) -> FloatArray:
    """Node times (S·N + 1,) of a leg whose sub-legs last ``T``."""
    h = np.repeat(np.asarray(T, dtype=float) / intervals, intervals)
    return np.concatenate([[0.0], np.cumsum(h)])


def resample_leg(
    Q: FloatArray, V: FloatArray, A: FloatArray, T: FloatArray, intervals: int, *, dt: float = FINE_DT
) -> Trajectory:
    """The transcription's piecewise cubic of one leg on a uniform grid of step at most ``dt``.

    ``Q``, ``V``, ``A``: nodes (n, S·N + 1); ``T``: sub-leg durations (S,). Each
    interval's jerk is the one that carries its start node's state to the next node's
    acceleration; the path is evaluated exactly from the interval's start node.
    """
    tn = _node_times(T, intervals)
    h = np.diff(tn)
    U = np.diff(A, axis=1) / h
    duration = float(tn[-1])
    steps = max(1, math.ceil(duration / dt - 1e-9))
    t = np.linspace(0.0, duration, steps + 1)
    k = np.clip(np.searchsorted(tn, t, side="right") - 1, 0, h.size - 1)
    s = t - tn[k]
    q = Q[:, k] + s * V[:, k] + s**2 / 2 * A[:, k] + s**3 / 6 * U[:, k]
    qd = V[:, k] + s * A[:, k] + s**2 / 2 * U[:, k]
    qdd = A[:, k] + s * U[:, k]
    return Trajectory(t=t, q=q.T.copy(), qd=qd.T.copy(), qdd=qdd.T.copy())


def _values(value: Any, variables: tuple[Any, ...]) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """A leg's solved nodes (Q, V, A of shape (n, K)) and sub-leg durations (S,)."""
    Q, V, A, _, T = variables
    q, v, a = (np.atleast_2d(np.asarray(value(X), dtype=float)) for X in (Q, V, A))
    return q, v, a, np.atleast_1d(np.asarray(value(T), dtype=float)).ravel()


def _held(report: LimitReport) -> bool:
    return all(w.excess <= VERIFY_TOLERANCE for w in report.worst)


def _interval_function(cs: Any, rnea: Any, friction: Any, n: int, substeps: int) -> Any:
    """One interval of the transcription as a CasADi SX Function, to be mapped over the intervals.

    ``(q, v, a, u, h, eps) -> (next state (3n,), q and v and tau at the substeps (n, substeps)
    each, smoothed energy of the interval)``: the exact cubic of jerk ``u`` over ``h``.
    """
    q, v, a, u = (cs.SX.sym(name, n) for name in ("q", "v", "a", "u"))
    h = cs.SX.sym("h")
    eps = cs.SX.sym("eps")
    nxt = cs.vertcat(q + h * v + h**2 / 2 * a + h**3 / 6 * u, v + h * a + h**2 / 2 * u, a + h * u)
    qs, vs, taus = [], [], []
    energy = cs.SX(0)
    for j in range(substeps):
        s_ = h * (j / substeps)
        qj = q + s_ * v + s_**2 / 2 * a + s_**3 / 6 * u
        vj = v + s_ * a + s_**2 / 2 * u
        aj = a + s_ * u
        tau = rnea(qj, vj, aj)
        if friction is not None:
            tau = tau + friction(vj)
        power = tau * vj
        energy = energy + cs.sum1(cs.sqrt(power**2 + eps**2) - eps) * (h / substeps)
        qs.append(qj)
        vs.append(vj)
        taus.append(tau)
    return cs.Function(
        "interval", [q, v, a, u, h, eps], [nxt, cs.horzcat(*qs), cs.horzcat(*vs), cs.horzcat(*taus), energy]
    )


def cycle_optimum(
    robot: Robot,
    legs: Sequence[CycleLeg],
    budget: float,
    *,
    acceleration_limit: FloatArray | None = None,
    jerk_limit: FloatArray | None = None,
    friction: Friction | None = NOMINAL_FRICTION,
    intervals: int = 40,
    substeps: int = 4,
    initial: Sequence[Trajectory] | None = None,
    continuation: tuple[float, ...] = (0.1, 0.03, 0.01),
    tol: float = 1e-8,
    max_iter: int = 3000,
    time_limit_s: float = 600.0,
) -> CycleOptimum:
    """Solve the legs together by direct transcription and IPOPT with ``Σ durations ≤ budget``.

    Parameters
    ----------
    robot : Robot
    legs : sequence of CycleLeg
    budget : float
        s, the time the legs share.
    acceleration_limit, jerk_limit : ndarray of shape (n,), optional
        rad/s², rad/s³ (e.g. :func:`joulepath.sim.acceleration_limit`).
    friction : Friction or None
        In the objective and the effort limits (Coulomb–viscous terms only).
    intervals : int
        Jerk intervals per sub-leg (a leg with ``m`` vias has ``m + 1`` sub-legs).
    substeps : int
        Points per interval where energy and limits are evaluated inside the solve.
    initial : sequence of Trajectory, optional
        One path per leg to start from (any duration and grid; its vias are taken where
        it comes closest to them). Default: a minimum-jerk move per sub-leg, the budget
        split in proportion to each sub-leg's kinematic lower bound.
    continuation : tuple of float
        Smoothing ``ε`` of ``|p|`` at each stage, as a share of the start's mean ``|tau qd|``.
    tol, max_iter, time_limit_s : IPOPT's tolerance, iterations and wall time per stage
        (the time limit is shared by all stages).

    Returns
    -------
    CycleOptimum
        Verified on a grid of at most ``FINE_DT``. A budget below the legs' kinematic
        lower bounds (:func:`leg_lower_bound`) returns ``feasible=False`` without a solve.

    Raises
    ------
    InvalidInput
        A budget that is not a positive number, a joint vector of the wrong length, an
        ``initial`` that does not fit the legs.
    """
    t_start = time.perf_counter()
    cs = _casadi()
    n = robot.n_joints
    checked = _check_legs(robot, legs, budget, intervals)
    if substeps < 1:
        raise InvalidInput(f"substeps must be ≥ 1, got {substeps}")
    if not continuation or any(not e > 0 for e in continuation):
        raise InvalidInput(f"continuation must be positive shares, got {continuation}")
    if initial is not None:
        if len(initial) != len(checked):
            raise InvalidInput(
                f"initial holds {len(initial)} paths for {len(checked)} legs; give one per leg"
            )
        for i, p in enumerate(initial):
            if p.q.ndim != 2 or p.q.shape[1] != n or p.t.size < 2:
                raise InvalidInput(f"initial path {i} must be (n_steps ≥ 2, {n}), got {p.q.shape}")
    amax = None if acceleration_limit is None else _vector(acceleration_limit, n, "acceleration_limit")
    jmax = None if jerk_limit is None else _vector(jerk_limit, n, "jerk_limit")
    bounds = [leg_lower_bound(robot, leg, acceleration_limit=amax, jerk_limit=jmax) for leg in legs]
    if sum(bounds) > budget:
        return CycleOptimum(
            durations=tuple(bounds),
            energy_J=math.nan,
            legs_energy_J=tuple(math.nan for _ in legs),
            paths=(),
            feasible=False,
            status=f"budget {budget:g} s is below the legs' shortest {sum(bounds):.4g} s (kinematic bound)",
            wall_s=time.perf_counter() - t_start,
        )
    start = (
        [_from_initial(leg, p, intervals) for leg, p in zip(checked, initial, strict=True)]
        if initial is not None
        else _warm_start(robot, checked, budget, intervals, amax, jmax)
    )

    rnea = casadi_rnea(robot)
    v_sym = cs.SX.sym("v", n)
    fr = cs.Function("friction", [v_sym], [_casadi_friction(cs, friction, v_sym, n)])
    lo, hi = robot.joint_ranges()
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    emax = np.asarray(robot.effort_limit, dtype=float)

    step = _interval_function(cs, rnea, fr if friction is not None else None, n, substeps)
    opti = cs.Opti()
    eps = opti.parameter()
    variables = []
    energy_terms = []
    total_time = 0
    for leg in checked:
        S, N = leg.n_sub, intervals
        M = S * N
        Q, V, A = (opti.variable(n, M + 1) for _ in range(3))
        U = opti.variable(n, M)
        T = opti.variable(S)
        variables.append((Q, V, A, U, T))
        opti.subject_to(Q[:, 0] == leg.targets[0])
        opti.subject_to(Q[:, -1] == leg.targets[-1])
        for X in (V, A):
            opti.subject_to(X[:, 0] == 0)
            opti.subject_to(X[:, -1] == 0)
        for k in range(1, S):  # the shared node at each via: exactly, or within its zone
            node = Q[:, k * N]
            r = leg.radius[k - 1]
            for i in range(n):
                if r[i] > 0:
                    opti.subject_to(opti.bounded(leg.targets[k][i] - r[i], node[i], leg.targets[k][i] + r[i]))
                else:
                    opti.subject_to(node[i] == leg.targets[k][i])
        opti.subject_to(T >= MIN_SUBLEG_S)
        duration = cs.sum1(T)
        if leg.t_min > 0:
            opti.subject_to(duration >= leg.t_min)
        if math.isfinite(leg.t_max):
            opti.subject_to(duration <= leg.t_max)
        total_time = total_time + duration
        H = cs.horzcat(*[cs.repmat(T[k] / N, 1, N) for k in range(S)])  # (1, M) step of each interval
        nxt, qs, vs, taus, e = step.map(M)(Q[:, :-1], V[:, :-1], A[:, :-1], U, H, eps)
        opti.subject_to(cs.vertcat(Q[:, 1:], V[:, 1:], A[:, 1:]) == nxt)
        for i in range(n):
            if np.isfinite(lo[i]):
                opti.subject_to(qs[i, :] >= lo[i])
            if np.isfinite(hi[i]):
                opti.subject_to(qs[i, :] <= hi[i])
            if np.isfinite(vmax[i]):
                opti.subject_to(opti.bounded(-vmax[i], vs[i, :], vmax[i]))
            if amax is not None and np.isfinite(amax[i]):
                # the acceleration is linear in each interval: its nodes bound it
                opti.subject_to(opti.bounded(-amax[i], A[i, :], amax[i]))
            if jmax is not None and np.isfinite(jmax[i]):
                opti.subject_to(opti.bounded(-jmax[i], U[i, :], jmax[i]))
            if np.isfinite(emax[i]):
                opti.subject_to(opti.bounded(-emax[i], taus[i, :], emax[i]))
        energy_terms.append(cs.sum2(e))
    opti.subject_to(total_time <= budget)

    # scale of the objective and of ε: the start's energy and mean |tau qd| at its nodes
    unit_num, unit_den, scale = 0.0, 0, 0.0
    for Q0, V0, A0, T0 in start:
        tau0 = robot.inverse_dynamics(Q0.T, V0.T, A0.T, friction=friction)
        p0 = np.abs(tau0 * V0.T)
        h0 = np.diff(_node_times(T0, intervals))
        unit_num += float(p0.sum())
        unit_den += p0.size
        scale += float((p0[:-1].sum(axis=1) * h0).sum())
    unit = unit_num / unit_den or 1.0
    opti.minimize(cs.sum1(cs.vertcat(*energy_terms)) / max(scale, 1e-9))

    def set_start(values: list[tuple[FloatArray, FloatArray, FloatArray, FloatArray]]) -> None:
        for (Q, V, A, U, T), (Q0, V0, A0, T0) in zip(variables, values, strict=True):
            opti.set_initial(Q, Q0)
            opti.set_initial(V, V0)
            opti.set_initial(A, A0)
            opti.set_initial(U, np.diff(A0, axis=1) / np.diff(_node_times(T0, intervals)))
            opti.set_initial(T, np.asarray(T0))

    set_start(start)
    current, status, succeeded = ipopt_stages(
        opti,
        eps,
        unit,
        continuation,
        read=lambda value: [_values(value, X) for X in variables],
        set_start=set_start,
        tol=tol,
        max_iter=max_iter,
        deadline=t_start + time_limit_s,
        start=start,
    )

    paths, energies, reports, vias = [], [], [], []
    for Q0, V0, A0, T0 in current:
        path = resample_leg(Q0, V0, A0, T0, intervals)
        paths.append(path)
        energies.append(energy_on_samples(robot, path, friction=friction))
        reports.append(check_limits(robot, path, friction=friction, acceleration_limit=amax, jerk_limit=jmax))
        vias.append(tuple(float(x) for x in np.cumsum(T0)[:-1]))
    durations = tuple(float(p.t[-1]) for p in paths)
    feasible = succeeded and all(_held(r) for r in reports) and sum(durations) <= budget + 1e-6
    return CycleOptimum(
        durations=durations,
        energy_J=float(sum(energies)),
        legs_energy_J=tuple(energies),
        paths=tuple(paths),
        feasible=feasible,
        status=status,
        wall_s=time.perf_counter() - t_start,
        via_times_s=tuple(vias),
        limits=tuple(reports),
    )


def ipopt_stages(
    opti: Any,
    eps: Any,
    unit: float,
    continuation: Sequence[float],
    *,
    read: Callable[[Callable[[Any], Any]], Any],
    set_start: Callable[[Any], None],
    tol: float,
    max_iter: int,
    deadline: float,
    start: Any,
) -> tuple[Any, str, bool]:
    """IPOPT through the smoothing stages ``continuation`` (ε = share · ``unit``), each warm-started
    from the one before, within the wall-time ``deadline`` (``time.perf_counter()``).

    ``read(value)`` turns a solve's values into the start ``set_start`` takes. A stage that fails
    after one converged keeps the converged one (the optimum of a slightly smoother objective).
    Returns the values, IPOPT's status and whether a stage converged and was kept."""
    status = "not run"
    current, converged = start, ""
    for stage, share in enumerate(continuation):
        left = deadline - time.perf_counter()
        if left <= 0:
            status = "Maximum_WallTime_Exceeded"
            break
        opti.solver(
            "ipopt",
            {"print_time": False},
            {
                "print_level": 0,
                "tol": tol,
                "max_iter": max_iter,
                "sb": "yes",
                "mu_strategy": "adaptive",
                **(WARM_START if stage else {}),
                "max_wall_time": float(left),
            },
        )
        opti.set_value(eps, share * unit)
        try:
            sol = opti.solve()
            status = str(sol.stats()["return_status"])
            value = sol.value
        except RuntimeError:
            status = str(opti.stats()["return_status"])
            value = opti.debug.value
        if status not in SUCCESS and converged:
            status = f"{converged} (stage ε share {share:g}: {status}; kept the stage before)"
            break
        current = read(value)
        set_start(current)
        if status not in SUCCESS:
            break
        converged = status
    return current, status, bool(converged) and status.startswith(converged)
