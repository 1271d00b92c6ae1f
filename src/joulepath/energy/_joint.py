"""The thesis' joint power and energy (pure array functions).

The thesis' definition (§2.1) of the energy of joint ``i`` over one sample of
length ``dt`` is ``E_i = |tau_i * qd_i| * dt`` (J), and a move's energy is the sum
over its samples. Units: ``tau`` N·m, ``qd`` rad/s, ``dt`` s, power W, energy J
(see :mod:`joulepath.units`).

Modes of the mechanical power ``p = tau * qd``:

* ``"absolute"`` — ``|p|`` (the thesis: braking costs as much as driving);
* ``"signed"`` — ``p`` (full regeneration: braking returns energy);
* ``"positive"`` — ``max(p, 0)`` (no regeneration, braking is free).

``copper_loss=k`` (W/(N·m)², scalar or one per joint) adds the drives' resistive
losses ``k * tau**2``, which are spent whatever the sign of ``p``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import ArrayLike, FloatArray
from joulepath.errors import InvalidInput

MODES = ("absolute", "signed", "positive")


def _pair(tau: ArrayLike, qd: ArrayLike) -> tuple[FloatArray, FloatArray]:
    t = np.asarray(tau, dtype=float)
    v = np.asarray(qd, dtype=float)
    if t.shape != v.shape:
        raise InvalidInput(f"tau has shape {t.shape} but qd has shape {v.shape}; they must match")
    return t, v


def joint_power(
    tau: ArrayLike,
    qd: ArrayLike,
    *,
    mode: str = "absolute",
    copper_loss: float | ArrayLike | None = None,
) -> FloatArray:
    """Per-joint power in W, same shape as ``tau`` and ``qd``.

    Examples
    --------
    >>> joint_power([2.0, -3.0], [1.0, 1.0])
    array([2., 3.])
    >>> joint_power([2.0, -3.0], [1.0, 1.0], mode="signed")
    array([ 2., -3.])
    """
    t, v = _pair(tau, qd)
    p = t * v
    if mode == "absolute":
        p = np.abs(p)
    elif mode == "positive":
        p = np.maximum(p, 0.0)
    elif mode != "signed":
        raise InvalidInput(f"mode must be one of {MODES}, got {mode!r}")
    if copper_loss is not None:
        k = np.asarray(copper_loss, dtype=float)
        if np.any(k < 0):
            raise InvalidInput("copper_loss must be ≥ 0 W/(N·m)²")
        p = p + k * t * t
    return p


def _dt(dt: float | ArrayLike, shape: tuple[int, ...]) -> FloatArray:
    d = np.asarray(dt, dtype=float)
    if np.any(d < 0) or not np.all(np.isfinite(d)):
        raise InvalidInput("dt must be finite and ≥ 0 s")
    if d.ndim > 0:
        d = d[..., None]  # one dt per sample, broadcast over joints
        try:
            np.broadcast_shapes(d.shape, shape)
        except ValueError as err:
            raise InvalidInput(
                f"dt has shape {d.shape[:-1]}; expected a scalar or one value per sample {shape[:-1]}"
            ) from err
    return d


def joint_energy(
    tau: ArrayLike,
    qd: ArrayLike,
    dt: float | ArrayLike,
    *,
    mode: str = "absolute",
    copper_loss: float | ArrayLike | None = None,
) -> FloatArray:
    """Per-sample, per-joint energy ``E_i = |tau_i * qd_i| * dt`` in J.

    Parameters
    ----------
    tau, qd : array_like of shape (..., n)
        N·m and rad/s.
    dt : float or array_like of shape (...)
        Sample length in s: one value, or one per sample.
    mode, copper_loss
        See the module docstring.

    Returns
    -------
    ndarray of shape (..., n)

    Examples
    --------
    >>> joint_energy([[10.0, -4.0]], [[0.5, 2.0]], 0.025)
    array([[0.125, 0.2  ]])
    """
    t, v = _pair(tau, qd)
    return joint_power(t, v, mode=mode, copper_loss=copper_loss) * _dt(dt, t.shape)


def total_energy(
    tau: ArrayLike,
    qd: ArrayLike,
    dt: float | ArrayLike,
    *,
    mode: str = "absolute",
    copper_loss: float | ArrayLike | None = None,
) -> FloatArray:
    """Per-sample energy summed over joints (the thesis' target ``E``), shape (...)."""
    out: FloatArray = joint_energy(tau, qd, dt, mode=mode, copper_loss=copper_loss).sum(axis=-1)
    return out


@dataclass(frozen=True, slots=True)
class PathEnergy:
    """Energy of sampled paths.

    Attributes
    ----------
    per_joint : ndarray of shape (..., n)
        J, summed over the path's samples.
    total : ndarray of shape (...)
        J, summed over joints as well.
    """

    per_joint: FloatArray
    total: FloatArray


def path_energy(
    tau: ArrayLike,
    qd: ArrayLike,
    dt: float | ArrayLike,
    *,
    mode: str = "absolute",
    copper_loss: float | ArrayLike | None = None,
) -> PathEnergy:
    """Energy of paths sampled at ``dt``: ``tau``, ``qd`` of shape (..., n_steps, n).

    Examples
    --------
    >>> e = path_energy([[1.0], [1.0]], [[2.0], [2.0]], 0.5)
    >>> float(e.total)
    2.0
    """
    e = joint_energy(tau, qd, dt, mode=mode, copper_loss=copper_loss)
    if e.ndim < 2:
        raise InvalidInput(f"expected shape (..., n_steps, n), got {e.shape}")
    per_joint = e.sum(axis=-2)
    return PathEnergy(per_joint=per_joint, total=per_joint.sum(axis=-1))
