"""Ready-made robots shipped with joulepath (data only)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from joulepath.description._irml import read_irml
from joulepath.description._model import RobotDescription
from joulepath.errors import InvalidRobotDescription

DEFAULT_ROBOT = "irb120"
"""The robot every command and config uses when none is named (the thesis' ABB IRB 120)."""

PRESETS = ("irb120",)
"""Names accepted by :func:`preset_path` and :func:`joulepath.load_robot`."""

HOME = {"irb120": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)}
"""Named configurations (rad): ABB's home pose is q = 0."""


def preset_path(name: str, *, fmt: str = "irml") -> Path:
    """Path of a bundled robot file (``fmt`` is ``"irml"`` or ``"urdf"``)."""
    if name not in PRESETS:
        raise InvalidRobotDescription(
            f"unknown robot {name!r}; bundled robots: {', '.join(PRESETS)} "
            "(or give a path to an .irml or .urdf file)"
        )
    ref = resources.files("joulepath.description") / "presets" / f"{name}.{fmt}"
    return Path(str(ref))


def preset_description(name: str) -> RobotDescription:
    """The IRML description of a bundled robot."""
    return read_irml(preset_path(name))
