"""Identification data: joint samples ``(q, qd, qdd, tau)`` (or currents) from controller or generic logs.

How the motion is derived from a log (``speed_cutoff_hz``; what was applied is recorded
as a :class:`MotionDerivation`, on the twin's card as ``motion``):

* **Raw** (``None``): accelerations are a log's own ``ddq`` columns when it has them
  (generic logs); otherwise the central difference of the logged joint speed on the
  log's own timestamps, ``qdd[k] = (qd[k+1] - qd[k-1]) / (t[k+1] - t[k-1])``, within
  each stretch between gaps in ``t`` (:func:`joulepath.data.find_gaps`). That is the
  mean acceleration over two sample periods, with an error of order ``h² q'''' / 6`` on
  a smooth motion; but it divides speed noise by ``2h`` and takes timestamp jitter as
  motion, so on a fast, jittered log (Franka Panda: 1 kHz, 0.7-1.8 ms between rows, 6 %
  of rows repeating the one before) it is noise.
* **Low-passed** (a cutoff in Hz, :func:`filtered_motion`): within each stretch, rows
  whose positions and speeds repeat the row before exactly (a logger writing a stale
  sample again) are left out of the fit; the other rows' speeds are interpolated
  (linearly) onto a uniform time base at their median period, low-passed by a
  Butterworth filter of order :data:`FILTER_ORDER` run forwards and backwards
  (``scipy.signal.filtfilt``: zero phase, no delay), differentiated there (central
  differences), and read back (linearly) at every row's own timestamp. A log's own
  ``ddq`` columns are low-passed the same way instead of the difference. The positions
  of a repeated row are interpolated between its neighbours; the others stay as logged.
  The logged torques and currents are never touched: what is scored stays the raw
  log, only the motion that predicts it is filtered.
* ``"auto"``: :data:`AUTO_SPEED_CUTOFF_HZ` for a log sampled at :data:`AUTO_MIN_RATE_HZ`
  or faster without ``ddq`` columns of its own, else raw (:func:`resolve_speed_cutoff`).

Either way the rows kept are the same (all, or, when the accelerations are
differentiated, all but the first and last of each stretch), with the same torques.
"""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.data import find_gaps, is_moves_sidecar, log_in_joints, read_log
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, InvalidLog

SIGNALS = {"torque": "N·m", "current": "A"}
"""What identification data hold per joint, and its unit."""

AUTO_SPEED_CUTOFF_HZ = 20.0
"""Hz: the low-pass of the logged speeds that ``speed_cutoff_hz="auto"`` applies to a fast log."""
AUTO_MIN_RATE_HZ = 200.0
"""Hz: the slowest sample rate ``"auto"`` low-passes (20 Hz is then a fifth of Nyquist or less);
slower logs stay raw (their central difference already spans 10 ms or more)."""
FILTER_ORDER = 4
"""Order of the Butterworth low-pass (run twice by ``filtfilt``: zero phase)."""

SpeedCutoff = float | str | None
"""``None`` (raw), a cutoff in Hz, or ``"auto"`` (:func:`resolve_speed_cutoff`)."""


@dataclass(frozen=True, slots=True, eq=False)
class IdentificationData:
    """Joint samples for identification, SI units.

    Attributes
    ----------
    q, qd, qdd, tau : ndarray of shape (N, n)
        rad, rad/s, rad/s², and the logged drive signal: torque in N·m (motor side when the
        drives measure it), or motor current in A when ``signal == "current"``.
    dt : ndarray of shape (N,)
        Length of each sample, s (for energies).
    stretch : ndarray of int, shape (N,)
        Label of the continuous stretch (between gaps, per file) each sample belongs to.
    sources : tuple of str
    data_hash : str
        SHA-256 of the logs' bytes (in the order given), or of the arrays.
    signal : {"torque", "current"}
        What ``tau`` holds (:data:`SIGNALS`); :meth:`scaled` turns currents into torques.
    motion : MotionDerivation or None
        How ``q``, ``qd`` and ``qdd`` were derived from the logs (None: given as arrays).
    """

    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    tau: FloatArray
    dt: FloatArray
    stretch: np.ndarray
    sources: tuple[str, ...] = ()
    data_hash: str = ""
    signal: str = "torque"
    motion: MotionDerivation | None = None

    def __post_init__(self) -> None:
        if self.signal not in SIGNALS:
            raise InvalidInput(f"signal must be one of {', '.join(SIGNALS)}, got {self.signal!r}")

    @property
    def unit(self) -> str:
        """The unit of :attr:`tau` (``"N·m"`` or ``"A"``)."""
        return SIGNALS[self.signal]

    def scaled(self, gains: FloatArray) -> IdentificationData:
        """Currents times per-joint torque constants ``gains`` (N·m/A): the same samples as torques."""
        if self.signal != "current":
            raise InvalidInput("only motor currents are scaled into torques; these data hold torques")
        return replace(self, tau=self.tau * np.asarray(gains, dtype=float)[None, :], signal="torque")

    @property
    def n_samples(self) -> int:
        return int(self.q.shape[0])

    @property
    def n_joints(self) -> int:
        return int(self.q.shape[1])

    def subset(self, mask: np.ndarray) -> IdentificationData:
        """The samples where ``mask`` holds."""
        return IdentificationData(
            q=self.q[mask],
            qd=self.qd[mask],
            qdd=self.qdd[mask],
            tau=self.tau[mask],
            dt=self.dt[mask],
            stretch=self.stretch[mask],
            sources=self.sources,
            data_hash=self.data_hash,
            signal=self.signal,
            motion=self.motion,
        )

    @classmethod
    def from_arrays(
        cls,
        q: FloatArray,
        qd: FloatArray,
        qdd: FloatArray,
        tau: FloatArray,
        dt: float | FloatArray,
        *,
        stretch: np.ndarray | None = None,
        source: str = "<arrays>",
        signal: str = "torque",
    ) -> IdentificationData:
        """Samples given directly (e.g. a plant's exact signals); checked for shape and finiteness.

        ``tau`` holds torques (N·m), or motor currents (A) with ``signal="current"``.
        """
        arrays = [np.asarray(a, dtype=float) for a in (q, qd, qdd, tau)]
        shape = arrays[0].shape
        if len(shape) != 2 or any(a.shape != shape for a in arrays):
            raise InvalidInput(
                f"q, qd, qdd and tau must all have shape (N, n); got {[a.shape for a in arrays]}"
            )
        if not all(np.all(np.isfinite(a)) for a in arrays):
            raise InvalidInput("q, qd, qdd and tau must be finite (a NaN or inf was given)")
        d = np.broadcast_to(np.asarray(dt, dtype=float), shape[:1]).copy()
        lab = np.zeros(shape[0], dtype=np.int64) if stretch is None else np.asarray(stretch, dtype=np.int64)
        h = hashlib.sha256()
        for a in arrays:
            h.update(np.ascontiguousarray(a).tobytes())
        return cls(
            q=arrays[0],
            qd=arrays[1],
            qdd=arrays[2],
            tau=arrays[3],
            dt=d,
            stretch=lab,
            sources=(source,),
            data_hash=h.hexdigest(),
            signal=signal,
        )


def _central(qd: FloatArray, t: FloatArray) -> FloatArray:
    out = np.full_like(qd, np.nan)
    out[1:-1] = (qd[2:] - qd[:-2]) / (t[2:] - t[:-2])[:, None]
    return out


def check_speed_cutoff(cutoff: SpeedCutoff) -> SpeedCutoff:
    """``cutoff`` when it is None, ``"auto"`` or a finite frequency > 0 Hz (as a float).

    Raises
    ------
    InvalidInput
        Anything else.
    """
    if cutoff is None or cutoff == "auto":
        return cutoff
    if (
        isinstance(cutoff, bool)
        or not isinstance(cutoff, int | float)
        or not (np.isfinite(cutoff) and cutoff > 0)
    ):
        raise InvalidInput(
            f"speed cutoff must be a frequency > 0 in Hz, 'auto' or None (raw), got {cutoff!r}; "
            f"e.g. {AUTO_SPEED_CUTOFF_HZ:g}"
        )
    return float(cutoff)


def resolve_speed_cutoff(cutoff: SpeedCutoff, rate_hz: float, *, has_qdd: bool = False) -> float | None:
    """The cutoff (Hz) a log sampled at ``rate_hz`` gets; None: raw.

    ``"auto"`` gives :data:`AUTO_SPEED_CUTOFF_HZ` when ``rate_hz >= AUTO_MIN_RATE_HZ`` and the
    log has no accelerations of its own (``has_qdd``), else None; a number is returned as is.
    """
    if cutoff == "auto":
        return AUTO_SPEED_CUTOFF_HZ if rate_hz >= AUTO_MIN_RATE_HZ and not has_qdd else None
    return None if cutoff is None else float(cutoff)


@dataclass(frozen=True, slots=True, kw_only=True)
class MotionDerivation:
    """How the speeds and accelerations were derived from each log (see the module docstring).

    Attributes
    ----------
    requested : float, str or None
        What was asked: a cutoff in Hz, ``"auto"``, or None (raw).
    cutoff_hz : tuple of (float or None)
        Per log, the cutoff applied (None: raw).
    sample_rate_hz : tuple of float
        Per log, the median sample rate within its stretches.
    period_range_s : tuple of (float, float)
        Per log, the shortest and longest time between consecutive rows within a stretch.
    repeated_rows : tuple of int
        Per log, the rows whose positions and speeds repeat the row before exactly (left out
        of the filter's fit when it is applied; always kept as samples, their torque as logged).
    n_rows : tuple of int
        Per log, the rows read.
    """

    requested: float | str | None
    cutoff_hz: tuple[float | None, ...]
    sample_rate_hz: tuple[float, ...]
    period_range_s: tuple[tuple[float, float], ...]
    repeated_rows: tuple[int, ...]
    n_rows: tuple[int, ...]

    @property
    def filtered(self) -> bool:
        """Whether any log's motion was low-passed."""
        return any(c is not None for c in self.cutoff_hz)

    @property
    def speed_cutoff_hz(self) -> float | None:
        """The one cutoff applied to every log (None: raw, or logs given different ones)."""
        cuts = set(self.cutoff_hz)
        return cuts.pop() if len(cuts) == 1 else None

    def describe(self) -> str:
        """One line: what was applied to the motion, the log's rate, jitter and repeated rows."""
        rates = [r for r in self.sample_rate_hz if np.isfinite(r)]
        rate = (
            f"{min(rates):.0f}"
            if rates and round(min(rates)) == round(max(rates))
            else (f"{min(rates):.0f}-{max(rates):.0f}" if rates else "?")
        )
        lo = f"{1e3 * min(p[0] for p in self.period_range_s):.2g}"
        hi = f"{1e3 * max(p[1] for p in self.period_range_s):.2g}"
        gaps = lo if lo == hi else f"{lo}-{hi}"
        share = 100.0 * sum(self.repeated_rows) / max(sum(self.n_rows), 1)
        facts = f"{rate} Hz, {gaps} ms between rows, {share:.1f} % of rows repeat the one before"
        if not self.filtered:
            why = ""
            if self.requested == "auto":
                why = (
                    f"; 'auto' low-passes only logs of {AUTO_MIN_RATE_HZ:g} Hz or more without ddq columns, "
                    "--speed-cutoff HZ low-passes any"
                )
            return f"motion: raw logged speeds, differentiated as logged ({facts}){why}"
        cuts = sorted({"raw" if c is None else f"{c:g} Hz" for c in self.cutoff_hz})
        how = "auto, from the sample rate" if self.requested == "auto" else "as given"
        return (
            f"motion: logged speeds low-passed at {', '.join(cuts)} ({how}; Butterworth order "
            f"{FILTER_ORDER}, zero phase, uniform time base, repeated rows left out) before differentiation; "
            f"torques and currents as logged ({facts})"
        )

    def to_json(self) -> dict[str, Any]:
        """The card's ``motion`` entry."""
        return {
            "requested": self.requested,
            "speed_cutoff_hz": list(self.cutoff_hz),
            "filter": f"Butterworth order {FILTER_ORDER}, zero phase (filtfilt), on a uniform time base",
            "sample_rate_hz": list(self.sample_rate_hz),
            "period_range_s": [list(p) for p in self.period_range_s],
            "repeated_rows": list(self.repeated_rows),
            "n_rows": list(self.n_rows),
        }

    @classmethod
    def merge(cls, parts: Sequence[MotionDerivation]) -> MotionDerivation:
        """One record for several logs, from each log's own record, in order."""
        return cls(
            requested=parts[0].requested,
            cutoff_hz=tuple(c for p in parts for c in p.cutoff_hz),
            sample_rate_hz=tuple(c for p in parts for c in p.sample_rate_hz),
            period_range_s=tuple(c for p in parts for c in p.period_range_s),
            repeated_rows=tuple(c for p in parts for c in p.repeated_rows),
            n_rows=tuple(c for p in parts for c in p.n_rows),
        )


def repeated_rows(q: FloatArray, qd: FloatArray) -> np.ndarray:
    """Mask of the rows whose positions and speeds all equal the row before's (the first row: False)."""
    out = np.zeros(q.shape[0], dtype=bool)
    out[1:] = np.all(q[1:] == q[:-1], axis=1) & np.all(qd[1:] == qd[:-1], axis=1)
    return out


def filtered_motion(
    t: FloatArray,
    q: FloatArray,
    qd: FloatArray,
    cutoff_hz: float,
    *,
    qdd: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Positions, low-passed speeds and their accelerations at every timestamp of one stretch.

    Repeated rows (:func:`repeated_rows`) and rows whose time does not advance are left out;
    the others' speeds go onto a uniform time base of their median period, through a
    Butterworth low-pass at ``cutoff_hz`` (order :data:`FILTER_ORDER`, forwards and
    backwards), are differentiated there by central differences (or the logged ``qdd`` is
    low-passed the same way), and are read back at ``t`` by linear interpolation (the filter's
    ends padded by one period of the cutoff, odd extension); the
    positions of the rows left out are interpolated between the others. Contract (checked
    by the callers): ``t`` non-decreasing, and ``0 < cutoff_hz`` below half the rate.
    """
    from scipy.signal import butter, filtfilt

    fresh = ~repeated_rows(q, qd)
    fresh[1:] &= np.diff(t) > 0
    tf = t[fresh]
    if tf.size < 3:  # the motion never changes: hold the first sample
        return q.copy(), np.repeat(qd[:1], t.size, axis=0), np.zeros_like(qd)
    h = float(np.median(np.diff(tf)))
    grid = tf[0] + h * np.arange(int(np.floor((tf[-1] - tf[0]) / h + 1e-9)) + 1)
    if grid[-1] < tf[-1]:
        grid = np.r_[grid, tf[-1]]

    def resample(a: FloatArray, at: FloatArray, xs: FloatArray) -> FloatArray:
        return np.column_stack([np.interp(at, xs, a[:, j]) for j in range(a.shape[1])])

    b, a = butter(FILTER_ORDER, min(2.0 * cutoff_hz * h, 0.99))
    # padded by one period of the cutoff (odd extension, filtfilt's default kind): scipy's default
    # 15 samples leave a start-up error at the stretch's ends of up to 35 rad/s² on an exact 1 kHz
    # motion at 20 Hz, one period 3 (measured on the sums of sines of tests/identify/test_speed_filter.py)
    pad = min(max(3 * (FILTER_ORDER + 1), math.ceil(1.0 / (cutoff_hz * h))), grid.size - 1)
    speed = filtfilt(b, a, resample(qd[fresh], grid, tf), axis=0, padlen=pad)
    if qdd is None:
        accel = np.gradient(speed, grid, axis=0)
    else:
        accel = filtfilt(b, a, resample(qdd[fresh], grid, tf), axis=0, padlen=pad)
    positions = q.copy()
    if not fresh.all():
        positions[~fresh] = resample(q[fresh], t[~fresh], tf)
    return positions, resample(speed, t, grid), resample(accel, t, grid)


def stretch_motion(
    t: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray | None, cutoff_hz: float | None
) -> tuple[np.ndarray, FloatArray, FloatArray, FloatArray]:
    """The rows kept of one stretch and their ``(q, qd, qdd)``: all rows when the log gives ``qdd``,
    else all but the first and last (no central difference there), raw or filtered alike.

    Raw (``cutoff_hz`` None): as logged, ``qdd`` the log's or the central difference of
    ``qd`` on ``t``; else :func:`filtered_motion`. Needs at least 3 rows.
    """
    keep = np.arange(t.size) if qdd is not None else np.arange(1, t.size - 1)
    if cutoff_hz is None:
        acc = qdd if qdd is not None else _central(qd, t)
        return keep, q[keep], qd[keep], acc[keep]
    pos, speed, acc = filtered_motion(t, q, qd, cutoff_hz, qdd=qdd)
    return keep, pos[keep], speed[keep], acc[keep]


def motion_record(
    t: FloatArray,
    bounds: np.ndarray,
    q: FloatArray,
    qd: FloatArray,
    requested: SpeedCutoff,
    *,
    has_qdd: bool,
    source: str,
) -> MotionDerivation:
    """The :class:`MotionDerivation` of one log (stretches between ``bounds``), its cutoff resolved.

    Raises
    ------
    InvalidInput
        A cutoff at or above half the log's sample rate.
    """
    inner = np.ones(max(t.size - 1, 0), dtype=bool)
    cuts = np.asarray(bounds[1:-1], dtype=np.int64) - 1
    inner[cuts[(cuts >= 0) & (cuts < inner.size)]] = False  # a step across a gap is no period
    steps = np.diff(t)[inner]
    steps = steps[steps > 0]
    if steps.size:
        period = float(np.median(steps))
        span = (float(steps.min()), float(steps.max()))
    else:
        period, span = float("nan"), (float("nan"), float("nan"))
    rate = 1.0 / period
    cutoff = resolve_speed_cutoff(requested, rate, has_qdd=has_qdd)
    if cutoff is not None and steps.size and not cutoff < 0.5 * rate:
        raise InvalidInput(
            f"{source}: speed cutoff {cutoff:g} Hz is not below half the log's sample rate "
            f"({rate:.4g} Hz); give a lower cutoff (e.g. {0.1 * rate:.3g} Hz), or none (--speed-cutoff off)"
        )
    return MotionDerivation(
        requested=requested,
        cutoff_hz=(cutoff,),
        sample_rate_hz=(rate,),
        period_range_s=(span,),
        repeated_rows=(int(repeated_rows(q, qd).sum()),),
        n_rows=(int(t.size),),
    )


def logged_signal(paths: Sequence[str | os.PathLike[str]]) -> str:
    """What identification reads from the logs: ``"torque"`` when each logs ``tau{k}``, else ``"current"``.

    Raises
    ------
    InvalidLog
        A log that cannot be read, or logs of which some hold neither torques nor
        currents for a signal the others hold (mixed torque-only and current-only logs).
    """
    logs = [read_log(Path(p)) for p in paths if not is_moves_sidecar(p)]
    if all(log.tau is not None for log in logs):
        return "torque"
    missing = [log.source for log in logs if log.current is None]
    if missing:
        raise InvalidLog(
            f"{missing[0]}: logs joint torques but no motor currents, while other logs hold currents "
            "only; identify from one kind of log: all with torques tau{k}, or all with currents i{k}"
        )
    return "current"


def data_from_logs(
    paths: Sequence[str | os.PathLike[str]],
    robot: Robot,
    *,
    signal: str = "torque",
    speed_cutoff_hz: SpeedCutoff = None,
) -> IdentificationData:
    """Read controller or generic logs of ``robot``.

    ``signal="current"`` reads the motor currents ``i{k}`` (A) of generic logs in place of
    the torques (:attr:`IdentificationData.signal`). ``speed_cutoff_hz``: how the motion is
    derived (module docstring): None (default) raw, a cutoff in Hz to low-pass the logged
    speeds before their differentiation, or ``"auto"``; recorded in
    :attr:`IdentificationData.motion`. The torques or currents are read as logged either way.

    Raises
    ------
    InvalidLog
        A log that cannot be read (the reader names file and line), no logs at all,
        or a log whose positions or speeds are outside the robot's ranges or limits.
    InvalidInput
        The robot's joint count differs from the logs', or a cutoff is not a frequency
        below half a log's sample rate.
    """
    requested = check_speed_cutoff(speed_cutoff_hz)
    if signal not in SIGNALS:
        raise InvalidInput(f"signal must be one of {', '.join(SIGNALS)}, got {signal!r}")
    from joulepath.data import check_limits as _check_limits  # the ingest check: ranges and speeds, named

    files = [Path(p) for p in paths if not is_moves_sidecar(p)]
    if not files:
        raise InvalidLog(
            "no joint logs given (only `joulepath simulate`'s *.moves.csv lists of programmed moves); "
            "give the logs beside them"
        )
    h = hashlib.sha256()
    parts: list[tuple[FloatArray, ...]] = []
    labels: list[np.ndarray] = []
    records: list[MotionDerivation] = []
    n_stretch = 0
    for path in files:
        log = log_in_joints(read_log(path), robot)
        if signal == "current":
            if log.current is None:
                raise InvalidLog(
                    f"{path}: logs no motor currents; identifying from currents needs i1..i"
                    f"{log.q.shape[1]} (A) in every log"
                )
            tau = log.current
        else:
            tau = log.torques("identification")
        if log.q.shape[1] != robot.n_joints:
            raise InvalidInput(
                f"{path}: the log has {log.q.shape[1]} joints but robot {robot.name!r} has "
                f"{robot.n_joints}; give the robot that was logged (--robot)"
            )
        _check_limits(log, robot)
        h.update(path.read_bytes())
        t = log.t
        bounds = np.r_[0, find_gaps(t), t.size]
        record = motion_record(
            t, bounds, log.q, log.qd, requested, has_qdd=log.qdd is not None, source=str(path)
        )
        records.append(record)
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            if b - a < 3:
                continue
            sl = slice(a, b)
            tt = t[sl]
            keep, q, qd, qdd = stretch_motion(
                tt, log.q[sl], log.qd[sl], None if log.qdd is None else log.qdd[sl], record.cutoff_hz[0]
            )
            dt = np.r_[np.diff(tt), np.diff(tt)[-1:]]
            parts.append((q, qd, qdd, tau[sl][keep], dt[keep]))
            labels.append(np.full(parts[-1][0].shape[0], n_stretch, dtype=np.int64))
            n_stretch += 1
    if not parts:
        raise InvalidLog(
            f"{files[0]}: no stretch of 3 or more samples between gaps; nothing to identify from"
        )
    q, qd, qdd, tau, dt = (np.concatenate([p[i] for p in parts]) for i in range(5))
    return IdentificationData(
        q=q,
        qd=qd,
        qdd=qdd,
        tau=tau,
        dt=dt,
        stretch=np.concatenate(labels),
        sources=tuple(str(p) for p in files),
        data_hash=h.hexdigest(),
        signal=signal,
        motion=MotionDerivation.merge(records),
    )


__all__ = [
    "AUTO_MIN_RATE_HZ",
    "AUTO_SPEED_CUTOFF_HZ",
    "FILTER_ORDER",
    "IdentificationData",
    "MotionDerivation",
    "SIGNALS",
    "SpeedCutoff",
    "check_speed_cutoff",
    "data_from_logs",
    "filtered_motion",
    "logged_signal",
    "repeated_rows",
    "resolve_speed_cutoff",
    "stretch_motion",
]
