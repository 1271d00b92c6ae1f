import numpy as np
import pytest

from joulepath.description import chain_from_urdf, pinocchio_model, preset_path
from joulepath.errors import InvalidRobotDescription

LINK = (
    '<link name="{n}"><inertial><mass value="1"/><origin xyz="0 0 0.1"/>'
    '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
)
JOINT = (
    '<joint name="j{i}" type="{t}"><parent link="l{p}"/><child link="l{i}"/>'
    '<origin xyz="0 0 0.2"/><axis xyz="{axis}"/>'
    '<limit lower="-1" upper="1" effort="10" velocity="2"/></joint>'
)


def urdf(tmp_path, n=6, types=None, axis="0 0 1"):
    types = types or ["revolute"] * n
    body = LINK.format(n="l0") + "".join(
        LINK.format(n=f"l{i}") + JOINT.format(i=i, p=i - 1, t=types[i - 1], axis=axis)
        for i in range(1, n + 1)
    )
    path = tmp_path / "arm.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="arm">{body}</robot>')
    return path


def test_chain_from_urdf_generic_arm(tmp_path):
    chain = chain_from_urdf(urdf(tmp_path, axis="0 1 0"))
    assert chain.n_joints == 6 and chain.name == "arm"
    np.testing.assert_allclose(chain.axes, [[0, 1, 0]] * 6)
    np.testing.assert_allclose(chain.velocity, 2.0)
    np.testing.assert_allclose(chain.effort, 10.0)
    np.testing.assert_allclose(chain.tool, np.eye(4))  # last link's frame


def test_chain_from_urdf_unaligned_axis(tmp_path):
    chain = chain_from_urdf(urdf(tmp_path, axis="0 0.6 0.8"))
    np.testing.assert_allclose(chain.axes[0], [0, 0.6, 0.8])


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"n": 4}, r"has 4 movable joints \(j1, j2, j3, j4\); joulepath takes serial arms of 5 to 7"),
        ({"n": 8}, r"has 8 movable joints .*lock the extra ones"),
        ({"types": ["revolute"] * 5 + ["prismatic"]}, r"joint 'j6' is prismatic.*--lock j6=VALUE"),
        ({"types": ["revolute"] * 5 + ["floating"]}, r"joint 'j6' is floating"),
    ],
)
def test_chain_from_urdf_refuses_other_arms(tmp_path, kwargs, pattern):
    with pytest.raises(InvalidRobotDescription, match=pattern):
        chain_from_urdf(urdf(tmp_path, **kwargs))


def test_chain_from_urdf_not_urdf(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link></robot>")
    with pytest.raises(InvalidRobotDescription, match="cannot parse it as URDF"):
        chain_from_urdf(bad)
    with pytest.raises(InvalidRobotDescription, match="no such URDF file"):
        chain_from_urdf(tmp_path / "missing.urdf")


def test_pinocchio_model_tool0_frame_matches_urdf_tool0():
    import pinocchio as pin

    chain = chain_from_urdf(preset_path("irb120", fmt="urdf"))
    model = pinocchio_model(chain)
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.zeros(6))
    tool = data.oMf[model.getFrameId("tool0")]
    np.testing.assert_allclose(tool.translation, [0.374, 0, 0.630], atol=1e-12)
