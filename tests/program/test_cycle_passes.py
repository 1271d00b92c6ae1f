"""When a long fly-by chain passes its targets: the search on coarse probes (issue 36) never ends
above the pass times it starts from, and comes near the best of an exhaustive search over them."""

import numpy as np
import pytest

import joulepath
from joulepath.optimize import GradientSettings
from joulepath.program import CycleSettings, parse_module, resolve_module
from joulepath.program._cycle import CycleOptimizer
from joulepath.program._cycle_model import STEP
from joulepath.program._cycle_passes import LONG_PROBE_KNOTS, screens_durations, time_warped, tune_passes
from joulepath.program._cycle_solve import ON_TAUGHT_MARGIN
from joulepath.trajectory import SplineBasis, minimum_jerk

# few knots at most: this short chain counts as a long one (GradientSettings.is_long), as the
# 8-leg chain of benchmarks/fly_by_chain.mod does under the cycle's defaults
LONG = GradientSettings(
    knot_spacing=0.05, max_knots=12, continuation=(0.3, 0.03), max_iter=60, coarse_factor=1
)

CHAIN = """MODULE Chain
    CONST jointtarget j1 := [[-40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j2 := [[-15, 30, -10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j3 := [[40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveAbsJ j1, v1000, fine, tool0;
        MoveAbsJ j2, v1000, z50, tool0;
        MoveAbsJ j3, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""


@pytest.fixture(scope="module")
def spec():
    return resolve_module(parse_module(CHAIN, path="chain.mod"), joulepath.load_robot("irb120"))


def _chain(opt: CycleOptimizer) -> tuple[int, int]:
    (i,) = [k for k, c in opt.units.chains.items() if len(c) == 2]
    return i, int(np.floor(opt.units.span[i] / STEP + 1e-9))


@pytest.fixture(scope="module")
def exhaustive(spec):
    """The chain solved at every other pass time it can reach, as its own solves are: the least energy."""
    opt = CycleOptimizer(spec, CycleSettings(gradient=LONG))
    i, units = _chain(opt)
    assert opt.solver.gradient.is_long(units * STEP)
    m = opt.units.by_index[i]
    energies = []
    for a in range(2, units - 1, 2):
        if opt.units.passes_reachable(i, (a,), units):
            s = opt.solver.solve_once(
                m, units * STEP, units, opt.settings.corridor_mm, way=((a * STEP, m.path.q1),)
            )
            if s.usable:
                energies.append(s.energy_J)
    assert len(energies) >= 5
    return min(energies)


@pytest.mark.parametrize("skew", [0.6, 1.0, 1.6])
def test_a_long_chain_s_pass_search_never_loses_and_nears_the_exhaustive_search(spec, exhaustive, skew):
    """Started where the chain's legs share its duration in proportion to their shortest durations,
    or far from there on either side (the first leg's share scaled), the search on coarse probes
    keeps a verified solve at most the one at the pass time it starts from, passing its target within
    its zone, within 2 % of the best of the exhaustive search (the solves themselves scatter by about
    1 % from one pass time to the next); started far off, it moves and keeps the pass time it found."""
    opt = CycleOptimizer(spec, CycleSettings(gradient=LONG))
    i, units = _chain(opt)
    lo = opt.solver.leg_lo[i]
    opt.solver.leg_lo[i] = (lo[0] * skew, lo[1])
    T = units * STEP
    m = opt.units.by_index[i]
    untuned = opt.solver.solve_once(m, T, units, opt.settings.corridor_mm)
    tune_passes(opt.solver, i, T)
    kept = opt.solver.cache[(i, units)]
    assert untuned.usable and kept.usable
    assert kept.energy_J <= untuned.energy_J * (1 + 1e-12)
    assert kept.energy_J <= exhaustive * 1.02
    assert opt.solver.zone_miss_mm(i, kept) <= 1e-6
    if skew != 1.0:
        assert i in opt.solver.shares and kept.energy_J < untuned.energy_J
    if i in opt.solver.shares:  # the kept solve passes where the chain's solves at every duration will
        (t_pass,) = [t for t, _ in opt.solver.waypoints(i, T)]
        assert kept.passes == (pytest.approx(t_pass),)
    assert opt.solver.solve(i, T) is kept


def test_a_probe_starts_from_the_best_path_shifted_to_its_pass_times(spec):
    """:meth:`CycleOptimizer._time_warped`: at the pass times of the path it shifts, on the knots it
    was solved on, the path itself; at pass times 75 ms earlier or later, on the probes' knots, a path
    that is at each new pass time where the shifted one was at the old (its target's zone), within a
    quarter of the distance the path not shifted is from there (a probe started from it misses its
    targets)."""
    opt = CycleOptimizer(spec, CycleSettings(gradient=LONG))
    i, units = _chain(opt)
    T = units * STEP
    near = opt.solver.solve_once(opt.units.by_index[i], T, units, opt.settings.corridor_mm)
    assert near.usable and near.passes is not None
    edges = tuple(int(round(t / STEP)) for t in near.passes)
    m0, m1 = opt.units.by_index[i], opt.units.by_index[opt.units.chains[i][-1]]

    def path(g: GradientSettings, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        basis = SplineBasis(T, knot_spacing=g.spacing_for(T), degree=g.degree, dt=STEP)
        fine = basis.grid(STEP / g.check_factor)
        default = minimum_jerk(m0.path.q0, m1.path.q1, T, dt=STEP / g.check_factor)
        return fine.t, default.q + fine.B @ x.reshape(-1, m0.path.q0.size)

    t, q = path(opt.solver.gradient, time_warped(opt.solver, i, near, edges, opt.solver.gradient))
    assert np.abs(q - near.fine.q).max() < 1e-6
    probe = GradientSettings(
        knot_spacing=LONG_PROBE_KNOTS, degree=LONG.degree, check_factor=LONG.check_factor
    )
    _, q_kept = path(
        probe, time_warped(opt.solver, i, near, edges, probe)
    )  # not shifted, on the probes' knots
    for shift in (-3, 3):
        moved = tuple(e + shift for e in edges)
        t, q = path(probe, time_warped(opt.solver, i, near, moved, probe))
        for e_old, e_new in zip(edges, moved, strict=True):
            k_new = int(np.argmin(np.abs(t - e_new * STEP)))
            was = near.fine.q[int(np.argmin(np.abs(near.fine.t - e_old * STEP)))]
            assert np.abs(q[k_new] - was).max() < 0.25 * np.abs(q_kept[k_new] - was).max()


LOOP = """MODULE Loop
    CONST jointtarget j1 := [[-40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j2 := [[-15, 30, -10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget j3 := [[40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        WHILE TRUE DO
            MoveAbsJ j2, v500, z50, tool0;
            MoveAbsJ j3, v500, z50, tool0;
            MoveAbsJ j1, v500, fine, tool0;
        ENDWHILE
    ENDPROC
ENDMODULE
"""


@pytest.fixture(scope="module")
def loop():
    """The chain of ``LOOP``, alone in its cycle, its time table at its own cycle time."""
    spec = resolve_module(parse_module(LOOP, path="loop.mod"), joulepath.load_robot("irb120"))
    opt = CycleOptimizer(spec, CycleSettings(gradient=LONG, pass_search=1))
    budget = opt.units.budget(opt.plan.cycle_time, False)
    return opt, opt.table(budget), budget


def test_a_long_chain_alone_in_its_cycle_skips_only_durations_that_cannot_win(loop):
    """A long chain alone in its cycle (no other unit takes the time its shorter durations leave;
    taught slower than it can run, so its table spans 1.6-2.6 s): its time table solves a shorter
    duration only where the coarse probe there could win (:meth:`CycleOptimizer._screened`), by the
    rule its docstring states. Every duration it skips, solved as the table solves the others, takes
    more energy than the longest, so the best allocation of the whole table is the one of the
    screened table."""
    opt, table, budget = loop
    (i,) = opt.units.optimizable
    assert len(opt.units.chains[i]) == 3
    probed = sorted({u for (j, u, _) in opt.solver.probes if j == i})
    longest = probed[-1]
    assert opt.solver.gradient.is_long(longest * STEP) and screens_durations(opt.solver, i, longest)
    solved = {int(round(s.duration / STEP)) for s in table[i] if not s.taught and s.coefficients is not None}
    assert longest in solved
    skipped = [u for u in probed[:-1] if u not in solved]
    assert skipped  # the test exercises the screen
    best_longest = opt.solver.cache[(i, longest)]
    assert best_longest.usable
    probes = {u: s for (j, u, _), s in opt.solver.probes.items() if j == i}
    ref = probes[longest]
    bar = ref.energy_J + max(ref.energy_J - best_longest.energy_J, 0.0)
    for u in probed[:-1]:  # solved where its probe is below the bar, or not usable
        assert (u in solved) == (not probes[u].usable or probes[u].energy_J < bar)
    full = {i: [*table[i]]}
    for u in skipped:
        s = opt.solver.solve(i, u * STEP)
        assert not s.usable or s.energy_J > best_longest.energy_J
        full[i].append(s)
    screened = opt.best(table, budget, opt.units.wait_total)
    assert screened.energy_J == pytest.approx(
        opt.best(full, budget, opt.units.wait_total).energy_J, rel=1e-12
    )


def test_a_long_chain_s_taught_motion_reshaped_from_its_solve_never_costs_the_plan(loop):
    """A long chain's taught motion reshaped (:meth:`CycleOptimizer.solve_on_taught`) starts from
    the chain's solve at its taught duration: it passes the targets where the taught motion does,
    within every limit, and where it is not solved from the taught motion as well (it ends more than
    ``ON_TAUGHT_MARGIN`` above the chain's solve), the one from the taught motion would not have
    won the allocation either."""
    opt, table, budget = loop
    (i,) = opt.units.optimizable
    n = int(np.floor(opt.units.span[i] / STEP + 1e-9))
    kept = opt.solver.cache[(i, -2)]
    assert any(s is kept for s in table[i])
    assert kept.usable and kept.duration == opt.units.span[i]
    base = opt.solver.base(i, n)
    assert kept.passes == tuple(t for t, _ in opt.solver.taught_passes(i, base))
    assert opt.solver.zone_miss_mm(i, kept) <= 1e-6
    near = opt.solver.cache[(i, n)]
    cold = opt.solver._on_taught_once(i, n)
    if kept.energy_J > near.energy_J * (1 + ON_TAUGHT_MARGIN):  # the cold solve was skipped
        assert not cold.usable or cold.energy_J > near.energy_J
        with_cold = {i: [*table[i], cold]}
        best = opt.best(table, budget, opt.units.wait_total).energy_J
        assert best == pytest.approx(opt.best(with_cold, budget, opt.units.wait_total).energy_J, rel=1e-12)
    else:  # both were solved: the lower kept
        assert kept.energy_J <= cold.energy_J * (1 + 1e-12)
