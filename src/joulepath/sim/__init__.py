"""The controller model and simulated data collection.

One controller model (STYLE §15): the emulated ABB controller's moves
(:mod:`joulepath.sim._controller`, :mod:`joulepath.sim._profile`), its timing of whole
programs with zones, ``\\T`` and timed fly-by chains (:mod:`joulepath.sim._timing`), and
where via points go so that it follows an optimized path (:mod:`joulepath.sim._via`);
two plants (the sim twin and the emulated lab robot) and the measurement loop.
"""

from joulepath.sim._controller import (
    ControllerConfig,
    MotionPlan,
    Segment,
    evaluate_plan,
    log_times,
    plan_moves,
)
from joulepath.sim._limits import ACCEL_TIME, JERK_TIME, acceleration_limit, jerk_limit
from joulepath.sim._plants import PLANTS, LabFriction, Measured, Plant, make_plant, run_plant
from joulepath.sim._profile import Profile, evaluate_profile, plan_profile
from joulepath.sim._run import (
    THESIS_PLAN,
    SimulatedLog,
    log_text,
    measure,
    moves_text,
    simulate,
    simulate_plan,
)
from joulepath.sim._steps import SpeedData, Step, StepSequence
from joulepath.sim._timing import (
    FINE_DT,
    ChainProfile,
    PathCache,
    PlannedCycle,
    PlannedMove,
    acc_share,
    check_motion_time,
    evaluate_cycle,
    plan_cycle,
    stops_after,
    tcp_pose,
)
from joulepath.sim._timing import _tcp as tcp_path
from joulepath.sim._via import RAPID_ACCEL_SHARE, FollowedPath, follow_path, timed_move
from joulepath.sim._via import _interpolate as interpolate_via
from joulepath.sim._via import _leg_indices as leg_indices
from joulepath.sim._via import layout as via_layout

__all__ = [
    "ACCEL_TIME",
    "ChainProfile",
    "ControllerConfig",
    "FINE_DT",
    "FollowedPath",
    "JERK_TIME",
    "LabFriction",
    "Measured",
    "MotionPlan",
    "PLANTS",
    "PathCache",
    "PlannedCycle",
    "PlannedMove",
    "Plant",
    "Profile",
    "RAPID_ACCEL_SHARE",
    "Segment",
    "SimulatedLog",
    "SpeedData",
    "Step",
    "StepSequence",
    "THESIS_PLAN",
    "acc_share",
    "acceleration_limit",
    "check_motion_time",
    "evaluate_cycle",
    "evaluate_plan",
    "evaluate_profile",
    "follow_path",
    "interpolate_via",
    "jerk_limit",
    "leg_indices",
    "log_text",
    "log_times",
    "make_plant",
    "measure",
    "moves_text",
    "plan_cycle",
    "plan_moves",
    "plan_profile",
    "run_plant",
    "simulate",
    "simulate_plan",
    "stops_after",
    "tcp_path",
    "tcp_pose",
    "timed_move",
    "via_layout",
]
