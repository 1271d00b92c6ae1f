"""The drives file's power-saving modes: both keys or neither, at most the standby power, sourced."""

import pytest

import joulepath
from joulepath.energy._drives import DriveModel, drives_toml, read_drives_file
from joulepath.errors import InvalidInput

BASE = {"torque_constant": (2.0,), "resistance": (1.0,), "drive_efficiency": (1.0,), "standby_W": 100.0}


def test_drive_model_refuses_half_a_mode_and_a_mode_above_standby():
    with pytest.raises(InvalidInput, match="give both brakes_W and brakes_entry_s"):
        DriveModel(**BASE, brakes_W=30.0)
    with pytest.raises(InvalidInput, match=r"bus_off_W must be in \[0, standby_W = 100.0\]"):
        DriveModel(**BASE, bus_off_W=120.0, bus_off_entry_s=5.0)
    with pytest.raises(InvalidInput, match="brakes_entry_s must be ≥ 0 s"):
        DriveModel(**BASE, brakes_W=30.0, brakes_entry_s=-1.0)


def test_drives_file_round_trips_its_modes(tmp_path):
    model = DriveModel(**BASE, brakes_W=38.0, brakes_entry_s=0.5, sources={"brakes_W": "measured"})
    path = tmp_path / "arm.drives.toml"
    path.write_text(drives_toml(model))
    back = read_drives_file(path, 1)
    assert (back.brakes_W, back.brakes_entry_s, back.bus_off_W) == (38.0, 0.5, None)
    assert back.source("brakes_W") == "measured" and back.source("brakes_entry_s") == "assumed"


def test_irb120_modes_are_assumed_and_below_its_standby():
    drives = joulepath.load_robot("irb120").drivetrain.drives
    assert drives is not None
    for mode in ("brakes", "bus_off"):
        assert 0 < getattr(drives, f"{mode}_W") < drives.standby_W
        assert drives.source(f"{mode}_W").startswith("assumed") and "Bukata" in drives.source(f"{mode}_W")
    assert drives.bus_off_W < drives.brakes_W
    assert "mode" not in drives.describe()  # the electrical figures' line names the values they use only
