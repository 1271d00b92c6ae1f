"""Drive gains from motor currents: each joint's torque constant ``k`` (N·m/A), then the dynamics.

A drive logs the motor current ``i_j``; ``k_j i_j`` is the torque as the drive measures
it (motor side, referred to the joint), the quantity :func:`~joulepath.identify.identify`
fits. ``k_j > 0``, so the side of the gear losses is the sign of ``i_j qd_j`` and
:func:`~joulepath.identify.joint_side` is linear in ``k``::

    joint_side(k_j i_j, qd_j, eta) = k_j joint_side(i_j, qd_j, eta) = [Y_b beta + F f]_j + tau_ref_j

For a fixed gear efficiency ``eta`` this is linear in ``(beta, f, k)``, with the base
regressor ``Y_b`` and friction columns ``F`` of :func:`~joulepath.identify.identify`.
Without a known torque ``tau_ref`` it is homogeneous: scaling ``beta``, ``f`` and ``k``
together changes no current. One scale needs a **reference** (:data:`REFERENCES`):

* ``"payload"`` (:class:`PayloadReference`): a second log of the same robot carrying a
  payload of known mass and centre of mass (tool0 frame). Its torque
  ``tau_ref = tau(robot + payload) - tau(robot)`` (rigid body; the payload's own
  parameters only, since torque is linear in the inertial parameters) is known, so the
  stacked least-squares problem of both logs gives every ``k_j`` together with the base
  parameters and friction. A payload whose effect is below the noise is refused.
* ``"nominal"``: the description's masses. The same least-squares problem of the logs
  alone, plus a weak pull (weight :data:`NOMINAL_PRIOR_WEIGHT` against the data's rows)
  of the identified rigid-body torque ``Y_b beta`` towards the nominal model's on the
  logged motion. What the currents determine (the shape of the dynamics, friction,
  the ratios the coupling between joints fixes) stays the data's; what they leave open
  (the common scale, and a joint whose torque is mostly friction) follows the nominal
  masses, so ``k`` carries their error.

With the nominal reference, a joint whose ``k`` the log cannot fix (the fit gives
``k <= 0``, or a standard error over :data:`UNFIXED_GAIN_ERROR`: a wrist whose torque is
mostly friction, a joint the excitation hardly loads) keeps a stated prior (:class:`AssumedGain`): the data
sheet's ``k`` where the robot's drives file gives one (a source not marked
``assumed``), else the ``k`` of a joint with the same motor (:func:`same_motor`),
identified together with it (one parameter for both). Without either it is refused
(give a payload log, or the data sheet's ``k``). With a payload reference every ``k``
must come from the payload: a joint it does not fix means its effect is below the
noise, and that is refused.

Both search ``eta`` by a bounded scalar search (or keep a given one) on the linear
problem, weight each joint's rows by the inverse of its current residual (three passes),
and then minimise the current residual itself, ``motor_torque(Y_b beta + F f + tau_ref)
/ k - i`` in amperes, from the linear solution (the linear problem has the noisy current
in its regressor, which biases ``k`` towards zero). A gain's standard error comes from
the weighted residual; with a payload reference one known to worse than
:data:`MAX_GAIN_ERROR` is refused. With the nominal reference the error also holds the
common scale the weak pull leaves open, so there a gain counts as not fixed only over
:data:`UNFIXED_GAIN_ERROR` (the card keeps each gain's error).
:func:`identify_from_currents` then identifies the dynamics from the torques ``k·i``
with that ``eta`` fixed, so the twin, its gear efficiency and its drive gains are one
model; :func:`identified_drives` turns the gains into the twin's drives file
(:mod:`joulepath.energy`'s format).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot, motor_torque
from joulepath.energy import ASSUMED, DriveModel
from joulepath.errors import InvalidInput
from joulepath.identify._data import IdentificationData
from joulepath.identify._fit import (
    Identification,
    IdentifyOptions,
    _check_motion,
    gear_side_speed,
    identify,
    joint_side,
    search_eta,
)
from joulepath.identify._regressor import base_parameters, friction_regressor, inertial_regressor

REFERENCES = ("payload", "nominal")
"""What fixes the scale between current and torque (see the module docstring)."""

NOMINAL_PRIOR_WEIGHT = 1e-2
"""Weight of the pull towards the nominal rigid-body torque (reference "nominal"), relative to the data."""

MAX_GAIN_ERROR = 0.05
"""Largest relative standard error (one sigma) of a torque constant a payload reference fixes."""

UNFIXED_GAIN_ERROR = 0.25
"""Nominal reference: a torque constant known to worse than this (one sigma) keeps its prior."""


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class PayloadReference:
    """A log of the robot carrying a known payload: the scale between current and torque.

    Attributes
    ----------
    data : IdentificationData
        Motor currents (``signal == "current"``) logged with the payload.
    mass : float
        kg, > 0.
    com : tuple of 3 float
        Centre of mass in the tool0 (flange) frame, m. The payload is a point mass
        (its own inertia about its centre of mass is taken as zero).
    """

    data: IdentificationData
    mass: float
    com: tuple[float, float, float]

    def __post_init__(self) -> None:
        if not (math.isfinite(self.mass) and self.mass > 0):
            raise InvalidInput(f"the payload mass must be a positive number of kg, got {self.mass}")
        if len(self.com) != 3 or not all(math.isfinite(v) for v in self.com):
            raise InvalidInput(f"the payload's centre of mass must be 3 finite numbers (m), got {self.com}")
        if self.data.signal != "current":
            raise InvalidInput("the payload log must hold motor currents i1..in (A)")

    def describe(self) -> str:
        """One line: the payload and the log(s) it was carried in."""
        com = ", ".join(f"{v:g}" for v in self.com)
        return (
            f"payload of {self.mass:g} kg at ({com}) m in the flange frame, logged in "
            f"{', '.join(self.data.sources)}"
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class AssumedGain:
    """A torque constant the log does not fix, kept at a stated prior.

    Attributes
    ----------
    joint : int
        1-based.
    value : float
        N·m/A, the ``k`` used.
    reason : str
        Why the log does not fix it (e.g. ``"the fit gives k ≤ 0"``).
    prior : str
        Where the value comes from: ``"the data sheet (...)"`` or
        ``"joint 5 (same motor, identified together)"``.
    tied_to : int or None
        The 1-based joint whose ``k`` it shares (same motor), None for a data-sheet value.
    """

    joint: int
    value: float
    reason: str
    prior: str
    tied_to: int | None = None

    def warning(self) -> str:
        """One line: the joint, why, and the prior kept."""
        return (
            f"joint {self.joint}: the log does not fix its torque constant ({self.reason}); "
            f"assumed {self.value:.4g} N·m/A from {self.prior}"
        )

    def card(self) -> dict[str, Any]:
        return {
            "joint": self.joint,
            "value_Nm_per_A": self.value,
            "reason": self.reason,
            "prior": self.prior,
            "tied_to": self.tied_to,
        }


@dataclass(frozen=True, slots=True, kw_only=True)
class DriveGainFit:
    """Identified joint-side torque constants (see the module docstring).

    Attributes
    ----------
    torque_constant : tuple of float
        ``k`` per joint, N·m/A (``i = tau_motor / k``).
    relative_error : tuple of float
        One-sigma standard error of each ``k_j`` over ``k_j`` (from the fit's residual;
        with the nominal reference it leaves out the nominal masses' own error); NaN
        for a data-sheet ``k`` kept as a prior, the shared parameter's for a tied one.
    gear_efficiency : float
    reference : {"payload", "nominal"}
    reference_note : str
        What the reference was, in words.
    sources : tuple of str
        The logs the gains were fitted on (the payload log included).
    assumed : tuple of AssumedGain
        The joints whose ``k`` the log does not fix, each with its prior and why.
    """

    torque_constant: tuple[float, ...]
    relative_error: tuple[float, ...]
    gear_efficiency: float
    reference: str
    reference_note: str
    sources: tuple[str, ...]
    assumed: tuple[AssumedGain, ...] = ()

    def __post_init__(self) -> None:
        if self.reference not in REFERENCES:
            raise InvalidInput(f"reference must be one of {', '.join(REFERENCES)}, got {self.reference!r}")

    def source_text(self) -> str:
        """Where the gains come from: the drives file's ``[sources]`` entry."""
        names = ", ".join(Path(s).name for s in self.sources)
        return f"identified from {names} (reference: {self.reference_note})"

    def status(self, joint: int) -> str:
        """``"identified"`` or ``"assumed"`` for the 1-based ``joint``'s ``k``."""
        return "assumed" if any(a.joint == joint for a in self.assumed) else "identified"

    def card(self) -> dict[str, Any]:
        """JSON-ready summary (the twin's card)."""
        return {
            "reference": self.reference,
            "reference_note": self.reference_note,
            "torque_constant_Nm_per_A": list(self.torque_constant),
            "relative_error": list(self.relative_error),
            "gear_efficiency": self.gear_efficiency,
            "logs": list(self.sources),
            "assumed": [a.card() for a in self.assumed],
        }


@dataclass(frozen=True, slots=True, eq=False)
class CurrentIdentification:
    """An identification from currents: the dynamics (in torque ``k·i``) and the drive gains."""

    identification: Identification
    gains: DriveGainFit

    def card(self) -> dict[str, Any]:
        """What the twin's card adds: the drive gains and their reference."""
        return {"signal": "current", "drive_gains": self.gains.card()}


def _regressor(robot: Robot, data: IdentificationData, options: IdentifyOptions) -> FloatArray:
    """``[Y_b | F]`` of shape ``(N, n, p)`` (the columns :func:`identify` fits)."""
    F, _ = friction_regressor(
        data.qd,
        smoothing=options.smoothing,
        offset=options.offset,
        stribeck_speed=options.stribeck_speed,
        viscous_offset=options.viscous_offset,
    )
    Y = inertial_regressor(robot, data.q, data.qd, data.qdd)[:, :, base_parameters(robot).independent]
    return np.concatenate([Y, F], axis=2)


def _diagonal(values: FloatArray) -> FloatArray:
    """``(N, n)`` -> ``(N, n, n)`` with the values on each sample's diagonal."""
    N, n = values.shape
    out = np.zeros((N, n, n))
    idx = np.arange(n)
    out[:, idx, idx] = values
    return out


def _standard_errors(Mw: FloatArray, rw: FloatArray) -> FloatArray:
    """One-sigma standard errors of a weighted least-squares solution (columns scaled for the SVD)."""
    norms = np.linalg.norm(Mw, axis=0)
    norms[norms == 0] = 1.0
    _, s, vt = np.linalg.svd(Mw / norms, full_matrices=False)
    dof = max(Mw.shape[0] - Mw.shape[1], 1)
    s2 = float(rw @ rw) / dof
    with np.errstate(divide="ignore"):
        inv = np.where(s > s[0] * 1e-12, 1.0 / s**2, np.inf)
    var = (vt.T**2 * inv[None, :]).sum(axis=1) * s2 / norms**2
    out: FloatArray = np.sqrt(var)
    return out


@dataclass(frozen=True, slots=True)
class _Set:
    """One data set: regressor ``[Y_b | F]``, currents, speeds and the known joint torque.

    ``qd`` is the speed that decides the side of the gear losses (:func:`gear_side_speed`).
    """

    A: FloatArray
    current: FloatArray
    qd: FloatArray
    known: FloatArray


@dataclass(frozen=True, slots=True)
class _Prior:
    """A weak pull of the rigid-body torque ``Y_b beta`` towards the nominal model's, ``tau``."""

    Yb: FloatArray
    tau: FloatArray
    weight: float


def _payload_sets(
    data: IdentificationData, reference: PayloadReference, robot: Robot, options: IdentifyOptions
) -> list[_Set]:
    ref = reference.data
    loaded = robot.with_payload(reference.mass, reference.com, what="the reference payload")
    tau_ref = loaded.inverse_dynamics(ref.q, ref.qd, ref.qdd) - robot.inverse_dynamics(ref.q, ref.qd, ref.qdd)
    return [
        _Set(
            _regressor(robot, data, options),
            data.tau,
            gear_side_speed(data.qd, options.rest_speed),
            np.zeros_like(data.tau),
        ),
        _Set(_regressor(robot, ref, options), ref.tau, gear_side_speed(ref.qd, options.rest_speed), tau_ref),
    ]


def _stacked(
    sets: list[_Set], prior: _Prior | None, w: FloatArray, eta: float
) -> tuple[FloatArray, FloatArray]:
    """Weighted rows ``[A | -diag(joint_side(i))]`` and right-hand side ``-known`` (prior rows after)."""
    p, n = sets[0].A.shape[2], w.size
    rows, rhs = [], []
    for s in sets:
        M = np.concatenate([s.A, -_diagonal(joint_side(s.current, s.qd, eta))], axis=2)
        rows.append((M * w[None, :, None]).reshape(-1, p + n))
        rhs.append((-s.known * w).ravel())
    if prior is not None:
        c = math.sqrt(prior.weight)
        P = np.zeros((*prior.tau.shape, p + n))
        P[:, :, : prior.Yb.shape[2]] = prior.Yb
        rows.append((P * (c * w)[None, :, None]).reshape(-1, p + n))
        rhs.append((prior.tau * c * w).ravel())
    return np.vstack(rows), np.concatenate(rhs)


def _current_residual(sets: list[_Set], x: FloatArray, k: FloatArray, eta: float) -> FloatArray:
    """Predicted minus logged current (A), every set's samples stacked; inf where a ``k`` is not > 0."""
    safe = np.where(k > 0, k, np.inf)
    return np.vstack([motor_torque(s.A @ x + s.known, s.qd, eta) / safe - s.current for s in sets])


@dataclass(frozen=True, slots=True)
class _Gains:
    """``k = T theta + k0``: each joint's ``k`` its own parameter, one shared with a joint of the
    same motor (a column of ``T`` with several ones), or fixed (a row of zeros, the value in ``k0``)."""

    T: FloatArray
    k0: FloatArray

    @classmethod
    def free(cls, n: int) -> _Gains:
        return cls(np.eye(n), np.zeros(n))

    def fixed(self, j: int, value: float) -> _Gains:
        T, k0 = self.T.copy(), self.k0.copy()
        T[j] = 0.0
        k0[j] = value
        return _Gains(T[:, T.any(axis=0)], k0)

    def tied(self, j: int, to: int) -> _Gains:
        T = self.T.copy()
        T[j] = T[to]
        return _Gains(T[:, T.any(axis=0)], self.k0.copy())

    def k(self, theta: FloatArray) -> FloatArray:
        out: FloatArray = self.T @ theta + self.k0
        return out


def _reduced(Mw: FloatArray, bw: FloatArray, p: int, gains: _Gains) -> tuple[FloatArray, FloatArray]:
    """Rows in ``(x, theta)``: the ``k`` columns through ``T``, the fixed ``k`` moved to the right side."""
    Mk = Mw[:, p:]
    return np.concatenate([Mw[:, :p], Mk @ gains.T], axis=1), bw - Mk @ gains.k0


def _solve_linear(
    sets: list[_Set], prior: _Prior | None, w: FloatArray, eta: float, gains: _Gains
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Weighted least squares in ``(x, theta)`` for one ``eta``: ``x``, ``theta``, current residual (A)."""
    p = sets[0].A.shape[2]
    M, b = _reduced(*_stacked(sets, prior, w, eta), p, gains)
    z = np.asarray(np.linalg.lstsq(M, b, rcond=None)[0], dtype=np.float64)
    x, theta = z[:p], z[p:]
    return x, theta, _current_residual(sets, x, gains.k(theta), eta)


def _refine_in_current(
    sets: list[_Set],
    prior: _Prior | None,
    x: FloatArray,
    theta: FloatArray,
    eta: float,
    w: FloatArray,
    gains: _Gains,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Least squares of the current residual, ``motor_torque(A x + known) / k - i``, in ``(x, log theta)``.

    The linear problem puts the noisy current in the regressor (``k`` multiplies it),
    which biases ``k`` towards zero by about the noise's share of the current's
    variance; here the noise is only in what is fitted. Started from the linear
    solution; rows weighted ``w k`` (the current-space weights of the torque weights ``w``).
    """
    p, m = x.size, theta.size
    w_current = w * gains.k(theta)

    def parts(z: FloatArray) -> tuple[list[FloatArray], list[FloatArray], FloatArray]:
        kk = gains.k(np.exp(z[p:]))
        taus = [s.A @ z[:p] + s.known for s in sets]
        return taus, [motor_torque(t, s.qd, eta) for t, s in zip(taus, sets, strict=True)], kk

    def residual(z: FloatArray) -> FloatArray:
        _, motors, kk = parts(z)
        out = [((m / kk - s.current) * w_current).ravel() for m, s in zip(motors, sets, strict=True)]
        if prior is not None:
            nb = prior.Yb.shape[2]
            out.append(((prior.Yb @ z[:nb] - prior.tau) * math.sqrt(prior.weight) * w).ravel())
        return np.concatenate(out)

    def jacobian(z: FloatArray) -> FloatArray:
        taus, motors, kk = parts(z)
        blocks = []
        for t, mt, s in zip(taus, motors, sets, strict=True):
            slope = np.where(t * s.qd > 0, 1.0 / eta, eta) if eta != 1.0 else np.ones_like(t)
            scale = (w_current / kk)[None, :] * slope
            dk = _diagonal(-(mt / kk) * w_current[None, :]) @ gains.T  # d/d log theta (a free k is theta)
            blocks.append(np.concatenate([s.A * scale[:, :, None], dk], axis=2).reshape(-1, p + m))
        if prior is not None:
            nb = prior.Yb.shape[2]
            P = np.zeros((*prior.tau.shape, p + m))
            P[:, :, :nb] = prior.Yb * (math.sqrt(prior.weight) * w)[None, :, None]
            blocks.append(P.reshape(-1, p + m))
        return np.vstack(blocks)

    z0 = np.concatenate([x, np.log(theta)])
    sol = least_squares(residual, z0, jac=jacobian, method="lm", max_nfev=50)
    theta = np.exp(sol.x[p:])
    return sol.x[:p], theta, _current_residual(sets, sol.x[:p], gains.k(theta), eta)


def _fit_sets(
    sets: list[_Set],
    prior: _Prior | None,
    options: IdentifyOptions,
    gains: _Gains,
    *,
    max_error: float = MAX_GAIN_ERROR,
) -> tuple[FloatArray, float, FloatArray, dict[int, str]]:
    """``k``, ``eta``, the standard errors of ``k`` over ``k`` and the joints the data do not fix.

    The last maps a 0-based joint whose ``k`` is a parameter (not fixed) to why the
    data do not fix it: the fit gives ``k <= 0``, or a standard error over
    ``max_error``. Empty when every parameter is fixed by the data.
    """
    n = sets[0].current.shape[1]
    p = sets[0].A.shape[2]
    w = np.ones(n)
    eta = 1.0
    for _ in range(3):  # unweighted, then weights 1 / (k sigma_i): residuals in current units

        def cost(e: float, w: FloatArray = w) -> float:
            return float((_solve_linear(sets, prior, w, e, gains)[2] ** 2).sum())

        eta = search_eta(cost, options.gear_efficiency)
        x, theta, res = _solve_linear(sets, prior, w, eta, gains)
        if not np.all(theta > 0):
            break
        sigma = np.sqrt(np.mean(res**2, axis=0))
        sigma = np.maximum(sigma, 1e-9 * max(float(sigma.max()), 1e-12))
        w = 1.0 / (gains.k(theta) * sigma)
    x, theta, res = _solve_linear(sets, prior, w, eta, gains)
    is_free = np.asarray(gains.T.any(axis=1), dtype=bool)
    if not np.all(theta > 0):
        bad_theta = gains.T @ (theta <= 0).astype(float) > 0
        k = gains.k(theta)
        return k, eta, np.full(n, np.nan), {j: "the fit gives k ≤ 0" for j in range(n) if bad_theta[j]}
    x, theta, res = _refine_in_current(sets, prior, x, theta, eta, w, gains)
    M, b = _reduced(*_stacked(sets, prior, w, eta), p, gains)
    z = np.concatenate([x, theta])
    rel_theta = _standard_errors(M, M @ z - b)[p:] / theta
    rel = np.where(is_free, gains.T @ rel_theta, np.nan)
    bad = {
        j: f"known only to ±{100 * rel[j]:.3g} %, limit {100 * max_error:g} %"
        for j in range(n)
        if is_free[j] and not rel[j] <= max_error
    }
    return gains.k(theta), eta, rel, bad


def same_motor(robot: Robot) -> tuple[tuple[int, ...], ...]:
    """Per joint (0-based), the other joints (0-based) that have the same motor.

    Joints have the same motor when their rated torque and speed limits are equal
    (and finite) and, where the robot has a drives file, their nominal torque constant
    and winding resistance too.

    Examples
    --------
    >>> import joulepath
    >>> same_motor(joulepath.load_robot("irb120"))[4]
    ()
    """
    effort, speed = robot.effort_limit, robot.velocity_limit
    drives = robot.drives if robot.drives is not None and robot.drives.n_joints == robot.n_joints else None

    def key(j: int) -> tuple[float, ...]:
        out: tuple[float, ...] = (float(effort[j]), float(speed[j]))
        if drives is not None:
            out = (*out, float(drives.torque_constant[j]), float(drives.resistance[j]))
        return out

    n = robot.n_joints
    known = [bool(np.isfinite(effort[j]) and np.isfinite(speed[j])) for j in range(n)]
    return tuple(
        tuple(i for i in range(n) if i != j and known[i] and known[j] and key(i) == key(j)) for j in range(n)
    )


def _data_sheet(robot: Robot) -> tuple[FloatArray, str] | None:
    """The drives file's torque constants and their source, where it gives them (a source not assumed)."""
    d = robot.drives
    if d is None or d.n_joints != robot.n_joints:
        return None
    source = d.source("torque_constant")
    if source.lower().startswith(ASSUMED):
        return None
    return np.asarray(d.torque_constant, dtype=np.float64), source


def _fit_with_priors(
    sets: list[_Set],
    prior: _Prior | None,
    options: IdentifyOptions,
    robot: Robot,
    *,
    fix: str,
    unfixed: dict[int, str] | None = None,
) -> tuple[FloatArray, float, FloatArray, tuple[AssumedGain, ...]]:
    """:func:`_fit_sets`, each joint the data do not fix kept at its prior (see the module docstring).

    ``unfixed`` names joints known before any fit to be unfixable (0-based, with why).
    """
    n = robot.n_joints
    gains = _Gains.free(n)
    sheet = _data_sheet(robot)
    siblings = same_motor(robot)
    why: dict[int, str] = {}
    bad = dict(unfixed or {})
    for _ in range(n + 1):
        for j, reason in sorted(bad.items()):
            why[j] = reason
            is_free = np.asarray(gains.T.any(axis=1), dtype=bool)
            free_sibling = [i for i in siblings[j] if i not in bad and is_free[i]]
            if sheet is not None:
                gains = gains.fixed(j, float(sheet[0][j]))
            elif free_sibling:
                gains = gains.tied(j, free_sibling[0])
            else:
                raise InvalidInput(
                    f"the log does not fix the torque constant of joint {j + 1} ({reason}), and there is no "
                    "prior for it (no data-sheet torque constant in the robot's drives file, no joint with "
                    f"the same motor): {fix}, or give the data sheet's torque_constant in the drives file"
                )
        k, eta, rel, bad = _fit_sets(sets, prior, options, gains, max_error=UNFIXED_GAIN_ERROR)
        if not bad:
            break
    else:  # pragma: no cover - each pass fixes or ties a joint, so n passes end it
        raise InvalidInput(f"the torque constants of joints {sorted(j + 1 for j in bad)} stay unfixed: {fix}")
    assumed = []
    for j in sorted(why):
        shared = [i for i in range(n) if i != j and gains.T[j].any() and (gains.T[i] == gains.T[j]).all()]
        to = next((i for i in shared if i not in why), shared[0] if shared else None)
        if to is not None:
            assumed.append(
                AssumedGain(
                    joint=j + 1,
                    value=float(k[j]),
                    reason=why[j],
                    prior=f"joint {to + 1} (same motor, identified together)",
                    tied_to=to + 1,
                )
            )
        else:
            source = "" if sheet is None else sheet[1]
            assumed.append(
                AssumedGain(joint=j + 1, value=float(k[j]), reason=why[j], prior=f"the data sheet ({source})")
            )
    return k, eta, rel, tuple(assumed)


def _fit_payload(
    data: IdentificationData, reference: PayloadReference, robot: Robot, options: IdentifyOptions
) -> tuple[FloatArray, float, FloatArray, tuple[AssumedGain, ...]]:
    """Every ``k`` from the payload's scale; no priors: a joint the payload does not fix says the
    payload's effect is below the noise, and a prior would hide that the scale is not fixed."""
    k, eta, rel, bad = _fit_sets(
        _payload_sets(data, reference, robot, options), None, options, _Gains.free(robot.n_joints)
    )
    if bad:
        j, reason = min(bad.items())
        joints = ", ".join(str(i + 1) for i in sorted(bad))
        raise InvalidInput(
            f"the reference does not fix the torque constant of joint(s) {joints} (joint {j + 1}: "
            f"{reason}): {_PAYLOAD_FIX}"
        )
    return k, eta, rel, ()


def _fit_nominal(
    data: IdentificationData, robot: Robot, options: IdentifyOptions
) -> tuple[FloatArray, float, FloatArray, tuple[AssumedGain, ...]]:
    """The data's own solution, its scale (and what else the data leave open) set by the nominal torque."""
    A = _regressor(robot, data, options)
    nominal = robot.inverse_dynamics(data.q, data.qd, data.qdd)
    flat = {
        j: "the nominal model gives it no torque on these logs"
        for j in range(robot.n_joints)
        if not np.std(nominal[:, j]) > 1e-9
    }
    prior = _Prior(A[:, :, : base_parameters(robot).n], nominal, NOMINAL_PRIOR_WEIGHT)
    sets = [_Set(A, data.tau, gear_side_speed(data.qd, options.rest_speed), np.zeros_like(data.tau))]
    return _fit_with_priors(sets, prior, options, robot, fix=_NOMINAL_FIX, unfixed=flat)


_PAYLOAD_FIX = (
    "the payload's effect on their currents is below the noise; log the payload with a larger mass or "
    "a centre of mass further off the flange axis, over more varied poses and speeds"
)
_NOMINAL_FIX = (
    "the nominal model's torque there is too small against the logged current (friction) to scale "
    "it; give a payload log (--payload-log, --payload-mass, --payload-com)"
)


def fit_drive_gains(
    data: IdentificationData,
    robot: Robot,
    options: IdentifyOptions | None = None,
    *,
    payload: PayloadReference | None = None,
) -> DriveGainFit:
    """Each joint's torque constant ``k`` (N·m/A) from logged currents (see the module docstring).

    Parameters
    ----------
    data : IdentificationData
        Motor currents (``signal == "current"``) of the robot's motion.
    robot : Robot
        Kinematics and the nominal masses.
    options : IdentifyOptions, optional
        Friction terms and a fixed gear efficiency, as for :func:`identify`.
    payload : PayloadReference, optional
        The reference; without it the nominal masses are.

    Returns
    -------
    DriveGainFit
        With the nominal reference, ``assumed`` lists each joint whose ``k`` the data do
        not fix (``k_j <= 0`` or known to worse than :data:`UNFIXED_GAIN_ERROR`), kept at its
        prior: the drives file's data-sheet ``k``, else shared with a joint of the same motor.

    Raises
    ------
    InvalidInput
        Data that hold torques, or whose joint count differs from the robot's; a joint
        whose ``k`` the data do not fix and that has no prior; a payload that does not
        fix every ``k`` (its effect below the noise).
    """
    options = options or IdentifyOptions()
    for d in (data, *(() if payload is None else (payload.data,))):
        if d.signal != "current":
            raise InvalidInput("fit_drive_gains needs motor currents (signal 'current'); these hold torques")
        if d.n_joints != robot.n_joints:
            raise InvalidInput(
                f"the data hold {d.n_joints} joints but robot {robot.name!r} has {robot.n_joints}"
            )
    if payload is None:
        k, eta, rel, assumed = _fit_nominal(data, robot, options)
        reference, note = "nominal", f"the nominal masses of {robot.name}"
        sources = data.sources
    else:
        k, eta, rel, assumed = _fit_payload(data, payload, robot, options)
        reference, note = "payload", payload.describe()
        sources = (*data.sources, *payload.data.sources)
    return DriveGainFit(
        torque_constant=tuple(float(v) for v in k),
        relative_error=tuple(float(v) for v in rel),
        gear_efficiency=float(eta),
        reference=reference,
        reference_note=note,
        sources=sources,
        assumed=assumed,
    )


def identify_from_currents(
    data: IdentificationData,
    robot: Robot,
    options: IdentifyOptions | None = None,
    *,
    payload: PayloadReference | None = None,
) -> CurrentIdentification:
    """Drive gains, base parameters, friction and gear losses of ``robot`` from logged currents.

    :func:`fit_drive_gains` on the fitted share of ``data`` (a hold-out, when asked
    for, is left out), then :func:`identify` on the torques ``k·i`` with the gains'
    gear efficiency. Its torque scores are the current scores (an R² per joint does not
    change with the joint's scale).

    Raises
    ------
    InvalidInput
        As :func:`fit_drive_gains` and :func:`identify`.
    """
    options = options or IdentifyOptions()
    fit_part = data
    if options.holdout > 0:
        cut = int(round((1.0 - options.holdout) * data.n_samples))
        fit_part = data.subset(np.arange(data.n_samples) < cut)
    _check_motion(fit_part, base_parameters(robot).n)
    gains = fit_drive_gains(fit_part, robot, options, payload=payload)
    torques = data.scaled(np.asarray(gains.torque_constant))
    ident = identify(torques, robot, replace(options, gear_efficiency=gains.gear_efficiency))
    return CurrentIdentification(identification=ident, gains=gains)


def identified_drives(gains: DriveGainFit, nominal: DriveModel | None, n_joints: int) -> DriveModel:
    """The twin's drive data: the identified ``k`` and gear efficiency, the rest as ``nominal`` gives it.

    Values not identified keep their source (or ``"assumed"``); without nominal drive
    data the winding resistance and the drive efficiency are unknown and written as
    assumed (0 Ω, 1.0), saying so.
    """
    k = gains.torque_constant
    if len(k) != n_joints:
        raise InvalidInput(f"{len(k)} torque constants for {n_joints} joints")
    identified = gains.source_text()
    if nominal is not None and nominal.n_joints == n_joints:
        sources = dict(nominal.sources)
        sources.update(torque_constant=identified, gear_efficiency=identified)
        return replace(
            nominal,
            torque_constant=k,
            gear_efficiency=(gains.gear_efficiency,) * n_joints,
            sources=sources,
            origin=f"identified ({identified}); the rest from {nominal.origin}",
        )
    unknown = (
        f"{ASSUMED}: unknown (currents and positions do not identify it, and the nominal robot has "
        "no drives file); give it in the twin's drives.toml"
    )
    return DriveModel(
        torque_constant=k,
        resistance=(0.0,) * n_joints,
        drive_efficiency=(1.0,) * n_joints,
        gear_efficiency=(gains.gear_efficiency,) * n_joints,
        bus="per-axis",
        sources={
            "torque_constant": identified,
            "gear_efficiency": identified,
            "resistance": unknown,
            "drive_efficiency": unknown,
            "bus": unknown,
            "standby_W": unknown,
        },
        origin=f"identified ({identified})",
    )


__all__ = [
    "AssumedGain",
    "CurrentIdentification",
    "DriveGainFit",
    "MAX_GAIN_ERROR",
    "UNFIXED_GAIN_ERROR",
    "PayloadReference",
    "REFERENCES",
    "fit_drive_gains",
    "identified_drives",
    "identify_from_currents",
    "same_motor",
]
