"""A calibrated twin: identified joint friction, drive losses, and the twin folder it lives in.

A twin folder (``joulepath identify ... --out twin/``) is a contract declared here
once, read by :func:`joulepath.load_robot` and written by :mod:`joulepath.identify`:

* :data:`TWIN_ROBOT_FILE` — an IRML robot description with the identified
  (physically consistent) link masses, centres of mass and inertias; for an arm read
  from a URDF (a named arm, a ``.urdf`` file) :data:`TWIN_URDF_FILE` instead: the arm as
  joulepath reads it (locked joints fixed, fixed links merged) written as a serial URDF
  with the identified inertials. A folder holds one of the two, never both;
* :data:`TWIN_FRICTION_FILE` — JSON: the identified :class:`IdentifiedFriction`,
  the drives' gear efficiency and (when identified) their armature, the reflected rotor
  inertia per joint (kg·m², :attr:`joulepath.description.Chain.armature`; neither URDF nor
  IRML has a place for it, so it is written with the other drive terms);
* :data:`TWIN_CARD_FILE` — JSON: what the twin was identified from and how well it fits.

Loading a twin never executes code: the friction file is plain JSON checked field by field.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._io import load_json
from joulepath._typing import FloatArray
from joulepath.energy import motor_side_torque
from joulepath.errors import InvalidRobotDescription

TWIN_ROBOT_FILE = "robot.irml"
TWIN_URDF_FILE = "robot.urdf"
TWIN_FRICTION_FILE = "friction.json"
TWIN_CARD_FILE = "card.json"
TWIN_FILES = (TWIN_ROBOT_FILE, TWIN_URDF_FILE, TWIN_FRICTION_FILE, TWIN_CARD_FILE)
FRICTION_FORMAT = "joulepath-friction/1"


@dataclass(frozen=True, slots=True, kw_only=True)
class IdentifiedFriction:
    """Per-joint friction as identified (joint side, N·m), linear in its parameters::

        tau_f = coulomb * s + viscous * qd + offset * |s| + stribeck * exp(-(qd / stribeck_speed)²) * s
                + viscous_offset * qd * s

    with ``s = tanh(qd / smoothing)``. ``offset`` is a torque that adds in both
    directions of motion (a direction asymmetry of the Coulomb level) and vanishes at
    rest; ``stribeck`` is the extra break-away torque at low speed (0 when not identified);
    ``viscous_offset`` the same asymmetry of the viscous level (``qd * s`` is ``|qd|``,
    smoothed at rest): the viscous slope is ``viscous + viscous_offset`` turning one way
    and ``viscous - viscous_offset`` the other (empty: 0, a friction without it).
    """

    coulomb: tuple[float, ...]
    viscous: tuple[float, ...]
    offset: tuple[float, ...]
    stribeck: tuple[float, ...]
    stribeck_speed: float = 0.05
    smoothing: float = 0.005
    viscous_offset: tuple[float, ...] = ()
    _p: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        vo = self.viscous_offset if len(self.viscous_offset) else (0.0,) * len(self.coulomb)
        arr = np.array([self.coulomb, self.viscous, self.offset, self.stribeck, vo], dtype=float)
        if arr.ndim != 2 or not np.all(np.isfinite(arr)):
            raise InvalidRobotDescription(
                "friction: coulomb, viscous, offset, stribeck and viscous_offset must be finite, one value "
                "per joint each"
            )
        if not (self.stribeck_speed > 0 and self.smoothing > 0):
            raise InvalidRobotDescription("friction: stribeck_speed and smoothing must be positive (rad/s)")
        object.__setattr__(self, "_p", arr)

    @property
    def n_joints(self) -> int:
        return int(self._p.shape[1])

    def torque(self, qd: FloatArray) -> FloatArray:
        fc, fv, fo, fs, fvo = self._p
        s = np.tanh(qd / self.smoothing)
        bump = np.exp(-((qd / self.stribeck_speed) ** 2))
        out: FloatArray = (fc + fs * bump) * s + fv * qd + fo * np.abs(s) + fvo * qd * s
        return out

    def derivative(self, qd: FloatArray) -> FloatArray:
        """``d tau_f / d qd`` per joint (analytic)."""
        fc, fv, fo, fs, fvo = self._p
        s = np.tanh(qd / self.smoothing)
        ds = (1.0 - s * s) / self.smoothing
        bump = np.exp(-((qd / self.stribeck_speed) ** 2))
        dbump = -2.0 * qd / self.stribeck_speed**2 * bump
        out: FloatArray = (
            (fc + fs * bump) * ds + fs * dbump * s + fv + fo * np.sign(s) * ds + fvo * (s + qd * ds)
        )
        return out

    def to_json(self) -> dict[str, Any]:
        return {
            "coulomb": list(self.coulomb),
            "viscous": list(self.viscous),
            "offset": list(self.offset),
            "stribeck": list(self.stribeck),
            "stribeck_speed": self.stribeck_speed,
            "smoothing": self.smoothing,
            **({"viscous_offset": list(self.viscous_offset)} if len(self.viscous_offset) else {}),
        }


def motor_torque(tau: FloatArray, qd: FloatArray, gear_efficiency: float) -> FloatArray:
    """Motor-side torque of a joint torque through gears of efficiency ``eta``.

    ``tau / eta`` while the motor drives (``tau * qd > 0``), ``tau * eta`` otherwise
    (braking or at rest): the lab plant's drive-loss model.
    """
    if gear_efficiency == 1.0:
        return tau
    return motor_side_torque(tau, qd, gear_efficiency)


@dataclass(frozen=True, slots=True, kw_only=True)
class Calibration:
    """What a twin adds to its robot description: friction, drive losses, origin."""

    friction: IdentifiedFriction
    gear_efficiency: float = 1.0
    twin_of: str | None = None
    folder: str | None = None
    armature: tuple[float, ...] = ()
    """kg·m² per joint (:attr:`joulepath.description.Chain.armature`); empty: none identified."""

    def motor_torque(self, tau: FloatArray, qd: FloatArray) -> FloatArray:
        """Joint torque ``tau`` as the drives measure it (see :func:`motor_torque`)."""
        return motor_torque(tau, qd, self.gear_efficiency)

    def to_json(self) -> dict[str, Any]:
        return {
            "format": FRICTION_FORMAT,
            "twin_of": self.twin_of,
            "gear_efficiency": self.gear_efficiency,
            "friction": self.friction.to_json(),
            **({"armature": list(self.armature)} if len(self.armature) else {}),
        }


MAX_FRICTION_JSON_BYTES = 1 << 20
"""Largest ``friction.json`` read (the file is a few hundred bytes)."""


def _is_number(value: Any) -> bool:
    """A JSON number (never ``true``/``false``) that is a finite float of sane size."""
    return isinstance(value, int | float) and not isinstance(value, bool) and abs(value) <= 1e12


def _floats(value: Any, where: str, n: int) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != n or not all(_is_number(v) for v in value):
        raise InvalidRobotDescription(
            f"{where}: expected a list of {n} finite numbers of magnitude at most 1e12 "
            "(one per joint, not true/false)"
        )
    return tuple(float(v) for v in value)


def read_calibration(path: str | os.PathLike[str], n_joints: int) -> Calibration:
    """Read and check a twin's friction file (plain JSON; nothing is executed)."""
    p = Path(path)
    data = load_json(
        p, max_bytes=MAX_FRICTION_JSON_BYTES, what="a JSON friction file", error=InvalidRobotDescription
    )
    if not isinstance(data, dict) or data.get("format") != FRICTION_FORMAT:
        raise InvalidRobotDescription(
            f'{p}: not a joulepath friction file (expected "format": "{FRICTION_FORMAT}"); '
            "write the twin again with `joulepath identify`"
        )
    fr = data.get("friction")
    if not isinstance(fr, dict):
        raise InvalidRobotDescription(f'{p}: no "friction" object')
    eta = data.get("gear_efficiency", 1.0)
    if not _is_number(eta) or not 0.0 < float(eta) <= 1.0:
        raise InvalidRobotDescription(f"{p}: gear_efficiency must be a number in (0, 1], got {eta!r}")
    twin_of = data.get("twin_of")
    if twin_of is not None and not isinstance(twin_of, str):
        raise InvalidRobotDescription(f"{p}: twin_of must be a robot name or null")
    speeds = {k: fr.get(k) for k in ("stribeck_speed", "smoothing")}
    for k, v in speeds.items():
        if not _is_number(v):
            raise InvalidRobotDescription(f"{p}: friction.{k} must be a finite number (rad/s)")
    friction = IdentifiedFriction(
        coulomb=_floats(fr.get("coulomb"), f"{p}: friction.coulomb", n_joints),
        viscous=_floats(fr.get("viscous"), f"{p}: friction.viscous", n_joints),
        offset=_floats(fr.get("offset"), f"{p}: friction.offset", n_joints),
        stribeck=_floats(fr.get("stribeck"), f"{p}: friction.stribeck", n_joints),
        stribeck_speed=float(speeds["stribeck_speed"]),  # type: ignore[arg-type]
        smoothing=float(speeds["smoothing"]),  # type: ignore[arg-type]
        viscous_offset=(
            _floats(fr["viscous_offset"], f"{p}: friction.viscous_offset", n_joints)
            if "viscous_offset" in fr
            else ()
        ),
    )
    armature: tuple[float, ...] = ()
    if "armature" in data:
        armature = _floats(data["armature"], f"{p}: armature", n_joints)
        bad = [j + 1 for j, a in enumerate(armature) if a < 0]
        if bad:
            raise InvalidRobotDescription(
                f"{p}: armature of joint {bad[0]} is {armature[bad[0] - 1]:g} kg·m²; a rotating inertia "
                "cannot be negative: identify the twin again"
            )
    return Calibration(
        friction=friction,
        gear_efficiency=float(eta),
        twin_of=twin_of,
        folder=str(p.parent),
        armature=armature,
    )


def twin_paths(folder: str | os.PathLike[str]) -> tuple[Path, Path]:
    """The robot file (IRML or URDF) and friction file of a twin folder.

    Raises
    ------
    InvalidRobotDescription
        A file is missing, or the folder holds both an IRML and a URDF robot.
    """
    f = Path(folder)
    irml, urdf, friction = f / TWIN_ROBOT_FILE, f / TWIN_URDF_FILE, f / TWIN_FRICTION_FILE
    if irml.is_file() and urdf.is_file():
        raise InvalidRobotDescription(
            f"{f}: holds both {TWIN_ROBOT_FILE} and {TWIN_URDF_FILE}; a twin has one robot file: "
            "remove the one `joulepath identify` did not write"
        )
    robot = urdf if urdf.is_file() else irml
    missing = [p.name for p in (robot, friction) if not p.is_file()]
    if missing:
        if robot is irml and TWIN_ROBOT_FILE in missing:
            missing[0] = f"{TWIN_ROBOT_FILE} (or {TWIN_URDF_FILE})"
        raise InvalidRobotDescription(
            f"{f}: a folder, but not a twin: {', '.join(missing)} missing "
            "(a twin folder is what `joulepath identify LOG... --out FOLDER` writes)"
        )
    return robot, friction


__all__ = [
    "Calibration",
    "FRICTION_FORMAT",
    "IdentifiedFriction",
    "TWIN_CARD_FILE",
    "TWIN_FILES",
    "TWIN_FRICTION_FILE",
    "TWIN_ROBOT_FILE",
    "TWIN_URDF_FILE",
    "motor_torque",
    "read_calibration",
    "twin_paths",
]
