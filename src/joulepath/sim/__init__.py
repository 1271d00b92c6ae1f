"""Simulated data collection: an emulated ABB controller and two plants (sim twin, lab robot)."""

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
from joulepath.sim._run import (
    THESIS_PLAN,
    SimulatedLog,
    log_text,
    measure,
    moves_text,
    simulate,
    simulate_plan,
)

__all__ = [
    "ACCEL_TIME",
    "ControllerConfig",
    "JERK_TIME",
    "LabFriction",
    "Measured",
    "MotionPlan",
    "PLANTS",
    "Plant",
    "Segment",
    "SimulatedLog",
    "THESIS_PLAN",
    "acceleration_limit",
    "evaluate_plan",
    "jerk_limit",
    "log_text",
    "log_times",
    "make_plant",
    "measure",
    "moves_text",
    "plan_moves",
    "run_plant",
    "simulate",
    "simulate_plan",
]
