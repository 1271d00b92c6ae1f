"""Joint friction as composable per-joint terms.

A friction term maps joint velocities ``qd`` (``(..., n)``, rad/s) to the torque
the drives must add to overcome friction (``(..., n)``, N·m); it opposes motion,
so it has the sign of ``qd``. Terms add up with ``+``::

    friction = ElastoPlasticFriction() + CoulombViscousFriction(viscous=0.1)

Parameters are scalars (every joint) or sequences of one value per joint.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from joulepath._io import load_toml
from joulepath._typing import FloatArray
from joulepath.errors import InvalidInput

PerJoint = float | tuple[float, ...]


@runtime_checkable
class Friction(Protocol):
    """Anything with ``torque(qd) -> tau_friction`` of the same shape."""

    def torque(self, qd: FloatArray) -> FloatArray: ...


def friction_derivative(friction: Friction, qd: FloatArray) -> FloatArray:
    """``d tau_f / d qd`` per joint, same shape as ``qd`` (friction acts joint by joint).

    Uses the term's own ``derivative(qd)`` when it has one; otherwise a central
    difference of ``torque`` with a step of 1e-6 rad/s.
    """
    own = getattr(friction, "derivative", None)
    if callable(own):
        out: FloatArray = np.asarray(own(qd), dtype=float)
        return out
    h = 1e-6
    diff: FloatArray = (friction.torque(qd + h) - friction.torque(qd - h)) / (2 * h)
    return diff


class _Addable:
    def __add__(self, other: Friction) -> FrictionSum:
        if not isinstance(other, Friction):
            return NotImplemented
        left = self.terms if isinstance(self, FrictionSum) else (self,)
        right = other.terms if isinstance(other, FrictionSum) else (other,)
        return FrictionSum(terms=(*left, *right))


def _param(value: PerJoint, name: str) -> FloatArray:
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.ndim != 1 or not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise InvalidInput(f"friction parameter {name} must be ≥ 0 (one value or one per joint)")
    return arr


@dataclass(frozen=True, slots=True, kw_only=True)
class ElastoPlasticFriction(_Addable):
    """The thesis' elasto-plastic friction (§2.1, Appendix B), ``mu_k = 0.504, mu_s = 0.302``.

    ``form="listing"`` (default) is what the thesis' code computes::

        tau_f = mu_k * sgn(qd) * (1 - exp(-(|qd| - mu_s) / mu_k))

    ``form="text"`` is the printed equation::

        tau_f = mu_k * sgn(qd) * (1 - exp(-|qd| - mu_s) / mu_k)

    Both are zero at ``qd = 0``, jump at 0 and change sign at low speed (the
    listing form below ``|qd| = mu_s``); they are reproduced as published. Use
    :class:`CoulombViscousFriction` for a conventional model.
    """

    mu_k: PerJoint = 0.504
    mu_s: PerJoint = 0.302
    form: str = "listing"

    def __post_init__(self) -> None:
        if self.form not in ("listing", "text"):
            raise InvalidInput(f"form must be 'listing' or 'text', got {self.form!r}")
        if np.any(_param(self.mu_k, "mu_k") == 0):
            raise InvalidInput("mu_k must be positive")
        _param(self.mu_s, "mu_s")

    def torque(self, qd: FloatArray) -> FloatArray:
        mk = _param(self.mu_k, "mu_k")
        ms = _param(self.mu_s, "mu_s")
        v = np.abs(qd)
        if self.form == "listing":
            shape = 1.0 - np.exp(-(v - ms) / mk)
        else:
            shape = 1.0 - np.exp(-v - ms) / mk
        out: FloatArray = mk * np.sign(qd) * shape
        return out

    def derivative(self, qd: FloatArray) -> FloatArray:
        """``d tau_f / d qd`` away from ``qd = 0`` (the jump at 0 has no derivative)."""
        mk = _param(self.mu_k, "mu_k")
        ms = _param(self.mu_s, "mu_s")
        v = np.abs(qd)
        if self.form == "listing":
            out: FloatArray = np.exp(-(v - ms) / mk) * np.ones_like(qd)
        else:
            out = np.exp(-v - ms) * np.ones_like(qd)
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class CoulombViscousFriction(_Addable):
    """``tau_f = coulomb * sgn(qd) + viscous * qd`` (N·m and N·m·s/rad).

    With ``smoothing > 0`` (rad/s) the sign is replaced by ``tanh(qd / smoothing)``,
    which keeps the torque continuous through zero speed.
    """

    coulomb: PerJoint = 0.0
    viscous: PerJoint = 0.0
    smoothing: float = 0.0
    _fc: FloatArray = field(init=False, repr=False, compare=False)
    _fv: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # validated once; the optimizer calls torque() and derivative() thousands of times
        object.__setattr__(self, "_fc", _param(self.coulomb, "coulomb"))
        object.__setattr__(self, "_fv", _param(self.viscous, "viscous"))
        if not self.smoothing >= 0:
            raise InvalidInput("smoothing must be ≥ 0 rad/s")

    def torque(self, qd: FloatArray) -> FloatArray:
        fc, fv = self._fc, self._fv
        sgn = np.tanh(qd / self.smoothing) if self.smoothing > 0 else np.sign(qd)
        out: FloatArray = fc * sgn + fv * qd
        return out

    def derivative(self, qd: FloatArray) -> FloatArray:
        """``d tau_f / d qd``: ``coulomb / smoothing · sech²(qd / smoothing) + viscous`` (0 if unsmoothed)."""
        fc, fv = self._fc, self._fv
        if self.smoothing > 0:
            th = np.tanh(qd / self.smoothing)
            out: FloatArray = fc / self.smoothing * (1.0 - th * th) + fv
        else:
            out = fv * np.ones_like(qd)
        return out


@dataclass(frozen=True, slots=True)
class FrictionSum(_Addable):
    """The sum of several friction terms."""

    terms: tuple[Friction, ...]

    def torque(self, qd: FloatArray) -> FloatArray:
        total = np.zeros_like(qd, dtype=float)
        for term in self.terms:
            total = total + term.torque(qd)
        return total

    def derivative(self, qd: FloatArray) -> FloatArray:
        total = np.zeros_like(qd, dtype=float)
        for term in self.terms:
            total = total + friction_derivative(term, qd)
        return total


NOMINAL_FRICTION = CoulombViscousFriction(
    coulomb=(0.9, 1.1, 0.7, 0.25, 0.25, 0.15),
    viscous=(0.6, 0.7, 0.4, 0.08, 0.08, 0.04),
    smoothing=0.005,
)
"""Nominal joint friction assumed for the IRB 120 (N·m, N·m·s/rad, joint side).

No identified friction of the IRB 120 is public; these values are of the size
reported for robots of its class. The ``sim`` plant uses them, the ``lab`` plant
departs from them, and the physics baseline of the energy models uses them."""


FRICTION_SUFFIX = ".friction.toml"
"""A robot's friction file sits beside its description: ``ur5.urdf`` -> ``ur5.friction.toml``."""
_FRICTION_KEYS = {"coulomb", "viscous", "smoothing", "source"}
MAX_FRICTION_BYTES = 64 << 10


def read_friction_file(path: str | os.PathLike[str], n_joints: int) -> CoulombViscousFriction:
    """Read a friction file: Coulomb + viscous friction, one value per joint (TOML, data only).

    ::

        # ur5.friction.toml: identified on our UR5, joint side
        coulomb = [5.2, 5.0, 3.1, 1.2, 1.1, 1.1]   # N·m
        viscous = [3.0, 3.1, 1.9, 0.5, 0.5, 0.5]   # N·m·s/rad
        smoothing = 0.005                            # rad/s (optional, default 0.005)
        source = "identified 2026-05, payload 0"     # optional, shown in outputs

    Raises
    ------
    InvalidInput
        Unreadable file, unknown key, not one non-negative finite value per joint.
    """
    p = Path(path)
    data = load_toml(p, max_bytes=MAX_FRICTION_BYTES, what="a TOML friction file")
    unknown = sorted(set(data) - _FRICTION_KEYS)
    if unknown:
        raise InvalidInput(f"{p}: unknown key {unknown[0]!r}; a friction file holds {sorted(_FRICTION_KEYS)}")
    values = {}
    for key in ("coulomb", "viscous"):
        raw = data.get(key)
        ok = isinstance(raw, list) and len(raw) == n_joints
        ok = ok and all(isinstance(v, int | float) and not isinstance(v, bool) for v in raw or [])
        arr = np.asarray(raw if ok else [], dtype=float)
        if not ok or not np.all(np.isfinite(arr)) or np.any(arr < 0):
            raise InvalidInput(
                f"{p}: {key} must be a list of {n_joints} non-negative numbers (one per joint), got {raw!r}"
            )
        values[key] = tuple(float(v) for v in arr)
    smoothing = data.get("smoothing", 0.005)
    if isinstance(smoothing, bool) or not isinstance(smoothing, int | float) or not 0 <= smoothing < 1:
        raise InvalidInput(f"{p}: smoothing must be a number of rad/s in [0, 1), got {smoothing!r}")
    return CoulombViscousFriction(
        coulomb=values["coulomb"], viscous=values["viscous"], smoothing=float(smoothing)
    )
