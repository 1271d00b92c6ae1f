"""Descriptive statistics and distribution overlays of several energy tables (thesis Figs 4.3-4.10)."""

from __future__ import annotations

import io
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from joulepath._io import atomic_write_bytes, make_folder
from joulepath._typing import FloatArray
from joulepath.data import EnergyTable
from joulepath.errors import InvalidInput

if TYPE_CHECKING:
    from joulepath.dynamics import Robot

STATISTICS_FILE = "statistics.csv"
"""What :meth:`Comparison.write` names the descriptive statistics."""

SCORES_FILE = "scores.csv"
"""What :meth:`Comparison.write` names the quality and kinematic-consistency scores."""

FEATURE_GROUPS: dict[str, tuple[str, ...]] = {
    "joint_positions": tuple(f"q{i}" for i in range(1, 7)),
    "joint_speeds": tuple(f"dq{i}" for i in range(1, 7)),
    "joint_accelerations": tuple(f"ddq{i}" for i in range(1, 7)),
    "tcp_position": ("x", "y", "z"),
    "tcp_derivatives": ("dx", "dy", "dz", "ddx", "ddy", "ddz"),
    "orientation": ("qw", "qx", "qy", "qz", "yaw", "pitch", "roll"),
    "orientation_derivatives": ("dphi", "dtheta", "dpsi", "ddphi", "ddtheta", "ddpsi"),
    "energies": ("E1", "E2", "E3", "E4", "E5", "E6", "E"),
}
"""Column groups of the distribution plots, one figure each (the content of thesis Figs 4.3-4.10)."""

STATISTICS: tuple[str, ...] = (
    "mean",
    "median",
    "mode",
    "variance",
    "std",
    "range",
    "skewness",
    "kurtosis",
)
"""Statistics of :func:`describe`, in column order."""

MODE_BINS = 100
"""Bins of the histogram whose fullest bin gives the mode (see :func:`describe`)."""

_UNITS = {"q": "rad", "dq": "rad/s", "ddq": "rad/s²", "E": "J"}
_TCP_UNITS = {
    **{c: "m" for c in ("x", "y", "z")},
    **{c: "m/s" for c in ("dx", "dy", "dz")},
    **{c: "m/s²" for c in ("ddx", "ddy", "ddz")},
    **{c: "rad" for c in ("yaw", "pitch", "roll")},
    **{c: "rad/s" for c in ("dphi", "dtheta", "dpsi")},
    **{c: "rad/s²" for c in ("ddphi", "ddtheta", "ddpsi")},
    **{c: "" for c in ("qw", "qx", "qy", "qz")},
    "dt": "s",
    "t": "s",
}


def _unit(column: str) -> str:
    if column in _TCP_UNITS:
        return _TCP_UNITS[column]
    prefix = column.rstrip("0123456789")
    return _UNITS.get(prefix, "")


def _check_tables(tables: Mapping[str, EnergyTable], *, where: str) -> list[str]:
    """The columns the tables share (first table's order, without move_id and t)."""
    if not isinstance(tables, Mapping) or not tables:
        raise InvalidInput(f"{where} expects a non-empty mapping of names to EnergyTables")
    for name, table in tables.items():
        if not isinstance(table, EnergyTable):
            raise InvalidInput(f"{where}: {name!r} is a {type(table).__name__}, expected an EnergyTable")
        if len(table.frame) == 0:
            raise InvalidInput(f"{where}: table {name!r} has no rows")
    first = next(iter(tables.values()))
    shared = [c for c in first.frame.columns if c not in ("move_id", "t")]
    for table in tables.values():
        shared = [c for c in shared if c in table.frame.columns]
    if not shared:
        raise InvalidInput(f"{where}: the tables share no data columns")
    return shared


def histogram_mode(values: FloatArray, *, bins: int = MODE_BINS) -> float:
    """Centre of the fullest of ``bins`` equal bins between the 1st and 99th percentiles.

    Examples
    --------
    >>> histogram_mode(np.array([0.0, 1.0, 1.0, 1.0, 2.0]), bins=4)  # bins of 0.48 from 0.04
    1.24
    """
    x = values[np.isfinite(values)]
    if x.size == 0:
        return float("nan")
    lo, hi = np.percentile(x, [1.0, 99.0])
    if not hi - lo > bins * 4 * np.finfo(float).eps * max(abs(lo), abs(hi)):  # no room for the bins
        return float(np.median(x))
    counts, edges = np.histogram(x, bins=bins, range=(lo, hi))
    k = int(np.argmax(counts))
    return float((edges[k] + edges[k + 1]) / 2)


def describe(tables: Mapping[str, EnergyTable], *, columns: Sequence[str] | None = None) -> pd.DataFrame:
    """Per-column descriptive statistics of each named table.

    Parameters
    ----------
    tables : mapping of str to EnergyTable
        E.g. ``{"real": real, "sim": sim, "tvae": synthetic}``.
    columns : sequence of str, optional
        Default: all columns the tables share except ``move_id`` and ``t``.

    Returns
    -------
    DataFrame
        Index ``(column, table)``; columns :data:`STATISTICS`: mean, median, mode,
        variance and std (``ddof=1``), range (max - min), skewness and excess
        kurtosis (pandas' bias-corrected estimators). The mode of continuous data
        is estimated as the centre of the fullest of 100 histogram bins between
        the 1st and 99th percentiles (:func:`histogram_mode`).

    Raises
    ------
    InvalidInput
        An empty mapping, a value that is not an EnergyTable, an empty table, or
        a requested column that a table lacks.
    """
    shared = _check_tables(tables, where="describe")
    if columns is None:
        cols = shared
    else:
        cols = list(dict.fromkeys(columns))
        missing = [c for c in cols if c not in shared]
        if missing:
            raise InvalidInput(f"describe: not every table has column(s) {', '.join(missing)}")
    rows = []
    index = []
    for col in cols:
        for name, table in tables.items():
            s = table.frame[col].astype("float64")
            rows.append(
                (
                    s.mean(),
                    s.median(),
                    histogram_mode(s.to_numpy()),
                    s.var(),
                    s.std(),
                    s.max() - s.min(),
                    s.skew(),
                    s.kurt(),
                )
            )
            index.append((col, name))
    return pd.DataFrame(
        rows,
        index=pd.MultiIndex.from_tuples(index, names=["column", "table"]),
        columns=list(STATISTICS),
        dtype="float64",
    )


def plot_distributions(
    tables: Mapping[str, EnergyTable],
    out_dir: str | os.PathLike[str],
    *,
    bins: int = 60,
    groups: Mapping[str, Sequence[str]] | None = None,
) -> list[Path]:
    """Overlay the distributions of the tables, one PNG per feature group.

    Each panel shows one column as a density histogram (outline) per table, on
    bins shared by all tables between the pooled 0.5th and 99.5th percentiles
    (so that rare extremes do not squeeze the bulk into one bin).

    Parameters
    ----------
    tables : mapping of str to EnergyTable
    out_dir : path
        Folder for ``<group>.png`` (created if missing).
    bins : int
        Bins per panel.
    groups : mapping of str to column names, optional
        Default :data:`FEATURE_GROUPS`; groups whose columns the tables lack are skipped.

    Returns
    -------
    list of Path
        The files written, in group order.

    Raises
    ------
    InvalidInput
        As :func:`describe`, or ``bins < 2``.
    """
    from matplotlib.figure import Figure

    shared = set(_check_tables(tables, where="plot_distributions"))
    if not isinstance(bins, int) or bins < 2:
        raise InvalidInput(f"bins must be an integer >= 2, got {bins!r}")
    out = Path(out_dir)
    make_folder(out)
    written = []
    for group, wanted in (groups or FEATURE_GROUPS).items():
        cols = [c for c in wanted if c in shared]
        if not cols:
            continue
        ncols = min(3, len(cols))
        nrows = -(-len(cols) // ncols)
        fig = Figure(figsize=(4.2 * ncols, 3.0 * nrows), layout="constrained")
        axes = fig.subplots(nrows, ncols, squeeze=False)
        for ax, col in zip(axes.flat, cols, strict=False):
            data = {name: t.frame[col].to_numpy(dtype=float) for name, t in tables.items()}
            pooled = np.concatenate([v[np.isfinite(v)] for v in data.values()])
            lo, hi = np.percentile(pooled, [0.5, 99.5]) if pooled.size else (0.0, 1.0)
            if not hi > lo:
                lo, hi = lo - 0.5, hi + 0.5
            edges = np.linspace(lo, hi, bins + 1)
            for name, values in data.items():
                ax.hist(values[np.isfinite(values)], bins=edges, density=True, histtype="step", label=name)
            unit = _unit(col)
            ax.set_xlabel(f"{col} ({unit})" if unit else col)
            ax.set_ylabel("density")
        for ax in list(axes.flat)[len(cols) :]:
            ax.set_visible(False)
        axes.flat[0].legend(fontsize="small")
        fig.suptitle(group.replace("_", " "))
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=100)
        written.append(atomic_write_bytes(out / f"{group}.png", buf.getvalue()))
    return written


@dataclass(frozen=True, slots=True)
class Comparison:
    """What :func:`compare` found.

    Attributes
    ----------
    statistics : DataFrame
        :func:`describe` of all tables.
    plots : tuple of Path
        The PNG files of :func:`plot_distributions`.
    quality : dict
        Table name -> :func:`quality_report` scores against the first table (empty unless asked).
    consistency : dict
        Table name -> share of rows within 5 mm of FK(q) (empty unless a robot was given).
    """

    statistics: pd.DataFrame
    plots: tuple[Path, ...]
    quality: dict[str, dict[str, float]] = field(default_factory=dict)
    consistency: dict[str, float] = field(default_factory=dict)

    def scores(self) -> pd.DataFrame:
        """Quality and consistency per table (columns as available); empty when neither was asked."""
        rows: dict[str, dict[str, float]] = {}
        for name, q in self.quality.items():
            rows.setdefault(name, {}).update({k: float(v) for k, v in q.items()})
        for name, share in self.consistency.items():
            rows.setdefault(name, {})["tcp_within_5mm"] = float(share)
        frame = pd.DataFrame.from_dict(rows, orient="index")
        frame.index.name = "table"
        return frame

    def write(self, out_dir: str | os.PathLike[str]) -> tuple[Path, ...]:
        """Write ``statistics.csv`` (index column, table) and, if any, ``scores.csv`` into ``out_dir``."""
        out = Path(out_dir)
        written = [atomic_write_bytes(out / STATISTICS_FILE, self.statistics.to_csv().encode())]
        scores = self.scores()
        if len(scores):
            written.append(atomic_write_bytes(out / SCORES_FILE, scores.to_csv().encode()))
        return tuple(written)

    def to_text(self) -> str:
        """The statistics table, scores and files as plain text for a terminal."""
        with pd.option_context("display.max_rows", None, "display.width", 200):
            lines = [self.statistics.to_string(float_format=lambda v: f"{v:.5g}")]
        if self.quality:
            lines += ["", "quality against the first table (SDMetrics):"]
            for name, q in self.quality.items():
                lines.append(
                    f"  {name}: column shapes {q['column_shapes']:.3f}, column pair trends "
                    f"{q['column_pair_trends']:.3f}, overall {q['overall']:.3f}"
                )
        if self.consistency:
            lines += ["", "rows whose TCP position is within 5 mm of FK(q):"]
            lines += [f"  {name}: {share:.1%}" for name, share in self.consistency.items()]
        if self.plots:
            lines += ["", f"wrote {len(self.plots)} plots:"]
            lines += [f"  {p}" for p in self.plots]
        return "\n".join(lines)


def compare(
    tables: Mapping[str, EnergyTable],
    *,
    out_dir: str | os.PathLike[str] | None = None,
    quality: bool = False,
    robot: Robot | str | None = None,
) -> Comparison:
    """Statistics, plots and optionally quality and kinematic consistency of several tables.

    Only the plots are written here; :meth:`Comparison.write` writes the
    statistics (and scores) as CSV, as ``joulepath compare`` does.

    Parameters
    ----------
    tables : mapping of str to EnergyTable
        The first table is the reference for ``quality``.
    out_dir : path, optional
        Where to write the distribution plots; None writes none.
    quality : bool
        Score every other table against the first with :func:`quality_report`.
    robot : Robot or str, optional
        Report each ``full40`` table's share of rows whose TCP position is within
        5 mm of this robot's FK(q).

    Returns
    -------
    Comparison

    Raises
    ------
    InvalidInput
        As :func:`describe` and :func:`quality_report`.
    """
    stats = describe(tables)
    plots = tuple(plot_distributions(tables, out_dir)) if out_dir is not None else ()
    scores: dict[str, dict[str, float]] = {}
    if quality:
        from joulepath.synth._quality import quality_report

        names = list(tables)
        for name in names[1:]:
            scores[name] = quality_report(tables[names[0]], tables[name])
    shares: dict[str, float] = {}
    if robot is not None:
        from joulepath.synth._kinematics import kinematic_consistency, resolve_robot

        r = resolve_robot(robot)
        shares = {
            name: kinematic_consistency(t, r) for name, t in tables.items() if t.feature_set == "full40"
        }
    return Comparison(statistics=stats, plots=plots, quality=scores, consistency=shares)


__all__ = [
    "FEATURE_GROUPS",
    "SCORES_FILE",
    "STATISTICS",
    "STATISTICS_FILE",
    "Comparison",
    "compare",
    "describe",
    "histogram_mode",
    "plot_distributions",
]
