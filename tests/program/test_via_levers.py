"""A plan for RAPID made on the controller emulation: the plan's via points with the levers of its via points.

Invariants and agreement only: the written module, read again by the RAPID interpreter (not the reader
the search used) and run by the controller emulation, gives the cycle time and energy the result
reports, recomputed here from its own motion; it keeps the taught cycle time and spends less; only the
added via-point procedures change, so the module still reads back as the program it was written from;
and a corridor it leaves refuses it.
"""

import re
from dataclasses import replace

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.energy import measure_power
from joulepath.program import CycleSettings, optimize_cycle, parse_module, resolve_module, via_levers
from joulepath.program._rapid_write import HEADERS, restore_program
from joulepath.program._task import as_sequence, read_written
from joulepath.program._via_levers import _CALL, _marked, _plain, _reverted, _scaled, _units, _with_header
from joulepath.sim import FINE_DT, ControllerConfig, evaluate_cycle, plan_cycle

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
PROGRAM = f"""MODULE T
    ! a cell of three joint moves, two stops with a gripper's wait
    CONST robtarget pB := [[300, 200, 400], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    CONST robtarget pC := [[300, -200, 350], [0, 0, 1, 0], [-1, 0, -1, 0], {EXT}];
    CONST jointtarget jH := [[0, 0, 0, 0, 30, 0], {EXT}];
    PROC main()
        MoveAbsJ jH, v1000, fine, tool0;
        WHILE TRUE DO
            MoveJ pB, v1000, fine, tool0;
            WaitTime 0.3;
            MoveJ pC, v1000, z20, tool0;
            MoveAbsJ jH, v1000, fine, tool0;
            WaitTime 0.3;
        ENDWHILE
    ENDPROC
ENDMODULE
"""


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb120")


@pytest.fixture(scope="module")
def planned(robot):
    spec = resolve_module(parse_module(PROGRAM, path="cell.mod"), robot)
    settings = CycleSettings(table_points=2, pass_search=0)
    settings = replace(settings, gradient=replace(settings.gradient, knot_spacing=0.1))
    result = optimize_cycle(spec, settings)
    return result, via_levers(result, robot, energy="thesis", max_seconds=60, timed_chains=False)


def _executed(text: str, robot) -> tuple[float, float]:
    """``text`` read by the RAPID interpreter, run by the controller emulation: cycle time, energy (J)."""
    plan = plan_cycle(as_sequence(read_written(text, "written.mod", robot)), ControllerConfig())
    n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
    traj = evaluate_cycle(plan, np.linspace(0.0, plan.cycle_time, n))
    r = plan.moves[0].step.robot
    tau = r.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
    power = measure_power("thesis", tau, traj.qd, r.drivetrain).value
    return plan.cycle_time, float((power * np.append(np.diff(traj.t), 0.0)).sum())  # each sample to the next


def test_written_module_runs_within_the_taught_cycle_and_saves_as_executed(robot, planned):
    result, via = planned
    assert via.levers is not None, via.note
    lv = via.levers
    assert lv.base == "via points" and lv.reads_back is None
    t, e = _executed(lv.written_text, robot)  # recomputed from the written module's own motion
    t0, e0 = _executed(PROGRAM, robot)
    assert t == pytest.approx(lv.cycle_s, abs=1e-9)
    assert e == pytest.approx(lv.energy_J, rel=1e-9)
    assert (t0, e0) == pytest.approx((lv.taught_cycle_s, lv.default_energy_J), rel=1e-9)
    assert t <= t0 + 1e-6
    assert e < e0
    assert lv.saved_pct == pytest.approx(100.0 * (1.0 - e / e0), rel=1e-9)
    # the levers only ever lower the via-point module's energy, within the taught cycle
    assert e <= via.via_energy_J * (1 + 1e-12)


def test_it_restores_to_the_program_and_every_change_is_marked(robot, planned):
    result, via = planned
    lv = via.levers
    assert lv is not None
    # the module reads back as the program it was written from: byte for byte
    assert restore_program(lv.written_text) == PROGRAM
    lines = lv.written_text.splitlines()
    spec = resolve_module(parse_module(_plain(lv.written_text), path="w.mod"), robot)
    shift = len(lines) - len(_plain(lv.written_text).splitlines())
    added = [
        (p.line + shift, p.end_line + shift) for p in spec.module.procedures if p.name.startswith("jp_opt_")
    ]
    assert added
    for m in lv.moves:
        if m.changed:  # in an added procedure, or a statement of the program under its `was:` lines
            assert any(a <= m.line <= b for a, b in added) or lines[m.line - 2].strip().startswith(
                "! joulepath: was:"
            ), m
    assert lv.n_changed >= 1


def test_marked_edits_restore_and_run_as_edited():
    before = (
        "MODULE M\n"
        "    PROC main()\n"
        "        MoveJ p, v1000, z50, tool0; ! to the pick\n"
        "        WaitTime 0.2;\n"
        "        jp_opt_main_3;\n"
        "    ENDPROC\n"
        "    PROC jp_opt_main_3()\n"
        "        MoveAbsJ j{1}, v7000 \\T:=0.25, z200, tool0;\n"
        "    ENDPROC\n"
        "ENDMODULE\n"
    )
    after = (
        before.replace("        MoveJ p, v1000, z50,", "        AccSet 50, 100;\n        MoveJ p, v800, z20,")
        .replace("        WaitTime 0.2;\n", "        AccSet 100, 100;\n        WaitTime 0.2;\n")
        .replace("\\T:=0.25", "\\T:=0.3")
    )
    marked, where = _marked(before, after, added=set(range(7, 10)))
    out = marked.splitlines()
    assert out[2:5] == [  # the statement and the AccSet lines around it on one line, the comment at its end
        "        ! joulepath: was: MoveJ p, v1000, z50, tool0; ! to the pick",
        "        AccSet 50, 100; MoveJ p, v800, z20, tool0; AccSet 100, 100; ! to the pick",
        "        WaitTime 0.2;",
    ]
    assert (where[3], where[4], where[5]) == (4, 5, 6)
    assert "\\T:=0.3" in out[where[8] - 1]  # the added procedure as the levers wrote it
    assert restore_program(_with_header(marked, [HEADERS[1]])).splitlines()[:5] == before.splitlines()[:5]
    from joulepath.rapid import parse_module as parse_rapid

    calls = [c.name for c in parse_rapid(marked, path="m.mod").routines[0].body]
    assert calls == ["AccSet", "MoveJ", "AccSet", "WaitTime", "jp_opt_main_3"]


def test_a_corridor_it_leaves_refuses_it(robot, planned):
    result, via = planned
    assert via.deviation_mm is not None and via.deviation_mm > 0.5
    narrow = via_levers(result, robot, energy="thesis", corridor_mm=0.5, max_seconds=60, timed_chains=False)
    assert narrow.levers is None
    assert "corridor" in narrow.note and f"{narrow.deviation_mm:.1f} mm" in narrow.note


def test_scaling_changes_only_the_t_of_the_given_lines():
    text = (
        "MODULE M\n"
        "    PROC jp_opt_main_1()\n"
        "        MoveAbsJ j{1}, v7000 \\T:=0.25, z200, tool0;\n"
        "        MoveAbsJ j{2}, v7000 \\T := 1.5, fine, tool0;\n"
        "    ENDPROC\n"
        "    PROC main()\n"
        "        MoveJ p, v1000 \\T:=2, z10, tool0;\n"
        "    ENDPROC\n"
        "ENDMODULE\n"
    )
    out = _scaled(text, {3, 4}, 0.5)
    assert re.findall(r"\\T\s*:=\s*([\d.]+)", out) == ["0.1250", "0.7500", "2"]
    changed = [a for a, b in zip(text.splitlines(), out.splitlines(), strict=True) if a != b]
    assert changed == text.splitlines()[2:4]


def test_header_goes_under_the_module_line_with_its_line_ends():
    text = "MODULE M\r\n    PROC main()\r\n    ENDPROC\r\nENDMODULE\r\n"
    out = _with_header(text, ["! one", "! two"])
    assert out.splitlines(keepends=True)[1:3] == ["    ! one\r\n", "    ! two\r\n"]
    assert _plain(_with_header(text, ["! Optimized by joulepath x"])) == text


def test_a_unit_put_back_as_taught_is_the_taught_statement(robot, planned):
    from joulepath.program._output import written_rapid

    result, _ = planned
    text = _plain(written_rapid(result.unretimed or result).text)
    units = _units(text)
    assert units  # every optimized move of this program is a call under its `was:` lines
    for u in units:
        back = _reverted(text, u)
        assert len(back.splitlines()) == len(text.splitlines()) - 1
        assert not _CALL.match(back.splitlines()[u - 1])
        assert restore_program(_with_header(back, [HEADERS[1]])) == PROGRAM
        # the statement put back runs as the taught program ran it: the same target
        again = resolve_module(parse_module(back, path="b.mod"), robot)
        taught = [s for s in result.spec.steps if s.kind == "move"]
        moved = [s.q for s in again.steps if s.kind == "move"]
        assert any(np.allclose(q, taught[-1].q) for q in moved)


def test_calls_with_arguments_go_back_to_the_statement_they_replaced():
    text = (
        "MODULE M\n"
        "    PROC Transfer(robtarget pFrom, robtarget pTo, num jpRun)\n"
        "        ! joulepath: was: MoveJ Offs(pTo, 0, 0, 100), v1000, z20, tool0;\n"
        "        jp_opt_Transfer_4 pFrom, pTo, jpRun;\n"
        "        jp_opt_Transfer_5 pFrom, pTo, jpRun;\n"
        "    ENDPROC\n"
        "ENDMODULE\n"
    )
    assert _units(text) == [3]  # the second call stands under no `was:` line: it stays
    assert _reverted(text, 3).splitlines()[2:4] == [
        "        MoveJ Offs(pTo, 0, 0, 100), v1000, z20, tool0;",
        "        jp_opt_Transfer_5 pFrom, pTo, jpRun;",
    ]


def test_a_bundled_program_keeps_its_structure_and_saves_as_executed(robot):
    from pathlib import Path

    from joulepath.program import read_cycle_program

    path = Path(__file__).parents[2] / "examples" / "approach_depart.mod"
    spec, _ = read_cycle_program(path, robot)
    settings = CycleSettings(table_points=2, pass_search=0)
    settings = replace(settings, gradient=replace(settings.gradient, knot_spacing=0.1))
    result = optimize_cycle(spec, settings)
    via = via_levers(result, robot, energy="thesis", max_seconds=10)
    assert via.levers is not None, via.note
    text = via.levers.written_text
    # read again by the interpreter, run by the emulation: the figures, recomputed from its own motion
    t, e = _executed(text, robot)
    t0, e0 = _executed(path.read_text(), robot)
    assert (t, e) == pytest.approx((via.levers.cycle_s, via.levers.energy_J), rel=1e-9)
    assert t <= t0 + 1e-6 and e < e0
    # the program as written: its procedures, its loop, its named targets, and it restores to it
    original = path.read_text()
    for word in re.findall(r"PROC\s+(\w+)", original) + re.findall(r"robtarget\s+(\w+)", original):
        assert word in text
    assert "WHILE TRUE DO" in text
    assert restore_program(text) == original
    # every taught MoveL line run no faster than its speed data, but in the controller's own blends
    # between two statements (a timed chain's corners, whose \T were chosen, are counted)
    from joulepath.optimize._retime import tcp_velocity
    from joulepath.program._line_speed import SPEED_TOL, fastest_on_lines, line_speeds
    from joulepath.sim import tcp_pose
    from joulepath.sim._timing import ChainProfile

    lines = line_speeds(plan_cycle(spec, ControllerConfig()))
    assert lines, "approach_depart approaches and leaves its parts on MoveL lines"
    plan = plan_cycle(as_sequence(read_written(text, "written.mod", robot)), ControllerConfig())
    t = np.linspace(0.0, plan.cycle_time, int(np.ceil(plan.cycle_time / FINE_DT)) + 1)
    traj = evaluate_cycle(plan, t)
    own = np.ones(t.size, dtype=bool)
    moving = [m for m in plan.moves if m.profile.duration > 0]
    for a, b in zip(moving, moving[1:], strict=False):
        if b.t0 < a.t_end and not (
            isinstance(a.profile, ChainProfile) and isinstance(b.profile, ChainProfile)
        ):
            own &= (t < b.t0) | (t > a.t_end)
    tcp = plan.moves[0].step.tcp
    pos, _ = tcp_pose(robot, traj.q[own], tcp)
    ratio, line = fastest_on_lines(lines, pos, tcp_velocity(robot, traj.q[own], traj.qd[own], tcp))
    assert ratio <= 1.0 + SPEED_TOL, line
