"""Ready-made robots shipped with joulepath (data only): the IRB 120 and the ABB range.

The ABB range (``irb140-6-0.8`` ... ``irb6700-235-2.65``) is named as ABB names its variants,
payload and reach (``IRB 4600-40/2.55`` -> ``irb4600-40-2.55``); a family's name alone
(``irb4600``) is its default variant (:data:`FAMILY_DEFAULTS`). Each of them has a
``.provenance.toml`` beside its ``.irml``: its masses and inertias are estimates
(:func:`joulepath.description.read_provenance`). ``scripts/make_abb_presets.py`` writes them;
``scripts/make_irb2400_preset.py`` the IRB 2400 (published masses, part-published inertias and
friction; its axis 3 is coupled to axis 2, see :func:`joulepath.description.axes_to_joints`).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from joulepath.description._irml import read_irml
from joulepath.description._model import RobotDescription
from joulepath.errors import InvalidRobotDescription

DEFAULT_ROBOT = "irb120"
"""The robot every command and config uses when none is named (the thesis' ABB IRB 120)."""

ABB_RANGE = (
    "irb140-6-0.8",
    "irb1200-7-0.7",
    "irb1200-5-0.9",
    "irb1600-6-1.2",
    "irb1600-8-1.45",
    "irb2400-12-1.55",
    "irb2600-12-1.65",
    "irb4600-20-2.50",
    "irb4600-40-2.55",
    "irb4600-60-2.05",
    "irb6700-200-2.60",
    "irb6700-235-2.65",
)
"""The bundled ABB variants beyond the IRB 120 (estimated dynamics; see each one's provenance)."""

FAMILY_DEFAULTS = {
    "irb140": "irb140-6-0.8",
    "irb1200": "irb1200-7-0.7",
    "irb1600": "irb1600-8-1.45",
    "irb2400": "irb2400-12-1.55",
    "irb2600": "irb2600-12-1.65",
    "irb4600": "irb4600-40-2.55",
    "irb6700": "irb6700-200-2.60",
}
"""A family's name -> the variant it stands for (the family's headline variant among those bundled)."""

ABB_DRIVE_CLASSES = {
    "compact": ("irb140-6-0.8", "irb1200-7-0.7", "irb1200-5-0.9"),
    "medium": ("irb1600-6-1.2", "irb1600-8-1.45", "irb2400-12-1.55", "irb2600-12-1.65"),
    "large": ("irb4600-20-2.50", "irb4600-40-2.55", "irb4600-60-2.05"),
    "heavy": ("irb6700-200-2.60", "irb6700-235-2.65"),
}
"""The ABB range by size, for its drive and idle figures: each class's arms share one bundled drives
file, ``presets/abb-<class>.drives.toml`` (every value assumed, its basis and source given in the file),
unless a drives file of their own lies beside their description."""

PRESETS = ("irb120", *ABB_RANGE, *FAMILY_DEFAULTS)
"""Names accepted by :func:`preset_path` and :func:`joulepath.load_robot` (variants, then family names)."""

HOME = {name: (0.0, 0.0, 0.0, 0.0, 0.0, 0.0) for name in PRESETS}
"""Named configurations (rad): ABB's home pose is q = 0."""


def abb_preset(robot_type: str) -> str | None:
    """The bundled robot an ABB robot type names (as a controller's ``MOC.cfg`` writes it:
    ``ROB1_4600_2.55_40`` is an IRB 4600 of 2.55 m reach and 40 kg), or None where none is bundled:
    the variant of that payload and reach, else none (another variant of the family is another arm).

    >>> abb_preset("ROB1_4600_2.55_40"), abb_preset("ROB1_120_0.58_3"), abb_preset("ROB1_360_1.6_6")
    ('irb4600-40-2.55', 'irb120', None)
    """
    import re

    m = re.match(r"ROB\d*_(\d+)[A-Za-z]*_([0-9.]+)_([0-9.]+)", robot_type)
    if m is None:
        return None
    family, reach, payload = m.group(1), float(m.group(2)), float(m.group(3))
    if family == "120":
        return "irb120"
    for name in ABB_RANGE:
        fam, pay, rea = name[3:].split("-")
        if fam == family and abs(float(pay) - payload) < 1e-6 and abs(float(rea) - reach) < 1e-6:
            return name
    return None


def abb_drive_class(name: str) -> str | None:
    """The size class of a bundled ABB arm (variant or family name), or None (not of the ABB range).

    >>> abb_drive_class("irb6700"), abb_drive_class("irb1200-5-0.9"), abb_drive_class("irb120")
    ('heavy', 'compact', None)
    """
    variant = preset_variant(name)
    return next((c for c, arms in ABB_DRIVE_CLASSES.items() if variant in arms), None)


def abb_drives_path(name: str) -> Path | None:
    """The bundled drives file of a bundled ABB arm's size class (:data:`ABB_DRIVE_CLASSES`), or None."""
    cls = abb_drive_class(name)
    if cls is None:
        return None
    return Path(str(resources.files("joulepath.description") / "presets" / f"abb-{cls}.drives.toml"))


def preset_variant(name: str) -> str:
    """The bundled file a name stands for: a family's name gives its default variant."""
    return FAMILY_DEFAULTS.get(name, name)


def preset_path(name: str, *, fmt: str = "irml") -> Path:
    """Path of a bundled robot file (``fmt`` is ``"irml"``, ``"urdf"`` or ``"provenance.toml"``)."""
    if name not in PRESETS:
        raise InvalidRobotDescription(
            f"unknown robot {name!r}; bundled robots: {', '.join(PRESETS)} "
            "(or give a path to an .irml or .urdf file)"
        )
    ref = resources.files("joulepath.description") / "presets" / f"{preset_variant(name)}.{fmt}"
    return Path(str(ref))


def preset_description(name: str) -> RobotDescription:
    """The IRML description of a bundled robot."""
    return read_irml(preset_path(name))
