"""simulate_program: a module's main once on the controller emulation and a plant, as a controller log."""

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.data import read_log
from joulepath.errors import InvalidInput
from joulepath.program import RapidError, program_motion, read_rapid_cycle, simulate_program
from joulepath.sim import ControllerConfig, make_plant

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
A = [10, 0, 0, 0, 30, 0]
B = [40, 20, -10, 15, 45, 30]
PROGRAM = f"""MODULE Two
    CONST jointtarget jA := [[{", ".join(map(str, A))}], {EXT}];
    CONST jointtarget jB := [[{", ".join(map(str, B))}], {EXT}];
    PROC main()
        FOR i FROM 1 TO 2 DO
            MoveAbsJ jA, v1000, fine, tool0;
            WaitTime 0.5;
            MoveAbsJ jB, v1000 \\T:=1.2, fine, tool0;
        ENDFOR
    ENDPROC
ENDMODULE
"""


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb120")


@pytest.fixture
def program(tmp_path):
    path = tmp_path / "two.mod"
    path.write_text(PROGRAM)
    return path


def test_simulate_program_writes_the_controller_log(tmp_path, program, robot):
    res = simulate_program(program, tmp_path / "log.csv", robot=robot, plant="sim", seed=3)
    log = read_log(res.log)
    assert res.n_rows == log.n_rows and res.n_moves == 4
    np.testing.assert_allclose(res.start_rad, np.radians(A), atol=1e-12)  # the first move's target
    np.testing.assert_allclose(log.q[0], np.radians(A), atol=1e-6)  # at rest there when main starts
    np.testing.assert_allclose(log.q[-1], np.radians(B), atol=1e-6)  # and at the last target at the end
    assert np.abs(log.qd[-1]).max() < 1e-6
    # main runs once: twice to jB (1.2 s each, \T) after the move back to jA and its wait
    config = ControllerConfig()
    plan = program_motion(read_rapid_cycle([program], robot), config).plan
    assert res.program_time_s == pytest.approx(plan.cycle_time)
    assert res.duration_s == pytest.approx(plan.cycle_time + 2 * config.idle, abs=2 * config.sample_period)
    to_b = [m for m in plan.moves if m.step.label == "MoveAbsJ jB"]
    assert [m.profile.duration for m in to_b] == pytest.approx([1.2, 1.2])


def test_simulate_program_torque_is_the_plants(tmp_path, program, robot):
    res = simulate_program(program, tmp_path / "log.csv", robot=robot, plant="sim", seed=0)
    log = read_log(res.log)
    tau = make_plant("sim", robot).drive_torque(log.q, log.qd, np.zeros_like(log.q))
    rest = np.abs(log.qd).max(axis=1) < 1e-9  # at rest the torque holds the arm against gravity
    np.testing.assert_allclose(log.tau[rest], tau[rest], atol=2e-5)


def test_simulate_program_from_a_given_start(tmp_path, program, robot):
    q0 = np.radians([0, 0, 0, 0, 30, 0])
    res = simulate_program(program, tmp_path / "log.csv", robot=robot, plant="sim", start=q0)
    log = read_log(res.log)
    np.testing.assert_allclose(log.q[0], q0, atol=1e-6)
    assert res.n_moves == 4


def test_simulate_program_same_seed_same_log(tmp_path, program, robot):
    a = simulate_program(program, tmp_path / "a.csv", robot=robot, plant="lab", seed=5)
    b = simulate_program(program, tmp_path / "b.csv", robot=robot, plant="lab", seed=5)
    c = simulate_program(program, tmp_path / "c.csv", robot=robot, plant="lab", seed=6)
    assert a.log.read_text() == b.log.read_text()
    assert a.log.read_text() != c.log.read_text()


def test_simulate_program_refuses_a_start_outside_the_ranges(tmp_path, program, robot):
    with pytest.raises(InvalidInput, match="start joint 5 = 150.00 deg is outside its range"):
        simulate_program(program, tmp_path / "log.csv", robot=robot, start=np.radians([0, 0, 0, 0, 150, 0]))
    assert not (tmp_path / "log.csv").exists()


def test_simulate_program_refuses_an_unreadable_module(tmp_path, robot):
    bad = tmp_path / "bad.mod"
    bad.write_text(PROGRAM.replace("TO 2 DO", "TO 2"))
    with pytest.raises(RapidError, match=r"bad.mod:6: syntax error at .MoveAbsJ.: RAPID expects DO"):
        simulate_program(bad, tmp_path / "log.csv", robot=robot)
    assert not (tmp_path / "log.csv").exists()


def test_collection_program_in_table_mode_runs_as_simulate_draws_it(tmp_path, robot):
    """JPCollect.mod (table mode) as a program: the moves and times ``simulate --seed`` runs."""
    from joulepath.export import collection_programs, draw_moves
    from joulepath.sim import plan_moves

    path = tmp_path / "JPCollect.mod"
    path.write_text(collection_programs(robot, n_moves=12, mode="table", seed=4)["JPCollect.mod"])
    config = ControllerConfig()
    drawn = draw_moves(robot, 12, range_set="collection", rng=np.random.default_rng(4))
    direct = plan_moves(robot, robot.home, drawn, config)
    spec = read_rapid_cycle([path], robot)
    program = program_motion(spec, config, start=robot.home)
    assert len(program.plan.moves) == len(direct.segments) == 12
    for seg, move in zip(direct.segments, program.plan.moves, strict=True):
        np.testing.assert_allclose(move.step.q, seg.move.target, atol=1e-5)  # 4 decimals of a degree
        assert move.t0 + program.offset == pytest.approx(seg.t0, abs=1e-3)
        assert move.t_end + program.offset == pytest.approx(seg.t_end, abs=1e-3)


def test_simulate_program_runs_a_task_folder_as_the_interpreter_reads_it(tmp_path, program, robot):
    """A task of two modules (the targets in one, main in the other) runs as the one-module program."""
    task = tmp_path / "task"
    task.mkdir()
    decls = "\n".join(line for line in PROGRAM.splitlines() if "CONST jointtarget" in line)
    (task / "Data.mod").write_text(f"MODULE Data\n{decls}\nENDMODULE\n")
    body = "\n".join(line for line in PROGRAM.splitlines()[1:] if "CONST jointtarget" not in line)
    (task / "Main.mod").write_text(f"MODULE Main\n{body}\n")
    one = simulate_program(program, tmp_path / "one.csv", robot=robot, plant="sim", seed=2)
    two = simulate_program(task, tmp_path / "two.csv", robot=robot, plant="sim", seed=2)
    assert two.n_moves == one.n_moves == 4
    assert two.log.read_text() == one.log.read_text()


def test_simulate_program_says_what_it_assumed(tmp_path, program, robot):
    """A bound declared nowhere is a stand-in (0 taken): the run says so, a line, and runs what is left."""
    text = PROGRAM.replace(
        "FOR i FROM 1 TO 2 DO", "MoveAbsJ jB, v1000, fine, tool0;\n        FOR i FROM 1 TO nTimes DO"
    )
    (tmp_path / "p.mod").write_text(text)
    res = simulate_program(tmp_path / "p.mod", tmp_path / "log.csv", robot=robot, plant="sim")
    assert res.n_moves == 1
    assert any(line.startswith("assumed: ") and "nTimes" in line for line in res.said), res.said
