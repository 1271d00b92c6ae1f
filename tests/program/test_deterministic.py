"""The same input gives the same answer on any machine (issue 48, item 1): every search of the default
cycle is bounded by work, not by wall time. Each test runs a program twice, once as it is and once
under a clock that jumps an hour at every reading, so that every wall-time check fires at once; unless
``--max-time`` is given, both write the same files. ``wall_s`` (how long the run took) is the one
figure of ``cycle.json`` that measures the machine rather than the result, and is left out."""

from __future__ import annotations

import itertools
import json
import time
from pathlib import Path

import pytest

from joulepath.cli import main
from joulepath.plant import CellTask, run_cell

PROGRAM = """MODULE Pick
    CONST robtarget pA := [[380, -120, 260], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[380, 140, 300], [0, 0, 1, 0], [0, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        WHILE TRUE DO
            MoveAbsJ jHome, v1000, z50, tool0;
            MoveJ Offs(pA, 0, 0, 80), v1000, z20, tool0;
            MoveL pA, v200, fine, tool0;
            MoveL Offs(pA, 0, 0, 80), v500, z20, tool0;
            MoveJ pB, v1000, fine, tool0;
        ENDWHILE
    ENDPROC
ENDMODULE
"""
SETTINGS = ["--table-points", "2", "--knot-spacing", "0.1", "--lever-plans", "40"]


def _jumping(monkeypatch: pytest.MonkeyPatch) -> None:
    """``time.perf_counter`` jumps an hour at every reading."""
    ticks = itertools.count()
    start = time.perf_counter()
    monkeypatch.setattr(time, "perf_counter", lambda: start + 3600.0 * next(ticks))


def _without_wall(data: object) -> object:
    if isinstance(data, dict):
        return {k: _without_wall(v) for k, v in data.items() if k != "wall_s"}
    if isinstance(data, list):
        return [_without_wall(v) for v in data]
    return data


def _files(folder: Path) -> dict[str, object]:
    out: dict[str, object] = {}
    for f in sorted(folder.rglob("*")):
        if f.is_file():
            name = str(f.relative_to(folder))
            out[name] = _without_wall(json.loads(f.read_text())) if f.suffix == ".json" else f.read_bytes()
    return out


def test_a_cycle_writes_the_same_files_under_a_clock_that_jumps(tmp_path, monkeypatch):
    prog = tmp_path / "Pick.mod"
    prog.write_text(PROGRAM)
    assert main(["cycle", str(prog), "--out", str(tmp_path / "calm"), *SETTINGS]) in (0, 1)
    with monkeypatch.context() as m:
        _jumping(m)
        assert main(["cycle", str(prog), "--out", str(tmp_path / "jumpy"), *SETTINGS]) in (0, 1)
    calm, jumpy = _files(tmp_path / "calm"), _files(tmp_path / "jumpy")
    assert "cycle.json" in calm and ("optimized.mod" in calm or "egm.mod" in calm)
    assert calm.keys() == jumpy.keys()
    for name in calm:
        assert calm[name] == jumpy[name], name
    data = calm["cycle.json"]
    assert isinstance(data, dict) and data.get("rapid_levers", {}).get("plans_searched", 1) > 0


def test_max_time_is_the_one_setting_that_depends_on_the_clock(tmp_path, monkeypatch):
    prog = tmp_path / "Pick.mod"
    prog.write_text(PROGRAM)
    with monkeypatch.context() as m:
        _jumping(m)
        main(["cycle", str(prog), "--out", str(tmp_path / "capped"), *SETTINGS, "--max-time", "5"])
    data = json.loads((tmp_path / "capped" / "cycle.json").read_text())
    assert data["timed_out"] is True  # the clock ran past the cap at once: the taught motion is kept


def test_a_plant_cell_gives_the_same_result_under_a_clock_that_jumps(tmp_path, monkeypatch):
    prog = tmp_path / "Pick.mod"
    prog.write_text(PROGRAM)
    task = CellTask(
        name="cell",
        key="k",
        robot="irb120",
        program=(str(prog),),
        settings={"table_points": 2, "knot_spacing": 0.1, "lever_plans": 40},
    )
    calm = run_cell(task)
    with monkeypatch.context() as m:
        _jumping(m)
        jumpy = run_cell(task)
    assert calm["status"] == "ok", calm.get("reason")

    def plain(result: dict) -> object:
        files = {
            n: _without_wall(json.loads(x)) if n.endswith(".json") else x for n, x in result["files"].items()
        }
        return _without_wall({**result, "files": files})

    assert plain(calm) == plain(jumpy)
    # and the plant's cell writes what `joulepath cycle` writes for the same program and settings
    assert main(["cycle", str(prog), "--out", str(tmp_path / "cli"), *SETTINGS]) in (0, 1)
    for name, text in calm["files"].items():
        written = (tmp_path / "cli" / name).read_text(encoding="utf-8")
        if name.endswith(".json"):
            assert _without_wall(json.loads(text)) == _without_wall(json.loads(written))
        else:
            assert text == written, name


def test_a_cycle_runs_on_one_blas_thread_whatever_the_callers(tmp_path, monkeypatch):
    """Sums in BLAS depend on its thread count (the same search took another path with 2 threads than
    with 1): the pipeline plans on one, so a machine's cores do not change the result."""
    from threadpoolctl import threadpool_info, threadpool_limits

    import joulepath.program._pipeline as pipeline

    seen: list[int] = []
    plan = pipeline.optimize_cycle

    def spy(*args, **kwargs):
        seen.extend(p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas")
        return plan(*args, **kwargs)

    monkeypatch.setattr(pipeline, "optimize_cycle", spy)
    prog = tmp_path / "Pick.mod"
    prog.write_text(PROGRAM)
    with threadpool_limits(limits=2, user_api="blas"):
        assert main(["cycle", str(prog), "--out", str(tmp_path / "run"), *SETTINGS, "--export", "egm"]) in (
            0,
            1,
        )
    assert seen and set(seen) == {1}
