"""Energy, declared once: the chain from joint to cabinet, drive data, and the registry of measures.

* :mod:`joulepath.energy._joint` — the thesis' joint energy ``|tau * qd| * dt``
  (:func:`joint_power`, :func:`joint_energy`, :func:`total_energy`, :func:`path_energy`,
  with their ``mode`` and ``copper_loss`` options);
* :mod:`joulepath.energy._chain` — the chain's stages (:data:`STAGES`): joint
  power, gear losses, copper losses, drive losses, the DC bus, standby;
* :mod:`joulepath.energy._drives` — a robot's drive data (:class:`DriveModel`,
  ``<stem>.drives.toml``);
* :mod:`joulepath.energy._measures` — the measures (:data:`MEASURES`): ``thesis``,
  ``mechanical``, ``electrical``, each taken at one stage.

Foundation: imports nothing of ours but ``_typing`` and ``errors``.
"""

from joulepath.energy._chain import (
    STAGES,
    ChainPower,
    Drivetrain,
    SmoothPower,
    Stage,
    chain_power,
    electrical_power,
    mechanical_power,
    motor_side_torque,
    thesis_power,
)
from joulepath.energy._drives import (
    ASSUMED,
    BUS_KINDS,
    DRIVES_SUFFIX,
    IDLE_MODES,
    TWIN_DRIVES_FILE,
    DriveModel,
    drives_toml,
    read_drives_file,
    read_drives_toml,
)
from joulepath.energy._joint import MODES, PathEnergy, joint_energy, joint_power, path_energy, total_energy
from joulepath.energy._measures import (
    DEFAULT_MEASURE,
    MEASURES,
    EnergyMeasure,
    MeasuredEnergy,
    available_measures,
    check_measure,
    energy_measure,
    measure_energy,
    measure_power,
    register_measure,
)

__all__ = [
    "ASSUMED",
    "BUS_KINDS",
    "ChainPower",
    "DEFAULT_MEASURE",
    "DRIVES_SUFFIX",
    "DriveModel",
    "Drivetrain",
    "EnergyMeasure",
    "IDLE_MODES",
    "MEASURES",
    "MODES",
    "MeasuredEnergy",
    "PathEnergy",
    "STAGES",
    "SmoothPower",
    "Stage",
    "TWIN_DRIVES_FILE",
    "available_measures",
    "chain_power",
    "check_measure",
    "drives_toml",
    "electrical_power",
    "energy_measure",
    "joint_energy",
    "joint_power",
    "measure_energy",
    "measure_power",
    "mechanical_power",
    "motor_side_torque",
    "path_energy",
    "read_drives_file",
    "read_drives_toml",
    "register_measure",
    "thesis_power",
    "total_energy",
]
