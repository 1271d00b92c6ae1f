"""Batch shapes of fk and inverse_dynamics, and IRML round trips, for arbitrary inputs."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import joulepath
from joulepath.description import (
    Inertial,
    JointDescription,
    RobotDescription,
    irml_string,
    parse_irml,
)

ROBOT = joulepath.load_robot("irb120")
batch_shapes = hnp.array_shapes(min_dims=0, max_dims=3, min_side=1, max_side=4)
angles = st.floats(-7.0, 7.0, allow_nan=False)


@given(shape=batch_shapes, data=st.data())
def test_fk_keeps_any_batch_shape(shape, data):
    q = data.draw(hnp.arrays(np.float64, shape + (6,), elements=angles))
    pose = ROBOT.fk(q)
    assert pose.position_m.shape == shape + (3,)
    assert pose.quaternion.shape == shape + (4,)
    np.testing.assert_allclose(np.linalg.norm(pose.quaternion, axis=-1), 1.0)
    assert ROBOT.jacobian(q).shape == shape + (6, 6)


@given(shape=batch_shapes, data=st.data())
def test_inverse_dynamics_keeps_any_batch_shape(shape, data):
    arrays = [data.draw(hnp.arrays(np.float64, shape + (6,), elements=angles)) for _ in range(3)]
    tau = ROBOT.inverse_dynamics(*arrays)
    assert tau.shape == shape + (6,)
    flat = ROBOT.inverse_dynamics(*(a.reshape(-1, 6) for a in arrays))
    np.testing.assert_allclose(tau.reshape(-1, 6), flat)


finite = st.floats(-10.0, 10.0, allow_nan=False, allow_subnormal=False)


@st.composite
def descriptions(draw):
    n = draw(st.integers(1, 7))
    joints = []
    for i in range(n):
        com = tuple(draw(finite) for _ in range(3))
        inertia = tuple(tuple(draw(finite) for _ in range(3)) for _ in range(3))
        lower = draw(st.one_of(st.none(), finite))
        joints.append(
            JointDescription(
                id=i + 1,
                type=draw(st.sampled_from("TR")),
                xi=1,
                variable=f"q{i + 1}",
                sign=draw(st.sampled_from([1.0, -1.0])),
                offset=draw(finite),
                d=draw(finite),
                r=draw(finite),
                alpha=draw(finite),
                inertial=Inertial(mass=draw(finite), com=com, inertia=inertia),
                lower=lower,
                velocity=draw(st.one_of(st.none(), finite)),
            )
        )
    info = tuple(
        (f"k{i}", draw(st.text("abc xyz-0123", max_size=8)).strip()) for i in range(draw(st.integers(0, 3)))
    )
    return RobotDescription(name="R", manufacturer="M", info=info, joints=tuple(joints))


@given(descriptions())
def test_irml_write_read_round_trip(desc):
    assert parse_irml(irml_string(desc)) == desc
