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
  masses, so ``k`` carries their error. A joint whose nominal torque is too small
  against its friction to scale it is refused (give a payload log).

Both search ``eta`` by a bounded scalar search (or keep a given one) on the linear
problem, weight each joint's rows by the inverse of its current residual (three passes),
and then minimise the current residual itself, ``motor_torque(Y_b beta + F f + tau_ref)
/ k - i`` in amperes, from the linear solution (the linear problem has the noisy current
in its regressor, which biases ``k`` towards zero). A gain's standard error comes from
the weighted residual; one known to worse than :data:`MAX_GAIN_ERROR` is refused.
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
from joulepath.energy import DriveModel
from joulepath.energy._drives import ASSUMED
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
"""Largest relative standard error (one sigma) of an identified torque constant that is accepted."""


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
class DriveGainFit:
    """Identified joint-side torque constants (see the module docstring).

    Attributes
    ----------
    torque_constant : tuple of float
        ``k`` per joint, N·m/A (``i = tau_motor / k``).
    relative_error : tuple of float
        One-sigma standard error of each ``k_j`` over ``k_j`` (from the fit's residual;
        with the nominal reference it leaves out the nominal masses' own error).
    gear_efficiency : float
    reference : {"payload", "nominal"}
    reference_note : str
        What the reference was, in words.
    sources : tuple of str
        The logs the gains were fitted on (the payload log included).
    """

    torque_constant: tuple[float, ...]
    relative_error: tuple[float, ...]
    gear_efficiency: float
    reference: str
    reference_note: str
    sources: tuple[str, ...]

    def __post_init__(self) -> None:
        if self.reference not in REFERENCES:
            raise InvalidInput(f"reference must be one of {', '.join(REFERENCES)}, got {self.reference!r}")

    def source_text(self) -> str:
        """Where the gains come from: the drives file's ``[sources]`` entry."""
        names = ", ".join(Path(s).name for s in self.sources)
        return f"identified from {names} (reference: {self.reference_note})"

    def card(self) -> dict[str, Any]:
        """JSON-ready summary (the twin's card)."""
        return {
            "reference": self.reference,
            "reference_note": self.reference_note,
            "torque_constant_Nm_per_A": list(self.torque_constant),
            "relative_error": list(self.relative_error),
            "gear_efficiency": self.gear_efficiency,
            "logs": list(self.sources),
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
        data.qd, smoothing=options.smoothing, offset=options.offset, stribeck_speed=options.stribeck_speed
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


def _solve_linear(
    sets: list[_Set], prior: _Prior | None, w: FloatArray, eta: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Weighted least squares in ``(x, k)`` for one ``eta``: ``x``, ``k`` and the current residual (A)."""
    p = sets[0].A.shape[2]
    Mw, bw = _stacked(sets, prior, w, eta)
    z = np.asarray(np.linalg.lstsq(Mw, bw, rcond=None)[0], dtype=np.float64)
    x, k = z[:p], z[p:]
    return x, k, _current_residual(sets, x, k, eta)


def _refine_in_current(
    sets: list[_Set], prior: _Prior | None, x: FloatArray, k: FloatArray, eta: float, w: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Least squares of the current residual itself, ``motor_torque(A x + known) / k - i``, in ``(x, log k)``.

    The linear problem puts the noisy current in the regressor (``k`` multiplies it),
    which biases ``k`` towards zero by about the noise's share of the current's
    variance; here the noise is only in what is fitted. Started from the linear
    solution; rows weighted ``w k`` (the current-space weights of the torque weights ``w``).
    """
    p, n = x.size, k.size
    w_current = w * k

    def parts(z: FloatArray) -> tuple[list[FloatArray], list[FloatArray], FloatArray]:
        kk = np.exp(z[p:])
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
        for t, m, s in zip(taus, motors, sets, strict=True):
            slope = np.where(t * s.qd > 0, 1.0 / eta, eta) if eta != 1.0 else np.ones_like(t)
            scale = (w_current / kk)[None, :] * slope
            dk = _diagonal(-(m / kk) * w_current[None, :])  # d/d log k
            blocks.append(np.concatenate([s.A * scale[:, :, None], dk], axis=2).reshape(-1, p + n))
        if prior is not None:
            nb = prior.Yb.shape[2]
            P = np.zeros((*prior.tau.shape, p + n))
            P[:, :, :nb] = prior.Yb * (math.sqrt(prior.weight) * w)[None, :, None]
            blocks.append(P.reshape(-1, p + n))
        return np.vstack(blocks)

    z0 = np.concatenate([x, np.log(k)])
    sol = least_squares(residual, z0, jac=jacobian, method="lm", max_nfev=50)
    kk = np.exp(sol.x[p:])
    return sol.x[:p], kk, _current_residual(sets, sol.x[:p], kk, eta)


def _fit_sets(
    sets: list[_Set], prior: _Prior | None, options: IdentifyOptions, *, fix: str
) -> tuple[FloatArray, float, FloatArray]:
    """``k``, ``eta`` and the standard errors of ``k`` over ``k`` (see the module docstring)."""
    n = sets[0].current.shape[1]
    p = sets[0].A.shape[2]
    w = np.ones(n)
    eta = 1.0
    for _ in range(3):  # unweighted, then weights 1 / (k sigma_i): residuals in current units

        def cost(e: float, w: FloatArray = w) -> float:
            return float((_solve_linear(sets, prior, w, e)[2] ** 2).sum())

        eta = search_eta(cost, options.gear_efficiency)
        x, k, res = _solve_linear(sets, prior, w, eta)
        if not np.all(k > 0):
            break
        sigma = np.sqrt(np.mean(res**2, axis=0))
        sigma = np.maximum(sigma, 1e-9 * max(float(sigma.max()), 1e-12))
        w = 1.0 / (k * sigma)
    x, k, res = _solve_linear(sets, prior, w, eta)
    if np.all(k > 0):
        x, k, res = _refine_in_current(sets, prior, x, k, eta, w)
    bad = [j + 1 for j in range(n) if not k[j] > 0]
    if bad:
        raise InvalidInput(
            f"the reference does not fix the torque constant of joint(s) {', '.join(map(str, bad))} (the "
            f"fit gives k ≤ 0): {fix}"
        )
    Mw, bw = _stacked(sets, prior, w, eta)
    z = np.concatenate([x, k])
    rel = _standard_errors(Mw, Mw @ z - bw)[p:] / k
    return k, eta, rel


def _fit_payload(
    data: IdentificationData, reference: PayloadReference, robot: Robot, options: IdentifyOptions
) -> tuple[FloatArray, float, FloatArray]:
    return _fit_sets(_payload_sets(data, reference, robot, options), None, options, fix=_PAYLOAD_FIX)


def _fit_nominal(
    data: IdentificationData, robot: Robot, options: IdentifyOptions
) -> tuple[FloatArray, float, FloatArray]:
    """The data's own solution, its scale (and what else the data leave open) set by the nominal torque."""
    A = _regressor(robot, data, options)
    nominal = robot.inverse_dynamics(data.q, data.qd, data.qdd)
    flat = [j + 1 for j in range(robot.n_joints) if not np.std(nominal[:, j]) > 1e-9]
    if flat:
        raise InvalidInput(
            f"the nominal model of {robot.name!r} gives joint(s) {', '.join(map(str, flat))} no torque on "
            "these logs: its masses fix no torque constant there; give a payload log "
            "(--payload-log, --payload-mass, --payload-com)"
        )
    prior = _Prior(A[:, :, : base_parameters(robot).n], nominal, NOMINAL_PRIOR_WEIGHT)
    sets = [_Set(A, data.tau, gear_side_speed(data.qd, options.rest_speed), np.zeros_like(data.tau))]
    return _fit_sets(sets, prior, options, fix=_NOMINAL_FIX)


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

    Raises
    ------
    InvalidInput
        Data that hold torques, or whose joint count differs from the robot's; a
        reference that does not fix every ``k_j`` (a payload whose effect is below the
        noise: ``k_j <= 0`` or known to worse than :data:`MAX_GAIN_ERROR`).
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
        k, eta, rel = _fit_nominal(data, robot, options)
        reference, note = "nominal", f"the nominal masses of {robot.name}"
        sources = data.sources
    else:
        k, eta, rel = _fit_payload(data, payload, robot, options)
        reference, note = "payload", payload.describe()
        sources = (*data.sources, *payload.data.sources)
    worst = int(np.argmax(rel))
    if not rel[worst] <= MAX_GAIN_ERROR:
        raise InvalidInput(
            f"joint {worst + 1}'s torque constant is known only to ±{100 * rel[worst]:.3g} % (limit "
            f"{100 * MAX_GAIN_ERROR:g} %): " + (_PAYLOAD_FIX if payload is not None else _NOMINAL_FIX)
        )
    return DriveGainFit(
        torque_constant=tuple(float(v) for v in k),
        relative_error=tuple(float(v) for v in rel),
        gear_efficiency=float(eta),
        reference=reference,
        reference_note=note,
        sources=sources,
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
    "CurrentIdentification",
    "DriveGainFit",
    "MAX_GAIN_ERROR",
    "PayloadReference",
    "REFERENCES",
    "fit_drive_gains",
    "identified_drives",
    "identify_from_currents",
]
