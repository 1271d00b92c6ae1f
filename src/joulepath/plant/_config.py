"""The plant file (TOML): the plant's figures, default settings and one table per cell program.

::

    [plant]
    name = "Body shop line 3"
    hours_per_year = 6000          # production hours a year (0 < h <= 8784)
    tariff_eur_per_kwh = 0.20      # >= 0
    co2_kg_per_kwh = 0.35          # >= 0
    [defaults]                     # any setting of CELL_SETTINGS, overridable per cell
    energy = "electrical"
    [[cell]]
    name = "cell-01"               # letters, digits, '.', '_', '-'; unique
    robot = "irb120"               # a bundled name, a description file or a twin folder
    program = ["cell01/main.mod", "cell01/user.sys"]  # the task's modules or a folder
    io = { diPartReady = 1 }       # optional: the I/O scenario (signal -> value)
    routine = "main"               # optional: the entry routine
    cell = "cells/cell01.toml"     # optional: obstacles (joulepath cycle --cell)
    share = 0.8                    # optional (default 1): share of production hours it runs

Paths are relative to the plant file. :func:`read_plant` checks every file and value
before anything runs, gathers every problem (one line each, naming the cell) and raises
them together as :class:`PlantFileError`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from joulepath._io import load_toml
from joulepath.errors import InvalidInput, JoulepathError

MAX_PLANT_BYTES = 4 << 20
"""A plant file of 1,000 cells is about 200 KiB."""
PROGRAM_SUFFIXES = (".mod", ".modx", ".sys", ".prg", ".toml")
"""Files of a program folder that belong to the task (a ``.toml`` is a plain cycle file)."""
HOURS_PER_YEAR_MAX = 8784.0
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")
_PLANT_KEYS = ("name", "hours_per_year", "tariff_eur_per_kwh", "co2_kg_per_kwh")
_CELL_KEYS = ("name", "robot", "program", "io", "routine", "cell", "share")


def _number(lo: float, hi: float, *, lo_open: bool = False) -> Any:
    def check(v: Any) -> str | None:
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            return "a number"
        if (v <= lo if lo_open else v < lo) or v > hi:
            return f"a number in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
        return None

    return check


def _integer(lo: int, hi: int) -> Any:
    def check(v: Any) -> str | None:
        if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
            return f"an integer in [{lo}, {hi}]"
        return None

    return check


def _boolean(v: Any) -> str | None:
    return None if isinstance(v, bool) else "true or false"


def _choice(*options: str) -> Any:
    def check(v: Any) -> str | None:
        return None if v in options else " or ".join(repr(o) for o in options)

    return check


def _cycle_time(v: Any) -> str | None:
    if v == "same":
        return None
    return _number(0.0, 3600.0, lo_open=True)(v) and '"same" or a number of seconds in (0, 3600]'


def _lines(v: Any) -> str | None:
    ok = isinstance(v, list) and all(isinstance(x, int) and not isinstance(x, bool) and x >= 1 for x in v)
    return None if ok else "a list of line numbers (integers >= 1)"


def _measure(v: Any) -> str | None:
    from joulepath.energy import MEASURES

    return None if isinstance(v, str) and v in MEASURES else " or ".join(repr(m) for m in MEASURES)


CELL_SETTINGS: dict[str, Any] = {
    "cycle_time": _cycle_time,
    "use_waits": _boolean,
    "idle_wait": _lines,
    "stop_at_targets": _boolean,
    "exact_targets": _boolean,
    "export": _choice("auto", "rapid", "egm"),
    "lever_plans": _integer(0, 100_000),
    "max_time": _number(1.0, 1e6),
    "accel_time": _number(0.05, 10.0),
    "jerk_time": _number(0.0, 10.0),
    "write_anyway": _boolean,
    "knot_spacing": _number(0.02, 1.0),
    "table_points": _integer(2, 20),
    "pass_search": _integer(0, 20),
    "rapid_plan": _boolean,
    "retime_segments": _boolean,
    "corridor": _number(0.0, 1e4),
    "seed": _integer(0, 2**32 - 1),
    "energy": _measure,
}
"""The settings a plant's ``[defaults]`` or a cell may give: ``joulepath cycle``'s options (``--max-time``
is ``max_time``, ``--idle-wait`` is ``idle_wait``, a list), and ``pass_search``, ``rapid_plan`` and
``retime_segments`` (:class:`joulepath.program.CycleSettings`' fields; ``lever_plans`` is
:class:`joulepath.program.ProgramSettings`': false for the last two plans
for EGM samples only, much faster, at the risk of no RAPID program written). Each maps to its check
(None: valid, else what is expected)."""


class PlantFileError(InvalidInput):
    """A plant file that cannot be run: :attr:`problems` holds one line per problem."""

    def __init__(self, problems: list[str]) -> None:
        super().__init__("\n".join(problems))
        self.problems = tuple(problems)


@dataclass(frozen=True, slots=True, kw_only=True)
class CellConfig:
    """One cell program of a plant, its paths absolute and its settings merged with the defaults.

    ``robot`` is a bundled name, or the absolute path of a description file or twin folder.
    ``program`` holds the task's files, in order (a folder given is expanded to its files).
    ``io`` is the I/O scenario (signal -> value), ``settings`` the cell's settings (the
    plant's defaults, overridden by the cell's own).
    """

    name: str
    robot: str
    program: tuple[Path, ...]
    io: dict[str, float | str] = field(default_factory=dict)
    routine: str | None = None
    cell: Path | None = None
    share: float = 1.0
    settings: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True, kw_only=True)
class PlantConfig:
    """A plant: its production hours, tariff, CO₂ factor and cell programs."""

    name: str
    path: Path
    hours_per_year: float
    tariff_eur_per_kwh: float
    co2_kg_per_kwh: float
    cells: tuple[CellConfig, ...]


def _where(path: Path, cell: str | None) -> str:
    return f"{path}: cell {cell!r}" if cell is not None else f"{path}"


def _program_files(raw: Any, base: Path, say: Any) -> tuple[Path, ...]:
    items = [raw] if isinstance(raw, str) else raw
    if not isinstance(items, list) or not items or not all(isinstance(x, str) and x for x in items):
        say("program must be a file, a folder or a list of files (paths relative to the plant file)")
        return ()
    files: list[Path] = []
    for item in items:
        p = (base / item).resolve()
        if p.is_dir():
            found = sorted(f for f in p.iterdir() if f.is_file() and f.suffix.lower() in PROGRAM_SUFFIXES)
            if not found:
                say(
                    f"program {item}: the folder holds no {', '.join(PROGRAM_SUFFIXES)} file; "
                    "give the task's modules"
                )
            files.extend(found)
        elif p.is_file():
            files.append(p)
        else:
            say(
                f"program {item}: no such file or folder (looked at {p}); "
                "fix the path, relative to the plant file"
            )
    if len(set(files)) != len(files):
        say("program names a file twice; give each module once")
    return tuple(files)


def _io(raw: Any, say: Any) -> dict[str, float | str]:
    if not isinstance(raw, dict):
        say("io must be a table of signal = value (a number or a string)")
        return {}
    out: dict[str, float | str] = {}
    for k, v in raw.items():
        if isinstance(v, bool):
            out[k] = float(v)
        elif isinstance(v, int | float) and math.isfinite(v):
            out[k] = float(v)
        elif isinstance(v, str):
            out[k] = v
        else:
            say(f"io.{k} must be a number or a string, got {v!r}")
    return out


def check_settings(raw: Any, say: Any) -> dict[str, Any]:
    """The settings of ``raw`` (a table) that pass their check; ``say`` is told each problem."""
    if not isinstance(raw, dict):
        say("settings must be a table")
        return {}
    out: dict[str, Any] = {}
    for key, value in raw.items():
        check = CELL_SETTINGS.get(key)
        if check is None:
            say(f"unknown setting {key!r}; the settings are {', '.join(sorted(CELL_SETTINGS))}")
            continue
        expected = check(value)
        if expected:
            say(f"{key} must be {expected}, got {value!r}")
            continue
        out[key] = value
    return out


def _robot(raw: Any, base: Path, say: Any, loaded: dict[str, str | None]) -> str:
    """The robot as the task loads it (a name, or an absolute path); loaded once per distinct value."""
    if not isinstance(raw, str) or not raw:
        say("robot must be a bundled robot's name, a description file or a twin folder")
        return ""
    candidate = base / raw
    resolved = str(candidate.resolve()) if candidate.exists() else raw
    if resolved not in loaded:
        from joulepath.dynamics import load_robot

        try:
            load_robot(resolved)
            loaded[resolved] = None
        except JoulepathError as err:
            loaded[resolved] = str(err)
    if loaded[resolved] is not None:
        say(f"robot {raw!r}: {loaded[resolved]}")
    return resolved


def _cell_settings(defaults: dict[str, Any], own: dict[str, Any], robot: str, say: Any) -> dict[str, Any]:
    merged = {**defaults, **own}
    try:
        from joulepath.plant._task import cycle_settings

        cycle_settings(merged)
        if robot and "energy" in merged:
            from joulepath.dynamics import load_robot
            from joulepath.energy import check_measure

            check_measure(str(merged["energy"]), load_robot(robot).drivetrain)
    except JoulepathError as err:
        say(str(err))
    return merged


def read_plant(path: str | Path) -> PlantConfig:
    """Read and check a plant file (see the module docstring).

    Raises
    ------
    PlantFileError
        Every problem found, one line each naming the file and the cell: an unknown key or
        setting, a value out of range (a negative tariff, a share above 1, ...), a missing
        program or cell file, an unknown robot, duplicate cell names.
    """
    p = Path(path)
    data = load_toml(p, max_bytes=MAX_PLANT_BYTES, what="a plant file")
    problems: list[str] = []

    def sayer(cell: str | None) -> Any:
        return lambda message: problems.append(f"{_where(p, cell)}: {message}")

    say = sayer(None)
    for key in sorted(set(data) - {"plant", "defaults", "cell"}):
        say(f"unknown table {key!r}; a plant file has [plant], [defaults] and [[cell]]")
    head = data.get("plant")
    if not isinstance(head, dict):
        say("[plant] is missing; give name, hours_per_year, tariff_eur_per_kwh and co2_kg_per_kwh")
        head = {}
    for key in sorted(set(head) - set(_PLANT_KEYS)):
        say(f"[plant]: unknown key {key!r}; [plant] holds {', '.join(_PLANT_KEYS)}")
    name = head.get("name", p.stem)
    if not isinstance(name, str) or not name.strip():
        say(f"[plant]: name must be a text, got {name!r}")
        name = p.stem
    figures: dict[str, float] = {}
    checks = {
        "hours_per_year": _number(0.0, HOURS_PER_YEAR_MAX, lo_open=True),
        "tariff_eur_per_kwh": _number(0.0, 1e3),
        "co2_kg_per_kwh": _number(0.0, 1e2),
    }
    for key, check in checks.items():
        if key not in head:
            say(f"[plant]: {key} is missing")
            continue
        expected = check(head[key])
        if expected:
            say(f"[plant]: {key} must be {expected}, got {head[key]!r}")
        else:
            figures[key] = float(head[key])
    defaults = check_settings(data.get("defaults", {}), lambda m: say(f"[defaults]: {m}"))
    raw_cells = data.get("cell", [])
    if not isinstance(raw_cells, list) or not raw_cells:
        say("no [[cell]]; give one [[cell]] table per cell program")
        raw_cells = []
    base = p.resolve().parent
    loaded: dict[str, str | None] = {}
    seen: set[str] = set()
    cells: list[CellConfig] = []
    for k, raw in enumerate(raw_cells, start=1):
        if not isinstance(raw, Mapping):
            say(f"[[cell]] number {k} is not a table")
            continue
        cname = raw.get("name")
        label = cname if isinstance(cname, str) else f"#{k}"
        csay = sayer(label)
        if not isinstance(cname, str) or not _NAME.match(cname):
            csay("name must be 1-64 letters, digits, '.', '_' or '-' (it names the cell's folder)")
        elif cname in seen:
            csay("duplicate cell name; give each cell its own name")
        seen.add(str(cname))
        own = {key: value for key, value in raw.items() if key not in _CELL_KEYS}
        settings = check_settings(own, csay)
        robot = _robot(raw.get("robot", "irb120"), base, csay, loaded)
        files = _program_files(raw.get("program"), base, csay) if "program" in raw else ()
        if "program" not in raw:
            csay("program is missing; give the task's modules or a folder")
        io = _io(raw.get("io", {}), csay)
        routine = raw.get("routine")
        if routine is not None and not (isinstance(routine, str) and routine.isidentifier()):
            csay(f"routine must be a RAPID routine's name, got {routine!r}")
            routine = None
        cell_file = None
        if "cell" in raw:
            cell_file = _cell_file(raw["cell"], base, csay)
        share = raw.get("share", 1.0)
        expected = _number(0.0, 1.0, lo_open=True)(share)
        if expected:
            csay(f"share must be {expected} (the share of production hours it runs), got {share!r}")
            share = 1.0
        merged = _cell_settings(defaults, settings, robot if loaded.get(robot, "") is None else "", csay)
        cells.append(
            CellConfig(
                name=str(cname),
                robot=robot,
                program=files,
                io=io,
                routine=routine,
                cell=cell_file,
                share=float(share),
                settings=merged,
            )
        )
    if problems:
        raise PlantFileError(problems)
    return PlantConfig(
        name=name.strip(),
        path=p.resolve(),
        hours_per_year=figures["hours_per_year"],
        tariff_eur_per_kwh=figures["tariff_eur_per_kwh"],
        co2_kg_per_kwh=figures["co2_kg_per_kwh"],
        cells=tuple(cells),
    )


def _cell_file(raw: Any, base: Path, say: Any) -> Path | None:
    if not isinstance(raw, str) or not raw:
        say("cell must be a cell file's path (TOML or URDF)")
        return None
    p = (base / raw).resolve()
    if not p.is_file():
        say(f"cell {raw}: no such file (looked at {p}); fix the path, relative to the plant file")
        return None
    from joulepath.program import read_cell

    try:
        read_cell(p)
    except JoulepathError as err:
        say(f"cell: {err}")
        return None
    return p
