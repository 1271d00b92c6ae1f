"""SDMetrics' quality report against the real table."""

from __future__ import annotations

import numpy as np
import pytest

from joulepath.data import EnergyTable
from joulepath.errors import InvalidInput, InvalidLog
from joulepath.synth import METHODS, quality_report

SUBSET = ["q1", "q2", "dq1", "dq2", "x", "z", "ddq1", "E1", "E2", "E"]


@pytest.mark.parametrize("method", METHODS)
def test_quality_scores_lie_in_unit_interval(fitted, energy_table, method):
    _, synthetic = fitted(method)
    columns = None if method == "tvae" else SUBSET  # all model columns once; a subset saves time
    scores = quality_report(energy_table, synthetic, columns=columns)
    assert set(scores) == {"column_shapes", "column_pair_trends", "overall"}
    for value in scores.values():
        assert 0.0 <= value <= 1.0
    assert scores["overall"] == pytest.approx((scores["column_shapes"] + scores["column_pair_trends"]) / 2)


def test_quality_of_the_real_table_against_itself_is_one(energy_table):
    scores = quality_report(energy_table, energy_table, columns=SUBSET[:4])
    assert scores["column_shapes"] == pytest.approx(1.0)
    assert scores["column_pair_trends"] == pytest.approx(1.0)


def test_quality_correlation_threshold_scores_fewer_pairs(fitted, energy_table):
    _, synthetic = fitted("copula")
    every = quality_report(energy_table, synthetic, columns=SUBSET)
    strong = quality_report(energy_table, synthetic, columns=SUBSET, correlation_threshold=0.5)
    assert every["column_shapes"] == strong["column_shapes"]
    assert every["column_pair_trends"] != strong["column_pair_trends"]
    # no pair of q1 and q2 correlates above 0.99 in the real table: nothing left to score
    none = quality_report(energy_table, synthetic, columns=["q1", "q2"], correlation_threshold=0.99)
    assert np.isnan(none["column_pair_trends"])


def test_quality_rejects_unknown_or_too_few_columns(energy_table):
    with pytest.raises(InvalidInput, match="column\\(s\\) move_id, nope cannot be scored"):
        quality_report(energy_table, energy_table, columns=["q1", "move_id", "nope"])
    with pytest.raises(InvalidInput, match="at least 2 columns"):
        quality_report(energy_table, energy_table, columns=["q1"])
    with pytest.raises(InvalidInput, match="correlation_threshold must lie in \\[0, 1\\), got 1.5"):
        quality_report(energy_table, energy_table, correlation_threshold=1.5)


def test_quality_rejects_mismatched_tables(energy_table, joint_table):
    with pytest.raises(InvalidInput, match="feature set 'full40' and the synthetic one 'joint'"):
        quality_report(energy_table, joint_table)
    with pytest.raises(InvalidInput, match="synthetic must be an EnergyTable"):
        quality_report(energy_table, energy_table.frame)  # type: ignore[arg-type]
    with pytest.raises(InvalidLog, match="missing column\\(s\\) E"):
        quality_report(
            energy_table, EnergyTable(frame=energy_table.frame.drop(columns="E"), feature_set="full40")
        )
