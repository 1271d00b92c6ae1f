"""Dynamic identification: a robot's base inertial parameters, friction and drive losses from its logs.

Linear in the parameters (Gautier & Khalil): Pinocchio's joint torque regressor
reduced to the identifiable base set by a pivoted QR, friction columns per joint,
weighted least squares, a gear efficiency found by a scalar search, and a physically
consistent refinement (log-Cholesky). From motor currents, the drives' torque
constants too, scaled by a payload of known mass or the nominal masses
(:func:`identify_from_currents`). The result writes a calibrated twin folder
that :func:`joulepath.load_robot` reads back (``--robot twin/`` on the command line).
"""

from joulepath.identify._consistency import (
    from_log_cholesky,
    min_eigenvalues,
    pseudo_inertia,
    to_log_cholesky,
    triangle_margins,
)
from joulepath.identify._currents import (
    MAX_GAIN_ERROR,
    NOMINAL_PRIOR_WEIGHT,
    REFERENCES,
    UNFIXED_GAIN_ERROR,
    AssumedGain,
    CurrentIdentification,
    DriveGainFit,
    PayloadReference,
    fit_drive_gains,
    identified_drives,
    identify_from_currents,
    same_motor,
)
from joulepath.identify._data import SIGNALS, IdentificationData, data_from_logs, logged_signal
from joulepath.identify._evaluate import (
    EVALUATE_FILES,
    DriveGains,
    EvaluateConfig,
    Evaluation,
    drives_path,
    evaluate_model,
    read_drive_gains,
    write_evaluation,
)
from joulepath.identify._excitation import (
    ExcitationDesign,
    FourierExcitation,
    design_excitation,
    simulate_excitation,
)
from joulepath.identify._fit import (
    MAX_CONDITION,
    MAX_KEPT_SHARE,
    FitScores,
    Identification,
    IdentifyOptions,
    KeptParameter,
    UnexcitedParameterWarning,
    gear_side_speed,
    identify,
    joint_side,
    r2_per_joint,
    score_prediction,
)
from joulepath.identify._regressor import (
    RANK_TOLERANCE,
    BaseParameters,
    base_parameters,
    friction_regressor,
    inertial_regressor,
    true_parameters,
)
from joulepath.identify._twin import (
    CARD_FORMAT,
    link_inertials,
    parameter_report,
    twin_chain,
    twin_description,
    twin_robot,
    write_twin,
)

__all__ = [
    "AssumedGain",
    "BaseParameters",
    "CARD_FORMAT",
    "CurrentIdentification",
    "DriveGainFit",
    "DriveGains",
    "EVALUATE_FILES",
    "EvaluateConfig",
    "Evaluation",
    "ExcitationDesign",
    "FitScores",
    "FourierExcitation",
    "Identification",
    "IdentificationData",
    "IdentifyOptions",
    "KeptParameter",
    "MAX_CONDITION",
    "MAX_GAIN_ERROR",
    "MAX_KEPT_SHARE",
    "NOMINAL_PRIOR_WEIGHT",
    "PayloadReference",
    "RANK_TOLERANCE",
    "REFERENCES",
    "SIGNALS",
    "UNFIXED_GAIN_ERROR",
    "UnexcitedParameterWarning",
    "base_parameters",
    "data_from_logs",
    "design_excitation",
    "drives_path",
    "evaluate_model",
    "fit_drive_gains",
    "friction_regressor",
    "from_log_cholesky",
    "gear_side_speed",
    "identified_drives",
    "identify",
    "identify_from_currents",
    "inertial_regressor",
    "joint_side",
    "link_inertials",
    "logged_signal",
    "min_eigenvalues",
    "parameter_report",
    "pseudo_inertia",
    "r2_per_joint",
    "read_drive_gains",
    "same_motor",
    "score_prediction",
    "simulate_excitation",
    "to_log_cholesky",
    "triangle_margins",
    "true_parameters",
    "twin_chain",
    "twin_description",
    "twin_robot",
    "write_evaluation",
    "write_twin",
]
