"""Rigid-body dynamics: the :class:`Robot`, two inverse-dynamics implementations, friction."""

from joulepath.dynamics._calibration import (
    TWIN_CARD_FILE,
    TWIN_FILES,
    TWIN_FRICTION_FILE,
    TWIN_ROBOT_FILE,
    TWIN_URDF_FILE,
    Calibration,
    IdentifiedFriction,
    motor_torque,
)
from joulepath.dynamics._derivatives import DynamicsDerivatives, inverse_dynamics_derivatives
from joulepath.dynamics._friction import (
    FRICTION_SUFFIX,
    NOMINAL_FRICTION,
    CoulombViscousFriction,
    ElastoPlasticFriction,
    Friction,
    FrictionSum,
    friction_derivative,
    read_friction_file,
)
from joulepath.dynamics._lagrange_euler import lagrange_euler, mass_matrix_le
from joulepath.dynamics._rnea import PinocchioRnea
from joulepath.dynamics._robot import DEFAULT_ROBOT, FALLBACK_RANGE_SETS, METHODS, Robot, load_robot

__all__ = [
    "Calibration",
    "CoulombViscousFriction",
    "DEFAULT_ROBOT",
    "DynamicsDerivatives",
    "ElastoPlasticFriction",
    "FALLBACK_RANGE_SETS",
    "FRICTION_SUFFIX",
    "Friction",
    "FrictionSum",
    "IdentifiedFriction",
    "METHODS",
    "NOMINAL_FRICTION",
    "PinocchioRnea",
    "Robot",
    "TWIN_CARD_FILE",
    "TWIN_FILES",
    "TWIN_FRICTION_FILE",
    "TWIN_ROBOT_FILE",
    "TWIN_URDF_FILE",
    "friction_derivative",
    "inverse_dynamics_derivatives",
    "lagrange_euler",
    "load_robot",
    "mass_matrix_le",
    "motor_torque",
    "read_friction_file",
]
