"""Least-squares identification of base inertial parameters, friction and drive losses.

Steps (:func:`identify`):

1. **Regressor.** ``tau = [Y_b(q, qd, qdd) | F(qd)] x`` stacked over every sample and
   joint: ``Y_b`` the base columns of Pinocchio's joint torque regressor with, by default,
   one armature column per joint (the drives' reflected rotor inertia, ``armature_i *
   qdd_i``; :func:`~joulepath.identify.base_parameters`), ``F`` the friction columns.
2. **Excitation.** The condition number of the stacked regressor with unit-norm
   columns (weighted rows). Data that leave a parameter unexcited (a joint that never
   moves, a condition number over ``max_condition``) are refused with the parameter
   named, never turned into a twin.
3. **Drive losses.** Logged torque is motor side: ``tau/eta`` while driving,
   ``tau*eta`` while braking or at rest. For a trial ``eta`` the logged torque is
   mapped back to the joint side and the linear least-squares problem solved; ``eta``
   minimises the motor-side residual (a bounded scalar search; fixed when given).
4. **Weighting.** Two passes: ordinary least squares, then each joint's rows
   weighted by the inverse of its residual standard deviation (Gautier's weighted LS).
5. **Physical consistency.** The full parameters (10 per link) are searched in
   log-Cholesky coordinates (:mod:`joulepath.identify._consistency`, consistent by
   construction) with ``scipy.optimize.least_squares``: the same weighted data
   residual (through a QR compression of the full regressor), plus a small pull
   towards the nominal parameters (``prior_weight``) that fixes the directions the data
   cannot see (which do not change any torque). Friction coefficients and the armature
   are kept ≥ 0 (the offset may take either sign). Started from the least-squares base solution
   lifted onto the nominal parameters (minimum-norm change), or from the nominal
   parameters when that lift is not consistent.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
from scipy.optimize import least_squares, minimize_scalar

from joulepath._typing import FloatArray
from joulepath.dynamics import IdentifiedFriction, Robot, motor_torque
from joulepath.energy import joint_energy
from joulepath.errors import InvalidInput
from joulepath.identify._consistency import from_log_cholesky, min_eigenvalues, to_log_cholesky
from joulepath.identify._data import IdentificationData, MotionDerivation
from joulepath.identify._regressor import (
    BaseParameters,
    base_parameters,
    dynamic_regressor,
    friction_regressor,
    true_parameters,
)

REST_SPEED = np.radians(1.0)
MIN_TORQUE_SPREAD = 1e-6
"""N·m: a joint whose logged torque varies less (standard deviation) holds no torque information."""
"""A joint whose logged speed never exceeds this (rad/s) never moved: its friction cannot be identified."""

GEAR_REST_SPEED = 0.005
"""rad/s: an arm whose every logged joint speed is within this is at rest for the side of the gear
losses (:func:`gear_side_speed`); the width of the friction model's ``sign(qd)`` by default."""

MAX_CONDITION = 1e4
"""Default refusal threshold of the condition number of the column-normalised stacked regressor."""

ETA_BOUNDS = (0.5, 1.0)

UNEXCITED = ("prior", "refuse")
MAX_KEPT_SHARE = 0.25
"""Logs that would leave more than this share of the parameters at their priors are refused."""
KEPT_WEIGHT = 1e3
"""Pull that holds a kept parameter at its prior in the consistent refinement, relative to the
strongest pull of the data on any parameter."""


class UnexcitedParameterWarning(UserWarning):
    """The logs do not excite a parameter: it keeps its prior value (:attr:`Identification.kept`)."""


@dataclass(frozen=True, slots=True)
class KeptParameter:
    """A parameter the logs leave unexcited, kept at its prior value.

    Attributes
    ----------
    name : str
        ``link<i>.<parameter>`` (a base parameter, named by its leading column) or
        ``joint<j>.<term>`` (a friction term).
    prior : float
        The value kept (SI: kg, kg·m, kg·m², N·m, N·m·s/rad).
    prior_source : str
        Where the value comes from.
    reason : str
        Why it is not identified.
    """

    name: str
    prior: float
    prior_source: str
    reason: str

    def warning(self) -> str:
        return (
            f"{self.name} is not excited by the logs ({self.reason}): kept at its prior {self.prior:.4g} "
            f"({self.prior_source}); log moves that excite it to identify it"
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class IdentifyOptions:
    """Settings of :func:`identify`.

    Attributes
    ----------
    offset : bool
        Identify a per-joint friction offset (a torque added in both directions of motion).
    stribeck_speed : float or None
        rad/s: identify a Stribeck term of this characteristic speed (None: none).
    viscous_offset : bool
        Identify the viscous level per direction of motion (a ``viscous_offset`` term,
        ``|qd|`` smoothed at rest, beside ``viscous * qd``). On the KUKA KR300 logs the
        largest single gain in held-out torque R² (``benchmarks/identify_real.py``).
    smoothing : float
        rad/s: the ``tanh`` width standing for ``sign(qd)`` in the friction terms.
    gear_efficiency : float or None
        Fixed drive efficiency in (0, 1] (1: the log holds joint-side torque); None estimates it.
    weighted : bool
        Second, weighted pass (inverse residual standard deviation per joint).
    consistent : bool
        Refine to physically consistent parameters (log-Cholesky); False keeps the
        least-squares base parameters only (and the nominal parameters elsewhere).
    prior_weight : float
        Weight of the pull towards the nominal parameters in the consistent refinement.
    max_condition : float
        Refuse data whose stacked, column-normalised regressor has a larger condition number.
    holdout : float
        Share of the samples (the last ones, in log order) kept out of the fit and scored.
    unexcited : {"prior", "refuse"}
        What to do when the logs leave parameters unexcited (the condition number over
        ``max_condition``). ``"prior"``: keep the least excited parameter at its prior
        value (a base parameter at the nominal description's, a friction term at the
        robot's friction, else 0), one by one until the rest is conditioned within
        ``max_condition``, with an :class:`UnexcitedParameterWarning` naming each
        (:attr:`Identification.kept`); refused when that would keep more than
        :data:`MAX_KEPT_SHARE` of the parameters. ``"refuse"``: refuse the logs.
    rest_speed : float
        rad/s: a sample whose every joint speed is within this counts as the arm at rest
        for the side of the gear losses (:func:`gear_side_speed`): logged speeds that small
        are sensor noise. 0 for exact speeds (a plant's signals).
    armature : bool
        Identify an armature per joint (the drives' rotating inertia reflected to the joint,
        ``armature_i * qdd_i``, :attr:`joulepath.description.Chain.armature`), ≥ 0 in the
        consistent refinement. A log of motor torques holds it (KUKA KR300: +0.02 to +0.04
        held-out torque R², ``benchmarks/identify_real.py``); a joint-side torque sensor
        after the gear does not (it reads about 0 there). Its prior is the robot's own armature
        (0 for a URDF or IRML arm). False: the rigid-body links only (the twin has no armature).
    """

    offset: bool = True
    stribeck_speed: float | None = None
    viscous_offset: bool = False
    smoothing: float = 0.005
    gear_efficiency: float | None = None
    weighted: bool = True
    consistent: bool = True
    prior_weight: float = 1e-4
    max_condition: float = MAX_CONDITION
    holdout: float = 0.0
    unexcited: str = "prior"
    rest_speed: float = GEAR_REST_SPEED
    armature: bool = True

    def __post_init__(self) -> None:
        if not self.smoothing > 0:
            raise InvalidInput(f"smoothing must be a positive speed in rad/s, got {self.smoothing}")
        if self.stribeck_speed is not None and not self.smoothing <= self.stribeck_speed <= 100.0:
            raise InvalidInput(
                f"the Stribeck speed must be {self.smoothing:g} to 100 rad/s, got {self.stribeck_speed:g}: "
                f"below the smoothing width ({self.smoothing:g} rad/s) the term acts only at rest and cannot "
                "be identified; give e.g. 0.05"
            )
        if self.gear_efficiency is not None and not 0.0 < self.gear_efficiency <= 1.0:
            raise InvalidInput(f"gear efficiency must be in (0, 1], got {self.gear_efficiency}")
        if not 0.0 <= self.holdout < 0.9:
            raise InvalidInput(f"holdout must be a share in [0, 0.9), got {self.holdout}")
        if not (math.isfinite(self.rest_speed) and self.rest_speed >= 0):
            raise InvalidInput(f"rest_speed must be a speed ≥ 0 in rad/s, got {self.rest_speed}")
        if self.unexcited not in UNEXCITED:
            raise InvalidInput(f"unexcited must be one of {UNEXCITED}, got {self.unexcited!r}")
        if not self.max_condition > 1 or not self.prior_weight >= 0:
            raise InvalidInput("max_condition must be > 1 and prior_weight ≥ 0")


@dataclass(frozen=True, slots=True)
class FitScores:
    """How well identified torques and energies match the logged ones (motor side).

    ``path_energy_error_pct`` is the median over the data's continuous stretches of
    ``|E_pred - E_logged| / E_logged`` (energies ``Σ |tau qd| dt``).
    """

    n_samples: int
    torque_r2: tuple[float, ...]
    torque_rmse: tuple[float, ...]
    energy_r2: float
    energy_error_pct: float
    path_energy_error_pct: float


@dataclass(frozen=True, slots=True, eq=False)
class Identification:
    """The identified model of one robot.

    Attributes
    ----------
    robot_name : str
    base : BaseParameters
    beta_ls : ndarray
        Least-squares base parameters (unconstrained).
    phi : ndarray of shape (10 n,)
        Full inertial parameters: physically consistent when ``consistent`` (else the
        nominal parameters moved by the minimum-norm change that gives ``beta_ls``).
    friction : IdentifiedFriction
    gear_efficiency : float
    condition_number : float
        Of the stacked, weighted, column-normalised regressor ``[Y_b | F]``.
    weakest : str
        The parameter least excited by the data (largest share of the smallest singular vector).
    weights : ndarray of shape (n,)
        Row weight of each joint (1/N·m).
    fit, held_out : FitScores
        On the fitted samples; on the held-out ones (None without a hold-out).
    min_pseudo_inertia_eig : ndarray of shape (n,)
        Smallest eigenvalue of each link's pseudo-inertia (> 0: consistent).
    armature : ndarray of shape (n,) or None
        kg·m² per joint (:attr:`joulepath.description.Chain.armature`), ≥ 0 when ``consistent``;
        None when not identified (``IdentifyOptions(armature=False)``).
    motion : MotionDerivation or None
        How the data's speeds and accelerations were derived from the logs
        (:attr:`IdentificationData.motion`: raw, or low-passed at a cutoff); the card's ``motion``.
    """

    robot_name: str
    base: BaseParameters
    beta_ls: FloatArray
    phi: FloatArray
    friction: IdentifiedFriction
    gear_efficiency: float
    condition_number: float
    weakest: str
    weights: FloatArray
    fit: FitScores
    held_out: FitScores | None
    min_pseudo_inertia_eig: FloatArray
    consistent: bool
    options: IdentifyOptions
    data_hash: str = ""
    sources: tuple[str, ...] = field(default=())
    kept: tuple[KeptParameter, ...] = field(default=())
    armature: FloatArray | None = None
    motion: MotionDerivation | None = None

    @property
    def parameters(self) -> FloatArray:
        """The full parameters the base set is of: :attr:`phi`, then :attr:`armature` if identified."""
        return self.phi if self.armature is None else np.concatenate([self.phi, self.armature])

    @property
    def beta(self) -> FloatArray:
        """Base parameters of :attr:`parameters` (:attr:`beta_ls` up to the consistency constraint)."""
        return self.base.project(self.parameters)

    def joint_torque(self, robot: Robot, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
        """Joint-side torque ``Y phi + armature qdd + F f`` (N·m) for samples ``(N, n)``; ``robot``
        gives the kinematics."""
        Y = dynamic_regressor(robot, q, qd, qdd, armature=self.armature is not None)
        out: FloatArray = Y @ self.parameters + self.friction.torque(qd)
        return out

    def motor_torque(self, robot: Robot, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
        """Torque as the drives log it (gear losses included), N·m."""
        side = gear_side_speed(qd, self.options.rest_speed)
        return motor_torque(self.joint_torque(robot, q, qd, qdd), side, self.gear_efficiency)

    def card(self) -> dict[str, Any]:
        """JSON-ready summary (the twin's card adds what it was written from)."""
        return {
            "robot": self.robot_name,
            "data_sha256": self.data_hash,
            "logs": list(self.sources),
            "n_base_parameters": self.base.n,
            "condition_number": self.condition_number,
            "least_excited_parameter": self.weakest,
            "gear_efficiency": self.gear_efficiency,
            "physically_consistent": self.consistent,
            "min_pseudo_inertia_eigenvalue": [float(v) for v in self.min_pseudo_inertia_eig],
            "armature": None if self.armature is None else [float(v) for v in self.armature],
            "motion": None if self.motion is None else self.motion.to_json(),
            "fit": asdict(self.fit),
            "held_out": None if self.held_out is None else asdict(self.held_out),
            "options": asdict(self.options),
            "kept_at_prior": [asdict(k) for k in self.kept],
            "base_parameters": {name: float(v) for name, v in zip(self.base.names, self.beta, strict=True)},
            "base_parameters_least_squares": {
                name: float(v) for name, v in zip(self.base.names, self.beta_ls, strict=True)
            },
        }


def gear_side_speed(qd: FloatArray, rest_speed: float = GEAR_REST_SPEED) -> FloatArray:
    """The speeds that decide the side of the gear losses in a log: 0 while the arm is at rest.

    The arm is at rest in a sample where every joint is within ``rest_speed``. Its
    logged speeds are then the speed sensor's noise, not directions of motion: a joint
    held at rest pays ``tau * eta`` (see :func:`motor_torque`) whatever the noise's sign.
    A single joint passing through zero speed while others move keeps its sign.
    Identification and evaluation decide the side of logged samples by these speeds.
    """
    rest = np.all(np.abs(qd) <= rest_speed, axis=-1, keepdims=True)
    out: FloatArray = np.where(rest, 0.0, qd)
    return out


def joint_side(tau_motor: FloatArray, qd: FloatArray, eta: float) -> FloatArray:
    """Invert the drive-loss model: joint torque of a logged motor torque (see :func:`motor_torque`)."""
    if eta == 1.0:
        return tau_motor
    out: FloatArray = np.where(tau_motor * qd > 0, tau_motor * eta, tau_motor / eta)
    return out


def _check_motion(data: IdentificationData, n_params: int) -> None:
    if data.n_samples * data.n_joints < 2 * n_params:
        raise InvalidInput(
            f"{data.n_samples} samples give {data.n_samples * data.n_joints} torque equations for "
            f"{n_params} parameters; log at least {2 * n_params // data.n_joints + 1} samples "
            "(more moves)"
        )
    spread = np.std(data.tau, axis=0)
    flat = [j + 1 for j in range(data.n_joints) if not spread[j] > MIN_TORQUE_SPREAD]
    if flat:
        j = flat[0] - 1
        what = "torque" if data.signal == "torque" else "current"
        raise InvalidInput(
            f"the logged {what} of joint(s) {', '.join(map(str, flat))} never varies (joint {j + 1}: "
            f"{float(data.tau[0, j]):g} {data.unit} in every sample): such logs hold no torque "
            "information, whatever the motion; log the drives' torque (or current) and identify again"
        )
    still = [j + 1 for j in range(data.n_joints) if np.abs(data.qd[:, j]).max() <= REST_SPEED]
    if still:
        raise InvalidInput(
            f"joint(s) {', '.join(map(str, still))} never move in the logs (speed ≤ 1 deg/s): their "
            "friction and inertia cannot be identified; log moves of every joint (e.g. random moves "
            "from `joulepath simulate`) and identify again"
        )


def _excitation(A: FloatArray) -> tuple[float, int]:
    """Condition number of ``A`` (rows x params) with unit-norm columns, and the least excited column."""
    norms = np.linalg.norm(A, axis=0)
    zero = np.nonzero(norms == 0)[0]
    if zero.size:
        return float("inf"), int(zero[0])
    R = scipy.linalg.qr(A / norms, mode="r")[0][: A.shape[1]]
    _, s, vt = np.linalg.svd(R)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    return cond, int(np.argmax(np.abs(vt[-1])))


def _least_excited(A: FloatArray, known: FloatArray) -> tuple[float, int]:
    """Like :func:`_excitation`, but the column to keep at its prior: of the columns that make up the
    weakest direction (at least half the largest share), one whose prior is known (``known``)
    before one whose prior is a bare 0; of those alike (within 1 %, e.g. Coulomb and offset of a
    joint turning one way), the later column (the offset, the outer link), so that the earlier one
    is identified."""
    norms = np.linalg.norm(A, axis=0)
    if np.any(norms == 0):
        return _excitation(A)
    R = scipy.linalg.qr(A / norms, mode="r")[0][: A.shape[1]]
    _, s, vt = np.linalg.svd(R)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    share = np.abs(vt[-1])
    part = np.nonzero(share >= 0.5 * share.max())[0]
    if np.any(known[part]):
        part = part[known[part]]
    tied = part[share[part] >= 0.99 * share[part].max()]
    return cond, int(tied[-1])


def _select_kept(
    Aw: FloatArray, kept: list[int], options: IdentifyOptions, known: FloatArray
) -> tuple[list[int], float, int]:
    """Columns to keep at their priors (``kept`` plus the least excited, one by one), the condition
    number of the rest and its least excited column. ``"refuse"`` adds none; neither adds beyond
    :data:`MAX_KEPT_SHARE` of the columns (the caller refuses then)."""
    p = Aw.shape[1]
    kept = list(kept)
    while True:
        free = [i for i in range(p) if i not in kept]
        cond, weak = _least_excited(Aw[:, free], known[free])
        if (
            cond <= options.max_condition
            or options.unexcited == "refuse"
            or len(kept) + 1 > MAX_KEPT_SHARE * p
        ):
            return kept, cond, free[weak]
        kept.append(free[weak])


def r2_per_joint(measured: FloatArray, predicted: FloatArray) -> FloatArray:
    """Coefficient of determination per column: ``1 - Σ(pred - meas)² / Σ(meas - mean)²``.

    Parameters
    ----------
    measured, predicted : ndarray of shape (N, n)

    Returns
    -------
    ndarray of shape (n,)
        1 for a perfect prediction; NaN for a column of constant measured values
        (no variance to explain).

    Examples
    --------
    >>> r2_per_joint(np.array([[0.0], [1.0], [2.0]]), np.array([[0.0], [1.0], [3.0]])).round(3).tolist()
    [0.5]
    """
    res = predicted - measured
    sst = ((measured - measured.mean(axis=0)) ** 2).sum(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        out: FloatArray = np.where(sst > 0, 1.0 - (res**2).sum(axis=0) / np.where(sst > 0, sst, 1.0), np.nan)
    return out


def score_prediction(pred: FloatArray, data: IdentificationData) -> FitScores:
    """Scores of predicted (motor-side) torques ``pred`` ``(N, n)`` against the data's."""
    tau = data.tau
    res = pred - tau
    r2 = r2_per_joint(tau, pred)
    e_true = joint_energy(tau, data.qd, data.dt).sum(axis=1)
    e_pred = joint_energy(pred, data.qd, data.dt).sum(axis=1)
    sse = float(((e_pred - e_true) ** 2).sum())
    sst_e = float(((e_true - e_true.mean()) ** 2).sum())
    errors = []
    for s in np.unique(data.stretch):
        m = data.stretch == s
        total = e_true[m].sum()
        if total > 0:
            errors.append(abs(e_pred[m].sum() - total) / total)
    return FitScores(
        n_samples=data.n_samples,
        torque_r2=tuple(float(v) for v in r2),
        torque_rmse=tuple(float(v) for v in np.sqrt((res**2).mean(axis=0))),
        energy_r2=1.0 - sse / sst_e if sst_e > 0 else float("nan"),
        energy_error_pct=100.0 * abs(float(e_pred.sum() - e_true.sum())) / max(float(e_true.sum()), 1e-300),
        path_energy_error_pct=100.0 * float(np.median(errors)) if errors else float("nan"),
    )


def search_eta(cost: Callable[[float], float], fixed: float | None) -> float:
    """The gear efficiency in :data:`ETA_BOUNDS` of least ``cost`` (a bounded scalar search), or ``fixed``."""
    if fixed is not None:
        return fixed
    best = minimize_scalar(cost, bounds=ETA_BOUNDS, method="bounded", options={"xatol": 1e-5})
    return float(best.x)


class _Problem:
    """The stacked weighted least-squares problem of one data set."""

    def __init__(self, A: FloatArray, tau: FloatArray, qd: FloatArray, prior: FloatArray) -> None:
        self.A, self.tau, self.qd, self.prior = A, tau, qd, prior  # A: (N, n, p); prior: (p,)
        self.n = tau.shape[1]

    def solve(self, w: FloatArray, eta: float | None, kept: list[int]) -> tuple[float, FloatArray]:
        """The gear efficiency and parameters of least weighted residual, ``kept`` at their priors."""
        N, n, p = self.A.shape
        free = np.array([i for i in range(p) if i not in kept], dtype=int)
        fixed = np.zeros(p)
        fixed[kept] = self.prior[kept]
        known = self.A @ fixed
        Aw = (self.A[:, :, free] * w[None, :, None]).reshape(-1, free.size)
        pinv = np.linalg.pinv(Aw)

        def fit(e: float) -> tuple[float, FloatArray]:
            target = joint_side(self.tau, self.qd, e) - known
            x = fixed.copy()
            x[free] = pinv @ (target * w).ravel()
            pred = motor_torque(self.A @ x, self.qd, e)
            return float((((pred - self.tau) * w) ** 2).sum()), x

        e = search_eta(lambda e: fit(e)[0], eta)
        return e, fit(e)[1]


def _friction_of(
    f: FloatArray, terms: tuple[str, ...], n: int, options: IdentifyOptions
) -> IdentifiedFriction:
    blocks = {t: tuple(float(v) for v in f[k * n : (k + 1) * n]) for k, t in enumerate(terms)}
    zero = (0.0,) * n
    return IdentifiedFriction(
        coulomb=blocks["coulomb"],
        viscous=blocks["viscous"],
        offset=blocks.get("offset", zero),
        stribeck=blocks.get("stribeck", zero),
        stribeck_speed=options.stribeck_speed or 0.05,
        viscous_offset=tuple(blocks["viscous_offset"]) if "viscous_offset" in blocks else (),
        smoothing=options.smoothing,
    )


def _lift(base: BaseParameters, beta: FloatArray, prior: FloatArray) -> FloatArray:
    """Full parameters closest to ``prior`` (least squares) whose base parameters are ``beta``."""
    B = base.matrix()
    out: FloatArray = prior + np.linalg.lstsq(B, beta - B @ prior, rcond=None)[0]
    return out


LINK_FLOORS = np.array([0.1, 0.01, 0.01, 0.01, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3])
"""Smallest scale of each of a link's 10 parameters in the pull towards the prior (kg, kg·m, kg·m²)."""
ARMATURE_SCALE_SHARE = 0.1
"""The scale of a joint's armature in the pull towards the prior: at least this share of the nominal
mass matrix's diagonal at home (the inertia the joint turns), and at least the least-squares value
(a geared drive's reflected rotor inertia can be many times its wrist link's: 70 kg·m² on a KUKA
KR300's joint 4, whose link turns 1.2 kg·m²), so that a prior of 0 does not pull an armature the
data show towards 0."""


def _parameter_floors(robot: Robot, n_params: int) -> FloatArray:
    """Smallest scale of each full parameter (``10 n`` inertial, then the armature if any)."""
    n = robot.n_joints
    floors = np.tile(LINK_FLOORS, n)
    if n_params == 10 * n:
        return floors
    turned = np.diag(np.asarray(robot.mass_matrix(robot.home), dtype=float))
    return np.concatenate([floors, np.maximum(ARMATURE_SCALE_SHARE * turned, 1e-3)])


def _prior_scale(prior: FloatArray, floors: FloatArray) -> FloatArray:
    out: FloatArray = np.maximum(np.abs(prior), floors)
    return out


CONSISTENT_MAX_NFEV = 300
"""Most residual evaluations of the consistent refinement."""

CONSISTENT_TOL = 1e-12
"""kg·m²: a link's pseudo-inertia with its smallest eigenvalue above minus this is consistent (an
eigenvalue of zero to rounding, -1.7e-18 on a UR5's first link refined to the boundary, is not a
violation)."""


def _consistent(
    Y: FloatArray,
    F: FloatArray,
    tau_joint: FloatArray,
    w: FloatArray,
    start_phi: FloatArray,
    start_f: FloatArray,
    prior: FloatArray,
    lower_f: FloatArray,
    prior_weight: float,
    held: tuple[FloatArray, FloatArray, FloatArray],
    f_fixed: dict[int, float],
    *,
    floors: FloatArray,
    max_nfev: int,
) -> tuple[FloatArray, FloatArray]:
    """``held = (G, g, scale)``: rows ``G @ phi = g`` held with weight :data:`KEPT_WEIGHT` (base
    parameters kept at their priors, each row divided by its scale); ``f_fixed``: friction
    coefficients (by index) kept at these values, not searched. ``phi`` (``start_phi``, ``prior``,
    ``Y``'s columns) holds ``10 n`` link parameters (searched in log-Cholesky coordinates), then
    the armature if any (searched ≥ 0)."""
    N, n, n_phi = Y.shape
    A = np.concatenate([Y, F], axis=2) * w[None, :, None]
    b = (tau_joint * w).reshape(-1, 1)
    Raug = scipy.linalg.qr(np.hstack([A.reshape(-1, A.shape[2]), b]), mode="r")[0]
    q = A.shape[2]
    R, c = Raug[:q, :q], Raug[:q, q]
    scale = _prior_scale(prior, floors)
    links = n
    n_arm = n_phi - 10 * links
    reg = np.sqrt(prior_weight * N * n)
    G, g, g_scale = held
    hold = KEPT_WEIGHT * float(np.abs(R).max()) * g_scale  # per unit of the parameter, 1e3 x the data's

    n_f = start_f.size
    free_f = np.array([k for k in range(n_f) if k not in f_fixed], dtype=int)
    f_all = np.zeros(n_f)
    for k, v in f_fixed.items():
        f_all[k] = v

    def phi_of(z: FloatArray) -> FloatArray:
        bodies = [from_log_cholesky(z[10 * i : 10 * i + 10]) for i in range(links)]
        return np.concatenate([*bodies, z[10 * links : 10 * links + n_arm]])

    def f_of(z: FloatArray) -> FloatArray:
        out = f_all.copy()
        out[free_f] = z[10 * links + n_arm :]
        return out

    def residual(z: FloatArray) -> FloatArray:
        with np.errstate(all="ignore"):  # trial steps far out (exp overflow) just read as very bad
            phi = phi_of(z)
            x = np.concatenate([phi, f_of(z)])
            out = np.concatenate([R @ x - c, reg * (phi - prior) / scale, hold * (G @ phi - g) / g_scale])
        clean: FloatArray = np.nan_to_num(out, nan=1e150, posinf=1e150, neginf=-1e150)
        return clean

    try:
        theta0 = np.concatenate([to_log_cholesky(start_phi[10 * i : 10 * i + 10]) for i in range(links)])
    except np.linalg.LinAlgError:
        theta0 = np.concatenate([to_log_cholesky(prior[10 * i : 10 * i + 10]) for i in range(links)])
    arm0 = np.maximum(start_phi[10 * links :], 1e-6 * floors[10 * links :])
    f0 = np.maximum(start_f, lower_f + 1e-9)[free_f]
    z0 = np.concatenate([theta0, arm0, f0])
    lo = np.concatenate([np.full(theta0.size, -np.inf), np.zeros(n_arm), lower_f[free_f]])
    # a trial step the residual marks with its 1e150 sentinel overflows in the solver's cost
    # (0.5 f·f); the solver rejects that step, so the overflow is no error
    with np.errstate(over="ignore"):
        sol = least_squares(residual, z0, bounds=(lo, np.inf), method="trf", x_scale="jac", max_nfev=max_nfev)
    return phi_of(sol.x), f_of(sol.x)


def _prior_values(
    robot: Robot, base: BaseParameters, prior: FloatArray, terms: tuple[str, ...]
) -> tuple[FloatArray, list[str], FloatArray]:
    """Prior value of every column of ``[Y_b | F]``, where it comes from, and whether it is known.

    Base parameters: the nominal description's. Friction: the robot's own friction
    where it has the term (an identified twin's, or Coulomb and viscous levels of a
    friction file), else 0 (none known).
    """
    n = robot.n_joints
    beta = base.project(prior)
    values = list(beta)
    given = robot.chain.armature is not None
    sources = [
        (
            f"nominal description of {robot.name}"
            if not name.endswith(".armature")
            else f"the armature of {robot.name}" + ("" if given else " (none given: 0)")
        )
        for name in base.names
    ]
    known = [given or not name.endswith(".armature") for name in base.names]
    friction = robot.friction
    for t in terms:
        level = getattr(friction, t, None) if friction is not None else None
        arr = None
        if level is not None:
            try:
                arr = np.broadcast_to(np.asarray(level, dtype=float).ravel(), (n,))
            except ValueError:
                arr = None
        if arr is None or not np.all(np.isfinite(arr)):
            values.extend([0.0] * n)
            why = "no friction known" if friction is None else f"the robot's friction gives no {t} level"
            sources.extend([f"0: {why} ({robot.friction_note})"] * n)
            known.extend([False] * n)
        else:
            values.extend(float(v) for v in arr)
            sources.extend([f"the robot's friction ({robot.friction_note})"] * n)
            known.extend([True] * n)
    return np.array(values), sources, np.array(known)


def _held_rows(
    base: BaseParameters, kept: list[int], prior_x: FloatArray, floors: FloatArray
) -> tuple[tuple[FloatArray, FloatArray, FloatArray], dict[int, float]]:
    """Rows ``G phi = g`` (with scales) that hold the kept base parameters at their priors, and the
    kept friction coefficients (index into the friction columns: value)."""
    B = base.matrix()
    rows = [i for i in kept if i < base.n]
    scale = np.array(
        [max(abs(float(prior_x[i])), floors[int(base.independent[i])]) for i in rows], dtype=float
    )
    friction = {i - base.n: float(prior_x[i]) for i in kept if i >= base.n}
    return (B[rows], prior_x[rows], scale), friction


def identify(
    data: IdentificationData, robot: Robot, options: IdentifyOptions | None = None
) -> Identification:
    """Identify base inertial parameters, friction and drive losses of ``robot`` from ``data``.

    ``robot`` gives the kinematics (and the nominal parameters the consistent
    refinement is pulled towards). See the module docstring for the steps.

    Raises
    ------
    InvalidInput
        The data cannot identify the model: too few samples, a joint that never
        moves, or a condition number over ``options.max_condition`` (the least
        excited parameter is named).
    """
    options = options or IdentifyOptions()
    if data.signal != "torque":
        raise InvalidInput(
            "these data hold motor currents (A), not torques: identify them with "
            "identify_from_currents and a reference for the torque scale (a payload log, or the "
            "nominal masses)"
        )
    if data.n_joints != robot.n_joints:
        raise InvalidInput(
            f"the data hold {data.n_joints} joints but robot {robot.name!r} has {robot.n_joints}"
        )
    fit_data, held = data, None
    if options.holdout > 0:
        cut = int(round((1.0 - options.holdout) * data.n_samples))
        idx = np.arange(data.n_samples)
        fit_data, held = data.subset(idx < cut), data.subset(idx >= cut)
    base = base_parameters(robot, armature=options.armature)
    n = robot.n_joints
    F, terms = friction_regressor(
        fit_data.qd,
        smoothing=options.smoothing,
        offset=options.offset,
        stribeck_speed=options.stribeck_speed,
        viscous_offset=options.viscous_offset,
    )
    _check_motion(fit_data, base.n + F.shape[2])
    Y = dynamic_regressor(robot, fit_data.q, fit_data.qd, fit_data.qdd, armature=options.armature)
    A = np.concatenate([Y[:, :, base.independent], F], axis=2)
    names = (*base.names, *(f"joint{j + 1}.{t}" for t in terms for j in range(n)))
    side = gear_side_speed(fit_data.qd, options.rest_speed)
    prior = true_parameters(robot, armature=options.armature)
    floors = _parameter_floors(robot, prior.size)
    prior_x, prior_sources, prior_known = _prior_values(robot, base, prior, terms)
    problem = _Problem(A, fit_data.tau, side, prior_x)
    w = np.ones(n)
    kept: list[int] = []
    if options.unexcited == "prior":
        kept = _select_kept(A.reshape(-1, A.shape[2]), kept, options, prior_known)[0]
    eta, x = problem.solve(w, options.gear_efficiency, kept)
    if options.weighted:
        res = motor_torque(A @ x, side, eta) - fit_data.tau
        sigma = np.sqrt((res**2).mean(axis=0))
        sigma = np.maximum(sigma, 1e-6 * max(float(sigma.max()), 1e-12))
        w = 1.0 / sigma
        eta, x = problem.solve(w, options.gear_efficiency, kept)
    Aw = (A * w[None, :, None]).reshape(-1, A.shape[2])
    more, cond, weak = _select_kept(Aw, kept, options, prior_known)
    if more != kept:
        kept = more
        eta, x = problem.solve(w, options.gear_efficiency, kept)
    weakest = names[weak]
    if not cond <= options.max_condition:
        also = (
            f" (even with {len(kept)} parameter(s) kept at their priors, at most "
            f"{int(MAX_KEPT_SHARE * 100)} % may be)"
            if options.unexcited == "prior"
            else ""
        )
        raise InvalidInput(
            f"the logs do not excite the dynamics enough to identify them: condition number {cond:.3g} of "
            f"the stacked regressor (limit {options.max_condition:.3g}){also}; least excited: {weakest}; "
            "log more varied moves (other speeds, ranges and joint combinations) and identify again"
        )
    kept_parameters = tuple(
        KeptParameter(
            name=names[i],
            prior=float(prior_x[i]),
            prior_source=prior_sources[i],
            reason="with it free, the stacked regressor's condition number is over "
            f"{options.max_condition:.3g}",
        )
        for i in kept
    )
    for k in kept_parameters:
        warnings.warn(k.warning(), UnexcitedParameterWarning, stacklevel=2)
    beta_ls, f_ls = x[: base.n], x[base.n :]
    phi = _lift(base, beta_ls, prior)
    floors[10 * n :] = np.maximum(floors[10 * n :], np.abs(phi[10 * n :]))
    f = f_ls
    if options.consistent:
        lower_f = np.concatenate(
            [np.full(n, -np.inf if t in ("offset", "viscous_offset") else 0.0) for t in terms]
        )
        phi, f = _consistent(
            Y,
            F,
            joint_side(fit_data.tau, side, eta),
            w,
            phi,
            f_ls,
            prior,
            lower_f,
            options.prior_weight,
            *_held_rows(base, kept, prior_x, floors),
            floors=floors,
            max_nfev=CONSISTENT_MAX_NFEV,
        )
    friction = _friction_of(f, terms, n, options)
    armature = phi[10 * n :] if options.armature else None
    eig = min_eigenvalues(phi[: 10 * n])

    def predict(d: IdentificationData) -> FloatArray:
        Yd = dynamic_regressor(robot, d.q, d.qd, d.qdd, armature=options.armature)
        return motor_torque(Yd @ phi + friction.torque(d.qd), gear_side_speed(d.qd, options.rest_speed), eta)

    return Identification(
        robot_name=robot.name,
        base=base,
        beta_ls=beta_ls,
        phi=phi[: 10 * n],
        friction=friction,
        gear_efficiency=eta,
        condition_number=cond,
        weakest=weakest,
        weights=w,
        fit=score_prediction(motor_torque(Y @ phi + friction.torque(fit_data.qd), side, eta), fit_data),
        held_out=None if held is None else score_prediction(predict(held), held),
        min_pseudo_inertia_eig=eig,
        consistent=bool(np.all(eig > -CONSISTENT_TOL)) and (armature is None or bool(np.all(armature >= 0))),
        options=options,
        data_hash=data.data_hash,
        sources=data.sources,
        kept=kept_parameters,
        armature=armature,
        motion=data.motion,
    )


__all__ = [
    "ETA_BOUNDS",
    "GEAR_REST_SPEED",
    "FitScores",
    "Identification",
    "IdentifyOptions",
    "KeptParameter",
    "MAX_CONDITION",
    "MAX_KEPT_SHARE",
    "REST_SPEED",
    "UNEXCITED",
    "UnexcitedParameterWarning",
    "gear_side_speed",
    "identify",
    "joint_side",
    "r2_per_joint",
    "score_prediction",
    "search_eta",
]
