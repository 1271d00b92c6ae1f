"""The lever search's energy by runs (:class:`joulepath.program._levers.RunEnergy`) against the cycle's
energy on its one grid, as the written-program check takes it: two implementations that differ only
in where their samples fall."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.program import read_cycle_program
from joulepath.program._levers import RunEnergy, _Evaluator, _runs
from joulepath.sim import ControllerConfig

EXAMPLES = Path(__file__).parents[2] / "examples"


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


@pytest.mark.parametrize("name", ["pick_and_place", "palletizing", "machine_tending"])
@pytest.mark.parametrize("measure", ["thesis", "mechanical", "electrical"])
def test_energy_by_runs_agrees_with_the_whole_grid(robot, name, measure):
    spec, _ = read_cycle_program(EXAMPLES / f"{name}.mod", robot)
    ev = _Evaluator(spec, [], measure, ControllerConfig(), by_runs=True)
    plan, _, e_runs = ev(())
    e_whole = ev.whole_energy(plan)
    # the sampling alone: 2.5 ms grids that start at each run's start instead of the cycle's
    assert e_runs == pytest.approx(e_whole, rel=1e-3)
    assert len(_runs(plan)) >= 2
    # each run ends where the arm stops, and no run overlaps the next
    runs = _runs(plan)
    for a, b in zip(runs, runs[1:], strict=False):
        assert a[-1].stops
        assert b[0].t0 >= max(m.t_end for m in a) - 1e-12


def test_a_run_is_found_once_and_a_changed_run_alone_again(robot):
    spec, _ = read_cycle_program(EXAMPLES / "pick_and_place.mod", robot)
    ev = _Evaluator(spec, [], "thesis", ControllerConfig(), by_runs=True)
    plan, _, e1 = ev.run(spec)
    energy = ev.runs
    assert isinstance(energy, RunEnergy)
    n_runs = len(_runs(plan))
    assert len(energy._runs) == n_runs
    assert ev.energy(plan) == e1 and len(energy._runs) == n_runs  # found again, not computed
    # the last move slower (its \T doubled): its run alone is new, and the total follows the whole grid
    moves = [i for i, s in enumerate(spec.steps) if s.kind == "move"]
    last = spec.steps[moves[-1]]
    slower = replace(last, time_s=2.0 * plan.moves[-1].profile.duration)
    steps = list(spec.steps)
    steps[moves[-1]] = slower
    plan2, _, e2 = ev.run(replace(spec, steps=tuple(steps)))
    assert len(energy._runs) == n_runs + 1
    assert e2 == pytest.approx(ev.whole_energy(plan2), rel=1e-3)
    assert not np.isclose(e1, e2)
