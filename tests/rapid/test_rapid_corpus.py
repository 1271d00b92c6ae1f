"""The corpus of RAPID programs written the way integrators write them (tests/fixtures/rapid_corpus).

Each program folder has an ``expect.toml``: the task's modules, the I/O scenario, the routine, and
whether it is read (``ok``, with at least ``kept_at_least`` moves kept as taught) or refused in one
line naming what is wrong. Every program is read and interpreted, its cycle's targets checked against
the robot's ranges, its modules written back byte for byte and read again to the same motion; a
refused one exits 2 through the CLI with one line and no traceback.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.program import read_cycle_program
from joulepath.rapid import RapidError
from joulepath.rapid.interpreter import Interpreter, Motion
from joulepath.rapid.task import load_task
from joulepath.rapid.writer import original_bytes

ROOT = Path(__file__).parents[1] / "fixtures" / "rapid_corpus"
PROGRAMS = sorted(p for p in ROOT.iterdir() if p.is_dir())


def expect(folder: Path) -> dict:
    return tomllib.loads((folder / "expect.toml").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


def test_the_corpus_is_large_and_varied():
    assert len(PROGRAMS) >= 30
    outcomes = [expect(p)["outcome"] for p in PROGRAMS]
    assert outcomes.count("ok") >= 30 and outcomes.count("refused") >= 4


@pytest.mark.parametrize("folder", PROGRAMS, ids=lambda p: p.name)
def test_each_program_is_read_or_refused_as_expected(folder, robot):
    e = expect(folder)
    paths = [folder / p for p in e["program"]]
    if e["outcome"] == "refused":
        with pytest.raises(RapidError) as err:
            read_cycle_program(paths, robot, io=e.get("io"), routine=e.get("routine"))
        msg = str(err.value)
        assert e["refusal"] in msg and "\n" not in msg
        return
    spec, rapid = read_cycle_program(paths, robot, io=e.get("io"), routine=e.get("routine"))
    assert rapid
    moves = [s for s in spec.steps if s.kind == "move"]
    assert moves
    lo, hi = robot.joint_ranges()
    for s in moves:
        assert s.q is not None and np.all(s.q >= lo - 1e-9) and np.all(s.q <= hi + 1e-9)
    kept = [s for s in moves if s.kept]
    assert len(kept) >= e.get("kept_at_least", 0)
    assert len(spec.kept) == len(kept)
    for move, why in spec.kept:  # every kept move names where it stands and why
        assert ":" in move and ":" in why
    if not e.get("io") and e.get("kept_at_least", 0) == 0:
        assert not kept  # nothing in it depends on run-time data
    # a partial task: exactly the names it declares nowhere, each with the role the program gives it
    assert {a.name: a.role for a in spec.assumed} == e.get("assumed", {})


@pytest.mark.parametrize(
    "folder", [p for p in PROGRAMS if expect(p)["outcome"] == "ok"], ids=lambda p: p.name
)
def test_written_back_byte_for_byte_and_read_again_to_the_same_motion(folder, tmp_path):
    e = expect(folder)
    task = load_task([folder / p for p in e["program"]])
    for path, data in original_bytes(task).items():
        assert Path(path).read_bytes() == data
    first = Interpreter(task, io=e.get("io")).run(e.get("routine"))
    again = Interpreter(load_task([folder / p for p in e["program"]]), io=e.get("io")).run(e.get("routine"))
    a = [m.target for m in first.motions]
    b = [m.target for m in again.motions]
    assert a == b and all(isinstance(m, Motion) for m in first.motions)


@pytest.mark.parametrize(
    "folder", [p for p in PROGRAMS if expect(p)["outcome"] == "refused"], ids=lambda p: p.name
)
def test_refused_programs_exit_2_with_one_line(folder, tmp_path, capsys):
    e = expect(folder)
    argv = ["cycle", *[str(folder / p) for p in e["program"]], "--out", str(tmp_path / "out")]
    if e.get("routine"):
        argv += ["--routine", e["routine"]]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert e["refusal"] in err and "Traceback" not in err
    assert len(err.splitlines()) == 1
    assert not (tmp_path / "out").exists()
