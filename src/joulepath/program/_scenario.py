"""The scenario file: what a program learns while it runs, and what a partial task leaves out.

A TOML file (``joulepath cycle --scenario FILE``)::

    [io]                        # inputs and run-time data, NAME = VALUE (top-level keys too)
    diStart = 1
    nPartType = 2
    [tool.tGripper]             # a tool declared in a module not given (else tool0's frame and a
    frame = [0, 0, 120, 1, 0, 0, 0]   #   stated load): x, y, z (mm), q1..q4
    mass = 1.2                  # kg
    cog = [0, 0, 60]            # mm, in the tool's frame (default: its origin)
    [wobj.wTable]               # a work object (else wobj0)
    frame = [500, 0, 200, 1, 0, 0, 0]
    [targets]                   # targets the program does not give (declared nowhere, or filled at
    pPick = [400, 0, 300, 0, 0, 1, 0]  #   run time): x, y, z (mm), q1..q4 in their work object,
    jHome = { joints = [0, 0, 0, 0, 30, 0] }  # or a jointtarget's six joints (deg)
    [data]                      # any other datum declared nowhere, as a RAPID literal (never run)
    vFast = "[2000, 500, 5000, 1000]"

Values are in RAPID's units (mm, deg), as a program writes them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from joulepath._io import load_toml
from joulepath.errors import InvalidInput

MAX_SCENARIO_BYTES = 1 << 20
_NO_EXT = (9e9,) * 6
_POSE0 = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
_SECTIONS = ("io", "tool", "wobj", "targets", "data")


@dataclass(frozen=True, slots=True)
class Scenario:
    """``io``: values by name (numbers, strings, bools); ``given``: RAPID values (tuples, in the
    program's units) for tools, work objects and targets by name."""

    io: Mapping[str, float | str | bool] = field(default_factory=dict)
    given: Mapping[str, Any] = field(default_factory=dict)


def _bad(path: Path | str, what: str) -> InvalidInput:
    return InvalidInput(f"{path}: {what}")


def _numbers(path: Path | str, where: str, v: Any, n: int) -> tuple[float, ...]:
    if (
        not isinstance(v, list)
        or len(v) != n
        or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
        or not all(math.isfinite(float(x)) for x in v)
    ):
        raise _bad(path, f"{where}: give {n} numbers, e.g. [{', '.join(['0'] * n)}]")
    return tuple(float(x) for x in v)


def _pose(path: Path | str, where: str, v: Any) -> tuple[tuple[float, ...], tuple[float, ...]]:
    x = _numbers(path, where, v, 7)
    q = x[3:]
    norm = math.sqrt(sum(c * c for c in q))
    if abs(norm - 1.0) > 1e-3:
        raise _bad(path, f"{where}: its quaternion {list(q)} is not a unit quaternion; correct it")
    return x[:3], q


def _table(path: Path | str, data: Mapping[str, Any], key: str) -> Mapping[str, Any]:
    v = data.get(key, {})
    if not isinstance(v, dict):
        raise _bad(path, f"[{key}] must be a table")
    return v


def scenario_from_dict(data: Mapping[str, Any], path: Path | str = "scenario") -> Scenario:
    """A :class:`Scenario` from a TOML document's tables (see the module docstring)."""
    io: dict[str, float | str | bool] = {}
    io_table = data.get("io") if "io" in data else {k: v for k, v in data.items() if k not in _SECTIONS}
    if not isinstance(io_table, dict):
        raise _bad(path, "[io] must be a table of NAME = VALUE")
    for k, v in io_table.items():
        if not isinstance(v, (int, float, str, bool)):
            raise _bad(path, f"{k} = {str(v)[:40]}: give a number, a string or a bool")
        io[str(k)] = float(v) if isinstance(v, int) and not isinstance(v, bool) else v
    given: dict[str, Any] = {}
    for name, t in _table(path, data, "tool").items():
        if not isinstance(t, dict):
            raise _bad(path, f"[tool.{name}] must be a table (frame, mass, cog)")
        frame = _pose(path, f"[tool.{name}] frame", t.get("frame", [0, 0, 0, 1, 0, 0, 0]))
        mass = t.get("mass", 0.0)
        if not isinstance(mass, (int, float)) or isinstance(mass, bool) or not 0 <= mass < 1e4:
            raise _bad(path, f"[tool.{name}] mass = {str(mass)[:40]}: give kg, 0 or more")
        cog = _numbers(path, f"[tool.{name}] cog", t.get("cog", [0, 0, 0]), 3)
        if mass == 0 and any(cog):
            cog = (0.0, 0.0, 0.0)
        given[name] = (True, frame, (float(mass), cog, (1.0, 0.0, 0.0, 0.0), 0.0, 0.0, 0.0))
    for name, w in _table(path, data, "wobj").items():
        if not isinstance(w, dict):
            raise _bad(path, f"[wobj.{name}] must be a table (frame)")
        frame = _pose(path, f"[wobj.{name}] frame", w.get("frame", [0, 0, 0, 1, 0, 0, 0]))
        given[name] = (False, True, "", frame, _POSE0)
    for name, v in _table(path, data, "targets").items():
        if isinstance(v, dict) and "joints" in v:
            given[name] = (_numbers(path, f"[targets] {name} joints", v["joints"], 6), _NO_EXT)
        else:
            trans, rot = _pose(path, f"[targets] {name}", v)
            given[name] = (trans, rot, (0.0, 0.0, 0.0, 0.0), _NO_EXT)
    for name, v in _table(path, data, "data").items():
        if isinstance(v, bool) or not isinstance(v, (int, float, str)):
            raise _bad(
                path, f'[data] {name}: give a RAPID literal as a string, e.g. "[2000, 500, 5000, 1000]"'
            )
        if isinstance(v, str) and len(v) > 4096:
            raise _bad(path, f"[data] {name}: a literal of {len(v)} characters; give at most 4096")
        given[name] = float(v) if isinstance(v, (int, float)) else v
    return Scenario(io, given)


def read_scenario(path: str | Path) -> Scenario:
    """The scenario file at ``path`` (one line :class:`InvalidInput` where it is not one)."""
    data = load_toml(Path(path), max_bytes=MAX_SCENARIO_BYTES, what="a scenario file (TOML)")
    return scenario_from_dict(data, path)
