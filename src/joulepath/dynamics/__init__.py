"""Rigid-body dynamics: the :class:`Robot`, two inverse-dynamics implementations, friction."""

from joulepath.dynamics._friction import (
    NOMINAL_FRICTION,
    CoulombViscousFriction,
    ElastoPlasticFriction,
    Friction,
    FrictionSum,
)
from joulepath.dynamics._lagrange_euler import lagrange_euler, mass_matrix_le
from joulepath.dynamics._rnea import PinocchioRnea
from joulepath.dynamics._robot import METHODS, Robot, load_robot

__all__ = [
    "CoulombViscousFriction",
    "ElastoPlasticFriction",
    "Friction",
    "FrictionSum",
    "METHODS",
    "NOMINAL_FRICTION",
    "PinocchioRnea",
    "Robot",
    "lagrange_euler",
    "load_robot",
    "mass_matrix_le",
]
