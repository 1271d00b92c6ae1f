"""The energy chain from joint to cabinet, declared once: each stage a named quantity with its units.

Per sample and joint ``i`` (arrays ``(..., n)``; SI units, :mod:`joulepath.units`):

1. ``joint`` — joint mechanical power ``p = tau * qd`` (W). ``tau`` is the joint
   torque the dynamics give, friction included.
2. ``gear`` — motor-side mechanical power ``tau_m * qd`` (W), with the gears of
   efficiency ``eta``: ``tau_m = tau / eta`` while the motor drives (``tau * qd > 0``),
   ``tau * eta`` otherwise (braking, or at rest). The gear loss is always ≥ 0.
3. ``copper`` — motor copper losses ``R * i**2`` (W) with ``i = tau_m / k``
   (``k`` the joint-side torque constant, N·m/A; ``R`` the winding resistance, Ω).
   Spent at rest too: holding costs energy.
4. ``motor`` — electrical power into each motor, ``gear + copper`` (W).
5. ``drive`` — power each drive draws from the DC bus (W): ``motor / eta_d`` when
   positive, ``motor * eta_d`` when negative (drive losses, both directions).
6. ``bus`` — the cabinet's motion power (W, per sample, summed over the axes) by bus kind:

   * ``"bleeder"``: the axes share a DC link; its net negative power is burnt in
     the bleeder resistor: ``max(Σ drive, 0)``;
   * ``"regenerative"``: the net negative power is returned to the grid with the
     efficiency ``eta_r``: ``Σ drive`` when positive, ``eta_r * Σ drive`` otherwise;
   * ``"per-axis"``: nothing is shared, each axis burns its own braking power:
     ``Σ max(drive, 0)``.
7. ``standby`` — the cabinet's standby power (W), drawn for the whole time.

:func:`chain_power` evaluates stages 1–6 exactly (``eps = 0``) or smoothed
(``eps > 0``, W): every ``|x|`` becomes ``sqrt(x² + eps²) - eps``, every
``max(x, 0)`` its half-sum with ``x`` and its step ``1[x > 0]`` that sum's
derivative; the gears' switch between driving and braking becomes ``p³ / (p³ + eps³)``
for ``p > 0`` (0 at rest, as exactly), so that the optimizer gets exact gradients of a
smooth function that tends to the true one as ``eps -> 0``, at rest too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import ArrayLike, FloatArray
from joulepath.energy._drives import DriveModel


@dataclass(frozen=True, slots=True)
class Stage:
    """One stage of the chain: its name, unit and what it assumes."""

    name: str
    unit: str
    quantity: str
    assumptions: str


STAGES: dict[str, Stage] = {
    s.name: s
    for s in (
        Stage("joint", "W", "tau * qd per joint", "tau: rigid body + the robot's friction, at the joint"),
        Stage(
            "gear",
            "W",
            "tau_m * qd per joint (motor side)",
            "tau_m = tau / eta driving (tau * qd > 0), tau * eta braking or at rest; eta per joint",
        ),
        Stage(
            "copper",
            "W",
            "R * (tau_m / k)² per joint",
            "k: joint-side torque constant (N·m/A), R: winding resistance (Ω); the torque current only",
        ),
        Stage("motor", "W", "gear + copper per joint", "electrical power into each motor"),
        Stage(
            "drive",
            "W",
            "motor / eta_d (drawing) or motor * eta_d (feeding back) per joint",
            "eta_d: the drive's efficiency, the same in both directions",
        ),
        Stage(
            "bus",
            "W",
            "the cabinet's motion power, summed over the axes",
            "bleeder: max(Σ, 0); regenerative: Σ, or eta_r * Σ when negative; per-axis: Σ max(drive, 0)",
        ),
        Stage("standby", "W", "standby power", "constant, drawn for the whole time"),
    )
}
"""The chain's stages, in order from joint to cabinet."""


@dataclass(frozen=True, slots=True)
class Drivetrain:
    """What a robot's measures beyond the joint need, and where each part came from.

    ``gear_efficiency`` (per joint, or None: unknown) and ``drives`` (None: no drive
    data); the ``*_source`` strings say where each came from, or why it is missing
    (shown with every figure that uses it).
    """

    gear_efficiency: tuple[float, ...] | None = None
    gear_source: str = "none"
    drives: DriveModel | None = None
    drives_source: str = "none"


def _abs(x: FloatArray, eps: float) -> tuple[FloatArray, FloatArray]:
    if eps > 0:
        r = np.sqrt(x * x + eps * eps)
        return r - eps, x / r
    return np.abs(x), np.sign(x)


def _step(x: FloatArray, eps: float) -> tuple[FloatArray, FloatArray]:
    """``1[x > 0]`` and its derivative (smoothed: the derivative of the smoothed ``max(x, 0)``)."""
    if eps > 0:
        r = np.sqrt(x * x + eps * eps)
        return 0.5 * (1.0 + x / r), 0.5 * eps * eps / (r * r * r)
    return (x > 0).astype(float), np.zeros_like(x)


def _driving(x: FloatArray, eps: float) -> tuple[FloatArray, FloatArray]:
    """The gears' switch ``1[p > 0]`` and its derivative; smoothed one-sided, ``p³ / (p³ + eps³)``
    for ``p > 0``: exactly 0 at rest (``p = 0``: the motor holds ``tau * eta``), twice continuously
    differentiable."""
    if eps > 0:
        pos = np.maximum(x, 0.0)
        e3 = eps * eps * eps
        d = pos * pos * pos + e3
        return pos * pos * pos / d, 3.0 * pos * pos * e3 / (d * d)
    return (x > 0).astype(float), np.zeros_like(x)


def _pos(x: FloatArray, eps: float) -> tuple[FloatArray, FloatArray]:
    """``max(x, 0)`` and its derivative."""
    a, _ = _abs(x, eps)
    h, _ = _step(x, eps)
    return 0.5 * (x + a), h


def motor_side_torque(tau: ArrayLike, qd: ArrayLike, gear_efficiency: float | ArrayLike) -> FloatArray:
    """Stage ``gear``'s torque: ``tau / eta`` while driving (``tau * qd > 0``), ``tau * eta`` otherwise.

    Examples
    --------
    >>> motor_side_torque([2.0, 2.0], [1.0, -1.0], 0.8)
    array([2.5, 1.6])
    """
    t = np.asarray(tau, dtype=float)
    v = np.asarray(qd, dtype=float)
    eta = np.asarray(gear_efficiency, dtype=float)
    out: FloatArray = np.where(t * v > 0, t / eta, t * eta)
    return out


@dataclass(frozen=True, slots=True)
class ChainPower:
    """Every stage of the chain for sampled torques and speeds (W).

    Per joint, shape (..., n): ``joint``, ``gear``, ``copper``, ``motor``, ``drive``
    (stages without their data are None). Per sample, shape (...): ``bus``.
    ``d_tau``, ``d_qd`` (..., n): the derivatives of ``bus`` (or of the last stage
    computed) with respect to ``tau`` and ``qd``.
    """

    joint: FloatArray
    gear: FloatArray | None
    copper: FloatArray | None
    motor: FloatArray | None
    drive: FloatArray | None
    bus: FloatArray | None


@dataclass(frozen=True, slots=True)
class SmoothPower:
    """A measure's power per sample (W, shape (...)) and its derivatives (shape (..., n))."""

    value: FloatArray
    d_tau: FloatArray
    d_qd: FloatArray


def _gear(
    tau: FloatArray, qd: FloatArray, eta: FloatArray, eps: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """``tau_m``, ``p_m`` and their derivatives with respect to ``tau`` and ``qd``."""
    p = tau * qd
    h, dh = _driving(p, eps)
    gain = eta + (1.0 / eta - eta) * h
    dgain = (1.0 / eta - eta) * dh  # d gain / d p
    tau_m = tau * gain
    dtm_dtau = gain + tau * dgain * qd
    dtm_dqd = tau * dgain * tau
    p_m = p * gain
    dpm_dp = gain + p * dgain
    return tau_m, dtm_dtau, dtm_dqd, p_m, dpm_dp * qd, dpm_dp * tau


def thesis_power(tau: FloatArray, qd: FloatArray, eps: float = 0.0) -> SmoothPower:
    """``Σ_i |tau_i qd_i|`` per sample (the thesis' measure, stage ``joint``) and its derivatives."""
    a, da = _abs(tau * qd, eps)
    return SmoothPower(a.sum(axis=-1), da * qd, da * tau)


def mechanical_power(
    tau: FloatArray, qd: FloatArray, gear_efficiency: ArrayLike, eps: float = 0.0
) -> SmoothPower:
    """``Σ_i |tau_m,i qd_i|`` per sample (stage ``gear``: at the motor side of the gears)."""
    eta = np.asarray(gear_efficiency, dtype=float)
    _, _, _, p_m, dpm_dtau, dpm_dqd = _gear(tau, qd, eta, eps)
    a, da = _abs(p_m, eps)
    return SmoothPower(a.sum(axis=-1), da * dpm_dtau, da * dpm_dqd)


def electrical_power(
    tau: FloatArray, qd: FloatArray, drivetrain: Drivetrain, eps: float = 0.0
) -> SmoothPower:
    """The cabinet's motion power per sample (stage ``bus``, standby not included) and its derivatives."""
    drives = drivetrain.drives
    if drives is None or drivetrain.gear_efficiency is None:
        raise ValueError("electrical_power needs drives and a gear efficiency")  # callers check first
    eta = np.asarray(drivetrain.gear_efficiency, dtype=float)
    k = np.asarray(drives.torque_constant, dtype=float)
    R = np.asarray(drives.resistance, dtype=float)
    eta_d = np.asarray(drives.drive_efficiency, dtype=float)
    tau_m, dtm_dtau, dtm_dqd, p_m, dpm_dtau, dpm_dqd = _gear(tau, qd, eta, eps)
    cu = R * tau_m * tau_m / (k * k)
    dcu = 2.0 * R * tau_m / (k * k)
    p_e = p_m + cu
    dpe_dtau = dpm_dtau + dcu * dtm_dtau
    dpe_dqd = dpm_dqd + dcu * dtm_dqd
    pos_e, h_e = _pos(p_e, eps)
    p_a = eta_d * p_e + (1.0 / eta_d - eta_d) * pos_e
    dpa = eta_d + (1.0 / eta_d - eta_d) * h_e
    if drives.bus == "per-axis":
        pos_a, h_a = _pos(p_a, eps)
        value = pos_a.sum(axis=-1)
        w = h_a
    else:
        total = p_a.sum(axis=-1)
        pos_t, h_t = _pos(total, eps)
        if drives.bus == "bleeder":
            value, w_bus = pos_t, h_t
        else:  # regenerative
            eta_r = drives.regen_efficiency
            value = eta_r * total + (1.0 - eta_r) * pos_t
            w_bus = eta_r + (1.0 - eta_r) * h_t
        w = np.broadcast_to(np.asarray(w_bus)[..., None], p_a.shape)
    g = w * dpa
    return SmoothPower(np.asarray(value, dtype=float), g * dpe_dtau, g * dpe_dqd)


def chain_power(tau: ArrayLike, qd: ArrayLike, drivetrain: Drivetrain) -> ChainPower:
    """Every stage of the chain, exactly, for torques and speeds of shape (..., n).

    Stages whose data the drivetrain lacks are None (``gear`` needs a gear
    efficiency, the later ones drive data as well).

    Examples
    --------
    >>> from joulepath.energy import DriveModel, Drivetrain
    >>> drives = DriveModel(torque_constant=(2.0,), resistance=(1.0,), drive_efficiency=(1.0,))
    >>> c = chain_power([[4.0]], [[0.0]], Drivetrain(gear_efficiency=(1.0,), drives=drives))
    >>> float(c.copper[0, 0])  # holding 4 N·m: 2 A through 1 Ω
    4.0
    """
    t = np.asarray(tau, dtype=float)
    v = np.asarray(qd, dtype=float)
    joint = t * v
    if drivetrain.gear_efficiency is None:
        return ChainPower(joint, None, None, None, None, None)
    eta = np.asarray(drivetrain.gear_efficiency, dtype=float)
    tau_m = motor_side_torque(t, v, eta)
    gear = tau_m * v
    drives = drivetrain.drives
    if drives is None:
        return ChainPower(joint, gear, None, None, None, None)
    k = np.asarray(drives.torque_constant, dtype=float)
    copper = np.asarray(drives.resistance, dtype=float) * (tau_m / k) ** 2
    motor = gear + copper
    eta_d = np.asarray(drives.drive_efficiency, dtype=float)
    drive = np.where(motor > 0, motor / eta_d, motor * eta_d)
    if drives.bus == "per-axis":
        bus = np.maximum(drive, 0.0).sum(axis=-1)
    else:
        total = drive.sum(axis=-1)
        if drives.bus == "bleeder":
            bus = np.maximum(total, 0.0)
        else:
            bus = np.where(total > 0, total, drives.regen_efficiency * total)
    return ChainPower(joint, gear, copper, motor, drive, np.asarray(bus, dtype=float))
