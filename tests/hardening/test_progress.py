"""Long but legal work shows progress on stderr, and stdout keeps the results alone (issue 25).

Each input sits at a work limit lowered through its ``JOULEPATH_MAX_*`` variable, so the
tests stay small; ``JOULEPATH_PROGRESS_S=0`` prints every message, so nothing here waits
for a clock. The rate limit itself is tested with a fake clock.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from joulepath.cli import main
from joulepath.cli._common import PROGRESS_ENV, ProgressLines, progress_interval
from joulepath.errors import InvalidInput
from joulepath.program import read_cycle_program
from joulepath.program._cell import read_cell

JOINTS = ("[0, 0, 0, 0, 30, 0]", "[20, 10, 0, 0, 30, 0]")
NEVER = "1e9"
"""A progress interval no test reaches: no progress line at all."""


def _module(n_moves: int) -> str:
    decl = "".join(
        f"    CONST jointtarget j{k} := [{q}, [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];\n"
        for k, q in enumerate(JOINTS)
    )
    body = "".join(f"        MoveAbsJ j{k % 2}, v1000, fine, tool0;\n" for k in range(n_moves))
    return f"MODULE Long\n{decl}    PROC main()\n{body}    ENDPROC\nENDMODULE\n"


def _boxes(n: int) -> str:
    """``n`` small boxes beyond the robot's reach (every move clears them)."""
    return "".join(
        f'[[box]]\nname = "b{k}"\ncenter_mm = [{1500 + 10 * k}, 0, 0]\nsize_mm = [5, 5, 5]\n'
        for k in range(n)
    )


def _tetra_stl(path: Path) -> None:
    """A binary STL of the 4 faces of a small tetrahedron (m)."""
    v = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]], dtype="<f4")
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    rec = np.zeros(
        len(faces), dtype=[("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")]
    )
    rec["vertices"] = v[np.array(faces)]
    path.write_bytes(b"tetra".ljust(80) + len(faces).to_bytes(4, "little") + rec.tobytes())


def _progress(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("[") and " s] " in line]


def test_progress_lines_at_most_one_per_interval(capsys):
    now = [100.0]
    say = ProgressLines(1.0, clock=lambda: now[0])
    for k in range(30):  # 30 messages over 3.75 s: one line per second, none in the first second
        say(f"message {k}")
        now[0] += 0.125
    err = capsys.readouterr()
    assert err.out == ""
    lines = err.err.splitlines()
    assert lines == ["[1 s] message 8", "[2 s] message 16", "[3 s] message 24"], lines
    assert say.printed == 3


def test_progress_lines_every_message_at_interval_zero(capsys):
    say = ProgressLines(0.0)
    for k in range(3):
        say(f"m{k}")
    assert [line.split("] ", 1)[1] for line in capsys.readouterr().err.splitlines()] == ["m0", "m1", "m2"]


def test_progress_interval_from_its_variable(monkeypatch):
    monkeypatch.delenv(PROGRESS_ENV, raising=False)
    assert progress_interval() == 1.0
    monkeypatch.setenv(PROGRESS_ENV, "0.25")
    assert progress_interval() == 0.25
    for bad in ("-1", "nan", "often"):
        monkeypatch.setenv(PROGRESS_ENV, bad)
        with pytest.raises(InvalidInput, match=f"{PROGRESS_ENV}=.*give a number of seconds"):
            progress_interval()


def test_read_cell_tells_each_obstacle_and_mesh(tmp_path):
    _tetra_stl(tmp_path / "m.stl")
    (tmp_path / "c.toml").write_text(
        _boxes(3) + '[[mesh]]\nname = "m"\nfile = "m.stl"\ncenter_mm = [1500, 500, 0]\n'
    )
    told: list[str] = []
    cell = read_cell(tmp_path / "c.toml", progress=told.append)
    assert len(cell.obstacles) == 4
    assert [t for t in told if t.startswith("reading the cell")] == [
        "reading the cell: box 1/3",
        "reading the cell: box 2/3",
        "reading the cell: box 3/3",
        "reading the cell: mesh 1/1",
    ]
    assert any("building the collision model of mesh m.stl (4 triangles)" in t for t in told), told
    assert read_cell(tmp_path / "c.toml").obstacles == cell.obstacles  # the same cell without a callback


def test_read_cycle_program_tells_each_move(tmp_path, irb120):
    (tmp_path / "p.mod").write_text(_module(5))
    told: list[str] = []
    spec, rapid = read_cycle_program(tmp_path / "p.mod", irb120, progress=told.append)
    assert rapid and sum(s.kind == "move" for s in spec.steps) == 5
    assert told == [f"reading {tmp_path / 'p.mod'}: move {k}/5" for k in range(1, 6)]


def _run(
    argv: list[str], capsys: pytest.CaptureFixture[str], interval: str, monkeypatch
) -> tuple[int, str, str]:
    monkeypatch.setenv(PROGRESS_ENV, interval)
    code = main(argv)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cycle_with_a_cell_at_the_obstacle_limit_shows_progress(tmp_path, capsys, monkeypatch):
    n = 60
    monkeypatch.setenv("JOULEPATH_MAX_OBSTACLES", str(n))  # the cell is at the limit
    prog, cell, out = tmp_path / "c.toml", tmp_path / "cell.toml", tmp_path / "out"
    prog.write_text("".join(f"[[step]]\njoints_deg = {q}\nduration_s = 1.0\n" for q in JOINTS))
    cell.write_text(_boxes(n))
    argv = ["cycle", str(prog), "--cell", str(cell), "--out", str(out), "--knot-spacing", "0.1"]
    argv += ["--table-points", "2"]
    code, quiet_out, quiet_err = _run(argv, capsys, NEVER, monkeypatch)
    assert code == 0 and quiet_err == "", quiet_err
    shutil.rmtree(out)
    code, shown_out, shown_err = _run(argv, capsys, "0", monkeypatch)
    assert code == 0
    assert shown_out == quiet_out  # progress never reaches stdout
    lines = _progress(shown_err)
    assert lines == shown_err.splitlines(), "stderr holds progress lines only"
    said = [line.split("] ", 1)[1] for line in lines]
    assert [s for s in said if s.startswith("reading the cell")] == [
        f"reading the cell: box {k}/{n}" for k in range(1, n + 1)
    ]
    for phase in ("c.toml: step 2/2", "clearance of the taught cycle to the cell: move 2/2"):
        assert any(s.endswith(phase) for s in said), (phase, said)
    assert "unit 2/2: reshaping its taught motion" in said and "sharing the cycle time" in said
    assert any(s.startswith("unit 2/2: solving") for s in said)
    assert said[-1].startswith(f"writing {out}")


def test_simulate_program_at_the_moves_limit_shows_progress_when_stderr_is_no_terminal(tmp_path):
    n = 40
    prog = tmp_path / "p.mod"
    prog.write_text(_module(n))
    env = {**os.environ, "JOULEPATH_MAX_MOVES": str(n), "OMP_NUM_THREADS": "1"}
    runs = {}
    for interval in ("0", NEVER):
        out = tmp_path / f"a{interval}.csv"
        argv = [sys.executable, "-m", "joulepath", "simulate", "--program", str(prog), "--out", str(out)]
        done = subprocess.run(
            argv,
            env={**env, PROGRESS_ENV: interval},
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert done.returncode == 0, done.stderr[-2000:]
        runs[interval] = (done.stdout.replace(str(out), "OUT"), done.stderr, out.read_bytes())
    (shown_out, shown_err, shown_log), (quiet_out, quiet_err, quiet_log) = runs["0"], runs[NEVER]
    assert quiet_err == "" and shown_out == quiet_out and shown_log == quiet_log
    said = [line.split("] ", 1)[1] for line in _progress(shown_err)]
    assert len(said) == len(shown_err.splitlines())
    assert [s for s in said if s.startswith("planning")] == [
        f"planning the taught cycle: move {k}/{n}" for k in range(1, n + 1)
    ]
    assert said[-1].startswith("running ") and said[-1].endswith("of motion on the lab plant")
