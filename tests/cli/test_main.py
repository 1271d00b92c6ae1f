import pytest

from joulepath.cli import main


def test_main_robot_show_bundled(capsys):
    assert main(["robot", "show", "irb120"]) == 0
    out = capsys.readouterr().out
    assert "ABB IRB 120" in out and "(374.0, 0.0, 630.0) mm" in out
    assert "physical check: 0 error(s), 2 warning(s)" in out
    assert "torque N·m" in out and "no torque (effort) limit" in out


def test_main_robot_show_appendix_c_lists_problems(capsys, appendix_c_path):
    assert main(["robot", "show", str(appendix_c_path)]) == 0
    out = capsys.readouterr().out
    assert "is a rotation matrix" in out and "repeats joint 5" in out
    assert main(["robot", "show", str(appendix_c_path), "--strict"]) == 1


def test_main_robot_show_urdf(capsys):
    from joulepath.description import preset_path

    assert main(["robot", "show", str(preset_path("irb120", fmt="urdf"))]) == 0
    assert "(374.0, 0.0, 630.0) mm" in capsys.readouterr().out


def test_main_bad_file_is_one_line_exit_2(capsys, tmp_path):
    bad = tmp_path / "bad.irml"
    bad.write_text("<robot><name>x</name><joint id='1'><type>Q</type></joint></robot>")
    assert main(["robot", "show", str(bad)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and "bad.irml: joint 1 <type>: unknown joint type 'Q'" in lines[0]
    assert "Traceback" not in captured.err


def test_main_debug_shows_traceback(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        main(["robot", "show", str(tmp_path / "x.irml"), "--debug"])


def test_main_robot_fk(capsys):
    assert main(["robot", "fk", "irb120", "--q", "0,0,0,0,0,0"]) == 0
    assert "374.000 0.000 630.000" in capsys.readouterr().out
    assert main(["robot", "fk", "irb120", "--q", "0,90,0,0,0,0", "--degrees"]) == 0
    assert "340.000 0.000 -84.000" in capsys.readouterr().out


def test_main_robot_fk_bad_joints(capsys):
    assert main(["robot", "fk", "irb120", "--q", "1,2,3"]) == 2
    assert "expected 6 joint values, got 3" in capsys.readouterr().err
    assert main(["robot", "fk", "irb120", "--q", "a,b,c,d,e,f"]) == 2


def test_main_version_and_unknown_command(capsys):
    assert main(["--version"]) == 0
    assert "joulepath 0.1.0" in capsys.readouterr().out
    assert main(["frobnicate"]) == 2


def _zero_axis_urdf(tmp_path):
    from joulepath.description import preset_path

    text = preset_path("irb120", fmt="urdf").read_text()
    path = tmp_path / "zero_axis.urdf"
    path.write_text(text.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>', 1))
    return path


def test_main_robot_show_reports_what_other_commands_refuse(capsys, tmp_path):
    bad = _zero_axis_urdf(tmp_path)
    assert main(["robot", "show", str(bad)]) == 0
    out = capsys.readouterr().out
    assert "physical check: 1 error(s)" in out and "<axis>: rotation axis [0, 0, 0] is zero" in out
    assert "experts can use it with --unchecked" in out


def test_main_robot_fk_refuses_an_unphysical_robot_unless_unchecked(capsys, tmp_path):
    bad = _zero_axis_urdf(tmp_path)
    assert main(["robot", "fk", str(bad), "--q", "0,0,0,0,0,0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "fails the physical check" in err[0] and "is zero" in err[0]
    assert main(["robot", "fk", str(bad), "--q", "0,0,0,0,0,0", "--unchecked"]) == 0
    captured = capsys.readouterr()
    assert "374.000 0.000 630.000" in captured.out
    assert captured.err.startswith("warning: --unchecked:") and "is zero" in captured.err


def test_main_optimize_refuses_an_unphysical_robot_and_writes_nothing(capsys, tmp_path):
    from joulepath.description import preset_path

    text = preset_path("irb120", fmt="urdf").read_text()
    bad = tmp_path / "negative_mass.urdf"
    bad.write_text(text.replace('<mass value="3.909"/>', '<mass value="-3.909"/>', 1))
    out = tmp_path / "out"
    argv = ["optimize", "--start", "0,0,0,0,0,0", "--end", "0.5,0,0,0,0,0", "--duration", "1"]
    argv += ["--fitness", "physics", "--robot", str(bad), "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "mass -3.909 kg is not positive" in err[0]
    assert not out.exists()


def test_main_demo_and_run_demo_and_make_demo_share_one_folder(monkeypatch, tmp_path):
    import re
    from pathlib import Path

    import joulepath.experiment

    folders = []

    def fake_run(exp, folder, **_kwargs):
        folders.append(Path(folder))
        return {"mean_saved_pct": None, "report": str(Path(folder) / "report.html")}

    monkeypatch.setattr(joulepath.experiment, "run_experiment", fake_run)
    monkeypatch.chdir(tmp_path)
    assert main(["demo", "--quiet"]) == 0
    assert main(["run", "demo", "--quiet"]) == 0
    assert main(["run", "study", "--quiet"]) == 0  # the bundled larger study
    assert folders == [Path("runs/demo"), Path("runs/demo"), Path("runs/study")]
    makefile = (Path(__file__).parents[2] / "Makefile").read_text()
    recipe = re.search(r"^demo:.*\n((?:\t.*\n)+)", makefile, re.M)
    assert recipe is not None
    assert "joulepath run demo\n" in recipe[1] and "--out" not in recipe[1]
    assert "runs/demo/report.html" in recipe[1]


def test_main_error_line_names_files_of_a_deep_folder_within_300_characters(capsys, tmp_path, monkeypatch):
    """Two modules of one name in a task given by a long absolute path: the one error line stays
    within 300 characters and still names both files (their last parts)."""
    deep = tmp_path.joinpath(*(f"a_rather_long_folder_name_{k}" for k in range(6)), "TASK1", "PROGMOD")
    deep.mkdir(parents=True)
    body = "MODULE MainModule\nPROC main()\n  WaitTime 1;\nENDPROC\nENDMODULE\n"
    (deep / "first.mod").write_text(body)
    (deep / "second.mod").write_text(body)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    task = deep.parent
    assert len(str(task)) > 150
    assert main(["cycle", str(task), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:")
    assert len(err[0]) <= 300, err[0]
    assert "first.mod" in err[0] and "second.mod" in err[0]
    assert "MainModule" in err[0]
    assert not (tmp_path / "out").exists()


def test_short_paths_keeps_a_short_line_and_shortens_paths_of_a_long_one():
    from joulepath.cli._main import short_paths

    line = "error: /x/y.mod:3: a name declared twice"
    assert short_paths(line) == line
    long_path = "/" + "/".join(f"part{k:02d}_of_a_long_path" for k in range(12)) + "/m.mod"
    text = f"error: {long_path}:4: one thing; {long_path}:9: another"
    out = short_paths(text)
    assert len(out) < 300 < len(text)
    assert out.count("part11_of_a_long_path/m.mod:") == 2


def test_short_paths_names_files_by_their_name_where_three_parts_are_too_long():
    from joulepath.cli._main import short_paths

    where = "/" + "/".join(f"folder{k:02d}_of_a_long_name" for k in range(8)) + "/Module.mod:12"
    names = ", ".join(f"Routine{k:03d}" for k in range(16))
    text = f"error: {where}: the cycle holds no move; give --routine NAME, one of: {names}; fix it so"
    out = short_paths(text)
    assert len(out) <= 300 < len(text)
    assert out.startswith("error: …/Module.mod:12: the cycle holds no move")
    assert out.endswith(f"{names}; fix it so")
