"""Simulated data collection: an emulated ABB controller and two plants (sim twin, lab robot)."""

from joulepath.sim._controller import (
    ControllerConfig,
    MotionPlan,
    Segment,
    evaluate_plan,
    log_times,
    plan_moves,
)
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
    "ControllerConfig",
    "LabFriction",
    "Measured",
    "MotionPlan",
    "PLANTS",
    "Plant",
    "Segment",
    "SimulatedLog",
    "THESIS_PLAN",
    "evaluate_plan",
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
