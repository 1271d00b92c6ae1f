"""Which inputs drive the energy (thesis §2.3.4, §4.1, Figs 4.1–4.2): correlations, model importance."""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from joulepath._io import atomic_write_bytes
from joulepath.data import EnergyTable
from joulepath.errors import InvalidInput

METHODS = ("pearson", "spearman", "kendall", "rf_impurity", "permutation")
N_JOINTS = 6


def feature_importance(
    table: EnergyTable, target: str = "E", *, max_rows: int = 20000, seed: int = 0
) -> pd.DataFrame:
    """Importance of every input for ``target`` by five methods, each scaled to sum to 1.

    Correlations use absolute coefficients; the random forest (100 trees) gives
    impurity importance and, on a held-out quarter of the moves, permutation
    importance (clipped at 0). At most ``max_rows`` rows (a seeded sample) are used.

    Returns
    -------
    DataFrame indexed by input name with one column per method and ``mean``,
    sorted by ``mean`` (descending).
    """
    from sklearn.ensemble import RandomForestRegressor
    from sklearn.inspection import permutation_importance

    if target not in table.frame.columns:
        raise InvalidInput(f"unknown target {target!r}; use one of {', '.join(table.targets)}")
    rng = np.random.default_rng(seed)
    frame = table.frame
    if len(frame) > max_rows:
        frame = frame.iloc[np.sort(rng.choice(len(frame), max_rows, replace=False))]
    features = list(table.features)
    X = frame[features].to_numpy()
    y = frame[target].to_numpy()
    out = pd.DataFrame(index=features)
    for name, fn in (
        ("pearson", stats.pearsonr),
        ("spearman", stats.spearmanr),
        ("kendall", stats.kendalltau),
    ):
        vals = []
        for k in range(X.shape[1]):
            if np.std(X[:, k]) == 0:
                vals.append(0.0)
                continue
            r = fn(X[:, k], y)[0]
            vals.append(abs(float(r)) if np.isfinite(r) else 0.0)
        out[name] = vals
    moves = frame["move_id"].to_numpy()
    unique = np.unique(moves)
    held = rng.choice(unique, max(1, unique.size // 4), replace=False)
    test = np.isin(moves, held)
    forest = RandomForestRegressor(n_estimators=100, min_samples_leaf=5, n_jobs=1, random_state=seed)
    forest.fit(X[~test], y[~test])
    out["rf_impurity"] = forest.feature_importances_
    perm = permutation_importance(forest, X[test], y[test], n_repeats=5, random_state=seed, n_jobs=1)
    out["permutation"] = np.clip(perm.importances_mean, 0.0, None)
    for col in METHODS:
        total = out[col].sum()
        out[col] = out[col] / total if total > 0 else 0.0
    out["mean"] = out[list(METHODS)].mean(axis=1)
    return out.sort_values("mean", ascending=False)


def _joint_of(feature: str) -> int | None:
    for prefix in ("ddq", "dq", "q"):
        if feature.startswith(prefix) and feature[len(prefix) :].isdigit():
            return int(feature[len(prefix) :])
    return None


def rank_joints(importance: pd.DataFrame) -> list[int]:
    """Joints (1-based) ordered by the summed importance of their q, dq, ddq inputs (most first).

    The optimizer's informed local search scales the coefficients of the first
    ones — derived from the data at hand, not hard-coded as in the thesis.
    """
    joints = [_joint_of(str(feature)) for feature in importance.index]
    n = max([j for j in joints if j is not None], default=N_JOINTS)
    score = {j: 0.0 for j in range(1, n + 1)}
    for feature, value in importance["mean"].items():
        joint = _joint_of(str(feature))
        if joint is not None:
            score[joint] += float(value)
    return sorted(score, key=lambda j: -score[j])


def plot_importance(importance: pd.DataFrame, path: str | os.PathLike[str], *, title: str) -> Path:
    """Stacked horizontal bars of the five methods per input (thesis Figs 4.1–4.2)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = importance[list(METHODS)].iloc[::-1]
    fig, ax = plt.subplots(figsize=(8, max(4, 0.22 * len(data))))
    left = np.zeros(len(data))
    for method in METHODS:
        ax.barh(data.index, data[method], left=left, label=method)
        left += data[method].to_numpy()
    ax.set_xlabel("importance (each method scaled to sum 1)")
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return atomic_write_bytes(Path(path), buf.getvalue())
