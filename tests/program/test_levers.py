"""The controller's own levers: AccSet/VelSet in the controller model, the lever search, the writer.

Invariants and agreement only: the AccSet limit is what the emulated moves reach, 100 % reproduces the
timing of the code before AccSet existed (a copy of it, below), the written program read back and run
again gives the figures the search reports, and only the move statements and AccSet lines change.
"""

import difflib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.errors import InvalidInput
from joulepath.program import parse_module, read_cycle_program, resolve_module
from joulepath.program._cycle_model import trajectory_energy
from joulepath.program._levers import _slots, levers_module, write_levers
from joulepath.sim import ControllerConfig, make_plant, tcp_pose
from joulepath.sim import _timing as timing
from joulepath.sim._limits import jerk_limit
from joulepath.sim._profile import Profile, plan_profile
from joulepath.sim._timing import FINE_DT, PathCache, evaluate_cycle, plan_cycle, standalone

EXAMPLES = Path(__file__).parents[2] / "examples"
EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
DECL = (
    f"    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];\n"
    f"    CONST robtarget pB := [[300, 200, 400], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];\n"
    f"    CONST robtarget pC := [[300, -200, 350], [0, 0, 1, 0], [-1, 0, -1, 0], {EXT}];\n"
    f"    CONST jointtarget jH := [[0, 0, 0, 0, 30, 0], {EXT}];\n"
)


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb120")


def _module(body: str) -> str:
    loop = f"        WHILE TRUE DO\n{body}        ENDWHILE\n"
    return f"MODULE T\n{DECL}    PROC main()\n{loop}    ENDPROC\nENDMODULE\n"


def _spec(text: str, robot):
    return resolve_module(parse_module(text, path="t.mod"), robot)


def _moves(spec):
    return [s for s in spec.steps if s.kind == "move"]


def _with_all(spec, **fields):
    return replace(spec, steps=tuple(replace(s, **fields) if s.kind == "move" else s for s in spec.steps))


JOINT_CYCLE = _module(
    "            MoveAbsJ jH, v1000, fine, tool0;\n"
    "            MoveJ pA, v1000, z20, tool0;\n"
    "            MoveJ pB, v2000, fine, tool0;\n"
    "            MoveJ pC, v1500, z10, tool0;\n"
)


# ---------------------------------------------------------------- AccSet / VelSet in the controller model
@pytest.mark.parametrize("acc", [70.0, 50.0, 25.0])
def test_lower_acc_never_shortens_a_move_and_lowers_its_peak_acceleration(robot, acc):
    spec = _spec(JOINT_CYCLE, robot)
    config = ControllerConfig()
    base = plan_cycle(spec, config)
    low = plan_cycle(_with_all(spec, acc_pct=acc), config)
    amax = np.asarray(robot.velocity_limit) / config.accel_time
    strictly_lower = 0
    for m0, m1 in zip(base.moves, low.moves, strict=True):
        assert m1.profile.duration >= m0.profile.duration - 1e-12
        peak0 = np.abs(standalone(m0).qdd).max(axis=0)
        peak1 = np.abs(standalone(m1).qdd).max(axis=0)
        assert np.all(peak1 <= peak0 * (1 + 1e-9) + 1e-12)
        # the controller keeps the lowered limit: every joint within acc % of its acceleration limit
        assert np.all(peak1 <= amax * acc / 100.0 * (1 + 1e-6))
        strictly_lower += bool(peak1.max() < peak0.max() * (1 - 1e-6))
    assert strictly_lower >= 2  # the moves at the acceleration limit accelerate less
    assert low.cycle_time > base.cycle_time


def test_lower_ramp_lowers_the_jerk_and_never_shortens(robot):
    spec = _spec(JOINT_CYCLE, robot)
    config = ControllerConfig()
    jmax = jerk_limit(robot, config.accel_time, config.jerk_time)
    base = plan_cycle(spec, config)
    low = plan_cycle(_with_all(spec, ramp_pct=25.0), config)
    for m0, m1 in zip(base.moves, low.moves, strict=True):
        assert m1.profile.duration >= m0.profile.duration - 1e-12
        traj = standalone(m1, dt=FINE_DT / 8)
        jerk = np.abs(np.diff(traj.qdd, axis=0) / np.diff(traj.t)[:, None]).max(axis=0)
        assert np.all(jerk <= jmax * 0.25 * 1.01)


def test_acc_and_ramp_below_abb_minimum_are_clamped(robot):
    spec = _spec(JOINT_CYCLE, robot)
    config = ControllerConfig()
    at_min = plan_cycle(_with_all(spec, acc_pct=20.0, ramp_pct=10.0), config)
    below = plan_cycle(_with_all(spec, acc_pct=1.0, ramp_pct=1.0), config)
    assert below.cycle_time == at_min.cycle_time


def test_velset_override_doubles_t_and_max_caps_the_speed(robot):
    text = _module("            MoveJ pA, v1000, fine, tool0;\n            MoveL pB, v1000, fine, tool0;\n")
    spec = _spec(text, robot)
    config = ControllerConfig()
    moves = _moves(spec)
    timed = replace(spec, steps=(replace(moves[0], time_s=3.0), replace(moves[1], time_s=2.0)))
    half = plan_cycle(_with_all(timed, vel_override_pct=50.0), config)
    assert [m.profile.duration for m in half.moves] == pytest.approx([6.0, 4.0], abs=1e-12)
    # VelSet 50 halves the speeds: the MoveL runs as at v500
    slower = plan_cycle(_with_all(spec, vel_override_pct=50.0), config)
    v500 = plan_cycle(
        replace(spec, steps=tuple(replace(s, speed=replace(s.speed, v_tcp=500.0)) for s in moves)), config
    )
    assert slower.moves[1].profile == v500.moves[1].profile
    # VelSet 100, 100 on a v1000 MoveL runs it as a v100 MoveL
    capped = plan_cycle(_with_all(spec, vel_max_mm_s=100.0), config)
    slow = plan_cycle(
        replace(spec, steps=tuple(replace(s, speed=replace(s.speed, v_tcp=100.0)) for s in moves)), config
    )
    assert capped.moves[1].profile == slow.moves[1].profile


def _fastest_profile_before_levers(step, path, config):
    """``joulepath.sim._timing.fastest_profile`` as it was before AccSet and VelSet (commit 540da8e)."""
    robot = step.robot
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    amax = vmax / config.accel_time
    jerk = jerk_limit(robot, config.accel_time, config.jerk_time)
    jmax = np.full(vmax.shape, np.inf) if jerk is None else jerk
    _, dqds, _ = path.at(np.linspace(0.0, 1.0, 33))
    peak = np.abs(dqds).max(axis=0)
    moving = peak > 1e-9
    bounds = [float(np.min(vmax[moving] / peak[moving]))]
    if path.length_mm > 1e-6:
        bounds.append(step.speed.v_tcp / path.length_mm)
    if path.angle_deg > 1e-6:
        bounds.append(step.speed.v_ori / path.angle_deg)
    profile = plan_profile(
        min(bounds), float(np.min(amax[moving] / peak[moving])), float(np.min(jmax[moving] / peak[moving]))
    )
    if step.time_s is not None and step.time_s > profile.duration:
        k = step.time_s / profile.duration
        profile = Profile(ta=profile.ta * k, tc=profile.tc * k, v=profile.v / k)
    return profile


@pytest.mark.parametrize("name", sorted(p.stem for p in EXAMPLES.glob("*.mod")))
def test_full_acc_reproduces_the_timing_before_levers(robot, name, monkeypatch):
    spec, _ = read_cycle_program(EXAMPLES / f"{name}.mod", robot)
    assert all(
        (s.acc_pct, s.ramp_pct, s.vel_override_pct, s.vel_max_mm_s) == (100, 100, 100, None)
        for s in _moves(spec)
    )
    config = ControllerConfig()
    paths = PathCache()  # the moves' paths (code untouched by the levers) solved once for two plans
    now = plan_cycle(spec, config)
    explicit = plan_cycle(
        _with_all(spec, acc_pct=100.0, ramp_pct=100.0, vel_override_pct=100.0), config, paths=paths
    )
    monkeypatch.setattr(timing, "fastest_profile", _fastest_profile_before_levers)
    before = plan_cycle(spec, config)  # no cache: its profiles are the function's before the levers
    for plan in (now, explicit):
        assert plan.cycle_time == before.cycle_time
        assert [(m.t0, m.profile) for m in plan.moves] == [(m.t0, m.profile) for m in before.moves]


def _timed_chain_module() -> str:
    """Timed fly-by chains (\\T and zones on joint moves), a stop, a MoveL and a wait."""
    return _module(
        "            MoveJ pA, v1000\\T:=0.9, z50, tool0;\n"
        "            MoveJ pB, v1000\\T:=0.8, z50, tool0;\n"
        "            MoveAbsJ jH, v1000\\T:=0.7, z40, tool0;\n"
        "            MoveJ pC, v500\\T:=0.9, fine, tool0;\n"
        "            MoveL pA, v800, z10, tool0;\n"
        "            WaitTime 0.2;\n"
        "            MoveJ pB, v1000\\T:=1.0, z50, tool0;\n"
        "            MoveJ pC, v1000\\T:=0.3, z50, tool0;\n"
        "            MoveJ pA, v1000, fine, tool0;\n"
    )


def _same_plans(a, b) -> None:
    assert a.cycle_time == b.cycle_time
    assert [(m.index, m.t0, m.profile) for m in a.moves] == [(m.index, m.t0, m.profile) for m in b.moves]


def test_the_plan_cache_plans_every_setting_as_without_it(robot):
    """A search's cache (paths, profiles, timed chains) gives each plan exactly as planned afresh,
    whatever the settings planned before with the same cache."""
    spec = _spec(_timed_chain_module(), robot)
    assert any(isinstance(m.profile, timing.ChainProfile) for m in plan_cycle(spec, ControllerConfig()).moves)
    config = ControllerConfig()
    paths = PathCache()
    variants = [
        spec,
        _with_all(spec, acc_pct=60.0),
        spec,
        _with_all(spec, ramp_pct=40.0, vel_override_pct=80.0),
        _with_all(spec, acc_pct=60.0),
    ]
    for variant in variants:
        _same_plans(plan_cycle(variant, config, paths=paths), plan_cycle(variant, config))
    assert paths.chains  # the chains were kept, and asked again


def test_a_cycle_is_evaluated_the_same_at_times_in_any_order(robot):
    plan = plan_cycle(_spec(_timed_chain_module(), robot), ControllerConfig())
    t = np.linspace(0.0, plan.cycle_time, 997)
    order = np.random.default_rng(3).permutation(t.size)
    ordered, shuffled = evaluate_cycle(plan, t), evaluate_cycle(plan, t[order])
    for field in ("q", "qd", "qdd"):
        np.testing.assert_array_equal(getattr(shuffled, field), getattr(ordered, field)[order])


# ---------------------------------------------------------------- AccSet / VelSet in the reader
def test_accset_and_velset_are_read_and_carried_over_the_loop(robot):
    text = (
        f"MODULE T\n{DECL}    PROC main()\n        VelSet 50, 800;\n        WHILE TRUE DO\n"
        "            MoveJ pA, v1000, z20, tool0;\n            AccSet 40, 60;\n"
        "            MoveJ pB, v1000, fine, tool0;\n            AccSet 70, 100;\n"
        "        ENDWHILE\n    ENDPROC\nENDMODULE\n"
    )
    a, b = _moves(_spec(text, robot))
    # the loop's last AccSet is in force when the next run starts; VelSet from before the loop throughout
    assert (a.acc_pct, a.ramp_pct, b.acc_pct, b.ramp_pct) == (70.0, 100.0, 40.0, 60.0)
    assert (a.vel_override_pct, a.vel_max_mm_s) == (b.vel_override_pct, b.vel_max_mm_s) == (50.0, 800.0)


# ---------------------------------------------------------------- the search and the writer
def _executed(text: str, robot, measure: str) -> tuple[float, float]:
    """The written module read again and run by the controller emulation: cycle time and energy."""
    spec = _spec(text, robot)
    plan = plan_cycle(spec, ControllerConfig())
    n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
    traj = evaluate_cycle(plan, np.linspace(0.0, plan.cycle_time, n))
    first = plan.moves[0].step
    return plan.cycle_time, trajectory_energy(first.robot, make_plant("lab", first.robot), traj, measure)[0]


def _changed_lines(before: str, after: str) -> tuple[list[str], list[str]]:
    removed, added = [], []
    for line in difflib.ndiff(before.splitlines(), after.splitlines()):
        if line.startswith("- "):
            removed.append(line[2:])
        elif line.startswith("+ "):
            added.append(line[2:])
    return removed, added


@pytest.fixture(scope="module")
def approach(robot):
    spec, _ = read_cycle_program(EXAMPLES / "approach_depart.mod", robot)
    return spec, levers_module(spec, robot, energy="thesis", max_evaluations=120)


def test_levers_keep_the_cycle_time_and_save_as_executed(robot, approach):
    spec, result = approach
    assert result.reads_back is None
    assert result.n_evaluations <= 120 + 1
    assert result.cycle_s <= result.taught_cycle_s + 1e-9
    assert result.energy_J < result.default_energy_J
    assert result.n_changed >= 1
    # recomputed here from the written program's own motion
    t, e = _executed(result.written_text, robot, "thesis")
    assert t == pytest.approx(result.cycle_s, abs=1e-12)
    assert e == pytest.approx(result.energy_J, rel=1e-12)
    assert (result.searched_cycle_s, result.searched_energy_J) == pytest.approx((t, e), rel=1e-12)
    t0, e0 = _executed("\n".join(spec.module.source) + "\n", robot, "thesis")
    assert (t0, e0) == pytest.approx((result.taught_cycle_s, result.default_energy_J), rel=1e-12)


def test_levers_written_where_the_statements_stand(robot, approach):
    spec, result = approach
    original = (EXAMPLES / "approach_depart.mod").read_text()
    removed, added = _changed_lines(original, result.written_text)
    moves = {spec.module.source[s.line - 1] for s in _moves(spec)}
    assert removed and set(removed) <= moves
    for line in added:
        assert line.strip().startswith(("AccSet ", "MoveJ ", "MoveL ", "MoveAbsJ "))
    # every changed move keeps its target and tool, and reads back with the chosen settings
    again = _spec(result.written_text, robot)
    assert len(_moves(again)) == len(_moves(spec))  # (its lines move where AccSet lines are added)
    for a, b in zip(_moves(spec), _moves(again), strict=True):
        np.testing.assert_array_equal(a.q, b.q)
    chosen = {m.line: m.chosen for m in result.moves}
    for a, b in zip(_moves(spec), _moves(again), strict=True):
        c = chosen[a.line]
        assert (b.acc_pct, b.ramp_pct, b.time_s) == (c.acc_pct, c.ramp_pct, c.time_s)
        assert b.statement.speed == c.speed and b.statement.zone == c.zone


def test_levers_keep_line_ends_and_encoding(robot, tmp_path):
    text = (EXAMPLES / "approach_depart.mod").read_text().replace("(joulepath example)", "(Prüfstand)")
    path = tmp_path / "crlf.mod"
    path.write_bytes(text.replace("\n", "\r\n").encode("latin-1"))
    spec, _ = read_cycle_program(path, robot)
    result = levers_module(spec, robot, energy="thesis", max_evaluations=40)
    assert result.encoding == "latin-1" and result.reads_back is None
    data = result.written_bytes()
    assert data.count(b"\r\n") == data.count(b"\n")  # every line end is CRLF, as in the file
    assert "Prüfstand".encode("latin-1") in data
    kept = [ln for ln in data.decode("latin-1").splitlines() if not ln.strip().startswith(("AccSet", "Move"))]
    assert kept == [ln for ln in text.splitlines() if not ln.strip().startswith("Move")]


def test_existing_accset_is_changed_in_place_and_restored(robot):
    text = _module(
        "            AccSet 80, 100;\n            ! approach\n            MoveJ pA, v1000, z20, tool0;\n"
        "            MoveJ pB, v1000, fine, tool0;\n"
    )
    spec = _spec(text, robot)
    slots = _slots(spec, text.splitlines(keepends=True))
    assert [s.taught.acc_pct for s in slots] == [80.0, 80.0]
    chosen = (replace(slots[0].taught, acc_pct=50.0, ramp_pct=25.0), slots[1].taught)
    written, where = write_levers(spec.module, text, slots, chosen)
    removed, added = _changed_lines(text, written)
    assert removed == ["            AccSet 80, 100;"]
    assert added == ["            AccSet 50, 25;", "            AccSet 80, 100;"]
    a, b = _moves(_spec(written, robot))
    assert (a.acc_pct, a.ramp_pct, b.acc_pct, b.ramp_pct) == (50.0, 25.0, 80.0, 100.0)
    assert where[slots[1].line] == slots[1].line + 1


def test_adjacent_moves_share_one_accset(robot):
    text = JOINT_CYCLE
    spec = _spec(text, robot)
    slots = _slots(spec, text.splitlines(keepends=True))
    low = [replace(s.taught, acc_pct=50.0) for s in slots[:3]]
    written, _ = write_levers(spec.module, text, slots, (*low, replace(slots[3].taught, zone="z50")))
    _, added = _changed_lines(text, written)
    assert [ln.strip() for ln in added] == [
        "AccSet 50, 100;",
        "AccSet 100, 100;",
        "MoveJ pC, v1500, z50, tool0;",
    ]


def test_idle_waits_are_spent_and_shortened_in_place(robot):
    text = _module(
        "            MoveAbsJ jH, v1000, fine, tool0;\n            MoveJ pA, v1000, z20, tool0;\n"
        "            MoveJ pB, v1000, fine, tool0;\n            WaitTime 1; ! joulepath: idle\n"
    )
    spec = _spec(text, robot)
    plain = levers_module(spec, robot, energy="thesis", text=text, max_evaluations=60)
    spent = levers_module(spec, robot, energy="thesis", text=text, max_evaluations=60, use_waits=True)
    assert spent.reads_back is None and spent.cycle_s <= spent.taught_cycle_s + 1e-9
    assert spent.energy_J < plain.energy_J
    ((line, taught, now),) = spent.waits
    assert taught == 1.0 and 0.0 <= now < 1.0
    assert f"            WaitTime {now:g}; ! joulepath: idle" in spent.written_text.splitlines()


def test_levers_refuse_a_cycle_file_and_a_zero_budget(robot, tmp_path):
    spec = _spec(JOINT_CYCLE, robot)
    with pytest.raises(InvalidInput, match="max_evaluations"):
        levers_module(spec, robot, energy="thesis", text=JOINT_CYCLE, max_evaluations=0)
    with pytest.raises(InvalidInput, match="RAPID module"):
        levers_module(replace(spec, module=None), robot, energy="thesis", max_evaluations=5)
    with pytest.raises(InvalidInput, match="source"):
        levers_module(spec, robot, energy="thesis", text=JOINT_CYCLE.replace("pC", "pD"), max_evaluations=5)


def test_writer_edits_arguments_in_place_across_lines_and_comments(robot):
    text = _module(
        "            MoveJ pA,\n                  v1000 \\T:=2,\n                  z20, tool0; ! to A\n"
        "            MoveL pB, v500 \\V:=450, z10, tool0;\n"
        "            MoveJ pC, v1000, z10, tool0; MoveAbsJ jH, v1000, fine, tool0;\n"
    )
    spec = _spec(text, robot)
    slots = _slots(spec, text.splitlines(keepends=True))
    assert [("speed" in s.open, "zone" in s.open, "acc" in s.open) for s in slots] == [
        (True, True, True),  # \T is a lever; the comment after the ';' stays
        (False, True, True),  # \V: the speed stays as written
        (False, False, False),  # two statements on one line: not edited
        (False, False, False),
    ]
    chosen = (
        replace(slots[0].taught, time_s=2.5, zone="z5"),
        replace(slots[1].taught, zone="z30"),
        *(s.taught for s in slots[2:]),
    )
    written, where = write_levers(spec.module, text, slots, chosen)
    assert "                  v1000 \\T:=2.5,\n                  z5, tool0; ! to A\n" in written
    assert "            MoveL pB, v500 \\V:=450, z30, tool0;\n" in written
    assert where == {k: k for k in range(1, len(text.splitlines()) + 1)}
    a, b, *_ = _moves(_spec(written, robot))
    assert (a.time_s, a.zone_mm, b.zone_mm, b.speed.v_tcp) == (2.5, 5.0, 30.0, 450.0)


def test_a_module_over_its_baseline_time_is_first_brought_into_it(robot):
    # the joint cycle's fly-by targets at z1: larger zones (a lever) cut the corners and buy time
    text = JOINT_CYCLE.replace("z20", "z1")
    spec = _spec(text, robot)
    plan = plan_cycle(spec, ControllerConfig())
    over = 0.004  # the module runs this much longer than the program it replaces (s)
    baseline = (plan.cycle_time - over, 1e9, 1e9)  # any energy: only the time is asked here
    lv = levers_module(spec, robot, energy="thesis", text=text, baseline=baseline, max_evaluations=400)
    assert lv.cycle_s <= baseline[0] + 1e-6 < plan.cycle_time
    # what it wrote, read back and run, is that cycle
    again = plan_cycle(_spec(lv.written_text, robot), ControllerConfig())
    assert again.cycle_time == pytest.approx(lv.cycle_s, abs=1e-9)
    assert any(m.chosen.zone != m.taught.zone for m in lv.moves)
    # where no lever buys the time, the result stays over it (for the caller to refuse), never faked
    fine = _module(
        "            MoveL pA, v300, fine, tool0;\n            MoveL pB, v300, fine, tool0;\n"
    )  # stop points,
    # and a MoveL's speed is the programmer's bound: nothing to gain
    spec_f = _spec(fine, robot)
    t_f = plan_cycle(spec_f, ControllerConfig()).cycle_time
    lv_f = levers_module(
        spec_f, robot, energy="thesis", text=fine, baseline=(t_f - over, 1e9, 1e9), max_evaluations=400
    )
    assert lv_f.cycle_s > t_f - over


def test_a_search_stopped_by_its_time_budget_reports_the_plans_it_made(robot):
    spec = _spec(JOINT_CYCLE, robot)
    lv = levers_module(spec, robot, energy="thesis", text=JOINT_CYCLE, max_seconds=1e-9, max_evaluations=400)
    assert 1 <= lv.n_evaluations <= 400  # the plans made, not the marker that stopped the search


def _farthest(plan, taught_pos) -> tuple[float, float]:
    """The farthest the cycle's TCP comes from ``taught_pos`` (mm), by brute force, and when (s)."""
    n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
    traj = evaluate_cycle(plan, np.linspace(0.0, plan.cycle_time, n))
    first = plan.moves[0].step
    pos = tcp_pose(first.robot, traj.q, first.tcp)[0]
    d = np.linalg.norm(pos[:, None, :] - taught_pos[None, :, :], axis=2).min(axis=1)
    return 1000.0 * float(d.max()), float(traj.t[np.argmax(d)])


def _farthest_mm(plan, taught_pos) -> float:
    return _farthest(plan, taught_pos)[0]


def test_a_bound_on_the_motion_holds_at_every_step_the_search_takes(robot):
    spec = _spec(JOINT_CYCLE, robot)
    plan0 = plan_cycle(spec, ControllerConfig())
    n = int(np.ceil(plan0.cycle_time / FINE_DT)) + 1
    traj0 = evaluate_cycle(plan0, np.linspace(0.0, plan0.cycle_time, n))
    first = plan0.moves[0].step
    taught_pos = tcp_pose(first.robot, traj0.q, first.tcp)[0]
    free = levers_module(spec, robot, energy="thesis", text=JOINT_CYCLE, max_evaluations=300)
    free_dev = _farthest_mm(plan_cycle(_spec(free.written_text, robot), ControllerConfig()), taught_pos)
    assert free.energy_J < free.default_energy_J and free_dev > 0.5  # its levers move the path
    limit_mm = free_dev / 2.0
    asked = []

    def past(plan):
        asked.append(plan)
        mm, at_s = _farthest(plan, taught_pos)
        return mm - limit_mm, at_s

    held = levers_module(spec, robot, energy="thesis", text=JOINT_CYCLE, max_evaluations=300, bound=past)
    assert asked  # it was asked, and what the search took keeps it
    again = plan_cycle(_spec(held.written_text, robot), ControllerConfig())
    assert _farthest_mm(again, taught_pos) <= limit_mm
    assert held.cycle_s <= held.taught_cycle_s + 1e-9 and held.energy_J <= held.default_energy_J
    # a bound nothing passes: nothing taken, the program as given
    none = levers_module(
        spec, robot, energy="thesis", text=JOINT_CYCLE, max_evaluations=300, bound=lambda p: (1.0, 0.0)
    )
    assert none.n_changed == 0 and none.written_text == JOINT_CYCLE


def test_a_module_past_the_bound_is_first_brought_within_it(robot):
    # the bound: the path of the cycle with small zones; the module cuts its corners at z20 and has time
    # to spare (its baseline), so smaller zones bring it within the bound
    near = JOINT_CYCLE.replace("z20", "z1").replace("z10", "z1")
    plan_n = plan_cycle(_spec(near, robot), ControllerConfig())
    n = int(np.ceil(plan_n.cycle_time / FINE_DT)) + 1
    traj_n = evaluate_cycle(plan_n, np.linspace(0.0, plan_n.cycle_time, n))
    first = plan_n.moves[0].step
    ref = tcp_pose(first.robot, traj_n.q, first.tcp)[0]
    spec = _spec(JOINT_CYCLE, robot)
    plan0 = plan_cycle(spec, ControllerConfig())
    dev0 = _farthest_mm(plan0, ref)
    assert dev0 > 2.0
    limit_mm = dev0 / 2.0
    baseline = (plan_n.cycle_time + 0.05, 1e9, 1e9)
    lv = levers_module(
        spec,
        robot,
        energy="thesis",
        text=JOINT_CYCLE,
        baseline=baseline,
        max_evaluations=300,
        bound=lambda p: (_farthest(p, ref)[0] - limit_mm, _farthest(p, ref)[1]),
    )
    again = plan_cycle(_spec(lv.written_text, robot), ControllerConfig())
    assert _farthest_mm(again, ref) <= limit_mm
    assert lv.cycle_s <= baseline[0] + 1e-6
    assert any(m.chosen.zone != m.taught.zone for m in lv.moves)


def _long_chain_module() -> str:
    """One long timed fly-by chain whose short moves break corners in its middle."""
    moves = [("pA", 0.9), ("pB", 0.9), ("pC", 0.15), ("pA", 0.3), ("pB", 1.2), ("pC", 0.5), ("pA", 0.15)]
    lines = "".join(f"            MoveJ {p}, v1000\\T:={t}, z50, tool0;\n" for p, t in moves)
    return _module(lines + "            MoveJ pB, v1000, fine, tool0;\n")


def _dropped_one_at_a_time(plans, chain, config):
    """The reference: the whole chain timed again after each corner it drops."""
    active = set(chain)
    while True:
        out, bad = timing._chain_profiles(plans, active, config)
        if bad is None:
            return out
        active.discard(bad)


@pytest.mark.parametrize("acc", [100.0, 60.0, 30.0])
def test_a_chain_split_at_its_dropped_corners_times_as_the_whole_chain(robot, acc, monkeypatch):
    """Timing each part of a chain on its own after a corner is dropped drops the same corners and
    gives the same profiles as timing the whole chain again after each drop."""
    spec = _with_all(_spec(_long_chain_module(), robot), acc_pct=acc)
    config = ControllerConfig()
    drops = []
    real = timing._chain_profiles

    def counted(plans, active, config):
        out, bad = real(plans, active, config)
        if bad is not None and min(active) < bad < max(active):
            drops.append(bad)  # a corner dropped with corners on both sides: the chain splits
        return out, bad

    monkeypatch.setattr(timing, "_chain_profiles", counted)
    split = plan_cycle(spec, config)
    monkeypatch.setattr(timing, "_timed_chain", _dropped_one_at_a_time)
    _same_plans(split, plan_cycle(spec, config))
    assert drops, "no chain was split: the case does not test the split"
