import json

import pytest

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


FIXED = ["--start", "0.3,0.2,-0.4,0.5,-0.6,1.0", "--end", "-0.9,0.6,0.3,-1.2,0.8,-1.5", "--duration", "1.6"]


def test_optimize_jerk_time_refused_in_one_line(tmp_path, capsys):
    for bad in ("-0.1", "11", "nan"):
        assert main(["optimize", *FIXED, "--jerk-time", bad, "--out", str(tmp_path / "run")]) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "jerk_time must be 0..10 s (0: no jerk limit)" in err
    assert not (tmp_path / "run").exists()


def test_optimize_jerk_time_zero_runs_without_a_jerk_limit(tmp_path, capsys):
    """``--jerk-time 0``: the optimizer without a jerk limit, the same search as the library's."""
    import numpy as np

    from joulepath import load_robot
    from joulepath.optimize import OptimizeConfig, optimize_move

    out = tmp_path / "run"
    assert main(["optimize", *FIXED, "--jerk-time", "0", "--export", "egm", "--out", str(out)]) == 0
    data = json.loads((out / "result.json").read_text())
    assert data["jerk_limit_rad_s3"] is None and data["config"]["jerk_time"] == 0
    q0, qf = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0]), np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])
    ref = optimize_move(load_robot("irb120"), q0, qf, 1.6, OptimizeConfig(jerk_time=0.0))
    assert data["energy_optimized_J"] == pytest.approx(ref.summary.energy_optimized_J, rel=1e-9)
    assert data["max_jerk_rad_s3"] > 1000  # what a jerk limit would have removed
    assert "largest jerk" in capsys.readouterr().out


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


def test_optimize_energy_electrical_without_drive_data_is_refused_in_one_line(tmp_path, capsys):
    import shutil

    from joulepath.description import preset_path

    urdf = tmp_path / "arm.urdf"  # the IRB 120 without its drives file beside it
    shutil.copy(preset_path("irb120", fmt="urdf"), urdf)
    out = str(tmp_path / "run")
    args = ["optimize", *FIXED, "--robot", str(urdf), "--energy", "electrical", "--out", out]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert "needs drive data" in err and "arm.drives.toml" in err
    assert not (tmp_path / "run").exists()
    assert main([*args[:-4], "--energy", "meter", "--out", str(tmp_path / "run")]) == 2
    assert "thesis, mechanical, electrical" in capsys.readouterr().err


def test_optimize_command_imports_no_data_frames():
    """`joulepath optimize` reads and writes no tables: its modules import without pandas (a quarter
    of a second of every run's start)."""
    import subprocess
    import sys

    code = (
        "import sys, joulepath.cli._main, joulepath.cli._optimize, joulepath.optimize, joulepath.export, "
        "joulepath.sim; print('pandas' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert out.stdout.strip() == "False"
