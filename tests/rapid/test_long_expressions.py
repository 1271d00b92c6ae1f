"""Long chains of operators: read where the reader can follow them, else refused in one line (never a
RecursionError)."""

from __future__ import annotations

import pytest

import joulepath
from joulepath.errors import RapidError
from joulepath.program import read_cycle_program
from joulepath.rapid import parse_module

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"


def _module(terms: int, where: str = "decl") -> str:
    chain = "1+" * terms + "1"
    decl = f"    CONST num x := {chain};\n" if where == "decl" else "    VAR num x := 0;\n"
    body = f"        x := {chain};\n" if where == "body" else ""
    return (
        f"MODULE P\n    CONST jointtarget jA := [[10, 0, 0, 0, 30, 0], {EXT}];\n"
        f"    CONST jointtarget jB := [[40, 20, -10, 15, 45, 30], {EXT}];\n{decl}"
        f"    PROC main()\n{body}        MoveAbsJ jA, v1000, fine, tool0;\n"
        "        MoveAbsJ jB, v1000, fine, tool0;\n    ENDPROC\nENDMODULE\n"
    )


def test_a_chain_of_a_thousand_terms_is_read_and_evaluated(tmp_path):
    module = parse_module(_module(1000))
    assert module.name == "P"
    path = tmp_path / "p.mod"
    path.write_text(_module(1000, "body"))
    spec, _ = read_cycle_program(path, joulepath.load_robot("irb120"))
    assert sum(s.kind == "move" for s in spec.steps) == 2


def test_a_chain_too_long_to_parse_is_refused_in_one_line():
    with pytest.raises(RapidError, match="chains more operators than this reader follows") as err:
        parse_module(_module(200_000), path="long.mod")
    assert str(err.value).startswith("long.mod:") and "\n" not in str(err.value)


def test_a_chain_too_deep_to_evaluate_is_refused_in_one_line(tmp_path):
    path = tmp_path / "p.mod"
    path.write_text(_module(6000, "body"))
    with pytest.raises(RapidError, match="runs deeper than this interpreter follows"):
        read_cycle_program(path, joulepath.load_robot("irb120"))
