"""Grid search: resumable from its cache, grouped folds keep moves together, Dask backend."""

import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.learn import grid_search, input_columns, make_pipeline, make_splits


@pytest.fixture(scope="module")
def xy(lab_tables):
    train, _ = lab_tables
    cols = input_columns("full40", "physics", train.n_joints)
    return (
        train.frame[list(cols)].to_numpy(),
        train.frame["E"].to_numpy(),
        train.frame["move_id"].to_numpy(),
        cols,
    )


GRID = {"model__eta0": [0.01, 0.1], "model__learning_rate": ["pa1", "pa2"], "model__epsilon": [0.005]}


def test_make_splits_grouped_keeps_moves_together(xy):
    _, y, groups, _ = xy
    for train, test in make_splits(len(y), groups, split="grouped", n_splits=3, seed=0):
        assert not set(groups[train]) & set(groups[test])
    with pytest.raises(InvalidInput, match="cannot make 1000 grouped folds"):
        make_splits(len(y), groups, split="grouped", n_splits=1000, seed=0)


def test_interrupted_search_resumes_without_refitting(xy, tmp_path):
    X, y, groups, cols = xy
    pipe = make_pipeline("par", seed=0, columns=cols, robot="irb120")
    first = grid_search(pipe, GRID, X, y, groups, family="par", n_splits=3, cache_dir=tmp_path)
    assert first.n_fitted == 4
    files = sorted(tmp_path.glob("*.json"))
    assert len(files) == 4
    for f in files[:2]:  # the search was interrupted before these two finished
        f.unlink()
    second = grid_search(pipe, GRID, X, y, groups, family="par", n_splits=3, cache_dir=tmp_path)
    assert second.n_fitted == 2
    assert second.best.params == first.best.params
    np.testing.assert_allclose([c.r2_mean for c in second.candidates], [c.r2_mean for c in first.candidates])
    third = grid_search(pipe, GRID, X, y, groups, family="par", n_splits=3, cache_dir=tmp_path)
    assert third.n_fitted == 0


def test_grid_search_on_a_dask_local_cluster(xy, dask_scheduler):
    X, y, groups, cols = xy
    pipe = make_pipeline("par", seed=0, columns=cols, robot="irb120")
    res = grid_search(pipe, GRID, X, y, groups, family="par", n_splits=3, scheduler=dask_scheduler)
    local = grid_search(pipe, GRID, X, y, groups, family="par", n_splits=3)
    assert res.n_fitted == 4
    np.testing.assert_allclose([c.r2_mean for c in res.candidates], [c.r2_mean for c in local.candidates])


def test_pending_candidates_counts_what_is_not_cached(xy, tmp_path):
    from joulepath.learn._search import pending_candidates

    X, y, groups, cols = xy
    kwargs = {"family": "par", "n_splits": 3, "cache_dir": tmp_path}
    assert pending_candidates(GRID, X, y, groups, **kwargs) == 4
    grid_search(make_pipeline("par", seed=0, columns=cols, robot="irb120"), GRID, X, y, groups, **kwargs)
    assert pending_candidates(GRID, X, y, groups, **kwargs) == 0
    files = sorted(tmp_path.glob("*.json"))
    files[0].unlink()
    files[1].write_text("{not json")  # a damaged cache entry is fitted again, not a crash
    assert pending_candidates(GRID, X, y, groups, **kwargs) == 2
    assert pending_candidates(GRID, X, y, groups, family="par", n_splits=3, cache_dir=None) == 4


def test_estimate_fit_seconds_is_a_positive_time_from_small_trials(xy):
    from joulepath.learn import QUICK_GRIDS
    from joulepath.learn._search import estimate_fit_seconds

    X, y, _, cols = xy
    for family in ("par", "mlp"):
        pipe = make_pipeline(family, seed=0, columns=cols, robot="irb120")
        seconds, trial = estimate_fit_seconds(pipe, QUICK_GRIDS[family], X, y, n_rows=50_000, seed=0)
        assert np.isfinite(seconds) and 0 < seconds < 600, (family, seconds)
        assert trial == min(2000, len(y))
