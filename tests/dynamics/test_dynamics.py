"""Inverse dynamics: two independent implementations, and physical invariants."""

import numpy as np
import pytest

import joulepath
from joulepath.dynamics import lagrange_euler
from joulepath.errors import InvalidInput
from joulepath.trajectory import minimum_jerk


def _random_state(rng, n=200):
    q = rng.uniform(-np.pi, np.pi, size=(n, 6))
    qd = rng.uniform(-4, 4, size=(n, 6))
    qdd = rng.uniform(-20, 20, size=(n, 6))
    return q, qd, qdd


@pytest.mark.parametrize("robot_fixture", ["irb120", "irb120_urdf"])
def test_rnea_and_lagrange_euler_agree(robot_fixture, request, rng):
    robot = request.getfixturevalue(robot_fixture)
    q, qd, qdd = _random_state(rng)
    rnea = robot.inverse_dynamics(q, qd, qdd)
    le = robot.inverse_dynamics(q, qd, qdd, method="lagrange-euler")
    scale = np.abs(rnea).max(axis=1, keepdims=True)
    assert np.all(np.abs(rnea - le) <= 1e-8 * scale)


def test_lagrange_euler_agrees_on_generic_urdf_arm(tmp_path, rng):
    """An arm with unaligned axes and off-axis masses, nothing like a DH robot."""
    links, joints = [], []
    axes = rng.normal(size=(6, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    for i in range(7):
        a = rng.uniform(0.01, 0.05, size=3)
        ixx, iyy, izz = a[1] + a[2], a[0] + a[2], a[0] + a[1]
        com = " ".join(f"{v:.4f}" for v in rng.uniform(-0.1, 0.1, 3))
        links.append(
            f'<link name="l{i}"><inertial><mass value="{rng.uniform(0.5, 3):.3f}"/>'
            f'<origin xyz="{com}" rpy="0.1 0.2 0.3"/><inertia ixx="{ixx}" ixy="0.001" ixz="0" '
            f'iyy="{iyy}" iyz="0.002" izz="{izz}"/></inertial></link>'
        )
    for i in range(1, 7):
        xyz = " ".join(f"{v:.3f}" for v in rng.uniform(-0.3, 0.3, 3))
        ax = " ".join(f"{v:.6f}" for v in axes[i - 1])
        joints.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="{xyz}" rpy="0.3 -0.2 0.5"/><axis xyz="{ax}"/>'
            '<limit lower="-3" upper="3" effort="100" velocity="3"/></joint>'
        )
    path = tmp_path / "weird.urdf"
    path.write_text(f'<robot name="weird">{"".join(links + joints)}</robot>')
    robot = joulepath.load_robot(path)
    q, qd, qdd = _random_state(rng, 50)
    rnea = robot.inverse_dynamics(q, qd, qdd)
    le = lagrange_euler(robot.chain, q, qd, qdd)
    np.testing.assert_allclose(le, rnea, rtol=0, atol=1e-8 * np.abs(rnea).max())


def test_irml_and_urdf_robots_give_same_torques(irb120, irb120_urdf, rng):
    q, qd, qdd = _random_state(rng)
    np.testing.assert_allclose(
        irb120.inverse_dynamics(q, qd, qdd), irb120_urdf.inverse_dynamics(q, qd, qdd), atol=1e-10
    )


def test_mass_matrix_matches_pinocchio_crba(irb120, rng):
    import pinocchio as pin

    model = irb120.pinocchio_model
    data = model.createData()
    for q in rng.uniform(-3, 3, size=(10, 6)):
        ref = pin.crba(model, data, q)
        ref = np.triu(ref) + np.triu(ref, 1).T
        np.testing.assert_allclose(irb120.mass_matrix(q), ref, atol=1e-12)
        assert np.all(np.linalg.eigvalsh(ref) > 0)


def test_static_gravity_torques_at_rest_give_zero_power(irb120, rng):
    q = rng.uniform(-2, 2, size=(30, 6))
    tau = irb120.gravity_torque(q)
    assert np.abs(tau[:, 1]).max() > 1.0  # the shoulder holds the arm up
    energy = joulepath.energy.joint_energy(tau, np.zeros_like(q), 0.025)
    assert np.all(energy == 0.0)


def test_gravity_torque_joint1_is_zero(irb120, rng):
    """Gravity is along joint 1's axis: it never loads joint 1."""
    tau = irb120.gravity_torque(rng.uniform(-2, 2, size=(30, 6)))
    np.testing.assert_allclose(tau[:, 0], 0.0, atol=1e-12)


def test_power_balance_along_a_path(irb120):
    """sum(tau * qd) = d/dt (kinetic + potential energy), friction off."""
    move = minimum_jerk(np.zeros(6), np.array([1.0, 0.5, -0.7, 1.2, 0.8, -1.0]), 1.0, dt=0.001)
    q, qd, qdd = move.q, move.qd, move.qdd
    power = np.sum(irb120.inverse_dynamics(q, qd, qdd) * qd, axis=1)
    mass = irb120.mass_matrix(q)
    kinetic = 0.5 * np.einsum("ni,nij,nj->n", qd, mass, qd)
    frames = irb120.chain
    from joulepath.kinematics import link_frames

    f = link_frames(frames, q)
    coms = f[..., :3, 3] + np.einsum("niab,ib->nia", f[..., :3, :3], frames.coms)
    potential = -np.einsum("nia,i,a->n", coms, frames.masses, frames.gravity)
    dE = np.gradient(kinetic + potential, move.t)
    np.testing.assert_allclose(power[2:-2], dE[2:-2], atol=2e-3 * np.abs(power).max())


def test_payload_adds_to_shoulder_holding_torque(irb120):
    loaded = irb120.with_payload(3.0, com=(0.0, 0.0, 0.1))
    q = np.zeros(6)
    tau0, tau1 = irb120.gravity_torque(q), loaded.gravity_torque(q)
    # 3 kg, 0.1 m beyond tool0 along tool0's z (= base +x at home): x = 0.474 m from joint 2.
    # Gravity's moment about joint 2's +y axis is +m g x (it tips the arm forward, the
    # positive direction), so the drive holds it with -m g x.
    np.testing.assert_allclose(tau1[1] - tau0[1], -3.0 * 9.80665 * 0.474, rtol=1e-9)
    np.testing.assert_allclose(tau1[[0, 3, 5]], tau0[[0, 3, 5]], atol=1e-12)
    assert loaded.payload is not None and irb120.payload is None


def test_payload_matches_pinocchio_composition(irb120_urdf, rng):
    import pinocchio as pin

    loaded = irb120_urdf.with_payload(2.0, com=(0.01, 0.02, 0.05), inertia=(0.01, 0.02, 0.015))
    model = irb120_urdf.pinocchio_model.copy()
    tool = model.frames[model.getFrameId("tool0")].placement
    load = pin.Inertia(2.0, np.array([0.01, 0.02, 0.05]), np.diag([0.01, 0.02, 0.015]))
    model.inertias[6] = model.inertias[6] + tool.act(load)
    data = model.createData()
    q, qd, qdd = _random_state(rng, 10)
    ours = loaded.inverse_dynamics(q, qd, qdd)
    for k in range(10):
        np.testing.assert_allclose(ours[k], pin.rnea(model, data, q[k], qd[k], qdd[k]), atol=1e-10)


def test_inverse_dynamics_broadcasts_and_keeps_shape(irb120, rng):
    q = rng.uniform(-1, 1, size=(2, 3, 6))
    tau = irb120.inverse_dynamics(q, np.zeros(6), np.zeros(6))
    assert tau.shape == (2, 3, 6)
    np.testing.assert_allclose(tau[1, 2], irb120.inverse_dynamics(q[1, 2], np.zeros(6), np.zeros(6)))


def test_inverse_dynamics_errors(irb120):
    with pytest.raises(InvalidInput, match=r"qd has shape \(5,\)"):
        irb120.inverse_dynamics(np.zeros(6), np.zeros(5), np.zeros(6))
    with pytest.raises(InvalidInput, match="do not broadcast"):
        irb120.inverse_dynamics(np.zeros((2, 6)), np.zeros((3, 6)), np.zeros(6))
    with pytest.raises(InvalidInput, match="method must be one of"):
        irb120.inverse_dynamics(np.zeros(6), np.zeros(6), np.zeros(6), method="euler")


def test_load_robot_errors(tmp_path):
    with pytest.raises(joulepath.InvalidRobotDescription, match="not a bundled robot"):
        joulepath.load_robot("irb999")
    other = tmp_path / "robot.sdf"
    other.write_text("<sdf/>")
    with pytest.raises(joulepath.InvalidRobotDescription, match="unknown robot file type '.sdf'"):
        joulepath.load_robot(other)


def test_joint_ranges(irb120):
    lo, hi = irb120.joint_ranges("lab")
    np.testing.assert_allclose(np.degrees(hi), [90, 45, 40, 160, 120, 400])
    lo, hi = irb120.joint_ranges()
    np.testing.assert_allclose(np.degrees(lo), [-165, -110, -110, -160, -120, -400])
    assert irb120.range_set_names == ("nominal", "lab", "collection")
    np.testing.assert_allclose(np.degrees(irb120.velocity_limit), [250, 250, 250, 320, 320, 420])
