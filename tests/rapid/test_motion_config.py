"""A backup's ``MOC.cfg`` as a cell of several arms writes it: one ``ROBOT`` instance per arm, each with
its own type and base frame. A task reads its own arm's (the task's number names it), never a mix."""

from __future__ import annotations

from pathlib import Path

import pytest

from joulepath.cli import main
from joulepath.rapid import find_moc, read_moc

MOC = """MOC:CFG_1.0:6:0::
#
ROBOT:

      -name "ROB_1" -use_robot_serial_number "rob_1"\\
      -use_robot_type "ROB1_120_0.58_3" -use_robot_calib "r1_uncalib"\\
      -base_frame_pos_x -0.2 -base_frame_pos_z 0.8

      -name "ROB_2" -use_robot_serial_number "rob_2"\\
      -use_robot_type "ROB2_4600_2.55_40" -use_robot_calib "r2_uncalib"\\
      -base_frame_pos_y 4 -gravity_beta 3.14159265

#
ROBOT_TYPE:

      -name "ROB1_120_0.58_3" -base_frame_pos_z 9
"""
EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"


def _backup(tmp_path: Path) -> Path:
    (tmp_path / "SYSPAR").mkdir()
    (tmp_path / "SYSPAR" / "MOC.cfg").write_text(MOC)
    for task, x in ((1, -150), (2, 1500)):
        folder = tmp_path / "RAPID" / f"TASK{task}" / "PROGMOD"
        folder.mkdir(parents=True)
        (folder / "Cell.mod").write_text(
            f"""MODULE Cell
    CONST robtarget pA := [[{x}, 0, 1400], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    CONST robtarget pB := [[{x + 50}, 100, 1350], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    PROC main()
        MoveJ pA, v1000, fine, tool0;
        MoveJ pB, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""
        )
    return tmp_path


def test_each_task_reads_its_own_robot_instance(tmp_path):
    root = _backup(tmp_path)
    first = find_moc([root / "RAPID" / "TASK1"]) or find_moc([root])
    second = read_moc(root / "SYSPAR" / "MOC.cfg", task=2)
    assert first is not None
    assert first.robots == ("ROB_1", "ROB_2")
    assert (first.robot, first.robot_type) == ("ROB_1", "ROB1_120_0.58_3")
    assert first.base_pos_m == pytest.approx((-0.2, 0.0, 0.8)) and first.mounting == "floor"
    assert (second.robot, second.robot_type) == ("ROB_2", "ROB2_4600_2.55_40")
    assert second.base_pos_m == pytest.approx((0.0, 4.0, 0.0)) and second.mounting == "ceiling"
    assert any("2 robots (ROB_1, ROB_2): ROB_1's data read" in line for line in first.lines())


def test_a_task_without_a_number_reads_the_first_instance(tmp_path):
    root = _backup(tmp_path)
    moc = read_moc(root / "SYSPAR" / "MOC.cfg")
    assert (moc.robot, moc.robot_type, moc.base_pos_m) == (
        "ROB_1",
        "ROB1_120_0.58_3",
        pytest.approx((-0.2, 0, 0.8)),
    )


def test_a_single_robot_file_reads_as_before(tmp_path):
    path = tmp_path / "MOC.cfg"
    path.write_text(MOC.split('      -name "ROB_2"')[0] + "#\n")
    moc = read_moc(path, task=3)
    assert (moc.robot, moc.robots, moc.robot_type) == ("ROB_1", ("ROB_1",), "ROB1_120_0.58_3")
    assert not any("robots (" in line for line in moc.lines())


def test_cycle_places_the_first_tasks_targets_by_its_own_base_frame(tmp_path, capsys):
    """The targets lie about 600 mm from ROB_1's base; with ROB_2's base frame mixed in (4 m along y)
    they would be refused as 4 m out of reach (as they were before)."""
    root = _backup(tmp_path)
    code = main(
        [
            "cycle",
            str(root / "RAPID" / "TASK1"),
            str(root / "SYSPAR" / "MOC.cfg"),
            "--out",
            str(tmp_path / "out"),
            "--export",
            "egm",
        ]
    )
    captured = capsys.readouterr()
    assert "beyond its reach" not in captured.err
    assert code == 0 and "ROB_1's data read" in captured.out + captured.err
