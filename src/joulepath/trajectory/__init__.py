"""Joint trajectories over a fixed duration, sampled at the data rate."""

from joulepath.trajectory._minimum_jerk import Trajectory, minimum_jerk, sample_times

__all__ = ["Trajectory", "minimum_jerk", "sample_times"]
