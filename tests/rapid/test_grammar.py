"""The grammar and the typed tree: RAPID text in, nodes with positions out (no interpretation)."""

from __future__ import annotations

import pytest

from joulepath.rapid import RapidError, nodes, parse_module, read_module_file
from joulepath.rapid._parse import decode

EVERY_CONSTRUCT = """MODULE Cell(SYSMODULE, NOSTEPIN)
  RECORD part
    num weight;
    robtarget grip;
  ENDRECORD
  ALIAS num counter;
  CONST robtarget p10 := [[400,0,300],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  LOCAL VAR num grid{2,3} := [[1,2,3],[4,5,6]];
  TASK PERS tooldata tGrip := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,50],[1,0,0,0],0,0,0]];
  VAR signaldi diExtra;
  PROC main()
    VAR num i;
    FOR i FROM 1 TO 3 STEP 1 DO
      MoveL Offs(p10, i*10, -5, 0), v100, z10, tGrip\\WObj:=wobj0;
      MoveJ p10,v100,fine,tGrip,\\WObj:=wobj0;
    ENDFOR
    IF DInput(di1) = 1 AND NOT bFlag THEN
      Pick \\Fast;
    ELSEIF a <> 2 THEN
      reg1 := reg1 + 1;
    ELSE
      grid{1,2} := 3 DIV 2 MOD 4;
    ENDIF
    IF reg1 > 3 reg1 := 0;
    TEST nState
      CASE 1, 2:
        %"Proc" + NumToStr(nState, 0)%;
      DEFAULT:
        Stop;
    ENDTEST
    WHILE TRUE DO
      lbl:
      GOTO lbl;
    ENDWHILE
    CONNECT intno1 WITH trReset;
    RETURN;
  ERROR
    IF ERRNO = ERR_X RETRY;
  UNDO
    Stop;
  ENDPROC
  FUNC robtarget Above(robtarget p, \\num dz | switch none)
    RETURN Offs(p, 0, 0, 10);
  ENDFUNC
  TRAP trReset
    reg2 := 0;
  ENDTRAP
ENDMODULE
"""


def test_every_construct_parses_into_typed_nodes():
    m = parse_module(EVERY_CONSTRUCT, path="cell.sys")
    assert m.name == "Cell" and m.system
    assert [r.name for r in m.records] == ["part"] and m.records[0].fields == (
        ("num", "weight"),
        ("robtarget", "grip"),
    )
    assert [a.name for a in m.aliases] == ["counter"]
    assert [d.name for d in m.data] == ["p10", "grid", "tGrip", "diExtra"]
    assert m.data[1].scope == "LOCAL" and len(m.data[1].dims) == 2
    kinds = {r.name: r.kind for r in m.routines}
    assert kinds == {"main": "PROC", "Above": "FUNC", "trReset": "TRAP"}
    main = m.routines[0]
    assert main.error is not None and main.undo is not None
    types = [type(s).__name__ for s in main.body]
    assert types == ["DataDecl", "For", "If", "If", "Test", "While", "Connect", "Return"]
    above = m.routines[1]
    assert above.type == "robtarget"
    assert [(p.name, p.optional, p.group) for p in above.params] == [
        ("p", False, 0),
        ("dz", True, 1),
        ("none", True, 1),
    ]
    loop = main.body[1]
    assert isinstance(loop, nodes.For)
    movel, movej = loop.body
    assert isinstance(movel, nodes.Call) and [a.kind for a in movel.args] == [
        "pos",
        "pos",
        "pos",
        "pos",
        "opt",
    ]
    assert isinstance(movej, nodes.Call) and [a.kind for a in movej.args] == [
        "pos",
        "pos",
        "pos",
        "pos",
        "opt",
    ]
    compact = main.body[3]
    assert isinstance(compact, nodes.If) and compact.compact


def test_positions_point_at_the_source_text():
    m = parse_module(EVERY_CONSTRUCT, path="cell.sys")
    loop = m.routines[0].body[1]
    assert isinstance(loop, nodes.For)
    movel = loop.body[0]
    assert movel.pos.line == 14
    assert m.text[movel.pos.start : movel.pos.end].startswith("MoveL Offs(p10")
    assert m.text[movel.pos.start : movel.pos.end].endswith(";")
    speed = movel.args[1]
    assert m.text[speed.pos.start : speed.pos.end] == "v100"


def test_operator_precedence():
    m = parse_module(
        "MODULE M\nPROC main()\nx := 1 + 2 * 3 - -4 / 2;\nb := a OR b AND NOT c = d;\nENDPROC\nENDMODULE\n"
    )
    x = m.routines[0].body[0]
    assert isinstance(x, nodes.Assign)
    top = x.value
    assert isinstance(top, nodes.BinOp) and top.op == "-"
    assert isinstance(top.a, nodes.BinOp) and top.a.op == "+" and isinstance(top.a.b, nodes.BinOp)
    b = m.routines[0].body[1]
    assert isinstance(b, nodes.Assign) and isinstance(b.value, nodes.BinOp) and b.value.op == "OR"
    rhs = b.value.b
    assert isinstance(rhs, nodes.BinOp) and rhs.op == "AND" and isinstance(rhs.b, nodes.Not)


def test_keywords_in_any_case_and_the_header_keeps_line_numbers():
    text = (
        "%%%\n  VERSION:1\n  LANGUAGE:ENGLISH\n%%%\n\n"
        "module m\n  proc MAIN()\n    waittime 1;\n  endproc\nendmodule\n"
    )
    m = parse_module(text)
    assert m.routines[0].name == "MAIN"
    assert m.routines[0].body[0].pos.line == 8


def test_latin1_and_crlf_are_decoded_and_remembered(tmp_path):
    text = "MODULE Hämta\r\n  PROC Hämta_Del()\r\n    WaitTime 1; ! vänta\r\n  ENDPROC\r\nENDMODULE\r\n"
    path = tmp_path / "h.mod"
    path.write_bytes(text.encode("latin-1"))
    m = read_module_file(path)
    assert m.encoding == "latin-1" and m.newline == "\r\n"
    assert m.routines[0].name == "Hämta_Del"
    assert "\r" not in m.text
    assert decode(b"ok\n")[1:] == ("utf-8", "\n")


@pytest.mark.parametrize(
    ("text", "line"),
    [
        ("MODULE M\nPROC main()\n  MoveJ p10 v100, fine, tool0;\nENDPROC\nENDMODULE\n", 3),
        ("MODULE M\nPROC main()\n  x := ;\nENDPROC\nENDMODULE\n", 3),
        ("MODULE M\nPROC main()\n  WaitTime 1;\n", 3),
        ("this is not RAPID\n", 1),
        ("MODULE M\nPROC main()\n  x := 1 # 2;\nENDPROC\nENDMODULE\n", 3),
    ],
)
def test_text_that_is_not_rapid_is_refused_with_its_line(text, line):
    with pytest.raises(RapidError) as err:
        parse_module(text, path="bad.mod")
    msg = str(err.value)
    assert msg.startswith(f"bad.mod:{line}:") and "\n" not in msg


def test_a_binary_file_is_refused(tmp_path):
    p = tmp_path / "x.mod"
    p.write_bytes(b"MODULE\x00\x01")
    with pytest.raises(RapidError, match="binary"):
        read_module_file(p)


def test_the_bundled_examples_parse():
    from pathlib import Path

    for f in sorted(Path("examples").glob("*.mod")):
        m = read_module_file(f)
        assert any(r.name.lower() == "main" for r in m.routines)
