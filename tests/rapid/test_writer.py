"""Writing back at source positions: unchanged bytes stay, only the edited statements change."""

from __future__ import annotations

import difflib

import pytest

from joulepath.rapid.interpreter import Interpreter
from joulepath.rapid.task import load_task
from joulepath.rapid.writer import (
    Edit,
    apply_edits,
    insert_before,
    original_bytes,
    replace_argument,
    set_optional,
)

MAIN = (
    "MODULE Hauptmodul\r\n"
    "  ! Zelle 3: Greifer wechseln, Teile ablegen (ä ö ü)\r\n"
    "  CONST robtarget pÜber := [[400,0,300],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\r\n"
    "  PROC main()\r\n"
    "    MoveJ pÜber, v1000, z50, tGreifer;   ! anfahren\r\n"
    "    MoveL Offs(pÜber,0,0,-100), v200, fine, tGreifer\\WObj:=wTisch;\r\n"
    "    MoveL pÜber, v200, z10, tGreifer;\r\n"
    "  ENDPROC\r\n"
    "ENDMODULE\r\n"
)
USER = (
    "MODULE Zelldaten(SYSMODULE)\n"
    "  PERS tooldata tGreifer := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,50],[1,0,0,0],0,0,0]];\n"
    '  PERS wobjdata wTisch := [FALSE,TRUE,"",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];\n'
    "ENDMODULE\n"
)


@pytest.fixture
def task(tmp_path):
    (tmp_path / "PROGMOD").mkdir()
    (tmp_path / "SYSMOD").mkdir()
    (tmp_path / "PROGMOD" / "Hauptmodul.mod").write_bytes(MAIN.encode("latin-1"))
    (tmp_path / "SYSMOD" / "user.sys").write_bytes(USER.encode("utf-8"))
    return load_task([tmp_path])


def test_no_edit_gives_every_byte_back(task):
    for m, data in original_bytes(task).items():
        with open(m, "rb") as f:
            assert f.read() == data


def test_only_the_edited_statements_change_and_read_back(task, tmp_path):
    trace = Interpreter(task).run()
    first, second, _ = trace.motions
    main = task.module_of(first.pos.file)
    assert main is not None
    edits = [
        replace_argument(first.stmt, 1, "v800"),
        set_optional(main, second.stmt, "V", "150", after=1),
        insert_before(main, second.stmt, "AccSet 60, 40;"),
    ]
    out = apply_edits(task, edits)
    old_text = MAIN.encode("latin-1").decode("latin-1").splitlines()
    new_text = out[main.path].decode("latin-1").splitlines()
    changed = [ln for ln in difflib.ndiff(old_text, new_text) if ln[:1] in "+-"]
    assert changed == [
        "-     MoveJ pÜber, v1000, z50, tGreifer;   ! anfahren",
        "+     MoveJ pÜber, v800, z50, tGreifer;   ! anfahren",
        "+     AccSet 60, 40;",
        "-     MoveL Offs(pÜber,0,0,-100), v200, fine, tGreifer\\WObj:=wTisch;",
        "+     MoveL Offs(pÜber,0,0,-100), v200 \\V:=150, fine, tGreifer\\WObj:=wTisch;",
    ]
    assert out[main.path].count(b"\r\n") == MAIN.count("\r\n") + 1  # line ends kept, one line added
    sysmod = next(m for m in task.modules if m.path != main.path)
    assert out[sysmod.path] == USER.encode()
    # read back: the interpreter sees the new values, and nothing else moved
    for m in task.modules:
        dest = tmp_path / "again" / m.path.split("/")[-2] / m.path.split("/")[-1]
        dest.parent.mkdir(parents=True, exist_ok=True)
        dest.write_bytes(out[m.path])
    again = Interpreter(load_task([tmp_path / "again"])).run()
    a, b, c = again.motions
    assert a.speed.get("v_tcp") == 800.0 and b.speed.get("v_tcp") == 150.0 and b.settings.acc_pct == 60.0
    assert [m.target for m in again.motions] == [m.target for m in trace.motions]


def test_overlapping_edits_are_refused(task):
    m = task.modules[0]
    with pytest.raises(ValueError, match="overlap"):
        apply_edits(task, [Edit(m.path, 10, 20, "x"), Edit(m.path, 15, 25, "y")])
