"""A partial task (issue 47, item 1): what it declares nowhere gets a stand-in by its role, said a line
each; the scenario file gives the real values, and then the cycle is the whole task's."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.errors import InvalidInput
from joulepath.program import read_cycle_program, read_scenario, scenario_from_dict

TASK = Path(__file__).parents[2] / "examples" / "cell_task"
MAIN = TASK / "RAPID" / "TASK1" / "PROGMOD" / "MainModule.mod"


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


def test_the_scenario_file_gives_a_partial_task_the_whole_tasks_cycle(robot):
    full, _ = read_cycle_program([TASK], robot, io=read_scenario(TASK / "scenario.toml").io)
    given = read_scenario(TASK / "partial.toml")
    partial, _ = read_cycle_program([MAIN], robot, io=given.io, given=given.given)
    assert {a.name for a in partial.assumed} == {"tGripper", "wInfeed", "wFixture", "jHome", "lPart"}
    assert all(a.value == "the scenario's value" for a in partial.assumed)
    assert not full.assumed
    a = [s for s in full.steps if s.kind == "move"]
    b = [s for s in partial.steps if s.kind == "move"]
    assert len(a) == len(b) and len(a) > 4
    for x, y in zip(a, b, strict=True):  # the same joints, TCP and load as read from CellData.sys
        assert np.allclose(x.q, y.q, atol=1e-12)
        assert np.allclose(x.tcp, y.tcp, atol=1e-12)
        assert x.robot.payload == y.robot.payload or np.isclose(
            x.robot.payload.mass if x.robot.payload else 0.0, y.robot.payload.mass if y.robot.payload else 0.0
        )


def test_without_its_frames_no_move_can_be_planned_and_the_line_says_why(tmp_path, capsys):
    code = main(["cycle", str(MAIN), "--out", str(tmp_path / "out"), "--export", "egm"])
    lines = [ln for ln in capsys.readouterr().err.strip().splitlines() if not ln.startswith("[")]
    assert code == 2 and len(lines) == 1  # (progress lines aside, on a slow machine)
    err = lines[0]
    assert "Traceback" not in err and len(err) < 400
    assert "no move of the cycle can be planned" in err and "wInfeed" in err and "scenario file" in err
    assert not (tmp_path / "out").exists()


PARTIAL = """MODULE Partial
  CONST robtarget pA := [[380,-120,260],[0,0,1,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pB := [[380,140,300],[0,0,1,0],[0,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    WHILE TRUE DO
      MoveJ pA, vFast, z20, tSuction;
      MoveL Offs(pA, 0, 0, -40), v200, fine, tSuction;
      GripOn;
      MoveL Offs(pA, 0, 0, 60), v500, z10, tSuction;
      MoveJ pB, vFast, fine, tSuction;
      GripOff;
    ENDWHILE
  ENDPROC
ENDMODULE
"""


def test_a_partial_module_gets_a_cycle_with_every_assumption_in_cycle_json(tmp_path, capsys):
    prog = tmp_path / "Partial.mod"
    prog.write_text(PARTIAL)
    out = tmp_path / "run"
    args = ["--export", "egm", "--table-points", "2", "--knot-spacing", "0.1", "--fast"]
    assert main(["cycle", str(prog), "--out", str(out), *args]) == 0
    printed = capsys.readouterr().out
    data = json.loads((out / "cycle.json").read_text())
    roles = {a["name"]: a["role"] for a in data["assumed"]}
    assert roles == {"vFast": "speeddata", "tSuction": "tooldata", "GripOn": "routine", "GripOff": "routine"}
    for a in data["assumed"]:  # name, role, what was taken, where: a line each on the output too
        assert a["at"].startswith(str(prog)) and a["value"]
        assert f"assumed: {a['at']}: {a['name']} ({a['role']})" in printed
    assert data["saved_pct"] > 0 and not data["kept_moves"]


def test_scenario_files_are_checked_in_one_line(tmp_path):
    with pytest.raises(InvalidInput, match=r"\[tool.t\] frame: its quaternion .* is not a unit quaternion"):
        scenario_from_dict({"tool": {"t": {"frame": [0, 0, 0, 2, 0, 0, 0]}}})
    with pytest.raises(InvalidInput, match=r"\[targets\] p: give 7 numbers"):
        scenario_from_dict({"targets": {"p": [1, 2, 3]}})
    with pytest.raises(InvalidInput, match=r"\[tool.t\] mass = -1: give kg"):
        scenario_from_dict({"tool": {"t": {"mass": -1}}})
    s = scenario_from_dict({"diStart": 1, "targets": {"j": {"joints": [0, 0, 0, 0, 30, 0]}}})
    assert s.io == {"diStart": 1.0} and s.given["j"][0] == (0.0, 0.0, 0.0, 0.0, 30.0, 0.0)
