"""The RAPID integrators write: case, headers, handlers, computed targets, work objects, arguments, branches.

Every expected value is worked out by hand in the comment beside it (not copied from a run).
"""

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.program import RapidError, parse_module, read_cycle_program, resolve_module, write_module

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
# pA: 375 mm in front of the base, 540 mm up, tool pointing down (q = [0, 0, 1, 0]: 180 deg about y)
PA = f"    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];\n"
DOWN = np.diag([-1.0, 1.0, -1.0])  # rotation of the quaternion [0, 0, 1, 0]


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb120")


def _module(body: str, decl: str = "", procs: str = "") -> str:
    return f"MODULE T\n{PA}{decl}    PROC main()\n{body}    ENDPROC\n{procs}ENDMODULE\n"


def _spec(text: str, robot, **kw):
    return resolve_module(parse_module(text, path="t.mod"), robot, **kw)


def _tcp(step) -> tuple[np.ndarray, np.ndarray]:
    """TCP position (mm) and rotation of a move's joint target, by forward kinematics."""
    pose = step.robot.fk(step.q)
    return pose.position_m * 1000 + pose.rotation @ step.tcp[:3, 3] * 1000, pose.rotation @ step.tcp[:3, :3]


def _moves(spec):
    return [s for s in spec.steps if s.kind == "move"]


def _refused(text: str, robot) -> str:
    with pytest.raises(RapidError) as info:
        _spec(text, robot)
    message = str(info.value)
    assert len(message.splitlines()) == 1, message
    return message


# ---------------------------------------------------------------- 1. case, header, ERROR handler
def test_keywords_in_any_case_read_the_same(robot):
    lower = (
        "module t\n" + PA.lower().replace("pa", "pA") + "    proc main()\n"
        "        movej pA, v1000, fine, tool0;\n        MOVEL pA, V200, Z10, TOOL0;\n"
        "        waittime 0.25;\n    endproc\nendmodule\n"
    )
    spec = _spec(lower, robot)
    assert [s.label for s in spec.steps] == ["MoveJ pA", "MoveL pA", "WaitTime 0.25"]
    assert spec.steps[1].speed.v_tcp == 200.0 and spec.steps[1].zone_mm == 10.0
    np.testing.assert_allclose(_tcp(spec.steps[0])[0], [375, 0, 540], atol=1e-6)


def test_saved_module_header_keeps_line_numbers(robot):
    text = "%%%\n  VERSION:1\n  LANGUAGE:ENGLISH\n%%%\n\n" + _module(
        "        MoveJ pA, v1000, fine, tool0;\n"
    )
    spec = _spec(text, robot)
    # 5 header lines, MODULE on 6, pA on 7, PROC on 8: the move is on line 9
    assert _moves(spec)[0].line == 9
    assert write_module(parse_module(text, path="t.mod")) == text


def test_unclosed_header_is_refused():
    with pytest.raises(RapidError, match=r"^t.mod:1: the %%% header is not closed"):
        parse_module("%%%\n  VERSION:1\nMODULE T\nENDMODULE\n", path="t.mod")


def test_error_handler_is_kept_verbatim_and_not_run(robot):
    body = (
        "        MoveJ pA, v1000, fine, tool0;\n    ERROR\n        IF ERRNO = ERR_PATH_STOP THEN\n"
        "            RETRY;\n        ENDIF\n        TRYNEXT;\n"
    )
    text = _module(body)
    spec = _spec(text, robot)
    assert [s.kind for s in spec.steps] == ["move"]  # RETRY / TRYNEXT are not part of the cycle
    assert write_module(parse_module(text, path="t.mod")) == text


# ---------------------------------------------------------------- 2. predefined data
def test_vmax_and_predefined_data(robot):
    spec = _spec(_module("        MoveJ pA, vmax, z200, tool0 \\WObj:=wobj0;\n"), robot)
    (move,) = _moves(spec)
    assert (move.speed.v_tcp, move.speed.v_ori) == (5000.0, 500.0)  # RobotWare vmax
    assert move.zone_mm == 200.0


# ---------------------------------------------------------------- 3. Offs and RelTool
def test_offs_displaces_in_the_object_frame(robot):
    spec = _spec(_module("        MoveL Offs(pA, 10, 20, 30), v100, fine, tool0;\n"), robot)
    pos, rot = _tcp(_moves(spec)[0])
    np.testing.assert_allclose(pos, [385, 20, 570], atol=1e-6)  # 375+10, 0+20, 540+30
    np.testing.assert_allclose(rot, DOWN, atol=1e-9)  # same orientation


def test_reltool_displaces_and_turns_in_the_tool_frame(robot):
    spec = _spec(_module("        MoveL RelTool(pA, 0, 0, 50 \\Rz:=90), v100, fine, tool0;\n"), robot)
    pos, rot = _tcp(_moves(spec)[0])
    # tool z points down (DOWN @ [0, 0, 50] = [0, 0, -50]); DOWN @ Rz(90) = [[0, 1, 0], [1, 0, 0], [0, 0, -1]]
    np.testing.assert_allclose(pos, [375, 0, 490], atol=1e-6)
    np.testing.assert_allclose(rot, [[0, 1, 0], [1, 0, 0], [0, 0, -1]], atol=1e-9)


def test_robtarget_declared_as_offs_and_arguments_computed(robot):
    decl = "    CONST num nUp := 25;\n    CONST robtarget pB := Offs(pA, 0, 0, -2 * nUp - 10);\n"
    spec = _spec(_module("        MoveJ pB, v100, fine, tool0;\n", decl), robot)
    np.testing.assert_allclose(_tcp(_moves(spec)[0])[0], [375, 0, 480], atol=1e-6)  # 540 - 60


# ---------------------------------------------------------------- 4. work objects
WOBJ = (
    '    PERS wobjdata wobjM := [FALSE, TRUE, "", [[100, 50, 0], [1, 0, 0, 0]], '
    "[[0, 0, 20], [0.7071068, 0, 0, 0.7071068]]];\n"
    f"    CONST robtarget pW := [[200, 0, 400], [0, 0, 1, 0], [0, 0, -1, 0], {EXT}];\n"
)


def test_fixed_work_object_places_the_target(robot):
    spec = _spec(_module("        MoveL pW, v100, fine, tool0 \\WObj:=wobjM;\n", WOBJ), robot)
    pos, rot = _tcp(_moves(spec)[0])
    # oframe turns [200, 0, 400] by 90 deg about z -> [0, 200, 400], + [0, 0, 20], + uframe [100, 50, 0]
    np.testing.assert_allclose(pos, [100, 250, 420], atol=1e-3)
    np.testing.assert_allclose(rot, [[0, -1, 0], [-1, 0, 0], [0, 0, -1]], atol=1e-6)  # Rz(90) @ DOWN


@pytest.mark.parametrize(
    ("edit", "needle"),
    [('[FALSE, TRUE, ""', "robhold TRUE"), ('[FALSE, TRUE, ""', "ufmec 'STN1'")],
)
def test_moving_work_object_is_refused(robot, edit, needle):
    new = '[TRUE, TRUE, ""' if "robhold" in needle else '[FALSE, TRUE, "STN1"'
    text = _module("        MoveL pW, v100, fine, tool0 \\WObj:=wobjM;\n", WOBJ.replace(edit, new))
    message = _refused(text, robot)
    assert message.startswith("t.mod:6:") and needle in message and "wobjM" in message


# ---------------------------------------------------------------- 5. WaitTime
def test_waittime_inpos_and_pers_num(robot):
    decl = "    PERS num nPause := 1.25;\n"
    body = "        MoveJ pA, v1000, z50, tool0;\n        WaitTime \\InPos, 0.5;\n        WaitTime nPause;\n"
    spec = _spec(_module(body, decl), robot)
    waits = [s for s in spec.steps if s.kind == "wait"]
    assert [w.seconds for w in waits] == [0.5, 1.25]
    assert waits[0].statement.inpos and waits[0].label == "WaitTime \\InPos, 0.5"


def test_waittime_on_an_assigned_pers_is_refused(robot):
    decl = "    PERS num nPause := 1.25;\n"
    body = "        MoveJ pA, v1000, z50, tool0;\n        nPause := 2;\n        WaitTime nPause;\n"
    message = _refused(_module(body, decl), robot)
    assert message.startswith("t.mod:7:") and "assigned at line 6" in message


# ---------------------------------------------------------------- 6. procedures with arguments
def test_procedure_arguments_are_substituted(robot):
    procs = (
        "    PROC Visit(robtarget pT, num nUp, speeddata vApp)\n"
        "        MoveJ Offs(pT, 0, 0, nUp), vApp, fine, tool0;\n    ENDPROC\n"
    )
    decl = "    CONST robtarget pB := Offs(pA, -75, 100, -140);\n"
    body = "        Visit pA, 40, v500;\n        Visit pB, 20, v1000;\n"
    moves = _moves(_spec(_module(body, decl, procs), robot))
    np.testing.assert_allclose(_tcp(moves[0])[0], [375, 0, 580], atol=1e-6)  # pA + 40 up
    np.testing.assert_allclose(_tcp(moves[1])[0], [300, 100, 420], atol=1e-6)  # pA - 75, +100, -140 + 20
    assert [m.speed.v_tcp for m in moves] == [500.0, 1000.0]
    assert all(m.repeated for m in moves)  # one source line run twice


def test_procedure_argument_count_is_checked(robot):
    procs = "    PROC Visit(robtarget pT, num nUp)\n        MoveJ pT, v100, fine, tool0;\n    ENDPROC\n"
    message = _refused(_module("        Visit pA;\n", "", procs), robot)
    assert message.startswith("t.mod:4:") and "takes 2 argument(s)" in message


# ---------------------------------------------------------------- 7. IF / TEST on constants
def test_if_on_a_constant_runs_the_chosen_branch_and_says_so(robot):
    decl = "    CONST robtarget pB := Offs(pA, 0, 0, -100);\n    CONST bool bDoubleGrip := FALSE;\n"
    body = (
        "        IF bDoubleGrip THEN\n            MoveJ pA, v100, fine, tool0;\n"
        "        ELSE\n            MoveJ pB, v200, fine, tool0;\n        ENDIF\n"
    )
    spec = _spec(_module(body, decl), robot)
    (move,) = _moves(spec)
    np.testing.assert_allclose(_tcp(move)[0], [375, 0, 440], atol=1e-6)
    assert spec.choices == ("line 6: IF bDoubleGrip (FALSE) -> ELSE branch",)


def test_test_on_a_pers_num_picks_its_case(robot):
    decl = "    PERS num nMode := 2;\n"
    body = (
        "        TEST nMode\n        CASE 1:\n            MoveJ pA, v100, fine, tool0;\n"
        "        CASE 2, 3:\n            MoveJ pA, v300, fine, tool0;\n        DEFAULT:\n            Stop;\n"
        "        ENDTEST\n"
    )
    spec = _spec(_module(body, decl), robot)
    assert [m.speed.v_tcp for m in _moves(spec)] == [300.0]
    assert spec.choices == ("line 5: TEST nMode (2) -> CASE branch (line 8)",)


def test_if_on_a_comparison_inside_a_for_loop(robot):
    body = (
        "        FOR i FROM 1 TO 3 DO\n            IF i MOD 2 = 1 THEN\n"
        "                MoveL Offs(pA, 0, 0, -10 * i), v100, fine, tool0;\n"
        "            ENDIF\n        ENDFOR\n"
    )
    spec = _spec(_module(body), robot)
    heights = [round(_tcp(m)[0][2], 6) for m in _moves(spec)]
    assert heights == [530.0, 510.0]  # i = 1 and 3 run: 540 - 10, 540 - 30


def test_if_on_a_run_time_value_is_refused_at_the_move(robot):
    decl = "    VAR num nCount := 0;\n"
    body = "        IF nCount > 3 THEN\n            MoveJ pA, v100, fine, tool0;\n        ENDIF\n"
    message = _refused(_module(body, decl), robot)
    assert message.startswith("t.mod:6:") and "IF (line 5)" in message and "nCount" in message


# ---------------------------------------------------------------- 8. refusals
@pytest.mark.parametrize(
    ("instruction", "needle"),
    [
        ("PDispOn \\ExeP:=pA, pA, tool0;", "PDispOn"),
        ("PDispSet [[0, 0, 10], [1, 0, 0, 0]];", "PDispSet"),
        ("EOffsSet [0, 0, 0, 0, 0, 0];", "EOffsSet"),
        ("AccSet 50, 100 \\FinePointRamp:=50;", "AccSet"),
        ("AccSet 150, 100;", "AccSet"),
        ("VelSet 50;", "VelSet"),
        ("MoveC pA, pA, v100, fine, tool0;", "MoveC"),
        ("MoveL \\Conc, pA, v100, fine, tool0;", "\\Conc"),
        ("MoveL CRobT(\\Tool:=tool0), v100, fine, tool0;", "CRobT"),
        ("ConfL \\Off;", "ConfL"),
    ],
)
def test_motion_changes_are_refused_in_one_line(robot, instruction, needle):
    text = _module(
        f"        MoveJ pA, v100, fine, tool0;\n        {instruction}\n        MoveL pA, v100, fine, tool0;\n"
    )
    message = _refused(text, robot)
    assert message.startswith("t.mod:5:") and needle in message, message


def test_target_assigned_by_crobt_is_refused_where_a_move_uses_it(robot):
    decl = "    VAR robtarget pHere;\n"
    body = "        pHere := CRobT(\\Tool:=tool0);\n        MoveL pHere, v100, fine, tool0;\n"
    message = _refused(_module(body, decl), robot)
    assert message.startswith("t.mod:6:") and "assigned at line 5" in message and "CRobT" in message


def test_non_motion_instructions_stay_verbatim(robot):
    body = (
        "        MoveJ pA, v100, fine, tool0;\n        SetDO doGrip, 1;\n        WaitDI diPart, 1;\n"
        '        TPWrite "done";\n        Reset doGrip;\n        PDispOff;\n'
    )
    spec = _spec(_module(body, "    VAR robtarget pUnused;\n"), robot)
    assert [s.label for s in spec.steps if s.kind == "fixed"] == [
        "SetDO",
        "WaitDI",
        "TPWrite",
        "Reset",
        "PDispOff",
    ]


# ---------------------------------------------------------------- 9. idle waits
def test_idle_waits_by_marker_and_by_line(robot):
    procs = "    PROC Grip()\n        ! joulepath: idle\n        WaitTime 0.2;\n    ENDPROC\n"
    body = (
        "        MoveJ pA, v100, fine, tool0;\n        WaitTime 1; ! joulepath: idle\n        Grip;\n"
        "        WaitTime 0.3;\n        Grip;\n        WaitTime 0.4;\n"
    )
    text = _module(body, "", procs)
    waits = [s for s in _spec(text, robot, idle_waits=[9]).steps if s.kind == "wait"]
    # line 5: marked after the ';'; line 13 (twice, in Grip): marked above; line 9: by idle_waits
    assert [(w.line, w.idle) for w in waits] == [(5, True), (13, True), (7, False), (13, True), (9, True)]


def test_idle_waits_naming_another_line_is_refused(robot):
    text = _module("        MoveJ pA, v100, fine, tool0;\n        WaitTime 1;\n")
    with pytest.raises(RapidError, match=r"^t.mod:4: idle_waits names line 4, which is not a WaitTime"):
        _spec(text, robot, idle_waits=[4])


def test_read_cycle_program_passes_idle_waits(tmp_path, robot):
    prog = tmp_path / "p.mod"
    prog.write_text(_module("        MoveJ pA, v100, fine, tool0;\n        WaitTime 1;\n"))
    spec, rapid = read_cycle_program(prog, robot, idle_waits={5})
    assert rapid and [s.idle for s in spec.steps] == [False, True]
