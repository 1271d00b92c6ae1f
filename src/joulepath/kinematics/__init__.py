"""Kinematics of a serial chain: tool pose (ABB units and conventions) and Jacobian."""

from joulepath.kinematics._fk import (
    Pose,
    check_q,
    forward_kinematics,
    geometric_jacobian,
    link_frames,
    position_and_jacobian,
)
from joulepath.kinematics._ik import check_layout, confdata, ik_branches, solve_ik, solve_ik_along
from joulepath.kinematics._rotations import (
    axis_angle_matrix,
    euler_zyx_to_rotation,
    quaternion_to_rotation,
    rotation_to_euler_zyx,
    rotation_to_quaternion,
)

__all__ = [
    "Pose",
    "axis_angle_matrix",
    "check_layout",
    "check_q",
    "confdata",
    "euler_zyx_to_rotation",
    "forward_kinematics",
    "geometric_jacobian",
    "ik_branches",
    "link_frames",
    "position_and_jacobian",
    "quaternion_to_rotation",
    "rotation_to_euler_zyx",
    "rotation_to_quaternion",
    "solve_ik",
    "solve_ik_along",
]
