"""Whole studies from one TOML file: ``joulepath run EXPERIMENT.toml``."""

from joulepath.experiment._config import DataStage, Experiment, OptimizeStage, TrainStage, load_experiment
from joulepath.experiment._run import run_experiment

__all__ = ["DataStage", "Experiment", "OptimizeStage", "TrainStage", "load_experiment", "run_experiment"]
