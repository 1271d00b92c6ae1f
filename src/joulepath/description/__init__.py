"""Robot descriptions: the thesis' IRML format, URDF through Pinocchio, physical checks.

Everything here is data: :class:`RobotDescription` mirrors an IRML file and
:class:`Chain` is the generic serial chain that kinematics and dynamics use.
"""

from joulepath.description._chain import (
    chain_from_description,
    combine_inertials,
    dh_transform,
    transform_inertial,
)
from joulepath.description._check import Finding, check_inertial, check_physical
from joulepath.description._irml import irml_string, parse_irml, read_irml, write_irml
from joulepath.description._model import (
    Chain,
    Inertial,
    JointDescription,
    RangeSet,
    RobotDescription,
)
from joulepath.description._named import NAMED_ARMS, NamedArm, named_arm_path
from joulepath.description._pinocchio import chain_from_urdf, pinocchio_model
from joulepath.description._presets import DEFAULT_ROBOT, HOME, PRESETS, preset_description, preset_path

__all__ = [
    "Chain",
    "DEFAULT_ROBOT",
    "Finding",
    "HOME",
    "Inertial",
    "JointDescription",
    "NAMED_ARMS",
    "NamedArm",
    "PRESETS",
    "RangeSet",
    "RobotDescription",
    "chain_from_description",
    "chain_from_urdf",
    "check_inertial",
    "check_physical",
    "combine_inertials",
    "dh_transform",
    "irml_string",
    "named_arm_path",
    "parse_irml",
    "pinocchio_model",
    "preset_description",
    "preset_path",
    "read_irml",
    "transform_inertial",
    "write_irml",
]
