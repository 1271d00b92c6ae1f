import numpy as np
import pytest

from joulepath.errors import InvalidInput
from joulepath.kinematics import (
    euler_zyx_to_rotation,
    quaternion_to_rotation,
    rotation_to_euler_zyx,
    rotation_to_quaternion,
)
from joulepath.units import DEG


def test_fk_home_pose_is_abb_home(irb120):
    pose = irb120.fk(np.zeros(6))
    np.testing.assert_allclose(pose.position_mm, [374.0, 0.0, 630.0], atol=1e-9)
    np.testing.assert_allclose(pose.position_m, [0.374, 0.0, 0.630], atol=1e-12)
    np.testing.assert_allclose(pose.quaternion, [np.sqrt(0.5), 0, np.sqrt(0.5), 0], atol=1e-12)
    np.testing.assert_allclose(pose.euler_zyx_deg, [0, 90, 0], atol=1e-9)


def test_fk_upper_arm_vertical_at_zero(irb120):
    """Turning joint 2 by +90 deg lays the upper arm forward: the wrist drops by 0.27 m."""
    q = np.array([0, 90, 0, 0, 0, 0]) * DEG
    p = irb120.fk(q).position_m
    # elbow now at (0.27, 0, 0.29); forearm points down: tool0 at x = 0.27 + 0.07, z = 0.29 - 0.374
    np.testing.assert_allclose(p, [0.34, 0.0, 0.29 - 0.374], atol=1e-12)


def test_fk_matches_pinocchio_frame_placement(irb120, rng):
    import pinocchio as pin

    model = irb120.pinocchio_model
    data = model.createData()
    fid = model.getFrameId("tool0")
    for q in rng.uniform(-3, 3, size=(20, 6)):
        pin.framesForwardKinematics(model, data, q)
        pose = irb120.fk(q)
        np.testing.assert_allclose(pose.position_m, data.oMf[fid].translation, atol=1e-12)
        np.testing.assert_allclose(pose.rotation, data.oMf[fid].rotation, atol=1e-12)


@pytest.mark.parametrize("shape", [(6,), (4, 6), (2, 3, 6)])
def test_fk_batch_shapes(irb120, rng, shape):
    q = rng.uniform(-2, 2, size=shape)
    pose = irb120.fk(q)
    assert pose.position_m.shape == shape[:-1] + (3,)
    assert pose.rotation.shape == shape[:-1] + (3, 3)
    assert pose.quaternion.shape == shape[:-1] + (4,)
    assert pose.euler_zyx_deg.shape == shape[:-1] + (3,)
    flat = irb120.fk(q.reshape(-1, 6)).position_m.reshape(shape[:-1] + (3,))
    np.testing.assert_array_equal(flat, pose.position_m)


def test_fk_rejects_wrong_shape(irb120):
    with pytest.raises(InvalidInput, match=r"q has shape \(5,\), but the robot has 6 joints"):
        irb120.fk(np.zeros(5))
    with pytest.raises(InvalidInput, match="NaN"):
        irb120.fk([0, 0, np.nan, 0, 0, 0])


def test_quaternion_and_euler_round_trips(rng):
    quat = rng.normal(size=(200, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    quat *= np.sign(quat[:, :1])
    rot = quaternion_to_rotation(quat)
    np.testing.assert_allclose(rotation_to_quaternion(rot), quat, atol=1e-12)
    angles = rotation_to_euler_zyx(rot)
    np.testing.assert_allclose(euler_zyx_to_rotation(angles), rot, atol=1e-12)
    assert np.all(np.abs(angles[:, 1]) <= np.pi / 2 + 1e-12)


def test_euler_zyx_is_rz_ry_rx():
    z, y, x = 0.3, -0.2, 1.1
    c, s = np.cos, np.sin
    rz = np.array([[c(z), -s(z), 0], [s(z), c(z), 0], [0, 0, 1]])
    ry = np.array([[c(y), 0, s(y)], [0, 1, 0], [-s(y), 0, c(y)]])
    rx = np.array([[1, 0, 0], [0, c(x), -s(x)], [0, s(x), c(x)]])
    np.testing.assert_allclose(rotation_to_euler_zyx(rz @ ry @ rx), [z, y, x], atol=1e-14)


def test_jacobian_matches_finite_differences(irb120, rng):
    q = rng.uniform(-2, 2, size=6)
    jac = irb120.jacobian(q)
    h = 1e-6
    for i in range(6):
        dq = np.zeros(6)
        dq[i] = h
        plus, minus = irb120.fk(q + dq), irb120.fk(q - dq)
        np.testing.assert_allclose(jac[:3, i], (plus.position_m - minus.position_m) / (2 * h), atol=1e-8)
        drot = (plus.rotation - minus.rotation) / (2 * h) @ irb120.fk(q).rotation.T
        omega = np.array([drot[2, 1], drot[0, 2], drot[1, 0]])
        np.testing.assert_allclose(jac[3:, i], omega, atol=1e-8)


def test_jacobian_matches_pinocchio(irb120, rng):
    import pinocchio as pin

    model = irb120.pinocchio_model
    data = model.createData()
    fid = model.getFrameId("tool0")
    q = rng.uniform(-2, 2, size=(3, 6))
    ours = irb120.jacobian(q)
    for k in range(3):
        ref = pin.computeFrameJacobian(model, data, q[k], fid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(ours[k], ref, atol=1e-12)


def test_position_and_jacobian_match_the_pose_and_pinocchio(irb120, rng):
    """One pass over the chain gives the tool position of the forward kinematics and Pinocchio's
    Jacobian, for a batch (the corridor rows of the gradient search take both at once)."""
    import pinocchio as pin

    from joulepath.kinematics import forward_kinematics, position_and_jacobian

    q = rng.uniform(-2, 2, size=(4, 6))
    position, jac = position_and_jacobian(irb120.chain, q)
    np.testing.assert_allclose(position, forward_kinematics(irb120.chain, q).position_m, atol=1e-15)
    model = irb120.pinocchio_model
    data = model.createData()
    fid = model.getFrameId("tool0")
    for k in range(4):
        ref = pin.computeFrameJacobian(model, data, q[k], fid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(jac[k], ref, atol=1e-12)
