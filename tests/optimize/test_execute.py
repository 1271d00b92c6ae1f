"""path.mod runs as planned: the written module, read back and run by the controller emulation,
is the motion result.json's executed figures describe; the RAPID plan keeps the controller's ramp."""

import json

import numpy as np
import pytest

from joulepath.energy import path_energy
from joulepath.optimize import OptimizeConfig, rapid_execution
from joulepath.program._parse import parse_module
from joulepath.program._resolve import resolve_module
from joulepath.sim import RAPID_ACCEL_SHARE, ControllerConfig, acceleration_limit, evaluate_cycle, plan_cycle
from joulepath.sim._timing import FINE_DT

Q0 = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
QF = np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])


@pytest.fixture(scope="module")
def rapid_run(via_points_run):
    """Q0 -> QF in 1.6 s optimized with ``follow="via-points"``, written (tests/conftest.py)."""
    result, folder = via_points_run
    s = result.summary
    assert (s.start_rad, s.end_rad, s.duration_s) == (tuple(Q0), tuple(QF), 1.6)
    return result, folder, json.loads((folder / "result.json").read_text())


def _energy(robot, traj):
    tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=robot.friction)
    return float(path_energy(tau, traj.qd, traj.dt).total)


def test_rapid_plan_stays_within_the_via_point_share_of_the_acceleration_limit(rapid_run, irb120):
    result, _, _ = rapid_run
    amax = acceleration_limit(irb120, OptimizeConfig().accel_time) * RAPID_ACCEL_SHARE
    np.testing.assert_allclose(result.summary.acceleration_limit_rad_s2, amax)
    assert np.all(np.abs(result.optimized.qdd) <= amax * (1 + 1e-6))


def test_written_path_mod_read_back_runs_as_result_json_says(rapid_run, irb120):
    """The module's text, parsed and run by the emulation, gives the executed duration and energies."""
    _, folder, summary = rapid_run
    assert summary["rapid"] == "path.mod" and summary["executed_matches_plan"]
    module = parse_module((folder / "path.mod").read_text(), path="path.mod")
    spec = resolve_module(module, irb120)
    plan = plan_cycle(spec, ControllerConfig())
    moves = plan.moves
    # the structure path.mod declares: per repetition a move to START, then the default (1 move) or
    # the optimized move (its via points); 5 + 5 repetitions
    n_via = summary["executed_via_points"]
    assert len(moves) == 5 * 2 + 5 * (1 + n_via)
    default = moves[1]
    opt = moves[-n_via:]
    assert default.t_end - default.t0 == pytest.approx(summary["executed_default_duration_s"], abs=1e-9)
    assert opt[-1].t_end - opt[0].t0 == pytest.approx(summary["executed_duration_s"], abs=1e-9)
    for first, last, key in ((default, default, "default"), (opt[0], opt[-1], "optimized")):
        n = int(np.ceil((last.t_end - first.t0) / FINE_DT)) + 1
        traj = evaluate_cycle(plan, np.linspace(first.t0, last.t_end, n))
        # the timed chain's acceleration steps at its corners: a 2.5 ms grid whose phase differs by
        # float round-off lands a sample on the other side of a step (up to ~1 % of a move's energy)
        assert _energy(irb120, traj) == pytest.approx(summary[f"executed_energy_{key}_J"], rel=1e-2)
    np.testing.assert_allclose(opt[-1].step.q, QF, atol=1e-6)  # 4 decimals of a degree


def test_executed_motion_keeps_the_plan(rapid_run, irb120):
    """Within the tolerances it is written under: never slower, on the planned TCP path, a real saving."""
    result, _, s = rapid_run
    assert s["executed_duration_s"] <= 1.6 * 1.02
    assert s["executed_tcp_deviation_mm"] <= 5.0
    assert s["executed_energy_optimized_J"] < s["executed_energy_default_J"]
    assert s["executed_saved_pct"] == pytest.approx(
        100 * (1 - s["executed_energy_optimized_J"] / s["executed_energy_default_J"])
    )


def test_follow_path_reproduces_a_gentle_path_at_its_times(irb120):
    """A slow minimum-jerk move written as via points is run by the emulation close to the plan."""
    from joulepath.sim import follow_path
    from joulepath.trajectory import minimum_jerk

    path = minimum_jerk(Q0, QF, 4.0)
    followed = follow_path(irb120, path)
    assert followed.executed_duration_s == pytest.approx(4.0, abs=1e-9)
    assert followed.max_joint_deviation_rad < np.radians(1.0)
    assert followed.indices[-1] == path.t.size - 1


def test_refusal_names_the_egm_export(rapid_run, irb120):
    """A module that runs slower than planned is refused, and the refusal says which export carries it."""
    result, _, _ = rapid_run
    slow = result.optimized
    execution, _ = rapid_execution(irb120, slow, result.summary.energy_optimized_fine_J)
    from dataclasses import replace

    late = replace(
        execution, executed_duration_s=1.7, executed_duration_vs_plan_pct=6.25, executed_matches_plan=False
    )
    reason = late.refusal()
    assert reason is not None and "--export egm" in reason and "+6.2 %" in reason
    assert execution.refusal() is None


def test_tracked_motion_lags_a_ramp_by_the_servos_time_constant(irb120):
    """The lab robot's servo (``w²/(s² + 2ws + w²)``, critically damped) runs a ramp ``v t`` a time
    ``2/w`` behind, once its start has died out; a plant without a tracking lag runs the command."""
    from joulepath.optimize._execute import tracked
    from joulepath.sim import make_plant
    from joulepath.trajectory import Trajectory

    lab = make_plant("lab", irb120)
    t = np.arange(0.0, 1.0 + 1e-9, 0.0025)
    v = np.linspace(0.5, 1.0, irb120.n_joints)
    ramp = Trajectory(t=t, q=t[:, None] * v, qd=np.tile(v, (t.size, 1)), qdd=np.zeros((t.size, v.size)))
    run = tracked(lab, ramp)
    late = t >= 0.5
    lag = (ramp.q[late] - run.q[late]) / v
    np.testing.assert_allclose(lag, 2.0 / (2 * np.pi * lab.tracking_hz), rtol=1e-2)
    np.testing.assert_allclose(run.qd[late], ramp.qd[late], rtol=1e-6)
    sim = make_plant("sim", irb120)
    assert sim.tracking_hz is None and tracked(sim, ramp) is ramp
