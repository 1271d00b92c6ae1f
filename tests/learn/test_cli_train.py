"""``joulepath train`` on the command line: plain progress lines without a terminal, one-line refusals."""

import re

import pytest

import joulepath
from joulepath.cli import main
from joulepath.data import EnergyTable, ingest, save_table
from joulepath.errors import InvalidInput
from joulepath.learn import TrainConfig, train
from joulepath.sim import simulate


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli-train")
    robot = joulepath.load_robot("irb120")
    full = ingest([simulate(d / "train.csv", plant="lab", n_moves=6, seed=3).log], robot=robot)
    test = ingest([simulate(d / "test.csv", plant="lab", n_moves=3, seed=4).log], robot=robot)
    empty = EnergyTable(frame=test.frame.iloc[:0], feature_set=test.feature_set)
    return {
        "train": save_table(full, d / "train.parquet"),
        "test": save_table(test, d / "test.parquet"),
        "empty": save_table(empty, d / "empty.parquet"),
        "tables": (full, test, empty),
    }


def test_train_without_a_terminal_prints_plain_progress_lines(tables, tmp_path, capsys):
    out = tmp_path / "models"
    argv = ["train", "--data", str(tables["train"]), "--test", str(tables["test"])]
    code = main([*argv, "--family", "par", "--cv", "2", "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    lines = captured.err.splitlines()
    assert not any("\x1b" in line for line in lines)  # no terminal control codes
    plan = [line for line in lines if " fits (" in line]
    assert len(plan) == 1
    assert re.fullmatch(
        r"par E: 11 fits \(4 of 4 candidates x 2 folds, 2 shuffled folds, 1 refit\) on ~[\d,]+ rows; "
        r"roughly \d+ (s|min|h) \(extrapolated from trial fits on up to [\d,]+ rows\)",
        plan[0],
    ), plan[0]
    assert "par E: 0/4 candidates" in lines and lines.index(plan[0]) < lines.index("par E: 0/4 candidates")
    assert any(re.fullmatch(r"par E: 4/4 candidates, \d+ s spent", line) for line in lines), lines
    assert any(line.startswith("par E: refitting the best candidate on all") for line in lines)
    assert (out / "par-E" / "card.json").exists()
    assert "test_r2" not in captured.err and "par" in captured.out  # results stay on stdout


@pytest.mark.parametrize(
    ("data", "test", "option"), [("train", "empty", "--test"), ("empty", "test", "--data")]
)
def test_train_refuses_an_empty_table_in_one_line(tables, tmp_path, capsys, data, test, option):
    out = tmp_path / "models"
    code = main(["train", "--data", str(tables[data]), "--test", str(tables[test]), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    expected = f"{tables['empty']}: the table has no rows; give {option} a table ingested from logs"
    assert err.splitlines() == [f"error: {expected} with moves"]
    assert not out.exists()


def test_train_library_refuses_empty_tables(tables, tmp_path):
    full, test, empty = tables["tables"]
    with pytest.raises(InvalidInput, match="the test table has no rows"):
        train(full, empty, TrainConfig(families=("par",), cv=2), tmp_path / "m")
    with pytest.raises(InvalidInput, match="the training table has no rows"):
        train(empty, test, TrainConfig(families=("par",), cv=2), tmp_path / "m")
    assert not (tmp_path / "m").exists()


def test_train_reports_search_progress_as_numbers(tables, tmp_path):
    """Progress bars get (family, target, done, total) without parsing the messages."""
    full, test, _ = tables["tables"]
    events, messages = [], []
    train(
        full,
        test,
        TrainConfig(families=("par",), cv=2),
        tmp_path / "m",
        progress=messages.append,
        on_search=lambda *event: events.append(event),
    )
    assert events[0] == ("par", "E", 0, 4) and events[-1] == ("par", "E", 4, 4)
    assert [e[2] for e in events] == [0, 1, 2, 3, 4]
    assert len([m for m in messages if re.match(r"par E: \d/4 candidates", m)]) == len(events)


@pytest.fixture(scope="module")
def generic_tables(tmp_path_factory):
    """Generic joint logs (t, q, dq, tau, move in SI) of an arm joulepath is told nothing about,
    ingested with the defaults (no --robot): the joint-only tables a user of another arm makes."""
    import numpy as np

    from joulepath.data import read_log

    d = tmp_path_factory.mktemp("generic")
    tables = {}
    for name, n_moves, seed in (("train", 10, 5), ("test", 4, 6)):
        sim = simulate(d / f"{name}-ctl.csv", plant="lab", n_moves=n_moves, seed=seed)
        log = read_log(sim.log)
        cols = ["t"] + [f"{p}{i}" for i in range(1, 7) for p in ("q", "dq", "tau")]
        data = [log.t] + [a[:, i] for i in range(6) for a in (log.q, log.qd, log.tau)]
        csv = d / f"{name}.csv"
        np.savetxt(csv, np.column_stack(data), delimiter=",", header=",".join(cols), comments="", fmt="%.9g")
        out = d / f"{name}.parquet"
        assert main(["ingest", str(csv), "--out", str(out)]) == 0
        tables[name] = out
    return tables


def test_train_a_generic_log_with_the_defaults(generic_tables, tmp_path, capsys):
    """No robot known: the kinematic inputs, one line saying so, the held-out R² on stdout and on the
    card beside the CV estimate."""
    import json

    import numpy as np

    from joulepath.data import load_table
    from joulepath.learn import NO_ROBOT_NOTE

    assert load_table(generic_tables["train"]).robot is None
    capsys.readouterr()
    out = tmp_path / "models"
    argv = ["train", "--data", str(generic_tables["train"]), "--test", str(generic_tables["test"])]
    code = main([*argv, "--family", "par", "--cv", "2", "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert captured.err.splitlines().count(NO_ROBOT_NOTE) == 1
    assert "--robot" in NO_ROBOT_NOTE and "kinematic inputs" in NO_ROBOT_NOTE
    card = json.loads((out / "par-E" / "card.json").read_text())
    assert card["inputs"] == "kinematic" and card["inputs_reason"] == "default: no robot known"
    assert card["cv_grouped"]["groups"] == "move"  # a table of one log
    assert card["cv_vs_held_out"]["held_out_r2"] == card["test"]["r2"]
    assert card["cv_vs_held_out"]["cv_r2"] == card["cv_grouped"]["r2_mean"]
    header = next(line for line in captured.out.splitlines() if "test_r2" in line).split()
    row = next(line for line in captured.out.splitlines() if line.split()[:2] == ["par", "E"]).split()
    held_out = float(row[header.index("test_r2")])
    assert held_out == pytest.approx(card["test"]["r2"], abs=1e-4)  # the card's held-out score, shown
    assert np.isfinite(held_out) and held_out <= 1.0
    assert card["test"]["n_moves"] == load_table(generic_tables["test"]).n_moves == 4


def test_train_physics_inputs_without_a_robot_names_both_ways_out(generic_tables, tmp_path, capsys):
    out = tmp_path / "models"
    argv = ["train", "--data", str(generic_tables["train"]), "--test", str(generic_tables["test"])]
    assert main([*argv, "--inputs", "physics", "--family", "par", "--cv", "2", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--robot" in err[0] and "--inputs thesis" in err[0], err
    assert not out.exists()
