import json

from joulepath.cli import main


def test_optimize_physics(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(
        [
            "optimize",
            "--start",
            "-60,10,-30,40,20,0",
            "--end",
            "70,30,10,-50,-40,90",
            "--degrees",
            "--duration",
            "1.5",
            "--fitness",
            "physics",
            "--algo",
            "ga",
            "--generations",
            "15",
            "--population",
            "30",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    assert "saved at equal cycle time" in capsys.readouterr().out
    assert json.loads((out / "result.json").read_text())["fitness"] == "physics"


def test_optimize_user_errors(tmp_path, capsys):
    args = [
        "optimize",
        "--start",
        "0,0,0,0,0,0",
        "--end",
        "0.5,0.1,0,0,0,0",
        "--duration",
        "1.0",
        "--out",
        str(tmp_path),
    ]
    assert main([*args, "--fitness", "surrogate"]) == 2
    assert "needs --model" in capsys.readouterr().err
    assert main([*args, "--fitness", "surrogate", "--model", str(tmp_path)]) == 2
    assert "no models" in capsys.readouterr().err
    assert main([*args[:-4], "--duration", "1.01", "--fitness", "physics", "--out", str(tmp_path)]) == 2
    assert "not a whole number of 0.025 s samples" in capsys.readouterr().err
    assert (
        main(
            [
                "optimize",
                "--start",
                "0,2.5,0,0,0,0",
                "--end",
                "0,0,0,0,0,0",
                "--duration",
                "1",
                "--fitness",
                "physics",
                "--out",
                str(tmp_path),
            ]
        )
        == 2
    )
    assert "outside its range" in capsys.readouterr().err


def test_bench_optimizers_quick_physics(tmp_path, capsys, monkeypatch):
    code = main(
        [
            "bench-optimizers",
            "--tasks",
            "2",
            "--generations",
            "3",
            "--population",
            "8",
            "--jobs",
            "1",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    text = (tmp_path / "optimizers_single.csv").read_text()
    assert "MA informed local search" in text and "GA differential" in text


def test_synth_and_compare_are_registered(capsys):
    assert main(["synth", "--help"]) == 0
    assert main(["compare", "--help"]) == 0
