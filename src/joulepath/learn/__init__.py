"""Energy models (thesis §2.2, §4.3): pipelines, resumable grid search, safe files, importance."""

from joulepath.learn._bases import JointEnergyBases, joint_bases
from joulepath.learn._evaluate import Scores, path_errors, physics_baseline, physics_predict, score
from joulepath.learn._families import (
    FAMILIES,
    GRIDS,
    QUICK_GRIDS,
    SUBSTITUTIONS,
    THESIS_GRIDS,
    grid_for,
    make_pipeline,
)
from joulepath.learn._features import (
    INPUTS,
    KinematicFeatures,
    PhysicsFeatures,
    input_columns,
    kinematic_transform,
    physics_transform,
)
from joulepath.learn._importance import feature_importance, plot_importance, rank_joints
from joulepath.learn._model import TRUSTED_TYPES, EnergyModel, check_finite_predictions
from joulepath.learn._search import CandidateResult, SearchResult, connect_scheduler, grid_search, make_splits
from joulepath.learn._svr import KERNEL_SVR_MAX_ROWS, ScalableSVR, SubsampleWarning
from joulepath.learn._train import (
    NO_ROBOT_NOTE,
    TrainConfig,
    TrainingReport,
    best_model,
    choose_inputs,
    cv_groups,
    load_models,
    run_ids,
    train,
    training_range,
)
from joulepath.learn._validate import read_joints_json

__all__ = [
    "CandidateResult",
    "EnergyModel",
    "FAMILIES",
    "GRIDS",
    "INPUTS",
    "JointEnergyBases",
    "KERNEL_SVR_MAX_ROWS",
    "KinematicFeatures",
    "NO_ROBOT_NOTE",
    "PhysicsFeatures",
    "QUICK_GRIDS",
    "SUBSTITUTIONS",
    "ScalableSVR",
    "Scores",
    "SearchResult",
    "SubsampleWarning",
    "THESIS_GRIDS",
    "TRUSTED_TYPES",
    "TrainConfig",
    "TrainingReport",
    "best_model",
    "check_finite_predictions",
    "choose_inputs",
    "connect_scheduler",
    "cv_groups",
    "feature_importance",
    "grid_for",
    "grid_search",
    "input_columns",
    "joint_bases",
    "kinematic_transform",
    "load_models",
    "make_pipeline",
    "make_splits",
    "path_errors",
    "physics_baseline",
    "physics_predict",
    "physics_transform",
    "plot_importance",
    "rank_joints",
    "read_joints_json",
    "run_ids",
    "score",
    "train",
    "training_range",
]
