"""Exciting trajectories: within every limit by construction, better conditioned, usable end to end."""

from __future__ import annotations

import numpy as np
import pytest

from joulepath.cli import main
from joulepath.errors import LimitViolation
from joulepath.export import excitation_module
from joulepath.identify import (
    FourierExcitation,
    IdentifyOptions,
    data_from_logs,
    design_excitation,
    identify,
    simulate_excitation,
)


@pytest.fixture(scope="module")
def design(irb120):
    return design_excitation(irb120, periods=2, samples=60, iterations=2, seed=4)


def test_fourier_derivatives_agree_with_finite_differences(rng):
    traj = FourierExcitation(
        q_mid=np.zeros(2), a=rng.normal(size=(2, 3)), b=rng.normal(size=(2, 3)), base_hz=0.2
    )
    t = np.linspace(0.5, 4.5, 41)
    h = 1e-6
    q_p, qd_p, _ = traj.evaluate(t + h)
    q_m, qd_m, _ = traj.evaluate(t - h)
    _, qd, qdd = traj.evaluate(t)
    np.testing.assert_allclose(qd, (q_p - q_m) / (2 * h), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(qdd, (qd_p - qd_m) / (2 * h), rtol=1e-6, atol=1e-6)


def test_design_stays_within_limits_and_starts_at_rest(design, irb120):
    margin, accel_time = 0.9, 0.25
    path = design.trajectory.sample(0.002)
    lo, hi = irb120.joint_ranges("collection")
    assert np.all(path.q >= lo) and np.all(path.q <= hi)
    vmax = irb120.velocity_limit
    assert np.all(np.abs(path.qd) <= margin * vmax * (1 + 1e-12))
    assert np.all(np.abs(path.qdd) <= margin * vmax / accel_time * (1 + 1e-12))
    for k in (0, -1):
        np.testing.assert_allclose(path.qd[k], 0.0, atol=1e-12)
        np.testing.assert_allclose(path.qdd[k], 0.0, atol=1e-9)
    assert design.trajectory.end_time == pytest.approx(20.0)
    assert design.condition_number <= design.condition_number_start


def test_simulated_excitation_identifies_the_sim_plant(design, irb120, tmp_path):
    log = tmp_path / "exc.csv"
    rows, seconds = simulate_excitation(log, design, irb120, plant="sim", seed=1)
    assert rows > 100 and seconds > design.trajectory.end_time
    result = identify(data_from_logs([log], irb120), irb120, IdentifyOptions(gear_efficiency=1.0))
    assert result.condition_number < 1e3
    assert min(result.fit.torque_r2) > 0.99


def test_excitation_program_is_checked_against_the_limits(design, irb120):
    path = design.trajectory.sample(0.025)
    text = excitation_module(irb120, path.q, path.qd, design.trajectory.end_time)
    assert text.startswith("MODULE JPExcite") and "MoveAbsJ START, v200, fine, tool0;" in text
    far = path.q.copy()
    far[10, 2] = irb120.upper[2] + 0.1
    with pytest.raises(LimitViolation, match="joint 3"):
        excitation_module(irb120, far, path.qd, design.trajectory.end_time)


def test_simulate_mode_excitation_cli(tmp_path, capsys):
    log = tmp_path / "exc.csv"
    assert (
        main(
            [
                "simulate",
                "--mode",
                "excitation",
                "--periods",
                "1",
                "--harmonics",
                "2",
                "--plant",
                "lab",
                "--out",
                str(log),
            ]
        )
        == 0
    )
    assert "condition number" in capsys.readouterr().out
    assert main(["simulate", "--mode", "sweep", "--out", str(tmp_path / "x.csv")]) == 2
    assert "unknown mode" in capsys.readouterr().err
