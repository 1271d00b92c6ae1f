"""The fast default optimizer against the slow reference (CasADi transcription + IPOPT)."""

import numpy as np
import pytest

pytest.importorskip("casadi")

from joulepath.dynamics import NOMINAL_FRICTION  # noqa: E402
from joulepath.optimize import (  # noqa: E402
    ACCEL_TIME,
    JERK_TIME,
    OptimizeConfig,
    acceleration_limit,
    jerk_limit,
    optimize_move,
    path_jerk,
)
from joulepath.optimize._reference import casadi_rnea, reference_optimum  # noqa: E402


def test_casadi_rnea_agrees_with_pinocchio(irb120, rng):
    f = casadi_rnea(irb120)
    for _ in range(20):
        q, qd, qdd = rng.standard_normal((3, 6)) * 2
        np.testing.assert_allclose(
            np.asarray(f(q, qd, qdd)).ravel(), irb120.inverse_dynamics(q, qd, qdd), atol=1e-10
        )


def test_default_optimizer_reaches_the_reference_optimum_on_a_small_move(irb120):
    q0 = np.array([0.2, -0.1, 0.1, 0.4, -0.3, 0.5])
    qf = np.array([-0.6, 0.4, -0.3, -0.5, 0.6, -0.8])
    T = 0.8
    ours = optimize_move(irb120, q0, qf, T, OptimizeConfig()).summary
    jmax = jerk_limit(irb120, ACCEL_TIME, JERK_TIME)
    ref = reference_optimum(
        irb120,
        q0,
        qf,
        T,
        friction=NOMINAL_FRICTION,
        acceleration_limit=acceleration_limit(irb120, ACCEL_TIME),
        jerk_limit=jmax,
    )
    assert ref.status == "Solve_Succeeded" and ref.max_violation < 1e-6
    # the same jerk limit as ours: its piecewise-constant jerk, measured as the limit check does
    assert np.all(np.abs(path_jerk(ref.path)[1]) <= jmax * (1 + 1e-6))
    assert ours.jerk_limit_rad_s3 == pytest.approx(tuple(jmax))
    # the reference optimizes the integral (fine grid); compare like with like
    assert ref.energy_fine_J < ours.energy_default_fine_J
    share = (ours.energy_default_fine_J - ours.energy_optimized_fine_J) / (
        ours.energy_default_fine_J - ref.energy_fine_J
    )
    assert share > 0.85, f"reached {share:.1%} of the reference saving"
    # and the reference, an independent solver, never finds a path much worse than ours
    assert ref.energy_fine_J <= ours.energy_optimized_fine_J * 1.01


def test_experiment_states_the_share_of_the_optimum(irb120):
    """The `[optimize] reference = true` columns: the optimum's saving and the share of it reached."""
    from joulepath.experiment._run import _optimum

    q0 = np.array([0.1, 0.0, 0.0, 0.3, 0.2, 0.0])
    qf = np.array([-0.3, 0.2, -0.2, -0.2, 0.5, 0.6])
    res = optimize_move(irb120, q0, qf, 0.6, OptimizeConfig())
    row = _optimum(irb120, res)
    assert set(row) == {"optimum_J", "optimum_saved_pct", "share_of_optimum_pct", "optimum_wall_s"}
    assert row["optimum_J"] <= res.summary.energy_default_fine_J
    assert 0 < row["optimum_saved_pct"] < 100
    expected = (
        100
        * (res.summary.energy_default_fine_J - res.summary.energy_optimized_fine_J)
        / (res.summary.energy_default_fine_J - row["optimum_J"])
    )
    assert row["share_of_optimum_pct"] == pytest.approx(expected)
    assert row["share_of_optimum_pct"] > 80
