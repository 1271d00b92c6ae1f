"""Energy tables on disk: Parquet with the schema's metadata; ingestion of logs into a table."""

from __future__ import annotations

import hashlib
import io
import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from joulepath._io import atomic_write_bytes
from joulepath.data._features import log_to_frame
from joulepath.data._logs import JointLog, read_log
from joulepath.data._schema import (
    FEATURE_SETS,
    METADATA_KEY,
    SCHEMA_VERSION,
    TARGETS,
    table_columns,
)
from joulepath.errors import InvalidLog

if TYPE_CHECKING:
    from joulepath.dynamics import Robot

TCP_TOLERANCE_M = 0.005
"""Largest median distance between a log's TCP columns and FK(q) before ingestion refuses it."""


@dataclass(frozen=True, slots=True, eq=False)
class EnergyTable:
    """An energy table and what it holds (see :mod:`joulepath.data._schema`)."""

    frame: pd.DataFrame
    feature_set: str
    robot: str | None = None
    sources: tuple[dict[str, Any], ...] = field(default_factory=tuple)

    @property
    def features(self) -> tuple[str, ...]:
        return FEATURE_SETS[self.feature_set]

    @property
    def n_moves(self) -> int:
        return int(self.frame["move_id"].nunique())

    def metadata(self) -> dict[str, Any]:
        return {
            "schema_version": SCHEMA_VERSION,
            "feature_set": self.feature_set,
            "robot": self.robot,
            "sources": list(self.sources),
            "units": "SI: s, rad, rad/s, rad/s^2, m, m/s, m/s^2, J",
        }

    def fingerprint(self) -> str:
        """SHA-256 of the table's values (for model cards and caches)."""
        h = hashlib.sha256()
        h.update(",".join(self.frame.columns).encode())
        h.update(np.ascontiguousarray(self.frame.to_numpy(dtype=float)).tobytes())
        return h.hexdigest()


def save_table(table: EnergyTable, path: str | os.PathLike[str]) -> Path:
    """Write a table to Parquet atomically, with its metadata."""
    arrow = pa.Table.from_pandas(table.frame, preserve_index=False)
    meta = dict(arrow.schema.metadata or {})
    meta[METADATA_KEY] = json.dumps(table.metadata()).encode()
    arrow = arrow.replace_schema_metadata(meta)
    buf = io.BytesIO()
    pq.write_table(arrow, buf, compression="zstd")
    return atomic_write_bytes(path, buf.getvalue())


def load_table(path: str | os.PathLike[str]) -> EnergyTable:
    """Read a table written by :func:`save_table` and check its columns against the schema.

    Raises
    ------
    InvalidLog
        Not a Parquet file, no joulepath metadata, or columns that do not match
        the feature set (naming the missing and unexpected ones).
    """
    p = Path(path)
    if not p.exists():
        raise InvalidLog(f"{p}: no such file; give an energy table (.parquet) written by `joulepath ingest`")
    try:
        arrow = pq.read_table(p)
    except (OSError, pa.ArrowInvalid) as err:
        raise InvalidLog(
            f"{p}: not a readable Parquet energy table ({' '.join(str(err).split())}); "
            "give a table written by `joulepath ingest`"
        ) from err
    raw = (arrow.schema.metadata or {}).get(METADATA_KEY)
    if raw is None:
        raise InvalidLog(f"{p}: has no joulepath metadata; create tables with `joulepath ingest`")
    meta = json.loads(raw)
    feature_set = meta.get("feature_set")
    if feature_set not in FEATURE_SETS:
        raise InvalidLog(f"{p}: unknown feature set {feature_set!r}")
    frame = arrow.to_pandas()
    check_columns(frame, feature_set, source=str(p))
    return EnergyTable(
        frame=frame[list(table_columns(feature_set))],
        feature_set=feature_set,
        robot=meta.get("robot"),
        sources=tuple(meta.get("sources", ())),
    )


def check_columns(frame: pd.DataFrame, feature_set: str, *, source: str) -> None:
    """Raise InvalidLog naming the missing and unexpected columns of a table."""
    want = table_columns(feature_set)
    missing = [c for c in want if c not in frame.columns]
    extra = [c for c in frame.columns if c not in want]
    if missing or extra:
        parts = []
        if missing:
            parts.append(f"missing column(s) {', '.join(missing)}")
        if extra:
            parts.append(f"unexpected column(s) {', '.join(extra)}")
        raise InvalidLog(
            f"{source}: {'; '.join(parts)} for feature set {feature_set!r}; "
            "write the table again with `joulepath ingest` (or `save_table`)"
        )


def _tcp_from_robot(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pose = robot.fk(q)
    return pose.position_m, pose.quaternion, pose.euler_zyx


def _check_tcp(log: JointLog, robot: Robot) -> None:
    assert log.tcp_position is not None
    step = max(1, log.n_rows // 2000)
    logged = log.tcp_position[::step]
    err = np.linalg.norm(robot.fk(log.q[::step]).position_m - logged, axis=1)
    median = float(np.median(err))
    if median <= TCP_TOLERANCE_M:
        return
    hint = ""
    as_rad = np.linalg.norm(robot.fk(log.q[::step] * 180 / np.pi).position_m - logged, axis=1)
    if np.median(as_rad) <= TCP_TOLERANCE_M:
        hint = "; the q columns match if read as radians: the log mixes units"
    raise InvalidLog(
        f"{log.source}: the TCP columns x, y, z are {median * 1000:.1f} mm (median) away from "
        f"{robot.name}'s forward kinematics of q{hint}; is this log from another robot? "
        "(pass the right robot, or none to skip the check)"
    )


def ingest(
    paths: Sequence[str | os.PathLike[str]],
    *,
    robot: Robot | None = None,
    progress: Callable[[str], None] | None = None,
) -> EnergyTable:
    """Read logs and build one energy table.

    Controller logs give the ``full40`` feature set from their TCP columns (checked
    against ``robot``'s kinematics when a robot is given); generic logs give
    ``full40`` with TCP signals from ``robot``'s kinematics, or the ``joint`` set
    when no robot is given. Files that cannot all give ``full40`` make a ``joint``
    table. ``move_id`` is unique across files, in the order given.

    Raises
    ------
    InvalidLog
        For the first log that cannot be used; nothing is returned then.
    """
    if not paths:
        raise InvalidLog("no log files given")
    logs = []
    for p in paths:
        log = read_log(p)
        if robot is not None and log.kind == "controller":
            _check_tcp(log, robot)
        logs.append(log)
        if progress:
            progress(str(p))
    full = all(log.kind == "controller" or robot is not None for log in logs)
    feature_set = "full40" if full else "joint"
    frames = []
    sources = []
    offset = 0
    scale = robot.velocity_limit if robot is not None else None
    for log in logs:
        tcp = None
        if feature_set == "full40" and log.kind == "generic":
            assert robot is not None
            tcp = _tcp_from_robot(robot, log.q)
        frame = log_to_frame(log, feature_set=feature_set, tcp=tcp, speed_scale=scale, move_offset=offset)
        n_moves = int(frame["move_id"].nunique())
        sources.append(
            {
                "file": Path(log.source).name,
                "kind": log.kind,
                "rows": len(frame),
                "moves": n_moves,
                "first_move_id": offset,
            }
        )
        offset += n_moves
        frames.append(frame)
    frame = pd.concat(frames, ignore_index=True)
    return EnergyTable(
        frame=frame,
        feature_set=feature_set,
        robot=robot.name if robot is not None else None,
        sources=tuple(sources),
    )


__all__ = ["EnergyTable", "TARGETS", "check_columns", "ingest", "load_table", "save_table"]
