"""A move on a large ABB arm: optimized within its limits, its saving stated over the model's uncertainty."""

from __future__ import annotations

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.description import Uncertainty, provenance_beside, sample_chains
from joulepath.errors import InvalidInput
from joulepath.optimize import OptimizeConfig, optimize_move, saving_over_uncertainty


@pytest.fixture(scope="module")
def big_move():
    robot = load_robot("irb4600")
    q0 = np.radians([-60.0, 10.0, -20.0, 30.0, 40.0, 0.0])
    qf = np.radians([60.0, 40.0, -50.0, -30.0, 60.0, 90.0])
    return robot, optimize_move(robot, q0, qf, 2.5, OptimizeConfig(seed=1))


def test_optimize_move_on_a_large_arm_stays_within_every_limit(big_move):
    robot, result = big_move
    s = result.summary
    assert s.limits_ok and s.limit_excess == ()
    lo, hi = robot.joint_ranges()
    assert np.all(result.optimized.q >= lo - 1e-9) and np.all(result.optimized.q <= hi + 1e-9)
    assert np.all(np.abs(result.optimized.qd) <= robot.chain.velocity * (1 + 1e-6))
    assert s.energy_optimized_J < s.energy_default_J


def test_saving_over_uncertainty_zero_width_gives_the_nominal_saving(big_move):
    robot, result = big_move
    stated = saving_over_uncertainty(
        robot, result.default, result.optimized, Uncertainty(), n_samples=5, seed=3
    )
    assert stated.nominal_pct == pytest.approx(result.summary.saved_pct, rel=1e-9)
    assert stated.median_pct == pytest.approx(stated.nominal_pct, rel=1e-12)
    assert stated.p5_pct == pytest.approx(stated.nominal_pct, rel=1e-12)


def test_saving_over_uncertainty_is_seeded_and_spreads_with_the_bounds(big_move):
    robot, result = big_move
    prov = provenance_beside(robot.source)
    assert prov is not None and prov.is_estimate
    a = saving_over_uncertainty(
        robot, result.default, result.optimized, prov.uncertainty, n_samples=16, seed=5
    )
    b = saving_over_uncertainty(
        robot, result.default, result.optimized, prov.uncertainty, n_samples=16, seed=5
    )
    c = saving_over_uncertainty(
        robot, result.default, result.optimized, prov.uncertainty, n_samples=16, seed=6
    )
    assert a == b
    assert a.median_pct != c.median_pct
    assert a.p5_pct <= a.median_pct
    assert a.p5_pct != a.nominal_pct  # a non-zero width moves the statement off the nominal model
    assert ("NOT headlined" in a.line()) == (a.p5_pct < 0)


def test_saving_over_uncertainty_refuses_no_samples(big_move):
    robot, result = big_move
    with pytest.raises(InvalidInput, match="n_samples must be an integer"):
        saving_over_uncertainty(robot, result.default, result.optimized, Uncertainty(), n_samples=0)


def test_sample_chains_stay_within_the_bounds_and_physical():
    chain = load_robot("irb6700").chain
    u = Uncertainty(link_mass_rel=0.5, link_com_m=0.1, link_inertia_rel=0.4)
    samples = sample_chains(chain, u, 50, rng=np.random.default_rng(0))
    masses = np.stack([s.masses for s in samples])
    assert np.all(masses >= chain.masses * 0.5 - 1e-12) and np.all(masses <= chain.masses * 1.5 + 1e-12)
    shifts = np.stack([s.coms - chain.coms for s in samples])
    assert np.abs(shifts).max() <= 0.1 + 1e-12 and np.abs(shifts).max() > 0.05
    for s in samples:
        principal = np.linalg.eigvalsh(s.inertias)
        assert np.all(principal > 0)
        assert np.all(principal <= principal.sum(-1, keepdims=True) - principal + 1e-9)
        np.testing.assert_array_equal(s.placements, chain.placements)
    same = sample_chains(chain, Uncertainty(), 2, rng=np.random.default_rng(0))
    np.testing.assert_array_equal(same[0].masses, chain.masses)


def test_optimize_command_states_the_saving_over_the_uncertainty(tmp_path, capsys):
    from joulepath.cli import main

    args = ["optimize", "--robot", "irb4600", "--start=-60,10,-20,30,40,0", "--end=60,40,-50,-30,60,90"]
    assert main([*args, "--degrees", "--duration", "2.5", "--out", str(tmp_path / "run")]) == 0
    captured = capsys.readouterr()
    assert "planned saving" in captured.out and "5th percentile" in captured.out
    assert "is ESTIMATED" in captured.out
    assert "model estimated" in captured.err  # the warning every command prints for a model of estimates
    assert (tmp_path / "run" / "path.mod").is_file()


def test_expected_energy_zero_width_is_the_nominal_physics_energy(big_move):
    """The robust objective over zero-width samples sums, path by path, to the nominal energy."""
    from joulepath.optimize import ExpectedEnergy, physics_energy
    from joulepath.optimize._features import path_features
    from joulepath.trajectory import Trajectory

    robot, result = big_move
    paths = Trajectory(
        t=result.default.t,
        q=np.stack([result.default.q, result.optimized.q]),
        qd=np.stack([result.default.qd, result.optimized.qd]),
        qdd=np.stack([result.default.qdd, result.optimized.qdd]),
    )
    model = ExpectedEnergy(robot, Uncertainty(), rng=0, n_samples=3)
    rows = path_features(robot, paths, model.input_columns)
    expected = model.predict_rows(rows).reshape(2, -1).sum(axis=1)
    nominal, _ = physics_energy(robot, paths)
    np.testing.assert_allclose(expected, nominal, rtol=1e-12)
    wide = ExpectedEnergy(robot, provenance_beside(robot.source).uncertainty, rng=0, n_samples=3)
    assert not np.allclose(wide.predict_rows(rows).reshape(2, -1).sum(axis=1), nominal)


def test_optimize_robust_needs_a_model_with_a_stated_uncertainty(tmp_path, capsys):
    from joulepath.cli import main

    args = ["optimize", "--robot", "irb120", "--start=0,0,0,0,0,0", "--end=0.5,0.2,0.1,0,0.3,0"]
    assert main([*args, "--duration", "1.5", "--robust", "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "states no uncertainty" in err[0]
    assert not (tmp_path / "r").exists()


def test_optimize_robust_on_a_large_arm_is_within_limits_and_stated(tmp_path, capsys):
    from joulepath.cli import main

    args = ["optimize", "--robot", "irb1200", "--start=-60,10,-20,30,40,0", "--end=60,40,-50,-30,60,90"]
    assert main([*args, "--degrees", "--duration", "1.175", "--robust", "--out", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    assert "robust objective: expected energy over 16 models" in out
    assert "within every limit" in out and "5th percentile" in out
