"""The program path gives what it gave before its rebuild (issue 46): for programs of the RAPID corpus,
`joulepath cycle` writes the same files, byte for byte, and the same `cycle.json` figures (to 1e-9,
`wall_s` aside) as the code before the change, stored under ``tests/fixtures/golden``.

The stored outputs were written by ``scripts/golden_outputs.py write`` with the code of commit
ecb0354 (before the interpreter was split by node type and the cycle optimizer taken apart), each
program with ``--lever-plans 40``, so that the search ends by its bound of work, the same way in both.
A change that is meant to change the outputs writes them again with the script and says so: corpus 34's
were written again at stop 54, where the lever search's energy by runs and one BLAS thread changed its
search's path (one zone z40 -> z50 in its optimized task; its executed energy by 2e-6 J). At stop 55
the ``rapid_refused`` line of corpus 05, 27 and 34 was written again alone: it now says why this program
has no module for the via-point writer (its modules, its scenario, a move kept, what the writer's static
reader does not read), where it listed every possible reason.
"""

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "tests" / "fixtures" / "golden"


def _script():
    spec = importlib.util.spec_from_file_location("golden_outputs", ROOT / "scripts" / "golden_outputs.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


STORED = sorted(str(p.parent.relative_to(GOLDEN)) for p in GOLDEN.rglob("exit.json"))


def test_the_stored_outputs_are_there_and_name_known_targets():
    targets = _script().targets()
    assert len(STORED) >= 3
    assert set(STORED) <= set(targets)
    assert any((GOLDEN / name / "run" / "cycle.json").is_file() for name in STORED)


@pytest.mark.parametrize("name", STORED)
def test_cycle_writes_what_the_code_before_wrote(name, tmp_path):
    script = _script()
    script.run_one(ROOT / "src", name, script.targets()[name], tmp_path)
    (expected := tmp_path / "expected" / name).mkdir(parents=True)
    for f in (GOLDEN / name).rglob("*"):
        if f.is_file():
            (expected / f.relative_to(GOLDEN / name)).parent.mkdir(parents=True, exist_ok=True)
            (expected / f.relative_to(GOLDEN / name)).write_bytes(f.read_bytes())
    diffs = script.differences(tmp_path / "expected", tmp_path)
    assert diffs == []


def test_a_changed_figure_or_file_is_found(tmp_path):
    """The comparison is not blind: a figure changed by more than 1e-9 and a byte changed are told."""
    script = _script()
    name = next(n for n in STORED if (GOLDEN / n / "run" / "cycle.json").is_file())
    for side in ("a", "b"):
        for f in (GOLDEN / name).rglob("*"):
            if f.is_file():
                dest = tmp_path / side / name / f.relative_to(GOLDEN / name)
                dest.parent.mkdir(parents=True, exist_ok=True)
                dest.write_bytes(f.read_bytes())
    assert script.differences(tmp_path / "a", tmp_path / "b") == []
    cycle = tmp_path / "b" / name / "run" / "cycle.json"
    text = cycle.read_text(encoding="utf-8")
    data = json.loads(text)
    numbers = [k for k, v in data.items() if isinstance(v, float) and k != "wall_s" and v != 0.0]
    assert numbers
    data[numbers[0]] *= 1.0 + 1e-6
    cycle.write_text(json.dumps(data), encoding="utf-8")
    other = next(p for p in (tmp_path / "b" / name / "run").iterdir() if p.suffix != ".json")
    other.write_bytes(other.read_bytes() + b" ")
    diffs = script.differences(tmp_path / "a", tmp_path / "b")
    assert any(numbers[0] in d for d in diffs) and any("bytes differ" in d for d in diffs)
