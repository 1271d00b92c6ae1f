"""The interpreter on trees: RAPID's semantics, the known/unknown marking, the bounds, the refusals."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from joulepath.rapid import RapidError, parse_module
from joulepath.rapid.interpreter import Action, Interpreter, Motion, Wait
from joulepath.rapid.task import Task
from joulepath.rapid.values import Array, Record

HEAD = """MODULE T
  CONST robtarget p10 := [[400,0,300],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS tooldata tG := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,50],[1,0,0,0],0,0,0]];
"""


def run(body: str, *, decl: str = "", extra: str = "", io=None, routine=None, modules=()):
    text = HEAD + decl + "  PROC main()\n" + body + "\n  ENDPROC\n" + extra + "ENDMODULE\n"
    m = parse_module(text, path="t.mod")
    task = Task((m, *modules), frozenset(), "t.mod")
    interp = Interpreter(task, io=io)
    return interp, interp.run(routine)


def value(interp: Interpreter, name: str):
    return interp.lookup(name, interp.task.modules[0].pos).value  # type: ignore[union-attr]


def test_arithmetic_strings_and_precedence():
    interp, _ = run(
        '    x := 1 + 2 * 3 - -4 / 2;\n    y := 17 DIV 5 + 17 MOD 5;\n    s := "a" + NumToStr(2.5, 1);\n'
        "    b := 1 < 2 AND NOT (3 <= 2) OR FALSE;\n    r := Round(2.345\\Dec:=2) + Trunc(-1.7);",
        decl="  VAR num x; VAR num y; VAR string s; VAR bool b; VAR num r;\n",
    )
    assert value(interp, "x") == 9.0
    assert value(interp, "y") == 3.0 + 2.0
    assert value(interp, "s") == "a2.5"
    assert value(interp, "b") is True
    assert value(interp, "r") == pytest.approx(2.35 - 1.0)


def test_records_arrays_and_user_record_types():
    interp, _ = run(
        "    parts{2}.w := 4;\n    parts{1} := [1, p10];\n    grid{2,3} := grid{1,1} + 10;\n"
        "    q := p10;\n    q.trans.z := q.trans.z + 50;",
        decl="  VAR part parts{2};\n  VAR num grid{2,3} := [[1,2,3],[4,5,6]];\n  VAR robtarget q;\n",
        extra="  RECORD part\n    num w;\n    robtarget p;\n  ENDRECORD\n",
    )
    parts = value(interp, "parts")
    assert isinstance(parts, Array) and parts.dims == (2,)
    assert parts.items[1].get("w") == 4.0 and parts.items[0].get("w") == 1.0
    assert value(interp, "grid").items == (1.0, 2.0, 3.0, 4.0, 5.0, 11.0)
    q = value(interp, "q")
    assert isinstance(q, Record) and q.get("trans").get("z") == 350.0
    # the constant itself is untouched: values, not references
    assert value(interp, "p10").get("trans").get("z") == 300.0


def test_loops_test_goto_compact_if_and_incr():
    interp, _ = run(
        "    FOR i FROM 1 TO 4 DO\n      n := n + i;\n    ENDFOR\n"
        "    FOR i FROM 10 TO 1 STEP -3 DO\n      Incr m;\n    ENDFOR\n"
        "    WHILE k < 5 DO\n      k := k + 2;\n    ENDWHILE\n"
        "    TEST k\n    CASE 1, 6:\n      c := 1;\n    DEFAULT:\n      c := 2;\n    ENDTEST\n"
        "    IF k > 5 c := c + 10;\n"
        "    again:\n    Decr k;\n    IF k > 0 GOTO again;",
        decl="  VAR num n; VAR num m; VAR num k; VAR num c;\n",
    )
    assert value(interp, "n") == 10.0
    assert value(interp, "m") == 4.0  # 10, 7, 4, 1
    assert value(interp, "c") == 11.0
    assert value(interp, "k") == 0.0


def test_routines_by_value_by_reference_optional_and_recursion():
    interp, _ = run(
        "    Bump n, 5;\n    Bump n, 5 \\Twice;\n    Stack 4, depth;\n    f := Half(9);",
        decl="  VAR num n; VAR num depth; VAR num f;\n",
        extra=(
            "  PROC Bump(INOUT num x, num by \\switch Twice)\n    x := x + by;\n"
            "    IF Present(Twice) x := x + by;\n    by := 0;\n  ENDPROC\n"
            "  PROC Stack(num k, VAR num d)\n    IF k > 0 THEN\n      d := d + 1;\n      Stack k - 1, d;\n"
            "    ENDIF\n  ENDPROC\n"
            "  FUNC num Half(num v)\n    RETURN v / 2;\n  ENDFUNC\n"
        ),
    )
    assert value(interp, "n") == 15.0
    assert value(interp, "depth") == 4.0
    assert value(interp, "f") == 4.5


def test_offs_and_reltool_agree_with_an_independent_rotation():
    interp, trace = run(
        "    a := Offs(p10, 10, -20, 30);\n    b := RelTool(p10, 5, 6, 7 \\Rx:=10 \\Ry:=-20 \\Rz:=30);",
        decl="  VAR robtarget a; VAR robtarget b;\n",
    )
    a, b = value(interp, "a"), value(interp, "b")
    assert [a.get("trans").get(k) for k in "xyz"] == [410.0, -20.0, 330.0]
    rot = Rotation.from_quat([0, 1, 0, 0])  # p10's orient [0,0,1,0] is (w,x,y,z): a half turn about y
    shift = rot.apply([5.0, 6.0, 7.0])
    assert [b.get("trans").get(k) for k in "xyz"] == pytest.approx(np.array([400.0, 0.0, 300.0]) + shift)
    expect = rot * Rotation.from_euler("XYZ", [10, -20, 30], degrees=True)
    w, x, y, z = (b.get("rot").get(k) for k in ("q1", "q2", "q3", "q4"))
    got = Rotation.from_quat([x, y, z, w])
    assert (got.inv() * expect).magnitude() < 1e-9


def test_motion_events_carry_their_settings_and_context():
    _, trace = run(
        "    AccSet 50, 30;\n    VelSet 80, 800;\n    ConfL \\Off;\n"
        "    FOR i FROM 1 TO 2 DO\n      Go Offs(p10, 0, 0, i * 10);\n    ENDFOR\n"
        "    MoveC Offs(p10,20,20,0), Offs(p10,40,0,0), v200 \\V:=250, z5 \\Z:=7, tG;\n"
        "    MoveL p10, v100 \\T:=2, fine \\Inpos, tG;\n    WaitTime \\InPos, 0.5;\n    SetDO do1, 1;",
        extra="  PROC Go(robtarget p)\n    MoveJ p, v1000, z10, tG;\n  ENDPROC\n",
    )
    moves = trace.motions
    assert [m.kind for m in moves] == ["joint", "joint", "circular", "linear"]
    first = moves[0]
    assert first.settings.acc_pct == 50.0 and first.settings.ramp_pct == 30.0
    assert first.settings.vel_override_pct == 80.0 and not first.settings.conf_l
    assert first.context[0].startswith("Go (t.mod:") and first.context[-1] == "i=1"
    assert moves[1].target.get("trans").get("z") == 320.0
    circ = moves[2]
    assert circ.circle is not None and circ.circle.get("trans").get("x") == 420.0
    assert circ.speed.get("v_tcp") == 250.0 and circ.zone_mm == 7.0
    lin = moves[3]
    assert lin.time_s == 2.0 and lin.fine and lin.inpos
    kinds = [type(e).__name__ for e in trace.cycle]
    assert kinds[-2:] == ["Wait", "Action"]
    assert all(not m.kept for m in moves)


def test_an_input_without_a_value_marks_what_it_decides():
    body = (
        "    MoveJ p10, v1000, z10, tG;\n"
        "    IF DInput(diBig) = 1 THEN\n      MoveJ Offs(p10, 0, 50, 0), v1000, z10, tG;\n"
        "    ELSE\n      MoveJ Offs(p10, 0, -50, 0), v1000, z10, tG;\n    ENDIF\n"
        "    MoveJ Offs(p10, 50, 0, 0), v1000, z10, tG;\n    MoveJ p10, v1000, fine, tG;"
    )
    _, trace = run(body)
    kept = [bool(m.kept) for m in trace.motions]
    # the branch taken is assumed (a note says so) and its move planned; the move after the IF is kept
    # (its start depends on which branch runs); the others known
    assert kept == [False, False, True, False]
    assert any("diBig" in n and "assumed" in n for n in trace.notes)
    assert trace.motions[1].target.get("trans").get("y") == -50.0  # the stand-in: the input reads 0
    assert any("diBig" in n and "ELSE" in n for n in trace.notes)
    _, given = run(body, io={"diBig": 1})
    assert [bool(m.kept) for m in given.motions] == [False, False, False, False]
    assert given.motions[1].target.get("trans").get("y") == 50.0


def test_data_set_in_a_branch_that_moves_nothing_stay_known_only_at_run_time():
    """A branch decided at run time that moves nothing (a message parsed, a flag set) is not an
    assumption about the cycle: what it sets decides later branches toward the motion, as at run time."""
    body = (
        "    n := GInput(giMsg);\n"
        "    IF n > 5 THEN\n      k := -1;\n    ELSE\n      k := 7;\n    ENDIF\n"
        "    MoveJ p10, v1000, z10, tG;\n"
        "    IF k = 7 THEN\n      MoveJ Offs(p10, 0, 50, 0), v1000, z10, tG;\n    ENDIF\n"
        "    MoveJ p10, v1000, fine, tG;"
    )
    _, trace = run(body, decl="  VAR num n; VAR num k;\n")
    assert len(trace.motions) == 3  # the later IF is decided toward its move, whichever k the first set
    # that IF's moving branch is then the one assumed (planned); the move after it starts from either
    assert [bool(m.kept) for m in trace.motions] == [False, False, True]


def test_marks_flow_through_data_and_calls():
    _, trace = run(
        "    n := GInput(giLayer);\n    k := n * 2 + 1;\n    MoveL Offs(p10, 0, 0, k), v100, fine, tG;\n"
        "    MoveL Offs(p10, 0, 0, 1), v100, fine, tG;\n    MoveL p10, v100, fine, tG;",
        decl="  VAR num n; VAR num k;\n",
    )
    kept = [bool(m.kept) for m in trace.motions]
    assert kept == [True, True, False]  # the second starts where the first (unknown) ended


def test_the_production_loop_is_the_cycle():
    _, trace = run(
        "    MoveJ Offs(p10,0,0,100), v1000, fine, tG;\n    WHILE TRUE DO\n      MoveJ p10, v1000, z10, tG;\n"
        "      MoveL Offs(p10,0,0,-50), v100, fine, tG;\n    ENDWHILE"
    )
    assert trace.loop is not None and trace.loop.line == 6
    assert len(trace.motions) == 2 and len(trace.events) == 5  # the way there, a first turn, the cycle


def test_a_loop_in_another_routine_is_the_cycle_too():
    _, trace = run(
        "    Production;",
        decl="  PERS bool bRun := TRUE;\n",
        extra="  PROC Production()\n    "
        "    WHILE bRun DO\n      MoveJ p10, v1000, fine, tG;\n    ENDWHILE\n  ENDPROC\n",
    )
    assert trace.loop is not None and len(trace.motions) == 1


@pytest.mark.parametrize(
    ("body", "extra", "io", "match"),
    [
        ("    WHILE n >= 0 DO\n      n := n + 1;\n    ENDWHILE", "", None, "statements without finishing"),
        ("    Rec 1;", "  PROC Rec(num k)\n    Rec k + 1;\n  ENDPROC\n", None, "recursion"),
        ("    WaitDI diGo, 1;", "", {"diGo": 0}, "never ends"),
        ("    MoveJ Offs(p10, 2000, 0, 0), v100, fine, tG;", "", None, None),
    ],
)
def test_bounded_and_refused_in_one_line(body, extra, io, match):
    if match is None:  # an unreachable target is refused where a robot is given
        from joulepath import load_robot
        from joulepath.program._task import RobotKinematics

        text = HEAD + "  PROC main()\n" + body + "\n  ENDPROC\nENDMODULE\n"
        task = Task((parse_module(text, path="t.mod"),), frozenset(), "t.mod")
        with pytest.raises(RapidError, match="beyond its reach .* a larger arm; give it with --robot") as err:
            Interpreter(task, kinematics=RobotKinematics(load_robot("irb120"))).run()
        assert str(err.value).startswith("t.mod:5:") and len(str(err.value)) < 300
        return
    with pytest.raises(RapidError, match=match) as err:
        run(body, decl="  VAR num n;\n", extra=extra, io=io)
    assert str(err.value).startswith("t.mod:") and "\n" not in str(err.value)


def test_no_main_lists_the_routines_that_move():
    text = HEAD + "  PROC Path1()\n    MoveJ p10, v100, fine, tG;\n  ENDPROC\nENDMODULE\n"
    task = Task((parse_module(text, path="lib.mod"),), frozenset(), "lib.mod")
    with pytest.raises(RapidError, match="--routine NAME.*Path1"):
        Interpreter(task).run()
    trace = Interpreter(task).run("Path1")
    assert len(trace.motions) == 1


def test_data_and_routines_are_found_across_modules():
    sysmod = parse_module(
        "MODULE CellData(SYSMODULE)\n  "
        "  PERS tooldata tPen := [TRUE,[[0,0,120],[1,0,0,0]],[0.5,[0,0,40],[1,0,0,0],0,0,0]];\n"
        "  PROC Home()\n    MoveAbsJ [[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]], "
        " v1000, fine, tPen;\n  ENDPROC\n"
        "ENDMODULE\n",
        path="cell.sys",
    )
    _, trace = run("    Home;\n    MoveJ p10, v100, fine, tPen;", modules=(sysmod,))
    assert [m.tool_name for m in trace.motions] == ["tPen", "tPen"]
    assert trace.motions[0].pos.file == "cell.sys"


def test_traps_and_error_handlers_are_not_run():
    interp, trace = run(
        "    n := 1;\n  ERROR\n    n := 99;",
        decl="  VAR num n;\n",
        extra="  TRAP tr\n    n := 7;\n  ENDTRAP\n",
    )
    assert value(interp, "n") == 1.0
    assert all(isinstance(e, (Action, Wait, Motion)) for e in trace.events)


def test_random_numbers_follow_the_seed_and_are_marked():
    text = (
        HEAD + "  VAR num r;\n  PROC main()\n    "
        "    r := Rand();\n    MoveJ Offs(p10, 0, 0, r * 10), v100, fine, tG;\n  ENDPROC\nENDMODULE\n"
    )
    task = Task((parse_module(text, path="t.mod"),), frozenset(), "t.mod")
    a = Interpreter(task, seed=3).run()
    b = Interpreter(task, seed=3).run()
    assert a.motions[0].target == b.motions[0].target
    assert a.motions[0].kept


def test_the_cycle_starts_with_the_settings_a_turn_leaves():
    _, trace = run(
        "    AccSet 100, 100;\n    WHILE TRUE DO\n      MoveJ p10, v1000, z10, tG;\n      AccSet 40, 20;\n"
        "      MoveL Offs(p10,0,0,-50), v100, fine, tG;\n      "
        "      AccSet 100, 100;\n      n := n + 1;\n    ENDWHILE",
        decl="  VAR num n;\n",
    )
    first, second = trace.motions
    assert (first.settings.acc_pct, second.settings.acc_pct) == (100.0, 40.0)
    _, trace = run(
        "    WHILE TRUE DO\n      MoveJ p10, v1000, z10, tG;\n      AccSet 40, 20;\n"
        "      MoveL Offs(p10,0,0,-50), v100, fine, tG;\n    ENDWHILE"
    )
    assert [m.settings.acc_pct for m in trace.motions] == [40.0, 40.0]  # the steady state, not the first turn


def _kinematic_run(body: str, *, decl: str = "", given=None, io=None):
    from joulepath import load_robot
    from joulepath.program._task import RobotKinematics

    robot = load_robot("irb120")
    text = HEAD + decl + "  PROC main()\n" + body + "\n  ENDPROC\nENDMODULE\n"
    task = Task((parse_module(text, path="t.mod"),), frozenset(), "t.mod")
    interp = Interpreter(
        task, io=io, kinematics=RobotKinematics(robot), given=given, rated_payload_kg=robot.rated_payload_kg
    )
    return interp.run(), robot


def test_a_partial_task_runs_on_stand_ins_by_role_each_stated_once():
    trace, robot = _kinematic_run(
        "    MoveJ p10, v100, fine, tWelder\\WObj:=wFixture;\n    g_GripIn;\n    GripClose;\n"
        "    MoveL Offs(p10, 0, 0, 50), vFast, zMine, tWelder\\WObj:=wFixture;\n    GripClose;\n"
        "    MoveJ pHome, v100, fine, tWelder;\n    MoveJ p10, v100, fine, tWelder;"
    )
    roles = {a.name: a.role for a in trace.assumed}
    assert roles == {
        "tWelder": "tooldata", "wFixture": "wobjdata", "GripClose": "routine",
        "vFast": "speeddata", "zMine": "zonedata", "pHome": "robtarget",
    }  # fmt: skip
    assert len(trace.assumed) == len(roles)  # each said once, where it is first used
    # an option's documented instruction is not a name declared nowhere: it is run as no motion, said
    assert any("g_GripIn: the SmartGripper option's instruction" in note for note in trace.notes)
    first = trace.motions[0]
    # tool0's frame and the stated share of the rated payload
    assert first.tool.get("tframe").get("trans").get("z") == 0.0
    assert first.tool.get("tload").get("mass") == pytest.approx(0.5 * robot.rated_payload_kg)
    assert first.wobj.get("uframe").get("trans").get("x") == 0.0
    moves = trace.motions
    assert [bool(m.kept) for m in moves] == [False, False, True, True]  # the unknown target and the next
    assert np.allclose(moves[2].joints, moves[1].joints)  # placed where the arm is
    assert any("an unknown target" in why for why in moves[2].kept)


def test_the_scenario_gives_what_the_task_leaves_out():
    given = {
        "tWelder": (True, ((0, 0, 150.0), (1.0, 0, 0, 0)), (2.0, (0, 0, 60.0), (1.0, 0, 0, 0), 0, 0, 0)),
        "pHome": ((400.0, 100.0, 350.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 0.0), (9e9,) * 6),
        "vFast": "[2000, 500, 5000, 1000]",
        "pCam": ((420.0, -80.0, 300.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 0.0), (9e9,) * 6),
    }  # fmt: skip
    trace, _ = _kinematic_run(
        "    MoveJ pHome, vFast, fine, tWelder;\n    SocketReceive sock \\Str:=msg;\n"
        "    ok := StrToVal(msg, pCam);\n    MoveJ pCam, v100, fine, tWelder;\n"
        "    MoveJ p10, v100, fine, tWelder;",
        decl="  VAR socketdev sock;\n  VAR string msg;\n  VAR robtarget pCam;\n  VAR bool ok;\n",
        given=given,
    )
    assert [bool(m.kept) for m in trace.motions] == [False, False, False]
    assert trace.motions[0].speed.get("v_tcp") == 2000.0
    assert trace.motions[0].tool.get("tload").get("mass") == 2.0
    assert trace.motions[1].target.get("trans").get("y") == -80.0


def test_a_target_that_arrives_at_run_time_is_unknown_not_out_of_reach():
    trace, _ = _kinematic_run(
        "    MoveJ p10, v100, fine, tG;\n    SocketReceive sock \\Str:=msg;\n    ok := StrToVal(msg, pCam);\n"
        "    MoveJ pCam, v100, fine, tG;\n    MoveJ p10, v100, fine, tG;",
        decl="  VAR socketdev sock;\n  VAR string msg;\n  VAR robtarget pCam;\n  VAR bool ok;\n",
    )
    kept = trace.motions[1].kept
    assert any("an unknown target" in why and "SocketReceive" in why for why in kept)
    assert np.allclose(trace.motions[1].joints, trace.motions[0].joints)
    assert trace.motions[2].kept  # it starts where the unknown one ended


def test_confdata_as_the_controller_checks_it():
    # the same target with its axis-6 quadrant edited by one: moved to the nearest solution, with a note
    decl = "  CONST robtarget pE := [[400,0,300],[0,0,1,0],[0,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
    trace, _ = _kinematic_run("    MoveJ p10, v100, fine, tG;\n    MoveJ pE, v100, fine, tG;", decl=decl)
    assert any("matches no joint solution exactly" in note for note in trace.notes)
    # cfx (the arm's branch) that no solution has: the controller stops, so is the program refused
    decl = "  CONST robtarget pX := [[400,0,300],[0,0,1,0],[0,0,0,5],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
    with pytest.raises(RapidError, match="controller stops here"):
        _kinematic_run("    MoveJ p10, v100, fine, tG;\n    MoveJ pX, v100, fine, tG;", decl=decl)


HANDSHAKE = """  PERS bool bReq := FALSE;
  PERS num nJob := 0;
  CONST robtarget pA := [[400,-100,300],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pB := [[400,100,300],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
"""
HANDSHAKE_LOOP = (
    "    WHILE TRUE DO\n      IF bReq THEN\n        bReq := FALSE;\n        TEST nJob\n"
    "        CASE 1:\n          MoveJ pA, v1000, fine, tG;\n"
    "        CASE 2:\n          MoveJ pB, v1000, z10, tG;\n          MoveL p10, v500, fine, tG;\n"
    "        ENDTEST\n        nJob := 0;\n      ENDIF\n      WaitTime 0.05;\n    ENDWHILE"
)


def _targets(trace) -> list[str]:
    return [m.stmt.args[0].value.name for m in trace.motions]  # type: ignore[attr-defined]


def test_data_the_task_only_clears_is_a_handshake_set_outside_it():
    """A request flag and a job number the task only sets back to their declared values (after it acts
    on them) are set by a PLC, a PC or the HMI: the production turn is the job that moves most, said;
    `--io` gives them, on every read (the PLC sets them again each turn)."""
    interp, trace = run(HANDSHAKE_LOOP, decl=HANDSHAKE)
    assert interp.handshake == {"breq", "njob"}
    assert _targets(trace) == ["pB", "p10"]  # CASE 2 moves most
    said = [line for line in trace.notes if "which this task only sets back to its declared value" in line]
    assert len(said) == 2 and all("--io NAME=VALUE" in line for line in said)
    _, given = run(HANDSHAKE_LOOP, decl=HANDSHAKE, io={"nJob": 1.0, "bReq": True})
    assert _targets(given) == ["pA"]
    assert not any("only sets back" in line for line in given.notes)


def test_data_the_task_also_sets_otherwise_is_not_a_handshake():
    # the task itself raises the request (TRUE) and picks the job: its values are the task's
    raised = "    WHILE TRUE DO\n      bReq := TRUE;\n      nJob := 1;\n"
    body = HANDSHAKE_LOOP.replace("    WHILE TRUE DO\n", raised)
    interp, trace = run(body, decl=HANDSHAKE)
    assert interp.handshake == set()
    assert _targets(trace) == ["pA"]
    with pytest.raises(RapidError, match="bReq is a bool; give TRUE or FALSE"):
        run(HANDSHAKE_LOOP, decl=HANDSHAKE, io={"bReq": 3.0})


def test_a_goto_back_for_ever_is_the_production_loop():
    """`label: ... GOTO label;` at the end of main repeats for ever, as WHILE TRUE does: the turn after
    the first is the cycle (before, the run went on until its bound of statements); a GOTO to the same
    label inside that turn ends it."""
    body = (
        "    MoveJ Offs(p10,0,0,100), v1000, fine, tG;\n    top:\n      MoveJ p10, v1000, z10, tG;\n"
        "      MoveL Offs(p10,0,0,-50), v100, fine, tG;\n    GOTO top;"
    )
    _, trace = run(body)
    assert trace.loop is not None and trace.loop.line == 9  # the GOTO
    assert len(trace.motions) == 2 and len(trace.events) == 5  # the way there, a first turn, the cycle
    assert any("GOTO top jumps back for ever" in line for line in trace.notes)
    short = body.replace("      MoveL", "      n := n + 1;\n      IF n = 2 GOTO top;\n      MoveL")
    _, second = run(short, decl="  VAR num n := 0;\n")  # the cycle's turn jumps back before its MoveL
    assert len(second.motions) == 1 and second.loop is not None
