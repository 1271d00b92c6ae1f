"""Dynamic identification: exact recovery, consistency under noise, physical consistency, refusals."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import joulepath
from joulepath.dynamics import NOMINAL_FRICTION, IdentifiedFriction, motor_torque
from joulepath.errors import InvalidInput
from joulepath.export import draw_moves
from joulepath.identify import (
    IdentificationData,
    IdentifyOptions,
    base_parameters,
    from_log_cholesky,
    identify,
    inertial_regressor,
    joint_side,
    min_eigenvalues,
    pseudo_inertia,
    to_log_cholesky,
    triangle_margins,
    true_parameters,
    twin_robot,
)
from joulepath.sim import ControllerConfig, LabFriction, Plant, evaluate_plan, log_times, plan_moves
from joulepath.sim._plants import NOMINAL_COULOMB, NOMINAL_VISCOUS, perturbed_robot


def _exact_data(robot, plant, n_moves, seed, *, noise=0.0, range_set="collection"):
    """A plant's exact signals (q, qd, qdd from the plan, no printing), optional torque noise."""
    rng = np.random.default_rng(seed)
    moves = draw_moves(robot, n_moves, range_set=range_set, rng=rng)
    plan = plan_moves(robot, robot.home, moves, ControllerConfig())
    t = log_times(plan.end_time, ControllerConfig(), rng=rng)
    q, qd, qdd = evaluate_plan(plan, t)
    tau = plant.drive_torque(q, qd, qdd) + noise * rng.standard_normal(q.shape)
    return IdentificationData.from_arrays(q, qd, qdd, tau, np.r_[np.diff(t), np.diff(t)[-1]])


def _relative_error(beta, truth):
    return float(np.linalg.norm(beta - truth) / np.linalg.norm(truth))


def test_base_parameters_reproduce_every_torque(irb120, rng):
    """Y phi == Y_b beta for any motion, and Pinocchio's regressor agrees with Lagrange-Euler."""
    base = base_parameters(irb120)
    q, qd, qdd = rng.normal(size=(3, 15, irb120.n_joints))
    Y = inertial_regressor(irb120, q, qd, qdd)
    phi = true_parameters(irb120)
    assert base.n < phi.size
    np.testing.assert_allclose(Y[:, :, base.independent] @ base.project(phi), Y @ phi, atol=1e-10)
    reference = irb120.inverse_dynamics(q, qd, qdd, method="lagrange-euler")
    np.testing.assert_allclose(Y @ phi, reference, atol=1e-9)
    # a change of phi that keeps beta keeps every torque: the base set is complete
    null = np.linalg.svd(base.matrix())[2][base.n :]
    moved = phi + null.T @ rng.normal(size=null.shape[0])
    np.testing.assert_allclose(Y @ moved, Y @ phi, atol=1e-9)


def test_exact_recovery_on_the_sim_plant(irb120):
    """Noise-free sim-plant data give the nominal robot's base parameters and friction exactly."""
    sim = Plant(name="sim", robot=irb120, friction=NOMINAL_FRICTION)
    data = _exact_data(irb120, sim, 12, seed=3)
    result = identify(data, irb120, IdentifyOptions(gear_efficiency=1.0))
    truth = base_parameters(irb120, armature=True).project(true_parameters(irb120, armature=True))
    assert _relative_error(result.beta_ls, truth) < 1e-9
    assert _relative_error(result.beta, truth) < 1e-6  # the consistent refinement keeps it
    np.testing.assert_allclose(result.friction.coulomb, NOMINAL_COULOMB, atol=1e-8)
    np.testing.assert_allclose(result.friction.viscous, NOMINAL_VISCOUS, atol=1e-8)
    np.testing.assert_allclose(result.friction.offset, 0.0, atol=1e-8)
    assert min(result.fit.torque_r2) > 1 - 1e-12


def test_exact_recovery_of_a_perturbed_robot_with_stribeck_friction_and_gear_losses(irb120):
    """The lab plant's model class (perturbed links, Stribeck, asymmetry, gear losses), without noise."""
    real = perturbed_robot(irb120, np.random.default_rng(7))
    friction = LabFriction(
        coulomb=1.3 * NOMINAL_COULOMB, viscous=1.2 * NOMINAL_VISCOUS, stribeck=0.4 * NOMINAL_COULOMB
    )
    plant = Plant(name="lab-exact", robot=real, friction=friction, gear_efficiency=0.85)
    data = _exact_data(irb120, plant, 16, seed=4)
    # exact speeds: no sensor noise to read as rest (rest_speed 0: the plant's own side of the gears)
    options = IdentifyOptions(stribeck_speed=friction.stribeck_speed, rest_speed=0.0)
    result = identify(data, irb120, options)
    truth = base_parameters(irb120, armature=True).project(true_parameters(real, armature=True))
    assert abs(result.gear_efficiency - 0.85) < 1e-4
    assert _relative_error(result.beta_ls, truth) < 1e-3
    np.testing.assert_allclose(result.friction.coulomb, friction.coulomb, rtol=1e-3, atol=1e-4)
    np.testing.assert_allclose(result.friction.offset, friction.asymmetry * friction.coulomb, atol=1e-3)
    np.testing.assert_allclose(result.friction.stribeck, friction.stribeck, rtol=1e-2, atol=1e-3)


def test_error_shrinks_with_more_noisy_data(irb120):
    """Consistency: with torque noise, 4x the moves gives clearly smaller base-parameter errors."""
    sim = Plant(name="sim", robot=irb120, friction=NOMINAL_FRICTION)
    truth = base_parameters(irb120, armature=True).project(true_parameters(irb120, armature=True))
    options = IdentifyOptions(gear_efficiency=1.0, consistent=False)
    errors = {}
    for n in (8, 32):
        errs = [
            _relative_error(
                identify(_exact_data(irb120, sim, n, seed=s, noise=0.3), irb120, options).beta_ls, truth
            )
            for s in (11, 12)
        ]
        errors[n] = float(np.mean(errs))
    assert errors[32] < 0.7 * errors[8]
    assert errors[32] < 0.05


def test_log_cholesky_maps_onto_consistent_parameters(rng, irb120):
    phi = true_parameters(irb120).reshape(-1, 10)
    for link in phi:
        np.testing.assert_allclose(from_log_cholesky(to_log_cholesky(link)), link, rtol=1e-9, atol=1e-12)
    for _ in range(50):
        p = from_log_cholesky(rng.normal(scale=1.5, size=10))
        assert np.linalg.eigvalsh(pseudo_inertia(p))[0] > 0
        assert triangle_margins(p)[0] > -1e-9 * max(1.0, abs(p[4:]).max())


def test_identified_parameters_are_physically_consistent(irb120):
    """Few, noisy samples of a heavily perturbed robot: the twin's links still pass every check."""
    real = perturbed_robot(irb120, np.random.default_rng(9))
    plant = Plant(name="noisy", robot=real, friction=NOMINAL_FRICTION)
    data = _exact_data(irb120, plant, 6, seed=5, noise=0.5)
    result = identify(data, irb120, IdentifyOptions(gear_efficiency=1.0))
    assert np.all(min_eigenvalues(result.phi) > 0)
    assert np.all(triangle_margins(result.phi) > 0)
    assert result.consistent
    twin = twin_robot(irb120, result)
    assert not [f for f in twin.check_physical() if f.severity == "error"]
    # the written description reproduces the identified model: IRML robot == parameter vector
    q, qd, qdd = data.q[::40], data.qd[::40], data.qdd[::40]
    np.testing.assert_allclose(
        twin.inverse_dynamics(q, qd, qdd, friction=twin.friction),
        result.joint_torque(irb120, q, qd, qdd),
        atol=1e-9,
    )


def test_gear_loss_inversion_round_trips(rng):
    tau, qd = rng.normal(size=(2, 100, 6))
    for eta in (1.0, 0.9, 0.6):
        np.testing.assert_allclose(joint_side(motor_torque(tau, qd, eta), qd, eta), tau)


def test_identified_friction_derivative_matches_finite_differences(rng):
    f = IdentifiedFriction(
        coulomb=(1.0, 0.5), viscous=(0.3, 0.1), offset=(0.1, -0.05), stribeck=(0.4, 0.2), stribeck_speed=0.05
    )
    qd = rng.normal(scale=0.2, size=(50, 2))
    h = 1e-7
    np.testing.assert_allclose(
        f.derivative(qd), (f.torque(qd + h) - f.torque(qd - h)) / (2 * h), rtol=1e-5, atol=1e-4
    )


def test_a_joint_that_never_moves_is_refused(irb120):
    sim = Plant(name="sim", robot=irb120, friction=NOMINAL_FRICTION)
    data = _exact_data(irb120, sim, 6, seed=6)
    frozen = replace(data, qd=data.qd * np.array([1, 1, 1, 0, 1, 1]))
    with pytest.raises(InvalidInput, match=r"joint\(s\) 4 never move"):
        identify(frozen, irb120)


def test_badly_conditioned_data_is_refused_naming_a_parameter(irb120):
    sim = Plant(name="sim", robot=irb120, friction=NOMINAL_FRICTION)
    data = _exact_data(irb120, sim, 3, seed=8)
    with pytest.raises(InvalidInput, match=r"condition number .* least excited: \S+"):
        identify(data, irb120, IdentifyOptions(gear_efficiency=1.0, max_condition=5.0, unexcited="refuse"))
    # keeping parameters at their priors has a bound: more than MAX_KEPT_SHARE of them is refused
    with pytest.raises(InvalidInput, match=r"kept at their priors, at most 25 %.* least excited"):
        identify(data, irb120, IdentifyOptions(gear_efficiency=1.0, max_condition=1.01))


def test_too_few_samples_and_bad_arrays_are_refused(irb120):
    sim = Plant(name="sim", robot=irb120, friction=NOMINAL_FRICTION)
    data = _exact_data(irb120, sim, 3, seed=8)
    with pytest.raises(InvalidInput, match="torque equations"):
        identify(data.subset(np.arange(data.n_samples) < 10), irb120)
    with pytest.raises(InvalidInput, match="finite"):
        IdentificationData.from_arrays(data.q * np.nan, data.qd, data.qdd, data.tau, 0.025)
    with pytest.raises(InvalidInput, match="shape"):
        IdentificationData.from_arrays(data.q[:, :5], data.qd, data.qdd, data.tau, 0.025)


def test_load_robot_refuses_a_folder_that_is_not_a_twin(tmp_path):
    with pytest.raises(joulepath.errors.InvalidRobotDescription, match="not a twin"):
        joulepath.load_robot(tmp_path)


def test_generic_log_with_accelerations_recovers_the_sim_plant_exactly(irb120, tmp_path):
    """The file route: a generic CSV (rad, with ddq columns) read by data_from_logs."""
    from joulepath.identify import data_from_logs

    sim = Plant(name="sim", robot=irb120, friction=NOMINAL_FRICTION)
    d = _exact_data(irb120, sim, 10, seed=21)
    t = np.cumsum(np.r_[0.0, d.dt[:-1]])
    cols = {"t": t}
    for i in range(6):
        for name, arr in (("q", d.q), ("dq", d.qd), ("ddq", d.qdd), ("tau", d.tau)):
            cols[f"{name}{i + 1}"] = arr[:, i]
    header = ",".join(cols)
    rows = np.column_stack(list(cols.values()))
    path = tmp_path / "generic.csv"
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    data = data_from_logs([path], irb120)
    assert data.n_samples == d.n_samples and len(data.data_hash) == 64
    result = identify(data, irb120, IdentifyOptions(gear_efficiency=1.0))
    truth = base_parameters(irb120, armature=True).project(true_parameters(irb120, armature=True))
    assert _relative_error(result.beta_ls, truth) < 1e-9


def test_viscous_level_per_direction_is_recovered_and_round_trips(irb120, tmp_path):
    """A plant whose viscous slope differs by direction (viscous_offset): identified exactly with the
    option, missed without it; the friction file keeps it, and a file without it reads as 0."""
    import json

    from joulepath.dynamics import Calibration
    from joulepath.dynamics._calibration import read_calibration

    n = irb120.n_joints
    zero = (0.0,) * n
    friction = IdentifiedFriction(
        coulomb=tuple(NOMINAL_COULOMB),
        viscous=tuple(NOMINAL_VISCOUS),
        offset=zero,
        stribeck=zero,
        viscous_offset=tuple(0.4 * np.asarray(NOMINAL_VISCOUS)),
    )
    plant = Plant(name="viscous-by-direction", robot=irb120, friction=friction)
    data = _exact_data(irb120, plant, 12, seed=5)
    with_it = identify(data, irb120, IdentifyOptions(gear_efficiency=1.0, viscous_offset=True))
    np.testing.assert_allclose(with_it.friction.viscous, NOMINAL_VISCOUS, atol=1e-6)
    np.testing.assert_allclose(with_it.friction.viscous_offset, friction.viscous_offset, atol=1e-6)
    assert min(with_it.fit.torque_r2) > 1 - 1e-9
    without = identify(data, irb120, IdentifyOptions(gear_efficiency=1.0, consistent=False))
    assert min(without.fit.torque_r2) < 1 - 1e-6 and without.friction.viscous_offset == ()
    # derivative of the new term, and the friction file both ways
    qd = np.random.default_rng(0).normal(scale=0.2, size=(40, n))
    h = 1e-7
    np.testing.assert_allclose(
        friction.derivative(qd),
        (friction.torque(qd + h) - friction.torque(qd - h)) / (2 * h),
        rtol=1e-5,
        atol=1e-4,
    )
    path = tmp_path / "friction.json"
    path.write_text(json.dumps(Calibration(friction=with_it.friction).to_json()))
    back = read_calibration(path, n).friction
    np.testing.assert_allclose(back.torque(qd), with_it.friction.torque(qd), rtol=1e-12)
    doc = json.loads(path.read_text())
    del doc["friction"]["viscous_offset"]
    path.write_text(json.dumps(doc))
    old = read_calibration(path, n).friction
    assert old.viscous_offset == ()
    np.testing.assert_allclose(
        old.torque(qd) - back.torque(qd), -np.asarray(back.viscous_offset) * qd * np.tanh(qd / old.smoothing)
    )
