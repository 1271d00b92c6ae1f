import json

import numpy as np
import pytest

from joulepath.errors import InvalidInput, LimitViolation
from joulepath.export import path_module
from joulepath.optimize import OptimizeConfig, optimize_move, write_run

Q0 = np.radians([-60, 10, -30, 40, 20, 0])
QF = np.radians([70, 30, 10, -50, -40, 90])


@pytest.fixture(scope="module")
def result(irb120):
    return optimize_move(irb120, Q0, QF, 1.5, OptimizeConfig(algorithm="ga", max_gen=25, pop_size=40, seed=3))


def test_short_optimization_beats_the_default_path_on_physics(result):
    s = result.summary
    assert s.energy_optimized_J < s.energy_default_J
    assert s.saved_pct > 2.0
    assert s.limits_ok
    # the optimized path keeps the cycle time and starts and ends at rest
    np.testing.assert_allclose(result.optimized.t[-1], 1.5)
    np.testing.assert_allclose(result.optimized.q[[0, -1]], [Q0, QF], atol=1e-12)
    np.testing.assert_allclose(result.optimized.qd[[0, -1]], 0.0, atol=1e-12)


@pytest.mark.parametrize("algorithm", ["de", "ma-random", "ma-informed"])
def test_algorithms_run_and_seed_reproduces(irb120, algorithm):
    cfg = OptimizeConfig(algorithm=algorithm, max_gen=4, pop_size=12, n_local=50, seed=5)
    a = optimize_move(irb120, Q0, QF, 1.0, cfg)
    b = optimize_move(irb120, Q0, QF, 1.0, cfg)
    np.testing.assert_array_equal(a.parameters, b.parameters)
    assert a.summary.energy_optimized_J <= a.summary.energy_default_J + 1e-12


def test_write_run_files(result, irb120, tmp_path):
    files = write_run(result, irb120, tmp_path)
    assert {"result.json", "path.csv", "convergence.csv", "path.mod", "joints.png", "power.png"} <= set(files)
    summary = json.loads((tmp_path / "result.json").read_text())
    for key in (
        "robot",
        "start_rad",
        "end_rad",
        "duration_s",
        "algorithm",
        "seed",
        "energy_default_J",
        "energy_optimized_J",
        "energy_optimized_fine_J",
        "energy_optimized_surrogate_J",
        "saved_pct",
        "limits_ok",
        "max_tcp_deviation_mm",
        "iterations",
        "evaluations",
        "wall_s",
    ):
        assert key in summary
    assert summary["representation"] == "rest_to_rest"
    path = np.loadtxt(tmp_path / "path.csv", delimiter=",", skiprows=1)
    assert path.shape == (61, 19)
    np.testing.assert_allclose(path[:, 0], np.arange(61) * 0.025)
    assert (tmp_path / "path.csv").read_text().startswith("t,q1,q2,q3,q4,q5,q6,qd1")
    mod = (tmp_path / "path.mod").read_text()
    assert "MoveAbsJ GOAL, v7000 \\T:=MOVE_TIME, fine, tool0;" in mod and "START" in mod


def test_path_module_refuses_violations(irb120, result):
    q = result.optimized.q.copy()
    q[10, 1] = np.radians(130)  # joint 2 past its +110 deg limit
    with pytest.raises(LimitViolation, match=r"sample 10: joint 2 at 130\.00 deg leaves its range"):
        path_module(irb120, q, result.optimized.qd, 1.5)
    qd = result.optimized.qd.copy()
    qd[5, 0] = 10.0
    with pytest.raises(LimitViolation, match="joint 1 speed 573.0 deg/s exceeds its limit 250.0"):
        path_module(irb120, result.optimized.q, qd, 1.5)


def test_write_run_refuses_rapid_for_violating_path(result, irb120, tmp_path):
    from dataclasses import replace

    write_run(result, irb120, tmp_path)
    assert (tmp_path / "path.mod").exists()  # an earlier, good run left a program
    bad = replace(result, summary=replace(result.summary, limits_ok=False, limit_excess=("joint 2 ...",)))
    files = write_run(bad, irb120, tmp_path)
    assert "path.mod" not in files and not (tmp_path / "path.mod").exists()
    assert json.loads((tmp_path / "result.json").read_text())["rapid"] is None


def test_result_json_is_strict_json(result, irb120, tmp_path):
    from dataclasses import replace

    odd = replace(result, summary=replace(result.summary, energy_default_lab_J=float("nan")))
    write_run(odd, irb120, tmp_path)
    text = (tmp_path / "result.json").read_text()
    assert "NaN" not in text and "Infinity" not in text
    assert json.loads(text)["energy_default_lab_J"] is None


def test_optimize_move_refuses_start_outside_the_range(irb120):
    with pytest.raises(LimitViolation, match=r"start joint 2 = 120\.00 deg is outside its range"):
        optimize_move(irb120, np.radians([0, 120, 0, 0, 0, 0]), QF, 1.0, OptimizeConfig())
    with pytest.raises(InvalidInput, match="algorithm must be one of"):
        OptimizeConfig(algorithm="pso")
    with pytest.raises(InvalidInput, match="needs fitness physics"):
        OptimizeConfig(algorithm="gradient", fitness="surrogate")
    with pytest.raises(InvalidInput, match="same configuration"):
        optimize_move(irb120, QF, QF, 1.0, OptimizeConfig())


def test_result_json_pairs_each_figure_with_its_measure(result, irb120, tmp_path):
    """Read as a user: each stage's pair is on the run's measure, the headline keys are those
    figures, and the lab's are the lab robot's own energies of the two paths on that measure."""
    from joulepath.optimize._verify import plant_measured
    from joulepath.sim import make_plant

    write_run(result, irb120, tmp_path)
    r = json.loads((tmp_path / "result.json").read_text())
    m = r["energy_measure"]
    figures = r["energy_figures"]
    assert m == "thesis" and figures["measure"] == m
    stages = [s for s in ("planned", "lab", "executed") if figures[s] is not None]
    assert stages[:2] == ["planned", "lab"]
    for stage in stages:
        assert figures[stage]["measure"] == m
        for key in ("default_J", "optimized_J", "saved_pct"):
            assert r[f"{stage}_{key}"] == pytest.approx(figures[stage][key])
    lab = make_plant("lab", irb120)
    for path, key in ((result.default, "lab_default_J"), (result.optimized, "lab_optimized_J")):
        assert r[key] == pytest.approx(plant_measured(lab, path, measure=m).total_J, rel=1e-12)
    assert r["planned_default_J"] == r["energy_default_J"] == pytest.approx(r["energies"][m]["default_J"])
    # the old lab keys are on another measure: kept, and listed as deprecated with their measure
    assert r["energy_default_lab_J"] == pytest.approx(r["energies"]["mechanical"]["lab_default_J"])
    assert r["energy_default_lab_J"] != pytest.approx(r["lab_default_J"], rel=1e-6)
    assert "mechanical" in r["deprecated_keys"]["energy_default_lab_J"]
    assert {k for k in r["deprecated_keys"] if not k.startswith("executed_")} <= set(r)  # still written
    vs = figures["planned_vs_lab"]
    assert vs["default_pct"] == pytest.approx(100 * (r["planned_default_J"] / r["lab_default_J"] - 1))
    if figures["executed"] is not None:  # path.mod written: the emulation on the model and the lab
        x = figures["executed"]
        assert x["default_J"] == pytest.approx(r["executed_energy_default_J"])
        assert x["lab_default_J"] == pytest.approx(r["executed_lab_default_J"])
