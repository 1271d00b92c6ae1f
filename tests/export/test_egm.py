"""--export egm: the RAPID EGM session module and its setup note."""

import re

import numpy as np
import pytest

from joulepath.errors import InvalidInput, LimitViolation
from joulepath.export import EGM_DEVICE, EGM_PORT, EXPORTERS, egm_module, render_egm
from joulepath.trajectory import Trajectory, minimum_jerk

START = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
END = np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])


def code_of(text):
    return "\n".join(line.split("!")[0] for line in text.splitlines())


def test_egm_is_registered_for_abb():
    e = EXPORTERS["egm"]
    assert e.vendor == "ABB" and e.files == ("egm.mod", "EGM_SETUP.md")


def test_render_egm_runs_an_egm_joint_session_and_the_default_move(irb120):
    path = minimum_jerk(START, END, 1.6)
    files = render_egm(irb120, path, 1.6)
    assert set(files) == set(EXPORTERS["egm"].files)
    code = code_of(files["egm.mod"])
    for open_, close in (("MODULE", "ENDMODULE"), ("PROC", "ENDPROC"), ("FOR", "ENDFOR")):
        opens = re.findall(rf"^\s*{open_}\b", code, re.M)
        assert len(opens) == len(re.findall(rf"^\s*{close}\b", code, re.M))
    order = ["EGMGetId egm_id", f'EGMSetupUC ROB_1, egm_id, "default", "{EGM_DEVICE}" \\Joint', "EGMActJoint"]
    order += ["EGMRunJoint egm_id, EGM_STOP_HOLD", "EGMStop egm_id"]
    at = [code.index(s) for s in order]
    assert at == sorted(at)
    act = code[code.index("EGMActJoint") : code.index(";", code.index("EGMActJoint"))]
    for j in range(1, 7):
        assert f"\\J{j}:=CONV" in act
    assert "," not in act.split("egm_id", 1)[1]  # optional arguments: no commas
    run = code[code.index("EGMRunJoint") : code.index(";", code.index("EGMRunJoint"))]
    assert "\\CondTime:=COND_TIME" in run and "\\RampInTime:=RAMP_IN" in run
    assert "MoveAbsJ GOAL, v7000 \\T:=MOVE_TIME, fine, tool0;" in code
    assert re.search(r"CONST num REPEATS := 5;", code)
    assert code.count("MoveAbsJ START, v200, fine, tool0;") == 2  # each run from the start
    cond = float(re.search(r"CONST num COND_TIME := ([\d.]+);", code).group(1))
    assert cond > 1.6
    for name, q in (("START", START), ("GOAL", END)):
        m = re.search(rf"CONST jointtarget {name} := \[\[([^\]]+)\]", code)
        np.testing.assert_allclose([float(v) for v in m.group(1).split(",")], np.degrees(q), atol=1e-4)


def test_setup_note_names_option_config_and_command(irb120):
    note = render_egm(irb120, minimum_jerk(START, END, 1.6), 1.6)["EGM_SETUP.md"]
    for needed in ("689-1", "3124-1", '-Type "UDPUC"', f'-Name "{EGM_DEVICE}"', "EXT_MOTION_DATA"):
        assert needed in note
    assert re.search(rf"joulepath stream RUN_FOLDER .*--port {EGM_PORT} --repeat 5", note)


def test_egm_module_refuses_a_path_outside_the_limits(irb120):
    hi = irb120.joint_ranges()[1]
    path = minimum_jerk(START, np.where(np.arange(6) == 0, hi[0] + 0.1, END), 1.6)
    with pytest.raises(LimitViolation, match="egm.mod is not written"):
        egm_module(irb120, path, 1.6)


def test_egm_module_refuses_other_joint_counts(irb120):
    t = np.linspace(0, 1, 5)
    z = np.zeros((5, 7))
    with pytest.raises(InvalidInput, match="shape"):
        egm_module(irb120, Trajectory(t=t, q=z, qd=z, qdd=z), 1.0)


def test_write_run_with_export_egm_writes_the_module_and_the_plan(egm_run):
    names = {p.name for p in egm_run.iterdir()}
    assert {"egm.mod", "EGM_SETUP.md", "path.csv", "result.json"} <= names
    assert "path.mod" not in names
    head = (egm_run / "path.csv").read_text().splitlines()[0].split(",")
    assert head == ["t", *(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, 7))]
