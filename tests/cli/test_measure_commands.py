"""``joulepath optimize`` -> ``simulate --program path.mod`` -> ``measure``, and their refusals."""

import json

import pytest

from joulepath.cli import main

TASK = ["--start", "0.3,0.2,-0.4,0.5,-0.6,1.0", "--end", "-0.9,0.6,0.3,-1.2,0.8,-1.5", "--duration", "1.6"]


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "run"
    # fewer knots than the default 0.05 s: a shorter search, still a saving the measurement finds
    assert main(["optimize", *TASK, "--knot-spacing", "0.1", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def lab_log(run):
    log = run.parent / "lab.csv"
    assert main(["simulate", "--program", str(run / "path.mod"), "--plant", "lab", "--out", str(log)]) == 0
    return log


def test_simulate_program_then_measure(run, lab_log, tmp_path, capsys):
    capsys.readouterr()
    out = tmp_path / "m"
    assert main(["measure", str(lab_log), "--plan", str(run), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "5 default and 5 optimized moves (shape)" in printed
    data = json.loads((out / "measure.json").read_text())
    assert [r["kind"] for r in data["repetitions"]] == ["default"] * 5 + ["optimized"] * 5
    s = data["saving"]
    assert s["ci95_low_pct"] < s["pct"] < s["ci95_high_pct"]
    assert f"saving {s['pct']:.1f} %" in printed
    assert data["planned_duration_s"] == 1.6 and data["optimized"]["duration_mean_s"] > 0
    assert (out / "power.png").exists()


def test_measure_refuses_a_truncated_log_and_writes_nothing(run, lab_log, tmp_path, capsys):
    lines = lab_log.read_text().splitlines(keepends=True)
    cut = tmp_path / "cut.csv"
    cut.write_text("".join(lines[: len(lines) // 2]))
    out = tmp_path / "m"
    capsys.readouterr()
    assert main(["measure", str(cut), "--plan", str(run), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "default and" in err and "optimized moves" in err
    assert not out.exists()


def test_measure_refuses_a_log_of_random_moves(run, tmp_path, capsys):
    log = tmp_path / "random.csv"
    assert main(["simulate", "--plant", "sim", "--moves", "10", "--out", str(log)]) == 0
    capsys.readouterr()
    assert main(["measure", str(log), "--plan", str(tmp_path / "nothing"), "--out", str(tmp_path / "m")]) == 2
    assert "not a folder; give the --out folder of joulepath optimize" in capsys.readouterr().err
    assert main(["measure", str(log), "--plan", str(run), "--out", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "found 0 moves from rest at START" in err
    assert not (tmp_path / "m").exists()


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--moves", "5"], "drop --moves"),
        (["--plan", "thesis"], "drop --plan"),
        (["--mode", "excitation", "--range-set", "lab"], "drop --mode, --range-set"),
        (["--start", "1,2,3"], "expected 6 joint values"),
    ],
)
def test_simulate_program_refuses_incompatible_options(run, tmp_path, capsys, extra, needle):
    log = tmp_path / "x.csv"
    assert main(["simulate", "--program", str(run / "path.mod"), *extra, "--out", str(log)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err, err
    assert not log.exists()


def test_simulate_start_needs_a_program(tmp_path, capsys):
    assert main(["simulate", "--start", "0,0,0,0,0,0", "--out", str(tmp_path / "x.csv")]) == 2
    assert "give --program" in capsys.readouterr().err


def test_simulate_program_needs_a_csv_and_a_readable_module(run, tmp_path, capsys):
    assert main(["simulate", "--program", str(run / "path.mod"), "--out", str(tmp_path / "log")]) == 2
    assert "give a .csv file" in capsys.readouterr().err
    bad = tmp_path / "bad.mod"
    bad.write_text((run / "path.mod").read_text().replace("TO REPEATS", "TO count"))
    assert main(["simulate", "--program", str(bad), "--out", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err.strip()
    # count is declared nowhere: taken as 0, the loops run no move, and the line says what was read so
    assert len(err.splitlines()) == 1 and "bad.mod:" in err and "holds no move" in err and "(count:" in err
    assert not (tmp_path / "x.csv").exists()
