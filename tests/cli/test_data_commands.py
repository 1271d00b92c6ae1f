import pandas as pd

from joulepath.cli import main
from joulepath.data import load_table


def test_rapid_collect(tmp_path, capsys):
    assert main(["rapid", "collect", "--out", str(tmp_path), "--moves", "20", "--mode", "table"]) == 0
    assert (tmp_path / "JPCollect.mod").read_text().startswith("MODULE JPCollect")
    assert (tmp_path / "JPMeasure.mod").exists()


def test_rapid_collect_unknown_range_set(tmp_path, capsys):
    assert main(["rapid", "collect", "--out", str(tmp_path), "--range-set", "nowhere"]) == 2
    assert "has no range set 'nowhere'" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_simulate_then_ingest(tmp_path, capsys):
    log = tmp_path / "lab.csv"
    assert main(["simulate", "--plant", "lab", "--moves", "8", "--seed", "3", "--out", str(log)]) == 0
    assert log.exists() and (tmp_path / "lab.moves.csv").exists()
    table = tmp_path / "lab.parquet"
    assert main(["ingest", str(log), "--out", str(table), "--robot", "irb120"]) == 0
    out = capsys.readouterr().out
    assert "feature set full40 (40 inputs)" in out
    assert load_table(table).n_moves >= 6


def test_simulate_plan_small(tmp_path):
    from joulepath.sim import simulate_plan

    plan = (("real", "lab", 6), ("sim", "sim", 6), ("micro", "lab", 3), ("test", "lab", 3))
    results = simulate_plan(tmp_path, seed=1, plan=plan, workers=2)
    assert [r["name"] for r in results] == ["real", "sim", "micro", "test"]
    for name in ("real", "sim", "micro", "test"):
        assert (tmp_path / "logs" / f"{name}.csv").exists()
        assert len(pd.read_parquet(tmp_path / f"{name}.parquet")) > 0
    micro = (tmp_path / "logs" / "micro.csv").read_text()
    test = (tmp_path / "logs" / "test.csv").read_text()
    assert micro != test


def test_simulate_unknown_plan_and_plant(tmp_path, capsys):
    assert main(["simulate", "--plan", "big", "--out", str(tmp_path)]) == 2
    assert "unknown plan 'big'" in capsys.readouterr().err
    assert main(["simulate", "--plant", "real", "--moves", "2", "--out", str(tmp_path / "x.csv")]) == 2
    assert "unknown plant 'real'" in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()


def test_ingest_missing_file(tmp_path, capsys):
    assert main(["ingest", str(tmp_path / "none.csv"), "--out", str(tmp_path / "t.parquet")]) == 2
    err = capsys.readouterr().err
    assert "none.csv: cannot be read" in err and len(err.strip().splitlines()) == 1
