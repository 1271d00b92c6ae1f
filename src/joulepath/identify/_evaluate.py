"""Score any robot model on any joint log: "does this model fit my robot?" (``joulepath evaluate``).

The model is a robot (a bundled name, a named arm, a robot file, or a twin folder)
and, for currents, its drives' joint-side torque constants. For every sample of the
log it predicts

* the logged torque: ``tau = RNEA(q, qd, qdd)`` plus the robot's friction, through
  a twin's identified gear losses (:meth:`joulepath.dynamics.Calibration.motor_torque`)
  when the model is a twin: the torque as the drives measure it, as ``identify`` fits it;
* the motor current: ``i = tau / k`` per joint, with ``k`` the joint-side torque
  constant in N·m/A (the motor's torque constant times the gear ratio).

The motion is derived as :func:`joulepath.identify.data_from_logs` derives it
(:attr:`EvaluateConfig.speed_cutoff_hz`): accelerations the log's ``ddq`` columns, or
central differences of the logged speed within each stretch between gaps (the ends of
a stretch are dropped), or, with a cutoff, the speeds low-passed (zero phase) before
their differentiation. Only the motion that predicts is filtered: the logged torques
and currents are scored as logged, and the per-move energies and the rest detection
use the logged speeds (measured and predicted energy alike).

Scores (:class:`Evaluation`):

* per joint R² of torque (where ``tau{k}`` is logged) and of current (where ``i{k}``
  is logged and ``k`` is known); a score that cannot be computed says what to provide;
* per move: the thesis energy ``Σ |tau qd| dt`` of the measured torque (the logged
  torque, or ``k·i`` for a log of currents only) against the predicted one;
* at rest (every joint slower than :data:`joulepath.data._features.REST_SPEED` for at
  least :attr:`EvaluateConfig.min_rest_samples` samples): the mean holding torque and
  current of each pose, measured and predicted. A joint at rest can hold anywhere
  within its static friction, so a pose is counted as predicted when the error is
  within :attr:`EvaluateConfig.hold_rel` of the measured value or an absolute
  tolerance (:attr:`EvaluateConfig.hold_abs_current_A`, ``hold_abs_torque_Nm``).

Drive gains (the small interface this module reads): a TOML file with one joint-side
torque constant per joint, the key the drives file of :mod:`joulepath.energy` uses::

    torque_constant = [45.0, 45.0, 45.0, 27.0, 27.0, 22.5]   # N·m/A, joint side
    [sources]
    torque_constant = "datasheet ..."                         # optional; else "assumed"

found beside the robot's description (``ur5.urdf`` -> ``ur5.drives.toml``), as
``drives.toml`` in a twin folder, or given explicitly. Other keys of a drives file are
ignored here. Reading it never executes code.
"""

from __future__ import annotations

import io
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._io import atomic_write_bytes, finite_json, make_folder
from joulepath._typing import FloatArray
from joulepath.data import REST_SPEED, find_gaps, log_in_joints, read_log, segment_moves
from joulepath.dynamics import Robot
from joulepath.energy import DRIVES_SUFFIX, TWIN_DRIVES_FILE, joint_energy, read_drives_toml
from joulepath.errors import InvalidInput
from joulepath.identify._data import (
    MotionDerivation,
    SpeedCutoff,
    check_speed_cutoff,
    motion_record,
    stretch_motion,
)
from joulepath.identify._fit import gear_side_speed, r2_per_joint

MOVE_COLUMNS = ("move", "t_start", "t_end", "energy_measured_J", "energy_predicted_J", "error_pct")
"""Columns of ``moves.csv``."""

EVALUATE_FILES = (
    "evaluate.json",
    "predictions.csv",
    "moves.csv",
    "holding.csv",
    "fit.png",
    "energy.png",
)
"""What :func:`write_evaluation` writes into its folder."""


@dataclass(frozen=True, slots=True, kw_only=True)
class DriveGains:
    """Joint-side torque constants of a robot's drives.

    Attributes
    ----------
    torque_constant : tuple of float
        ``k`` per joint, N·m/A: joint torque per ampere of motor current, so ``i = tau / k``.
    origin : str
        The file read.
    source : str
        Where the values come from (the file's ``[sources] torque_constant``), or ``"assumed"``.
    """

    torque_constant: tuple[float, ...]
    origin: str
    source: str = "assumed"

    def to_json(self) -> dict[str, Any]:
        return {
            "torque_constant_Nm_per_A": list(self.torque_constant),
            "file": self.origin,
            "source": self.source,
        }


def drives_path(robot_source: str | os.PathLike[str], robot: Robot) -> Path:
    """Where a robot's drive data would be: a twin folder's ``drives.toml``, or ``<stem>.drives.toml``.

    ``robot_source`` is what the robot was loaded from (a twin folder, a file, a name);
    for a name the description file the robot was read from (:attr:`Robot.source`) is used.
    """
    given = Path(robot_source)
    if given.is_dir():
        return given / TWIN_DRIVES_FILE
    described = Path(robot.source) if robot.source else given
    return described.with_name(described.stem + DRIVES_SUFFIX)


def read_drive_gains(path: str | os.PathLike[str], n_joints: int) -> DriveGains:
    """Read the joint-side torque constants of a drives file (TOML; see the module docstring).

    Raises
    ------
    InvalidInput
        The file cannot be read, is not TOML, is too large, or its ``torque_constant``
        is not ``n_joints`` positive finite numbers.
    """
    p = Path(path)
    data = read_drives_toml(p)
    k = data.get("torque_constant")
    fix = f"give torque_constant = [...] with {n_joints} numbers > 0 (N·m/A, joint side)"
    if k is None:
        raise InvalidInput(f"{p}: no torque_constant; {fix}")
    if (
        not isinstance(k, list)
        or len(k) != n_joints
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in k)
        or not all(math.isfinite(v) and v > 0 for v in k)
    ):
        raise InvalidInput(f"{p}: torque_constant is {k!r}; {fix}")
    sources = data.get("sources", {})
    source = sources.get("torque_constant") if isinstance(sources, dict) else None
    return DriveGains(
        torque_constant=tuple(float(v) for v in k),
        origin=str(p),
        source=source if isinstance(source, str) and source else "assumed",
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class EvaluateConfig:
    """Settings of :func:`evaluate_model`.

    Attributes
    ----------
    min_rest_samples : int
        Fewest consecutive samples at rest that make a holding pose.
    hold_rel : float
        A pose's holding torque or current is predicted when its error is within this
        share of the measured value ...
    hold_abs_current_A : float
        ... or within this many amperes ...
    hold_abs_torque_Nm : float
        ... or (torques) within this many N·m.
    speed_cutoff_hz : float, "auto" or None
        How the motion that predicts is derived from the log, as in
        :func:`joulepath.identify.data_from_logs`: None raw, a cutoff in Hz to low-pass the
        logged speeds before their differentiation, ``"auto"`` by the sample rate. A twin
        is best scored with the cutoff it was identified with (its card's ``motion``,
        :func:`twin_speed_cutoff`).
    """

    min_rest_samples: int = 5
    hold_rel: float = 0.15
    hold_abs_current_A: float = 0.3
    hold_abs_torque_Nm: float = 1.0
    speed_cutoff_hz: SpeedCutoff = None

    def __post_init__(self) -> None:
        check_speed_cutoff(self.speed_cutoff_hz)
        if self.min_rest_samples < 1:
            raise InvalidInput(f"min_rest_samples must be at least 1, got {self.min_rest_samples}")
        for key in ("hold_rel", "hold_abs_current_A", "hold_abs_torque_Nm"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value >= 0):
                raise InvalidInput(f"{key} must be a finite number ≥ 0, got {value}")


@dataclass(frozen=True, slots=True, eq=False)
class Evaluation:
    """A model scored on a log (see the module docstring).

    Attributes
    ----------
    log, robot, robot_source : str
        The log file, the robot's name and what it was loaded from.
    drives : DriveGains or None
        The torque constants used for currents; None when none were found.
    t : ndarray of shape (N,)
    tau_measured, i_measured : ndarray of shape (N, n) or None
        As logged (None: not logged).
    tau_predicted : ndarray of shape (N, n)
    i_predicted : ndarray of shape (N, n) or None
        None without drive gains.
    torque_r2, current_r2 : tuple of float or None
        Per joint; None when it cannot be computed (``notes`` says why).
    move_id : ndarray of int, shape (N,)
        The move each sample belongs to, -1 between moves.
    energy_from : str
        What the measured energy is computed from: ``"tau"`` (logged torque),
        ``"k*i"`` (currents times the torque constants) or ``""`` (not computable).
    moves : list of dict
        Per move: ``move``, ``t_start``, ``t_end``, ``energy_measured_J``,
        ``energy_predicted_J``, ``error_pct``.
    poses : list of dict
        Per holding pose: ``pose``, ``t_start``, ``t_end``, ``n_samples``, and per joint
        ``tau{k}_measured``/``_predicted`` and ``i{k}_measured``/``_predicted`` (means).
    config : EvaluateConfig
    notes : tuple of str
        What could not be scored and what to provide for it.
    motion : MotionDerivation or None
        How the predicting motion was derived from the log (raw or low-passed).
    """

    log: str
    robot: str
    robot_source: str
    drives: DriveGains | None
    t: FloatArray
    tau_measured: FloatArray | None
    tau_predicted: FloatArray
    i_measured: FloatArray | None
    i_predicted: FloatArray | None
    torque_r2: tuple[float, ...] | None
    current_r2: tuple[float, ...] | None
    move_id: np.ndarray
    energy_from: str
    moves: list[dict[str, float]]
    poses: list[dict[str, float]]
    config: EvaluateConfig
    notes: tuple[str, ...]
    motion: MotionDerivation | None = None

    @property
    def n_joints(self) -> int:
        return int(self.tau_predicted.shape[1])

    def holding_summary(self, signal: str) -> dict[str, Any] | None:
        """Per joint over the poses: median |error| and the share of poses predicted (``"tau"``/``"i"``)."""
        n = self.n_joints
        keys = [(f"{signal}{k}_measured", f"{signal}{k}_predicted") for k in range(1, n + 1)]
        if not self.poses or keys[0][0] not in self.poses[0] or keys[0][1] not in self.poses[0]:
            return None
        tol = self.config.hold_abs_current_A if signal == "i" else self.config.hold_abs_torque_Nm
        errors, shares = [], []
        for m_key, p_key in keys:
            meas = np.array([p[m_key] for p in self.poses])
            pred = np.array([p[p_key] for p in self.poses])
            err = np.abs(pred - meas)
            errors.append(float(np.median(err)))
            shares.append(float(np.mean(err <= np.maximum(self.config.hold_rel * np.abs(meas), tol))))
        unit = "A" if signal == "i" else "N·m"
        return {
            f"median_abs_error_{'A' if signal == 'i' else 'Nm'}": errors,
            "share_of_poses_predicted": shares,
            "criterion": f"|error| ≤ max({self.config.hold_rel:g} |measured|, {tol:g} {unit})",
        }

    def summary(self) -> dict[str, Any]:
        """The JSON summary (``evaluate.json``); non-finite numbers become null."""
        errors = np.array([m["error_pct"] for m in self.moves])
        measured = sum(m["energy_measured_J"] for m in self.moves)
        predicted = sum(m["energy_predicted_J"] for m in self.moves)
        out: dict[str, Any] = finite_json(
            {
                "log": self.log,
                "robot": self.robot,
                "robot_source": self.robot_source,
                "n_samples": int(self.t.size),
                "n_joints": self.n_joints,
                "drives": None if self.drives is None else self.drives.to_json(),
                "torque": None
                if self.torque_r2 is None
                else {"r2": list(self.torque_r2), "r2_mean": float(np.mean(self.torque_r2))},
                "current": None
                if self.current_r2 is None
                else {"r2": list(self.current_r2), "r2_mean": float(np.mean(self.current_r2))},
                "energy": None
                if not self.energy_from
                else {
                    "measure": "thesis: sum over joints of |tau qd| dt",
                    "measured_from": self.energy_from,
                    "n_moves": len(self.moves),
                    "median_error_pct": float(np.median(errors)) if errors.size else None,
                    "p95_error_pct": float(np.percentile(errors, 95)) if errors.size else None,
                    "total_measured_J": measured,
                    "total_predicted_J": predicted,
                    "total_error_pct": 100.0 * abs(predicted - measured) / measured if measured > 0 else None,
                },
                "holding": {
                    "n_poses": len(self.poses),
                    "torque": self.holding_summary("tau"),
                    "current": self.holding_summary("i"),
                },
                "config": {
                    "min_rest_samples": self.config.min_rest_samples,
                    "hold_rel": self.config.hold_rel,
                    "hold_abs_current_A": self.config.hold_abs_current_A,
                    "hold_abs_torque_Nm": self.config.hold_abs_torque_Nm,
                    "speed_cutoff_hz": self.config.speed_cutoff_hz,
                },
                "motion": None if self.motion is None else self.motion.to_json(),
                "notes": list(self.notes),
            }
        )
        return out


@dataclass(frozen=True, slots=True, eq=False)
class _Samples:
    """``q``, ``qd``, ``qdd``: the motion that predicts (raw or filtered); ``qd_logged``: as logged."""

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    qd_logged: FloatArray
    dt: FloatArray
    tau: FloatArray | None
    current: FloatArray | None
    stretch: np.ndarray
    move: np.ndarray
    motion: MotionDerivation


def _samples(
    path: str | os.PathLike[str], robot: Robot, speed_cutoff_hz: SpeedCutoff = None
) -> tuple[str, _Samples]:
    """The log's samples with accelerations, stretch and move labels (ends of stretches dropped
    when the accelerations are differentiated); the motion derived as ``speed_cutoff_hz`` says."""
    from joulepath.data import check_limits as _check_limits  # the ingest check: ranges and speeds, named

    log = log_in_joints(read_log(path), robot)
    if log.q.shape[1] != robot.n_joints:
        raise InvalidInput(
            f"{log.source}: the log has {log.q.shape[1]} joints but robot {robot.name!r} has "
            f"{robot.n_joints}; give the robot that was logged (--robot)"
        )
    _check_limits(log, robot)
    t = log.t
    bounds = np.r_[0, find_gaps(t), t.size]
    record = motion_record(
        t, bounds, log.q, log.qd, speed_cutoff_hz, has_qdd=log.qdd is not None, source=log.source
    )
    rows: list[np.ndarray] = []
    q_parts: list[FloatArray] = []
    qd_parts: list[FloatArray] = []
    qdd_parts: list[FloatArray] = []
    dt_parts: list[FloatArray] = []
    stretch: list[np.ndarray] = []
    moves: list[np.ndarray] = []
    n_moves = 0
    for s, (a, b) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
        if b - a < 3:
            continue
        sl = slice(a, b)
        tt = t[sl]
        inner, q, qd, qdd = stretch_motion(
            tt, log.q[sl], log.qd[sl], None if log.qdd is None else log.qdd[sl], record.cutoff_hz[0]
        )
        keep = inner + a
        dt = np.r_[np.diff(tt), np.diff(tt)[-1:]]
        if log.move is not None:
            _, labels = np.unique(log.move[sl], return_inverse=True)
            labels = labels.reshape(-1)
        else:
            labels = segment_moves(tt, log.qd[sl], speed_scale=robot.velocity_limit)
        rows.append(keep)
        q_parts.append(q)
        qd_parts.append(qd)
        qdd_parts.append(qdd)
        dt_parts.append(dt[inner])
        stretch.append(np.full(keep.size, s, dtype=np.int64))
        moves.append(np.where(labels[inner] >= 0, labels[inner] + n_moves, -1))
        n_moves += int(labels.max()) + 1 if labels.size and labels.max() >= 0 else 0
    if not rows:
        raise InvalidInput(f"{log.source}: no stretch of 3 or more samples between gaps; nothing to evaluate")
    idx = np.concatenate(rows)
    return log.source, _Samples(
        t=t[idx],
        q=np.concatenate(q_parts),
        qd=np.concatenate(qd_parts),
        qdd=np.concatenate(qdd_parts),
        qd_logged=log.qd[idx],
        dt=np.concatenate(dt_parts),
        tau=None if log.tau is None else log.tau[idx],
        current=None if log.current is None else log.current[idx],
        stretch=np.concatenate(stretch),
        move=np.concatenate(moves).astype(np.int64),
        motion=record,
    )


def _rest_poses(s: _Samples, min_samples: int) -> list[np.ndarray]:
    """Index arrays of the runs of at least ``min_samples`` samples at rest, each within one stretch."""
    rest = np.abs(s.qd_logged).max(axis=1) <= REST_SPEED
    cut = np.r_[True, (s.stretch[1:] != s.stretch[:-1]) | (rest[1:] != rest[:-1])]
    runs = np.split(np.arange(rest.size), np.nonzero(cut)[0][1:])
    return [r for r in runs if rest[r[0]] and r.size >= min_samples]


def twin_speed_cutoff(robot_source: str | os.PathLike[str]) -> tuple[bool, SpeedCutoff]:
    """The speed cutoff a twin folder's card says it was identified with: ``(found, cutoff)``.

    ``found`` is False when ``robot_source`` is no folder with a ``card.json`` holding a
    ``motion`` entry (not a twin, or one written before the entry existed: identified raw).
    ``cutoff`` is ``"auto"`` when the twin asked for it (the same rule then gives the same
    20 Hz on any log fast enough), else the one cutoff applied (Hz), or None (raw).
    """
    from joulepath.dynamics import TWIN_CARD_FILE

    card_path = Path(robot_source) / TWIN_CARD_FILE
    if not card_path.is_file():
        return False, None
    try:
        motion = json.loads(card_path.read_text()).get("motion")
    except (OSError, ValueError, AttributeError):
        return False, None
    if not isinstance(motion, dict):
        return False, None
    if motion.get("requested") == "auto":
        return True, "auto"
    cuts = {c for c in motion.get("speed_cutoff_hz") or [None] if c is None or isinstance(c, int | float)}
    if len(cuts) != 1:
        return False, None
    cut = cuts.pop()
    return True, None if cut is None else check_speed_cutoff(float(cut))


def predict_torque(robot: Robot, q: FloatArray, qd: FloatArray, qdd: FloatArray) -> FloatArray:
    """Torque as the drives log it: rigid body plus the robot's friction, through a twin's gear losses.

    The side of the gear losses is decided by :func:`~joulepath.identify.gear_side_speed`
    (a logged speed within the rest speed is rest).
    """
    tau = robot.inverse_dynamics(q, qd, qdd, friction=robot.friction)
    if robot.calibration is not None:
        tau = robot.calibration.motor_torque(tau, gear_side_speed(qd))
    return tau


def evaluate_model(
    log: str | os.PathLike[str],
    robot: Robot,
    *,
    robot_source: str,
    drives: DriveGains | None = None,
    config: EvaluateConfig | None = None,
) -> Evaluation:
    """Score ``robot`` (and its drives' torque constants) on one joint log.

    Parameters
    ----------
    log : path
        A controller or generic log (generic logs may hold ``i{k}`` currents).
    robot : Robot
        The model; a twin's identified friction and gear losses are used.
    robot_source : str
        What ``robot`` was loaded from (reported).
    drives : DriveGains, optional
        Torque constants for currents (:func:`read_drive_gains`).
    config : EvaluateConfig, optional

    Raises
    ------
    InvalidLog
        The log cannot be read.
    InvalidInput
        Another joint count than the robot's, positions or speeds outside its
        ranges, drive gains of another joint count, or no stretch to evaluate.
    """
    cfg = config or EvaluateConfig()
    source, s = _samples(log, robot, cfg.speed_cutoff_hz)
    n = robot.n_joints
    if drives is not None and len(drives.torque_constant) != n:
        raise InvalidInput(
            f"{drives.origin}: {len(drives.torque_constant)} torque constants for the {n} joints of "
            f"{robot.name!r}; give one per joint"
        )
    notes: list[str] = []
    tau_pred = predict_torque(robot, s.q, s.qd, s.qdd)
    k = None if drives is None else np.asarray(drives.torque_constant)
    i_pred = None if k is None else tau_pred / k
    torque_r2 = None
    if s.tau is not None:
        torque_r2 = tuple(float(v) for v in r2_per_joint(s.tau, tau_pred))
    else:
        notes.append(f"torque R² not computable: the log has no torques tau1..tau{n}")
    current_r2 = None
    need_k = (
        "give the drives' joint-side torque constants (torque_constant = [...] N·m/A, one per joint) in "
        "a drives file beside the robot's description (<stem>.drives.toml, or drives.toml in a twin "
        "folder) or with --drives FILE"
    )
    if s.current is None:
        notes.append(f"current R² not computable: the log has no motor currents i1..i{n}")
    elif i_pred is None:
        notes.append(f"current R² not computable: no drive model; {need_k}")
    else:
        current_r2 = tuple(float(v) for v in r2_per_joint(s.current, i_pred))
    measured, energy_from = None, ""
    if s.tau is not None:
        measured, energy_from = s.tau, "tau"
    elif s.current is not None and k is not None:
        measured, energy_from = s.current * k, "k*i"
    else:
        notes.append(f"per-move energy not computable: no torques and no drive model; {need_k}")
    moves: list[dict[str, float]] = []
    if measured is not None:
        e_meas = joint_energy(measured, s.qd_logged, s.dt).sum(axis=1)
        e_pred = joint_energy(tau_pred, s.qd_logged, s.dt).sum(axis=1)
        for m in np.unique(s.move[s.move >= 0]):
            sel = s.move == m
            em, ep = float(e_meas[sel].sum()), float(e_pred[sel].sum())
            moves.append(
                {
                    "move": int(m),
                    "t_start": float(s.t[sel][0]),
                    "t_end": float(s.t[sel][-1]),
                    "energy_measured_J": em,
                    "energy_predicted_J": ep,
                    "error_pct": 100.0 * abs(ep - em) / em if em > 0 else float("nan"),
                }
            )
        if not moves:
            notes.append("no moves found in the log (the arm never sets off from rest)")
    poses: list[dict[str, float]] = []
    for p, r in enumerate(_rest_poses(s, cfg.min_rest_samples)):
        row: dict[str, float] = {
            "pose": p,
            "t_start": float(s.t[r[0]]),
            "t_end": float(s.t[r[-1]]),
            "n_samples": int(r.size),
        }
        for j in range(n):
            if s.tau is not None:
                row[f"tau{j + 1}_measured"] = float(s.tau[r, j].mean())
            row[f"tau{j + 1}_predicted"] = float(tau_pred[r, j].mean())
            if s.current is not None:
                row[f"i{j + 1}_measured"] = float(s.current[r, j].mean())
            if i_pred is not None:
                row[f"i{j + 1}_predicted"] = float(i_pred[r, j].mean())
        poses.append(row)
    return Evaluation(
        log=source,
        robot=robot.name,
        robot_source=robot_source,
        drives=drives,
        t=s.t,
        tau_measured=s.tau,
        tau_predicted=tau_pred,
        i_measured=s.current,
        i_predicted=i_pred,
        torque_r2=torque_r2,
        current_r2=current_r2,
        move_id=s.move,
        energy_from=energy_from,
        moves=moves,
        poses=poses,
        config=cfg,
        notes=tuple(notes),
        motion=s.motion,
    )


def predictions_frame(ev: Evaluation) -> Any:
    """Per sample: ``t``, then per joint ``tau{k}_measured``/``_predicted``, ``i{k}_...`` (where known)."""
    import pandas as pd

    cols: dict[str, FloatArray] = {"t": ev.t}
    for j in range(ev.n_joints):
        k = j + 1
        for name, arr in (
            (f"tau{k}_measured", ev.tau_measured),
            (f"tau{k}_predicted", ev.tau_predicted),
            (f"i{k}_measured", ev.i_measured),
            (f"i{k}_predicted", ev.i_predicted),
        ):
            if arr is not None:
                cols[name] = arr[:, j]
    return pd.DataFrame(cols)


def fit_figure(ev: Evaluation) -> Any:
    """Measured against predicted over time, one panel per joint (current where scored, else torque)."""
    from matplotlib.figure import Figure

    use_current = ev.i_measured is not None and ev.i_predicted is not None
    measured = ev.i_measured if use_current else ev.tau_measured
    predicted = ev.i_predicted if use_current else ev.tau_predicted
    r2 = ev.current_r2 if use_current else ev.torque_r2
    unit = "A" if use_current else "N·m"
    fig = Figure(figsize=(9, 1.6 * ev.n_joints + 0.6))
    axes = fig.subplots(ev.n_joints, 1, sharex=True, squeeze=False)[:, 0]
    for j, ax in enumerate(axes):
        if measured is not None:
            ax.plot(ev.t, measured[:, j], ".", ms=1.5, color="tab:gray", label="measured")
        if predicted is not None:
            ax.plot(ev.t, predicted[:, j], "-", lw=0.8, color="tab:blue", label="predicted")
        label = f"{'i' if use_current else 'tau'}{j + 1} ({unit})"
        if r2 is not None:
            label += f"\nR² {r2[j]:.3f}"
        ax.set_ylabel(label, fontsize=8)
    axes[0].legend(loc="upper right", fontsize=7)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(f"{ev.robot} on {Path(ev.log).name}")
    fig.tight_layout()
    return fig


def energy_figure(ev: Evaluation) -> Any:
    """Predicted against measured energy per move, with the identity line."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4.5, 4.2))
    ax = fig.subplots()
    if ev.moves:
        em = np.array([m["energy_measured_J"] for m in ev.moves])
        ep = np.array([m["energy_predicted_J"] for m in ev.moves])
        top = float(max(em.max(), ep.max(), 1e-9)) * 1.05
        ax.plot([0, top], [0, top], "-", color="tab:gray", lw=0.8)
        ax.plot(em, ep, "o", ms=3, color="tab:blue")
        ax.set_xlim(0, top)
        ax.set_ylim(0, top)
    else:
        ax.text(0.5, 0.5, "no per-move energy (see evaluate.json notes)", ha="center", transform=ax.transAxes)
    ax.set_xlabel(f"measured energy per move (J, from {ev.energy_from or '-'})")
    ax.set_ylabel("predicted energy per move (J)")
    fig.tight_layout()
    return fig


def _png(fig: Any) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return buf.getvalue()


def write_evaluation(ev: Evaluation, out: str | os.PathLike[str]) -> dict[str, Path]:
    """Write :data:`EVALUATE_FILES` into ``out``; every file is rendered before the first is written."""
    import pandas as pd

    contents: dict[str, bytes] = {
        "evaluate.json": (json.dumps(ev.summary(), indent=2, allow_nan=False) + "\n").encode(),
        "predictions.csv": predictions_frame(ev).to_csv(index=False, float_format="%.6g").encode(),
        "moves.csv": pd.DataFrame(ev.moves, columns=list(MOVE_COLUMNS)).to_csv(index=False).encode(),
        "holding.csv": (
            pd.DataFrame(ev.poses)
            if ev.poses
            else pd.DataFrame(columns=["pose", "t_start", "t_end", "n_samples"])
        )
        .to_csv(index=False)
        .encode(),
        "fit.png": _png(fit_figure(ev)),
        "energy.png": _png(energy_figure(ev)),
    }
    folder = make_folder(out)
    return {name: atomic_write_bytes(folder / name, data) for name, data in contents.items()}


__all__ = [
    "DRIVES_SUFFIX",
    "DriveGains",
    "EVALUATE_FILES",
    "EvaluateConfig",
    "Evaluation",
    "TWIN_DRIVES_FILE",
    "drives_path",
    "energy_figure",
    "evaluate_model",
    "fit_figure",
    "predict_torque",
    "predictions_frame",
    "read_drive_gains",
    "twin_speed_cutoff",
    "write_evaluation",
]
