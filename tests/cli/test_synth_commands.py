"""``joulepath synth`` and ``joulepath compare``, through a local typer app until main() registers them."""

from __future__ import annotations

import pytest
import typer
from typer.testing import CliRunner

import joulepath
from joulepath.cli._synth import compare, synth
from joulepath.data import EnergyTable, ingest, load_table, save_table, table_columns
from joulepath.errors import InvalidInput
from joulepath.sim import simulate
from joulepath.synth import kinematic_consistency

app = typer.Typer(add_completion=False, pretty_exceptions_enable=False)
app.command("synth")(synth)
app.command("compare")(compare)
runner = CliRunner()


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("synth-cli")
    log = simulate(d / "lab.csv", plant="lab", n_moves=4, seed=2)
    full = ingest([log.log], robot=joulepath.load_robot("irb120"))
    joint = EnergyTable(frame=full.frame[list(table_columns("joint"))], feature_set="joint")
    return save_table(full, d / "full.parquet"), save_table(joint, d / "joint.parquet")


def test_synth_fit_save_and_sample_again(tables, tmp_path):
    _, joint = tables
    out, model = tmp_path / "s.parquet", tmp_path / "tvae.pkl"
    args = ["synth", "--method", "tvae", "--from", str(joint), "--rows", "120", "--out", str(out)]
    args += [
        "--seed",
        "3",
        "--epochs",
        "1",
        "--batch-size",
        "50",
        "--save-model",
        str(model),
        "--no-progress",
    ]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "wrote" in result.output and "120 synthetic rows" in result.output
    table = load_table(out)
    assert len(table.frame) == 120 and list(table.frame.columns) == list(table_columns("joint"))
    again = tmp_path / "again.parquet"
    result = runner.invoke(app, ["synth", "--model", str(model), "--rows", "30", "--out", str(again)])
    assert result.exit_code == 0, result.output
    assert len(load_table(again).frame) == 30


def test_synth_repair_kinematics(tables, tmp_path):
    full, _ = tables
    out = tmp_path / "r.parquet"
    args = ["synth", "--method", "copula", "--from", str(full), "--rows", "50", "--out", str(out)]
    result = runner.invoke(app, [*args, "--repair-kinematics"])
    assert result.exit_code == 0, result.output
    assert "TCP columns recomputed from q" in result.output
    assert kinematic_consistency(load_table(out)) == 1.0


def test_synth_needs_exactly_one_source(tables, tmp_path):
    result = runner.invoke(app, ["synth", "--out", str(tmp_path / "x.parquet")])
    assert isinstance(result.exception, InvalidInput)
    assert "exactly one of --from TABLE" in str(result.exception)


def test_synth_bad_batch_size_is_a_user_error(tables, tmp_path):
    _, joint = tables
    args = [
        "synth",
        "--method",
        "ctgan",
        "--from",
        str(joint),
        "--batch-size",
        "64",
        "--out",
        str(tmp_path / "x"),
    ]
    result = runner.invoke(app, args)
    assert isinstance(result.exception, InvalidInput) and "multiple of 10" in str(result.exception)
    assert not (tmp_path / "x").exists()


def test_compare_prints_statistics_and_writes_plots(tables, tmp_path):
    full, _ = tables
    out = tmp_path / "plots"
    result = runner.invoke(app, ["compare", str(full), str(full), "--out", str(out), "--robot", "irb120"])
    assert result.exit_code == 0, result.output
    assert "kurtosis" in result.output and "full-2" in result.output and "within 5 mm" in result.output
    assert len(list(out.glob("*.png"))) == 8


def test_compare_writes_the_statistics_it_promises(tables, tmp_path):
    import pandas as pd

    full, _ = tables
    out = tmp_path / "cmp"
    result = runner.invoke(app, ["compare", str(full), str(full), "--out", str(out), "--robot", "irb120"])
    assert result.exit_code == 0, result.output
    stats = pd.read_csv(out / "statistics.csv", index_col=[0, 1])
    assert {"mean", "kurtosis"} <= set(stats.columns)
    assert set(stats.index.get_level_values(1)) == {"full", "full-2"}
    scores = pd.read_csv(out / "scores.csv", index_col=0)
    assert scores.loc["full", "tcp_within_5mm"] == pytest.approx(1.0)
    assert "statistics.csv" in result.output


def test_compare_without_scores_writes_no_scores_file(tables, tmp_path):
    _, joint = tables
    out = tmp_path / "cmp"
    result = runner.invoke(app, ["compare", str(joint), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert (out / "statistics.csv").exists() and not (out / "scores.csv").exists()


def test_synth_prints_the_users_seed(tables, tmp_path):
    _, joint = tables
    out = tmp_path / "s.parquet"
    args = [
        "synth",
        "--method",
        "copula",
        "--from",
        str(joint),
        "--rows",
        "20",
        "--out",
        str(out),
        "--seed",
        "0",
    ]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    # the user's seed is shown as such; the integers handed to SDV only as derived from it
    assert "(seed 0; SDV fit seed " in result.output and "derived from it" in result.output
    assert "(seed 0)" in result.output.splitlines()[-1]
    for line in result.output.splitlines():
        if "seed" in line and "derived" not in line:
            assert "seed 0" in line, line
