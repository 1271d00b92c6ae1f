"""Loops that spin on what the world outside the task sets (an HMI, a PLC, an operator, another task):
a turn that leaves every datum as it found it would repeat for ever, so the loop is taken to end (moving
nothing) or to be the production loop (moving); loops that change data, or draw random numbers, run
as written."""

from __future__ import annotations

import numpy as np
import pytest

import joulepath
from joulepath.program import read_cycle_program

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
HEAD = f"""MODULE Cell
    CONST jointtarget jA := [[10, 0, 0, 0, 30, 0], {EXT}];
    CONST jointtarget jB := [[40, 20, -10, 15, 45, 30], {EXT}];
    CONST jointtarget jC := [[-30, 10, 10, 0, 20, -20], {EXT}];
"""


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


def _read(tmp_path, robot, text):
    path = tmp_path / "cell.mod"
    path.write_text(HEAD + text + "ENDMODULE\n")
    spec, _ = read_cycle_program(path, robot)
    labels = [s.label for s in spec.steps if s.kind == "move"]
    return spec, labels


def test_an_hmi_start_handshake_and_a_pattern_check_end_and_the_cycle_moves(tmp_path, robot):
    spec, labels = _read(
        tmp_path,
        robot,
        """    PERS bool hmiStart := TRUE;
    PERS num hmiCount := 0;
    VAR num entered := 0;
    PROC Handler()
        IF hmiCount > entered THEN
            entered := hmiCount;
        ENDIF
    ENDPROC
    FUNC bool Valid()
        RETURN entered > 0;
    ENDFUNC
    PROC WaitForPattern()
        VAR bool ready;
        ready := FALSE;
        hmiStart := FALSE;
        WHILE NOT ready DO
            WHILE NOT hmiStart DO
                Handler;
                WaitTime 0.1;
            ENDWHILE
            Handler;
            IF Valid() THEN
                ready := TRUE;
            ELSE
                hmiStart := FALSE;
            ENDIF
        ENDWHILE
    ENDPROC
    PROC main()
        WHILE TRUE DO
            WaitForPattern;
            MoveAbsJ jA, v1000, fine, tool0;
            MoveAbsJ jB, v1000, fine, tool0;
        ENDWHILE
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB"]
    spins = [c for c in spec.choices if "WHILE spins, moving nothing" in c]
    assert spins and all("assumed to end after" in c for c in spins)


def test_a_loop_that_repeats_the_same_moving_turn_is_the_production_loop(tmp_path, robot):
    spec, labels = _read(
        tmp_path,
        robot,
        """    VAR bool stopReq := FALSE;
    VAR bool fault := FALSE;
    PROC main()
        MoveAbsJ jC, v1000, fine, tool0;
        WHILE stopReq = FALSE AND fault = FALSE DO
            MoveAbsJ jA, v1000, z10, tool0;
            MoveAbsJ jB, v1000, fine, tool0;
        ENDWHILE
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB"]
    assert any("taken as the production loop" in c for c in spec.choices)
    np.testing.assert_allclose(np.degrees(spec.start), [40, 20, -10, 15, 45, 30], atol=1e-9)


def test_a_counting_loop_runs_every_turn(tmp_path, robot):
    spec, labels = _read(
        tmp_path,
        robot,
        """    VAR num i := 0;
    PROC main()
        WHILE TRUE DO
            i := 0;
            WHILE i < 50 DO
                i := i + 1;
            ENDWHILE
            IF i = 50 THEN
                MoveAbsJ jA, v1000, fine, tool0;
            ENDIF
            MoveAbsJ jB, v1000, fine, tool0;
        ENDWHILE
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB"]
    assert not any("WHILE spins" in c for c in spec.choices)


def test_a_loop_that_draws_random_numbers_is_not_cut(tmp_path, robot):
    spec, labels = _read(
        tmp_path,
        robot,
        """    VAR bool found := FALSE;
    PROC main()
        WHILE TRUE DO
            found := FALSE;
            WHILE NOT found DO
                IF Rand() > 0.9 THEN
                    found := TRUE;
                ENDIF
            ENDWHILE
            IF found THEN
                MoveAbsJ jA, v1000, fine, tool0;
            ENDIF
            MoveAbsJ jB, v1000, fine, tool0;
        ENDWHILE
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB"]
    assert not any("WHILE spins" in c for c in spec.choices)


def test_an_operator_retry_written_with_goto_is_assumed_to_end_and_the_cycle_moves(tmp_path, robot):
    spec, labels = _read(
        tmp_path,
        robot,
        """    PROC CheckGripper()
        VAR btnres answer;
        ask:
        IF DInput(diGripperOk) = 0 THEN
            answer := UIMessageBox(\\Header:="Gripper", \\BtnArray:=["", "", "", "", "OK"]);
            GOTO ask;
        ENDIF
    ENDPROC
    PROC main()
        MoveAbsJ jA, v1000, fine, tool0;
        CheckGripper;
        MoveAbsJ jB, v1000, fine, tool0;
        MoveAbsJ jC, v1000, fine, tool0;
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB", "MoveAbsJ jC"]
    assert any(
        "GOTO ask jumps back, moving nothing" in c and "assumed to end after" in c for c in spec.choices
    )


def test_a_goto_loop_that_counts_runs_as_written(tmp_path, robot):
    spec, labels = _read(
        tmp_path,
        robot,
        """    PROC main()
        VAR num k := 0;
        again:
        k := k + 1;
        IF k < 50 THEN
            GOTO again;
        ENDIF
        MoveAbsJ jA, v1000, fine, tool0;
        IF k = 50 MoveAbsJ jB, v1000, fine, tool0;
        MoveAbsJ jC, v1000, fine, tool0;
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB", "MoveAbsJ jC"]
    assert not any("jumps back, moving nothing" in c for c in spec.choices)


def test_a_while_true_that_a_function_returns_from_is_a_wait_for_an_answer_not_the_cycle(tmp_path, robot):
    """An operator's menu: ``WHILE TRUE`` until a valid answer, then ``RETURN`` it. Not the production
    loop (it is left by its RETURN): the answer is assumed to come, and the moves after it run."""
    spec, labels = _read(
        tmp_path,
        robot,
        """    VAR num mode;
    FUNC num AskMode()
        VAR num key;
        WHILE TRUE DO
            TPReadFK key, "Mode?", "A", "B", stEmpty, stEmpty, stEmpty;
            IF key = 1 OR key = 2 THEN
                RETURN key;
            ENDIF
        ENDWHILE
    ENDFUNC
    PROC main()
        MoveAbsJ jA, v1000, fine, tool0;
        mode := AskMode();
        MoveAbsJ jB, v1000, fine, tool0;
        MoveAbsJ jC, v1000, fine, tool0;
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB", "MoveAbsJ jC"]  # the answer came: it returned


def test_an_exitcycle_first_run_starts_main_again_with_its_data_kept(tmp_path, robot):
    """A first run that sets a flag and breaks the cycle (``ExitCycle``): the controller starts main
    again, data kept, and that run is the cycle; an ExitCycle after moves ends the cycle there."""
    spec, labels = _read(
        tmp_path,
        robot,
        """    PERS bool bFirstDone := FALSE;
    PROC main()
        IF bFirstDone = FALSE THEN
            bFirstDone := TRUE;
            ExitCycle;
        ENDIF
        MoveAbsJ jA, v1000, fine, tool0;
        MoveAbsJ jB, v1000, fine, tool0;
        ExitCycle;
        MoveAbsJ jC, v1000, fine, tool0;
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB"]
    assert any("before any move: main starts again" in c for c in spec.choices)


def test_an_error_flag_of_an_operators_read_is_no_error_of_any_kind(tmp_path, robot):
    """``\\BreakFlag`` of an operator's read gives an errnum known only at run time; its stand-in (0, no
    error) equals no ``ERR_`` constant, so the alarm branch that ends the program is not taken."""
    spec, labels = _read(
        tmp_path,
        robot,
        """    VAR num answer;
    PROC main()
        VAR errnum errvar;
        MoveAbsJ jA, v1000, fine, tool0;
        TPReadFK answer, "Mode?", "Run", stEmpty, stEmpty, stEmpty, stEmpty \\BreakFlag:=errvar;
        IF errvar = ERR_TP_MAXTIME EXIT;
        IF ERR_TP_MAXTIME = ERR_TP_DIBREAK EXIT;
        MoveAbsJ jB, v1000, fine, tool0;
        MoveAbsJ jC, v1000, fine, tool0;
    ENDPROC
""",
    )
    assert labels == ["MoveAbsJ jA", "MoveAbsJ jB", "MoveAbsJ jC"]


def test_a_menu_that_shows_itself_again_is_left_not_recursed_for_ever(tmp_path, robot):
    spec, labels = _read(
        tmp_path,
        robot,
        """    VAR num answer;
    PROC ServiceMenu()
        TPReadFK answer, "Service", "Home", "Back", stEmpty, stEmpty, stEmpty;
        IF answer = 1 THEN
            MoveAbsJ jC, v1000, fine, tool0;
            ServiceMenu;
        ENDIF
    ENDPROC
    PROC main()
        MoveAbsJ jA, v1000, fine, tool0;
        ServiceMenu;
        MoveAbsJ jB, v1000, fine, tool0;
    ENDPROC
""",
    )
    assert labels[0] == "MoveAbsJ jA" and labels[-1] == "MoveAbsJ jB"
    assert any("ServiceMenu calls itself again from a choice made at run time" in c for c in spec.choices)
