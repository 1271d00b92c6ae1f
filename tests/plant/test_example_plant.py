"""The example plant: a mixed line that its script regenerates exactly, every arm with meter-level data,
the large arms' targets reachable in the configurations they name."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import joulepath
from joulepath.plant import read_plant
from joulepath.program import read_cycle_program

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "plant"


def _files(folder: Path) -> dict[str, str]:
    return {
        str(p.relative_to(folder)): p.read_text(encoding="utf-8") for p in folder.rglob("*") if p.is_file()
    }


def test_the_script_writes_the_example_plant_exactly(tmp_path):
    out = tmp_path / "plant"
    subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "make_example_plant.py"), "--out", str(out), "--seed", "7"],
        check=True,
        capture_output=True,
    )
    assert _files(out) == _files(EXAMPLE)


def test_the_example_plant_is_a_mixed_line_measured_at_the_meter():
    plant = read_plant(EXAMPLE / "plant.toml")
    robots = {c.robot for c in plant.cells}
    assert {"irb6700-200-2.60", "irb4600-60-2.05", "irb2600-12-1.65", "irb1200-7-0.7", "irb120"} <= robots
    standby = {}
    for name in robots:
        drives = joulepath.load_robot(name).drives
        assert drives is not None, name  # every cell's energy is at the meter
        standby[name] = drives.standby_W
    assert max(standby, key=standby.__getitem__) == "irb6700-200-2.60"


@pytest.mark.parametrize("cell", ["pallet-sacks", "pallet-cartons", "tend-2600", "press-1600", "weld-1600"])
def test_a_large_arm_cell_reads_with_its_own_arm(cell):
    plant = read_plant(EXAMPLE / "plant.toml")
    c = next(c for c in plant.cells if c.name == cell)
    robot = joulepath.load_robot(c.robot)
    spec, rapid = read_cycle_program(list(c.program), robot, io=dict(c.io))
    moves = [s for s in spec.steps if s.kind == "move"]
    assert rapid and len(moves) >= 10
    lo, hi = robot.joint_ranges()
    for s in moves:
        assert s.q is not None and ((s.q >= lo - 1e-9) & (s.q <= hi + 1e-9)).all()
