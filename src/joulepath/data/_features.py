"""From a validated joint log to energy-table rows: move segmentation, finite differences, targets."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from joulepath._typing import FloatArray
from joulepath.data._logs import JointLog
from joulepath.data._schema import FEATURE_SETS, TARGETS, table_columns
from joulepath.energy import joint_energy

if TYPE_CHECKING:  # pandas is imported where used: an optimization needs no data frames
    import pandas as pd

REST_SPEED = 1.0 * np.pi / 180.0
"""Joint speed (rad/s) below which every joint counts as at rest: 1 deg/s."""

CORNER_DIP = 0.6
"""A blended corner: a local minimum of the joint speed below this share of both neighbouring peaks ..."""

CORNER_TURN_DEG = 30.0
"""... or a dip where the direction of joint motion turns by more than this angle."""

GAP_FACTOR = 2.0
"""A step in ``t`` longer than this many median sample periods is a gap: the log stops there."""


def find_gaps(t: FloatArray) -> np.ndarray:
    """Indices ``k`` where ``t[k] - t[k-1]`` exceeds :data:`GAP_FACTOR` median sample periods.

    A gap means the logger stopped (a pause, a lost connection, two recordings in
    one file). Ingestion ends the move before a gap and starts a new one after it,
    and gives the sample before the gap the median period as its length, so a gap
    never becomes one row whose ``dt`` spans the pause.

    Examples
    --------
    >>> find_gaps(np.array([0.0, 0.025, 0.05, 3600.0, 3600.025, 3600.05])).tolist()
    [3]
    """
    if t.size < 3:
        return np.zeros(0, dtype=np.int64)
    step = np.diff(t)
    period = float(np.median(step))
    return (np.nonzero(step > GAP_FACTOR * period)[0] + 1).astype(np.int64)


def segment_moves(t: FloatArray, qd: FloatArray, *, speed_scale: FloatArray | None = None) -> np.ndarray:
    """Label each sample with the move it belongs to; -1 for idle samples before the first move.

    A move starts where the arm sets off after standing still (all joints below
    :data:`REST_SPEED`), or at a blended corner (zone ``z1..z200``): a local minimum
    of the normalised joint speed ``max_i |qd_i| / speed_scale_i`` (with a
    prominence of at least 1 % of the stretch's top speed) that either dips below
    :data:`CORNER_DIP` of the peaks on both sides, or dips below 95 % of them while
    the direction of joint motion turns by more than :data:`CORNER_TURN_DEG` between
    those peaks (a joint-interpolated move never turns). A move keeps its trailing rest.

    Parameters
    ----------
    t : ndarray of shape (n,)
    qd : ndarray of shape (n, n_joints)
        rad/s.
    speed_scale : ndarray of shape (n_joints,), optional
        Per-joint speed limits used to normalise (default 1).

    Returns
    -------
    ndarray of int64, shape (n,)
    """
    n = t.size
    moving = np.abs(qd).max(axis=1) > REST_SPEED
    scale = (
        np.ones(qd.shape[1])
        if speed_scale is None
        else np.where(np.isfinite(speed_scale) & (speed_scale > 0), speed_scale, 1.0)
    )
    vel = qd / scale
    speed = np.abs(vel).max(axis=1)
    starts = np.nonzero(moving & ~np.r_[False, moving[:-1]])[0]
    stops = np.nonzero(moving & ~np.r_[moving[1:], False])[0]
    cos_turn = np.cos(np.radians(CORNER_TURN_DEG))
    corners: list[int] = []
    # blended corners inside each moving stretch (stretch k runs from starts[k] to stops[k]);
    # candidate minima need a prominence of 1 % of the stretch's top speed (not sensor noise)
    for s, e in zip(starts, stops, strict=True):
        seg = speed[s : e + 1]
        if seg.size < 5:
            continue
        from scipy.signal import find_peaks  # here: SciPy's signal package costs 0.3 s to import

        minima = find_peaks(-seg, prominence=0.01 * seg.max())[0]
        last = 0
        for k, m in enumerate(minima):
            right_end = minima[k + 1] if k + 1 < minima.size else seg.size
            pl = last + int(np.argmax(seg[last:m]))
            pr = int(m) + int(np.argmax(seg[m:right_end]))
            peak = min(seg[pl], seg[pr])
            if not seg[m] < 0.95 * peak:
                continue
            a, b = vel[s + pl], vel[s + pr]
            turn = a @ b < cos_turn * np.linalg.norm(a) * np.linalg.norm(b)
            if seg[m] < CORNER_DIP * peak or turn:
                corners.append(int(s + m))
                last = int(m)
    bounds = np.zeros(n, dtype=bool)
    bounds[starts] = True
    bounds[np.asarray(corners, dtype=np.int64)] = True
    labels = np.cumsum(bounds) - 1
    return labels.astype(np.int64)


def _differentiate(values: FloatArray, t: FloatArray, first: np.ndarray, last: np.ndarray) -> FloatArray:
    """d/dt within moves: central differences, one-sided at each move's first and last row."""
    out = np.zeros_like(values)
    if values.shape[0] < 2:
        return out
    fwd = (values[1:] - values[:-1]) / (t[1:] - t[:-1])[:, None]
    central = np.zeros_like(values)
    central[1:-1] = (values[2:] - values[:-2]) / (t[2:] - t[:-2])[:, None]
    interior = ~(first | last)
    out[interior] = central[interior]
    lone = first & last
    f = first & ~lone
    l_ = last & ~lone
    out[f] = fwd[np.nonzero(f)[0]]
    out[l_] = fwd[np.nonzero(l_)[0] - 1]
    return out


def tcp_columns(
    position: FloatArray,
    quaternion: FloatArray,
    euler_unwrapped: FloatArray,
    derivative: Callable[[FloatArray], FloatArray],
) -> dict[str, FloatArray]:
    """The 22 TCP inputs of the ``full40`` set from position, quaternion and EulerZYX.

    ``derivative`` differentiates along time (the caller's sampling and move
    boundaries); Euler angles come in unwrapped along time and are reported wrapped
    to (-pi, pi], their rates from the unwrapped signal. Arrays are ``(..., 3)``,
    ``(..., 4)`` (w first) and ``(..., 3)`` (z, y, x).
    """
    vel = derivative(position)
    acc = derivative(vel)
    rate = derivative(euler_unwrapped)
    rate_acc = derivative(rate)
    wrapped = (euler_unwrapped + np.pi) % (2 * np.pi) - np.pi
    cols: dict[str, FloatArray] = {}
    for k, name in enumerate(("x", "y", "z")):
        cols[name], cols[f"d{name}"], cols[f"dd{name}"] = position[..., k], vel[..., k], acc[..., k]
    for k, name in enumerate(("qw", "qx", "qy", "qz")):
        cols[name] = quaternion[..., k]
    for k, (name, dname) in enumerate((("yaw", "phi"), ("pitch", "theta"), ("roll", "psi"))):
        cols[name], cols[f"d{dname}"], cols[f"dd{dname}"] = wrapped[..., k], rate[..., k], rate_acc[..., k]
    return cols


def sample_lengths(t: FloatArray) -> FloatArray:
    """Length of each sample, s: ``t[k+1] - t[k]``; the last sample repeats the previous one."""
    if t.size < 2:
        return np.zeros_like(t)
    dt = np.diff(t)
    out: FloatArray = np.r_[dt, dt[-1]]
    return out


def log_to_frame(
    log: JointLog,
    *,
    feature_set: str,
    tcp: tuple[FloatArray, FloatArray, FloatArray] | None = None,
    speed_scale: FloatArray | None = None,
    move_offset: int = 0,
) -> pd.DataFrame:
    """Energy-table rows of one log.

    Moves end at every gap in ``t`` (:func:`find_gaps`); the sample before a gap
    lasts the median sample period.

    Parameters
    ----------
    log : JointLog
    feature_set : {"full40", "joint"}
    tcp : (position m (n, 3), quaternion w-first (n, 4), EulerZYX z,y,x rad (n, 3)), optional
        TCP signals for ``full40``; default: the ones the log carries.
    speed_scale : ndarray of shape (n,), optional
        Joint speed limits for move segmentation.
    move_offset : int
        Added to the move labels (to keep ``move_id`` unique across files).
    """
    t = log.t
    gaps = find_gaps(t)
    chunk = np.zeros(t.size, dtype=np.int64)
    chunk[gaps] = 1
    chunk = np.cumsum(chunk)
    if log.move is not None:
        # a gap splits a move: one label per (stretch between gaps, move) pair, in order
        _, labels = np.unique(np.column_stack([chunk, log.move]), axis=0, return_inverse=True)
        labels = labels.reshape(-1).astype(np.int64)
        keep = np.ones(t.size, dtype=bool)
    else:
        labels = np.full(t.size, -1, dtype=np.int64)
        bounds = np.r_[0, gaps, t.size]
        n_seen = 0
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            part = segment_moves(t[a:b], log.qd[a:b], speed_scale=speed_scale)
            labels[a:b] = np.where(part >= 0, part + n_seen, -1)
            n_seen += int(part.max()) + 1 if part.size else 0
        keep = labels >= 0
    dt = sample_lengths(t)
    if gaps.size:
        dt[gaps - 1] = float(np.median(np.diff(t)))
    idx = np.nonzero(keep)[0]
    t, labels, dt = t[idx], labels[idx], dt[idx]
    q, qd, tau = log.q[idx], log.qd[idx], log.torques("ingestion (the energy targets)")[idx]
    first = np.r_[True, labels[1:] != labels[:-1]]
    last = np.r_[labels[1:] != labels[:-1], True]
    cols: dict[str, np.ndarray] = {"move_id": labels + move_offset, "t": t}
    qdd = log.qdd[idx] if log.qdd is not None else _differentiate(qd, t, first, last)
    n = q.shape[1]
    for i in range(n):
        cols[f"q{i + 1}"] = q[:, i]
        cols[f"dq{i + 1}"] = qd[:, i]
        cols[f"ddq{i + 1}"] = qdd[:, i]
    if feature_set == "full40":
        if tcp is None:
            if log.tcp_position is None or log.tcp_quaternion is None or log.tcp_euler is None:
                raise ValueError("full40 needs TCP signals")
            tcp = (log.tcp_position, log.tcp_quaternion, log.tcp_euler)
        pos, quat, eul = (a[idx] for a in tcp)
        cols.update(
            tcp_columns(pos, quat, np.unwrap(eul, axis=0), lambda v: _differentiate(v, t, first, last))
        )
    energy = joint_energy(tau, qd, dt)  # the one definition: |tau_i qd_i| dt
    for i in range(n):
        cols[f"E{i + 1}"] = energy[:, i]
    cols["E"] = energy.sum(axis=1)
    cols["dt"] = dt
    import pandas as pd

    frame = pd.DataFrame(cols)
    return frame[list(table_columns(feature_set, n))]


__all__ = ["FEATURE_SETS", "TARGETS", "find_gaps", "log_to_frame", "sample_lengths", "segment_moves"]
