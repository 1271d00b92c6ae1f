"""The test files named in tests/conftest.py's scheduling tables exist (a renamed file would be
scheduled as any other, silently: this says so)."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# tests/conftest.py by its path (the module name `conftest` is shared by every folder's conftest.py)
_spec = importlib.util.spec_from_file_location("_root_conftest", ROOT / "tests" / "conftest.py")
assert _spec is not None and _spec.loader is not None
_conftest = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_conftest)
SHARED_FIXTURE_FILES, SLOW_FIRST, _unit = (
    _conftest.SHARED_FIXTURE_FILES,
    _conftest.SLOW_FIRST,
    _conftest._unit,
)


def test_scheduling_tables_name_existing_test_files():
    for members in SHARED_FIXTURE_FILES.values():
        for member in members:
            assert (ROOT / member).is_dir() if member.endswith("/") else (ROOT / member).is_file(), member
    for unit in SLOW_FIRST:
        assert unit in SHARED_FIXTURE_FILES or (ROOT / unit).is_file(), unit


def test_files_sharing_a_session_fixture_are_one_unit():
    assert (
        _unit("tests/learn/test_train.py::test_x") == _unit("tests/learn/test_validate.py::test_y") == "learn"
    )
    assert _unit("tests/report/test_report.py::test_x[a::b]") == "tiny_run"
    assert _unit("tests/program/test_cycle.py::test_x") == "tests/program/test_cycle.py"
