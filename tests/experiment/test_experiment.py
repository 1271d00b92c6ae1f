"""Experiment files: validation up front, stages cached, the CLI."""

import json

import pytest

from joulepath.cli import main
from joulepath.errors import InvalidInput
from joulepath.experiment import load_experiment, run_experiment

TINY = """
name = "tiny"
seed = 1
[data]
train_moves = 15
test_moves = 6
[train]
families = ["par"]
cv = 3
[optimize]
tasks = 2
generations = 6
population = 12
"""


def _write(tmp_path, text, name="exp.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize(
    ("edit", "pattern"),
    [
        (lambda t: t.replace("cv = 3", "folds = 3"), r"\[train\] unknown key 'folds'; allowed: cv, families"),
        (
            lambda t: t.replace('families = ["par"]', 'families = "par"'),
            r"\[train\] families must be a list of strings",
        ),
        (lambda t: t.replace("tasks = 2", 'tasks = "two"'), r"\[optimize\] tasks must be a int"),
        (
            lambda t: t.replace("[optimize]", '[optimize]\nalgorithm = "pso"'),
            r"algorithm = 'pso' is not allowed; use one of ga, de",
        ),
        (lambda t: t + "\n[report]\nx = 1\n", r"unknown section \[report\]"),
        (lambda t: t.replace('name = "tiny"', ""), r"missing key 'name'"),
        (lambda t: t.replace("[data]", "[data"), "not valid TOML"),
        (lambda t: t.replace("tasks = 2", "tasks = 0"), r"\[optimize\] tasks must be ≥ 1"),
    ],
)
def test_load_experiment_errors(tmp_path, edit, pattern):
    with pytest.raises(InvalidInput, match=pattern):
        load_experiment(_write(tmp_path, edit(TINY)))


def test_bundled_demo_experiment_is_valid():
    from importlib import resources

    exp = load_experiment(str(resources.files("joulepath.experiment") / "presets" / "demo.toml"))
    assert exp.name == "demo" and exp.train.families == ("mlp", "svr", "par", "xgb")


def test_run_experiment_caches_unchanged_stages(tmp_path):
    exp = load_experiment(_write(tmp_path, TINY))
    said: list[str] = []
    first = run_experiment(exp, tmp_path / "run", say=said.append)
    assert (tmp_path / "run" / "optimize" / "task-000" / "result.json").exists()
    assert first["mean_saved_pct"] is not None
    said.clear()
    run_experiment(exp, tmp_path / "run", say=said.append)
    assert said[:3] == [
        "data: unchanged, skipped",
        "train: unchanged, skipped",
        "optimize: unchanged, skipped",
    ]
    changed = load_experiment(_write(tmp_path, TINY.replace("generations = 6", "generations = 7")))
    said.clear()
    run_experiment(changed, tmp_path / "run", say=said.append)
    assert said[:2] == ["data: unchanged, skipped", "train: unchanged, skipped"]
    assert said[2].startswith("optimize: task 0")
    (tmp_path / "run" / "models" / "stage.json").unlink()  # an interrupted training stage runs again
    said.clear()
    run_experiment(changed, tmp_path / "run", say=said.append)
    assert said[1].startswith("train: par E")
    assert "mean_saved_pct" in json.loads((tmp_path / "run" / "summary.json").read_text())
    assert (tmp_path / "run" / "run.log").read_text().count("data: ") >= 4


def test_cli_run_errors_and_quiet(tmp_path, capsys):
    assert main(["run", str(tmp_path / "missing.toml")]) == 2
    assert "cannot be read" in capsys.readouterr().err
    bad = _write(tmp_path, TINY.replace("cv = 3", "folds = 3"), "bad.toml")
    assert main(["run", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown key 'folds'" in err[0]
    assert main(["run", str(_write(tmp_path, TINY)), "--out", str(tmp_path / "r"), "--quiet"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1 and out[0].startswith("tiny: mean saving")
