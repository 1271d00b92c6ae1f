"""Fuzzing the newer readers (issue 25): cycle TOML, cell TOML, twin folder, RAPID module.

Any input gives a valid result or a :class:`~joulepath.errors.JoulepathError`, never
another exception (no RecursionError, OverflowError, ValueError from int parsing,
ZeroDivisionError, broadcast error). The examples include the sizes that exposed the
defects: nesting 1,000-5,000 deep, integers of 400-5,000 digits, ``true`` where a
number goes, chains of 1,500 procedures, a 1 MB statement. ``derandomize`` keeps
``make test`` repeatable; the examples are bounded so the file runs in about a minute.
"""

from __future__ import annotations

import json
import math
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import joulepath
from joulepath.description import preset_path
from joulepath.dynamics._calibration import read_calibration
from joulepath.errors import JoulepathError
from joulepath.program import parse_module, read_cycle_toml, resolve_module
from joulepath.program._cell import read_cell

FEW = settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])

IRB120 = joulepath.load_robot("irb120")

CYCLE = b"""start_deg = [0, 0, 0, 0, 30, 0]
[[step]]
joints_deg = [60, 20, 10, 0, 40, 0]
duration_s = 0.9
[[step]]
wait_s = 0.3
[[step]]
joints_deg = [0, 0, 0, 0, 30, 0]
duration_s = 1.0
"""
CELL = b"""margin_mm = 20
[robot]
arm_radius_mm = 55
[[box]]
name = "table"
center_mm = [200, 0, -20]
size_mm = [1400, 1400, 40]
rpy_deg = [0, 0, 10]
[[cylinder]]
name = "post"
center_mm = [-350, -400, 600]
radius_mm = 40
length_mm = 1200
[[sphere]]
name = "ball"
center_mm = [0, 500, 300]
radius_mm = 50
"""
FRICTION: dict[str, Any] = {
    "format": "joulepath-friction/1",
    "twin_of": "irb120",
    "gear_efficiency": 0.9,
    "friction": {
        "coulomb": [1.0, 1.0, 1.0, 0.5, 0.5, 0.5],
        "viscous": [1.0, 1.0, 1.0, 0.5, 0.5, 0.5],
        "offset": [0.0] * 6,
        "stribeck": [0.0] * 6,
        "stribeck_speed": 0.05,
        "smoothing": 0.01,
    },
}
MODULE = """MODULE P
    CONST jointtarget jA := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget jB := [[30, 10, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pA := [[374, 0, 630], [0.5, 0, 0.866025, 0], [0, 0, 0, 0],
        [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num n := 2;
    PROC main()
        MoveAbsJ jA, v1000, fine, tool0;
        WHILE TRUE DO
            MoveAbsJ jB, v500, z10, tool0;
            MoveJ pA, v1000, fine, tool0;
            WaitTime 0.5;
            Go;
        ENDWHILE
    ENDPROC
    PROC Go()
        FOR k FROM 1 TO n DO
            MoveAbsJ jA, v1000, z20, tool0;
        ENDFOR
    ENDPROC
ENDMODULE
"""

NUMBERS = [
    "1" + "0" * 400,  # 1e400 written as an integer
    "9" * 5000,  # more digits than Python converts
    "-" + "9" * 19,  # just beyond 64 bits
    "9223372036854775807",
    "true",
    "false",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "1e-300",
    "0",
    "-0.0",
    '"1"',
    "[]",
    "{}",
    "1979-05-27",
]


def _deep(depth: int, kind: str) -> str:
    if kind == "array":
        return "[" * depth + "]" * depth
    return "{a = " * depth + "1" + "}" * depth


def _or_error(call: Callable[[], object]) -> object:
    try:
        return call()
    except JoulepathError:
        return None


def _in_file(data: bytes, name: str) -> tuple[tempfile.TemporaryDirectory[str], Path]:
    folder = tempfile.TemporaryDirectory()
    path = Path(folder.name) / name
    path.write_bytes(data)
    return folder, path


@st.composite
def toml_value_swapped(draw: Any, base: bytes) -> bytes:
    """``base`` with the value of one ``key = value`` line (or one list item) swapped for a hostile one."""
    lines = base.decode().splitlines()
    k = draw(st.sampled_from([i for i, line in enumerate(lines) if " = " in line]))
    key, value = lines[k].split(" = ", 1)
    new = draw(
        st.sampled_from(NUMBERS)
        | st.builds(_deep, st.sampled_from([40, 1000, 3000]), st.sampled_from(["array", "table"]))
        | st.text(alphabet="0123456789.eE+-_[], truefalsn", max_size=20)
    )
    if value.startswith("[") and draw(st.booleans()):  # one item of a list
        items = value.strip("[]").split(",")
        items[draw(st.integers(0, len(items) - 1))] = new
        new = "[" + ",".join(items) + "]"
    lines[k] = f"{key} = {new}"
    return ("\n".join(lines) + "\n").encode()


@st.composite
def mutated(draw: Any, base: bytes) -> bytes:
    data = bytearray(base)
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(data)))
        j = draw(st.integers(i, min(len(data), i + 30)))
        data[i:j] = draw(st.binary(max_size=20) | st.sampled_from([n.encode() for n in NUMBERS]))
    return bytes(data)


# --------------------------------------------------------------------------- cycle TOML


@FEW
@given(toml_value_swapped(CYCLE) | mutated(CYCLE))
def test_read_cycle_toml_any_bytes_gives_a_cycle_or_joulepath_error(data):
    folder, path = _in_file(data, "c.toml")
    with folder:
        spec = _or_error(lambda: read_cycle_toml(path, IRB120))
    if spec is not None:
        for s in spec.steps:
            assert s.kind != "move" or (np.all(np.isfinite(s.q)) and 0 < s.time_s <= 60)
            assert s.kind != "wait" or (math.isfinite(s.seconds) and 0 <= s.seconds <= 3600)


@pytest.mark.parametrize("n_steps", [10_001, 20_000])  # the moves limit: 10,000 (joulepath._work)
def test_read_cycle_toml_many_steps_is_refused_before_reading_them(n_steps):
    data = b"[[step]]\njoints_deg = [10, 0, 0, 0, 30, 0]\nduration_s = 1\n" * n_steps
    folder, path = _in_file(data, "c.toml")
    with folder, pytest.raises(JoulepathError, match="JOULEPATH_MAX_MOVES"):
        read_cycle_toml(path, IRB120)


# --------------------------------------------------------------------------- cell TOML


@FEW
@given(toml_value_swapped(CELL) | mutated(CELL))
def test_read_cell_any_bytes_gives_a_cell_or_joulepath_error(data):
    folder, path = _in_file(data, "c.toml")
    with folder:
        cell = _or_error(lambda: read_cell(path))
    if cell is not None:
        assert 0 <= cell.margin <= 1.0
        for ob in cell.obstacles:
            assert all(math.isfinite(v) for v in (*ob.center, *ob.size))


# --------------------------------------------------------------------------- twin folder


def _swap(doc: Any, path: tuple[Any, ...], value: Any) -> Any:
    out = json.loads(json.dumps(doc))
    node = out
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return out


JSON_VALUES = st.sampled_from(
    [True, False, None, "x", [], {}, 10**400, -(10**30), 1e308, -1.0, 0, 2**63, [[[[1]]]]]
) | st.recursive(st.integers(-3, 3), lambda inner: st.lists(inner, max_size=3), max_leaves=8)
JSON_PATHS = st.sampled_from(
    [
        ("gear_efficiency",),
        ("twin_of",),
        ("friction", "coulomb"),
        ("friction", "coulomb", 0),
        ("friction", "viscous", 5),
        ("friction", "offset", 2),
        ("friction", "stribeck_speed"),
        ("friction", "smoothing"),
    ]
)


@st.composite
def friction_json(draw: Any) -> bytes:
    kind = draw(st.sampled_from(["swap", "deep", "digits", "bytes"]))
    if kind == "swap":
        return json.dumps(_swap(FRICTION, draw(JSON_PATHS), draw(JSON_VALUES))).encode()
    if kind == "deep":
        depth = draw(st.sampled_from([33, 1000, 5000]))
        return json.dumps(FRICTION).replace('"irb120"', "[" * depth + "]" * depth).encode()
    if kind == "digits":
        digits = draw(st.sampled_from([20, 400, 4301, 5000]))
        return json.dumps(FRICTION).replace("0.05", "9" * digits).encode()
    return draw(mutated(json.dumps(FRICTION).encode()))


@FEW
@given(friction_json())
def test_read_calibration_any_friction_json_gives_a_calibration_or_joulepath_error(data):
    folder, path = _in_file(data, "friction.json")
    with folder:
        cal = _or_error(lambda: read_calibration(path, 6))
    if cal is not None:
        values = (*cal.friction.coulomb, *cal.friction.viscous, cal.friction.stribeck_speed)
        assert all(math.isfinite(v) for v in values)
        assert 0 < cal.gear_efficiency <= 1


@FEW
@given(friction_json())
def test_load_robot_any_twin_folder_gives_a_robot_or_joulepath_error(data):
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        (folder / "robot.irml").write_bytes(preset_path("irb120").read_bytes())
        (folder / "friction.json").write_bytes(data)
        _or_error(lambda: joulepath.load_robot(folder))


# --------------------------------------------------------------------------- RAPID


@st.composite
def rapid_module(draw: Any) -> str:
    kind = draw(st.sampled_from(["aggregate", "parens", "if", "chain", "double", "statement", "bytes"]))
    depth = draw(st.sampled_from([31, 33, 1000, 5000]))
    if kind == "aggregate":
        return MODULE.replace(
            "[[30, 10, 0, 0, 30, 0]", "[" * depth + "[30, 10, 0, 0, 30, 0]" + "]" * (depth - 1)
        )
    if kind == "parens":
        return MODULE.replace("WaitTime 0.5", "WaitTime " + "(" * depth + "0.5" + ")" * depth)
    if kind == "if":
        return MODULE.replace("Go;", "IF TRUE THEN\n" * depth + "Go;\n" + "ENDIF\n" * depth)
    if kind == "chain":
        n = draw(st.sampled_from([30, 40, 1500]))
        procs = "".join(f"    PROC c{i}()\n        c{i + 1};\n    ENDPROC\n" for i in range(n))
        procs += f"    PROC c{n}()\n        MoveAbsJ jB, v1000, fine, tool0;\n    ENDPROC\n"
        return MODULE.replace("Go;", "c0;").replace("ENDMODULE", procs + "ENDMODULE")
    if kind == "double":
        procs = "".join(
            f"    PROC d{i}()\n        d{i + 1};\n        d{i + 1};\n    ENDPROC\n" for i in range(30)
        )
        procs += "    PROC d30()\n        MoveAbsJ jB, v1000, z10, tool0;\n    ENDPROC\n"
        return MODULE.replace("Go;", "d0;").replace("ENDMODULE", procs + "ENDMODULE")
    if kind == "statement":
        n = draw(st.sampled_from([1000, 100_000, 500_000]))
        sep = draw(st.sampled_from(["+", "+\n"]))
        return MODULE.replace("CONST num n := 2;", "CONST num n := " + f"1{sep}" * n + "1;")
    return draw(mutated(MODULE.encode())).decode("latin-1")


@settings(max_examples=30, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(rapid_module())
def test_parse_and_resolve_any_module_gives_a_cycle_or_joulepath_error(text):
    module = _or_error(lambda: parse_module(text, path="fuzz.mod"))
    if module is not None:
        _or_error(lambda: resolve_module(module, IRB120))
