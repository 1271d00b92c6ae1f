"""End to end: optimize the fixed task, run its path.mod on the sim plant, measure what ran."""

import json
import shutil

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.energy import total_energy
from joulepath.errors import InvalidInput
from joulepath.measure import find_moves, measure_run, read_plan, saving_interval, write_measure
from joulepath.program import program_motion, read_module, resolve_module, simulate_program
from joulepath.sim import ControllerConfig, make_plant, simulate

START = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
END = np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb120")


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory, via_points_run):
    """START -> END in 1.6 s optimized with ``follow="via-points"``, written (tests/conftest.py); a copy."""
    result, shared = via_points_run
    s = result.summary
    assert (s.start_rad, s.end_rad, s.duration_s) == (tuple(START), tuple(END), 1.6)
    out = tmp_path_factory.mktemp("run") / "run"
    shutil.copytree(shared, out)
    return out


@pytest.fixture(scope="module")
def sim_log(run_folder, robot):
    return simulate_program(run_folder / "path.mod", run_folder / "sim.csv", robot=robot, plant="sim", seed=1)


@pytest.fixture(scope="module")
def measured(sim_log, run_folder):
    return measure_run(sim_log.log, run_folder)


def _commanded_energies(run_folder, robot):
    """Each repetition's energy on the sim plant from the commanded motion on a 0.5 ms grid."""
    motion = program_motion(resolve_module(read_module(run_folder / "path.mod"), robot), ControllerConfig())
    plant = make_plant("sim", robot)
    moves = motion.plan.moves
    windows = []
    for i, m in enumerate(moves):
        if m.step.label == "MoveAbsJ GOAL":
            windows.append(("default", m.t0, m.t_end))
        elif m.step.label == "MoveAbsJ OPT{1}":
            last = next(x for x in moves[i:] if np.abs(x.step.q - END).max() < 1e-3)
            windows.append(("optimized", m.t0, last.t_end))
    out = []
    for kind, a, b in windows:
        t = np.arange(a, b, 0.0005) + motion.offset
        q, qd, qdd = motion.evaluate(t)
        out.append((kind, b - a, float(total_energy(plant.drive_torque(q, qd, qdd), qd, 0.0005).sum())))
    return out


def test_measure_finds_five_default_then_five_optimized(measured):
    m = measured.measurement
    assert [r.kind for r in m.repetitions] == ["default"] * 5 + ["optimized"] * 5
    assert (m.default.n, m.optimized.n, m.classified_by, m.order_as_path_mod) == (5, 5, "shape", True)
    for r in m.repetitions:  # each is told by its path: on its own planned path, far from the other
        own, other = (
            (r.path_distance_default_deg, r.path_distance_optimized_deg)
            if r.kind == "default"
            else (r.path_distance_optimized_deg, r.path_distance_default_deg)
        )
        assert own < 1.0 < other


def test_measured_energies_match_the_commanded_motion_on_the_plant(measured, run_folder, robot):
    truth = _commanded_energies(run_folder, robot)
    reps = measured.measurement.repetitions
    assert [k for k, _, _ in truth] == [r.kind for r in reps]
    for r, (_, duration, energy) in zip(reps, truth, strict=True):
        # the 40 Hz log samples a timed via chain whose acceleration steps at its corners: the
        # log's rectangle rule misses part of the inertial power there (a few % of a move)
        assert r.energy_J == pytest.approx(energy, rel=0.05)
        assert r.duration_s == pytest.approx(duration, abs=3 * measured.measurement.sample_period_s)


def test_measured_saving_interval_holds_the_noiseless_saving(measured, run_folder, robot):
    truth = _commanded_energies(run_folder, robot)
    e_def = np.mean([e for k, _, e in truth if k == "default"])
    e_opt = np.mean([e for k, _, e in truth if k == "optimized"])
    s = measured.measurement.saving
    assert s.ci95_low_pct <= 100 * (1 - e_opt / e_def) <= s.ci95_high_pct
    assert s.ci95_low_pct < s.pct < s.ci95_high_pct


def test_measure_reports_the_executed_against_the_planned_duration(measured):
    m = measured.measurement
    assert m.planned_duration_s == 1.6
    assert m.default.executed_over_planned == pytest.approx(m.default.duration_mean_s / 1.6)
    assert m.default.duration_mean_s == pytest.approx(1.6, abs=3 * m.sample_period_s)  # MoveAbsJ \T keeps it
    off = {
        kind: abs(k.executed_over_planned - 1.0) > 0.05
        for kind, k in (("default", m.default), ("optimized", m.optimized))
    }
    assert off["default"] is False
    for kind in ("default", "optimized"):
        assert any(n.startswith(f"the {kind} move ran") for n in m.notes) == off[kind]
    for r in m.repetitions:
        assert (r.tracking_error_max_deg is None) == (r.kind == "default")
        if r.kind == "optimized":
            assert 0 <= r.tracking_error_rms_deg <= r.tracking_error_max_deg


def test_write_measure_writes_json_and_plot(measured, tmp_path):
    files = write_measure(measured, tmp_path / "m")
    data = json.loads(files["measure.json"].read_text())
    assert len(data["repetitions"]) == 10
    assert data["saving"]["pct"] == pytest.approx(measured.measurement.saving.pct)
    assert files["power.png"].read_bytes()[:4] == b"\x89PNG"


def test_measure_refuses_a_truncated_log(sim_log, run_folder, tmp_path):
    lines = sim_log.log.read_text().splitlines(keepends=True)
    cut = tmp_path / "cut.csv"
    cut.write_text("".join(lines[: int(0.75 * len(lines))]))
    with pytest.raises(InvalidInput, match=r"5 default and [0-4] optimized moves") as info:
        measure_run(cut, run_folder)
    assert len(str(info.value).splitlines()) == 1


def test_measure_refuses_a_log_of_another_plan(run_folder, tmp_path):
    other = simulate(tmp_path / "random.csv", plant="sim", n_moves=30, seed=2)
    with pytest.raises(InvalidInput, match="found 0 moves from rest at START") as info:
        measure_run(other.log, run_folder)
    assert len(str(info.value).splitlines()) == 1


def test_measure_refuses_a_plan_of_other_paths(sim_log, run_folder, tmp_path):
    other = tmp_path / "other"
    shutil.copytree(run_folder, other)
    text = (other / "path.csv").read_text().splitlines()
    head, rows = text[0], [np.array(r.split(","), float) for r in text[1:]]
    for row in rows[1:-1]:  # the same ends, another way between them
        row[2] += 0.5 * np.sin(np.pi * row[0] / 1.6)
    (other / "path.csv").write_text(
        head + "\n" + "\n".join(",".join(f"{v:.10g}" for v in r) for r in rows) + "\n"
    )
    with pytest.raises(InvalidInput, match="follows neither planned path") as info:
        measure_run(sim_log.log, other)
    assert len(str(info.value).splitlines()) == 1


def test_read_plan_refuses_a_folder_without_result(tmp_path):
    with pytest.raises(InvalidInput, match="missing result.json, path.csv, default_path.csv"):
        read_plan(tmp_path)


def test_find_moves_hand_made_log():
    # rest at 0, a move to 1, rest, back to 0 (not a move of the plan), rest, a move that turns back,
    # a move to 1 that arrives at sample 12 still moving and rests from 13
    t = np.arange(14) * 0.1
    q = np.array([0, 0, 0.5, 1, 1, 0.5, 0, 0, 0.5, 0, 0, 0.5, 1, 1], float)[:, None]
    qd = np.gradient(q[:, 0], t)[:, None]
    qd[[0, 1, 3, 4, 6, 7, 9, 10, 13]] = 0.0
    windows = find_moves(t, q, qd, np.array([0.0]), np.array([1.0]))
    assert [(w.first, w.last) for w in windows] == [(1, 3), (10, 13)]


def test_saving_interval_by_hand():
    d = np.array([10.0, 12.0])
    o = np.array([8.0, 9.0])
    s = saving_interval(d, o)
    ratio = 8.5 / 11.0
    se = ratio * np.sqrt(0.5 / (2 * 8.5**2) + 2.0 / (2 * 11.0**2))
    half = 4.302652729911275 * se  # t(0.975, 2 degrees of freedom)
    assert s.pct == pytest.approx(100 * (1 - ratio))
    assert (s.ci95_low_pct, s.ci95_high_pct) == pytest.approx(
        (100 * (1 - ratio - half), 100 * (1 - ratio + half))
    )
    with pytest.raises(InvalidInput, match="at least 2 repetitions"):
        saving_interval(d[:1], o)


def test_lab_rehearsal_measures_the_saving_result_json_predicts(run_folder, robot, tmp_path):
    """simulate --program on the lab plant, then measure: the realized saving agrees with the executed
    lab saving that write_run predicted from the commanded motion (two independent routes: the noisy
    40 Hz log's torques and speeds against the commanded motion on the plant's drive model)."""
    predicted = json.loads((run_folder / "result.json").read_text())["executed_saved_lab_pct"]
    log = simulate_program(run_folder / "path.mod", tmp_path / "lab.csv", robot=robot, plant="lab", seed=2)
    m = measure_run(log.log, run_folder).measurement
    assert m.default.n == 5 and m.optimized.n == 5
    # The two routes differ by a systematic gap the prediction does not model (the plant's tracking
    # lag, the 40 Hz log): measured on seeds 1-4, the log gives 9.9-10.4 % for this path.mod while
    # the commanded motion predicts 9.56 % (code of 29b263e) or 8.89 % (after the search's speed work:
    # the plan is the same to 5e-5 points, the via-point layout of path.mod is not), so 1.5 points.
    assert abs(m.saving.pct - predicted) <= 1.5
