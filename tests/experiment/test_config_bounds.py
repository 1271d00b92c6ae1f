"""Every count, ``jobs`` and ``seed`` of an experiment file has a range, checked on load.

Issue 15: ``train_moves = 1_000_000_000_000`` tried to allocate 43 TiB, ``tasks`` and
``jobs = 100000`` ran unbounded. Each out-of-range value is refused before anything
runs, with one line naming the file, the section, the key and the allowed range.
"""

from __future__ import annotations

import pytest

from joulepath.errors import InvalidInput
from joulepath.experiment import load_experiment
from joulepath.experiment._config import BOUNDS, SECTIONS

BASE = 'name = "bounds"\n'


def _toml(section: str, key: str, value: str) -> str:
    if section == "":
        return f'name = "bounds"\n{key} = {value}\n'
    return f"{BASE}\n[{section}]\n{key} = {value}\n"


CASES = [(section, key, low, high) for section, keys in BOUNDS.items() for key, (low, high) in keys.items()]


def test_bounds_cover_every_integer_setting():
    from dataclasses import fields

    from joulepath.experiment._config import Experiment

    for section, cls in {"": Experiment, **SECTIONS}.items():
        ints = {f.name for f in fields(cls) if type(f.default) is int}
        assert ints == set(BOUNDS[section]), section


@pytest.mark.parametrize(
    ("section", "key", "low", "high"), CASES, ids=[f"{s or 'top'}-{k}" for s, k, *_ in CASES]
)
def test_load_experiment_refuses_a_value_above_the_range(section, key, low, high, tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(_toml(section, key, str(high + 1)))
    where = f"[{section}] {key}" if section else f"[top level] {key}"
    with pytest.raises(InvalidInput) as info:
        load_experiment(path)
    line = str(info.value)
    assert "\n" not in line
    for needle in ("study.toml", where, f"must be ≤ {high:_}", f"{low}..{high:_}"):
        assert needle in line, (needle, line)


@pytest.mark.parametrize(
    ("section", "key", "low", "high"), CASES, ids=[f"{s or 'top'}-{k}" for s, k, *_ in CASES]
)
def test_load_experiment_refuses_a_value_below_the_range(section, key, low, high, tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(_toml(section, key, str(low - 1)))
    with pytest.raises(InvalidInput, match=f"{key} must be ≥ {low}, got {low - 1}"):
        load_experiment(path)


@pytest.mark.parametrize(
    ("section", "key", "value"),
    [
        ("data", "train_moves", "1_000_000_000_000"),
        ("optimize", "tasks", "1_000_000_000_000"),
        ("", "jobs", "100000"),
        ("", "seed", "18446744073709551616"),
        ("", "seed", "99999999999999999999999999999999999999"),
    ],
)
def test_load_experiment_refuses_the_issue_15_values(section, key, value, tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(_toml(section, key, value))
    with pytest.raises(InvalidInput, match=f"{key} must be ≤"):
        load_experiment(path)


@pytest.mark.parametrize("value", ["1e12", "nan", "inf", "-inf", "1.0"])
def test_load_experiment_refuses_a_float_count(value, tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(_toml("data", "train_moves", value))
    with pytest.raises(InvalidInput, match=r"\[data\] train_moves must be an integer"):
        load_experiment(path)


def test_load_experiment_accepts_the_bounds_themselves(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(
        'name = "bounds"\nseed = 4294967295\njobs = 256\n[data]\ntrain_moves = 20000\n'
        "[optimize]\ntasks = 1000\ngenerations = 10000\npopulation = 10000\n"
    )
    exp = load_experiment(path)
    assert (exp.seed, exp.jobs, exp.data.train_moves, exp.optimize.tasks) == (2**32 - 1, 256, 20000, 1000)


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ('name = ".."', "must be a folder name"),
        ('name = "."', "must be a folder name"),
        ('name = "a\\u0000b"', "control characters"),
        ('name = "   "', "must be a folder name"),
        (f'name = "{"x" * 101}"', "1 to 100 characters"),
        ('name = "x"\nrobot = "irb\\u0000120"', "control characters"),
        ('name = "x"\n[train]\nfamilies = ["par", "par"]', r"\[train\] families names 'par' more than once"),
        ('name = "x"\n[data]\ntrain_logs = ["a\\u0000"]\ntest_logs = ["b"]', "NUL"),
        ("name = " + "[" * 5000 + "]" * 5000, "not valid TOML"),
    ],
)
def test_load_experiment_refuses_hostile_text(text, pattern, tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(text)
    with pytest.raises(InvalidInput, match=pattern):
        load_experiment(path)


def test_load_experiment_refuses_a_folder_and_a_huge_file(tmp_path):
    with pytest.raises(InvalidInput, match="is a folder"):
        load_experiment(tmp_path)
    big = tmp_path / "big.toml"
    big.write_text('name = "x"\n' + "# padding\n" * 120_000)
    with pytest.raises(InvalidInput, match="larger than 1 MiB"):
        load_experiment(big)


def test_load_experiment_cuts_a_long_value_short_in_the_message(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(f'name = "x"\n[train]\ncv = "{"y" * 10_000}"\n')
    with pytest.raises(InvalidInput) as info:
        load_experiment(path)
    assert len(str(info.value)) < 300
