"""Drives files: the format, its sources, and every refusal in one line."""

import os

import pytest

from joulepath.energy import DriveModel, drives_toml, read_drives_file
from joulepath.errors import InvalidInput

GOOD = """
torque_constant = [10.0, 10.0, 5.0]
resistance = 0.5
drive_efficiency = [0.95, 0.95, 0.9]
gear_efficiency = 0.85
bus = "regenerative"
regen_efficiency = 0.8
standby_W = 90
bus_voltage_V = 48

[sources]
standby_W = "data sheet, p. 3"
"""


def _write(tmp_path, text, name="arm.drives.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_read_drives_file_reads_values_and_sources(tmp_path):
    d = read_drives_file(_write(tmp_path, GOOD), 3)
    assert d.torque_constant == (10.0, 10.0, 5.0)
    assert d.resistance == (0.5, 0.5, 0.5)  # one number: every joint
    assert d.bus == "regenerative" and d.regen_efficiency == 0.8 and d.standby_W == 90.0
    assert d.source("standby_W") == "data sheet, p. 3"
    assert d.source("resistance") == "assumed"
    assert "sourced: standby_W" in d.describe() and "assumed: torque_constant" in d.describe()


def test_drives_toml_round_trips(tmp_path):
    d = read_drives_file(_write(tmp_path, GOOD), 3)
    again = read_drives_file(_write(tmp_path, drives_toml(d, comment="written back"), "b.drives.toml"), 3)
    assert again.to_json() | {"origin": ""} == d.to_json() | {"origin": ""}


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (GOOD.replace("standby_W = 90", "standby_W = true"), r"standby_W must be a finite number, got True"),
        (GOOD.replace("resistance = 0.5", "resistance = nan"), "resistance must be a finite number"),
        (GOOD.replace("resistance = 0.5", "resistance = [1.0, true, 1.0]"), "resistance must be a finite"),
        (GOOD.replace("resistance = 0.5", "resistance = [1.0, 1.0]"), "has 2 values; give one number or 3"),
        (GOOD.replace("resistance = 0.5", "resistance = -1.0"), r"resistance must be ≥ 0 Ω"),
        (GOOD.replace("gear_efficiency = 0.85", "gear_efficiency = 1.5"), r"gear_efficiency must be in \("),
        (GOOD.replace('bus = "regenerative"', 'bus = "grid"'), "bus must be one of bleeder, regenerative"),
        (GOOD.replace('bus = "regenerative"', "bus = 1"), "bus must be one of"),
        (GOOD.replace("regen_efficiency = 0.8\n", ""), "needs regen_efficiency"),
        (GOOD.replace("torque_constant", "kt"), "unknown key 'kt'"),
        (GOOD.replace("drive_efficiency = [0.95, 0.95, 0.9]\n", ""), "drive_efficiency is missing"),
        ('torque = "x"\n' + GOOD, "unknown key 'torque'"),
        (GOOD.replace('standby_W = "data sheet, p. 3"', "standby_W = 3"), r"\[sources\] must map"),
        (GOOD.replace('standby_W = "data sheet, p. 3"', 'kt = "x"'), "sources.kt names no value"),
        ("torque_constant = [", "not a TOML drives file"),
    ],
)
def test_read_drives_file_refuses_in_one_line(tmp_path, text, match):
    with pytest.raises(InvalidInput, match=match) as err:
        read_drives_file(_write(tmp_path, text), 3)
    assert "\n" not in str(err.value)
    assert "arm.drives.toml" in str(err.value)


def test_read_drives_file_refuses_a_folder_and_a_huge_file(tmp_path):
    with pytest.raises(InvalidInput, match="not a regular file"):
        read_drives_file(tmp_path, 3)
    big = _write(tmp_path, "# " + "x" * (70 << 10))
    with pytest.raises(InvalidInput, match="larger than 64 KiB"):
        read_drives_file(big, 3)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_read_drives_file_refuses_a_fifo_without_blocking(tmp_path):
    fifo = tmp_path / "arm.drives.toml"
    os.mkfifo(fifo)
    with pytest.raises(InvalidInput, match="not a regular file"):
        read_drives_file(fifo, 3)


def test_drive_model_checks_its_values():
    with pytest.raises(InvalidInput, match="torque_constant must be > 0"):
        DriveModel(torque_constant=(0.0,), resistance=(1.0,), drive_efficiency=(1.0,))
    with pytest.raises(InvalidInput, match="one per joint"):
        DriveModel(torque_constant=(1.0, 1.0), resistance=(1.0,), drive_efficiency=(1.0, 1.0))


def test_the_documented_drives_example_reads(tmp_path):
    """The drives file shown in docs/reference/formats.md ("Drives files") reads as documented."""
    import re
    from pathlib import Path

    page = Path(__file__).resolve().parents[2] / "docs" / "reference" / "formats.md"
    text = page.read_text(encoding="utf-8")
    block = next(b for b in re.findall(r"```toml\n(.*?)```", text, flags=re.S) if "torque_constant" in b)
    d = read_drives_file(_write(tmp_path, block), 6)
    assert d.bus == "bleeder" and d.standby_W == 90.0 and d.source("standby_W").startswith("UR5")


def test_bundled_drives_files_read(tmp_path):
    from joulepath.description import preset_path

    for name in ("irb120", "ur5"):
        d = read_drives_file(preset_path("irb120").with_name(f"{name}.drives.toml"), 6)
        assert d.gear_efficiency is not None and d.standby_W > 0
