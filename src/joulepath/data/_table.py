"""Energy tables on disk: Parquet with the schema's metadata; ingestion of logs into a table."""

from __future__ import annotations

import hashlib
import io
import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from joulepath._io import atomic_write_bytes
from joulepath.data._features import GAP_FACTOR, REST_SPEED, find_gaps, log_to_frame
from joulepath.data._logs import JointLog, is_moves_sidecar, read_log
from joulepath.data._schema import (
    FEATURE_SETS,
    MAX_JOINTS,
    METADATA_KEY,
    MIN_JOINTS,
    MOVES_SIDECAR_SUFFIX,
    N_JOINTS,
    SCHEMA_VERSION,
    TARGETS,
    feature_columns,
    joints_in,
    table_columns,
    target_columns,
)
from joulepath.errors import InvalidInput, InvalidLog

if TYPE_CHECKING:  # pandas is imported where used: an optimization needs no data frames
    import pandas as pd

    from joulepath.dynamics import Robot

TCP_TOLERANCE_M = 0.005
"""Largest median distance between a log's TCP columns and FK(q) before ingestion refuses it."""

RANGE_TOLERANCE_RAD = 0.05
"""How far (rad, about 3 deg) a logged joint may sit outside the robot's range before ingestion refuses it."""

SPEED_TOLERANCE = 3.0
"""How many times its speed limit a logged joint speed may reach before ingestion refuses it.

Degrees in a radian log read 57 times too fast; a genuine log may pass the nominal
limit for a few samples (the emulated controller's zone blends reach about 1.7 times
it on joint 6, and differentiated positions are noisy), so the bound is set well
between the two."""


@dataclass(frozen=True, slots=True, eq=False)
class EnergyTable:
    """An energy table and what it holds (see :mod:`joulepath.data._schema`)."""

    frame: pd.DataFrame
    feature_set: str
    robot: str | None = None
    sources: tuple[dict[str, Any], ...] = field(default_factory=tuple)

    @property
    def n_joints(self) -> int:
        """Joints of the logged arm (from the ``q{i}`` columns)."""
        return joints_in(self.frame.columns)

    @property
    def features(self) -> tuple[str, ...]:
        return feature_columns(self.feature_set, self.n_joints)

    @property
    def targets(self) -> tuple[str, ...]:
        """``E1 .. En`` and ``E`` of this table's arm."""
        return target_columns(self.n_joints)

    @property
    def n_moves(self) -> int:
        return int(self.frame["move_id"].nunique())

    def metadata(self) -> dict[str, Any]:
        return {
            "schema_version": SCHEMA_VERSION,
            "feature_set": self.feature_set,
            "n_joints": self.n_joints,
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


def _corrupt(p: Path, what: str) -> InvalidLog:
    return InvalidLog(
        f"{p}: {what}; the file is damaged or not a joulepath table: write it again with `joulepath ingest`"
    )


def load_table(path: str | os.PathLike[str]) -> EnergyTable:
    """Read a table written by :func:`save_table` and check it against the schema.

    Raises
    ------
    InvalidLog
        Not a Parquet file, no (or damaged) joulepath metadata, columns that do not
        match the feature set (naming the missing and unexpected ones), or columns
        that are not numbers or hold NaN or infinite values.
    """
    p = Path(path)
    if not p.exists():
        raise InvalidLog(f"{p}: no such file; give an energy table (.parquet) written by `joulepath ingest`")
    try:
        arrow = pq.read_table(p)
    except (OSError, ValueError, pa.ArrowException) as err:
        raise InvalidLog(
            f"{p}: not a readable Parquet energy table ({' '.join(str(err).split())[:300]}); "
            "give a table written by `joulepath ingest`"
        ) from err
    raw = (arrow.schema.metadata or {}).get(METADATA_KEY)
    if raw is None:
        raise InvalidLog(f"{p}: has no joulepath metadata; create tables with `joulepath ingest`")
    try:
        meta = json.loads(raw)
    except ValueError as err:  # not UTF-8, or not JSON
        raise _corrupt(p, "its joulepath metadata is not valid JSON") from err
    if not isinstance(meta, dict):
        raise _corrupt(p, f"its joulepath metadata is a JSON {type(meta).__name__}, not an object")
    feature_set = meta.get("feature_set")
    if not isinstance(feature_set, str) or feature_set not in FEATURE_SETS:
        raise InvalidLog(
            f"{p}: unknown feature set {feature_set!r}; expected one of {', '.join(FEATURE_SETS)}"
        )
    robot, sources = meta.get("robot"), meta.get("sources", [])
    if robot is not None and not isinstance(robot, str):
        raise _corrupt(p, f"its metadata names the robot as {robot!r}, not a string")
    if not isinstance(sources, list) or not all(isinstance(s, dict) for s in sources):
        raise _corrupt(p, "its metadata's sources are not a list of objects")
    try:
        frame = arrow.to_pandas(ignore_metadata=True)  # pandas' own metadata is not needed
    except (ValueError, TypeError, KeyError, pa.ArrowException) as err:
        raise _corrupt(p, f"its columns cannot be read ({' '.join(str(err).split())[:200]})") from err
    n_joints = meta.get("n_joints", N_JOINTS)
    if (
        isinstance(n_joints, bool)
        or not isinstance(n_joints, int)
        or not MIN_JOINTS <= n_joints <= MAX_JOINTS
    ):
        raise _corrupt(p, f"its metadata gives {n_joints!r} joints, not {MIN_JOINTS} to {MAX_JOINTS}")
    check_columns(frame, feature_set, source=str(p), n_joints=n_joints)
    frame = frame[list(table_columns(feature_set, n_joints))]
    _check_values(frame, p)
    return EnergyTable(frame=frame, feature_set=feature_set, robot=robot, sources=tuple(sources))


def _check_values(frame: pd.DataFrame, p: Path) -> None:
    """Every column numeric and finite (one InvalidLog naming the columns)."""
    import pandas as pd

    text = [str(c) for c, dtype in frame.dtypes.items() if not pd.api.types.is_numeric_dtype(dtype)]
    if text:
        raise InvalidLog(f"{p}: column(s) {', '.join(text)} do not hold numbers; write the table again")
    values = frame.to_numpy(dtype=float)
    bad = ~np.isfinite(values)
    if bad.any():
        cols = [f"{frame.columns[j]} ({int(bad[:, j].sum())} rows)" for j in np.nonzero(bad.any(axis=0))[0]]
        raise InvalidLog(
            f"{p}: NaN or infinite values in column(s) {', '.join(cols[:5])}"
            f"{' ...' if len(cols) > 5 else ''}; write the table again from its logs"
        )


def check_columns(frame: pd.DataFrame, feature_set: str, *, source: str, n_joints: int | None = None) -> None:
    """Raise InvalidLog naming the missing and unexpected columns of a table.

    ``n_joints`` None: the joints the frame's ``q{i}`` columns name (6 if none).
    """
    want = table_columns(feature_set, n_joints or joints_in(frame.columns) or N_JOINTS)
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


def log_in_joints(log: JointLog, robot: Robot) -> JointLog:
    """A controller log in ``robot``'s joints: the controller logs its axis values (positions, speeds,
    torques), which differ from the model's joints on an arm whose axis 3 is coupled to axis 2
    (:meth:`~joulepath.dynamics.Robot.axes_to_joints`, ``axis_torques_to_joints``). The log
    itself for any other arm, and for a generic log (taken as in the model's joints).
    """
    if log.kind != "controller" or not robot.axes_coupled:
        return log
    tau = None if log.tau is None else robot.axis_torques_to_joints(log.tau)
    return replace(log, q=robot.axes_to_joints(log.q), qd=robot.axes_to_joints(log.qd), tau=tau)


def _check_limits(log: JointLog, robot: Robot) -> None:
    """Refuse logged positions outside ``robot``'s ranges and speeds far beyond its limits.

    Degrees in a radian log (x57) land here even when q and dq are consistent
    with each other; limits that are unknown (NaN) are not checked.
    """
    lower, upper, vmax = robot.lower, robot.upper, robot.velocity_limit
    problems: list[str] = []
    for j in range(log.q.shape[1]):
        q, qd = log.q[:, j], log.qd[:, j]
        lo = float(lower[j]) - RANGE_TOLERANCE_RAD if np.isfinite(lower[j]) else -np.inf
        hi = float(upper[j]) + RANGE_TOLERANCE_RAD if np.isfinite(upper[j]) else np.inf
        out = np.nonzero((q < lo) | (q > hi))[0]
        if out.size:
            k = int(out[np.argmax(np.abs(q[out]))])
            problems.append(
                f"line {k + 2}: q{j + 1} = {q[k]:.3f} rad is outside {robot.name}'s range "
                f"[{lower[j]:.3f}, {upper[j]:.3f}] rad ({out.size} rows)"
            )
        if np.isfinite(vmax[j]) and vmax[j] > 0:
            fast = np.nonzero(np.abs(qd) > SPEED_TOLERANCE * vmax[j])[0]
            if fast.size:
                k = int(fast[np.argmax(np.abs(qd[fast]))])
                problems.append(
                    f"line {k + 2}: dq{j + 1} = {qd[k]:.3f} rad/s is {abs(qd[k]) / vmax[j]:.1f} times "
                    f"{robot.name}'s speed limit {vmax[j]:.3f} rad/s ({fast.size} rows)"
                )
    if problems:
        unit = (
            "controller logs are read as deg and deg/s"
            if log.kind == "controller"
            else "generic logs are in rad and rad/s: degrees in q and dq?"
        )
        shown = problems[:5] + ([f"and {len(problems) - 5} more"] if len(problems) > 5 else [])
        raise InvalidLog(
            f"{log.source}: {'; '.join(shown)}; {unit} (is this log from {robot.name}? pass the right "
            "--robot, or leave --robot out to skip the check)"
        )


def _check_motion(log: JointLog, frame: pd.DataFrame) -> None:
    """Refuse a log that gives no rows: the arm never moved."""
    if len(frame) and np.abs(log.qd).max() > REST_SPEED:
        return
    top = float(np.abs(log.qd).max())
    raise InvalidLog(
        f"{log.source}: no motion: the fastest joint speed is {np.degrees(top):.3g} deg/s, below the "
        f"{np.degrees(REST_SPEED):.0f} deg/s at which a joint counts as moving, so the log gives no "
        "energy-table rows; log the arm while it moves"
    )


def _gap_note(log: JointLog) -> str:
    gaps = find_gaps(log.t)
    if not gaps.size:
        return ""
    period = float(np.median(np.diff(log.t)))
    k = int(gaps[0])
    return (
        f"note: {log.source}: {gaps.size} gap(s) in t longer than {GAP_FACTOR:g} x the median sample "
        f"period {period:.4g} s (first: line {k + 2}, {log.t[k] - log.t[k - 1]:.4g} s after line {k + 1}); "
        "the moves end there, and no energy is counted across a gap"
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

    Guards: the ``.moves.csv`` sidecars that :func:`joulepath.sim.simulate` writes
    beside its logs are skipped (with a note to ``progress``); a gap in ``t`` over
    ``GAP_FACTOR`` median sample periods ends the move there (with a note); with a
    robot, logged positions outside its ranges (by more than
    :data:`RANGE_TOLERANCE_RAD`) or speeds over :data:`SPEED_TOLERANCE` times its
    limits are refused (degrees in a radian log, or another robot's log); a log
    without motion, which would give no rows, is refused.

    Parameters
    ----------
    paths : sequence of path
        Controller or generic logs (see :func:`read_log`).
    robot : Robot, optional
        The robot that was logged; it has the logs' number of joints.
    progress : callable, optional
        Called with one line per file read, skipped or noted.

    Raises
    ------
    InvalidLog
        For the first log that cannot be used; nothing is returned then.
    InvalidInput
        ``robot`` has another number of joints than the logs.
    """
    if not paths:
        raise InvalidLog("no log files given")
    logs: list[JointLog] = []
    skipped = []
    for p in paths:
        if is_moves_sidecar(p):
            skipped.append(str(p))
            if progress:
                progress(
                    f"skipped {p}: the programmed moves that `joulepath simulate` writes beside its log "
                    f"(*{MOVES_SIDECAR_SUFFIX}), not a log"
                )
            continue
        log = read_log(p) if robot is None else log_in_joints(read_log(p), robot)
        log.torques("ingestion (the energy targets)")  # a log of currents only is refused here
        n_log = log.q.shape[1]
        if robot is not None and robot.n_joints != n_log:
            raise InvalidInput(
                f"{p}: logs {n_log} joints, but robot {robot.name!r} has {robot.n_joints}; "
                "give the robot that was logged"
            )
        if logs and logs[0].q.shape[1] != n_log:
            raise InvalidLog(
                f"{p}: logs {n_log} joints, but {logs[0].source} logs {logs[0].q.shape[1]}; "
                "one table holds the logs of one arm"
            )
        if robot is not None:
            _check_limits(log, robot)
        if robot is not None and log.kind == "controller":
            _check_tcp(log, robot)
        logs.append(log)
        if progress:
            progress(f"read {p}")
            note = _gap_note(log)
            if note:
                progress(note)
    if not logs:
        raise InvalidLog(
            f"no joint logs among the {len(skipped)} file(s) given: {', '.join(skipped[:3])}"
            f"{' ...' if len(skipped) > 3 else ''} are `joulepath simulate`'s lists of programmed moves "
            f"(*{MOVES_SIDECAR_SUFFIX}); give the logs beside them"
        )
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
        _check_motion(log, frame)
        n_moves = int(frame["move_id"].nunique())
        sources.append(
            {
                "file": Path(log.source).name,
                "kind": log.kind,
                "rows": len(frame),
                "moves": n_moves,
                "first_move_id": offset,
                "gaps": int(find_gaps(log.t).size),
            }
        )
        offset += n_moves
        frames.append(frame)
    import pandas as pd

    frame = pd.concat(frames, ignore_index=True)
    return EnergyTable(
        frame=frame,
        feature_set=feature_set,
        robot=robot.name if robot is not None else None,
        sources=tuple(sources),
    )


__all__ = ["EnergyTable", "TARGETS", "check_columns", "ingest", "load_table", "save_table"]
