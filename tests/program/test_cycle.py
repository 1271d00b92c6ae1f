"""The cycle: the controller emulation against independent evaluations, and the optimization's invariants."""

import json
from dataclasses import replace

import numpy as np
import pytest

import joulepath
from joulepath.cli._main import main
from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.energy import path_energy
from joulepath.optimize import GradientSettings
from joulepath.program import (
    FAST_CYCLE,
    CycleSettings,
    optimize_cycle,
    parse_module,
    plan_cycle,
    read_cycle_toml,
    read_module,
    resolve_module,
)
from joulepath.program._cycle import CycleOptimizer, _optimize_cycle
from joulepath.sim import JERK_TIME, ControllerConfig
from joulepath.sim._timing import FINE_DT, evaluate_cycle, standalone

SMALL = """MODULE Small
    CONST jointtarget jA := [[-30, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget jB := [[40, 25, -5, 20, 50, 30], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pDown := [[350, 0, 300], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pUp := [[350, 0, 420], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        WHILE TRUE DO
            MoveAbsJ jA, v1000, z20, tool0;
            MoveJ pUp, v1000, fine, tool0;
            MoveL pDown, v200, fine, tool0;
            WaitTime 0.2;
            MoveL pUp, v200, z10, tool0;
            MoveAbsJ jB, v800, fine, tool0;
            SetDO doGrip, 1;
        ENDWHILE
    ENDPROC
ENDMODULE
"""
FAST = GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), max_iter=60, coarse_factor=1)
REACHABLE = 4.0
"""s: a cycle time SMALL's optimized moves reach within the controller's jerk limits. Its own cycle,
3.552 s, is out of their reach (shortest 3.734 s): a minimum-jerk move under the jerk limit, which
each optimized move starts from, is slower than the controller's own sin² ramps."""


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


@pytest.fixture(scope="module")
def spec(robot):
    return resolve_module(parse_module(SMALL, path="small.mod"), robot)


@pytest.fixture(scope="module")
def reachable(spec):
    """SMALL optimized at REACHABLE with its waits spent (zones and fly-by on): (result, optimizer)."""
    return _optimize_cycle(
        spec, CycleSettings(gradient=FAST, table_points=3, use_waits=True, cycle_time=REACHABLE)
    )


def test_fine_moves_superposed_equal_standalone(spec, robot):
    """With stop points only, the superposed cycle is the standalone moves one after another."""
    plan = plan_cycle(spec, ControllerConfig())
    checked = 0
    for prev, m in zip((None, *plan.moves[:-1]), plan.moves, strict=True):
        if not m.stops or m.profile.duration == 0 or (prev is not None and not prev.stops):
            continue
        checked += 1
        alone = standalone(m)
        t = m.t0 + alone.t
        joint = evaluate_cycle(plan, t)
        assert np.allclose(joint.q, alone.q, atol=1e-9)
        assert np.allclose(joint.qd, alone.qd, atol=1e-9)
    assert checked >= 1


def test_movel_keeps_the_tcp_on_the_line(spec, robot):
    plan = plan_cycle(spec, ControllerConfig())
    m = next(m for m in plan.moves if m.step.linear)
    traj = standalone(m)
    tcp = robot.fk(traj.q).position_m
    a, b = tcp[0], tcp[-1]
    u = (b - a) / np.linalg.norm(b - a)
    off = (tcp - a) - ((tcp - a) @ u)[:, None] * u
    assert np.linalg.norm(off, axis=1).max() < 1e-4  # 0.1 mm (cubic spline between 64 IK points)
    speed = np.linalg.norm(np.gradient(tcp, traj.t, axis=0), axis=1)
    assert speed.max() <= 0.2 * 1.02  # v200


def test_zone_shortens_the_cycle(robot):
    fine = SMALL.replace("z20", "fine").replace("z10", "fine")
    a = plan_cycle(resolve_module(parse_module(SMALL, path="a.mod"), robot), ControllerConfig())
    b = plan_cycle(resolve_module(parse_module(fine, path="b.mod"), robot), ControllerConfig())
    assert a.cycle_time < b.cycle_time


def test_optimized_cycle_invariants(spec, robot, tmp_path):
    settings = CycleSettings(
        gradient=FAST, table_points=3, use_waits=True, cycle_time=REACHABLE, jerk_time=JERK_TIME
    )
    result = optimize_cycle(spec, settings, pareto_points=4)
    assert result.optimized_cycle_s <= result.target_cycle_s + 1e-9
    assert result.limits_ok
    units = {"MoveAbsJ jA", "MoveJ pUp", "MoveAbsJ jB"}
    assert units <= {m.label for m in result.moves if m.optimized}
    # any other move changed is a MoveL re-timed along its segment's path (its line kept)
    assert all(
        m.note.startswith("MoveL re-timed") for m in result.moves if m.optimized and m.label not in units
    )
    # the default corridor holds: tool0 within 100 mm of the joint-interpolated taught move
    assert result.corridor_mm == 100.0
    assert all(m.corridor_dev_mm <= 100.0 + 1e-6 for m in result.moves if m.optimized)
    # the reported total is the sum over the moves, on both plants
    assert result.optimized_energy_J == pytest.approx(sum(m.optimized_energy_J for m in result.moves))
    assert result.default_energy_J == pytest.approx(sum(m.default_energy_J for m in result.moves))
    # an optimized move's energy recomputed independently from its path (a move on its own)
    in_chain = {j for c in result.chains.values() for j in c}
    i, s = next((j, p) for j, p in result.paths.items() if j not in in_chain)
    r = spec.steps[i].robot
    # (each sample's power times the step to the next: a piece the cycle continues from ends in motion)
    w = np.append(np.diff(s.fine.t), 0.0)[:, None]
    tau = r.inverse_dynamics(s.fine.q, s.fine.qd, s.fine.qdd, friction=NOMINAL_FRICTION)
    assert s.energy_J == pytest.approx(float((np.abs(tau * s.fine.qd) * w).sum()))
    assert s.fine.dt == pytest.approx(FINE_DT, rel=1e-3)  # a re-timed piece: its segment on its own grid
    # every optimized move keeps the jerk limit (the controller's default) on the 2.5 ms grid
    from joulepath.optimize import jerk_limit, path_jerk

    jmax = jerk_limit(r, settings.accel_time, settings.jerk_time)
    assert jmax is not None
    for p in result.paths.values():
        assert np.all(np.abs(path_jerk(p.fine)[1]) <= jmax * (1 + 1e-7))
    # a result outside a limit is refused: no module, the reason in cycle.json, a stale module removed
    from dataclasses import replace

    from joulepath.errors import LimitViolation
    from joulepath.program import optimized_module, write_cycle_run

    bad = replace(result, limits_ok=False)
    with pytest.raises(LimitViolation, match="not written"):
        optimized_module(bad)
    (tmp_path / "optimized.mod").write_text("old")
    files = write_cycle_run(tmp_path, bad, pareto=None, write_rapid=True)
    assert "optimized.mod" not in files and not (tmp_path / "optimized.mod").exists()
    assert json.loads((tmp_path / "cycle.json").read_text())["rapid_refused"]
    # more cycle time never costs energy (each point: best combination within a larger budget)
    front = result.pareto
    e = [p.energy_J for p in front]
    assert len(front) == 4 and all(b <= a + 1e-9 for a, b in zip(e, e[1:], strict=False))
    assert front[0].cycle_time_s == pytest.approx(result.shortest_cycle_s)


def test_jerk_limits_lengthen_the_shortest_cycle(spec):
    """A jerk limit never shortens the shortest cycle; the program's own cycle time stays reachable
    with or without one (each unit's taught motion is a candidate), a shorter one is refused."""
    from joulepath.errors import LimitViolation

    loose = CycleOptimizer(spec, CycleSettings(gradient=FAST, jerk_time=0))
    tight = CycleOptimizer(spec, CycleSettings(gradient=FAST, jerk_time=JERK_TIME))
    assert all(tight.solver.t_lo[i] >= loose.solver.t_lo[i] - 1e-9 for i in loose.solver.t_lo)
    assert loose.solver.shortest_cycle <= tight.solver.shortest_cycle + 1e-9 <= tight.plan.cycle_time + 2e-9
    r = optimize_cycle(spec, CycleSettings(gradient=FAST, table_points=2, jerk_time=JERK_TIME))
    assert r.optimized_cycle_s <= r.default_cycle_s + 1e-9
    assert r.optimized_energy_J <= r.default_energy_J * (1 + 1e-9)
    with pytest.raises(
        LimitViolation, match=r"shorter than the shortest .*optimized moves at their shortest"
    ):
        optimize_cycle(
            spec,
            CycleSettings(gradient=FAST, jerk_time=JERK_TIME, cycle_time=0.9 * tight.solver.shortest_cycle),
        )
    # the default (no jerk limit yet for whole cycles) reaches the program's own cycle time
    assert CycleSettings().jerk_time == 0.0


def test_cycle_settings_refuse_a_negative_jerk_time(tmp_path):
    from joulepath.errors import InvalidInput

    with pytest.raises(InvalidInput, match=r"jerk_time must be in \[0, 10\] s"):
        CycleSettings(jerk_time=-0.1)
    prog = tmp_path / "small.mod"
    prog.write_text(SMALL)
    assert main(["cycle", str(prog), "--out", str(tmp_path / "run"), "--jerk-time", "-1"]) == 2


def test_cycle_time_too_short_refused(spec):
    from joulepath.errors import LimitViolation

    opt = CycleOptimizer(spec, CycleSettings(gradient=FAST))
    with pytest.raises(LimitViolation, match="shorter than the shortest"):
        optimize_cycle(spec, CycleSettings(gradient=FAST, cycle_time=0.5 * opt.solver.shortest_cycle))


def test_cli_writes_a_program_that_reads_back(tmp_path, robot):
    prog = tmp_path / "small.mod"
    prog.write_text(SMALL.replace("MoveAbsJ jB, v800", "MoveAbsJ jB, v300"))
    out = tmp_path / "run"
    args = ["--use-waits", "--idle-wait", "11", "--knot-spacing", "0.1", "--table-points", "2"]
    # the plan's own via-point module is what this test reads back: no search of the controller's
    # levers (tests/program/test_levers*.py, test_via_levers.py and test_export_choice.py test those)
    args += ["--lever-plans", "0"]
    rc = main(["cycle", str(prog), "--out", str(tmp_path / "strict"), "--export", "rapid", *args])
    strict = json.loads((tmp_path / "strict" / "cycle.json").read_text())
    if strict["written_program_matches_plan"]:
        assert rc == 0 and (tmp_path / "strict" / "optimized.mod").is_file()
    else:  # not written unless asked: the reason, with the emulated numbers, in cycle.json
        assert rc == 1 and not (tmp_path / "strict" / "optimized.mod").exists()
        assert "do not keep the plan" in strict["rapid_refused"] and strict["rapid"] is None
        assert not (tmp_path / "strict" / "egm.mod").exists()
    # the default (--export auto): RAPID where the emulation runs it, else the EGM module
    assert main(["cycle", str(prog), "--out", str(tmp_path / "auto"), *args]) == 0
    assert (tmp_path / "auto" / "optimized.mod").is_file() != (tmp_path / "auto" / "egm.mod").is_file()
    # energy against cycle time only here, where pareto.csv is read (the plan is the same without it)
    assert (
        main(["cycle", str(prog), "--out", str(out), *args, "--pareto", "--points", "3", "--write-anyway"])
        == 0
    )
    data = json.loads((out / "cycle.json").read_text())
    assert data["saved_pct"] == pytest.approx(strict["saved_pct"])  # same plan either way
    # every energy figure is one stage on the run's measure (read as a user reads cycle.json)
    m, figures = data["energy_measure"], data["energy_figures"]
    assert figures["measure"] == m
    for stage in ("planned", "lab", "executed"):
        assert figures[stage]["measure"] == m
        for key in ("default_J", "optimized_J", "saved_pct"):
            assert data[f"{stage}_{key}"] == pytest.approx(figures[stage][key])
    assert data["planned_default_J"] == pytest.approx(data["energy_default_J"])
    whole = data["energies"][m]  # the whole cycle, standby included where counted: the motion alone
    assert data["lab_default_J"] == pytest.approx(whole["lab_default_J"] - whole["standby_J"])
    assert data["executed_optimized_J"] == pytest.approx(data["executed_energy_J"])
    assert "mechanical" in data["deprecated_keys"]["saved_lab_pct"]
    assert data["limits_ok"] and data["optimized_cycle_s"] <= data["target_cycle_s"] + 1e-9
    assert data["waits"] == [{"line": 11, "default_s": 0.2, "optimized_s": 0.0}]  # the idle wait
    assert data["kept_verbatim_lines"] == [14]
    assert (out / "pareto.csv").read_text().count("\n") == 3 + 2
    written = read_module(out / "optimized.mod")
    again = resolve_module(written, robot)
    moves = [s for s in again.steps if s.kind == "move"]
    original = [s for s in resolve_module(parse_module(SMALL, path="s.mod"), robot).steps if s.kind == "move"]
    # the targets the original program stops at are reached by the optimized program too
    ends = {tuple(np.round(s.q, 6)) for s in moves}
    for s in original:
        if s.zone_mm is None:
            assert tuple(np.round(s.q, 6)) in ends
    # every written joint target within its range
    lo, hi = robot.joint_ranges()
    assert all(np.all(s.q >= lo - 1e-9) and np.all(s.q <= hi + 1e-9) for s in moves)
    # untouched statements are unchanged
    assert "MoveL pDown, v200, fine, tool0;" in (out / "optimized.mod").read_text()
    assert "SetDO doGrip, 1;" in (out / "optimized.mod").read_text()
    # a wait not declared idle keeps its length
    assert main(
        [
            "cycle",
            str(prog),
            "--out",
            str(tmp_path / "w"),
            "--use-waits",
            "--knot-spacing",
            "0.1",
            "--table-points",
            "2",
            "--lever-plans",
            "0",
        ]
    ) in (0, 1)
    kept = json.loads((tmp_path / "w" / "cycle.json").read_text())
    assert kept["waits"] == [{"line": 11, "default_s": 0.2, "optimized_s": 0.2}]


def test_plain_cycle_file(tmp_path, robot):
    f = tmp_path / "cycle.toml"
    f.write_text(
        "[[step]]\njoints_deg = [-30, 10, 10, 0, 40, 0]\nduration_s = 1.2\n"
        "[[step]]\nwait_s = 0.2\n"
        "[[step]]\njoints_deg = [40, 25, -5, 20, 50, 30]\nduration_s = 1.0\n"
    )
    spec = read_cycle_toml(f, robot)
    plan = plan_cycle(spec, ControllerConfig())
    assert [round(m.profile.duration, 9) for m in plan.moves] == [1.2, 1.0]
    result = optimize_cycle(spec, CycleSettings(gradient=FAST, table_points=2))
    assert result.limits_ok and result.optimized_cycle_s <= result.target_cycle_s + 1e-9
    # every measure of the whole cycle, the optimized one (thesis) agreeing with the headline
    thesis = {e.measure: e for e in result.energies}["thesis"]
    assert thesis.default_J == pytest.approx(result.default_energy_J, rel=1e-9)
    assert thesis.optimized_J == pytest.approx(result.optimized_energy_J, rel=1e-9)
    # the cycle optimized on the electrical energy: the meter-level figure includes the standby
    # power over the cycle time; the reshaped motion never costs more than the taught one
    electric = optimize_cycle(spec, CycleSettings(gradient=FAST, table_points=2, energy="electrical"))
    by = {e.measure: e for e in electric.energies}
    assert electric.energy_measure == "electrical" and set(by) == {"thesis", "mechanical", "electrical"}
    meter = by["electrical"]
    assert meter.standby_J == pytest.approx(robot.drives.standby_W * electric.default_cycle_s)
    assert meter.default_J == pytest.approx(electric.default_energy_J + meter.standby_J, rel=1e-9)
    assert electric.optimized_energy_J <= electric.default_energy_J + 1e-9
    assert 0 < meter.saved_pct < electric.saved_pct  # standby dilutes the motion's saving
    bad = tmp_path / "bad.toml"
    bad.write_text("[[step]]\njoints_deg = [0, 0, 0]\nduration_s = 1\n")
    with pytest.raises(joulepath.errors.InvalidInput, match="step 1"):
        read_cycle_toml(bad, robot)


def test_warm_start_solves_within_limits(spec):
    opt = CycleOptimizer(spec, CycleSettings(gradient=FAST, warm_start=True))
    i = opt.units.optimizable[0]
    first = opt.solver.solve(i, opt.solver.t_lo[i] + 0.2)
    assert opt.solver._neighbour(i, opt.solver.t_lo[i]) is first
    second = opt.solver.solve(i, opt.solver.t_lo[i])  # warm-started from the first
    assert second.usable and second.corridor_dev_mm <= 100.0 + 1e-6
    assert opt.solver.n_solves == 2


CHAIN = """MODULE Chain
    CONST jointtarget j0 := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
{decls}
    PROC main()
        WHILE TRUE DO
            MoveAbsJ j0, v1000, fine, tool0;
{moves}
        ENDWHILE
    ENDPROC
ENDMODULE
"""


def _chain(zone: str, n: int = 8, step_deg: float = 3.0, T: float = 0.1) -> str:
    decls, moves = [], []
    for k in range(1, n + 1):
        decls.append(
            f"    CONST jointtarget j{k} := [[{k * step_deg}, 0, 0, 0, 30, 0], "
            "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];"
        )
        z = "fine" if k == n else zone
        moves.append(f"            MoveAbsJ j{k}, v7000 \\T:={T}, {z}, tool0;")
    return CHAIN.format(decls="\n".join(decls), moves="\n".join(moves))


def test_timed_fly_by_chain_keeps_speed(robot):
    """Timed fly-by points in a large zone: the chain takes the sum of its \\T and the joint speed is
    continuous and constant between the start and end ramps."""
    cfg = ControllerConfig()
    n, T = 8, 0.2
    plan = plan_cycle(resolve_module(parse_module(_chain("z200", n, T=T), path="c.mod"), robot), cfg)
    chain = [m for m in plan.moves if m.step.time_s is not None]
    start, end = chain[0].t0, chain[-1].t_end
    assert end - start == pytest.approx(n * T, abs=1e-9)
    t = np.linspace(start, end, 4001)
    traj = evaluate_cycle(plan, t)
    v = np.radians(3.0) / T
    mid = (t > start + 1.5 * T) & (t < end - 1.5 * T)  # beyond the first and last corner paths
    assert np.allclose(traj.qd[mid, 0], v, rtol=1e-9)
    assert np.all(np.abs(traj.qd[:, 1:]) < 1e-12)
    assert np.max(np.abs(np.diff(traj.qd[:, 0]))) < 0.05 * v  # no velocity jumps
    assert traj.q[-1, 0] == pytest.approx(np.radians(3.0 * n), abs=1e-12)


def test_written_program_check_is_reported(tmp_path, robot, reachable):
    """cycle.json carries the written program run by the emulation beside the plan, with a verdict
    consistent with its numbers and tolerances."""
    from joulepath.program._output import check_written, optimized_module

    r, _ = reachable
    check = check_written(r, optimized_module(r))
    tol = check["tolerances"]
    expected = (
        check["emulated_cycle_s"] <= r.target_cycle_s + tol["slower_than_taught_s"]
        and check["emulated_energy_J"] <= r.default_energy_J * (1 - tol["saved_at_least_pct"] / 100)
        and check["tcp_path_deviation_mm"] <= tol["path_mm"]
    )
    assert check["within_tolerances"] == expected
    assert check["planned_cycle_s"] == r.optimized_cycle_s
    assert check["emulated_cycle_s"] > 0 and check["emulated_energy_J"] > 0
    # the module written to the run folder says so in its header when it does not reproduce the plan
    from joulepath.program import write_cycle_run

    files = write_cycle_run(tmp_path, r, pareto=None, write_rapid=True, write_anyway=True)
    text = files["optimized.mod"].read_text()
    data = json.loads(files["cycle.json"].read_text())
    if not data["rapid_follows"].startswith("the plan for via points"):  # the plan (before re-timing)
        assert ("WARNING: run by joulepath's controller emulation" in text) == (not expected)
        assert data["written_program_check"]["within_tolerances"] == expected
    else:  # the plan for via points, tried when the plan's module fails the checks; its own verdict
        assert not expected
        ok = data["written_program_check"]["within_tolerances"]
        assert ("WARNING: run by joulepath's controller emulation" in text) == (not ok)
        assert data["rapid_plan_saved_pct"] is not None
    resolve_module(parse_module(text, path="w.mod"), robot)  # the warning is a comment: it reads back


def test_moves_joined_by_a_zone_fly_through_their_target(spec, robot, reachable):
    """MoveAbsJ jA (z20) then MoveJ pUp: one chain that passes jA exactly (--exact-targets), at
    speed; written with the target as a timed fly-by point; with --stop-at-targets the chain is
    kept as taught; within its zone by default."""
    from joulepath.program import optimized_module

    settings = CycleSettings(gradient=FAST, table_points=3, use_waits=True, cycle_time=REACHABLE, zones=False)
    result = optimize_cycle(spec, settings)
    assert result.limits_ok
    labels = {tuple(spec.steps[j].label for j in c) for c in result.chains.values()}
    assert ("MoveAbsJ jA", "MoveJ pUp") in labels
    first, second = next(c for c in result.chains.values() if spec.steps[c[0]].label == "MoveAbsJ jA")
    a, b = result.paths[first], result.paths[second]
    np.testing.assert_allclose(a.fine.q[-1], spec.steps[first].q, atol=2e-6)  # the taught target
    np.testing.assert_allclose(a.fine.q[-1], b.fine.q[0], atol=1e-12)
    np.testing.assert_allclose(a.fine.qd[-1], b.fine.qd[0], atol=1e-12)
    assert np.abs(a.fine.qd[-1]).max() > 0.05  # not a stop
    # the pieces' energies add up to the chain's, recomputed on the joined path
    joined = [np.vstack([a.fine.q, b.fine.q[1:]]), np.vstack([a.fine.qd, b.fine.qd[1:]])]
    joined.append(np.vstack([a.fine.qdd, b.fine.qdd[1:]]))
    tau = robot.inverse_dynamics(*joined, friction=NOMINAL_FRICTION)
    whole = float(path_energy(tau, joined[1], a.fine.dt).total)
    assert a.energy_J + b.energy_J == pytest.approx(whole, rel=1e-9)
    np.testing.assert_allclose(a.fine.qd[0], 0.0, atol=1e-9)  # the chain starts and ends at rest
    np.testing.assert_allclose(b.fine.qd[-1], 0.0, atol=1e-9)
    text = optimized_module(result)
    lines = text.splitlines()
    at = next(k for k, ln in enumerate(lines) if ln.strip().startswith("PROC jp_opt_main_1("))
    body = lines[at : next(k for k in range(at, len(lines)) if lines[k].strip() == "ENDPROC")]
    moves = [ln.strip() for ln in body if ln.strip().startswith("MoveAbsJ")]
    # passed exactly: the chain's piece ends with the program's own target, in its own zone
    assert moves and moves[-1].startswith("MoveAbsJ jA, v7000") and moves[-1].endswith("z20, tool0;")
    resolve_module(parse_module(text, path="o.mod"), robot)  # reads back
    rest = optimize_cycle(
        spec, CycleSettings(gradient=FAST, table_points=3, use_waits=True, fly_by=False, cycle_time=REACHABLE)
    )
    assert rest.chains == {}
    assert result.shortest_cycle_s <= rest.shortest_cycle_s + 1e-9
    # within its zone: the TCP passes within the zone of jA (reduced as the controller reduces it)
    zoned, opt_z = reachable
    assert opt_z.settings == replace(settings, zones=True)
    assert opt_z.units.zone_mm(first) > 0.0
    assert zoned.zone_miss_mm <= 1e-3
    assert zoned.optimized_energy_J <= result.optimized_energy_J * 1.02  # more freedom, not much worse


def test_via_layout_of_a_gentle_move_is_run_as_planned(robot):
    """A minimum-jerk move (gentle at both ends) written as via points: the emulated controller keeps
    every corner, takes the planned time and stays on the path; the target is always a via point."""
    from joulepath.program._cycle_model import trajectory_energy
    from joulepath.sim import make_plant
    from joulepath.sim._timing import _chain_profiles
    from joulepath.sim._via import _segment, layout
    from joulepath.trajectory import minimum_jerk

    tool = np.eye(4)
    tool[2, 3] = 0.09
    q0 = np.radians([-60.0, 10.0, 10.0, 0.0, 40.0, 0.0])
    q1 = np.radians([40.0, 25.0, -5.0, 20.0, 50.0, 30.0])
    plan = minimum_jerk(q0, q1, 1.2, dt=FINE_DT)
    config = ControllerConfig()
    (idx,) = layout(robot, tool, [plan], spacing=0.05, config=config)
    assert idx[-1] == plan.t.size - 1 and len(idx) >= 10
    points = [(0, i) for i in idx]
    segments = [_segment(robot, tool, [plan], points, n, config, [None]) for n in range(len(points))]
    chained, bad = _chain_profiles(segments, set(range(len(segments) - 1)), config)
    assert bad is None and len(chained) == len(segments)
    # run by the emulation: same duration, the same TCP path (as a set of points, as check_written
    # measures it) within the 5 mm tolerance, the energy within 5 % (the controller's sin² ramps from and
    # to rest run at the acceleration limit, harder than the minimum-jerk move's ends)
    from joulepath.program._resolve import CycleSpec

    steps = tuple(s[1] for s in segments)
    emu_plan = plan_cycle(CycleSpec(steps, q0, "via", None, (), robot), config)
    assert emu_plan.cycle_time - config.fine_dwell == pytest.approx(1.2, abs=1e-9)
    emu = evaluate_cycle(emu_plan, plan.t)
    tcp = lambda q: robot.fk(q).position_m + np.einsum("kij,j->ki", robot.fk(q).rotation, tool[:3, 3])  # noqa: E731
    from scipy.spatial import cKDTree

    a, b = tcp(emu.q), tcp(plan.q)
    assert 1000 * max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max()) < 5.0
    plant = make_plant("lab", robot)
    assert trajectory_energy(robot, plant, emu)[0] == pytest.approx(
        trajectory_energy(robot, plant, plan)[0], rel=0.05
    )


def test_fast_preset_plans_within_limits(spec):
    """The preset for interactive use (FAST_CYCLE): fewer solves, the same checks on its plan."""
    settings = CycleSettings(**FAST_CYCLE, gradient=FAST, use_waits=True, cycle_time=REACHABLE)
    assert settings.table_points == 3 and settings.pass_search == 2 and not settings.retime_segments
    result = optimize_cycle(spec, settings)
    assert result.limits_ok
    assert result.optimized_cycle_s <= result.target_cycle_s + 1e-9
    assert result.optimized_energy_J <= result.default_energy_J + 1e-9


def test_cli_fast_preset_skips_the_path_retiming_and_keeps_the_checks(tmp_path):
    prog = tmp_path / "small.mod"
    prog.write_text(SMALL)
    base = ["cycle", str(prog), "--export", "egm", "--knot-spacing", "0.1"]
    assert main([*base, "--out", str(tmp_path / "fast"), "--fast"]) == 0
    fast = json.loads((tmp_path / "fast" / "cycle.json").read_text())
    assert fast["breakdown"]["segments_retimed_along_their_path_J"] is None  # FAST_CYCLE: no re-timing
    assert fast["limits_ok"] and fast["optimized_cycle_s"] <= fast["target_cycle_s"] + 1e-9
    assert fast["saved_pct"] > 0.0
