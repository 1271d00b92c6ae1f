import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.learn import feature_importance, plot_importance, rank_joints
from joulepath.learn._importance import METHODS


def test_feature_importance_methods_and_ranking(lab_tables, tmp_path):
    train, _ = lab_tables
    imp = feature_importance(train, "E", seed=0)
    assert list(imp.columns) == [*METHODS, "mean"]
    assert set(imp.index) == set(train.features)
    np.testing.assert_allclose(imp[list(METHODS)].sum(), 1.0)
    assert imp["mean"].is_monotonic_decreasing
    joints = rank_joints(imp)
    assert sorted(joints) == [1, 2, 3, 4, 5, 6]
    assert plot_importance(imp, tmp_path / "imp.png", title="E").stat().st_size > 1000


def test_feature_importance_is_seeded(lab_tables):
    train, _ = lab_tables
    a = feature_importance(train, "E2", seed=3, max_rows=800)
    b = feature_importance(train, "E2", seed=3, max_rows=800)
    np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())


def test_rank_joints_follows_the_importance():
    import pandas as pd

    imp = pd.DataFrame({"mean": [0.5, 0.3, 0.1, 0.1]}, index=["dq5", "q2", "ddq5", "x"])
    assert rank_joints(imp)[:2] == [5, 2]


def test_feature_importance_unknown_target(lab_tables):
    with pytest.raises(InvalidInput, match="unknown target 'P'"):
        feature_importance(lab_tables[0], "P")
