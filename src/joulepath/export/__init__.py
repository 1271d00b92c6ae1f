"""Programs that leave the tool: exporters for robot controllers, and the moves they run.

Every exporter renders a verified path into files (:class:`Exporter`,
:data:`EXPORTERS`): ABB RAPID, an ABB EGM session (RAPID module + setup note; the PC
streams the path with ``joulepath stream``), Universal Robots URScript (e-series
500 Hz, CB3 125 Hz) and a ROS 2 ``JointTrajectory``. Which one a robot gets by default is the
controller it declares (:func:`declared_controller`).
"""

from joulepath.export._base import (
    DEFAULT_CONTROLLER,
    EXPORTERS,
    Exporter,
    check_path,
    declared_controller,
    get_exporter,
    refuse_foreign,
    register_exporter,
    robot_vendor,
    select_exporter,
)
from joulepath.export._egm import EGM_DEVICE, EGM_PORT, egm_module, render_egm
from joulepath.export._excitation import excitation_module
from joulepath.export._moves import Move, draw_moves, random_moves
from joulepath.export._rapid import (
    MODES,
    collection_module,
    collection_programs,
    measurement_module,
    path_module,
    render_rapid,
)
from joulepath.export._ros2 import render_ros2
from joulepath.export._urscript import render_urscript, render_urscript_cb3, urscript_program

register_exporter(
    Exporter(
        "rapid",
        "ABB",
        ("path.mod",),
        "ABB RAPID module (MoveAbsJ), default and optimized move",
        render_rapid,
        follows="via-points",
    )
)
register_exporter(
    Exporter(
        "egm",
        "ABB",
        ("egm.mod", "EGM_SETUP.md"),
        "ABB EGM joint streaming (RAPID module + setup note; the PC runs `joulepath stream`)",
        render_egm,
    )
)
register_exporter(
    Exporter(
        "urscript",
        "Universal Robots",
        ("path.script",),
        "URScript, servoj at 500 Hz (e-series)",
        render_urscript,
    )
)
register_exporter(
    Exporter(
        "urscript-cb3",
        "Universal Robots",
        ("path.script",),
        "URScript, servoj at 125 Hz (CB3)",
        render_urscript_cb3,
    )
)
register_exporter(
    Exporter(
        "ros2",
        "any",
        ("trajectory.yaml", "trajectory.csv"),
        "ROS 2 trajectory_msgs/JointTrajectory (FollowJointTrajectory goal, YAML) and a CSV",
        render_ros2,
    )
)

__all__ = [
    "DEFAULT_CONTROLLER",
    "EGM_DEVICE",
    "EGM_PORT",
    "EXPORTERS",
    "Exporter",
    "MODES",
    "Move",
    "check_path",
    "collection_module",
    "collection_programs",
    "declared_controller",
    "draw_moves",
    "egm_module",
    "excitation_module",
    "get_exporter",
    "measurement_module",
    "path_module",
    "random_moves",
    "refuse_foreign",
    "register_exporter",
    "render_egm",
    "render_rapid",
    "render_ros2",
    "render_urscript",
    "render_urscript_cb3",
    "robot_vendor",
    "select_exporter",
    "urscript_program",
]
