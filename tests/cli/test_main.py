import pytest

from joulepath.cli import main


def test_main_robot_show_bundled(capsys):
    assert main(["robot", "show", "irb120"]) == 0
    out = capsys.readouterr().out
    assert "ABB IRB 120" in out and "(374.0, 0.0, 630.0) mm" in out
    assert "physical check: 0 error(s), 1 warning(s)" in out


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
