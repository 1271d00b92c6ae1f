"""The written module keeps the program: a diff against the input shows only the optimized moves and
the additions; parse -> write -> parse gives the motion written; a re-taught target moves the robot."""

import difflib
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.optimize import GradientSettings
from joulepath.optimize._gradient import GRID_SEARCH
from joulepath.program import CycleSettings, optimize_cycle, parse_module, read_cycle_program, resolve_module
from joulepath.program._output import check_written, reads_back, written_rapid
from joulepath.program._rapid_write import motion_model, planned_model, restore_program, same_model

# the cycle's own search (CycleSettings.gradient: GRID_SEARCH), on wider knots and fewer stages
FAST = GradientSettings(
    **{**GRID_SEARCH, "knot_spacing": 0.1, "continuation": (0.3, 0.03), "max_iter": 60, "coarse_factor": 1}
)
# The module is written from the plan before its MoveL segments are re-timed along their path
# (CycleResult.unretimed), which retime_segments=False gives as the result itself (measured: the same
# palletizing module but its header's planned energy, in 1/9 of the time); the module of a re-timed
# result is checked in test_cycle_units.py. The plan for via points (rapid_plan) is not written by
# written_rapid, and the modules written here had none (write_cycle_run tries it; test_cycle.py).
WRITE = CycleSettings(gradient=FAST, table_points=2, retime_segments=False, rapid_plan=False)
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

TWICE = """MODULE Twice
    CONST jointtarget jA := [[-30, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget jB := [[40, 25, -5, 20, 50, 30], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        WHILE TRUE DO
            Swing;
            WaitTime 0.5;
            Swing;
            WaitTime 0.5;
        ENDWHILE
    ENDPROC
    PROC Swing()
        MoveAbsJ jB, v1000, fine, tool0;
        MoveAbsJ jA, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


@pytest.fixture(scope="module")
def palletizing(robot):
    spec, _ = read_cycle_program(EXAMPLES / "palletizing.mod", robot)
    result = optimize_cycle(spec, WRITE)
    return result


@pytest.fixture(scope="module")
def twice(robot):
    spec = resolve_module(parse_module(TWICE, path="twice.mod"), robot)
    result = optimize_cycle(spec, replace(WRITE, cycle_time=4.5))
    return result


def _changes(before: str, after: str) -> tuple[list[tuple[int, str, str]], list[str]]:
    """(line, old, new) for lines changed in place, and the lines added, by difflib."""
    a, b = before.splitlines(), after.splitlines()
    changed: list[tuple[int, str, str]] = []
    added: list[str] = []
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(None, a, b, autojunk=False).get_opcodes():
        if tag == "equal":
            continue
        old, new = a[i1:i2], b[j1:j2]
        for k, line in enumerate(old):
            twin = next((n for n in new if n.strip().startswith(line.strip().rstrip(";)").strip())), None)
            changed.append((i1 + k + 1, line, twin or ""))
        added.extend(n for n in new if n not in {c[2] for c in changed})
    return changed, added


def _check_diff(source: str, layout) -> None:
    """Every changed line is an optimized move line or a call / PROC line of a procedure given
    jpRun (the same line with one more argument); every added line is an addition."""
    changed, added = _changes(source, layout.text)
    optimized = {m.line for m in layout.moves}
    indexed = [p.lower() for p in layout.indexed]
    for line, old, new in changed:
        if line in optimized:
            continue
        word = re.sub(r"^\s*(PROC\s+)?", "", old).split("(")[0].split()[0].rstrip(";").lower()
        assert word in indexed, f"line {line} changed: {old.strip()!r}"
        assert new.strip().startswith(old.strip().rstrip(";)")), (old, new)
        assert "jpRun" in new or new.rstrip().endswith(";"), new
    text = layout.text.splitlines()
    decl_at = next(k for k, t in enumerate(text) if "via points of the optimized moves" in t)
    decl_end = next(k for k in range(decl_at, len(text)) if not text[k].strip())
    procs_at = next(k for k, t in enumerate(text) if "the optimized moves (additions" in t)
    additions = set(text[decl_at:decl_end]) | set(text[procs_at:-1])
    for line in added:
        s = line.strip()
        assert line in additions or s.startswith("!") or re.fullmatch(r"jp_opt_\w+( .*)?;", s) or not s, (
            f"added outside the additions: {line!r}"
        )
    assert all(
        re.fullmatch(r"(CONST jointtarget jp_\w+\{\d+\} := \[|\[\[.*\]\],?|\];|!.*)", t.strip())
        for t in text[decl_at:decl_end]
    )


def test_palletizing_keeps_its_loops_procedures_and_targets(palletizing):
    """The written palletizing module keeps its FOR loops, its procedures and its named targets; a diff
    against the input shows only the optimized moves and the additions; it reads back as written."""
    source = (EXAMPLES / "palletizing.mod").read_text()
    layout = written_rapid(palletizing)
    text = layout.text
    for kept in (
        "FOR row FROM 0 TO 1 DO",
        "FOR col FROM 0 TO 2 DO",
        "MoveL pPick, v300, fine, tVacuum;",
        "MoveL pPlace, v300, fine, tVacuum;",
        "WaitTime 3; ! joulepath: idle",
    ):
        assert kept in text
    for decl in [ln for ln in source.splitlines() if ln.strip().startswith(("CONST", "PERS"))]:
        assert decl in text.splitlines()  # every declaration verbatim
    assert (
        re.search(r"PROC PickPart\(num jpRun\)", text)
        and "PROC PlacePart(robtarget pPlace, num jpRun)" in text
    )
    _check_diff(source, layout)
    assert reads_back(palletizing, text) is None
    # the runs of the pick approach differ (each from another place): per run, each run its own via points
    pick = next(m for m in layout.moves if m.procedure == "PickPart")
    assert pick.runs == 6 and pick.selection == "per run" and pick.shapes == pick.optimized_runs
    assert "TEST jpCtx" in text and "DEFAULT:" in text
    # a target the robot stops at ends with the program's own target
    home = next((m for m in layout.moves if m.final_target == "jHome"), None)
    if home is not None:
        assert re.search(r"MoveAbsJ jHome, v7000 \\T:=[\d.]+, fine, tVacuum;", text)
    assert set(layout.reteach) <= {"pPick", "pPallet", "jHome"} and "pPick" in layout.reteach


def test_reteaching_the_pick_moves_the_written_program(palletizing, robot):
    """Re-teach pPick in the written module (its value, as on the FlexPendant): parsed back, the
    program's pick moves go to the new pick, exactly where the taught program with the same edit goes,
    and the optimized via points stay."""
    old = "CONST robtarget pPick := [[175, -375, 140],"
    new = "CONST robtarget pPick := [[180, -370, 150],"
    source = (EXAMPLES / "palletizing.mod").read_text()
    text = written_rapid(palletizing).text
    assert old in text
    moved = resolve_module(parse_module(text.replace(old, new), path="w.mod"), robot)
    kept = resolve_module(parse_module(text, path="w.mod"), robot)
    taught = resolve_module(parse_module(source.replace(old, new), path="t.mod"), robot)
    picks = lambda spec: [s.q for s in spec.steps if s.kind == "move" and s.label == "MoveL pPick"]  # noqa: E731
    assert len(picks(moved)) == 6
    for q_new, q_taught, q_old in zip(picks(moved), picks(taught), picks(kept), strict=True):
        np.testing.assert_allclose(q_new, q_taught, atol=1e-12)
        assert np.abs(q_new - q_old).max() > 1e-3
    tcp = moved.steps[next(i for i, s in enumerate(moved.steps) if s.label == "MoveL pPick")]
    fk = robot.fk(tcp.q[None, :])
    p = fk.position_m[0] + fk.rotation[0] @ tcp.tcp[:3, 3]
    np.testing.assert_allclose(1000 * p, [180, -370, 150], atol=1e-6)
    vias = lambda spec: [s.q for s in spec.steps if s.label.startswith("MoveAbsJ jp_")]  # noqa: E731
    np.testing.assert_allclose(np.array(vias(moved)), np.array(vias(kept)), atol=0)


def test_stop_target_is_the_programs_own_and_is_retaught(twice, robot):
    """A move that stops at its target ends with the program's own move to it (same target, tool,
    timed): re-teaching jA moves the written program's stop there."""
    layout = written_rapid(twice)
    assert reads_back(twice, layout.text) is None
    named = [m for m in layout.moves if m.final_target is not None]
    assert named, "a stop at a target ends at the named target"
    for m in named:
        assert re.search(rf"MoveAbsJ {m.final_target}, v7000 \\T:=[\d.]+, fine, tool0;", layout.text)
    old = "[[-30, 10, 10, 0, 40, 0]"
    moved = resolve_module(
        parse_module(layout.text.replace(old, "[[-35, 10, 10, 0, 40, 0]"), path="w.mod"), robot
    )
    ends = [s.q for s in moved.steps if s.label == "MoveAbsJ jA"]
    assert ends and all(np.degrees(q[0]) == pytest.approx(-35.0) for q in ends)
    assert "jA" in layout.reteach


def test_procedure_called_twice_same_motion_is_one_shared_shape(twice):
    """Where every run of a move is the same motion, one shared shape is written (no TEST, no jpRun);
    where they differ, one per run, picked by the run number its call sites pass; both read back."""
    spec = twice.spec
    runs: dict[int, list[int]] = {}
    for i in twice.paths:
        runs.setdefault(spec.steps[i].line, []).append(i)
    line, (a, b) = next((ln, ix) for ln, ix in runs.items() if len(ix) == 2)
    same = replace(twice, paths={**twice.paths, b: twice.paths[a]}, vias={**twice.vias, b: twice.vias[a]})
    layout = written_rapid(same)
    move = next(m for m in layout.moves if m.line == line)
    assert move.selection == "shared" and move.shapes == 1 and move.runs == 2
    assert reads_back(same, layout.text) is None
    differ = written_rapid(twice)
    m2 = next(m for m in differ.moves if m.line == line)
    if m2.selection == "per run":
        assert "Swing" in differ.indexed and "Swing 1;" in differ.text and "Swing 2;" in differ.text
    assert reads_back(twice, differ.text) is None
    _check_diff(TWICE, differ)
    _check_diff(TWICE, layout)


def test_round_trip_is_checked_against_the_written_motion(twice, robot):
    """The round trip compares the motion itself: a written module with one via point's time changed
    does not read back as written."""
    text = written_rapid(twice).text
    spec = resolve_module(parse_module(text, path="w.mod"), robot)
    assert same_model(motion_model(spec), planned_model(twice)) is None
    tampered = re.sub(r"\\T:=([\d.]+)", lambda m: f"\\T:={float(m.group(1)) + 0.01:g}", text, count=1)
    spec2 = resolve_module(parse_module(tampered, path="w.mod"), robot)
    assert same_model(motion_model(spec2), planned_model(twice)) is not None


def test_written_module_goes_through_the_check(twice):
    """The structure-keeping module is what the controller emulation runs: the check's verdict is
    consistent with its numbers (whether it passes is reported, not assumed)."""
    check = check_written(twice, written_rapid(twice).text)
    tol = check["tolerances"]
    expected = (
        check["emulated_cycle_s"] <= twice.target_cycle_s + tol["slower_than_taught_s"]
        and check["emulated_energy_J"] <= twice.default_energy_J * (1 - tol["saved_at_least_pct"] / 100)
        and check["tcp_path_deviation_mm"] <= tol["path_mm"]
    )
    assert check["within_tolerances"] == expected


def test_run_number_expression_counts_the_runs_in_order():
    """The run number written for a position inside FOR loops (any first value and step, and a
    procedure's jpRun) counts 1, 2, ... in the order the loops run: the expression, evaluated by the
    program reader, against the mixed-radix count."""
    from joulepath.program._model import ForLoop
    from joulepath.program._parse import Names, _evaluate
    from joulepath.program._rapid_write import _run_expression, _run_value

    outer = ForLoop(1, 9, "i", (5, 3, 1), ())  # FOR i FROM 5 TO 1 STEP -2
    inner = ForLoop(2, 8, "j", (-1, 0, 1, 2), ())  # FOR j FROM -1 TO 2
    third = ForLoop(3, 7, "k", (0, 3, 6), ())  # FOR k FROM 0 TO 6 STEP 3
    loops = (outer, inner, third)
    for indexed in (False, True):
        expr = _run_expression(list(loops), indexed)
        count = 0
        for run in (1, 2) if indexed else (None,):
            for a in range(3):
                for b in range(4):
                    for c in range(3):
                        count += 1
                        names = Names(loop={"i": outer.values[a], "j": inner.values[b], "k": third.values[c]})
                        if run is not None:
                            names.params["jprun"] = float(run)
                        value = _evaluate("t.mod", 1, expr, names, "run")
                        here = ((outer, a), (inner, b), (third, c))
                        assert value == count == _run_value(here, run)


def test_payload_tool_procedure_with_arguments_reads_back(robot):
    """payload_tool: a procedure with two target arguments called twice, moves in a work object. Its
    written module keeps the procedure and its arguments, ends the stops at the program's own targets
    (with their work object), shows only optimized moves and additions in a diff, and reads back."""
    spec, _ = read_cycle_program(EXAMPLES / "payload_tool.mod", robot)
    result = optimize_cycle(spec, WRITE)
    source = (EXAMPLES / "payload_tool.mod").read_text()
    layout = written_rapid(result)
    assert "PROC Transfer(robtarget pFrom, robtarget pTo" in layout.text
    assert reads_back(result, layout.text) is None
    assert restore_program(layout.text) == source
    _check_diff(source, layout)
    for m in layout.moves:
        assert m.runs == 2
        if m.final_target is not None:
            end = r"\w+, tGripper2 \\WObj:=wobjFixture;"
            assert re.search(rf"Move[JL] {re.escape(m.final_target)}, v7000 \\T:=[\d.]+, {end}", layout.text)


def test_cycle_json_says_what_the_module_holds(twice, tmp_path):
    """cycle.json's rapid_structure names each optimized line, its procedure and how its runs are
    written, and the lines to optimize again per re-taught target, as the module holds them."""
    import json

    from joulepath.program import write_cycle_run

    files = write_cycle_run(tmp_path, twice, pareto=None, write_rapid=True, write_anyway=True)
    data = json.loads(files["cycle.json"].read_text())
    if "optimized.mod" not in files:
        assert data["rapid_structure"] is None
        return
    text = files["optimized.mod"].read_text()
    structure = data["rapid_structure"]
    for m in structure["optimized_lines"]:
        assert f"PROC {m['call']}(" in text and m["procedure"] == "Swing"
    assert set(structure["reteach"]) == {"jA", "jB"}


def test_a_name_the_module_already_uses_is_refused_in_one_line(twice, tmp_path):
    """The names joulepath adds must be new: one that the module already declares refuses the module in
    one line naming it (cycle.json's rapid_refused), nothing half-written."""
    import json

    from joulepath.errors import LimitViolation
    from joulepath.program import write_cycle_run

    lines = TWICE.splitlines()
    lines[2] += " CONST num jp_Swing_1 := 1;"  # same line numbers: the cycle's steps still fit
    clash = "\n".join(lines) + "\n"
    result = replace(twice, spec=replace(twice.spec, module=parse_module(clash, path="twice.mod")))
    with pytest.raises(LimitViolation, match=r"jp_swing_1\) are already used") as err:
        written_rapid(result)
    assert "\n" not in str(err.value)
    files = write_cycle_run(tmp_path, result, pareto=None, write_rapid=True, egm="never")
    assert "optimized.mod" not in files
    assert "already used" in json.loads(files["cycle.json"].read_text())["rapid_refused"]


def test_written_module_restores_the_program_it_was_written_from(palletizing, twice, robot, tmp_path):
    """restore(write(program)) is the program, to the character; a written module re-taught on the
    pendant is read by `cycle` as the program with the re-taught target, ready to optimize again."""
    source = (EXAMPLES / "palletizing.mod").read_text()
    text = written_rapid(palletizing).text
    assert restore_program(text) == source
    assert restore_program(written_rapid(twice).text) == TWICE
    assert restore_program(source) is None  # not written by joulepath: read as it is
    # with its waits spent (--use-waits): the wait comes back as written, its idle mark included
    spent = replace(twice, waits=tuple((line, s, s / 2) for line, s, _ in twice.waits))
    assert "WaitTime 0.25;" in written_rapid(spent).text
    assert restore_program(written_rapid(spent).text) == TWICE
    old, new = "[[175, -375, 140],", "[[180, -370, 150],"
    (tmp_path / "w.mod").write_text(text.replace(old, new))
    (tmp_path / "t.mod").write_text(source.replace(old, new))
    again, _ = read_cycle_program(tmp_path / "w.mod", robot)
    taught, _ = read_cycle_program(tmp_path / "t.mod", robot)
    assert "the program it was optimized from" in again.source
    assert same_model(motion_model(again), motion_model(taught), atol_rad=0.0) is None


LOOP = """MODULE Loop
    CONST jointtarget jA := [[-30, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pRow := [[350, 0, 300], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        WHILE TRUE DO
            MoveAbsJ jA, v1000, fine, tool0;
            FOR k FROM 0 TO 1 DO
                MoveJ Offs(pRow, 0, k * 120, 0), v1000, fine, tool0;
            ENDFOR
        ENDWHILE
    ENDPROC
ENDMODULE
"""


def test_move_inside_a_for_loop_gets_its_runs_by_the_loop_variable(robot):
    """A move directly inside a FOR loop: its optimized procedure receives the loop variable (for its
    Offs target) and the run number computed from it; it reads back and restores to the program."""
    spec = resolve_module(parse_module(LOOP, path="loop.mod"), robot)
    result = optimize_cycle(spec, WRITE)
    layout = written_rapid(result)
    assert reads_back(result, layout.text) is None
    assert restore_program(layout.text) == LOOP
    _check_diff(LOOP, layout)
    move = next((m for m in layout.moves if m.line == 8), None)
    if move is not None:
        assert move.runs == 2
        call = next(ln.strip() for ln in layout.text.splitlines() if ln.strip().startswith(move.call + " "))
        expected = f"{move.call} k, k + 1;" if move.selection == "per run" else f"{move.call} k;"
        assert call == expected
        assert f"PROC {move.call}(num k" in layout.text
