"""The armature (the drives' reflected rotor inertia): dynamics, regressor, recovery, twin, unexcited."""

from __future__ import annotations

import json
import warnings
from dataclasses import replace

import numpy as np
import pytest

import joulepath
from joulepath.dynamics import NOMINAL_FRICTION, TWIN_FRICTION_FILE
from joulepath.errors import InvalidRobotDescription
from joulepath.identify import (
    IdentificationData,
    IdentifyOptions,
    UnexcitedParameterWarning,
    armature_regressor,
    base_parameters,
    dynamic_regressor,
    identify,
    true_parameters,
    write_twin,
)

ARMATURE = np.array([0.9, 1.4, 0.6, 0.08, 0.05, 0.03])
"""kg·m²: of the order of the IRB 120's own link inertias about its joints (rotor inertia x ratio²)."""


def _with_armature(robot: joulepath.Robot, armature: np.ndarray) -> joulepath.Robot:
    return joulepath.Robot(replace(robot.chain, armature=armature), source=robot.source)


def _sine_motion(n: int, t: np.ndarray, *, ramp: int | None = None):
    """Sums of sines per joint (distinct frequencies); joint ``ramp`` turns at piecewise constant
    speeds instead (four levels, both directions; its acceleration is 0 throughout)."""
    freq = 0.3 + 0.17 * np.arange(n)
    amp = 0.6 / (1 + 0.2 * np.arange(n))
    w = 2 * np.pi * freq
    q = amp * (np.sin(w * t[:, None]) + 0.5 * np.sin(2.3 * w * t[:, None] + 1.0))
    qd = amp * w * (np.cos(w * t[:, None]) + 1.15 * np.cos(2.3 * w * t[:, None] + 1.0))
    qdd = -amp * w**2 * (np.sin(w * t[:, None]) + 2.645 * np.sin(2.3 * w * t[:, None] + 1.0))
    if ramp is not None:
        levels = np.array([0.2, 0.5, -0.3, -0.6])
        speed = levels[(t // 1.5).astype(int) % 4]
        q[:, ramp] = np.concatenate([[0.0], np.cumsum(speed[:-1] * np.diff(t))])
        qd[:, ramp], qdd[:, ramp] = speed, 0.0
    return q, qd, qdd


def test_dynamics_carry_the_armature_in_every_implementation(irb120, rng):
    """RNEA (Pinocchio) and Lagrange-Euler agree with armature; it adds exactly armature * qdd."""
    robot = _with_armature(irb120, ARMATURE)
    q, qd, qdd = rng.normal(size=(3, 12, 6))
    rigid = irb120.inverse_dynamics(q, qd, qdd)
    rnea = robot.inverse_dynamics(q, qd, qdd)
    le = robot.inverse_dynamics(q, qd, qdd, method="lagrange-euler")
    np.testing.assert_allclose(rnea, le, atol=1e-9)
    np.testing.assert_allclose(rnea - rigid, ARMATURE * qdd, atol=1e-9)
    # the mass matrix (Lagrange-Euler) against Pinocchio's CRBA of the model with the armature
    import pinocchio as pin

    model = robot.pinocchio_model
    data = model.createData()
    crba = pin.crba(model, data, q[0])
    crba = np.triu(crba) + np.triu(crba, 1).T
    np.testing.assert_allclose(robot.mass_matrix(q[0]), crba, atol=1e-9)
    np.testing.assert_allclose(np.diag(robot.mass_matrix(q[0]) - irb120.mass_matrix(q[0])), ARMATURE)


def test_payload_keeps_the_armature(irb120, rng):
    robot = _with_armature(irb120, ARMATURE).with_payload(1.0, (0.0, 0.0, 0.05))
    np.testing.assert_array_equal(robot.chain.armature, ARMATURE)


def test_regressor_times_parameters_is_the_inverse_dynamics_with_armature(irb120, rng):
    """[Y | diag(qdd)] [phi, armature] == RNEA with armature, and the base set reproduces it."""
    robot = _with_armature(irb120, ARMATURE)
    q, qd, qdd = rng.normal(size=(3, 15, 6))
    Y = dynamic_regressor(robot, q, qd, qdd, armature=True)
    x = true_parameters(robot, armature=True)
    assert Y.shape == (15, 6, 66) and x.size == 66
    np.testing.assert_allclose(x[60:], ARMATURE)
    np.testing.assert_allclose(Y @ x, robot.inverse_dynamics(q, qd, qdd), atol=1e-9)
    np.testing.assert_allclose(Y @ x, robot.inverse_dynamics(q, qd, qdd, method="lagrange-euler"), atol=1e-9)
    base = base_parameters(robot, armature=True)
    rigid = base_parameters(robot)
    np.testing.assert_allclose(Y[:, :, base.independent] @ base.project(x), Y @ x, atol=1e-9)
    # joint 1 turns about a fixed axis, and joint 2's axis is at right angles to it: link 1's and
    # link 2's inertia about their own axes act exactly as those joints' armatures (regrouped with
    # them); every other joint's armature is a base parameter of its own
    assert base.n == rigid.n + 4
    assert sorted(name for name in base.names if name.endswith("armature")) == [
        f"joint{j}.armature" for j in range(3, 7)
    ]
    np.testing.assert_array_equal(armature_regressor(qdd)[:, 2, 2], qdd[:, 2])


def test_identify_recovers_a_known_armature(irb120):
    """Exact signals of a perturbed plant with an armature: armatures and base parameters recovered."""
    from joulepath.sim import Plant
    from joulepath.sim._plants import perturbed_robot

    real = _with_armature(perturbed_robot(irb120, np.random.default_rng(5)), ARMATURE)
    plant = Plant(name="armature", robot=real, friction=NOMINAL_FRICTION)
    t = np.arange(0.0, 30.0, 0.01)
    q, qd, qdd = _sine_motion(6, t)
    data = IdentificationData.from_arrays(q, qd, qdd, plant.drive_torque(q, qd, qdd), 0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnexcitedParameterWarning)
        result = identify(data, irb120, IdentifyOptions(gear_efficiency=1.0, rest_speed=0.0))
    base = base_parameters(irb120, armature=True)
    truth = base.project(true_parameters(real, armature=True))
    assert np.linalg.norm(result.beta_ls - truth) / np.linalg.norm(truth) < 1e-8
    np.testing.assert_allclose(result.armature[2:], ARMATURE[2:], rtol=1e-4)
    assert result.consistent and np.all(result.armature >= 0)
    # without the armature term the same data are fitted worse: the term is not a free pass
    rigid = identify(data, irb120, IdentifyOptions(gear_efficiency=1.0, rest_speed=0.0, armature=False))
    assert rigid.armature is None
    assert min(result.fit.torque_r2) > 1 - 1e-9 > min(rigid.fit.torque_r2)


def test_unexcited_armature_keeps_its_prior_with_a_warning(irb120):
    """A joint that never accelerates (constant speed) leaves its armature unexcited: the prior stays."""
    prior = np.full(6, 0.02)
    nominal = _with_armature(irb120, prior)
    real = _with_armature(irb120, ARMATURE)
    t = np.arange(0.0, 30.0, 0.01)
    q, qd, qdd = _sine_motion(6, t, ramp=5)
    tau = real.inverse_dynamics(q, qd, qdd, friction=NOMINAL_FRICTION)
    data = IdentificationData.from_arrays(q, qd, qdd, tau, 0.01)
    with pytest.warns(UnexcitedParameterWarning, match=r"joint6\.armature"):
        result = identify(data, nominal, IdentifyOptions(gear_efficiency=1.0, rest_speed=0.0))
    assert "joint6.armature" in [k.name for k in result.kept]
    assert result.armature[5] == pytest.approx(0.02, rel=1e-6)
    np.testing.assert_allclose(result.armature[2:5], ARMATURE[2:5], rtol=1e-3)


def test_twin_writes_and_loads_the_armature(irb120, tmp_path, rng):
    """The twin folder holds the armature; the loaded twin's dynamics use it (== the identification)."""
    real = _with_armature(irb120, ARMATURE)
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = _sine_motion(6, t)
    tau = real.inverse_dynamics(q, qd, qdd, friction=NOMINAL_FRICTION)
    result = identify(IdentificationData.from_arrays(q, qd, qdd, tau, 0.01), irb120, IdentifyOptions())
    write_twin(result, irb120, tmp_path / "twin")
    twin = joulepath.load_robot(tmp_path / "twin")
    np.testing.assert_allclose(twin.chain.armature, result.armature)
    qs, qds, qdds = rng.normal(size=(3, 8, 6))
    np.testing.assert_allclose(
        twin.inverse_dynamics(qs, qds, qdds, friction=twin.friction),
        result.joint_torque(irb120, qs, qds, qdds),
        atol=1e-6,
    )
    card = json.loads((tmp_path / "twin" / "card.json").read_text())
    assert [row["armature"]["status"] for row in card["parameters"]] == ["identified in a sum"] * 2 + [
        "identified"
    ] * 4
    # a negative armature in the friction file is refused on load
    path = tmp_path / "twin" / TWIN_FRICTION_FILE
    data = json.loads(path.read_text())
    data["armature"][2] = -0.1
    path.write_text(json.dumps(data))
    with pytest.raises(InvalidRobotDescription, match="armature of joint 3"):
        joulepath.load_robot(tmp_path / "twin")
