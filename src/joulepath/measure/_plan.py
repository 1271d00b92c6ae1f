"""The run folder of ``joulepath optimize`` as the measurement reads it: the task and both planned paths."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.errors import InvalidInput

PLAN_FILES = ("result.json", "path.csv", "default_path.csv")
"""What :func:`read_plan` needs in a run folder (written by ``joulepath optimize --out``)."""


@dataclass(frozen=True, slots=True, eq=False)
class PlannedPath:
    """A planned path: ``t`` (s, from 0) and ``q`` (rad) of shape (n_samples, n_joints)."""

    t: FloatArray
    q: FloatArray

    def at(self, t: FloatArray) -> FloatArray:
        """``q`` at times ``t`` (clipped to the path: its start before, its end after)."""
        tc = np.clip(np.asarray(t, dtype=float), self.t[0], self.t[-1])
        return np.column_stack([np.interp(tc, self.t, self.q[:, j]) for j in range(self.q.shape[1])])


@dataclass(frozen=True, slots=True, eq=False)
class Plan:
    """The task of a run folder and its two planned paths."""

    folder: Path
    robot: str
    start: FloatArray
    end: FloatArray
    duration_s: float
    optimized: PlannedPath
    default: PlannedPath
    planned: dict[str, float | None]


def _path_csv(path: Path, n_joints: int) -> PlannedPath:
    try:
        with path.open(encoding="utf-8") as fh:
            header = fh.readline().strip().split(",")
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except (OSError, ValueError, UnicodeDecodeError) as err:
        raise InvalidInput(f"{path}: cannot be read as a path CSV ({err}); rerun joulepath optimize") from err
    want = ["t", *(f"q{i}" for i in range(1, n_joints + 1))]
    if header[: len(want)] != want or data.shape[0] < 2 or data.shape[1] < len(want):
        raise InvalidInput(
            f"{path}: expected columns {','.join(want)},... and at least 2 rows; rerun joulepath optimize"
        )
    t, q = data[:, 0], data[:, 1 : n_joints + 1]
    if not np.all(np.isfinite(data[:, : n_joints + 1])) or np.any(np.diff(t) <= 0):
        raise InvalidInput(f"{path}: times must increase and values be finite")
    return PlannedPath(t - t[0], q)


def _vector(summary: dict[str, Any], key: str, source: Path) -> FloatArray:
    value = summary.get(key)
    if not isinstance(value, list) or not value or not all(isinstance(v, int | float) for v in value):
        raise InvalidInput(f"{source}: {key} must be a list of joint values (rad); rerun joulepath optimize")
    return np.asarray(value, dtype=float)


def read_plan(folder: str | os.PathLike[str]) -> Plan:
    """Read a run folder of ``joulepath optimize`` (``result.json``, ``path.csv``, ``default_path.csv``).

    Raises
    ------
    InvalidInput
        A file is missing or does not hold what ``joulepath optimize`` writes.
    """
    root = Path(folder)
    if not root.is_dir():
        raise InvalidInput(f"{root}: not a folder; give the --out folder of joulepath optimize")
    missing = [name for name in PLAN_FILES if not (root / name).is_file()]
    if missing:
        raise InvalidInput(
            f"{root}: missing {', '.join(missing)}; give the --out folder of joulepath optimize"
        )
    source = root / "result.json"
    try:
        summary = json.loads(source.read_text(encoding="utf-8"))
    except (OSError, ValueError) as err:
        raise InvalidInput(f"{source}: not readable JSON ({err}); rerun joulepath optimize") from err
    if not isinstance(summary, dict):
        raise InvalidInput(f"{source}: expected a JSON object; rerun joulepath optimize")
    start = _vector(summary, "start_rad", source)
    end = _vector(summary, "end_rad", source)
    duration = summary.get("duration_s")
    if start.size != end.size or not isinstance(duration, int | float) or not duration > 0:
        raise InvalidInput(f"{source}: start_rad, end_rad and a positive duration_s are needed")
    n = start.size
    optimized = _path_csv(root / "path.csv", n)
    default = _path_csv(root / "default_path.csv", n)
    for name, p in (("path.csv", optimized), ("default_path.csv", default)):
        if np.abs(p.q[0] - start).max() > 1e-6 or np.abs(p.q[-1] - end).max() > 1e-6:
            raise InvalidInput(f"{root / name}: does not run from start_rad to end_rad of result.json")
    planned = {
        key: (float(summary[key]) if isinstance(summary.get(key), int | float) else None)
        for key in (
            "energy_default_J",
            "energy_optimized_J",
            "saved_pct",
            "energy_default_lab_J",
            "energy_optimized_lab_J",
            "saved_lab_pct",
        )
    }
    return Plan(
        folder=root,
        robot=str(summary.get("robot", "")),
        start=start,
        end=end,
        duration_s=float(duration),
        optimized=optimized,
        default=default,
        planned=planned,
    )
