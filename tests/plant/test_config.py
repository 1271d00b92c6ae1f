"""Plant files: every problem is one line naming the cell, exit code 2, nothing computed."""

from __future__ import annotations

from pathlib import Path

import pytest

from joulepath.cli import main
from joulepath.plant import CELL_SETTINGS, PlantFileError, read_plant

from .conftest import make_mini_plant


def test_read_plant_reads_the_mini_plant(tmp_path):
    plant = read_plant(make_mini_plant(tmp_path))
    assert plant.name == "Mini plant" and plant.hours_per_year == 6000
    assert [c.name for c in plant.cells] == ["alpha", "beta", "gamma", "task"]
    alpha, task = plant.cells[0], plant.cells[3]
    assert alpha.program == ((tmp_path / "alpha.mod").resolve(),) and alpha.share == 1.0
    assert alpha.settings["table_points"] == 2 and alpha.settings["energy"] == "electrical"
    assert [f.name for f in task.program] == ["lib.sys", "main.mod"]  # a folder: its modules
    assert task.io == {"diPartReady": 1.0}


def _bad(tmp_path: Path, old: str, new: str) -> Path:
    path = make_mini_plant(tmp_path)
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    return path


BAD = [
    (
        'program = "beta.mod"',
        'program = "nowhere/beta.mod"',
        "cell 'beta': program nowhere/beta.mod: no such file",
    ),
    ('name = "beta"\n', 'name = "beta"\nrobot = "irb9999"\n', "cell 'beta': robot 'irb9999'"),
    ('name = "gamma"', 'name = "alpha"', "cell 'alpha': duplicate cell name"),
    (
        "tariff_eur_per_kwh = 0.2",
        "tariff_eur_per_kwh = -0.2",
        "[plant]: tariff_eur_per_kwh must be a number in [0",
    ),
    ('name = "beta"\n', 'name = "beta"\nshare = 1.5\n', "cell 'beta': share must be a number in (0, 1]"),
    (
        'name = "beta"\n',
        'name = "beta"\nmax_iterations = 3\n',
        "cell 'beta': unknown setting 'max_iterations'",
    ),
    ("table_points = 2", "table_point = 2", "[defaults]: unknown setting 'table_point'"),
    ('name = "beta"\n', 'name = "beta"\nenergy = "joules"\n', "cell 'beta': energy must be 'thesis' or"),
]


@pytest.mark.parametrize(("old", "new", "expected"), BAD, ids=[b[2].split(":")[-2][-24:] for b in BAD])
def test_plant_refuses_a_bad_plant_file_with_one_line(tmp_path, capsys, old, new, expected):
    path = _bad(tmp_path, old, new)
    out = tmp_path / "run"
    assert main(["plant", str(path), "--out", str(out), "--jobs", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2, err  # the problem, then how many and that nothing was computed
    assert expected in err[0] and err[0].startswith(f"error: {path}: ")
    assert "nothing was computed" in err[1]
    assert not out.exists()


def test_read_plant_gathers_every_problem(tmp_path):
    path = make_mini_plant(tmp_path)
    text = path.read_text().replace("co2_kg_per_kwh = 0.35", "co2_kg_per_kwh = -1")
    path.write_text(text.replace('name = "gamma"', 'name = "alpha"') + "\n[extra]\n")
    with pytest.raises(PlantFileError) as caught:
        read_plant(path)
    problems = caught.value.problems
    assert len(problems) == 3 and all(p.startswith(f"{path}: ") for p in problems)
    assert any("co2_kg_per_kwh" in p for p in problems) and any("duplicate" in p for p in problems)


def test_every_setting_has_a_check_that_refuses_a_wrong_type():
    for name, check in CELL_SETTINGS.items():
        assert check(object()) is not None, name
