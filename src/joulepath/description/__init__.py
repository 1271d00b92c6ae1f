"""Robot descriptions: the thesis' IRML format, URDF through Pinocchio, physical checks.

Everything here is data: :class:`RobotDescription` mirrors an IRML file and
:class:`Chain` is the generic serial chain that kinematics and dynamics use.
"""

from joulepath.description._chain import (
    chain_from_description,
    combine_inertials,
    dh_link,
    dh_transform,
    transform_inertial,
)
from joulepath.description._check import Finding, check_chain, check_inertial, check_physical
from joulepath.description._coupling import (
    axes_to_joints,
    axis3_range,
    axis_torques_to_joints,
    has_axis3_coupling,
    joint_torques_to_axes,
    joints_to_axes,
)
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
from joulepath.description._presets import (
    ABB_DRIVE_CLASSES,
    ABB_RANGE,
    DEFAULT_ROBOT,
    FAMILY_DEFAULTS,
    HOME,
    PRESETS,
    abb_drive_class,
    abb_drives_path,
    abb_preset,
    preset_description,
    preset_path,
    preset_variant,
)
from joulepath.description._provenance import (
    KINDS,
    PROVENANCE_SUFFIX,
    ModelProvenance,
    ParameterSource,
    Uncertainty,
    provenance_beside,
    provenance_path,
    read_provenance,
)
from joulepath.description._sample import sample_chains

__all__ = [
    "ABB_DRIVE_CLASSES",
    "ABB_RANGE",
    "Chain",
    "DEFAULT_ROBOT",
    "FAMILY_DEFAULTS",
    "Finding",
    "HOME",
    "Inertial",
    "JointDescription",
    "KINDS",
    "ModelProvenance",
    "NAMED_ARMS",
    "NamedArm",
    "PRESETS",
    "PROVENANCE_SUFFIX",
    "ParameterSource",
    "RangeSet",
    "RobotDescription",
    "Uncertainty",
    "abb_drive_class",
    "abb_drives_path",
    "abb_preset",
    "axes_to_joints",
    "axis3_range",
    "axis_torques_to_joints",
    "chain_from_description",
    "chain_from_urdf",
    "check_chain",
    "check_inertial",
    "check_physical",
    "combine_inertials",
    "dh_link",
    "dh_transform",
    "has_axis3_coupling",
    "irml_string",
    "joint_torques_to_axes",
    "joints_to_axes",
    "named_arm_path",
    "parse_irml",
    "pinocchio_model",
    "preset_description",
    "preset_path",
    "preset_variant",
    "provenance_beside",
    "provenance_path",
    "read_irml",
    "read_provenance",
    "sample_chains",
    "transform_inertial",
    "write_irml",
]
