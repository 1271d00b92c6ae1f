"""The controller's levers written into a task of several modules (and Latin-1, CRLF files): only move
statements and AccSet lines change, every other byte stays, and the written task reads back and runs as
the search planned it."""

from __future__ import annotations

import difflib
import tomllib
from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.dynamics import NOMINAL_FRICTION
from joulepath.energy import measure_power
from joulepath.program import read_cycle_program
from joulepath.program._task_levers import task_levers
from joulepath.sim import ControllerConfig
from joulepath.sim._timing import FINE_DT, evaluate_cycle, plan_cycle

CORPUS = Path(__file__).parents[1] / "fixtures" / "rapid_corpus"


@pytest.mark.parametrize("name", ["27_split_modules_celldata", "24_latin1_swedish_crlf"])
def test_levers_written_into_the_task_as_written(name, tmp_path):
    folder = CORPUS / name
    e = tomllib.loads((folder / "expect.toml").read_text(encoding="utf-8"))
    paths = [folder / p for p in e["program"]]
    robot = joulepath.load_robot("irb120")
    spec, _ = read_cycle_program(paths, robot, io=e.get("io"), routine=e.get("routine"))
    lev = task_levers(
        spec, robot, energy="thesis", io=e.get("io"), routine=e.get("routine"), max_evaluations=300
    )
    assert lev.reads_back is None, lev.reads_back
    assert lev.cycle_s <= lev.taught_cycle_s + 1e-9 and lev.energy_J <= lev.default_energy_J
    written = dict(lev.written_files)
    modules = spec.task.task.modules  # type: ignore[union-attr]
    assert set(written) == {m.path for m in modules}
    changed_lines = 0
    for m in modules:
        before = Path(m.path).read_bytes()
        after = written[m.path]
        if before == after:
            continue
        assert (b"\r\n" in before) == (b"\r\n" in after)  # line ends kept
        old = before.decode(m.encoding).splitlines()
        new = after.decode(m.encoding).splitlines()
        for line in difflib.ndiff(old, new):
            if line[:1] in "+-":
                changed_lines += 1
                text = line[2:].strip()
                assert text.lower().startswith(("move", "accset")), line
    assert (
        lev.n_changed > 0 and changed_lines > 0
    )  # these programs have open levers, and the search uses them
    # the written task, read again, runs in the emulation as the result says
    out = tmp_path / "task"
    again_paths = []
    for k, m in enumerate(modules):
        dest = out / f"m{k}" / Path(m.path).name
        dest.parent.mkdir(parents=True)
        dest.write_bytes(written[m.path])
        again_paths.append(dest)
    again, _ = read_cycle_program(again_paths, robot, io=e.get("io"), routine=e.get("routine"))
    plan = plan_cycle(again, ControllerConfig())
    assert plan.cycle_time == pytest.approx(lev.cycle_s, abs=1e-9)
    # its executed energy, recomputed here from its own motion (the 2.5 ms grid, each sample to the next)
    t = np.linspace(0.0, plan.cycle_time, int(np.ceil(plan.cycle_time / FINE_DT)) + 1)
    traj = evaluate_cycle(plan, t)
    r = plan.moves[0].step.robot
    tau = r.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
    power = measure_power("thesis", tau, traj.qd, r.drivetrain).value
    assert float((power * np.append(np.diff(traj.t), 0.0)).sum()) == pytest.approx(lev.energy_J, rel=1e-9)
    a = [s.q for s in spec.steps if s.kind == "move"]
    b = [s.q for s in again.steps if s.kind == "move"]
    assert len(a) == len(b) and all(np.abs(x - y).max() < 1e-9 for x, y in zip(a, b, strict=True))


@pytest.mark.parametrize("name", ["08_conveyor_gitype_open", "32_vision_socket_runtime"])
def test_moves_known_only_at_run_time_are_never_changed(name):
    """A move the interpreter marked (its branch decided by an input with no value) runs as taught in
    the optimized cycle: not reshaped, not re-timed, its energy the taught energy."""
    from joulepath.optimize import GradientSettings
    from joulepath.program import CycleSettings, optimize_cycle

    folder = CORPUS / name
    e = tomllib.loads((folder / "expect.toml").read_text(encoding="utf-8"))
    robot = joulepath.load_robot("irb120")
    spec, _ = read_cycle_program([folder / p for p in e["program"]], robot)
    kept = [s.kept != () for s in spec.steps if s.kind == "move"]
    assert any(kept)
    settings = CycleSettings(table_points=2, gradient=GradientSettings(knot_spacing=0.2), max_time_s=60)
    result = optimize_cycle(spec, settings)
    assert len(result.moves) == len(kept)
    for m, k in zip(result.moves, kept, strict=True):
        if k:
            assert not m.optimized and m.note.startswith("kept as taught")
            assert m.optimized_energy_J == pytest.approx(m.default_energy_J, rel=1e-9)
