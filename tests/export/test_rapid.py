"""RAPID modules: structure, array sizes, external axes, bounds, determinism."""

import re

import numpy as np
import pytest

from joulepath.data import LOG_COLUMNS
from joulepath.errors import LimitViolation
from joulepath.export import collection_module, collection_programs, measurement_module


def check_structure(text: str) -> None:
    """MODULE/ENDMODULE, PROC/ENDPROC, FUNC/ENDFUNC, FOR/ENDFOR, WHILE/ENDWHILE balance; arrays sized."""
    code = "\n".join(line.split("!")[0] for line in text.splitlines())
    for open_, close in (
        ("MODULE", "ENDMODULE"),
        ("PROC", "ENDPROC"),
        ("FUNC", "ENDFUNC"),
        ("FOR", "ENDFOR"),
        ("WHILE", "ENDWHILE"),
    ):
        opens = len(re.findall(rf"^\s*{open_}\b", code, re.M))
        closes = len(re.findall(rf"^\s*{close}\b", code, re.M))
        assert opens == closes, (open_, opens, closes)
    for m in re.finditer(r"(CONST|VAR|PERS) (\w+) (\w+)\{(\d+)\} := \[(.*?)\];", code, re.S):
        body = m.group(5)
        depth, items = 0, 1
        for ch in body:
            depth += ch == "["
            depth -= ch == "]"
            items += ch == "," and depth == 0
        assert items == int(m.group(4)), (m.group(3), items, m.group(4))
    assert code.count('"') % 2 == 0
    for line in code.splitlines():
        s = line.strip()
        if s and not re.match(
            r"^(MODULE|ENDMODULE|PROC|ENDPROC|FUNC|ENDFUNC|FOR|ENDFOR|WHILE|ENDWHILE|ELSE)\b", s
        ):
            assert s.endswith((";", ",", "[")) or s.endswith("]") is False, line


@pytest.mark.parametrize("mode", ["rand", "table"])
def test_collection_module_structure(irb120, mode):
    progs = collection_programs(irb120, n_moves=25, mode=mode, seed=4)
    text = progs["JPCollect.mod"]
    check_structure(text)
    check_structure(progs["JPMeasure.mod"])
    assert "CONST num SIMULATION_COUNT := 25;" in text
    assert "FOR i FROM 1 TO SIMULATION_COUNT DO" in text
    speeds = re.search(r"SPEED_ARR\{(\d+)\} := \[(.*?)\];", text, re.S)
    assert speeds.group(1) == "17" and speeds.group(2).split()[0] == "v100,"
    zones = re.search(r"ZONE_ARR\{(\d+)\} := \[(.*?)\];", text, re.S)
    assert zones.group(1) == "14" and "fine" in zones.group(2) and "z200" in zones.group(2)


def test_collection_table_targets_carry_9e9_and_stay_inside_ranges(irb120):
    text = collection_programs(irb120, n_moves=50, mode="table", seed=1)["JPCollect.mod"]
    targets = re.findall(r"\[\[([-\d., ]+)\], \[([^\]]+)\]\]", text)
    assert len(targets) == 50
    lo, hi = (np.degrees(x) for x in irb120.joint_ranges())
    for joints, ext in targets:
        q = np.array([float(v) for v in joints.split(",")])
        assert ext.replace(" ", "") == ",".join(["9E9"] * 6)
        assert np.all(q >= lo) and np.all(q <= hi)


def test_collection_rand_bounds_are_appendix_d1(irb120):
    text = collection_programs(irb120, n_moves=3, mode="rand")["JPCollect.mod"]
    bounds = dict(re.findall(r"CONST num (J\d_(?:LO|HI)) := (-?[\d.]+);", text))
    assert bounds["J1_LO"] == "-120" and bounds["J2_LO"] == "-55" and bounds["J2_HI"] == "70"
    assert bounds["J3_LO"] == "-100" and bounds["J6_HI"] == "400"
    assert "MoveAbsJ [[J1, J2, J3, J4, J5, J6], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], V, Z, tool0;" in text
    assert "FUNC num RAND()" in text


def test_collection_module_refuses_bounds_outside_the_robot(irb120):
    with pytest.raises(LimitViolation, match=r"joint 2: bounds \[-55, 130\] deg leave the robot's range"):
        collection_module(
            lower_deg=[-120, -55, -100, -160, -120, -400],
            upper_deg=[120, 130, 40, 160, 120, 400],
            nominal=irb120.joint_ranges(),
            n_moves=10,
        )


def test_rapid_is_deterministic(irb120):
    a = collection_programs(irb120, n_moves=10, mode="table", seed=7)
    b = collection_programs(irb120, n_moves=10, mode="table", seed=7)
    c = collection_programs(irb120, n_moves=10, mode="table", seed=8)
    assert a == b and a["JPCollect.mod"] != c["JPCollect.mod"]


def test_measurement_module_writes_the_log_header():
    text = measurement_module()
    header = "".join(re.findall(r'Write logfile, "([^"]*)"', text))
    assert header == ",".join(LOG_COLUMNS)
    assert "WaitTime 0.025;" in text
    assert text.count("GetJointData") == 6
    assert text.count(", 5)") == len(LOG_COLUMNS)  # one NumToStr(value, 5) per column
