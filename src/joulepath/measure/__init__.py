"""Measure what ran: the default and the optimized move's repetitions in a log of ``path.mod``."""

from joulepath.measure._measure import (
    MEASURE_FILES,
    KindSummary,
    Measurement,
    MeasureRun,
    Repetition,
    Saving,
    measure_run,
    power_figure,
    saving_interval,
    write_measure,
)
from joulepath.measure._plan import PLAN_FILES, Plan, PlannedPath, read_plan
from joulepath.measure._segment import Window, find_moves, path_distance, tracking_error

__all__ = [
    "KindSummary",
    "MEASURE_FILES",
    "MeasureRun",
    "Measurement",
    "PLAN_FILES",
    "Plan",
    "PlannedPath",
    "Repetition",
    "Saving",
    "Window",
    "find_moves",
    "measure_run",
    "path_distance",
    "power_figure",
    "read_plan",
    "saving_interval",
    "tracking_error",
    "write_measure",
]
