"""The run folder's declared files (foundation): what ``experiment`` writes and ``report`` reads.

A stage's files are named relative to its folder. Only the ``[identify]`` and ``[cycle]`` stages'
files are declared here so far; the other stages' names are still spelled where they are used.
"""

from __future__ import annotations

IDENTIFY_STAGE = "identify"
"""The ``[identify]`` stage's folder in the run folder."""

IDENTIFY_TWIN = "twin"
"""The calibrated twin folder (``--robot`` accepts it)."""

IDENTIFY_SCORES = "scores.csv"
"""One row per model and test set; columns :data:`IDENTIFY_SCORE_COLUMNS`."""

IDENTIFY_SCORE_COLUMNS = (
    "model",
    "trained_on",
    "test_set",
    "moves",
    "rows",
    "torque_r2_worst_joint",
    "energy_r2",
    "path_error_median_pct",
)
"""``torque_r2_worst_joint`` is empty for a model that predicts energy only."""

IDENTIFY_LOOP = "loop.csv"
"""Tasks optimized on the twin: the saving it predicts against the one realized on the plant."""

CYCLE_STAGE = "cycle"
"""The ``[cycle]`` stage's folder: the files of ``joulepath cycle`` (``joulepath.program.CYCLE_FILES``)."""

CYCLE_JSON = "cycle.json"
"""Per move: default and optimized duration and energy; the cycle's totals and the written program's check."""

CYCLE_PARETO_PNG = "pareto.png"
"""Energy against cycle time (only when ``[cycle] pareto_points`` ≥ 3)."""

RUN_FILES = ("summary.json", "report.html", "run.log")
"""The files at the top of a run folder: the summary, the report and the log of every run."""

STAGE_FOLDERS = ("data", "synth", "models", "importance", "optimize", "bench", IDENTIFY_STAGE, CYCLE_STAGE)
"""Every stage's folder in a run folder (a stage runs in a hidden ``.NAME.partial`` sibling first)."""

__all__ = [
    "CYCLE_JSON",
    "CYCLE_PARETO_PNG",
    "CYCLE_STAGE",
    "IDENTIFY_LOOP",
    "IDENTIFY_SCORES",
    "IDENTIFY_SCORE_COLUMNS",
    "IDENTIFY_STAGE",
    "IDENTIFY_TWIN",
    "RUN_FILES",
    "STAGE_FOLDERS",
]
