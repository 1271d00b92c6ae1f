"""Identification data: joint samples ``(q, qd, qdd, tau)`` (or currents) from controller or generic logs.

Accelerations: a log's own ``ddq`` columns when it has them (generic logs);
otherwise the central difference of the logged joint speed on the log's own
timestamps, ``qdd[k] = (qd[k+1] - qd[k-1]) / (t[k+1] - t[k-1])``, within each
stretch between gaps in ``t`` (:func:`joulepath.data.find_gaps`). That difference is
the mean acceleration over two sample periods: it smooths speed noise (a moving
average of the exact derivative over ``[t[k-1], t[k+1]]``) and its error on a smooth
motion is of order ``h² q'''' / 6``. The first and last sample of each stretch (no
central difference) are dropped.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from joulepath._typing import FloatArray
from joulepath.data import find_gaps, is_moves_sidecar, log_in_joints, read_log
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, InvalidLog

SIGNALS = {"torque": "N·m", "current": "A"}
"""What identification data hold per joint, and its unit."""


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
    paths: Sequence[str | os.PathLike[str]], robot: Robot, *, signal: str = "torque"
) -> IdentificationData:
    """Read controller or generic logs of ``robot`` (see the module docstring for ``qdd``).

    ``signal="current"`` reads the motor currents ``i{k}`` (A) of generic logs in place of
    the torques (:attr:`IdentificationData.signal`).

    Raises
    ------
    InvalidLog
        A log that cannot be read (the reader names file and line), no logs at all,
        or a log whose positions or speeds are outside the robot's ranges or limits.
    InvalidInput
        The robot's joint count differs from the logs'.
    """
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
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            if b - a < 3:
                continue
            sl = slice(a, b)
            qdd = log.qdd[sl] if log.qdd is not None else _central(log.qd[sl], t[sl])
            keep = slice(0, b - a) if log.qdd is not None else slice(1, b - a - 1)
            tt = t[sl]
            dt = np.r_[np.diff(tt), np.diff(tt)[-1:]]
            parts.append((log.q[sl][keep], log.qd[sl][keep], qdd[keep], tau[sl][keep], dt[keep]))
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
    )


__all__ = ["IdentificationData", "SIGNALS", "data_from_logs", "logged_signal"]
