"""Valid programs run through the reader and the controller's plan; mutated ones fail in one line."""

from pathlib import Path

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.errors import InvalidInput
from joulepath.program import parse_module, read_cycle_program, resolve_module
from joulepath.sim import ControllerConfig, plan_cycle

CORPUS = sorted((Path(__file__).parent / "corpus").glob("*.mod"))
EXAMPLES = sorted((Path(__file__).parents[2] / "examples").glob("*.mod"))


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb120")


def test_corpus_is_large_enough():
    assert len(CORPUS) >= 12


@pytest.mark.parametrize("path", CORPUS + EXAMPLES, ids=lambda p: p.name)
def test_valid_program_reads_and_plans(path, robot):
    spec, rapid = read_cycle_program(path, robot)
    plan = plan_cycle(spec, ControllerConfig())
    assert rapid and any(s.kind == "move" for s in spec.steps)
    assert np.isfinite(plan.cycle_time) and plan.cycle_time > 0


def test_corpus_branch_choices_are_stated(robot):
    spec, _ = read_cycle_program(Path(__file__).parent / "corpus" / "args_and_branches.mod", robot)
    assert [c.split(".mod:", 1)[1] for c in spec.choices] == [
        "9: IF bDoubleGrip (FALSE) -> ELSE branch",
        "14: TEST nMode (2) -> CASE 2 (line 17) branch",
    ]


def test_corpus_idle_markers(robot):
    spec, _ = read_cycle_program(Path(__file__).parent / "corpus" / "inpos_idle.mod", robot)
    assert [(s.line, s.seconds, s.idle) for s in spec.steps if s.kind == "wait"] == [
        (9, 0.5, False),
        (12, 2.0, True),
        (13, 0.0, True),
    ]


def _mutants(text: str, n: int, seed: int) -> list[str]:
    """Programs one edit away from a valid one: a token or line deleted, a line doubled, bytes thrown in."""
    rng = np.random.default_rng(seed)
    lines = text.splitlines()
    out = []
    for _ in range(n):
        new = list(lines)
        k = int(rng.integers(len(new)))
        kind = int(rng.integers(4))
        if kind == 0:  # delete one token
            words = new[k].split(" ")
            if words:
                del words[int(rng.integers(len(words)))]
            new[k] = " ".join(words)
        elif kind == 1:  # duplicate a line
            new.insert(k, new[k])
        elif kind == 2:  # delete a line
            del new[k]
        else:  # random printable bytes into a line
            junk = "".join(chr(int(c)) for c in rng.integers(32, 127, size=int(rng.integers(1, 6))))
            at = int(rng.integers(len(new[k]) + 1))
            new[k] = new[k][:at] + junk + new[k][at:]
        out.append("\n".join(new) + "\n")
    return out


def test_mutated_programs_fail_in_one_line_or_read(robot):
    sources = [p.read_text() for p in CORPUS]
    n_ok = n_refused = 0
    for k, text in enumerate(sources):
        for mutant in _mutants(text, 25, seed=1000 + k):
            try:
                spec = resolve_module(parse_module(mutant, path="m.mod"), robot)
            except InvalidInput as err:
                assert len(str(err).splitlines()) == 1, str(err)
                assert str(err).strip(), mutant
                n_refused += 1
                continue
            assert any(s.kind == "move" for s in spec.steps)
            n_ok += 1
    assert n_ok + n_refused == 25 * len(sources) and n_ok > 0 and n_refused > 0
