"""Exciting trajectories for identification: Fourier series optimised for the condition number.

Each joint follows a finite Fourier series of base frequency ``f`` (Swevers et al.)::

    q_j(t) = q_mid_j + Σ_l [ a_jl / (w l) sin(w l t) - b_jl / (w l) cos(w l t) ],   w = 2 pi f

periodic with period ``1/f``. With ``Σ_l a_jl = 0`` and ``Σ_l l b_jl = 0`` it starts and ends
each period at rest (zero speed and acceleration), so a controller can start it from a
standstill and repeat it. Limits hold by construction, through bounds that no sample can
exceed: ``|q - q_mid| <= Σ r_l / (w l)``, ``|qd| <= Σ r_l``, ``|qdd| <= Σ w l r_l`` with
``r_l = sqrt(a_l² + b_l²)``; each joint's coefficients are scaled so that the tightest of
these bounds meets ``margin`` times its limit (range of the range set, speed limit, and the
acceleration limit ``v_max / accel_time`` the emulated controller assumes).

:func:`design_excitation` searches the coefficients (L-BFGS-B, numerical gradient, from a
seeded random start) for the smallest condition number of the column-normalised stacked
regressor ``[Y_b | F]`` over one period: the quantity :func:`~joulepath.identify.identify`
reports and refuses on.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput
from joulepath.identify._regressor import base_parameters, friction_regressor, inertial_regressor
from joulepath.trajectory import Trajectory


@dataclass(frozen=True, slots=True, eq=False)
class FourierExcitation:
    """A periodic Fourier-series joint trajectory (see the module docstring).

    Attributes
    ----------
    q_mid : ndarray of shape (n,)
        rad, the centre of each joint's motion.
    a, b : ndarray of shape (n, L)
        rad/s, the sine and cosine coefficients of the speed.
    base_hz : float
    periods : int
        Periods run one after the other; ``end_time = periods / base_hz``.
    """

    q_mid: FloatArray
    a: FloatArray
    b: FloatArray
    base_hz: float
    periods: int = 1

    @property
    def end_time(self) -> float:
        return self.periods / self.base_hz

    def evaluate(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``q, qd, qdd`` at times ``t`` (shape ``(len(t), n)``); before 0 and after the end: at rest."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.end_time)
        w = 2 * np.pi * self.base_hz
        L = self.a.shape[1]
        wl = w * np.arange(1, L + 1)
        ph = tt[:, None] * wl[None, :]  # (N, L)
        s, c = np.sin(ph), np.cos(ph)
        q = self.q_mid + s @ (self.a / wl).T - c @ (self.b / wl).T
        qd = c @ self.a.T + s @ self.b.T
        qdd = -s @ (self.a * wl).T + c @ (self.b * wl).T
        return q, qd, qdd

    def sample(self, dt: float) -> Trajectory:
        """The trajectory on a uniform grid of step ``dt`` (s), end included."""
        n = int(round(self.end_time / dt))
        t = np.linspace(0.0, n * dt, n + 1)
        q, qd, qdd = self.evaluate(t)
        return Trajectory(t=t, q=q, qd=qd, qdd=qdd)

    def bounds(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Per joint: bounds on ``|q - q_mid|``, ``|qd|`` and ``|qdd|`` that no sample exceeds."""
        w = 2 * np.pi * self.base_hz
        wl = w * np.arange(1, self.a.shape[1] + 1)
        r = np.hypot(self.a, self.b)
        return (r / wl).sum(axis=1), r.sum(axis=1), (r * wl).sum(axis=1)


@dataclass(frozen=True, slots=True, eq=False)
class ExcitationDesign:
    """An optimised exciting trajectory and how well it excites (condition numbers, one period)."""

    trajectory: FourierExcitation
    condition_number: float
    condition_number_start: float
    iterations: int


def _limits(robot: Robot, range_set: str, accel_time: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    lo, hi = robot.joint_ranges(range_set)
    vmax = robot.velocity_limit
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(np.isfinite(vmax))):
        raise InvalidInput(
            f"robot {robot.name!r} lacks a joint range or speed limit in range set {range_set!r}; "
            "an exciting trajectory needs both for every joint"
        )
    return 0.5 * (lo + hi), 0.5 * (hi - lo), vmax / accel_time


def _shape(
    x: FloatArray, n: int, L: int, w: float, caps: tuple[FloatArray, FloatArray, FloatArray]
) -> tuple[FloatArray, FloatArray]:
    """Raw coefficients -> at rest at t = 0 and scaled to the limits (see the module docstring)."""
    a = x[: n * L].reshape(n, L).copy()
    b = x[n * L :].reshape(n, L).copy()
    a -= a.mean(axis=1, keepdims=True)
    ell = np.arange(1, L + 1, dtype=float)
    b -= np.outer((b @ ell) / (ell @ ell), ell)
    wl = w * ell
    r = np.hypot(a, b)
    need = np.stack([(r / wl).sum(axis=1) / caps[0], r.sum(axis=1) / caps[1], (r * wl).sum(axis=1) / caps[2]])
    worst = need.max(axis=0)
    scale = np.where(worst > 0, 1.0 / np.where(worst > 0, worst, 1.0), 0.0)
    return a * scale[:, None], b * scale[:, None]


def _condition(robot: Robot, traj: FourierExcitation, t: FloatArray, independent: np.ndarray) -> float:
    q, qd, qdd = traj.evaluate(t)
    Y = inertial_regressor(robot, q, qd, qdd)[:, :, independent]
    F, _ = friction_regressor(qd, smoothing=0.005, offset=True, stribeck_speed=None)
    A = np.concatenate([Y, F], axis=2).reshape(-1, Y.shape[2] + F.shape[2])
    norms = np.linalg.norm(A, axis=0)
    if np.any(norms == 0):
        return float("inf")
    s = np.linalg.svd(A / norms, compute_uv=False)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")


def design_excitation(
    robot: Robot,
    *,
    harmonics: int = 5,
    base_hz: float = 0.1,
    periods: int = 1,
    range_set: str = "collection",
    accel_time: float = 0.25,
    margin: float = 0.9,
    samples: int = 120,
    iterations: int = 15,
    seed: int | np.random.SeedSequence = 0,
) -> ExcitationDesign:
    """An exciting Fourier trajectory for ``robot`` within its limits (see the module docstring).

    Parameters
    ----------
    harmonics : int
        Harmonics per joint (``L``).
    base_hz : float
        Base frequency; one period lasts ``1 / base_hz`` s.
    periods : int
        Periods of the returned trajectory.
    range_set, accel_time, margin
        Limits: the joint ranges of ``range_set``, the speed limits and ``v_max /
        accel_time``, each times ``margin``.
    samples, iterations, seed
        Samples of one period in the condition number; L-BFGS-B iterations; random start.
    """
    if harmonics < 1 or not base_hz > 0 or periods < 1 or not 0 < margin <= 1 or accel_time <= 0:
        raise InvalidInput(
            "harmonics and periods must be ≥ 1, base_hz and accel_time positive, margin in (0, 1]"
        )
    n = robot.n_joints
    mid, half, amax = _limits(robot, range_set, accel_time)
    caps = (margin * half, margin * robot.velocity_limit, margin * amax)
    w = 2 * np.pi * base_hz
    t = np.linspace(0.0, 1.0 / base_hz, samples, endpoint=False)
    independent = base_parameters(robot).independent
    rng = np.random.default_rng(seed)
    x0 = rng.standard_normal(2 * n * harmonics)

    def build(x: FloatArray, k: int = 1) -> FourierExcitation:
        a, b = _shape(x, n, harmonics, w, caps)
        return FourierExcitation(q_mid=mid, a=a, b=b, base_hz=base_hz, periods=k)

    def objective(x: FloatArray) -> float:
        return float(np.log(_condition(robot, build(x), t, independent)))

    start = objective(x0)
    res = minimize(objective, x0, method="L-BFGS-B", options={"maxiter": iterations})
    best = res.x if res.fun < start else x0
    return ExcitationDesign(
        trajectory=build(best, periods),
        condition_number=float(np.exp(min(res.fun, start))),
        condition_number_start=float(np.exp(start)),
        iterations=int(res.nit),
    )


@dataclass(frozen=True, slots=True)
class _Delayed:
    """A trajectory started ``delay`` s late (the controller's idle time before and after)."""

    trajectory: FourierExcitation
    delay: float

    def evaluate(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return self.trajectory.evaluate(np.asarray(t, dtype=float) - self.delay)


def simulate_excitation(
    out: str | os.PathLike[str],
    design: ExcitationDesign,
    robot: Robot,
    *,
    plant: str = "lab",
    seed: int | np.random.SeedSequence = 0,
) -> tuple[int, float]:
    """Run an exciting trajectory on a plant and write the controller log; returns (rows, seconds).

    The log holds the controller's idle time at rest before and after the motion, like
    :func:`joulepath.sim.simulate`'s.
    """
    from joulepath._io import make_folder
    from joulepath.data import write_controller_log
    from joulepath.sim import ControllerConfig, log_text, log_times, make_plant, run_plant

    rng = np.random.default_rng(seed)
    config = ControllerConfig()
    delayed = _Delayed(design.trajectory, config.idle)
    t = log_times(design.trajectory.end_time + 2 * config.idle, config, rng=rng)
    measured = run_plant(make_plant(plant, robot), delayed, t, rng=rng)
    make_folder(os.path.dirname(os.fspath(out)) or ".")
    write_controller_log(out, log_text(robot, measured))
    return int(t.size), float(t[-1])


__all__ = ["ExcitationDesign", "FourierExcitation", "design_excitation", "simulate_excitation"]
