"""What ran: the default and the optimized move's repetitions in a log, their energies and the saving."""

from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from joulepath._io import atomic_write_text, finite_json, make_folder
from joulepath._typing import FloatArray
from joulepath.data import JointLog, read_log
from joulepath.energy import joint_power, total_energy
from joulepath.errors import InvalidInput
from joulepath.measure._plan import Plan, read_plan
from joulepath.measure._segment import Window, find_moves, path_distance, tracking_error

MEASURE_FILES = ("measure.json", "power.png")
"""What :func:`write_measure` writes in its folder."""
SAVING_METHOD = (
    "delta method on the ratio of mean energies R = mean(optimized) / mean(default) (the two sets "
    "independent), saving = 1 - R; 95 % interval R +- t(0.975, n_default + n_optimized - 2) * SE(R)"
)
ENERGY_DEFINITION = (
    "sum over joints and samples of |tau_i * qd_i| * dt (joulepath.energy.total_energy, mode absolute) "
    "with the log's torques and speeds, dt the time to the next sample, from the last sample at rest at "
    "START to the first at rest at GOAL"
)
SHAPE_MARGIN = 2.0
"""A move is told default or optimized by its path when one planned path is this many times closer."""
DURATION_TOL = 0.05
"""A kind whose mean executed duration is off its planned one by more than this share gets a note."""
MATCH_TOL_DEG = 3.0
"""A move whose path is farther than this (mean, deg) from both planned paths is not a move of the plan."""


@dataclass(frozen=True, slots=True)
class Repetition:
    """One run of the default or the optimized move in the log (times in s from the log's start)."""

    index: int
    kind: str
    t_start_s: float
    t_end_s: float
    duration_s: float
    energy_J: float
    path_distance_default_deg: float
    path_distance_optimized_deg: float
    tracking_error_max_deg: float | None
    tracking_error_rms_deg: float | None


@dataclass(frozen=True, slots=True)
class KindSummary:
    """The repetitions of one kind: count, energy mean and sample standard deviation, durations."""

    n: int
    energy_mean_J: float
    energy_sd_J: float
    duration_mean_s: float
    duration_min_s: float
    duration_max_s: float
    executed_over_planned: float


@dataclass(frozen=True, slots=True)
class Saving:
    """The realized saving ``100 (1 - mean E_opt / mean E_def)`` % and its 95 % interval."""

    pct: float
    ci95_low_pct: float
    ci95_high_pct: float
    method: str


@dataclass(frozen=True, slots=True)
class Measurement:
    """``measure.json``: what ran, against what was planned."""

    log: str
    plan: str
    robot: str
    planned_duration_s: float
    sample_period_s: float
    classified_by: str
    order_as_path_mod: bool
    energy_definition: str
    repetitions: tuple[Repetition, ...]
    default: KindSummary
    optimized: KindSummary
    saving: Saving
    planned: dict[str, float | None]
    notes: tuple[str, ...] = ()

    def to_json(self) -> dict[str, Any]:
        """Plain JSON types; non-finite numbers become ``null``."""
        out: dict[str, Any] = finite_json(asdict(self))
        return out


def _energy(log: JointLog, w: Window) -> float:
    sl = slice(w.first, w.last)
    dt = np.diff(log.t[w.first : w.last + 1])
    return float(total_energy(log.torques("measuring")[sl], log.qd[sl], dt).sum())


def _classify(
    log: JointLog, windows: list[Window], plan: Plan
) -> tuple[list[str], list[tuple[float, float]], str]:
    dist = [
        (
            path_distance(log.q[w.first : w.last + 1], plan.default),
            path_distance(log.q[w.first : w.last + 1], plan.optimized),
        )
        for w in windows
    ]
    tol = np.radians(MATCH_TOL_DEG)
    for k, (w, (dd, do)) in enumerate(zip(windows, dist, strict=True)):
        if min(dd, do) > tol:
            raise InvalidInput(
                f"{log.source}: move {k + 1} from START to GOAL (t = {log.t[w.first]:.2f} s) follows "
                f"neither planned path (mean {np.degrees(dd):.1f} deg from default_path.csv, "
                f"{np.degrees(do):.1f} deg from path.csv); is this the log of this plan?"
            )
    separable = all(max(dd, do) >= SHAPE_MARGIN * min(dd, do) for dd, do in dist)
    half = len(windows) // 2
    by_order = ["default" if k < half else "optimized" for k in range(len(windows))]
    if not separable:
        return by_order, dist, "order"
    return ["default" if dd < do else "optimized" for dd, do in dist], dist, "shape"


def _summary(reps: list[Repetition], planned: float) -> KindSummary:
    e = np.array([r.energy_J for r in reps])
    d = np.array([r.duration_s for r in reps])
    return KindSummary(
        n=len(reps),
        energy_mean_J=float(e.mean()),
        energy_sd_J=float(e.std(ddof=1)),
        duration_mean_s=float(d.mean()),
        duration_min_s=float(d.min()),
        duration_max_s=float(d.max()),
        executed_over_planned=float(d.mean() / planned),
    )


def saving_interval(e_default: FloatArray, e_optimized: FloatArray) -> Saving:
    """The saving ``1 - mean(e_optimized) / mean(e_default)`` in % with its 95 % interval (delta method).

    Examples
    --------
    >>> s = saving_interval(np.array([10.0, 10.2, 9.8]), np.array([8.0, 8.1, 7.9]))
    >>> round(s.pct, 1), s.ci95_low_pct < s.pct < s.ci95_high_pct
    (20.0, True)
    """
    d = np.asarray(e_default, dtype=float)
    o = np.asarray(e_optimized, dtype=float)
    if d.size < 2 or o.size < 2:
        raise InvalidInput(
            f"an interval needs at least 2 repetitions of each move, got {d.size} and {o.size}"
        )
    md, mo = d.mean(), o.mean()
    if not md > 0:
        raise InvalidInput("the default move's mean energy is not positive; no saving can be measured")
    ratio = mo / md
    se = abs(ratio) * np.sqrt(o.var(ddof=1) / (o.size * mo * mo) + d.var(ddof=1) / (d.size * md * md))
    half = float(stats.t.ppf(0.975, d.size + o.size - 2)) * se
    return Saving(
        pct=float(100 * (1 - ratio)),
        ci95_low_pct=float(100 * (1 - ratio - half)),
        ci95_high_pct=float(100 * (1 - ratio + half)),
        method=SAVING_METHOD,
    )


@dataclass(frozen=True, slots=True, eq=False)
class MeasureRun:
    """A measurement and what its plot needs: the log and the repetitions' windows."""

    measurement: Measurement
    log: JointLog
    windows: tuple[Window, ...]


def measure_run(log: str | os.PathLike[str], plan: str | os.PathLike[str]) -> MeasureRun:
    """Measure the default and the optimized move in a log of ``path.mod`` against its run folder.

    Each move from rest at START to rest at GOAL is found from the joint positions and
    speeds; it is told default or optimized by its path (compared with
    ``default_path.csv`` and ``path.csv``, timing aside), or by the order ``path.mod``
    runs them (the first half default) when the two paths are too alike to tell.

    Parameters
    ----------
    log : path
        A controller log (or generic joint log) of a run of the run folder's ``path.mod``,
        measured or simulated (``joulepath simulate --program``).
    plan : path
        The run folder of ``joulepath optimize`` (``result.json``, ``path.csv``,
        ``default_path.csv``).

    Raises
    ------
    InvalidLog
        The log cannot be read.
    InvalidInput
        The log does not match the plan: another number of joints, no or too few moves
        from START to GOAL, a move that follows neither path, or not as many default as
        optimized moves.
    """
    the_plan = read_plan(plan)
    the_log = read_log(log)
    the_log.torques("measuring")  # a log of currents only is refused before the search
    source = the_log.source
    n = the_plan.start.size
    if the_log.q.shape[1] != n:
        raise InvalidInput(f"{source}: the log has {the_log.q.shape[1]} joints, the plan {n}; wrong plan?")
    windows = find_moves(the_log.t, the_log.q, the_log.qd, the_plan.start, the_plan.end)
    if len(windows) < 4:
        start_deg = np.round(np.degrees(the_plan.start), 2).tolist()
        goal_deg = np.round(np.degrees(the_plan.end), 2).tolist()
        raise InvalidInput(
            f"{source}: found {len(windows)} moves from rest at START {start_deg} deg to rest at GOAL "
            f"{goal_deg} deg; at least 2 default and 2 optimized are needed (a log of another plan, or cut "
            "short?)"
        )
    kinds, dist, how = _classify(the_log, windows, the_plan)
    n_def, n_opt = kinds.count("default"), kinds.count("optimized")
    if n_def != n_opt or n_def < 2:
        raise InvalidInput(
            f"{source}: {n_def} default and {n_opt} optimized moves from START to GOAL; path.mod runs as "
            "many of each (a log cut short, or of another program?)"
        )
    reps: list[Repetition] = []
    for k, (w, kind, (dd, do)) in enumerate(zip(windows, kinds, dist, strict=True)):
        t = the_log.t[w.first : w.last + 1]
        err = (
            tracking_error(t, the_log.q[w.first : w.last + 1], the_plan.optimized)
            if kind == "optimized"
            else None
        )
        reps.append(
            Repetition(
                index=k + 1,
                kind=kind,
                t_start_s=float(t[0]),
                t_end_s=float(t[-1]),
                duration_s=float(t[-1] - t[0]),
                energy_J=_energy(the_log, w),
                path_distance_default_deg=float(np.degrees(dd)),
                path_distance_optimized_deg=float(np.degrees(do)),
                tracking_error_max_deg=None if err is None else float(np.degrees(err[0])),
                tracking_error_rms_deg=None if err is None else float(np.degrees(err[1])),
            )
        )
    default = [r for r in reps if r.kind == "default"]
    optimized = [r for r in reps if r.kind == "optimized"]
    saving = saving_interval(
        np.array([r.energy_J for r in default]), np.array([r.energy_J for r in optimized])
    )
    half = len(reps) // 2
    summaries = {
        "default": _summary(default, the_plan.duration_s),
        "optimized": _summary(optimized, the_plan.duration_s),
    }
    notes = tuple(
        f"the {kind} move ran {k.duration_mean_s:.2f} s, {k.executed_over_planned:.2f} x its planned "
        f"{the_plan.duration_s:g} s: the saving is not at the planned cycle time"
        for kind, k in summaries.items()
        if abs(k.executed_over_planned - 1.0) > DURATION_TOL
    )
    measurement = Measurement(
        log=source,
        plan=str(the_plan.folder),
        robot=the_plan.robot,
        planned_duration_s=the_plan.duration_s,
        sample_period_s=float(np.median(np.diff(the_log.t))),
        classified_by=how,
        order_as_path_mod=all(r.kind == ("default" if r.index <= half else "optimized") for r in reps),
        energy_definition=ENERGY_DEFINITION,
        repetitions=tuple(reps),
        default=summaries["default"],
        optimized=summaries["optimized"],
        saving=saving,
        planned=the_plan.planned,
        notes=notes,
    )
    return MeasureRun(measurement, the_log, tuple(windows))


def power_figure(run: MeasureRun) -> Any:
    """Joint power ``Σ|τ·q̇|`` over time from each move's start, every repetition (default dashed)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 4))
    ax = fig.subplots()
    log = run.log
    for rep, w in zip(run.measurement.repetitions, run.windows, strict=True):
        t = log.t[w.first : w.last + 1]
        tau = log.torques("measuring")
        p = joint_power(tau[w.first : w.last + 1], log.qd[w.first : w.last + 1]).sum(axis=1)
        style = ("--", "tab:gray") if rep.kind == "default" else ("-", "tab:green")
        ax.plot(t - t[0], p, style[0], color=style[1], alpha=0.8, lw=1.0)
    ax.plot([], [], "--", color="tab:gray", label=f"default ({run.measurement.default.n})")
    ax.plot([], [], "-", color="tab:green", label=f"optimized ({run.measurement.optimized.n})")
    ax.axvline(run.measurement.planned_duration_s, color="k", lw=0.8, ls=":", label="planned duration")
    ax.set_xlabel("t from the move's start [s]")
    ax.set_ylabel("Σ |τ·q̇| [W]")
    s = run.measurement.saving
    ax.set_title(f"measured saving {s.pct:.1f} % (95 %: {s.ci95_low_pct:.1f} to {s.ci95_high_pct:.1f} %)")
    ax.legend()
    fig.tight_layout()
    return fig


def write_measure(run: MeasureRun, out: str | os.PathLike[str]) -> dict[str, Path]:
    """Write ``measure.json`` and ``power.png`` in ``out`` (each atomically)."""
    import io

    from joulepath._io import atomic_write_bytes

    folder = make_folder(out)
    buf = io.BytesIO()
    power_figure(run).savefig(buf, format="png", dpi=100)
    files = {"power.png": atomic_write_bytes(folder / "power.png", buf.getvalue())}
    text = json.dumps(run.measurement.to_json(), indent=2, allow_nan=False)
    files["measure.json"] = atomic_write_text(folder / "measure.json", text + "\n")
    return files
