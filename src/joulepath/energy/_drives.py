"""Drive data of a robot: what turns joint torque into current and bus power (a data file, never code).

A robot's drive data sit in ``<stem>.drives.toml`` beside its description
(``ur5.urdf`` -> ``ur5.drives.toml``), or in a twin's folder as ``drives.toml``,
like its friction. Every value carries its source, or ``"assumed"``::

    # ur5.drives.toml: joint side (torques and speeds at the joint, after the gears)
    torque_constant = [13.0, 13.0, 13.0, 9.0, 9.0, 9.0]  # N·m/A: joint torque per ampere of motor current
    resistance = [0.4, 0.4, 0.4, 1.2, 1.2, 1.2]          # Ω: winding resistance the current heats
    drive_efficiency = 0.95                              # one number (every joint) or one per joint
    gear_efficiency = 0.85                               # optional; a twin's identified value wins
    bus = "bleeder"                # "bleeder" (shared DC link, braking surplus burnt),
                                   # "regenerative" (surplus returned) or "per-axis" (nothing shared)
    regen_efficiency = 0.9         # share returned, with bus = "regenerative"
    standby_W = 90.0               # W drawn whatever the arm does
    bus_voltage_V = 48.0           # optional, informative
    brakes_W = 34.0                # optional: W drawn at rest with the brakes engaged (power-saving mode)
    brakes_entry_s = 0.5           # s a pause loses to entering and leaving that mode
    bus_off_W = 24.0               # optional: W drawn with the drives' bus power off
    bus_off_entry_s = 5.0          # s a pause loses to switching the bus off and on

    [sources]                      # where each value comes from; a missing one is "assumed"
    standby_W = "UR5 technical specifications: power consumption min 90 W"
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from joulepath.errors import InvalidInput

DRIVES_SUFFIX = ".drives.toml"
"""A robot's drive data sit beside its description: ``ur5.urdf`` -> ``ur5.drives.toml``."""
TWIN_DRIVES_FILE = "drives.toml"
"""A twin folder's drive data (optional)."""
MAX_DRIVES_BYTES = 64 << 10
BUS_KINDS = ("bleeder", "regenerative", "per-axis")
"""How the axes' drives share their DC bus (see :mod:`joulepath.energy`)."""
ASSUMED = "assumed"

_PER_JOINT = ("torque_constant", "resistance", "drive_efficiency", "gear_efficiency")
_MODE_KEYS = ("brakes_W", "brakes_entry_s", "bus_off_W", "bus_off_entry_s")
_SCALARS = ("regen_efficiency", "standby_W", "bus_voltage_V", *_MODE_KEYS)
IDLE_MODES = ("brakes", "bus_off")
"""Power-saving modes a drives file may give for the robot at rest (``<mode>_W``, ``<mode>_entry_s``)."""
_VALUE_KEYS = (*_PER_JOINT, "bus", *_SCALARS)
_KEYS = {*_VALUE_KEYS, "sources", "note"}


@dataclass(frozen=True, slots=True, kw_only=True)
class DriveModel:
    """One robot's drives, per joint (joint side) and for the cabinet.

    Attributes
    ----------
    torque_constant : tuple of float
        ``k`` per joint, N·m/A: joint torque per ampere of motor current (the motor's
        torque constant times the gear ratio), so that ``i = tau_motor / k``.
    resistance : tuple of float
        Ω per joint: the winding resistance the torque-producing current heats (``R·i²``).
    drive_efficiency : tuple of float
        In (0, 1] per joint: the drive's (inverter's) efficiency, in both directions.
    gear_efficiency : tuple of float or None
        In (0, 1] per joint, or None (unknown; a twin identifies its own).
    bus : {"bleeder", "regenerative", "per-axis"}
        The DC bus (:data:`BUS_KINDS`).
    regen_efficiency : float
        In [0, 1]: the share of a negative bus power returned (``bus = "regenerative"``).
    standby_W : float
        W the cabinet draws whatever the arm does (controller, fans, drives idle).
    bus_voltage_V : float or None
        Informative only.
    brakes_W, bus_off_W : float or None
        W the cabinet draws at rest in a power-saving mode: the brakes engaged (the drives
        hold no torque), or the drives' bus power off; at most ``standby_W``. None: not known.
    brakes_entry_s, bus_off_entry_s : float or None
        s of a pause lost to entering and leaving each mode (drawn at the ``standby_W``
        rate); a pause shorter than that gains nothing from the mode.
    sources : dict of str to str
        Where each value comes from; a value without an entry is ``"assumed"``, and so is
        one whose source starts with "assumed" (an estimate states its basis after it).
    origin : str
        The file read, or where the model came from.
    """

    torque_constant: tuple[float, ...]
    resistance: tuple[float, ...]
    drive_efficiency: tuple[float, ...]
    gear_efficiency: tuple[float, ...] | None = None
    bus: str = "bleeder"
    regen_efficiency: float = 0.0
    standby_W: float = 0.0
    bus_voltage_V: float | None = None
    brakes_W: float | None = None
    brakes_entry_s: float | None = None
    bus_off_W: float | None = None
    bus_off_entry_s: float | None = None
    sources: dict[str, str] = field(default_factory=dict)
    origin: str = "given"

    def __post_init__(self) -> None:
        n = len(self.torque_constant)
        where = self.origin
        for key in _PER_JOINT:
            value = getattr(self, key)
            if value is None:
                continue
            if len(value) != n or n == 0:
                raise InvalidInput(
                    f"{where}: {key} has {len(value)} values, torque_constant {n}; give one per joint"
                )
            if not all(math.isfinite(v) for v in value):
                raise InvalidInput(f"{where}: {key} must be finite numbers, got {list(value)}")
        if any(v <= 0 for v in self.torque_constant):
            raise InvalidInput(
                f"{where}: torque_constant must be > 0 N·m/A, got {list(self.torque_constant)}"
            )
        if any(v < 0 for v in self.resistance):
            raise InvalidInput(f"{where}: resistance must be ≥ 0 Ω, got {list(self.resistance)}")
        for key in ("drive_efficiency", "gear_efficiency"):
            value = getattr(self, key)
            if value is not None and any(not 0 < v <= 1 for v in value):
                raise InvalidInput(f"{where}: {key} must be in (0, 1], got {list(value)}")
        if self.bus not in BUS_KINDS:
            raise InvalidInput(f"{where}: bus must be one of {', '.join(BUS_KINDS)}, got {self.bus!r}")
        if not (math.isfinite(self.regen_efficiency) and 0 <= self.regen_efficiency <= 1):
            raise InvalidInput(f"{where}: regen_efficiency must be in [0, 1], got {self.regen_efficiency}")
        if not (math.isfinite(self.standby_W) and self.standby_W >= 0):
            raise InvalidInput(f"{where}: standby_W must be ≥ 0 W, got {self.standby_W}")
        for mode in IDLE_MODES:
            power, entry = getattr(self, f"{mode}_W"), getattr(self, f"{mode}_entry_s")
            if (power is None) != (entry is None):
                raise InvalidInput(f"{where}: give both {mode}_W and {mode}_entry_s, or neither")
            if power is not None and not (math.isfinite(power) and 0 <= power <= self.standby_W):
                raise InvalidInput(
                    f"{where}: {mode}_W must be in [0, standby_W = {self.standby_W}] W, got {power}"
                )
            if entry is not None and not (math.isfinite(entry) and entry >= 0):
                raise InvalidInput(f"{where}: {mode}_entry_s must be ≥ 0 s, got {entry}")
        unknown = sorted(set(self.sources) - set(_VALUE_KEYS))
        if unknown:
            raise InvalidInput(
                f"{where}: sources.{unknown[0]} names no value; sources name {list(_VALUE_KEYS)}"
            )

    @property
    def n_joints(self) -> int:
        return len(self.torque_constant)

    def source(self, key: str) -> str:
        """Where value ``key`` comes from (``"assumed"`` when the data do not say)."""
        return self.sources.get(key, ASSUMED)

    def describe(self) -> str:
        """One line: the file, and which values are sourced or assumed (shown with electrical figures)."""
        used = [
            k
            for k in _VALUE_KEYS
            if k != "bus_voltage_V" and k not in _MODE_KEYS and getattr(self, k) is not None
        ]
        if self.bus != "regenerative":
            used.remove("regen_efficiency")
        assumed = [k for k in used if self.source(k).lower().startswith(ASSUMED)]
        sourced = [k for k in used if k not in assumed]
        if not assumed:
            return f"{self.origin} (every value sourced)"
        if not sourced:
            return f"{self.origin} (every value assumed)"
        return f"{self.origin} (sourced: {', '.join(sourced)}; assumed: {', '.join(assumed)})"

    def to_json(self) -> dict[str, Any]:
        """Plain JSON types (the file's keys)."""
        out: dict[str, Any] = {k: getattr(self, k) for k in _VALUE_KEYS}
        for k in _PER_JOINT:
            if out[k] is not None:
                out[k] = list(out[k])
        out["sources"] = {k: self.source(k) for k in _VALUE_KEYS if getattr(self, k) is not None}
        out["origin"] = self.origin
        return out


def _number(raw: Any, where: str) -> float:
    if isinstance(raw, bool) or not isinstance(raw, int | float) or not math.isfinite(raw):
        raise InvalidInput(f"{where} must be a finite number, got {raw!r}")
    return float(raw)


def _per_joint(raw: Any, where: str, n: int) -> tuple[float, ...]:
    if isinstance(raw, list):
        if len(raw) != n:
            raise InvalidInput(f"{where} has {len(raw)} values; give one number or {n} (one per joint)")
        return tuple(_number(v, where) for v in raw)
    return (_number(raw, where),) * n


def read_drives_toml(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The TOML table of a drives file, unchecked beyond being one (a regular file of at most 64 KiB).

    Raises
    ------
    InvalidInput
        Not a regular readable file, larger than 64 KiB, or not TOML; one line naming the file.
    """
    p = Path(path)
    try:
        if not p.is_file():
            raise InvalidInput(f"{p}: not a regular file; a drives file is a TOML file")
        if p.stat().st_size > MAX_DRIVES_BYTES:
            raise InvalidInput(f"{p}: is larger than {MAX_DRIVES_BYTES >> 10} KiB; is it a drives file?")
        return tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as err:
        raise InvalidInput(f"{p}: cannot be read ({err.strerror})") from err
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise InvalidInput(f"{p}: not a TOML drives file ({err})") from err


def read_drives_file(path: str | os.PathLike[str], n_joints: int) -> DriveModel:
    """Read a drives file (TOML, data only; see the module docstring for the format).

    Raises
    ------
    InvalidInput
        Not a regular readable file, larger than 64 KiB, not TOML, an unknown key,
        a value that is not a finite number (booleans are not numbers), the wrong
        number of per-joint values, or a value out of its range. One line, naming
        the file and the key.
    """
    p = Path(path)
    data = read_drives_toml(p)
    unknown = sorted(set(data) - _KEYS)
    if unknown:
        raise InvalidInput(f"{p}: unknown key {unknown[0]!r}; a drives file holds {sorted(_KEYS)}")
    missing = [k for k in ("torque_constant", "resistance", "drive_efficiency", "bus") if k not in data]
    if missing:
        raise InvalidInput(f"{p}: {missing[0]} is missing; a drives file gives {', '.join(missing)}")
    values: dict[str, Any] = {}
    for key in _PER_JOINT:
        if key in data:
            values[key] = _per_joint(data[key], f"{p}: {key}", n_joints)
    if not isinstance(data["bus"], str):
        raise InvalidInput(f"{p}: bus must be one of {', '.join(BUS_KINDS)} (a string), got {data['bus']!r}")
    values["bus"] = data["bus"]
    for key in _SCALARS:
        if key in data:
            values[key] = _number(data[key], f"{p}: {key}")
    if values["bus"] == "regenerative" and "regen_efficiency" not in values:
        raise InvalidInput(f'{p}: bus = "regenerative" needs regen_efficiency (the share returned, 0..1)')
    sources = data.get("sources", {})
    if not isinstance(sources, dict) or not all(isinstance(v, str) for v in sources.values()):
        raise InvalidInput(f"{p}: [sources] must map value names to text (where each value comes from)")
    return DriveModel(**values, sources=dict(sources), origin=str(p))


def _toml_value(value: Any) -> str:
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, tuple | list):
        return "[" + ", ".join(repr(float(v)) for v in value) + "]"
    return repr(float(value))


def drives_toml(model: DriveModel, *, comment: str = "") -> str:
    """A drives file's text for ``model`` (what :func:`read_drives_file` reads back)."""
    lines = [f"# {line}" for line in comment.splitlines()] if comment else []
    for key in _VALUE_KEYS:
        value = getattr(model, key)
        if value is None or (key == "regen_efficiency" and model.bus != "regenerative"):
            continue
        lines.append(f"{key} = {_toml_value(value)}")
    lines.append("")
    lines.append("[sources]")
    for key in _VALUE_KEYS:
        if key in model.sources:
            lines.append(f"{key} = {_toml_value(model.sources[key])}")
    return "\n".join(lines) + "\n"
