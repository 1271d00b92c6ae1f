"""A task as published is often one of several: its ``PERS`` data declared without a value are another
task's (a socket server, a PLC-fed task), and the branches it takes on them run on stand-ins. Such a
program is read with each assumption said, never refused for what only the stand-in got wrong."""

from __future__ import annotations

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.errors import RapidError
from joulepath.program import read_cycle_program

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
HEAD = f"""MODULE Server
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], {EXT}];
    CONST robtarget pA := [[400, 0, 400], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    CONST robtarget pB := [[400, 150, 350], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
"""


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


def _read(tmp_path, robot, text, **kw):
    path = tmp_path / "server.mod"
    path.write_text(HEAD + text + "ENDMODULE\n")
    spec, _ = read_cycle_program(path, robot, **kw)
    return spec


def _moves(spec):
    return [s for s in spec.steps if s.kind == "move"]


def test_a_shared_tool_and_speed_take_the_stated_stand_ins_and_the_moves_are_optimized(tmp_path, robot):
    moves = """    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveJ pA, {speed}, z10, {tool};
        MoveL pB, v500, fine, {tool};
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
"""
    shared = _read(
        tmp_path,
        robot,
        "    PERS speeddata vShared;\n    PERS tooldata tShared;\n"
        + moves.format(speed="vShared", tool="tShared"),
    )
    plain = _read(tmp_path, robot, moves.format(speed="v1000", tool="tool0"))
    said = {a.name: a for a in shared.assumed}
    assert set(said) == {"vShared", "tShared"}
    assert said["tShared"].role == "tooldata" and said["tShared"].shared
    assert "PERS declared without a value" in said["tShared"].line()
    assert "tool0's frame" in said["tShared"].value
    # the stand-in tool is tool0's frame: the same joints as the program written with tool0
    for a, b in zip(_moves(shared), _moves(plain), strict=True):
        np.testing.assert_allclose(a.q, b.q, atol=1e-12)
    assert not shared.kept  # a stated stand-in, not a run-time value: the moves are optimized


def test_a_shared_target_is_unknown_and_the_scenario_gives_it(tmp_path, robot):
    text = """    PERS robtarget pShared;
    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveJ pA, v1000, z10, tool0;
        MoveJ pShared, v1000, fine, tool0;
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
"""
    spec = _read(tmp_path, robot, text)
    kept = dict(spec.kept)
    assert any("pShared is a PERS declared without a value" in why for why in kept.values())
    given = {"pshared": f"[[400, 150, 350], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}]"}  # as the scenario gives it
    known = _read(tmp_path, robot, text, given=given)
    assert not known.kept
    reference = _read(tmp_path, robot, text.replace("PERS robtarget pShared;", "").replace("pShared", "pB"))
    np.testing.assert_allclose(_moves(known)[2].q, _moves(reference)[2].q, atol=1e-12)


def test_a_branch_on_a_shared_value_reads_its_buffers_as_stand_ins_not_as_errors(tmp_path, robot):
    spec = _read(
        tmp_path,
        robot,
        """    PERS num nCommand;
    VAR robtarget buffer{8};
    VAR speeddata speeds{8};
    VAR num nBuffered := 0;
    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveJ pA, v1000, z10, tool0;
        IF nCommand = 2 THEN
            MoveL buffer{nBuffered}, speeds{nBuffered}, z10, tool0;
            MoveL RelTool(buffer{nBuffered}, 0, 0, -5), v100, fine, tool0;
        ENDIF
        MoveJ pB, v1000, fine, tool0;
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
""",
    )
    notes = "\n".join(spec.choices)
    assert "an index in a branch taken on run-time data" in notes
    assert "RelTool of a stand-in value fails" in notes
    kept = [label for label, _ in spec.kept]
    assert len(kept) >= 2 and all("buffer" in label or "RelTool" in label or "pB" in label for label in kept)


def test_the_same_index_error_outside_any_run_time_branch_is_refused(tmp_path, robot):
    with pytest.raises(RapidError, match=r"index 0 outside 1\.\.8; correct the index"):
        _read(
            tmp_path,
            robot,
            """    VAR robtarget buffer{8};
    VAR num nBuffered := 0;
    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveL buffer{nBuffered}, v1000, z10, tool0;
    ENDPROC
""",
        )


def test_a_server_whose_every_target_arrives_from_another_task_is_refused_naming_where(tmp_path, capsys):
    path = tmp_path / "server.mod"
    path.write_text(
        HEAD
        + """    PERS jointtarget jShared;
    PERS num nCommand;
    PROC main()
        WHILE TRUE DO
            IF nCommand = 1 THEN
                MoveAbsJ jShared, v1000, fine, tool0;
            ENDIF
        ENDWHILE
    ENDPROC
ENDMODULE
"""
    )
    assert main(["cycle", str(path), "--out", str(tmp_path / "out"), "--export", "egm"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no move of the cycle can be planned: its targets are unknown" in err[0]
    assert "(they come from jShared, PERS data declared without a value" in err[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("conf_j", ["On", "Off"])
def test_a_joint_move_goes_to_the_programmed_configuration_with_confj_on_and_off(tmp_path, robot, conf_j):
    """ABB: with ``ConfJ \\Off`` the robot moves to the closest configuration, which differs from the
    programmed one only where that is wrong; a programmed one that is reachable is taken, although
    another turn of axis 6 lies nearer the arm."""
    from joulepath.kinematics import confdata

    q = np.radians([10.0, 20.0, 10.0, 30.0, 40.0, 30.0])
    pose = robot.fk(q)
    p, r = pose.position_mm, pose.quaternion
    cf = [int(c) for c in confdata(robot.chain, q)]
    target = f"[[{p[0]:.6f}, {p[1]:.6f}, {p[2]:.6f}], [{', '.join(f'{x:.9f}' for x in r)}], {cf}, {EXT}]"
    spec = _read(
        tmp_path,
        robot,
        f"""    CONST robtarget pT := {target};
    CONST jointtarget jFar := [[10, 20, 10, 30, 40, 330], {EXT}];
    PROC main()
        ConfJ \\{conf_j};
        MoveAbsJ jFar, v1000, fine, tool0;
        MoveJ pT, v1000, fine, tool0;
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
""",
    )
    np.testing.assert_allclose(_moves(spec)[1].q, q, atol=1e-6)  # axis 6 at 30 deg, not at 390 deg


def test_a_speed_declared_nowhere_that_the_task_sets_is_a_variable_stand_in(tmp_path, robot):
    """A name declared nowhere whose component the task assigns (in a routine it calls) is data the task
    owns: a stand-in variable that the assignment changes, not a constant it may not assign."""
    spec = _read(
        tmp_path,
        robot,
        """    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveJ pA, vCell, fine, tool0;
        SlowDown;
        MoveL pB, vCell, fine, tool0;
    ENDPROC
    PROC SlowDown()
        vCell.v_tcp := 100;
    ENDPROC
""",
    )
    assert [(a.name, a.role) for a in spec.assumed] == [("vCell", "speeddata")]
    moves = _moves(spec)
    assert moves[1].speed is not None and moves[2].speed is not None
    assert moves[2].speed.v_tcp == pytest.approx(100.0) and moves[1].speed.v_tcp == pytest.approx(
        1000.0
    )  # mm/s


ARC = "[5,0,24,120,0,0,0,0,0]"
SEAM = f"[0.5,0.5,{ARC},1,0,0,0,0,[0,0,0,0,0,0,0,0,0],0,1,{ARC},0,0,[0,0,0,0,0,0,0,0,0],0]"


def test_an_options_data_components_and_an_egm_move_are_read_not_refused(tmp_path, robot):
    """Arc's ``seamdata`` carried whole (its components set in a program: not modelled, said), and
    ``EGMMoveL``: a linear move whose path a sensor corrects through EGM while it runs (kept)."""
    spec = _read(
        tmp_path,
        robot,
        f"""    PERS seamdata seams{{2}} := [{SEAM}, {SEAM}];
    VAR egmident egmId;
    PROC main()
        seams{{2}}.ign_move_delay := 2;
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveJ pA, v1000, fine, tool0;
        EGMGetId egmId;
        EGMMoveL egmId, pB, v100, fine, tool0;
        MoveJ pA, v1000, fine, tool0;
    ENDPROC
""",
    )
    assert any("seams.ign_move_delay: a component of seamdata" in c for c in spec.choices)
    labels = [s.label for s in _moves(spec)]
    assert labels == ["MoveAbsJ jHome", "MoveJ pA", "EGMMoveL pB", "MoveJ pA"]
    kept = dict(spec.kept)
    assert any("corrected by a sensor through EGM" in why for why in kept.values())


def test_a_cycle_that_does_not_move_on_its_stand_in_inputs_names_them(tmp_path, capsys):
    path = tmp_path / "cell.mod"
    path.write_text(
        HEAD
        + """    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        IF DInput(diPalletA) = 1 THEN
            WaitTime 0.5;
        ENDIF
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""
    )
    assert main(["cycle", str(path), "--out", str(tmp_path / "out"), "--export", "egm"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "the cycle does not move the arm" in err[0]
    assert "it reads inputs taken as 0 (diPalletA): where they choose its work, give them with --io" in err[0]
