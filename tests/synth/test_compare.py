"""Descriptive statistics, distribution plots and the compare helper."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from joulepath.data import EnergyTable
from joulepath.errors import InvalidInput
from joulepath.synth import (
    FEATURE_GROUPS,
    STATISTICS,
    Comparison,
    compare,
    describe,
    histogram_mode,
    plot_distributions,
)


def test_describe_matches_pandas(energy_table, fitted):
    _, synthetic = fitted("copula")
    stats = describe({"real": energy_table, "copula": synthetic})
    assert list(stats.columns) == list(STATISTICS)
    assert stats.index.names == ["column", "table"]
    assert len(stats) == 2 * (len(energy_table.frame.columns) - 2)  # without move_id and t
    col = energy_table.frame["dq2"]
    row = stats.loc[("dq2", "real")]
    assert row["mean"] == pytest.approx(col.mean())
    assert row["median"] == pytest.approx(col.median())
    assert row["variance"] == pytest.approx(col.var())
    assert row["std"] == pytest.approx(col.std())
    assert row["range"] == pytest.approx(col.max() - col.min())
    assert row["skewness"] == pytest.approx(col.skew())
    assert row["kurtosis"] == pytest.approx(col.kurt())
    assert col.min() <= row["mode"] <= col.max()


def test_describe_single_table_and_column_subset(energy_table):
    stats = describe({"real": energy_table}, columns=["E", "q1"])
    assert list(stats.index) == [("E", "real"), ("q1", "real")]


def test_histogram_mode_finds_the_peak():
    rng = np.random.default_rng(0)
    values = np.r_[rng.normal(2.0, 0.1, 5000), rng.uniform(-5, 5, 1000)]
    assert histogram_mode(values) == pytest.approx(2.0, abs=0.15)
    assert histogram_mode(np.full(10, 3.0)) == 3.0
    assert np.isnan(histogram_mode(np.array([np.nan])))
    # a column equal up to rounding (dt of a log sampled at exactly 40 Hz) has no room for 100 bins
    assert histogram_mode(0.025 + np.array([0.0, 1, -1, 2, 0, 3]) * 3.5e-18) == pytest.approx(0.025)


def test_describe_errors(energy_table):
    with pytest.raises(InvalidInput, match="non-empty mapping"):
        describe({})
    with pytest.raises(InvalidInput, match="'x' is a DataFrame, expected an EnergyTable"):
        describe({"x": energy_table.frame})  # type: ignore[dict-item]
    with pytest.raises(InvalidInput, match="not every table has column\\(s\\) nope"):
        describe({"real": energy_table}, columns=["nope"])
    empty = EnergyTable(frame=energy_table.frame.iloc[:0], feature_set="full40")
    with pytest.raises(InvalidInput, match="table 'e' has no rows"):
        describe({"e": empty})


def test_plot_distributions_writes_one_png_per_group(energy_table, joint_table, tmp_path):
    paths = plot_distributions({"real": energy_table, "part": joint_table}, tmp_path / "plots")
    # the joint-only table lacks TCP columns: only the groups both tables share are drawn
    assert [p.stem for p in paths] == ["joint_positions", "joint_speeds", "joint_accelerations", "energies"]
    for p in paths:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    full = plot_distributions({"real": energy_table}, tmp_path / "all", bins=20)
    assert [p.stem for p in full] == list(FEATURE_GROUPS)
    with pytest.raises(InvalidInput, match="bins must be an integer >= 2"):
        plot_distributions({"real": energy_table}, tmp_path, bins=1)


def test_compare_statistics_plots_quality_and_consistency(energy_table, fitted, tmp_path, irb120):
    _, synthetic = fitted("copula")
    result = compare({"real": energy_table, "copula": synthetic}, quality=True, robot=irb120)
    assert isinstance(result, Comparison)
    assert isinstance(result.statistics, pd.DataFrame) and result.plots == ()  # out_dir=None
    assert set(result.quality) == {"copula"}
    assert 0 <= result.quality["copula"]["column_shapes"] <= 1
    assert result.consistency["real"] == 1.0 and result.consistency["copula"] < 1.0
    text = result.to_text()
    assert "column shapes" in text and "within 5 mm" in text and "skewness" in text
    plain = compare({"real": energy_table}, out_dir=tmp_path)
    assert [p.stem for p in plain.plots] == list(FEATURE_GROUPS)
    assert plain.quality == {} and plain.consistency == {} and "wrote 8 plots" in plain.to_text()
