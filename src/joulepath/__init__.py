"""joulepath: energy-optimal point-to-point moves for six-axis industrial robot arms.

>>> import joulepath
>>> robot = joulepath.load_robot("irb120")
>>> robot.fk([0.0] * 6).position_mm.round(1).tolist()
[374.0, 0.0, 630.0]
"""

from joulepath import energy, units
from joulepath.dynamics import Robot, load_robot
from joulepath.errors import (
    InvalidInput,
    InvalidLog,
    InvalidRobotDescription,
    JoulepathError,
    LimitViolation,
    MissingDependency,
)

__version__ = "0.1.0"

__all__ = [
    "InvalidInput",
    "InvalidLog",
    "InvalidRobotDescription",
    "JoulepathError",
    "LimitViolation",
    "MissingDependency",
    "Robot",
    "__version__",
    "energy",
    "load_robot",
    "units",
]
