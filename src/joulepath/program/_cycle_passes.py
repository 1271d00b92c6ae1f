"""When a fly-by chain passes its inner targets: the search of its pass times, and the coarse probes
that screen a long chain's durations (on a :class:`~joulepath.program._cycle_solve.UnitSolver`, whose
``shares``, ``cache`` and ``probes`` they fill)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from joulepath._typing import FloatArray
from joulepath.optimize import GradientSettings
from joulepath.program._cycle_geometry import Passes
from joulepath.program._cycle_model import STEP, Solved
from joulepath.program._cycle_solve import ON_TAUGHT_KNOTS, UnitSolver
from joulepath.trajectory import SplineBasis, minimum_jerk

PROBE_ROUNDS = 3
"""Rounds of new limit rows per continuation stage, at most, of a probe of that search (one whose
pass times cannot be met spends them all; a probe's result is verified like any solve)."""
PROBE_WARM_STAGES = 1
"""Continuation stages of a pass-time probe started from the best probe so far (its path: the probes
differ in one target's time by a few samples; on one level of knots): the last. The first probe runs
them all. Measured on pick_and_place (issue 36): the probes on the taught motion, CPU 20.0 -> 13.8 s,
the same saving (12.15 %); the last two stages 15.3 s. The probes of a chain from rest to rest too:
its 2-move chain's 4.2 -> 3.4 s, the same energies but the probe that breaks a limit (12.1889 %
-> 12.1888 %)."""
LONG_PROBE_KNOTS = 0.15
"""s between knots, at least, of a pass-time probe of a long chain (one past the gradient's
``max_knots`` at its knot spacing, :meth:`GradientSettings.is_long`): its probes are compared among
themselves on these knots, through the continuation stages but the last, and only the best pass times
are solved as the chain's own solves are. Measured on the long fly-by chain of issue 36 (8 legs, 5.3 s,
one BLAS thread, CPU s per probe): on its own 0.083 s knots through every stage 13.5 s cold, 11-13 s
from the best probe's path shifted in time (:func:`time_warped`); on 0.15 s knots
through the first two stages 2.6 s cold, 0.8-2.6 s (1.5 s on average) from that shifted path, the
same energies as cold to 0.3 mJ, and the probes in the same order as on its own knots (a step of 75 ms
of the first pass time: +0.23 J on 0.15 s knots, +0.29 J on its own)."""
LONG_PROBES = 2
"""Pass-time probes per inner target, at most, in a row without a gain, of a long chain's search (its
first step 1/8 of a leg; ``pass_search`` per target in all, at most). Measured on the long fly-by
chain of issue 36: the pattern search run on to 53 probes (about 1.4 s each) found pass times 0.017 %
better than the untuned ones on the probes' knots, within the scatter of the solves; 14 find none."""


def tune_passes(solver: UnitSolver, i: int, T: float) -> None:
    """When chain ``i`` passes its inner targets, searched at duration ``T``: a pattern search over
    the pass times in whole 25 ms samples from those :meth:`UnitSolver.waypoints` gives (each candidate a
    solve, ``give_up`` and at most :data:`PROBE_ROUNDS` rounds; a step along one target's time is
    kept when it lowers the verified energy below the best so far, the steps halve down to one
    sample, at most ``pass_search`` probes per target). Pass times that beat the solve at the
    pass times it starts from are kept as shares of the duration (:meth:`UnitSolver.waypoints`) for the
    chain's solves at every duration; the better solve at ``T`` is cached. A unit inside a
    ``MoveL`` segment probes on knots :data:`ON_TAUGHT_KNOTS` apart (its own solves:
    :data:`WITHIN_KNOTS`), the probes compared among themselves (each after the first started from
    the best probe's path, through the last :data:`PROBE_WARM_STAGES` continuation stages, as a
    chain's probes are after the first); a probe that beats the one at the untuned pass times is
    kept as the unit's solve at ``T``, else the unit is solved at the untuned pass times as its
    own solves are. A long chain (:meth:`GradientSettings.is_long`) probes on knots
    :data:`LONG_PROBE_KNOTS` apart through the continuation stages but the last, each probe after
    the first from the best probe's path shifted in time to its pass times (:func:`time_warped`),
    at most :data:`LONG_PROBES` per target in a row without a gain, its first step 1/8 of a leg;
    the chain is then solved at the untuned pass times and, where a probe won, at the best
    probe's, each from its probe (:func:`_from_probe`), and the better is kept; the probe at the
    kept pass times screens the time table's shorter durations (:func:`screened`) (the long
    fly-by chain of issue 36: 42 probes of 7-9 s each, every one ending at the smoothest path,
    -> 14 of about 1.5 s). Measured on
    pick_and_place (issue 36, with the re-timing's scaled search): 19.9 s at 12.19 %; the best
    pass times solved again on :data:`WITHIN_KNOTS`, kept where that beat the untuned solve
    there (two solves of 144 variables, about 3 s each), as before: 25.0 s at 12.15 %; solved
    again without the untuned solve: 22.3 s at 12.15 %. Nothing for a single move or a MoveL."""
    members = solver.units.chains[i]
    if len(members) < 2 or i in solver.units.linear or i in solver.tuned or not solver.settings.pass_search:
        return
    solver.tuned.add(i)
    units = int(round(T / STEP))
    m = solver.units.by_index[i]
    corridor = solver.settings.corridor_mm
    coarse = i in solver.units.within  # probes on wider knots, compared among themselves
    long = not coarse and solver.gradient.is_long(units * STEP)  # so too, then solved on its own knots
    # where it passes them untuned (a unit inside a MoveL segment: only where no probe wins)
    first: Solved | None = None if coarse or long else solver.solve_once(m, units * STEP, units, corridor)
    untuned = [t for t, _ in solver.waypoints(i, units * STEP)]
    start = tuple(int(round(t / STEP)) for t in untuned)
    seen: dict[tuple[int, ...], Solved] = {}
    probe = replace(solver.gradient, give_up=True, max_rounds=min(solver.gradient.max_rounds, PROBE_ROUNDS))
    if coarse:
        probe = replace(probe, knot_spacing=max(probe.knot_spacing, ON_TAUGHT_KNOTS))
    elif long:
        probe = long_probe_settings(solver)
    elif first is not None and all(abs(e * STEP - t) < 1e-9 for e, t in zip(start, untuned, strict=True)):
        seen[start] = first

    warm = replace(probe, continuation=probe.continuation[-PROBE_WARM_STAGES:], coarse_factor=1)

    def energy(edges: tuple[int, ...]) -> float:
        if not solver.units.passes_reachable(i, edges, units):
            return np.inf
        if edges not in seen:
            way = _way_at(solver, i, edges)
            near = seen.get(best) if PROBE_WARM_STAGES else None
            if near is not None and near.usable and near.coefficients is not None:
                initial = time_warped(solver, i, near, edges, probe) if long else near.coefficients
                seen[edges] = solver.solve_once(
                    m, units * STEP, units, corridor, way=way, gradient=warm, initial=initial
                )
            else:
                seen[edges] = solver.solve_once(m, units * STEP, units, corridor, way=way, gradient=probe)
        s = seen[edges]
        return s.energy_J if s.usable else np.inf

    best = start
    if coarse or long:
        e_best = energy(start)
    else:
        assert first is not None
        e_best = first.energy_J if first.usable else np.inf
    won = False
    cap = solver.settings.pass_search * len(start)
    # a long chain: at most LONG_PROBES per target in a row without a gain
    idle_cap = min(solver.settings.pass_search, LONG_PROBES) * len(start) if long else cap
    if long:
        step = max(1, units // (8 * len(members)))
    else:
        step = max(1, units // (4 * len(members)) if i not in solver.units.within else 2)
    since = 0  # probes since the last gain
    while step >= 1 and len(seen) < cap and since < idle_cap:
        moved = False
        for k in range(len(best)):
            for d in (-step, step):
                cand = tuple(e + d if n == k else e for n, e in enumerate(best))
                if len(seen) >= cap or since >= idle_cap:
                    break
                n_seen = len(seen)
                e = energy(cand)
                since += len(seen) - n_seen
                if e < e_best - 1e-9:
                    best, e_best, moved, won, since = cand, e, True, True, 0
                    break
        if not moved:
            step //= 2
    if long:
        _keep_long(solver, i, units, seen, start, best if won else None)
        return
    if won:  # the best probe (inside a MoveL segment: on its wider knots), verified as every solve is
        solver.shares[i] = tuple(e / units for e in best)
        solver.cache[(i, units)] = seen[best]
        return
    if first is None:  # no probe beat the untuned pass times: the unit's own solve there
        first = solver.solve_once(m, units * STEP, units, corridor)
    if first.usable:
        solver.cache[(i, units)] = first


def _way_at(solver: UnitSolver, i: int, edges: tuple[int, ...]) -> Passes:
    """Chain ``i``'s inner targets, passed at samples ``edges``."""
    members = solver.units.chains[i]
    return tuple(
        (e * STEP, solver.units.by_index[j].path.q1) for e, j in zip(edges, members[:-1], strict=True)
    )


def _keep_long(
    solver: UnitSolver,
    i: int,
    units: int,
    seen: dict[tuple[int, ...], Solved],
    start: tuple[int, ...],
    won: tuple[int, ...] | None,
) -> None:
    """Long chain ``i`` after the search of its probes ``seen``: solved on its own knots at the untuned
    pass times ``start``, and at the best probe's (``won``, None where no probe beat ``start``), each
    from its probe (:func:`_from_probe`); the better kept (its pass times as the chain's shares where
    that is the best probe's), and the probe at the kept pass times for the screen of the time table
    (:func:`screened`)."""
    first = _from_probe(solver, i, units, _way_at(solver, i, start), seen.get(start))
    tuned = _from_probe(solver, i, units, _way_at(solver, i, won), seen[won]) if won is not None else None
    if (
        won is not None
        and tuned is not None
        and tuned.usable
        and (not first.usable or tuned.energy_J < first.energy_J)
    ):
        solver.shares[i] = tuple(e / units for e in won)
        solver.cache[(i, units)] = tuned
    elif first.usable:
        solver.cache[(i, units)] = first
    kept = won if won is not None and i in solver.shares else start  # the pass times of the chain's solves
    if kept in seen:
        solver.probes[(i, units, kept)] = seen[kept]


def long_probe_settings(solver: UnitSolver) -> GradientSettings:
    """The search of a long chain's coarse probes (:func:`tune_passes`, :func:`screened`): knots
    :data:`LONG_PROBE_KNOTS` apart, the continuation stages but the last, ``give_up`` and at most
    :data:`PROBE_ROUNDS` rounds per stage."""
    g = solver.gradient
    return replace(
        g,
        give_up=True,
        max_rounds=min(g.max_rounds, PROBE_ROUNDS),
        knot_spacing=max(g.knot_spacing, LONG_PROBE_KNOTS),
        coarse_factor=1,
        continuation=g.continuation[:-1] or g.continuation,
    )


def _from_probe(
    solver: UnitSolver, i: int, units: int, way: tuple[tuple[float, FloatArray], ...], probe: Solved | None
) -> Solved:
    """Long chain ``i`` solved at ``units`` samples through its targets at ``way`` on its own knots,
    from its coarse ``probe`` there (:func:`long_probe_settings`: the stages but the last, on
    wider knots; its path fitted to the chain's knots, :meth:`UnitSolver.time_scaled`) through the last
    ``refine_stages`` continuation stages, as the wide knots of a cold solve hand over to the fine
    ones; a cold solve where the probe or that solve is not usable. Measured on the long fly-by
    chain of issue 36 (one BLAS thread): 7.5 s at 42.277 J, cold 8.9 s at 42.286 J (its own wide
    knots, 0.166 s apart, take the first stages again)."""
    m = solver.units.by_index[i]
    T = units * STEP
    corridor = solver.settings.corridor_mm
    if probe is not None and probe.usable and probe.coefficients is not None:
        g = solver.gradient
        refine = replace(g, n_starts=1, coarse_factor=1, continuation=g.continuation[-g.refine_stages :])
        start = solver.time_scaled(i, T, probe)
        out = solver.solve_once(m, T, units, corridor, way=way, gradient=refine, initial=start)
        if out.usable:
            return out
    return solver.solve_once(m, T, units, corridor, way=way)


def _long_probe(solver: UnitSolver, i: int, units: int) -> Solved:
    """Chain ``i``'s coarse probe at ``units`` samples, through its targets where its solves pass
    them (:meth:`UnitSolver.waypoints`), as :func:`tune_passes` probes a long chain; cached. It starts from
    its nearest probe (at another duration) stretched in time (:meth:`UnitSolver.time_scaled`), through the
    last :data:`PROBE_WARM_STAGES` stages, and cold where that one is not usable."""
    T = units * STEP
    way = solver.waypoints(i, T)
    edges = tuple(int(round(t / STEP)) for t, _ in way)
    key = (i, units, edges)
    if key in solver.probes:
        return solver.probes[key]
    solver.before_solve()
    m = solver.units.by_index[i]
    probe = long_probe_settings(solver)
    corridor = solver.settings.corridor_mm
    near = [s for (j, _, _), s in solver.probes.items() if j == i and s.usable and s.coefficients is not None]
    out: Solved | None = None
    if near and PROBE_WARM_STAGES:
        nearest = min(near, key=lambda s: abs(s.duration - T))
        warm = replace(probe, continuation=probe.continuation[-PROBE_WARM_STAGES:])
        start = solver.time_scaled(i, T, nearest, probe)
        out = solver.solve_once(m, T, units, corridor, way=way, gradient=warm, initial=start)
    if out is None or not out.usable:
        out = solver.solve_once(m, T, units, corridor, way=way, gradient=probe)
    solver.probes[key] = out
    return out


def screens_durations(solver: UnitSolver, i: int, longest: int) -> bool:
    """Whether unit ``i``'s shorter durations in the time table are screened by coarse probes
    (:func:`screened`): a long fly-by chain (past the gradient's ``max_knots`` at ``longest``
    samples, :meth:`GradientSettings.is_long`) from rest to rest, alone in its cycle (no other
    unit takes the time its shorter durations leave: they count only where one of them takes
    less energy than its longest duration)."""
    return (
        len(solver.units.optimizable) == 1
        and len(solver.units.chains[i]) > 1
        and i not in solver.units.within
        and i not in solver.units.linear
        and solver.gradient.is_long(longest * STEP)
    )


def screened(solver: UnitSolver, i: int, units: list[int]) -> list[Solved]:
    """Unit ``i`` solved at its durations ``units`` (samples, ascending), alone in its cycle
    (:func:`screens_durations`): at the longest as every duration is (:meth:`UnitSolver.solve`), at a shorter
    one only where its coarse probe (:func:`_long_probe`) could win, i.e. is below the coarse
    probe at the longest by less than the longest's own gain from its probe to its solve (a
    shorter duration whose probe is above that needs more than twice that gain to win), or where
    either probe is not usable. Measured on the long fly-by chain of issue 36 (5.0, 5.025, 5.075
    and 5.325 s): probes 48.25, 47.77, 47.12 and 44.27 J (about 1 s each), solves 45.20, 44.95,
    44.45 and 42.29 J (14-16 s each under load): the gains 3.05, 2.82, 2.67 and 1.98 J, the
    shorter durations' at most 1.6 times the longest's; the three are screened out."""
    longest = solver.solve(i, units[-1] * STEP)
    out = [longest]
    bar = np.inf
    if longest.usable:
        ref = _long_probe(solver, i, units[-1])
        if ref.usable:
            bar = ref.energy_J + max(ref.energy_J - longest.energy_J, 0.0)
    for u in reversed(units[:-1]):  # the nearest first: each solve starts from its nearest
        if np.isfinite(bar):
            p = _long_probe(solver, i, u)
            if p.usable and p.energy_J >= bar:
                continue
        out.append(solver.solve(i, u * STEP))
    return sorted(out, key=lambda s: s.duration)


def time_warped(
    solver: UnitSolver, i: int, near: Solved, edges: tuple[int, ...], gradient: GradientSettings
) -> FloatArray:
    """The solve ``near`` of chain ``i`` shifted in time to pass its inner targets at samples
    ``edges`` of its duration (each leg stretched or squeezed on its own, linearly in time), in the
    coefficients of a solve on ``gradient``'s knots at that duration (flat; least squares on the
    fine grid, offsets from the minimum-jerk move): a start for a probe at those pass times, near
    the best probe's path and near its targets at their new times (a probe started from the best
    path itself, its targets missed, ends outside a limit or at the smoothest path)."""
    assert near.passes is not None
    T = near.duration
    basis = SplineBasis(T, knot_spacing=gradient.spacing_for(T), degree=gradient.degree, dt=STEP)
    fine = basis.grid(STEP / gradient.check_factor)
    q0, q1 = solver.units.by_index[i].path.q0, solver.units.by_index[solver.units.chains[i][-1]].path.q1
    default = minimum_jerk(q0, q1, T, dt=STEP / gradient.check_factor)
    t_old = np.interp(default.t, [0.0, *(e * STEP for e in edges), T], [0.0, *near.passes, T])
    q_old = np.column_stack([np.interp(t_old, near.fine.t, near.fine.q[:, j]) for j in range(q0.size)])
    c = np.asarray(np.linalg.lstsq(fine.B, q_old - default.q, rcond=None)[0], dtype=float)
    out: FloatArray = c.ravel()
    return out
