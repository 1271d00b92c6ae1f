"""Via points timed for the controller: each chain's ``\\T`` chosen on the emulation.

By agreement and invariants: the conditions the search keeps (written from the emulation's rules for a
timed fly-by chain) agree with the emulation itself on whether a chain holds; the timed module, read
again by the RAPID interpreter and run by the emulation, keeps every chain it timed, the taught cycle
time, and only the ``\\T`` of its via points changed.
"""

import re
from dataclasses import replace

import numpy as np
import pytest

from joulepath.program import CycleSettings, optimize_cycle, parse_module, resolve_module
from joulepath.program._levers import _Evaluator
from joulepath.program._output import written_rapid
from joulepath.program._task import as_sequence, read_written
from joulepath.program._via_levers import _added_lines, _plain
from joulepath.program._via_timing import MARGIN, T_ARG, _Chain, _fastest, chain_runs, dense_vias, time_chains
from joulepath.sim import ControllerConfig, plan_cycle
from joulepath.sim._timing import ChainProfile

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
PROGRAM = f"""MODULE Views
    ! a camera over three views, flying by each, then back to park and a pause
    CONST robtarget pV1 := [[300, 200, 400], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    CONST robtarget pV2 := [[380, 0, 300], [0, 0, 1, 0], [0, 0, 0, 0], {EXT}];
    CONST robtarget pV3 := [[300, -200, 350], [0, 0, 1, 0], [-1, 0, -1, 0], {EXT}];
    CONST jointtarget jPark := [[0, 0, 0, 0, 30, 0], {EXT}];
    PROC main()
        MoveAbsJ jPark, v1000, fine, tool0;
        WHILE TRUE DO
            MoveJ pV1, v1500, z50, tool0;
            MoveJ pV2, v1500, z50, tool0;
            MoveJ pV3, v1500, z50, tool0;
            MoveAbsJ jPark, v1500, fine, tool0;
            WaitTime 0.4;
        ENDWHILE
    ENDPROC
ENDMODULE
"""
CONFIG = ControllerConfig()


@pytest.fixture(scope="module")
def dense(irb120):
    """The plan's via-point module with the points at equal arc length, read as written."""
    spec = resolve_module(parse_module(PROGRAM, path="views.mod"), irb120)
    settings = CycleSettings(table_points=2, pass_search=0)
    settings = replace(settings, gradient=replace(settings.gradient, knot_spacing=0.1))
    result = optimize_cycle(spec, settings)
    plan = result.unretimed or result
    text = _plain(written_rapid(replace(plan, vias=dense_vias(plan, spacing=0.1))).text)
    return spec, text, resolve_module(parse_module(text, path="views (via points)"), irb120)


def _run(text: str, robot) -> tuple[float, float]:
    spec = resolve_module(parse_module(text, path="views (via points)"), robot)
    _, t, e = _Evaluator(spec, [], "thesis", CONFIG)(())
    return t, e


def test_the_conditions_agree_with_the_emulation_on_whether_a_chain_holds(dense):
    _, _, spec = dense
    runs = chain_runs(spec, _added_lines(spec))
    assert runs, "the fly-by chain of the three views is one timed chain of via points"
    rng = np.random.default_rng(5)
    agree = {True: 0, False: 0}
    for run in runs:
        chain = _Chain(spec, run, "thesis", CONFIG)
        T0 = np.array([spec.steps[i].time_s for i in run.steps])
        fast = _fastest(chain, T0)
        assert fast is not None and chain.conditions(fast).min() >= 0.0
        assert chain.motion(fast)[0]
        for k in range(60):  # times about the shortest: some hold, some break a corner or a ramp
            spread = (0.0, 0.02, 0.3)[k % 3]
            T = fast * rng.uniform(0.9, 1.5) * rng.uniform(1.0 - spread, 1.0 + spread, size=fast.size)
            exact = chain.conditions(T, extra=-MARGIN).min()  # the emulation's rules, no margin
            if abs(exact) < 1e-6:
                continue
            held = chain.motion(T)[0]
            assert held == (exact > 0.0), f"conditions {exact:.3g}, the emulation holds: {held}"
            agree[held] += 1
    assert agree[True] > 0 and agree[False] > 0, agree  # both sides seen


def test_timed_module_keeps_its_chains_the_taught_cycle_and_changes_only_the_times(irb120, dense):
    spec, text, spec_d = dense
    _, t_taught, e_taught = _Evaluator(spec, [], "thesis", CONFIG)(())
    timed = time_chains(
        text,
        spec_d,
        _added_lines(spec_d),
        measure="thesis",
        config=CONFIG,
        cycle_s=t_taught,
        run_cycle=lambda c: _run(c, irb120),
    )
    assert timed.timed >= 1
    # only \T values differ, and only on the lines of the added procedures
    before, after = text.splitlines(), timed.text.splitlines()
    assert len(before) == len(after)
    changed = [k + 1 for k, (a, b) in enumerate(zip(before, after, strict=True)) if a != b]
    assert changed and set(changed) <= _added_lines(spec_d)
    for k in changed:
        assert T_ARG.sub("", before[k - 1]) == T_ARG.sub("", after[k - 1])
    # read again by the interpreter (the other reader) and run: every timed chain holds, the taught time kept
    plan = plan_cycle(as_sequence(read_written(timed.text, "views.mod", irb120)), CONFIG)
    assert plan.cycle_time <= t_taught + 1e-6
    written = {m.step.line for m in plan.moves if isinstance(m.profile, ChainProfile)}
    again = resolve_module(parse_module(timed.text, path="views (via points)"), irb120)
    for run in chain_runs(again, _added_lines(again)):
        assert {again.steps[i].line for i in run.steps} <= written
    # the plan's own times, which break the chain on the controller, cost more than the timed ones
    t_dense, e_dense = _run(text, irb120)
    t_timed, e_timed = _run(timed.text, irb120)
    assert t_timed <= t_taught + 1e-6 and (t_dense > t_taught or e_timed < e_dense)
    assert re.search(r"\\T:=\d+\.\d{4},", timed.text)
