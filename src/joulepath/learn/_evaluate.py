"""Accuracy of energy predictions: per row, per move (what the optimizer needs), and the physics baseline."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from sklearn.metrics import mean_absolute_error, r2_score

from joulepath._typing import FloatArray
from joulepath.data import EnergyTable
from joulepath.energy import joint_energy

N_JOINTS = 6


@dataclass(frozen=True, slots=True)
class Scores:
    """Row-level R² and MAE (J) and move-level relative errors of one predictor on one table."""

    r2: float
    mae: float
    path_median_pct: float
    path_p95_pct: float
    n_moves: int

    def as_dict(self) -> dict[str, float]:
        return {
            "r2": self.r2,
            "mae": self.mae,
            "path_median_pct": self.path_median_pct,
            "path_p95_pct": self.path_p95_pct,
            "n_moves": self.n_moves,
        }


def path_errors(moves: np.ndarray, measured: FloatArray, predicted: FloatArray) -> FloatArray:
    """Per move: |Σ predicted − Σ measured| / Σ measured (moves with no energy are skipped)."""
    frame = pd.DataFrame({"m": moves, "y": measured, "p": predicted}).groupby("m").sum()
    keep = frame["y"] > 1e-9
    return np.asarray((frame["p"] - frame["y"]).abs()[keep] / frame["y"][keep], dtype=float)


def score(table: EnergyTable, target: str, predicted: FloatArray) -> Scores:
    """Scores of ``predicted`` against ``table[target]``."""
    y = table.frame[target].to_numpy()
    err = path_errors(table.frame["move_id"].to_numpy(), y, predicted)
    return Scores(
        r2=float(r2_score(y, predicted)),
        mae=float(mean_absolute_error(y, predicted)),
        path_median_pct=float(100 * np.median(err)) if err.size else float("nan"),
        path_p95_pct=float(100 * np.percentile(err, 95)) if err.size else float("nan"),
        n_moves=int(err.size),
    )


def physics_predict(table: EnergyTable, robot: Any, *, friction: Any = None) -> dict[str, FloatArray]:
    """The dynamics model as a predictor of E1..En and E on the table's rows."""
    f = table.frame
    j = range(1, table.n_joints + 1)
    q = f[[f"q{i}" for i in j]].to_numpy()
    qd = f[[f"dq{i}" for i in j]].to_numpy()
    qdd = f[[f"ddq{i}" for i in j]].to_numpy()
    tau = robot.inverse_dynamics(q, qd, qdd, friction=friction)
    e = joint_energy(tau, qd, f["dt"].to_numpy())
    out = {f"E{i}": e[:, i - 1] for i in j}
    out["E"] = e.sum(axis=1)
    return out


def physics_baseline(table: EnergyTable, robot: Any, *, friction: Any = None, label: str) -> dict[str, Any]:
    """Accuracy, latency per row and size of the analytical model on a table (thesis §4.4)."""
    t0 = time.perf_counter()
    preds = physics_predict(table, robot, friction=friction)
    per_row = (time.perf_counter() - t0) / max(len(table.frame), 1)
    one = table.frame.iloc[:1]
    single = EnergyTable(frame=one, feature_set=table.feature_set)
    t1 = time.perf_counter()
    for _ in range(20):
        physics_predict(single, robot, friction=friction)
    single_s = (time.perf_counter() - t1) / 20
    size = Path(robot.source).stat().st_size if robot.source and Path(robot.source).exists() else 0
    return {
        "label": label,
        "scores": {t: score(table, t, p).as_dict() for t, p in preds.items()},
        "latency_per_row_s_batch": per_row,
        "latency_single_prediction_s": single_s,
        "size_bytes": size,
    }
