"""FOR loops with constant bounds: unrolled into steps, arrays indexed by the loop variable."""

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.program import RapidError, parse_module, resolve_module, write_module
from joulepath.program._model import ForLoop, Move, Verbatim

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
JOINTS = ([10, 0, 0, 0, 30, 0], [20, 5, 0, 0, 30, 0], [30, 10, -5, 0, 30, 0])


def _module(body: str, decl: str = "") -> str:
    targets = ",\n".join(f"        [[{', '.join(str(v) for v in j)}], {EXT}]" for j in JOINTS)
    return (
        "MODULE Loops\n"
        f"    CONST jointtarget J{{3}} := [\n{targets}];\n"
        "    CONST num T{3} := [0.5, 0.75, 1.25];\n"
        "    CONST num N := 3;\n"
        f"{decl}"
        "    PROC main()\n"
        f"{body}"
        "    ENDPROC\n"
        "ENDMODULE\n"
    )


LOOP = (
    "        FOR k FROM 1 TO N DO\n            MoveAbsJ J{k}, v1000 \\T:=T{k}, z10, tool0;\n        ENDFOR\n"
)


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb120")


def _moves(text, robot):
    spec = resolve_module(parse_module(text, path="loops.mod"), robot)
    return [s for s in spec.steps if s.kind == "move"]


def test_for_loop_unrolls_indexed_targets_and_times(robot):
    moves = _moves(_module(LOOP), robot)
    assert [m.label for m in moves] == ["MoveAbsJ J{1}", "MoveAbsJ J{2}", "MoveAbsJ J{3}"]
    for m, joints in zip(moves, JOINTS, strict=True):
        np.testing.assert_allclose(m.q, np.radians(joints))
    assert [m.time_s for m in moves] == [0.5, 0.75, 1.25]
    assert all(m.line == 10 and m.repeated for m in moves)  # one source line, run three times


def test_for_loop_parses_as_one_statement_with_its_runs():
    main = parse_module(_module(LOOP), path="loops.mod").procedure("main")
    (loop,) = main.body
    assert isinstance(loop, ForLoop)
    assert (loop.variable, loop.values, loop.line, loop.end_line) == ("k", (1, 2, 3), 9, 11)
    assert [run[0].target for run in loop.runs] == ["J{1}", "J{2}", "J{3}"]


def test_for_loop_step_runs_backwards(robot):
    body = LOOP.replace("FROM 1 TO N DO", "FROM N TO 1 STEP -2 DO")
    moves = _moves(_module(body), robot)
    assert [m.label for m in moves] == ["MoveAbsJ J{3}", "MoveAbsJ J{1}"]
    assert [m.time_s for m in moves] == [1.25, 0.5]


def test_nested_loops_and_calls_run_in_order(robot):
    text = _module(
        "        FOR i FROM 1 TO 2 DO\n            Visit;\n            WaitTime 0.1;\n        ENDFOR\n"
    ).replace(
        "ENDMODULE\n",
        "    PROC Visit()\n"
        "        FOR k FROM 2 TO 3 DO\n"
        "            MoveAbsJ J{k}, v1000, fine, tool0;\n"
        "        ENDFOR\n"
        "        MoveAbsJ J{1}, v1000, fine, tool0;\n"
        "    ENDPROC\n"
        "ENDMODULE\n",
    )
    spec = resolve_module(parse_module(text, path="loops.mod"), robot)
    labels = [s.label for s in spec.steps]
    assert labels == ["MoveAbsJ J{2}", "MoveAbsJ J{3}", "MoveAbsJ J{1}", "WaitTime 0.1"] * 2
    assert spec.steps[2].repeated  # a move of a procedure called twice


def test_loop_that_runs_once_is_not_repeated(robot):
    moves = _moves(_module(LOOP.replace("TO N", "TO 1")), robot)
    assert [(m.label, m.repeated) for m in moves] == [("MoveAbsJ J{1}", False)]


def test_arrays_of_predefined_speeds_and_zones_indexed_through_an_index_array(robot):
    decl = (
        "    CONST speeddata SPEEDS{2} := [v100, v7000];\n"
        "    CONST zonedata ZONES{2} := [fine, z50];\n"
        "    CONST num PICK{3} := [2, 1, 2];\n"
    )
    body = (
        "        FOR k FROM 1 TO 3 DO\n"
        "            MoveAbsJ J{k}, SPEEDS{PICK{k}}, ZONES{PICK{4 - 1}}, tool0;\n"
        "        ENDFOR\n"
    )
    with pytest.raises(RapidError, match=r"loops.mod:13: the index '4 - 1'"):
        _moves(_module(body, decl=decl), robot)
    moves = _moves(_module(body.replace("4 - 1", "k"), decl=decl), robot)
    assert [m.statement.speed for m in moves] == ["SPEEDS{2}", "SPEEDS{1}", "SPEEDS{2}"]
    assert [m.speed.v_tcp for m in moves] == [7000.0, 100.0, 7000.0]
    assert [m.zone_mm for m in moves] == [50.0, None, 50.0]  # z50, fine, z50


def test_array_of_speeds_names_only_predefined_data(robot):
    decl = "    CONST speeddata SPEEDS{2} := [v100, vFast];\n"
    with pytest.raises(RapidError, match=r"loops.mod:8: element 2 of SPEEDS is 'vFast'"):
        parse_module(_module(LOOP, decl=decl), path="loops.mod")


def test_for_loop_that_never_runs_adds_no_step(robot):
    body = LOOP.replace("FROM 1 TO N", "FROM 2 TO 1") + "        MoveAbsJ J{3}, v1000, fine, tool0;\n"
    main = parse_module(_module(body), path="loops.mod").procedure("main")
    assert isinstance(main.body[0], ForLoop) and main.body[0].runs == ()
    assert [m.label for m in _moves(_module(body), robot)] == ["MoveAbsJ J{3}"]


def test_loops_of_calls_of_loops_are_refused_before_they_blow_up(robot):
    body = "        FOR i FROM 1 TO 9000 DO\n            Visit;\n        ENDFOR\n"
    text = _module(body).replace(
        "ENDMODULE\n",
        "    PROC Visit()\n"
        "        FOR k FROM 1 TO 9000 DO\n"
        "            MoveAbsJ J{1}, v1000, fine, tool0;\n"
        "        ENDFOR\n"
        "    ENDPROC\n"
        "ENDMODULE\n",
    )
    with pytest.raises(RapidError, match=r"^loops.mod:8: main runs more than 200000 statements"):
        resolve_module(parse_module(text, path="loops.mod"), robot)


def test_for_loop_round_trips_unchanged():
    text = _module(LOOP)
    assert write_module(parse_module(text, path="loops.mod")) == text


def test_for_loop_without_moves_stays_verbatim():
    text = _module(
        '        FOR i FROM 1 TO count DO\n            TPWrite "tick";\n        ENDFOR\n'
        "        MoveAbsJ J{1}, v1000, fine, tool0;\n",
        decl="    VAR num count := 2;\n",
    )
    main = parse_module(text, path="loops.mod").procedure("main")
    assert isinstance(main.body[0], Verbatim) and isinstance(main.body[1], Move)


@pytest.mark.parametrize(
    ("name", "body", "decl", "line", "needle"),
    [
        (
            "bound not constant",
            LOOP.replace("TO N", "TO count"),
            "    VAR num count := 3;\n",
            10,
            "TO 'count'",
        ),
        ("index past the end", LOOP.replace("TO N", "TO 4"), "", 10, "J{4} is outside the array J{3}"),
        ("unknown index", LOOP.replace("J{k}", "J{m}"), "", 10, "the index 'm'"),
        ("index is not whole", LOOP.replace("J{k}", "J{1.5}"), "", 10, "not a whole number"),
        ("step 0", LOOP.replace("TO N DO", "TO N STEP 0 DO"), "", 9, "STEP is 0"),
        ("too many runs", LOOP.replace("TO N", "TO 20000"), "", 9, "runs 20000 times"),
        ("not an array", LOOP.replace("J{k}", "JX{k}"), "", 10, "JX is not an array"),
        (
            "array size does not match",
            LOOP,
            "    CONST num W{2} := [1, 2, 3];\n",
            8,
            "W{2} needs [2 elements], got 3",
        ),
        ("whole array as a target", LOOP.replace("J{k}", "J"), "", 10, "J is an array"),
        (
            "move in a WHILE",
            LOOP.replace("FOR k FROM 1 TO N DO", "WHILE x DO").replace("FOR", "WHILE"),
            "",
            10,
            "WHILE",
        ),
    ],
    ids=lambda v: v if isinstance(v, str) and len(v) < 40 and "\n" not in v else "",
)
def test_for_loop_refusals_name_the_line(robot, name, body, decl, line, needle):
    with pytest.raises(RapidError) as info:
        resolve_module(parse_module(_module(body, decl=decl), path="loops.mod"), robot)
    message = str(info.value)
    assert len(message.splitlines()) == 1, name
    assert message.startswith(f"loops.mod:{line}:"), message
    assert needle in message, message
