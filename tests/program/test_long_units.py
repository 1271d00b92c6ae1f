"""No fixed size limit refuses a valid program (issue 47, item 6): a unit longer than the move_s limit
(a slow move, a long fly-by chain) is kept as taught and said, and the rest of the cycle is optimized."""

from __future__ import annotations

import json

from joulepath.cli import main

PROGRAM = """MODULE LongMove
  CONST jointtarget jA := [[-60, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget jB := [[60, 20, 0, 20, 50, 30], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget jC := [[0, 30, -10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    MoveAbsJ jA, v1000, fine, tool0;
    MoveAbsJ jB, v1000 \\T:={seconds}, fine, tool0;
    MoveAbsJ jC, v1000, fine, tool0;
  ENDPROC
ENDMODULE
"""
FAST = ["--export", "egm", "--table-points", "2", "--knot-spacing", "0.1"]


def test_a_move_longer_than_the_limit_is_kept_and_the_others_optimized(tmp_path, capsys):
    prog = tmp_path / "long.mod"
    prog.write_text(PROGRAM.format(seconds=12))
    assert main(["cycle", str(prog), "--out", str(tmp_path / "run"), *FAST]) == 0
    data = json.loads((tmp_path / "run" / "cycle.json").read_text())
    assert data["long_units"] == [7]
    assert data["saved_pct"] > 0  # the two other moves
    assert "kept as taught, longer than the 10 s" in capsys.readouterr().out


def test_the_limit_is_the_variable_s(tmp_path, monkeypatch):
    prog = tmp_path / "long.mod"
    prog.write_text(PROGRAM.format(seconds=3))
    monkeypatch.setenv("JOULEPATH_MAX_MOVE_S", "2.5")
    assert main(["cycle", str(prog), "--out", str(tmp_path / "run"), *FAST]) == 0
    assert json.loads((tmp_path / "run" / "cycle.json").read_text())["long_units"] == [7]
