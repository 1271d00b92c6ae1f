"""Joint trajectories over a fixed duration, sampled at the data rate."""

from joulepath.trajectory._bspline import DEFAULT_KNOT_SPACING, GridBasis, SplineBasis
from joulepath.trajectory._minimum_jerk import Trajectory, minimum_jerk, sample_times
from joulepath.trajectory._polynomial import (
    GRID_HIGH,
    GRID_LOW,
    GRID_STEP,
    N_COEFFICIENTS,
    quintic_hermite,
    rest_to_rest,
    thesis_quintic,
)

__all__ = [
    "DEFAULT_KNOT_SPACING",
    "GRID_HIGH",
    "GRID_LOW",
    "GRID_STEP",
    "GridBasis",
    "N_COEFFICIENTS",
    "SplineBasis",
    "Trajectory",
    "minimum_jerk",
    "quintic_hermite",
    "rest_to_rest",
    "sample_times",
    "thesis_quintic",
]
