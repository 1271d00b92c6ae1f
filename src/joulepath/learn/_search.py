"""Grid search with K-fold CV that can be interrupted and resumed, locally or on Dask.

Each candidate (one point of the grid) is cross-validated on the same folds; its
fold scores are written to ``cache_dir`` as soon as it finishes (one small JSON
file per candidate, keyed by the family, the parameters, the folds and a hash of
the data), so a search that is interrupted and started again fits no finished
candidate a second time. Candidates run in parallel through joblib: local
processes by default, or a Dask cluster (``scheduler="tcp://host:port"``) through
joblib's Dask backend.

Splits: ``"grouped"`` keeps all rows of a move in one fold (GroupKFold on
``move_id``) — the honest estimate, since rows 25 ms apart are near copies;
``"shuffled"`` is the thesis' row-wise shuffled KFold, which leaks.
"""

from __future__ import annotations

import hashlib
import json
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from sklearn.base import clone
from sklearn.exceptions import ConvergenceWarning
from sklearn.metrics import mean_absolute_error, r2_score
from sklearn.model_selection import GroupKFold, KFold, ParameterGrid
from sklearn.pipeline import Pipeline

from joulepath._io import atomic_write_text, outside_journal
from joulepath._typing import FloatArray
from joulepath.errors import InvalidInput, MissingDependency
from joulepath.learn._svr import SubsampleWarning

SPLITS = ("grouped", "shuffled")


@dataclass(frozen=True, slots=True)
class CandidateResult:
    """Cross-validation scores of one grid point."""

    params: dict[str, Any]
    r2: tuple[float, ...]
    mae: tuple[float, ...]
    fit_s: float
    cached: bool = False

    @property
    def r2_mean(self) -> float:
        return float(np.mean(self.r2))

    @property
    def r2_std(self) -> float:
        return float(np.std(self.r2))

    @property
    def mae_mean(self) -> float:
        return float(np.mean(self.mae))

    @property
    def mae_std(self) -> float:
        return float(np.std(self.mae))


@dataclass(frozen=True, slots=True)
class SearchResult:
    """All candidates, and the best one (highest mean R² on the folds)."""

    candidates: tuple[CandidateResult, ...]
    split: str
    n_splits: int
    best: CandidateResult = field(init=False)

    def __post_init__(self) -> None:
        finite = [c for c in self.candidates if np.isfinite(c.r2_mean)]
        pool = finite or list(self.candidates)
        object.__setattr__(self, "best", max(pool, key=lambda c: c.r2_mean))

    @property
    def n_fitted(self) -> int:
        """Candidates fitted in this run (not taken from the cache)."""
        return sum(not c.cached for c in self.candidates)


def make_splits(
    n_rows: int, groups: np.ndarray, *, split: str, n_splits: int, seed: int
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Train/validation index pairs for ``grouped`` (by move) or ``shuffled`` (by row) folds."""
    if split not in SPLITS:
        raise InvalidInput(f"split must be one of {SPLITS}, got {split!r}")
    if n_splits < 2:
        raise InvalidInput(f"cv needs at least 2 folds, got {n_splits}")
    idx = np.arange(n_rows)
    if split == "grouped":
        n_groups = np.unique(groups).size
        if n_groups < n_splits:
            raise InvalidInput(f"{n_groups} moves cannot make {n_splits} grouped folds; use fewer folds")
        splitter = GroupKFold(n_splits=n_splits, shuffle=True, random_state=seed)
        return [(a, b) for a, b in splitter.split(idx, groups=groups)]
    return [(a, b) for a, b in KFold(n_splits, shuffle=True, random_state=seed).split(idx)]


def _key(family: str, params: dict[str, Any], split: str, n_splits: int, seed: int, data: str) -> str:
    text = json.dumps(
        {
            "family": family,
            "params": {k: repr(v) for k, v in sorted(params.items())},
            "split": split,
            "n_splits": n_splits,
            "seed": seed,
            "data": data,
        },
        sort_keys=True,
    )
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def data_hash(X: FloatArray, y: FloatArray, groups: np.ndarray) -> str:
    h = hashlib.sha256()
    for a in (X, y, groups):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def cross_validate_candidate(
    pipeline: Pipeline,
    params: dict[str, Any],
    X: FloatArray,
    y: FloatArray,
    splits: Sequence[tuple[np.ndarray, np.ndarray]],
) -> tuple[list[float], list[float], float]:
    """Fit ``pipeline`` with ``params`` on each fold; R² and MAE on the held-out part.

    A 2-D ``y`` (per-joint energies, for the ``bases`` family) is scored on its row sums:
    the energy ``E`` the model predicts.
    """
    t0 = time.perf_counter()
    scored = y.sum(axis=1) if y.ndim == 2 else y
    r2, mae = [], []
    for train, test in splits:
        model = clone(pipeline).set_params(**params)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            warnings.simplefilter("ignore", RuntimeWarning)
            warnings.simplefilter("ignore", SubsampleWarning)  # train() states the sample size once
            try:
                model.fit(X[train], y[train])
                pred = model.predict(X[test])
            except (ValueError, ArithmeticError, np.linalg.LinAlgError):
                pred = np.full(test.size, np.nan)
        if np.all(np.isfinite(pred)):
            r2.append(float(r2_score(scored[test], pred)))
            mae.append(float(mean_absolute_error(scored[test], pred)))
        else:  # a diverged candidate (e.g. learning rate 1) scores as the worst
            r2.append(float("-inf"))
            mae.append(float("inf"))
    return r2, mae, time.perf_counter() - t0


def _read_cached(path: Path, params: dict[str, Any]) -> CandidateResult | None:
    """A finished candidate from the cache; None when absent or unreadable (it is fitted again)."""
    try:
        rec = json.loads(path.read_text())
        return CandidateResult(
            params,
            tuple(float(v) for v in rec["r2"]),
            tuple(float(v) for v in rec["mae"]),
            float(rec["fit_s"]),
            cached=True,
        )
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _plan(
    grid: dict[str, list[Any]],
    X: FloatArray,
    y: FloatArray,
    groups: np.ndarray,
    family: str,
    split: str,
    n_splits: int,
    seed: int,
    cache_dir: str | Path | None,
) -> tuple[list[dict[str, Any]], list[str], dict[int, CandidateResult], list[int]]:
    """Grid points, their cache keys, the finished ones (by index) and the indices still to fit."""
    points = list(ParameterGrid(grid))
    digest = data_hash(X, y, groups)
    keys = [_key(family, p, split, n_splits, seed, digest) for p in points]
    done: dict[int, CandidateResult] = {}
    todo: list[int] = []
    for i, (params, key) in enumerate(zip(points, keys, strict=True)):
        found = _read_cached(Path(cache_dir) / f"{key}.json", params) if cache_dir is not None else None
        if found is not None:
            done[i] = found
        else:
            todo.append(i)
    return points, keys, done, todo


def pending_candidates(
    grid: dict[str, list[Any]],
    X: FloatArray,
    y: FloatArray,
    groups: np.ndarray,
    *,
    family: str,
    split: str = "grouped",
    n_splits: int = 5,
    seed: int = 0,
    cache_dir: str | Path | None = None,
) -> int:
    """How many points of ``grid`` :func:`grid_search` would fit (the others are in the cache)."""
    return len(_plan(grid, X, y, groups, family, split, n_splits, seed, cache_dir)[3])


def _mlp_epochs_at(model: Any, m: int, n: int) -> float | None:
    """How many times the epochs an early-stopping MLP fitted on ``m`` rows needs on ``n``.

    More rows per epoch mean fewer epochs until the validation score stalls; we
    assume ``sqrt(m / n)`` times as many (never below ``n_iter_no_change + 1``). On the
    thesis-sized table, 2,000 -> 56,236 rows took the quick grid's MLPs from 114 to 16
    epochs (identity; sqrt predicts 22) and from 500 (max_iter) to 38 (relu; sqrt
    predicts 94), so the estimate errs high. None for other models.
    """
    from sklearn.neural_network import MLPRegressor

    est = model.steps[-1][1] if isinstance(model, Pipeline) else model
    if not isinstance(est, MLPRegressor) or not est.early_stopping or not getattr(est, "n_iter_", 0):
        return None
    epochs = max(est.n_iter_ * np.sqrt(m / n), est.n_iter_no_change + 1)
    return float(epochs / est.n_iter_)


def _timed_fit(model: Pipeline, X: FloatArray, y: FloatArray) -> float:
    """Seconds ``model.fit(X, y)`` takes (a failing fit counts the time until it failed)."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", SubsampleWarning)
        try:
            model.fit(X, y)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):
            pass
    return max(time.perf_counter() - t0, 1e-6)


def estimate_fit_seconds(
    pipeline: Pipeline,
    grid: dict[str, list[Any]],
    X: FloatArray,
    y: FloatArray,
    *,
    n_rows: int,
    seed: int,
    trial_rows: tuple[int, int] = (500, 2000),
    n_trials: int = 2,
) -> tuple[float, int]:
    """Rough seconds one fit of a grid point takes on ``n_rows`` rows, and the largest trial size.

    Fits up to ``n_trials`` grid points (first, last and evenly between) on seeded
    samples of the two ``trial_rows`` sizes, fits ``t = c + b * rows**a`` through the
    two times (``c``: per-fit overhead such as loading the robot or setting up 500
    trees; ``a = 1``, or 2 for kernel SVR, extrapolated to at most ``max_rows`` since
    it subsamples) and extrapolates each to ``n_rows``. An MLP with early stopping
    instead scales its per-epoch time linearly and its epochs as ``sqrt(trial / rows)``
    (fewer epochs on more rows). A rough estimate for planning, not a promise.
    """
    from joulepath.learn._svr import ScalableSVR

    points = list(ParameterGrid(grid))
    picks = sorted({round(k) for k in np.linspace(0, len(points) - 1, min(n_trials, len(points)))})
    sizes = sorted({min(m, len(y)) for m in trial_rows})
    rng = np.random.default_rng(seed)
    samples = [np.sort(rng.choice(len(y), m, replace=False)) for m in sizes]
    estimates = []
    warm = samples[0][: min(100, len(samples[0]))]
    _timed_fit(clone(pipeline).set_params(**points[picks[0]]), X[warm], y[warm])  # loads robot, imports
    for k in picks:
        spent = []
        for rows in samples:
            model = clone(pipeline).set_params(**points[k])
            spent.append(_timed_fit(model, X[rows], y[rows]))
        big = sizes[-1]
        est = model.steps[-1][1]
        target, power = float(n_rows), 1.0
        if isinstance(est, ScalableSVR) and est.kernel != "linear":
            target, power = min(target, float(est.max_rows)), 2.0
        epochs = _mlp_epochs_at(model, big, n_rows)
        if epochs is not None:
            estimates.append(spent[-1] * (target / big) * epochs)
            continue
        slope = 0.0
        if len(sizes) == 2:
            slope = max((spent[1] - spent[0]) / (big**power - sizes[0] ** power), 0.0)
        overhead = max(spent[-1] - slope * big**power, 0.0)
        if len(sizes) == 1:  # one trial size: all of it scales
            overhead, slope = 0.0, spent[-1] / big**power
        estimates.append(overhead + slope * target**power)
    return float(np.mean(estimates)), sizes[-1]


def grid_search(
    pipeline: Pipeline,
    grid: dict[str, list[Any]],
    X: FloatArray,
    y: FloatArray,
    groups: np.ndarray,
    *,
    family: str,
    split: str = "grouped",
    n_splits: int = 5,
    seed: int = 0,
    cache_dir: str | Path | None = None,
    n_jobs: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> SearchResult:
    """Cross-validate every point of ``grid``; cached points are not fitted again.

    Parameters
    ----------
    pipeline : Pipeline
        Unfitted; ``grid`` keys are its ``step__param`` names.
    X, y, groups : arrays of shape (n, n_inputs), (n,), (n,)
    family : str
        Part of the cache key.
    split, n_splits, seed
        Folds (see :func:`make_splits`).
    cache_dir : path, optional
        Where finished candidates are recorded.
    n_jobs : int
        Local processes (ignored with ``scheduler``).
    scheduler : str, optional
        Address of a Dask scheduler; joblib's Dask backend runs the candidates there.
    progress : callable(done, total), optional
    """
    from joblib import Parallel, delayed, parallel_config

    splits = make_splits(len(y), groups, split=split, n_splits=n_splits, seed=seed)
    points, keys, results, todo = _plan(grid, X, y, groups, family, split, n_splits, seed, cache_dir)
    cache = Path(cache_dir) if cache_dir is not None else None
    if cache is not None:
        cache.mkdir(parents=True, exist_ok=True)
    total = len(points)
    if progress:
        progress(len(results), total)

    def record(i: int, out: tuple[list[float], list[float], float]) -> None:
        r2, mae, seconds = out
        results[i] = CandidateResult(points[i], tuple(r2), tuple(mae), seconds)
        if cache is not None:
            with outside_journal():  # a content-keyed cache: kept for the next run even if this one fails
                atomic_write_text(
                    cache / f"{keys[i]}.json",
                    json.dumps(
                        {
                            "params": {k: repr(v) for k, v in points[i].items()},
                            "r2": r2,
                            "mae": mae,
                            "fit_s": seconds,
                        }
                    ),
                )
        if progress:
            progress(len(results), total)

    tasks = (delayed(cross_validate_candidate)(pipeline, points[i], X, y, splits) for i in todo)
    if not todo:
        pass
    elif scheduler is not None:
        with connect_scheduler(scheduler), parallel_config(backend="dask"):
            outputs = Parallel(return_as="generator")(tasks)
            for i, out in zip(todo, outputs, strict=True):
                record(i, out)
    elif n_jobs == 1:
        for i in todo:
            record(i, cross_validate_candidate(pipeline, points[i], X, y, splits))
    else:
        outputs = Parallel(n_jobs=n_jobs, return_as="generator")(tasks)
        for i, out in zip(todo, outputs, strict=True):
            record(i, out)
    return SearchResult(candidates=tuple(results[i] for i in range(total)), split=split, n_splits=n_splits)


def connect_scheduler(address: str) -> Any:
    """A ``dask.distributed.Client`` of the scheduler at ``address``; InvalidInput when unreachable."""
    try:
        from dask.distributed import Client
    except ImportError as err:
        raise MissingDependency("Dask is not installed: pip install 'joulepath[dask]'") from err
    try:
        return Client(address)  # type: ignore[no-untyped-call]
    except (OSError, ValueError, TypeError) as err:
        reason = " ".join(str(err).split())
        raise InvalidInput(
            f"cannot connect to the Dask scheduler {address!r} ({reason}); give the address of a running "
            "scheduler as tcp://HOST:PORT, or leave the scheduler out to use local processes"
        ) from err
