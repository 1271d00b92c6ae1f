"""Joint logs: the controller's CSV (thesis Appendix D.2) and a generic CSV for any arm.

Controller log (``kind="controller"``): header exactly
``t,q1,dq1,tau1,...,q6,dq6,tau6,x,y,z,e1,e2,e3,e4,psi,theta,phi``; units s, deg, deg/s,
N·m, mm, unit quaternion with ``e1 = w``, RAPID EulerZYX in deg (``psi`` about X,
``theta`` about Y, ``phi`` about Z); values as ``NumToStr(value, 5)`` writes them.

Generic log (``kind="generic"``): a header naming at least ``t`` (s) and, per
joint, ``q{i}`` (rad), ``dq{i}`` (rad/s), ``tau{i}`` (N·m); optional ``ddq{i}``
(rad/s²), ``i{i}`` (motor current, A) and ``move`` (an integer move label). With
currents for every joint, ``tau{i}`` may be left out (a drive's log often has no
torque); what needs torques (ingestion, identification, measuring) then says so.
Columns may come in any order.

Files are parsed block by block with pyarrow's streaming CSV reader. When that
fails, a line-by-line pass finds the exact line and field to report. Every check
(UTF-8 text, header, field count, numbers, NaN, strictly increasing time, duplicated
rows, at least :data:`MIN_ROWS` samples, plausible units) reports file and line;
nothing is written for a log that fails.

Units are checked, not assumed: ``t`` must be in seconds (a median sample period
over :data:`MAX_SAMPLE_PERIOD_S`, or logged speeds about 1000 times the rate of the
logged positions, mean milliseconds); a speed column that is about 57 times (or 1/57
of) the rate of its position column means degrees mixed with radians. A generic
log's header must name joints 1..n of an arm of 5 to 7 joints (``q1..q7``, ``dq1..dq7``,
``tau1..tau7`` for a 7-joint arm), each with ``q``, ``dq`` and ``tau`` (or ``i``):
``tau0`` or ``q9`` or ``i8`` or a missing ``tau3`` is refused, never dropped; a current
column is refused above :data:`MAX_CURRENT_A` (milliamperes, most likely). Gaps in ``t`` are not
refused here: ingestion splits the moves there (:func:`joulepath.data.find_gaps`).
"""

from __future__ import annotations

import csv
import io
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv

from joulepath._io import atomic_write_text, file_kind
from joulepath._typing import FloatArray
from joulepath.data._schema import (
    GENERIC_REQUIRED,
    LOG_COLUMNS,
    MAX_JOINTS,
    MIN_JOINTS,
    MOVES_SIDECAR_COLUMNS,
    MOVES_SIDECAR_SUFFIX,
    N_JOINTS,
)
from joulepath.errors import InvalidLog
from joulepath.units import DEG, MM

_MAX_REPORTED = 5
_BLOCK = 1 << 22  # 4 MiB blocks

MIN_ROWS = 3
"""Fewest data lines a log may hold (central differences need three samples)."""

MAX_SAMPLE_PERIOD_S = 1.0
"""Largest median sample period, s; above it ``t`` is taken for milliseconds and refused."""

MAX_CURRENT_A = 1000.0
"""Largest plausible motor current, A; a current column beyond it is taken for mA and refused."""

_JOINT_COLUMN = re.compile(r"^(q|dq|ddq|tau|i)(\d+)$")


@dataclass(frozen=True, slots=True, eq=False)
class JointLog:
    """A validated joint log in SI units.

    Attributes
    ----------
    source : str
    kind : {"controller", "generic"}
    t : ndarray of shape (n,)
        s.
    q, qd : ndarray of shape (n, n_joints)
        rad, rad/s (a controller log has 6 joints, a generic log 5 to 7).
    tau : ndarray of shape (n, n_joints) or None
        Joint torques, N·m; None for a generic log of currents only
        (:meth:`torques` refuses it in one line).
    current : ndarray of shape (n, n_joints) or None
        Motor currents, A (generic logs with ``i{k}`` columns).
    qdd : ndarray of shape (n, n_joints) or None
        Logged accelerations (generic logs only), rad/s².
    tcp_position : ndarray of shape (n, 3) or None
        m (controller logs).
    tcp_quaternion : ndarray of shape (n, 4) or None
        ``(w, x, y, z)``.
    tcp_euler : ndarray of shape (n, 3) or None
        RAPID EulerZYX ``(z, y, x)`` in rad.
    move : ndarray of shape (n,) or None
        Move labels given by a generic log.
    """

    source: str
    kind: str
    t: FloatArray
    q: FloatArray
    qd: FloatArray
    tau: FloatArray | None
    qdd: FloatArray | None = None
    tcp_position: FloatArray | None = None
    tcp_quaternion: FloatArray | None = None
    tcp_euler: FloatArray | None = None
    move: np.ndarray | None = None
    current: FloatArray | None = None

    @property
    def n_rows(self) -> int:
        return int(self.t.size)

    def torques(self, purpose: str) -> FloatArray:
        """The logged joint torques, or InvalidLog naming ``purpose`` for a log of currents only.

        Raises
        ------
        InvalidLog
            The log has motor currents ``i{k}`` but no torques ``tau{k}``.
        """
        if self.tau is None:
            raise InvalidLog(
                f"{self.source}: logs motor currents (i1..i{self.q.shape[1]}) but no joint torques; "
                f"{purpose} needs the torques tau1..tau{self.q.shape[1]} (N·m): log them too "
                "(`joulepath evaluate` scores a model on currents alone)"
            )
        return self.tau


def _fail(source: str, problems: list[str], fix: str = "") -> InvalidLog:
    shown = problems[:_MAX_REPORTED]
    more = len(problems) - len(shown)
    text = "; ".join(shown) + (f"; and {more} more" if more > 0 else "")
    return InvalidLog(f"{source}: {text}" + (f" ({fix})" if fix else ""))


def _not_utf8(source: str, data: bytes, err: UnicodeDecodeError, base: int = 0) -> InvalidLog:
    """InvalidLog naming the line and byte offset of the first byte that is not UTF-8."""
    pos = base + err.start
    line = data.count(b"\n", 0, err.start) + 1
    bad = data[err.start : err.start + 1].hex()
    return InvalidLog(
        f"{source}: line {line} (byte offset {pos}): byte 0x{bad} is not UTF-8 text; "
        "is this a CSV log? save it as UTF-8 (or plain ASCII) CSV"
    )


def _read_header(path: Path, source: str) -> list[str]:
    try:
        mode = os.stat(path).st_mode
    except OSError as err:
        raise InvalidLog(f"{source}: cannot be read ({err.strerror})") from err
    if stat.S_ISDIR(mode):
        raise InvalidLog(f"{source}: is a folder, not a log; give the log files in it (e.g. {source}/*.csv)")
    if not stat.S_ISREG(mode):
        raise InvalidLog(
            f"{source}: is a {file_kind(mode)}, not a regular file; a log is read several times, so save "
            "it to a file first and give that file"
        )
    try:
        with path.open("rb") as fh:
            raw = fh.readline()
    except OSError as err:
        raise InvalidLog(f"{source}: cannot be read ({err.strerror})") from err
    try:
        first = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise _not_utf8(source, raw, err) from err
    first = first.removeprefix("\ufeff")  # a byte-order mark some spreadsheet programs write
    if not first.strip():
        raise InvalidLog(
            f"{source}: is empty; a log starts with a header line such as '{','.join(LOG_COLUMNS[:4])},...'"
        )
    return [h.strip() for h in first.strip().split(",")]


def is_moves_sidecar(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is the ``.moves.csv`` sidecar ``joulepath simulate`` writes beside a log.

    Recognised by its header (``move,t_start,t_end,speed,zone,j1_deg,...``), not
    by its name alone; a file that cannot be read is not a sidecar.
    """
    p = Path(path)
    if not p.is_file() or p.is_fifo():
        return False
    try:
        with p.open("rb") as fh:
            first = fh.readline(4096).decode("utf-8", errors="replace")
    except OSError:
        return False
    header = [h.strip() for h in first.strip().split(",")]
    k = len(MOVES_SIDECAR_COLUMNS)
    joints = header[k:]
    return (
        tuple(header[:k]) == MOVES_SIDECAR_COLUMNS
        and len(joints) > 0
        and joints == [f"j{i + 1}_deg" for i in range(len(joints))]
    )


def moves_sidecar_path(log: str | os.PathLike[str]) -> Path:
    """The sidecar path beside a log: ``logs/lab.csv`` -> ``logs/lab.moves.csv``."""
    p = Path(log)
    return p.with_name(p.name.removesuffix(".csv") + MOVES_SIDECAR_SUFFIX)


def generic_joints(header: list[str]) -> int:
    """Joints of a generic log header: the largest ``i`` of ``q{i}``, ``dq{i}``, ``tau{i}`` (0 if none)."""
    found = [int(m.group(2)) for h in header if (m := _JOINT_COLUMN.match(h)) and m.group(1) != "ddq"]
    return max(found, default=0)


def _check_joint_columns(header: list[str], source: str) -> None:
    """Refuse generic-log columns of joints other than 1..n, n = 5..7 (never drop them)."""
    n = generic_joints(header)
    if not MIN_JOINTS <= n <= MAX_JOINTS:
        n = N_JOINTS
    other = sorted(
        {int(m.group(2)) for h in header if (m := _JOINT_COLUMN.match(h)) and not 1 <= int(m.group(2)) <= n}
    )
    if other:
        cols = [h for h in header if (m := _JOINT_COLUMN.match(h)) and int(m.group(2)) in other]
        raise InvalidLog(
            f"{source}: line 1: column(s) {', '.join(cols)} name joint(s) {', '.join(map(str, other))}, "
            f"but joulepath reads logs of arms of {MIN_JOINTS} to {MAX_JOINTS} joints, numbered from 1 "
            "(q1..qn, dq1..dqn, tau1..taun): remove those columns if they are not joints of the arm"
        )
    joints = range(1, n + 1)
    # torques, currents or both, each for every joint (torques when neither is there)
    kinds = [p for p in ("tau", "i") if any(f"{p}{k}" in header for k in joints)] or ["tau"]
    wanted = ("t", *(f"{p}{k}" for k in joints for p in ("q", "dq", *kinds)))
    missing = [c for c in wanted if c not in header]
    if missing:
        raise InvalidLog(
            f"{source}: line 1: header lacks column(s) {', '.join(missing)} of a {n}-joint log; a generic "
            f"log needs t and q{{i}}, dq{{i}}, tau{{i}} for i = 1..{n} (s, rad, rad/s, N·m), or motor "
            "currents i{i} (A) in place of (or beside) tau{i}"
        )


def _is_generic(header: list[str]) -> bool:
    """Whether a header has the generic log's columns for at least :data:`MIN_JOINTS` joints."""
    joints = range(1, MIN_JOINTS + 1)
    return (
        "x" not in header
        and all(c in header for c in ("t", *(f"{p}{k}" for k in joints for p in ("q", "dq"))))
        and (all(f"tau{k}" in header for k in joints) or all(f"i{k}" in header for k in joints))
    )


def detect_kind(header: list[str], source: str) -> str:
    """``"controller"`` or ``"generic"`` from a header; InvalidLog for anything else."""
    if tuple(header) == LOG_COLUMNS:
        return "controller"
    if tuple(header[: len(MOVES_SIDECAR_COLUMNS)]) == MOVES_SIDECAR_COLUMNS:
        raise InvalidLog(
            f"{source}: line 1: this is the list of programmed moves that `joulepath simulate` writes "
            f"beside its log (*{MOVES_SIDECAR_SUFFIX}), not a joint log; give the log itself"
        )
    if _is_generic(header):
        dup = sorted({h for h in header if header.count(h) > 1})
        if dup:
            raise InvalidLog(f"{source}: line 1: duplicated column(s) {', '.join(dup)}")
        _check_joint_columns(header, source)
        return "generic"
    if len(header) == len(LOG_COLUMNS) or "x" in header:
        wrong = [
            f"field {i + 1} is {got!r}, expected {want!r}"
            for i, (got, want) in enumerate(zip(header, LOG_COLUMNS, strict=False))
            if got != want
        ]
        if len(header) != len(LOG_COLUMNS):
            missing = [c for c in LOG_COLUMNS if c not in header]
            extra = [h for h in header if h not in LOG_COLUMNS]
            if missing or extra:  # name them rather than the shifted fields after them
                wrong = [f"lacks column(s) {', '.join(missing)}"] if missing else []
                wrong += [f"unexpected column(s) {', '.join(extra)}"] if extra else []
            wrong.insert(0, f"{len(header)} columns instead of {len(LOG_COLUMNS)}")
        raise InvalidLog(
            f"{source}: line 1: not the controller log header ({'; '.join(wrong[:3])}); "
            f"expected: {','.join(LOG_COLUMNS)}"
        )
    missing = [c for c in GENERIC_REQUIRED if c not in header]
    raise InvalidLog(
        f"{source}: line 1: header lacks column(s) {', '.join(missing)}; a generic log needs "
        "t and q{i}, dq{i}, tau{i} for i = 1..6 (s, rad, rad/s, N·m), or motor currents i{i} (A) "
        "in place of tau{i}"
    )


def _diagnose(path: Path, source: str, header: list[str]) -> InvalidLog:
    """Line-by-line pass that names the lines and fields pyarrow could not parse."""
    problems: list[str] = []
    n = len(header)
    data = path.read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        return _not_utf8(source, data, err)
    lines = text.split("\n")
    last = len(lines)
    while last > 1 and not lines[last - 1].strip():
        last -= 1
    for lineno in range(2, last + 1):
        raw = lines[lineno - 1].rstrip("\r")
        if not raw.strip():
            problems.append(f"line {lineno}: empty line")
            continue
        try:
            fields = next(csv.reader(io.StringIO(raw)))
        except (csv.Error, StopIteration) as err:
            problems.append(f"line {lineno}: not a CSV line ({err or 'a stray carriage return or quote'})")
            continue
        if len(fields) != n:
            what = f"line {lineno}: {len(fields)} fields instead of {n}"
            if lineno == last and len(fields) < n:
                what += " (the file is truncated: delete the last line or export again)"
            problems.append(what)
            continue
        for name, value in zip(header, fields, strict=True):
            try:
                float(value)
            except ValueError:
                problems.append(f"line {lineno}, field {name}: {value!r} is not a number")
        if len(problems) > _MAX_REPORTED:
            break
    if not problems:
        problems.append("cannot be parsed as CSV")
    return _fail(source, problems)


def _parse(path: Path, source: str, header: list[str]) -> dict[str, np.ndarray]:
    types = {h: pa.float64() for h in header}
    if "move" in header:
        types["move"] = pa.int64()
    convert = pacsv.ConvertOptions(
        column_types=types,
        null_values=[],
        strings_can_be_null=False,
        quoted_strings_can_be_null=False,
    )
    read = pacsv.ReadOptions(block_size=_BLOCK)
    chunks: dict[str, list[np.ndarray]] = {h: [] for h in header}
    try:
        with pacsv.open_csv(path, read_options=read, convert_options=convert) as reader:
            for batch in reader:
                for h, col in zip(batch.schema.names, batch.columns, strict=True):
                    chunks[h].append(col.to_numpy(zero_copy_only=False))
    except (pa.ArrowInvalid, pa.ArrowTypeError) as err:
        raise _diagnose(path, source, header) from err
    out = {h: (np.concatenate(v) if v else np.empty(0)) for h, v in chunks.items()}
    if out["t"].size == 0:
        raise InvalidLog(f"{source}: has a header but no data lines")
    if out["t"].size < MIN_ROWS:
        raise InvalidLog(
            f"{source}: has only {out['t'].size} data line(s); a log needs at least {MIN_ROWS} samples "
            "of a moving arm: log a whole move"
        )
    return out


def _check_rows(cols: dict[str, np.ndarray], header: list[str], source: str) -> None:
    problems: list[str] = []
    data = np.column_stack([cols[h].astype(float) for h in header])
    bad = ~np.isfinite(data)
    if bad.any():
        for r, c in zip(*np.nonzero(bad), strict=True):
            problems.append(f"line {r + 2}, field {header[c]}: {data[r, c]} is not a finite number")
            if len(problems) > _MAX_REPORTED:
                break
        raise _fail(source, problems, "remove or repair those lines")
    same = np.all(data[1:] == data[:-1], axis=1)
    if same.any():
        rows = np.nonzero(same)[0] + 3
        raise _fail(
            source,
            [f"line {r} duplicates line {r - 1}" for r in rows],
            "the logger wrote a sample twice: delete the duplicated lines",
        )
    t = cols["t"]
    back = np.nonzero(np.diff(t) <= 0)[0]
    if back.size:
        raise _fail(
            source,
            [
                f"line {k + 3}: t = {t[k + 1]:g} s does not increase (line {k + 2}: t = {t[k]:g} s)"
                for k in back
            ],
            "time must strictly increase; are two logs concatenated?",
        )


def _check_time_unit(t: FloatArray, q: FloatArray, qd: FloatArray, source: str) -> None:
    """Refuse ``t`` that is not in seconds (milliseconds, most likely)."""
    period = float(np.median(np.diff(t)))
    if period > MAX_SAMPLE_PERIOD_S:
        raise InvalidLog(
            f"{source}: column t advances {period:g} per sample (median); in seconds that is slower "
            f"than one sample per {MAX_SAMPLE_PERIOD_S:g} s: is t in milliseconds? t must be in seconds "
            "(divide it by 1000)"
        )
    ratios = _unit_ratio(q, qd, t)
    finite = ratios[np.isfinite(ratios)]
    if finite.size and abs(np.log(np.median(finite) / 1000.0)) < 0.4:
        raise InvalidLog(
            f"{source}: the logged speeds dq are about {np.median(finite):.0f} times the rate of change "
            "of q over t: is t in milliseconds? t must be in seconds (divide it by 1000)"
        )


def _unit_ratio(q: FloatArray, qd: FloatArray, t: FloatArray) -> FloatArray:
    """Per joint: median |logged speed| / median |d(logged position)/dt| over moving samples."""
    dq_fd = np.gradient(q, t, axis=0)
    ratios = np.full(q.shape[1], np.nan)
    for j in range(q.shape[1]):
        moving = np.abs(dq_fd[:, j]) > 1e-3 * max(np.abs(dq_fd[:, j]).max(), 1e-12)
        if moving.sum() >= 5 and np.abs(qd[moving, j]).max() > 0:
            ratios[j] = np.median(np.abs(qd[moving, j])) / np.median(np.abs(dq_fd[moving, j]))
    return ratios


def _check_units(q: FloatArray, qd: FloatArray, t: FloatArray, source: str, kind: str) -> None:
    unit = "deg" if kind == "controller" else "rad"
    ratios = _unit_ratio(q, qd, t)
    problems = []
    factor = 180.0 / np.pi
    for j, r in enumerate(ratios):
        if not np.isfinite(r):
            continue
        if abs(np.log(r / factor)) < 0.4:
            problems.append(
                f"column q{j + 1} looks like radians next to dq{j + 1} in degrees/s "
                f"(dq{j + 1} is {r:.1f} times dq/dt of q{j + 1})"
                if unit == "deg"
                else f"column dq{j + 1} looks like deg/s next to q{j + 1} in rad "
                f"(dq{j + 1} is {r:.1f} times dq/dt of q{j + 1})"
            )
        elif abs(np.log(r * factor)) < 0.4:
            problems.append(
                f"column dq{j + 1} looks like rad/s next to q{j + 1} in degrees "
                f"(dq{j + 1} is 1/{1 / r:.1f} of dq/dt of q{j + 1})"
                if unit == "deg"
                else f"column q{j + 1} looks like degrees next to dq{j + 1} in rad/s "
                f"(dq{j + 1} is 1/{1 / r:.1f} of dq/dt of q{j + 1})"
            )
    if kind == "generic":
        big = np.nonzero(np.abs(q).max(axis=0) > 4 * np.pi)[0]
        problems += [
            f"column q{j + 1} reaches {np.abs(q[:, j]).max():.1f}, more than 4π: degrees in a radian log?"
            for j in big
        ]
    if problems:
        fix = (
            "controller logs are in deg and deg/s"
            if unit == "deg"
            else "generic logs are in rad and rad/s: convert the columns"
        )
        raise _fail(source, problems, fix)


def _check_currents(current: FloatArray, source: str) -> None:
    """Refuse current columns beyond :data:`MAX_CURRENT_A` (milliamperes, most likely)."""
    peak = np.abs(current).max(axis=0)
    big = np.nonzero(peak > MAX_CURRENT_A)[0]
    if big.size:
        raise _fail(
            source,
            [f"column i{j + 1} reaches {peak[j]:g}, more than {MAX_CURRENT_A:g} A" for j in big],
            "motor currents are in A: is the column in mA? divide it by 1000",
        )


def read_log(path: str | os.PathLike[str]) -> JointLog:
    """Read and validate one controller or generic joint log.

    Raises
    ------
    InvalidLog
        With the file, line and field of every problem found (up to five).
    """
    p = Path(path)
    source = str(p)
    header = _read_header(p, source)
    kind = detect_kind(header, source)
    cols = _parse(p, source, header)
    _check_rows(cols, header, source)
    t = cols["t"]
    joints = range(1, (N_JOINTS if kind == "controller" else generic_joints(header)) + 1)
    q = np.column_stack([cols[f"q{i}"] for i in joints])
    qd = np.column_stack([cols[f"dq{i}"] for i in joints])
    tau = np.column_stack([cols[f"tau{i}"] for i in joints]) if "tau1" in cols else None
    _check_time_unit(t, q, qd, source)
    _check_units(q, qd, t, source, kind)
    if kind == "controller":
        quat = np.column_stack([cols[c] for c in ("e1", "e2", "e3", "e4")])
        norms = np.linalg.norm(quat, axis=1)
        bad = np.nonzero(np.abs(norms - 1.0) > 1e-3)[0]
        if bad.size:
            raise _fail(
                source,
                [f"line {k + 2}: quaternion e1..e4 has norm {norms[k]:.4f}, not 1" for k in bad],
            )
        return JointLog(
            source=source,
            kind=kind,
            t=t,
            q=q * DEG,
            qd=qd * DEG,
            tau=tau,
            tcp_position=np.column_stack([cols["x"], cols["y"], cols["z"]]) * MM,
            tcp_quaternion=quat,
            tcp_euler=np.column_stack([cols["phi"], cols["theta"], cols["psi"]]) * DEG,
        )
    qdd = None
    if all(f"ddq{i}" in cols for i in joints):
        qdd = np.column_stack([cols[f"ddq{i}"] for i in joints])
    move = cols["move"].astype(np.int64) if "move" in cols else None
    current = np.column_stack([cols[f"i{i}"] for i in joints]) if "i1" in cols else None
    if current is not None:
        _check_currents(current, source)
    return JointLog(source=source, kind=kind, t=t, q=q, qd=qd, tau=tau, qdd=qdd, move=move, current=current)


def _numtostr(values: FloatArray) -> np.ndarray:
    """RAPID ``NumToStr(value, 5)`` of single-precision ``num`` values, as strings."""
    as_num = values.astype(np.float32).astype(np.float64)
    return np.char.mod("%.5f", np.round(as_num, 5))


def controller_log_text(
    t: FloatArray,
    q_deg: FloatArray,
    qd_deg: FloatArray,
    tau: FloatArray,
    tcp_mm: FloatArray,
    quat: FloatArray,
    euler_xyz_deg: FloatArray,
) -> str:
    """The controller's CSV text (header and rows) for sampled signals in its units.

    ``euler_xyz_deg`` holds the columns ``psi, theta, phi`` (EulerZYX about X, Y, Z).
    """
    cols = [t[:, None]]
    for i in range(N_JOINTS):
        cols += [q_deg[:, i : i + 1], qd_deg[:, i : i + 1], tau[:, i : i + 1]]
    cols += [tcp_mm, quat, euler_xyz_deg]
    data = np.concatenate(cols, axis=1)
    text = _numtostr(data)
    body = "\n".join(",".join(row) for row in text.tolist())
    return ",".join(LOG_COLUMNS) + "\n" + body + "\n"


def generic_log_text(
    t: FloatArray,
    q: FloatArray,
    qd: FloatArray,
    tau: FloatArray | None,
    *,
    current: FloatArray | None = None,
) -> str:
    """A generic joint log's CSV text (s, rad, rad/s, N·m, A; 10 significant digits) for any joint count.

    ``tau`` may be None when ``current`` is given (a log of currents only).
    """
    n = q.shape[1]
    signals = [("q", q), ("dq", qd), ("tau", tau), ("i", current)]
    present = [(name, s) for name, s in signals if s is not None]
    head = ["t", *(f"{name}{i}" for i in range(1, n + 1) for name, _ in present)]
    cols = [t[:, None]]
    for i in range(n):
        cols += [s[:, i : i + 1] for _, s in present]
    data = np.concatenate(cols, axis=1)
    body = "\n".join(",".join(f"{v:.10g}" for v in row) for row in data.tolist())
    return ",".join(head) + "\n" + body + "\n"


def write_controller_log(path: str | os.PathLike[str], text: str) -> Path:
    """Write a controller log atomically."""
    return atomic_write_text(path, text)
