"""The interpreter's layout (issue 46, item 5): it dispatches by node type through tables, in the way of
:class:`ast.NodeVisitor`, with statements, expressions, built-ins and motion each in a module of their
own, and no class or function of ``rapid/`` grows past its bound."""

import ast
import dataclasses
import importlib
import inspect
import typing
from pathlib import Path

from joulepath.rapid import RapidError, builtins, parse_module, read_module_file
from joulepath.rapid import nodes as n
from joulepath.rapid._expressions import EXPRESSIONS
from joulepath.rapid._functions import FUNCTIONS, UNEVALUATED
from joulepath.rapid._instructions import INSTRUCTIONS
from joulepath.rapid._machine import Machine
from joulepath.rapid._motion import MOTIONS, motion
from joulepath.rapid._statements import CALLS, STATEMENTS
from joulepath.rapid._vocabulary import ALL_MOTIONS, INPUT_WRITERS, KNOWN_INSTRUCTIONS
from joulepath.rapid.interpreter import Interpreter

RAPID = Path(n.__file__).parent
CORPUS = Path(__file__).parents[1] / "fixtures" / "rapid_corpus"
STRUCTURE = {n.Pos, n.Arg, n.Param, n.Routine, n.RecordDef, n.Alias, n.Module}
"""Node classes that are the task's structure, not run by a handler."""
HANDLED = set(EXPRESSIONS) | set(STATEMENTS)

# the statements the corpus does not hold
REST = """MODULE jp_rest
  PROC main()
    ;
    %"Other"%;
    EXIT;
  ERROR
    TRYNEXT;
  ENDPROC
ENDMODULE
"""


def test_every_expression_and_statement_type_has_one_handler():
    assert set(EXPRESSIONS) == set(typing.get_args(n.Expr))
    assert set(STATEMENTS) == set(typing.get_args(n.Stmt))


def test_a_new_node_class_without_a_handler_fails():
    classes = {
        c
        for c in vars(n).values()
        if isinstance(c, type) and dataclasses.is_dataclass(c) and c.__module__ == n.__name__
    }
    assert classes - STRUCTURE == HANDLED


def test_every_node_the_grammar_produces_has_a_handler():
    seen: set[type] = set()
    for path in sorted(CORPUS.rglob("*")):
        if path.suffix.lower() in (".mod", ".sys"):
            try:
                seen |= {type(node) for node in n.walk_nodes(read_module_file(path))}
            except RapidError:  # the corpus' refused syntax
                continue
    seen |= {type(node) for node in n.walk_nodes(parse_module(REST, path="rest.mod"))}
    nodes = {c for c in seen if c.__module__ == n.__name__}
    assert nodes - STRUCTURE == HANDLED  # each produced, and each has its handler


def test_the_interpreter_plugs_the_tables_into_a_small_class():
    assert Interpreter.expressions is EXPRESSIONS and Interpreter.statements is STATEMENTS
    assert len(inspect.getsourcelines(Interpreter)[0]) < 100
    for method in (Machine.ev, Machine._exec):
        assert "isinstance" not in inspect.getsource(method)


def test_handler_modules_exist_one_per_kind():
    for name in ("_machine", "_expressions", "_statements", "_functions", "_instructions", "_motion"):
        importlib.import_module(f"joulepath.rapid.{name}")


def test_calls_go_to_moves_first_then_the_instructions_then_the_documented_table():
    assert all(CALLS[key] is motion for key in ALL_MOTIONS)
    assert set(MOTIONS) == ALL_MOTIONS
    assert set(CALLS) == ALL_MOTIONS | KNOWN_INSTRUCTIONS | set(INPUT_WRITERS)
    assert set(INSTRUCTIONS) <= KNOWN_INSTRUCTIONS | set(INPUT_WRITERS)
    assert not set(FUNCTIONS) & set(UNEVALUATED)
    # an instruction of the documented table the interpreter has no handler for is the table's
    documented = builtins.all_builtins(kind=builtins.Kind.INSTRUCTION)
    assert any(b.name.lower() not in CALLS for b in documented)


def _spans(kind: type) -> list[tuple[str, int]]:
    out = []
    for path in sorted(RAPID.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, kind):
                assert node.end_lineno is not None
                out.append((f"{path.name}:{node.lineno} {node.name}", node.end_lineno - node.lineno + 1))
    return out


def test_no_class_over_600_lines_and_no_function_over_120_in_rapid():
    big = [f"{where}: {k} lines" for where, k in _spans(ast.ClassDef) if k > 600]
    big += [f"{where}: {k} lines" for where, k in _spans(ast.FunctionDef) if k > 120]
    assert not big, "split these:\n" + "\n".join(big)
