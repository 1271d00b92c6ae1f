"""Whole cycles as the controller runs them: units cut at rest, the taught motion as a candidate,
zones as zones, joint runs inside MoveL segments, idle waits, --max-time, the streamed cycle."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.optimize import GradientSettings
from joulepath.program import CycleSettings, optimize_cycle, parse_module, read_cycle_program, resolve_module
from joulepath.program._cycle import CycleOptimizer, _optimize_cycle
from joulepath.program._cycle_model import segments
from joulepath.program._cycle_passes import tune_passes
from joulepath.program._output import cycle_path_csv, write_cycle_run
from joulepath.sim._timing import _tcp, evaluate_cycle

FAST = GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), max_iter=60, coarse_factor=1)
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "pick_and_place.mod"

TARGETS = """    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pA := [[400, -150, 250], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pAUp := [[400, -150, 350], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[350, 200, 250], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pBUp := [[350, 200, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
"""

BLENDED = (
    """MODULE Blended
"""
    + TARGETS
    + """    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveJ pAUp, v1000, z50, tool0;
        MoveL pA, v300, fine, tool0;
        WaitTime 0.3;
        MoveL pAUp, v300, z20, tool0;
        MoveJ pBUp, v1000, z20, tool0;
        MoveL pB, v300, fine, tool0;
        WaitTime 1.0;
        MoveL pBUp, v300, z20, tool0;
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""
)


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


@pytest.fixture(scope="module")
def blended(robot):
    return resolve_module(parse_module(BLENDED, path="blended.mod"), robot)


@pytest.fixture(scope="module")
def solved(blended):
    return _optimize_cycle(blended, CycleSettings(gradient=FAST, table_points=2))


def test_segments_partition_the_default_cycle(blended):
    """Segments follow one another in time, each ends where the robot stands still, and the spans,
    dwells and waits add up to the cycle time."""
    opt = CycleOptimizer(blended, CycleSettings(gradient=FAST))
    segs = segments(opt.plan)
    assert [j for s in segs for j in s.moves] == [m.index for m in opt.plan.moves]
    for a, b in zip(segs, segs[1:], strict=False):
        assert b.t0 >= a.t1 - 1e-12
    motion = opt.default_motion().trajectory
    for s in segs:  # at rest at the end of every segment
        k = int(np.argmin(np.abs(motion.t - s.t1)))
        assert np.abs(motion.qd[k]).max() < 0.05
    assert opt.units.fixed_time + sum(opt.units.span.values()) + opt.units.wait_total == pytest.approx(
        opt.plan.cycle_time
    )


def test_units_inside_moveL_segments_keep_the_taught_ends(blended, solved):
    """The MoveJ between two blended MoveL is a unit over its own motion and the blends at its ends;
    its optimized motion starts and ends in the taught motion's states, so the cycle stays continuous."""
    result, opt = solved
    inner = [i for i in opt.units.within]
    assert inner, "the MoveJ between the MoveL moves is a unit"
    for i in inner:
        base = opt.solver.base(i)
        for (unit, _), s in opt.solver.cache.items():
            if (
                unit != i
                or s.taught
                or int(round(s.duration / 0.025)) != int(round(opt.units.span[i] / 0.025))
            ):
                continue
            if s.fine.t.size != base.t.size:
                continue
            for a, b in ((s.fine.q, base.q), (s.fine.qd, base.qd), (s.fine.qdd, base.qdd)):
                np.testing.assert_allclose(a[[0, -1]], b[[0, -1]], atol=1e-9)
    traj = result.planned
    step = np.abs(np.diff(traj.q, axis=0)).max(axis=0)
    dt = np.diff(traj.t).max()
    robot = blended.robot
    assert np.all(step <= robot.velocity_limit * dt * 1.01)  # no jump anywhere in the cycle


def test_units_inside_moveL_segments_reshape_their_blends_within_the_zones(blended, solved):
    """A run of joint moves inside a MoveL segment is reshaped over the blends at its ends: its window
    starts where the controller starts its first move (not where the blend ends) and ends where it
    ends its last, and the TCP at both ends is within the zone of the target that blend rounds (the
    radius reduced to half of either move); before and after the window the MoveL runs on its line
    as taught. A run that ends at a stop has its last piece end at the target, at rest."""
    result, opt = solved
    robot = blended.robot
    covered = 0
    for i in opt.units.within:
        win = opt.units.segment_of[i]
        seg = next(g for g in opt.units.segments if i in g.moves)
        moving = [j for j in seg.moves if opt.units.by_index[j].profile.duration > 0]
        run = opt.units.chains[i]
        k0, k1 = moving.index(run[0]), moving.index(run[-1])
        ends = []
        if k0 > 0:
            ends.append((win.t0, opt.units.by_index[moving[k0 - 1]], opt.units.by_index[run[0]]))
            covered += win.t0 < opt.units.by_index[moving[k0 - 1]].t_end - 1e-9
        if k1 + 1 < len(moving):
            ends.append((win.t1, opt.units.by_index[run[-1]], opt.units.by_index[moving[k1 + 1]]))
            covered += win.t1 > opt.units.by_index[moving[k1 + 1]].t0 + 1e-9
        for t, into, out in ends:
            step = into.step
            p, _ = _tcp(robot, evaluate_cycle(opt.plan, np.array([t])).q, step.tcp)
            corner, _ = _tcp(robot, into.path.q1[None, :], step.tcp)
            radius = min(step.zone_mm, 0.5 * into.path.length_mm, 0.5 * out.path.length_mm)
            assert 1000 * np.linalg.norm(p - corner) <= radius + 1e-6
        last = opt.units.by_index[run[-1]]
        if last.stops and run[-1] in (result.unretimed or result).paths:
            piece = (result.unretimed or result).paths[run[-1]].fine
            np.testing.assert_allclose(piece.q[-1], last.path.q1, atol=1e-9)
            assert np.abs(piece.qd[-1]).max() < 1e-9
    assert covered >= 2  # the blends into and out of the MoveJ between the MoveL moves


def test_same_cycle_time_is_never_refused_nor_slower(blended, solved):
    result, _ = solved
    assert result.target_cycle_s == result.default_cycle_s
    assert result.optimized_cycle_s <= result.default_cycle_s + 1e-9
    assert result.optimized_energy_J <= result.default_energy_J * (1 + 1e-9)
    assert result.limits_ok


def test_reported_energies_are_the_planned_motion_s(blended, solved):
    """One definition: the cycle's energy is that of its planned motion, and the moves' add up to it."""
    result, opt = solved
    assert sum(m.optimized_energy_J for m in result.moves) == pytest.approx(result.optimized_energy_J)
    assert sum(m.default_energy_J for m in result.moves) == pytest.approx(result.default_energy_J)
    assert result.planned.t[-1] == pytest.approx(result.optimized_cycle_s)
    # ... and the whole planned motion's energy, recomputed from its samples, is the total
    tr = result.planned
    robot = blended.robot
    tau = robot.inverse_dynamics(tr.q, tr.qd, tr.qdd, friction=NOMINAL_FRICTION)
    step = np.append(np.diff(tr.t), 0.0)[:, None]
    assert float((np.abs(tau * tr.qd) * step).sum()) == pytest.approx(result.optimized_energy_J, rel=1e-9)
    # the allocation's sum of entries agrees with the motion's energy
    alloc = opt.evaluate(
        opt.at_taught_durations(opt.table(opt.units.budget(result.target_cycle_s, False))), 0.0
    )
    assert alloc.energy_J > 0
    default = opt.evaluate({i: opt.solver.taught(i) for i in opt.units.optimizable}, opt.units.wait_total)
    assert default.energy_J == pytest.approx(result.default_energy_J, rel=1e-9)


def test_max_time_returns_the_taught_cycle_when_nothing_was_solved(blended):
    """A wall-time bound spent before the first solve: the taught cycle, 0 % saved, stated."""
    result = optimize_cycle(blended, CycleSettings(gradient=FAST, max_time_s=1e-9))
    assert result.timed_out
    assert result.n_solves == 0
    assert result.saved_pct == pytest.approx(0.0, abs=1e-9)
    assert result.optimized_cycle_s == pytest.approx(result.default_cycle_s)
    assert len(result.taught_units) == len(result.optimizable)
    assert not result.paths


def test_waits_are_process_time_unless_declared_idle(blended):
    """--use-waits spends only the waits declared idle; the others keep their length."""
    settings = CycleSettings(gradient=FAST, table_points=2, use_waits=True)
    plain = optimize_cycle(blended, settings)
    assert [w[1] for w in plain.waits] == [w[2] for w in plain.waits]  # nothing is idle
    steps = tuple(
        replace(s, idle=True) if s.kind == "wait" and s.seconds == 1.0 else s for s in blended.steps
    )
    idle_spec = replace(blended, steps=steps)
    idle = optimize_cycle(idle_spec, settings)
    kept = {line: after for line, _, after in idle.waits}
    assert sorted(kept.values()) == [0.0, 0.3]
    assert idle.optimized_cycle_s <= idle.target_cycle_s + 1e-9
    assert idle.optimized_energy_J <= plain.optimized_energy_J * (1 + 1e-4)  # the same moves, resampled


def test_zones_let_a_chain_pass_near_its_targets(robot):
    """Three MoveAbsJ in zones: with zones the chain passes every target within its zone (TCP), at
    no more energy than through them exactly (the same start, more freedom)."""
    text = """MODULE Z
    CONST jointtarget j1 := [[-40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j2 := [[0, 30, -10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j3 := [[40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveAbsJ j1, v1000, fine, tool0;
        MoveAbsJ j2, v1000, z50, tool0;
        MoveAbsJ j3, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""
    spec = resolve_module(parse_module(text, path="z.mod"), robot)
    base = CycleSettings(gradient=FAST, table_points=2, cycle_time=3.0)
    exact = optimize_cycle(spec, replace(base, zones=False))
    zoned, opt = _optimize_cycle(spec, base)
    chain = next(i for i, c in opt.units.chains.items() if len(c) == 2)
    j = opt.units.chains[chain][0]
    assert 0 < opt.units.zone_mm(j) <= 50.0
    assert zoned.zone_miss_mm <= 1e-3
    assert zoned.optimized_energy_J <= exact.optimized_energy_J * 1.01
    # the radius is a joint box that keeps the TCP within the zone to first order
    (r,) = opt.units.zone_radius(chain)
    step = spec.steps[j]
    rng = np.random.default_rng(0)
    corners = step.q + r[0] * rng.choice([-1.0, 1.0], size=(64, step.q.size))
    p, _ = _tcp(robot, corners, step.tcp)
    p0, _ = _tcp(robot, step.q[None, :], step.tcp)
    assert 1000 * np.linalg.norm(p - p0, axis=1).max() <= opt.units.zone_mm(j)


def test_cycle_folder_streams_the_plan(blended, solved, tmp_path):
    """cycle_path.csv is the planned cycle (t, q, qd, qdd); with egm the folder holds egm.mod."""
    from joulepath.egm import read_plan

    result, _ = solved
    files = write_cycle_run(tmp_path, result, pareto=None, write_rapid=True, egm="always")
    assert {"cycle_path.csv", "egm.mod", "EGM_SETUP.md", "cycle.json"} <= set(files)
    plan = read_plan(files["cycle_path.csv"])
    assert plan.duration == pytest.approx(result.optimized_cycle_s, abs=1e-6)
    np.testing.assert_allclose(plan.q, result.planned.q, atol=1e-8)
    text = files["egm.mod"].read_text()
    assert "EGMRunJoint" in text and "DefaultMove" not in text
    data = json.loads(files["cycle.json"].read_text())
    assert data["robot"] == "IRB 120"
    assert cycle_path_csv(result).splitlines()[0].startswith("t,q1,")
    # without egm and with a module written, no stale egm.mod stays
    files2 = write_cycle_run(tmp_path, result, pareto=None, write_rapid=True, egm="never")
    assert "egm.mod" not in files2 and not (tmp_path / "egm.mod").exists()


def test_streamed_cycle_executes_its_planned_saving(blended, solved, tmp_path, background):
    """`joulepath stream` plays the cycle folder to the emulated controller on 127.0.0.1, cycle
    after cycle: the executed saving is the planned one, the duration the planned cycle time."""
    pytest.importorskip("abb_robot_client._egm_protobuf.egm_pb2")
    from joulepath.egm import EmulatorConfig, ServeConfig, StreamSettings, run_emulator, stream_run

    result, _ = solved
    write_cycle_run(tmp_path, result, pareto=None, write_rapid=False, egm="always")
    config = ServeConfig(host="127.0.0.1", port=0, timeout_s=3.0, settings=StreamSettings(repeats=2))
    server = background(lambda listening: stream_run(tmp_path, config, on_listening=listening))
    address = server.wait_listening()
    q0 = tuple(np.degrees(result.planned.q[0]))
    run_emulator(address, EmulatorConfig(q_start_deg=q0, wall_period_s=0.0005))
    server.join()
    s = json.loads((tmp_path / "stream.json").read_text())
    assert s["outcome"] == "done" and s["repetitions_executed"] == 2
    for rep in s["repetitions"]:
        assert abs(rep["executed_duration_s"] - result.optimized_cycle_s) <= 0.01
    assert s["saved_planned_pct"] == pytest.approx(result.saved_pct, abs=1e-6)
    assert abs(s["saved_executed_pct"] - result.saved_pct) <= 1.0


def test_bundled_example_at_its_own_cycle_time(robot):
    """The bundled example is optimized at its own cycle time, never slower, and saves energy."""
    spec, _ = read_cycle_program(EXAMPLE, robot)
    result, opt = _optimize_cycle(spec, CycleSettings(gradient=FAST, table_points=2))
    assert result.optimized_cycle_s <= result.default_cycle_s + 1e-9
    assert result.saved_pct > 0.0
    assert opt.units.within  # its MoveJ transfers blended into MoveL approaches are units


LINES = """MODULE Lin
    CONST robtarget pA := [[400, -150, 250], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[400, 150, 250], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveJ pA, v1000, fine, tool0;
        MoveL pB, v1000, fine, tool0;
        WaitTime 0.5;
        MoveL pA, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""


def test_moveL_from_rest_to_rest_is_re_timed_on_its_line(robot):
    """A MoveL between stops is re-timed along its straight line: the TCP stays on the line, the
    speeddata's TCP speed holds, the cycle is no longer and the energy no higher than taught."""
    pytest.importorskip("toppra")
    spec = resolve_module(parse_module(LINES, path="lin.mod"), robot)
    result, opt = _optimize_cycle(spec, CycleSettings(gradient=FAST, table_points=2))
    assert opt.units.linear and set(opt.units.linear) <= set(result.paths)
    assert result.optimized_cycle_s <= result.default_cycle_s + 1e-9
    assert result.optimized_energy_J < result.default_energy_J
    for i in opt.units.linear:
        step, s = spec.steps[i], result.paths[i]
        p, _ = _tcp(robot, s.fine.q, step.tcp)
        a, b = p[0], p[-1]
        u = (b - a) / np.linalg.norm(b - a)
        off = (p - a) - np.outer((p - a) @ u, u)
        assert 1000 * np.linalg.norm(off, axis=1).max() <= 0.1
        v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(s.fine.t)
        assert v.max() <= step.speed.v_tcp / 1000 * 1.01


def test_a_chain_through_a_zone_reaches_most_of_the_cycle_optimum_s_saving(robot):
    """A unit from rest to rest through one fly-by target (two legs, a zone): the plan (the search
    for when the chain passes its target, then the gradient search) reaches at least 90 % of the
    saving of the cycle optimum (IPOPT, one transcription with a free passing time) over the taught
    motion, at the same duration, on the same robot, within the same zone and limits; and the search
    over the passing time never ends above the passing time it starts from."""
    pytest.importorskip("casadi")
    from joulepath.optimize import CycleLeg, cycle_optimum

    text = """MODULE Z
    CONST jointtarget j1 := [[-40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j2 := [[-15, 30, -10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j3 := [[40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveAbsJ j1, v1000, fine, tool0;
        MoveAbsJ j2, v1000, z50, tool0;
        MoveAbsJ j3, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""
    spec = resolve_module(parse_module(text, path="z.mod"), robot)
    opt = CycleOptimizer(spec, CycleSettings(gradient=FAST))
    i = next(k for k, c in opt.units.chains.items() if len(c) == 2)
    units = int(np.floor(opt.units.span[i] / 0.025 + 1e-9))
    T = units * 0.025
    m = opt.units.by_index[i]
    start = opt.solver.solve_once(
        m, T, units, opt.settings.corridor_mm
    )  # in proportion to each leg's shortest
    tune_passes(opt.solver, i, T)
    plan = opt.solver.solve(i, T)
    assert start.usable and plan.usable
    assert plan.energy_J <= start.energy_J + 1e-9
    assert opt.solver.zone_miss_mm(i, plan) <= 1e-3
    best = cycle_optimum(
        m.step.robot,
        [
            CycleLeg(
                m.path.q0,
                opt.units.by_index[opt.units.chains[i][-1]].path.q1,
                via=(m.path.q1,),
                via_radius=opt.units.zone_radius(i),
            )
        ],
        T,
        acceleration_limit=opt.units.amax(m.step.robot),
        jerk_limit=opt.units.jmax(m.step.robot),
        intervals=8,
        continuation=(0.03,),  # one smoothing stage: within 0.2 % of three here, ten times faster
    )
    assert best.feasible, best.status
    taught = opt.solver.taught(i).energy_J
    assert best.energy_J < taught
    assert (taught - plan.energy_J) >= 0.9 * (taught - best.energy_J)


KINDS = (
    """MODULE Kinds
    CONST jointtarget jSide := [[-40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
"""
    + TARGETS
    + """    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveAbsJ jSide, v1000, z50, tool0;
        MoveJ pBUp, v1000, fine, tool0;
        MoveL pB, v300, fine, tool0;
        WaitTime 0.2;
        MoveL pBUp, v300, z20, tool0;
        MoveJ pAUp, v1000, z20, tool0;
        MoveL pA, v300, fine, tool0;
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""
)


def test_for_every_move_kind_the_optimizer_moves_as_fast_as_the_controller(robot):
    """One model of the motion: for every kind of unit (a chain of joint moves through a zone from
    rest to rest, a single joint move from rest to rest, a MoveL from rest to rest, a MoveJ blended
    between MoveL), the optimizer's own motion, not the taught candidate, is within every limit at
    the controller's duration or shorter, so the taught cycle time never needs the taught motion."""
    pytest.importorskip("toppra")
    spec = resolve_module(parse_module(KINDS, path="kinds.mod"), robot)
    opt = CycleOptimizer(spec, CycleSettings(gradient=FAST))
    kinds = {"chain": 0, "single": 0, "linear": 0, "within": 0}
    for i, members in opt.units.chains.items():
        span = opt.units.span[i]
        if i in opt.units.linear:
            kinds["linear"] += 1
            assert (
                opt.solver.t_lo[i] <= span + 0.025
            )  # TOPP-RA's shortest, whole samples, within the speeddata
            assert opt.solver.solve(i, float(np.ceil(span / 0.025 - 1e-9) * 0.025)).usable
        elif i in opt.units.within:
            kinds["within"] += 1
            assert opt.solver.solve(i, round(span / 0.025) * 0.025).usable  # its window is whole samples
        else:
            kinds["chain" if len(members) > 1 else "single"] += 1
            own = opt.solver.solve_on_taught(i)  # the optimizer's shape at the taught duration
            assert own is not None and own.usable, own.limit_excess if own else "under 0.15 s"
            assert own.duration == pytest.approx(span)
    assert all(kinds.values()), kinds
    assert opt.solver.shortest_cycle <= opt.plan.cycle_time + 1e-9


def test_ordered_closest_agrees_with_every_ordered_choice():
    """When a chain passes its targets: the least summed distance over indices in order, at least
    ``gap`` apart, as found by trying every such choice."""
    import itertools

    from joulepath.program._cycle_geometry import ordered_closest

    rng = np.random.default_rng(3)
    for _ in range(150):
        m, n = int(rng.integers(1, 4)), int(rng.integers(8, 14))
        d = rng.random((m, n))
        ks = ordered_closest(d, lo=2, hi=n - 3, gap=2)
        choices = [
            c
            for c in itertools.combinations(range(2, n - 2), m)
            if all(b - a >= 2 for a, b in zip(c, c[1:], strict=False))
        ]
        if not choices:
            continue
        best = min(sum(d[j, c[j]] for j in range(m)) for c in choices)
        assert sum(d[j, ks[j]] for j in range(m)) == pytest.approx(best, abs=1e-12)
        assert all(b - a >= 2 for a, b in zip(ks, ks[1:], strict=False))


def test_a_chain_through_the_same_target_twice_passes_each_in_turn(robot):
    """A fly-by chain back and forth between two targets (a legal program that raised a traceback):
    the taught motion's passes are found in order, each near its own target."""
    text = (
        "MODULE BackAndForth\n"
        + TARGETS
        + "    PROC main()\n"
        + "".join(f"        MoveJ {p}, v1000, z10, tool0;\n" for p in ("pAUp", "pBUp") * 3)
        + "    ENDPROC\nENDMODULE\n"
    )
    spec = resolve_module(parse_module(text, path="back_and_forth.mod"), robot)
    opt = CycleOptimizer(spec, CycleSettings(gradient=FAST))
    chains = [i for i, c in opt.units.chains.items() if len(c) > 2]
    assert chains
    for i in chains:
        n = int(np.floor(opt.units.segment_of[i].span / 0.025 + 1e-9))
        base = opt.solver.base(i, n)
        passes = opt.solver.taught_passes(i, base)
        times = [t for t, _ in passes]
        assert len(passes) == len(opt.units.chains[i]) - 1
        assert all(b > a for a, b in zip(times, times[1:], strict=False))
        for t, q in passes:
            k = int(np.argmin(np.abs(base.t - t)))
            at, _ = _tcp(robot, base.q[k][None, :], spec.steps[0].tcp)
            want, _ = _tcp(robot, q[None, :], spec.steps[0].tcp)
            assert 1000 * np.linalg.norm(at - want) < 15.0  # within its z10 zone (and the grid)


def test_segments_with_moveL_are_re_timed_along_their_own_path(blended, solved):
    """The last stage re-times each segment with a MoveL along its own joint path: the TCP runs the
    same path as the plan before it (every sample on it), in the same cycle time, with less energy
    (the breakdown's last part), and where it is on a MoveL's line no faster than its speeddata."""
    from joulepath.dynamics import NOMINAL_FRICTION
    from joulepath.optimize import check_limits, tcp_velocity
    from joulepath.sim import acceleration_limit

    result, opt = solved
    before = result.unretimed
    assert before is not None and before.unretimed is None and result.path_retimed
    assert not before.path_retimed and before.breakdown.path_retimed_J is None
    assert result.optimized_cycle_s == pytest.approx(before.optimized_cycle_s, abs=1e-9)
    assert result.optimized_energy_J < before.optimized_energy_J
    pct = 100 * (before.optimized_energy_J - result.optimized_energy_J) / result.default_energy_J
    # (the breakdown's step before is the allocation's energy: within 1e-3 J of the motion's)
    assert result.breakdown.by_path_retiming_pct == pytest.approx(pct, abs=0.01)
    robot = blended.robot
    tcp = blended.steps[result.path_retimed[0]].tcp
    new, _ = _tcp(robot, result.planned.q, tcp)
    old, _ = _tcp(robot, before.planned.q, tcp)
    a, d = old[:-1], np.diff(old, axis=0)
    far = 0.0
    for p in new:  # distance to the old TCP path, a polyline of its 2.5 ms samples
        u = np.clip(((p - a) * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), 1e-30), 0.0, 1.0)
        far = max(far, float(np.linalg.norm(a + u[:, None] * d - p, axis=1).min()))
    assert far < 5e-5  # 0.05 mm: the chords between samples
    new_v = tcp_velocity(robot, result.planned.q, result.planned.qd, tcp)
    old_v = tcp_velocity(robot, before.planned.q, before.planned.qd, tcp)
    speed, old_speed = np.linalg.norm(new_v, axis=1), np.linalg.norm(old_v, axis=1)
    lines = [j for j in result.path_retimed if blended.steps[j].linear]
    in_zone = np.zeros(len(new), dtype=bool)  # within a fly-by target's zone (where the blends are)
    for st in blended.steps:
        if st.kind == "move" and st.zone_mm is not None and st.q is not None:
            target = _tcp(robot, st.q[None, :], tcp)[0][0]
            in_zone |= np.linalg.norm(new - target, axis=1) < st.zone_mm / 1000 + 1e-3
    assert lines
    for j in lines:
        m = opt.units.by_index[j]
        p0, p1 = (_tcp(robot, q[None, :], tcp)[0][0] for q in (m.path.q0, m.path.q1))
        u = (p1 - p0) / np.linalg.norm(p1 - p0)
        w = (new - p0) @ u / np.linalg.norm(p1 - p0)
        off = np.linalg.norm((new - p0) - np.outer((new - p0) @ u, u), axis=1)
        on = np.flatnonzero((off < 1e-7) & (w > 0.0) & (w < 1.0) & ~in_zone)  # on its line, not in a blend
        assert on.size > 20
        for k in on:  # no faster than its speeddata, or than the plan before already went there
            same_way = (old_v @ new_v[k]) > 0  # (a line run both ways: the pass in the same direction)
            dist = np.where(same_way, np.linalg.norm(old - new[k], axis=1), np.inf)
            near = int(np.argmin(dist))
            allowed = max(m.step.speed.v_tcp / 1000, old_speed[max(near - 1, 0) : near + 2].max())
            assert speed[k] <= allowed * (1 + 1e-4)
    # every limit holds on the streamed cycle (its 2.5 ms steps, shorter at the pieces' joins)
    for piece in result.paths.values():
        report = check_limits(
            robot,
            piece.fine,
            friction=NOMINAL_FRICTION,
            acceleration_limit=acceleration_limit(robot, CycleSettings().accel_time),
        )
        assert report.ok, [x.describe() for x in report.worst]
    assert result.limits_ok


def test_rapid_follows_the_plan_before_its_paths_were_re_timed(blended, solved, tmp_path):
    """RAPID's own MoveL runs at its speeddata: the module is written from the plan before the
    segments were re-timed along their paths, and says so; the stream plays the re-timed plan."""
    result, _ = solved
    files = write_cycle_run(tmp_path, result, pareto=None, write_rapid=True, egm="always")
    data = json.loads(files["cycle.json"].read_text())
    assert data["breakdown"]["saved_by_path_retiming_pct"] > 0
    check = data["written_program_check"]
    assert check is not None  # the module was written and run by the controller emulation
    assert check["planned_energy_J"] == pytest.approx(result.unretimed.optimized_energy_J)
    if "optimized.mod" in files:
        assert data["rapid_follows"].startswith("the plan before its MoveL segments were re-timed")
    np.testing.assert_allclose(
        np.loadtxt(files["cycle_path.csv"], delimiter=",", skiprows=1)[:, 1:7], result.planned.q, atol=1e-8
    )


TRANSFER = (
    """MODULE Transfer
"""
    + TARGETS
    + """    PROC main()
        MoveJ pA, v1000, fine, tool0;
        MoveL pAUp, v300, z20, tool0;
        MoveAbsJ jHome, v1000, z50, tool0;
        MoveJ pBUp, v1000, z20, tool0;
        MoveL pB, v300, fine, tool0;
    ENDPROC
ENDMODULE
"""
)


def test_pass_times_of_a_run_between_moveL_are_searched_never_to_its_loss(robot):
    """A run of two joint moves between MoveL is one unit with an inner fly-by target. Its pass time
    is searched by probes on wider knots; the result kept for the unit (the best probe, or the unit's
    own solve where no probe wins) is verified, as good as the unit's own solve at the pass time it
    started from or better, and it passes the target within its zone. Started 0.1 s off the taught
    pass time, the search finds a better one."""
    spec = resolve_module(parse_module(TRANSFER, path="transfer.mod"), robot)
    for shift in (0.0, 0.1):
        opt = CycleOptimizer(spec, CycleSettings(gradient=FAST, pass_search=4))
        (i,) = [u for u in opt.units.within if len(opt.units.chains[u]) == 2]
        taught = opt.solver.taught_passes(i)
        opt.solver.taught_passes = lambda *_, w=taught, d=shift: tuple((t + d, q) for t, q in w)  # type: ignore[method-assign]
        units = int(round(opt.units.span[i] / 0.025))
        T = units * 0.025
        m = opt.units.by_index[i]
        untuned = opt.solver.solve_once(m, T, units, opt.settings.corridor_mm)
        tune_passes(opt.solver, i, T)
        tuned = opt.solver.cache[(i, units)]
        assert tuned.usable
        assert tuned.energy_J <= untuned.energy_J * (1 + 1e-12)
        assert opt.solver.zone_miss_mm(i, tuned) <= 1e-6
        if shift:
            assert i in opt.solver.shares and tuned.energy_J < untuned.energy_J
        if i in opt.solver.shares:  # a better pass time was found: the kept result is solved at it
            (t_pass,) = [t for t, _ in opt.solver.waypoints(i, T)]
            assert tuned.passes == (pytest.approx(t_pass),)


def test_hermite_path_is_the_quintic_hermite_interpolation():
    """The re-timing's joint path of a segment (``_hermite_path``, its Bernstein coefficients built
    for every interval at once) is :func:`joulepath.trajectory.quintic_hermite`'s interpolation (one
    interval at a time), in ``s`` on [0, 1]: the same positions and derivatives to the bit (the
    re-timing's search is sensitive to the last bit), and the samples' at the samples."""
    from joulepath.program._cycle_motion import hermite_path
    from joulepath.trajectory import quintic_hermite

    rng = np.random.default_rng(3)
    t = 0.4 + np.cumsum(0.002 + 0.01 * rng.random(300))
    q, qd, qdd = rng.normal(size=(3, t.size, 6))
    at = hermite_path(t, q, qd, qdd)
    span = t[-1] - t[0]
    ref = quintic_hermite((t - t[0]) / span, q, qd * span, qdd * span * span)
    s = np.linspace(0.0, 1.0, 4001)
    for k, got in enumerate(at(s)):
        assert np.array_equal(got, ref.derivative(k)(s) if k else ref(s))
    q_at, d_at, dd_at = at((t - t[0]) / span)
    assert np.allclose(q_at, q, atol=1e-12) and np.allclose(d_at, qd * span, atol=1e-10)
    assert np.allclose(dd_at, qdd * span * span, atol=1e-8)
