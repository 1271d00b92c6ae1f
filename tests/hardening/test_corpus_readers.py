# ruff: noqa: E501  (the case table keeps one line per case)
"""The hostile-input corpus of the newer readers (issue 25, the input side).

Cycle programs (RAPID ``.mod`` and plain cycle ``.toml``), cells (``--cell``), twin
folders (``friction.json``) and meshes, through the real CLI. One line per case:
``(id, argv, expected exit code, message fragment, files)``, as in
``test_corpus.py``. Every case ends with valid output (exit 0, the fragment on
stdout), or exit 2 with exactly one line on stderr that holds the fragment, no
traceback, nothing written and the inputs unchanged. The classes:

* readers bounded and typed: folders, FIFOs, devices and sparse 3 GiB files refused
  by name before they are opened; integers beyond 64 bits and 5,000-digit numbers;
  TOML ``true`` where a number goes; nesting 3,000-5,000 deep (TOML arrays, RAPID
  aggregates, brackets, IF blocks) and 1,500 chained procedures;
* linear time: 30 procedures that each call the next twice; a 1 MB statement;
* work bounded before it starts: tiny speeds, ``\\T:=600``, ``WaitTime 3600`` with
  ``--use-waits``, ``--cycle-time 7200``, 10,002 moves, 10,002 cycle-TOML steps,
  20,000 boxes, a fly-by chain of 40 moves (solved as one move); each refused with one
  line naming the limit and its variable;
* crashes: two identical consecutive targets, a cycle that never moves, a RAPID
  module given to a 7-joint arm.

Files are written small (a sparse file costs no disk), so the whole table runs in
about a minute: every refusal comes before any optimization starts.
"""

from __future__ import annotations

import os
import shlex
from pathlib import Path
from typing import Any

import pytest

from joulepath.cli import main
from joulepath.description import preset_path

# --------------------------------------------------------------------------- literal inputs

JA = "[[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]]"
JB = "[[30, 10, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]]"
DECL = f"    CONST jointtarget jA := {JA};\n    CONST jointtarget jB := {JB};\n"
AB = ("MoveAbsJ jA, v1000, fine, tool0;", "MoveAbsJ jB, v1000, fine, tool0;")


def mod(*body: str, decl: str = DECL, procs: str = "") -> str:
    """A RAPID module: ``decl``, then ``PROC main()`` with ``body``, then ``procs``."""
    lines = "".join(f"        {b}\n" for b in body)
    return f"MODULE P\n{decl}    PROC main()\n{lines}    ENDPROC\n{procs}ENDMODULE\n"


def step(joints: str, duration: str) -> str:
    return f"[[step]]\njoints_deg = {joints}\nduration_s = {duration}\n"


CYCLE_TOML = step("[10, 0, 0, 0, 30, 0]", "1.0") + step("[0, 0, 0, 0, 30, 0]", "1.0")
CELL = '[[box]]\nname = "table"\ncenter_mm = [200, 0, -20]\nsize_mm = [1400, 1400, 40]\n'
CHAIN_1500 = (
    "".join(f"    PROC p{i}()\n        p{i + 1};\n    ENDPROC\n" for i in range(1500))
    + "    PROC p1500()\n        MoveAbsJ jB, v1000, fine, tool0;\n    ENDPROC\n"
)
DOUBLE_30 = (
    "".join(f"    PROC p{i}()\n        p{i + 1};\n        p{i + 1};\n    ENDPROC\n" for i in range(30))
    + '    PROC p30()\n        TPWrite "x";\n    ENDPROC\n'
)
FRICTION = (
    '{"format": "joulepath-friction/1", "twin_of": "irb120", "gear_efficiency": 0.9, "friction": '
    '{"coulomb": [1, 1, 1, 0.5, 0.5, 0.5], "viscous": [1, 1, 1, 0.5, 0.5, 0.5], "offset": [0, 0, 0, 0, 0, 0], '
    '"stribeck": [0, 0, 0, 0, 0, 0], "stribeck_speed": 0.05, "smoothing": 0.01}}'
)
TWIN = "@twin"  # files key: a twin folder {in}/tw (the bundled IRML and FRICTION), then the edits
SEVEN_URDF = "@seven"  # a 7-joint URDF arm
FIFO, SPARSE = "@fifo", "@sparse"  # a named pipe; a 3 GiB sparse file
STL900K = "@stl900k"  # a binary STL header of 900,000 triangles, the rest a hole (sparse)


def _seven_urdf() -> str:
    def joint(i: int) -> str:
        axis = "0 0 1" if i % 2 else "0 1 0"
        return (
            f'<link name="l{i}"><inertial><mass value="1.5"/><origin xyz="0 0 0.02" rpy="0 0 0"/>'
            f'<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="{axis}"/>'
            f'<limit lower="-3" upper="3" velocity="4" effort="50"/></joint>'
        )

    return (
        '<?xml version="1.0"?><robot name="seven"><link name="l0"/>'
        + "".join(joint(i) for i in range(1, 8))
        + '<link name="tool0"/><joint name="t" type="fixed"><parent link="l7"/><child link="tool0"/></joint></robot>'
    )


def _friction(old: str, new: str) -> dict[str, str]:
    assert old in FRICTION
    return {TWIN: "", "tw/friction.json": FRICTION.replace(old, new, 1)}


CYC = "cycle {in}/p.mod --out {out}"
CYT = "cycle {in}/c.toml --out {out}"
QUICK = "cycle {in}/p.mod --out {out} --export egm --table-points 2 --knot-spacing 0.1"
"""A cycle that is optimized, not refused: the quick settings (no lever search, a coarse table)."""
CELLCMD = "cycle {in}/p.mod --cell {in}/c.toml --out {out}"
SHOW_TWIN = "robot show {in}/tw"


def C(case_id: str, argv: str, rc: int, needle: str, files: dict[str, str] | None = None) -> Any:
    return pytest.param(argv, rc, needle, files or {}, id=case_id)


# fmt: off
CASES = [
    # ---- bounded reading: not a regular file, or too large, refused by name before it is opened
    C("mod-dev-zero", "cycle /dev/zero --out {out}", 2, "is a character device, not a regular file", {}),
    C("mod-fifo", CYC, 2, "is a FIFO (named pipe), not a regular file", {"p.mod": FIFO}),
    C("mod-folder", "cycle {in} --out {out}", 2, "the folder holds no RAPID module", {}),  # a folder is a task
    C("mod-sparse-3gib", CYC, 2, "larger than the 8 MiB accepted", {"p.mod": SPARSE}),
    C("cycle-toml-fifo", CYT, 2, "is a FIFO (named pipe)", {"c.toml": FIFO}),
    C("cycle-toml-sparse-3gib", CYT, 2, "larger than the 4 MiB accepted", {"c.toml": SPARSE}),
    C("cell-dev-zero", "cycle {in}/p.mod --cell /dev/zero --out {out}", 2, "/dev/zero: is a character device", {"p.mod": mod(*AB)}),
    C("cell-fifo", CELLCMD, 2, "is a FIFO (named pipe)", {"p.mod": mod(*AB), "c.toml": FIFO}),
    C("cell-folder", "cycle {in}/p.mod --cell {in} --out {out}", 2, "is a folder, not a regular file", {"p.mod": mod(*AB)}),
    C("cell-sparse-3gib", CELLCMD, 2, "larger than the 4 MiB accepted", {"p.mod": mod(*AB), "c.toml": SPARSE}),
    C("cell-urdf-fifo", "cycle {in}/p.mod --cell {in}/c.urdf --out {out}", 2, "is a FIFO (named pipe)", {"p.mod": mod(*AB), "c.urdf": FIFO}),
    C("cell-mesh-fifo", CELLCMD, 2, "not a regular file", {"p.mod": mod(*AB), "c.toml": '[[mesh]]\nname = "m"\nfile = "m.stl"\ncenter_mm = [0, 0, 0]\n', "m.stl": FIFO}),
    C("twin-friction-fifo", SHOW_TWIN, 2, "friction.json", {TWIN: "", "tw/friction.json": FIFO}),
    C("twin-friction-sparse-3gib", SHOW_TWIN, 2, "larger than the 1 MiB accepted", {TWIN: "", "tw/friction.json": SPARSE}),
    C("twin-friction-folder", SHOW_TWIN, 2, "friction.json", {TWIN: "", "tw/friction.json/x": "{}"}),
    # ---- numbers: beyond 64 bits, more digits than Python reads, booleans, non-finite
    C("cycle-toml-int-1e400", CYT, 2, "beyond 64 bits", {"c.toml": step("[10, 0, 0, 0, 30, 0]", "1" + "0" * 400) + CYCLE_TOML}),
    C("cycle-toml-int-5000-digits", CYT, 2, "more than 4,300 digits", {"c.toml": step("[10, 0, 0, 0, 30, 0]", "9" * 5000) + CYCLE_TOML}),
    C("cycle-toml-joint-1e400", CYT, 2, "beyond 64 bits", {"c.toml": step("[1" + "0" * 400 + ", 0, 0, 0, 30, 0]", "1") + CYCLE_TOML}),
    C("cycle-toml-duration-true", CYT, 2, "duration_s: must be a number", {"c.toml": step("[10, 0, 0, 0, 30, 0]", "true") + CYCLE_TOML}),
    C("cycle-toml-joint-true", CYT, 2, "not true/false", {"c.toml": step("[true, 0, 0, 0, 30, 0]", "1") + CYCLE_TOML}),
    C("cycle-toml-wait-true", CYT, 2, "wait_s: must be a number", {"c.toml": CYCLE_TOML + "[[step]]\nwait_s = true\n"}),
    C("cycle-toml-wait-inf", CYT, 2, "wait_s: must be a number", {"c.toml": CYCLE_TOML + "[[step]]\nwait_s = inf\n"}),
    C("cycle-toml-start-nan", CYT, 2, "start_deg", {"c.toml": "start_deg = [nan, 0, 0, 0, 30, 0]\n" + CYCLE_TOML}),
    C("cell-margin-true", CELLCMD, 2, "margin_mm: must be a number", {"p.mod": mod(*AB), "c.toml": "margin_mm = true\n" + CELL}),
    C("cell-margin-5000-digits", CELLCMD, 2, "more than 4,300 digits", {"p.mod": mod(*AB), "c.toml": "margin_mm = " + "9" * 5000 + "\n" + CELL}),
    C("cell-margin-int-1e400", CELLCMD, 2, "beyond 64 bits", {"p.mod": mod(*AB), "c.toml": "margin_mm = 1" + "0" * 400 + "\n" + CELL}),
    C("cell-center-true", CELLCMD, 2, "center_mm", {"p.mod": mod(*AB), "c.toml": CELL.replace("[200, 0, -20]", "[true, 0, -20]")}),
    C("cell-size-1e300", CELLCMD, 2, "size_mm", {"p.mod": mod(*AB), "c.toml": CELL.replace("[1400, 1400, 40]", "[1e300, 1400, 40]")}),
    C("cell-radius-true", CELLCMD, 2, "arm_radius_mm", {"p.mod": mod(*AB), "c.toml": "[robot]\narm_radius_mm = true\n" + CELL}),
    C("twin-coulomb-true", SHOW_TWIN, 2, "friction.coulomb", _friction('"coulomb": [1,', '"coulomb": [true,')),
    C("twin-coulomb-int-1e400", SHOW_TWIN, 2, "beyond 64 bits", _friction('"coulomb": [1,', '"coulomb": [1' + "0" * 400 + ",")),
    C("twin-coulomb-5000-digits", SHOW_TWIN, 2, "more than 4,300 digits", _friction('"coulomb": [1,', '"coulomb": [' + "9" * 5000 + ",")),
    C("twin-coulomb-nan", SHOW_TWIN, 2, "NaN is not a JSON number", _friction('"coulomb": [1,', '"coulomb": [NaN,')),
    C("twin-efficiency-true", SHOW_TWIN, 2, "gear_efficiency", _friction('"gear_efficiency": 0.9', '"gear_efficiency": true')),
    C("twin-stribeck-speed-true", SHOW_TWIN, 2, "stribeck_speed", _friction('"stribeck_speed": 0.05', '"stribeck_speed": true')),
    C("twin-friction-not-utf8", SHOW_TWIN, 2, "not UTF-8", {TWIN: "", "tw/friction.json": "\udcff{}"}),
    C("rapid-joint-1e999", CYC, 2, "1E999 is not a finite number", {"p.mod": mod(*AB, decl=DECL.replace("[[30, 10", "[[1E999, 10"))}),
    C("rapid-robtarget-1e999", CYC, 2, "1E999 is not a finite number", {"p.mod": mod(*AB, "MoveJ pX, v1000, fine, tool0;", decl=DECL + "    CONST robtarget pX := [[1E999, 0, 630], [0.5, 0, 0.866025, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];\n")}),
    C("rapid-wait-overflow", CYC, 2, "not a finite number", {"p.mod": mod(*AB, "WaitTime 1E300 * 1E300;")}),
    C("rapid-div-overflow", CYC, 2, "not a finite number", {"p.mod": mod(*AB, "WaitTime 1E300 * 1E300 DIV 2;")}),
    C("rapid-div-fraction", CYC, 2, "DIV needs whole numbers", {"p.mod": mod(*AB, "WaitTime 0.1 DIV 0.5;")}),
    C("rapid-speed-v-1e999", CYC, 2, "not a finite number", {"p.mod": mod(AB[0], "MoveAbsJ jB, v1000\\V:=1E999, fine, tool0;")}),
    # ---- nesting
    C("cycle-toml-nested-3000", CYT, 2, "nested more than 32 deep", {"c.toml": "start_deg = " + "[" * 3000 + "]" * 3000 + "\n" + CYCLE_TOML}),
    C("cycle-toml-nested-40", CYT, 2, "nested more than 32 deep", {"c.toml": "start_deg = " + "[" * 40 + "]" * 40 + "\n" + CYCLE_TOML}),
    C("cell-nested-3000", CELLCMD, 2, "nested more than 32 deep", {"p.mod": mod(*AB), "c.toml": "margin_mm = " + "[" * 3000 + "]" * 3000 + "\n"}),
    C("cell-inline-tables-3000", CELLCMD, 2, "nested more than 32 deep", {"p.mod": mod(*AB), "c.toml": "robot = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n"}),
    C("twin-nested-5000", SHOW_TWIN, 2, "nested more than 32 deep", _friction('"twin_of": "irb120"', '"twin_of": ' + "[" * 5000 + "]" * 5000)),
    C("rapid-aggregate-5000-deep", CYC, 2, "brackets nested more than 32 deep", {"p.mod": mod(*AB, decl=DECL + "    CONST jointtarget jX := " + "[" * 5000 + "1" + "]" * 5000 + ";\n")}),
    C("rapid-parens-5000-deep", CYC, 2, "nested more than 32 deep", {"p.mod": mod(*AB, "WaitTime " + "(" * 5000 + "1" + ")" * 5000 + ";")}),
    C("rapid-signs-5000-deep", CYC, 2, "nested more than 32 deep", {"p.mod": mod(*AB, "WaitTime " + "-" * 5000 + "1;")}),
    C("rapid-if-2000-deep", CYC, 2, "blocks and calls nest more than 32 deep", {"p.mod": mod(AB[0], *["IF TRUE THEN"] * 2000, AB[1], *["ENDIF"] * 2000)}),
    C("rapid-1500-chained-procedures", CYC, 2, "calls nest more than 128 deep", {"p.mod": mod(AB[0], "p0;", procs=CHAIN_1500)}),
    C("rapid-1500-chained-recursive", CYC, 2, "calls nest more than 128 deep", {"p.mod": mod(AB[0], "p0;", procs=CHAIN_1500.replace("MoveAbsJ jB, v1000, fine, tool0;", "p0;"))}),
    C("rapid-recursion", CYC, 2, "calls itself", {"p.mod": mod(AB[0], "p0;", procs="    PROC p0()\n        p1;\n    ENDPROC\n    PROC p1()\n        p0;\n    ENDPROC\n")}),
    # ---- linear time
    C("rapid-30-procedures-each-call-the-next-twice", CYC, 2, "more than 200000 statements", {"p.mod": mod(*AB, "p0;", procs=DOUBLE_30)}),
    C("rapid-30-procedures-with-arguments-twice", CYC, 2, "more than 200000", {"p.mod": mod(*AB, "p0 1;", procs=DOUBLE_30.replace("()", "(num x)").replace("p30(num x)", "p30(num x)\n        MoveAbsJ jA, v1000, fine, tool0;").replace(";\n", " x;\n").replace("TPWrite \"x\" x;", "TPWrite \"x\";").replace("tool0 x;", "tool0;"))}),
    C("rapid-1mb-multiline-statement", "simulate --program {in}/p.mod --out {out}/a.csv", 2, "chains more operators", {"p.mod": mod(*AB, decl=DECL + "    CONST num x := " + "1 +\n" * 200_000 + "1;\n")}),
    C("rapid-1mb-statement", "simulate --program {in}/p.mod --out {out}/a.csv", 2, "chains more operators", {"p.mod": mod(*AB, decl=DECL + "    CONST num x := " + "1+" * 500_000 + "1;\n")}),
    # ---- work bounded before it starts (each names its limit and the variable that changes it)
    C("rapid-tiny-v", CYC, 2, "JOULEPATH_MAX_MOTION_S", {"p.mod": mod(AB[0], "MoveAbsJ jB, v1000\\V:=0.0001, fine, tool0;")}),
    C("rapid-speeddata-1e-9", CYC, 2, "JOULEPATH_MAX_MOTION_S", {"p.mod": mod(AB[0], "MoveAbsJ jB, vs, fine, tool0;", decl=DECL + "    CONST speeddata vs := [1e-9, 1e-9, 1e-9, 1e-9];\n")}),
    C("rapid-T4000", CYC, 2, "JOULEPATH_MAX_MOTION_S", {"p.mod": mod(AB[0], "MoveAbsJ jB, v1000\\T:=4000, fine, tool0;")}),
    # a unit over the move_s limit is kept as taught and said, not refused (issue 47, item 6)
    C("rapid-T60", QUICK, 0, "longer than the 10 s one optimized unit may take", {"p.mod": mod(AB[0], "MoveAbsJ jB, v1000\\T:=60, fine, tool0;")}),
    C("cycle-toml-duration-60", CYT + " --table-points 2 --knot-spacing 0.1", 0, "longer than the 10 s one optimized unit may take", {"c.toml": step("[10, 0, 0, 0, 30, 0]", "60") + CYCLE_TOML}),
    C("cell-mesh-900k-triangles", CELLCMD, 2, "JOULEPATH_MAX_TRIANGLES", {"p.mod": mod(*AB), "c.toml": '[[mesh]]\nname = "m"\nfile = "m.stl"\ncenter_mm = [0, 0, 0]\n', "m.stl": STL900K}),
    C("rapid-wait-3600-use-waits", CYC + " --use-waits", 2, "JOULEPATH_MAX_MOTION_S", {"p.mod": mod(*AB, "WaitTime 3600; ! joulepath: idle")}),
    C("rapid-cycle-time-7200", CYC + " --cycle-time 7200", 2, "under 3600 (an hour)", {"p.mod": mod(*AB)}),
    C("rapid-10002-moves", CYC, 2, "JOULEPATH_MAX_MOVES", {"p.mod": mod(*(AB * 5001))}),
    C("cycle-toml-10002-steps", CYT, 2, "JOULEPATH_MAX_MOVES", {"c.toml": CYCLE_TOML * 5001}),
    C("rapid-fly-by-chain-over-move-s", QUICK, 0, "longer than the 10 s one optimized unit may take", {"p.mod": mod(*[a.replace("fine", "z10") for a in AB * 20])}),
    C("cell-20000-boxes", CELLCMD, 2, "JOULEPATH_MAX_OBSTACLES", {"p.mod": mod(*AB), "c.toml": "".join(CELL.replace('"table"', f'"b{i}"') for i in range(20000))}),
    C("simulate-tiny-v", "simulate --program {in}/p.mod --out {out}/a.csv", 2, "JOULEPATH_MAX_MOTION_S", {"p.mod": mod(AB[0], "MoveAbsJ jB, v1000\\V:=0.0001, fine, tool0;")}),
    # ---- crashes
    C("rapid-same-target-twice-simulate", "simulate --program {in}/p.mod --out {out}/a.csv", 0, "3 moves", {"p.mod": mod(*AB, AB[1])}),
    C("rapid-never-moves", CYC, 2, "does not move the arm", {"p.mod": mod(AB[1])}),
    C("cycle-toml-never-moves", CYT, 2, "does not move the arm", {"c.toml": step("[0, 0, 0, 0, 30, 0]", "1") * 2}),
    C("rapid-7-joint-arm", CYC + " --robot {in}/r.urdf", 2, "this robot has 7 joints", {"p.mod": mod(*AB), "r.urdf": SEVEN_URDF}),
    C("simulate-7-joint-arm", "simulate --program {in}/p.mod --robot {in}/r.urdf --out {out}/a.csv", 2, "this robot has 7 joints", {"p.mod": mod(*AB), "r.urdf": SEVEN_URDF}),
]
# fmt: on


def _write_inputs(files: dict[str, str], inp: Path) -> None:
    if TWIN in files:
        (inp / "tw").mkdir()
        (inp / "tw" / "robot.irml").write_bytes(preset_path("irb120").read_bytes())
        (inp / "tw" / "friction.json").write_text(FRICTION)
    for name, data in files.items():
        if name == TWIN:
            continue
        path = inp / name
        for old in (path, path.parent):
            if old.is_file():
                old.unlink()
        path.parent.mkdir(parents=True, exist_ok=True)
        if data == FIFO:
            os.mkfifo(path)
        elif data == SPARSE:
            with path.open("wb") as fh:
                fh.truncate(3 << 30)  # no disk used: a hole of 3 GiB
        elif data == STL900K:
            with path.open("wb") as fh:
                fh.write(b"joulepath corpus".ljust(80) + (900_000).to_bytes(4, "little"))
                fh.truncate(84 + 50 * 900_000)
        elif data == SEVEN_URDF:
            path.write_text(_seven_urdf())
        else:
            path.write_bytes(data.encode("utf-8", "surrogateescape"))


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() if p.stat().st_size < 1 << 20 else b"<large>"
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_corpus_readers_cases_are_distinct():
    ids = [c.id for c in CASES]
    assert len(ids) == len(set(ids)) and len(ids) >= 60, len(ids)
    inputs = [(c.values[0], repr(sorted(c.values[3].items()))) for c in CASES]
    assert len(set(inputs)) == len(inputs), "two cases with the same input"


@pytest.mark.parametrize(("template", "rc", "needle", "files"), CASES)
def test_hostile_reader_input(template, rc, needle, files, tmp_path, capsys, monkeypatch):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    _write_inputs(files, inp)
    before = _snapshot(inp)
    monkeypatch.chdir(tmp_path)
    argv = [p.replace("{in}", str(inp)).replace("{out}", str(out)) for p in shlex.split(template)]
    code = main(argv)
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    assert code == rc, (code, captured.err[-2000:])
    if rc == 2:
        lines = captured.err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), captured.err[-2000:]
        assert needle in lines[0], lines[0]
        assert len(lines[0]) < 1000, "the line repeats the hostile input"
        assert not out.exists(), sorted(str(p) for p in out.rglob("*"))
        assert _snapshot(inp) == before, "an input was changed"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]
    else:
        assert needle in captured.out


def test_work_limit_is_changed_by_its_variable(tmp_path, capsys, monkeypatch):
    """JOULEPATH_MAX_MOVES=1 refuses a two-move cycle that the default limit accepts as far as reading."""
    (tmp_path / "p.mod").write_text(mod(*AB))
    monkeypatch.setenv("JOULEPATH_MAX_MOVES", "1")
    code = main(["cycle", str(tmp_path / "p.mod"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and "2 moves in one cycle, over the limit of 1" in err, err
    monkeypatch.setenv("JOULEPATH_MAX_MOVES", "many")
    code = main(["cycle", str(tmp_path / "p.mod"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and "JOULEPATH_MAX_MOVES='many': give a positive number" in err, err
