"""Named arms from ``example-robot-data`` (the ``[robots]`` extra): ``load_robot("ur5")``.

Data only: each name points to a URDF of that package and says which joints to
lock (a gripper's fingers) so that what remains is the arm. The package is found
through its installed files (``cmeel.prefix/share/example-robot-data/robots``);
nothing of it is imported or executed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from joulepath.errors import InvalidRobotDescription, MissingDependency

PACKAGE = "example-robot-data"
_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"


@dataclass(frozen=True, slots=True)
class NamedArm:
    """An arm of ``example-robot-data``: its URDF, the joints locked, and where it comes from."""

    urdf: str
    lock: dict[str, float] = field(default_factory=dict)
    about: str = ""
    payload_kg: float | None = None  # rated payload of the maker's data sheet (None: not recorded here)


NAMED_ARMS: dict[str, NamedArm] = {
    "ur3": NamedArm(
        "ur_description/urdf/ur3_robot.urdf", about="Universal Robots UR3 (CB3 limits ±360°)", payload_kg=3.0
    ),
    "ur5": NamedArm(
        "ur_description/urdf/ur5_robot.urdf", about="Universal Robots UR5 (CB3 limits ±360°)", payload_kg=5.0
    ),
    "ur10": NamedArm(
        "ur_description/urdf/ur10_robot.urdf",
        about="Universal Robots UR10 (CB3 limits ±360°)",
        payload_kg=10.0,
    ),
    "panda": NamedArm(
        "panda_description/urdf/panda.urdf",
        lock={"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0},
        about="Franka Emika Panda, 7 joints; the hand's two finger joints locked closed",
        payload_kg=3.0,
    ),
    "xarm7": NamedArm("xarm_description/urdf/xarm7.urdf", about="UFactory xArm7, 7 joints"),
    "z1": NamedArm(
        "z1_description/urdf/z1.urdf",
        lock={"jointGripper": 0.0},
        about="Unitree Z1, 6 joints; the gripper joint locked closed",
    ),
    "kinova": NamedArm(
        "kinova_description/robots/kinova.urdf", about="Kinova Jaco2 j2s6s200, continuous joints"
    ),
    "so100": NamedArm(
        "so_arm_description/urdf/so100.urdf",
        lock={"gripper": 0.0},
        about="SO-100, 5 joints; the gripper jaw locked",
    ),
}
"""Names :func:`joulepath.load_robot` takes besides the bundled IRB 120."""


def named_arm_path(name: str) -> Path:
    """The installed URDF of a named arm.

    Raises
    ------
    MissingDependency
        ``example-robot-data`` is not installed (``pip install 'joulepath[robots]'``).
    InvalidRobotDescription
        Not a named arm, or the package lacks the file.
    """
    arm = NAMED_ARMS.get(name)
    if arm is None:
        raise InvalidRobotDescription(f"unknown arm {name!r}; named arms: {', '.join(NAMED_ARMS)}")
    from importlib import metadata

    try:
        dist = metadata.distribution(PACKAGE)
    except metadata.PackageNotFoundError:
        raise MissingDependency(
            f"robot {name!r} comes from the {PACKAGE} package, which is not installed; "
            "install it with: pip install 'joulepath[robots]'"
        ) from None
    path = Path(str(dist.locate_file(f"{_ROBOTS}/{arm.urdf}")))
    if not path.is_file():
        raise InvalidRobotDescription(
            f"robot {name!r}: {PACKAGE} {dist.version} has no {arm.urdf}; install the pinned version "
            "(pip install -c constraints.txt 'joulepath[robots]')"
        )
    return path
