"""Unit solves: each unit of a cycle reshaped at one duration (or from its taught motion), verified.

A unit from rest to rest is solved by the single-move gradient optimizer
(:func:`joulepath.optimize.solve_move`) through its inner targets, at the pass times
:meth:`UnitSolver.waypoints` gives; a unit inside a ``MoveL`` segment as a shape added to the taught
motion over its window; a ``MoveL`` from rest to rest re-timed along its line. Each solve is checked
on the 2.5 ms grid against every limit (and the cell) and its energy summed on the physics model and
the lab plant (:class:`~joulepath.program._cycle_model.Solved`); solves are cached by unit and
duration. The search for when a chain passes its targets is :mod:`joulepath.program._cycle_passes`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Robot
from joulepath.errors import LimitViolation
from joulepath.optimize import (
    GradientSettings,
    SplineProblem,
    check_limits,
    optimize_spline,
    retime_on_path,
    shortest_feasible_duration,
    shortest_on_path,
    solve_move,
    tcp_deviation_mm,
)
from joulepath.program._cycle_geometry import Passes, taught_passes, zone_miss_mm
from joulepath.program._cycle_model import STEP, Solved, TimeBudgetSpent, trajectory_energy, window_energy
from joulepath.program._cycle_motion import taught_after
from joulepath.program._cycle_units import CycleUnits
from joulepath.sim import PlannedMove, Plant, evaluate_cycle, make_plant
from joulepath.trajectory import SplineBasis, Trajectory, minimum_jerk

ON_TAUGHT_KNOTS = 0.1
"""s between knots, at least, of a shape added to the taught motion: the taught motion runs at the
joints' speed limits, so nearly every speed row is active, and SLSQP's cost grows with their number."""

WITHIN_KNOTS = 0.075
"""s between knots, at least, of a shape added to a unit inside a ``MoveL`` segment (measured on
pick_and_place: 0.1 s saved 11.6 %, 0.075 s 11.7 % in 7 s more, 0.05 s 11.5 % in 50 s more)."""

ON_TAUGHT_MARGIN = 0.01
"""Share above a long chain's solve at its taught duration within which its reshaped taught motion,
started from that solve (:meth:`UnitSolver.solve_on_taught`), is also solved from the taught
motion. Measured on the long fly-by chain of issue 36 (one BLAS thread): from the taught motion
43.375 J in 10.0 s, from the solve (42.277 J) 43.556 J in 5.0 s, 0.4 % above the one from the
taught motion and 3.0 % above the solve."""


class UnitSolver:
    """The solves of one cycle's units (:class:`~joulepath.program._cycle_units.CycleUnits`), cached.

    ``t_lo``: each unit's shortest optimized duration (s); ``leg_lo``: each move's of a chain, from
    rest to rest; ``shortest_cycle``: the cycle with each unit at its shortest (or as taught where
    that is shorter), without the waits. ``shares``: by chain, when it passes its targets (found by
    :func:`~joulepath.program._cycle_passes.tune_passes`), ``tuned`` the chains searched, ``probes``
    a long chain's coarse probes. ``deadline``: ``time.perf_counter()`` after which no solve starts
    (:class:`~joulepath.program._cycle_model.TimeBudgetSpent`; ``timed_out`` then says so).
    """

    def __init__(
        self,
        units: CycleUnits,
        *,
        progress: Callable[[str], None],
        deadline: float | None = None,
    ) -> None:
        self.units = units
        self.settings = settings = units.settings
        self.progress = progress
        self.deadline = deadline
        self.timed_out = False
        self.gradient = replace(settings.gradient, energy_every=settings.energy_every)
        self._plants: dict[int, Plant] = {}
        self.cache: dict[tuple[int, int], Solved] = {}
        self.n_solves = 0
        self.shares: dict[int, tuple[float, ...]] = {}  # by chain: when it passes its targets (tune_passes)
        self.tuned: set[int] = set()  # chains whose pass times were searched
        # a long chain's coarse probes by (chain, duration in samples, pass times in samples)
        self.probes: dict[tuple[int, int, tuple[int, ...]], Solved] = {}
        self.t_lo: dict[int, float] = {}
        self.leg_lo: dict[int, tuple[float, ...]] = {}  # each move's shortest rest-to-rest duration
        chains = units.chains
        for n_unit, (i, members) in enumerate(chains.items(), start=1):
            progress(f"unit {n_unit}/{len(chains)}: its shortest duration")
            if i in units.within:  # its ends are the taught motion's: its duration stays
                self.leg_lo[i] = ()
                self.t_lo[i] = units.span[i]
                continue
            if i in units.linear:
                self.leg_lo[i] = ()
                self.t_lo[i] = self._linear_shortest(units.by_index[i])
                continue
            single = [self._move_shortest(units.by_index[j]) for j in members]
            self.leg_lo[i] = tuple(single)
            self.t_lo[i] = single[0] if len(members) == 1 else self._chain_shortest(i, sum(single))
        # each unit at its shortest optimized duration, or as taught where that is shorter
        self.shortest_cycle = units.fixed_time + sum(min(self.t_lo[i], units.span[i]) for i in chains)

    def _move_shortest(self, m: PlannedMove) -> float:
        """A joint move's shortest duration from rest to rest whose minimum-jerk move keeps every limit."""
        robot = self.units.robot(m)
        shortest = shortest_feasible_duration(
            robot,
            m.path.q0,
            m.path.q1,
            dt=STEP,
            friction=NOMINAL_FRICTION,
            acceleration_limit=self.units.amax(robot),
            jerk_limit=self.units.jmax(robot),
        )
        if shortest is None:
            raise LimitViolation(
                f"{self.units.spec.source}:{m.step.line}: {m.step.label}: no feasible duration found"
            )
        return shortest

    def before_solve(self) -> None:
        """Raise :class:`TimeBudgetSpent` once ``max_time_s`` is reached (no new solve starts)."""
        if self.deadline is not None and time.perf_counter() > self.deadline:
            self.timed_out = True
            raise TimeBudgetSpent(f"{self.units.spec.source}: --max-time reached")

    def _linear_shortest(self, m: PlannedMove) -> float:
        """A MoveL's shortest duration along its line within the limits and its speeddata (TOPP-RA,
        whole 25 ms samples); its taught duration when toppra (extra ``motion``) is not installed."""
        robot = self.units.robot(m)
        assert m.step.speed is not None
        try:
            t = shortest_on_path(
                robot,
                m.path,
                acceleration_limit=self.units.amax_array(robot),
                jerk_limit=self.units.jmax(robot),
                tcp_speed_limit=m.step.speed.v_tcp / 1000.0,
                tcp=m.step.tcp,
            )
        except ImportError:
            return self.units.span[m.index]
        return float(np.ceil(t / STEP - 1e-9) * STEP)

    def waypoints(self, i: int, T: float) -> Passes:
        """The chain's inner targets and when it passes them, in whole 25 ms samples, each leg at least
        two samples long: at the shares of ``T`` :func:`~joulepath.program._cycle_passes.tune_passes` found;
        else (a unit inside a MoveL segment) where the taught motion passes them; else ``T`` shared in
        proportion to each move's shortest rest-to-rest duration (at the sum of those durations, each leg gets
        its own)."""
        members = self.units.chains[i]
        if len(members) == 1:
            return ()
        units = int(round(T / STEP))
        if i in self.shares:
            edges = np.round(np.asarray(self.shares[i]) * units).astype(int)
        elif i in self.units.within:
            return self.taught_passes(i)
        else:
            base = np.array(self.leg_lo[i])
            edges = np.round(np.cumsum(base)[:-1] / base.sum() * units).astype(int)
        for k in range(edges.size):  # at least 2 samples per leg
            edges[k] = max(edges[k], (edges[k - 1] if k else 0) + 2)
        for k in range(edges.size - 1, -1, -1):
            edges[k] = min(edges[k], (edges[k + 1] if k + 1 < edges.size else units) - 2)
        return tuple(
            (float(e * STEP), self.units.by_index[j].path.q1)
            for e, j in zip(edges, members[:-1], strict=True)
        )

    def base(self, i: int, n_steps: int | None = None) -> Trajectory:
        """The taught motion over unit ``i``'s window (or its first ``n_steps`` 25 ms samples), on
        the optimizer's fine grid (from 0)."""
        win = self.units.segment_of[i]
        h = STEP / self.gradient.check_factor
        length = win.span if n_steps is None else n_steps * STEP
        n = int(round(length / h)) + 1
        t = np.linspace(0.0, (n - 1) * h, n)
        tr = evaluate_cycle(self.units.plan, win.t0 + t)
        return Trajectory(t=t, q=tr.q, qd=tr.qd, qdd=tr.qdd)

    def passes(self, i: int, s: Solved) -> Passes:
        """When the entry ``s`` of unit ``i`` passes the unit's inner targets, and the targets."""
        if s.passes is None:
            return self.waypoints(i, s.duration)
        members = self.units.chains[i]
        return tuple((t, self.units.by_index[j].path.q1) for t, j in zip(s.passes, members[:-1], strict=True))

    def taught_passes(self, i: int, traj: Trajectory | None = None) -> Passes:
        """Inner targets of a unit at the times (from the window's start, on the 2.5 ms grid of
        ``traj``, default :meth:`base`) the taught motion comes closest to each (TCP)."""
        traj = self.base(i) if traj is None else traj
        targets = [self.units.by_index[j].path.q1 for j in self.units.chains[i][:-1]]
        return taught_passes(self.units.by_index[i].step, traj, targets)

    def solve_on_taught(self, i: int) -> Solved | None:
        """A unit from rest to rest reshaped from its taught motion at its taught duration: the shape
        is added to the taught motion over its whole 25 ms samples (the rest of it, less than one
        sample to the stop, stays taught), through its targets where the taught motion passes them.
        It starts where the controller's own motion is, within every limit. None: under 0.15 s.

        A long fly-by chain (:meth:`long_on_taught`) with a usable solve at those whole samples
        starts from that solve instead, shifted in time to the taught pass times, through the last
        ``refine_stages`` continuation stages; it is solved from the taught motion as well only where
        that start ends within :data:`ON_TAUGHT_MARGIN` of the solve, and the lower of the two is kept."""
        key = (i, -2)
        if key in self.cache:
            return self.cache[key]
        win = self.units.segment_of[i]
        n = int(np.floor(win.span / STEP + 1e-9))
        if n < 6 or i in self.units.within or i in self.units.linear or self.settings.follow == "via-points":
            return None  # (via points: planned within a lower acceleration limit than taught)
        self.before_solve()
        near = self.cache.get((i, n)) if self.long_on_taught(i) else None
        out: Solved | None = None
        if near is not None and near.usable and near.coefficients is not None and near.passes is not None:
            out = self._on_taught_once(i, n, near)
            if out.usable and out.energy_J <= near.energy_J * (1 + ON_TAUGHT_MARGIN):
                cold = self._on_taught_once(i, n)
                out = cold if cold.usable and cold.energy_J < out.energy_J else out
            elif not out.usable:
                out = None
        if out is None:
            out = self._on_taught_once(i, n)
        self.cache[key] = out
        return out

    def long_on_taught(self, i: int) -> bool:
        """Whether unit ``i`` is a long fly-by chain from rest to rest (past the gradient's
        ``max_knots`` at its taught duration, :meth:`GradientSettings.is_long`): its reshaped taught
        motion (:meth:`solve_on_taught`) comes after its solves in the time table and starts from
        the one at its taught duration."""
        return (
            len(self.units.chains[i]) > 1
            and i not in self.units.within
            and i not in self.units.linear
            and self.gradient.is_long(self.units.span[i])
        )

    def _on_taught_once(self, i: int, n: int, near: Solved | None = None) -> Solved:
        """:meth:`solve_on_taught` over ``n`` samples: from the taught motion, or from the solve
        ``near`` of the chain at ``n`` samples shifted in time to the taught pass times (each leg
        stretched linearly in time; fitted by least squares) through the last ``refine_stages``
        continuation stages."""
        win = self.units.segment_of[i]
        m = self.units.by_index[i]
        robot = self.units.robot(m)
        base = self.base(i, n)
        way = self.taught_passes(i, base)
        amax, jmax = self.units.amax(robot), self.units.jmax(robot)
        seq = np.random.SeedSequence([self.settings.seed, m.index, 10_000 + n])
        corridor = self.settings.corridor_mm
        g = self.settings.gradient  # on the taught motion: the objective on the samples (see energy_every)
        g = replace(g, knot_spacing=max(g.knot_spacing, ON_TAUGHT_KNOTS), coarse_factor=1)
        initial: FloatArray | None = None
        if near is not None:
            assert near.passes is not None
            g = replace(g, n_starts=1, continuation=g.continuation[-g.refine_stages :])
            T = n * STEP
            basis = SplineBasis(T, knot_spacing=g.spacing_for(T), degree=g.degree, dt=STEP)
            grid = basis.grid(STEP / g.check_factor)
            t_old = np.interp(grid.t, [0.0, *(t for t, _ in way), T], [0.0, *near.passes, near.duration])
            q_old = np.column_stack(
                [np.interp(t_old, near.fine.t, near.fine.q[:, j]) for j in range(robot.n_joints)]
            )
            q_base = np.column_stack([np.interp(grid.t, base.t, base.q[:, j]) for j in range(robot.n_joints)])
            initial = np.asarray(np.linalg.lstsq(grid.B, q_old - q_base, rcond=None)[0], dtype=float).ravel()
        res, problem = solve_move(
            robot,
            base.q[0],
            base.q[-1],
            n * STEP,
            friction=NOMINAL_FRICTION,
            settings=g,
            rng=np.random.default_rng(seq),
            acceleration_limit=amax,
            max_deviation_m=None if corridor is None else corridor / 1000,
            waypoints=way,
            jerk_limit=jmax,
            waypoint_radius=self.units.zone_radius(i),
            base=base,
            energy_measure=self.settings.energy,
            deadline=self.deadline,
            initial=initial,
        )
        self.n_solves += 1
        x = res.coefficients.ravel()
        window = problem.path(x, fine=True)
        report = check_limits(
            robot, window, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=jmax
        )
        if win.span - n * STEP > 1e-9:  # the rest of the taught motion, to the stop
            fine = taught_after(self.units.plan, window, win.t0, win.span)
        else:
            fine = window
        e, e_lab = window_energy(robot, self.plant(robot), fine, self.settings.energy)
        samples = problem.path(x)
        samples = Trajectory(
            t=np.append(samples.t, win.span),
            q=np.vstack([samples.q, fine.q[-1:]]),
            qd=np.vstack([samples.qd, fine.qd[-1:]]),
            qdd=np.vstack([samples.qdd, fine.qdd[-1:]]),
        )
        return Solved(
            win.span,
            e,
            e_lab,
            report.ok and res.feasible,
            tuple(w_.describe() for w_ in report.worst),
            samples,
            fine,
            tcp_deviation_mm(robot, problem.path(x), problem.path(problem.origin)),
            None if self.settings.cell is None else self.units.clearance_mm(m, fine.q),
            corridor,
            passes=tuple(t for t, _ in way),
        )

    def zone_miss_mm(self, i: int, s: Solved) -> float:
        """Largest TCP distance (mm) beyond its zone of the chain's path from an inner target, at
        the time it passes it (0: within every zone)."""
        members = self.units.chains[i]
        if len(members) == 1:
            return 0.0
        zones = [self.units.zone_mm(j) for j in members[:-1]]
        return zone_miss_mm(self.units.by_index[i].step, s.fine, self.passes(i, s), zones)

    def _chain_problem(self, i: int, T: float) -> SplineProblem:
        """The chain's problem at ``T``: fine knots, no corridor (its smoothest path is ``origin``)."""
        m0, m1 = self.units.by_index[i], self.units.by_index[self.units.chains[i][-1]]
        robot = self.units.robot(m0)
        g = self.gradient
        return SplineProblem(
            robot,
            m0.path.q0,
            m1.path.q1,
            T,
            NOMINAL_FRICTION,
            SplineBasis(T, knot_spacing=g.spacing_for(T), degree=g.degree, dt=STEP),
            check_factor=g.check_factor,
            acceleration_limit=self.units.amax(robot),
            waypoints=self.waypoints(i, T),
            jerk_limit=self.units.jmax(robot),
            waypoint_radius=self.units.zone_radius(i),
        )

    def _chain_shortest(self, i: int, upper: float) -> float:
        """Shortest whole-sample chain duration: the first from half the sum of its moves' shortest
        rest-to-rest durations (``upper``) whose smoothest path through the targets keeps every limit,
        else ``upper`` (the moves back to back, each from rest to rest, are feasible there). Found by
        bisection (the smoothest path at a longer duration is the same path slower, its pass times
        at the same shares up to whole samples): inspection's chain 72 checks -> 7 (issue 36)."""
        robot = self.units.robot(self.units.by_index[i])
        amax = self.units.amax(robot)
        n_legs = len(self.units.chains[i])

        def keeps_limits(units: int) -> bool:
            if units * STEP >= upper - 1e-9:
                return True
            problem = self._chain_problem(i, units * STEP)
            fine = problem.path(problem.origin, fine=True)
            return check_limits(
                robot,
                fine,
                friction=NOMINAL_FRICTION,
                acceleration_limit=amax,
                jerk_limit=self.units.jmax(robot),
            ).ok

        lo = max(2 * n_legs + 2, int(np.floor(0.5 * upper / STEP)))
        if lo * STEP >= upper - 1e-9:
            return round(upper, 9)
        if keeps_limits(lo):
            return round(lo * STEP, 9)
        hi = int(np.ceil(upper / STEP - 1e-9))  # lo breaks a limit, hi keeps them (or is upper)
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (lo, mid) if keeps_limits(mid) else (mid, hi)
        return round(hi * STEP, 9) if hi * STEP < upper - 1e-9 else round(upper, 9)

    def plant(self, robot: Robot) -> Plant:
        key = id(robot)
        if key not in self._plants:
            self._plants[key] = make_plant("lab", robot)
        return self._plants[key]

    def solve(self, i: int, duration: float) -> Solved:
        """The optimized move ``i`` at ``duration`` (a whole number of 25 ms samples), verified; cached.

        A fly-by chain (not inside a ``MoveL`` segment) with a usable solve at another duration starts
        from it, stretched to ``duration`` (:meth:`time_scaled`), on its fine knots through the last
        continuation stages, and is solved as usual where that is not usable. Measured on
        pick_and_place (issue 36): its 2-move chain at its shortest duration 5.6 -> 0.6 s of CPU, at
        the next 0.3 -> 0.2 s, the same energies (to 1 mJ); the cold solve there ended SLSQP's rounds
        with incompatible constraints."""
        units = int(round(duration / STEP))
        key = (i, units)
        if key in self.cache:
            return self.cache[key]
        self.before_solve()
        m = self.units.by_index[i]
        T = units * STEP
        corridors: list[float | None] = [self.settings.corridor_mm]
        if self.settings.cell is not None:  # tighter corridors around the (clear) taught move
            first = self.settings.corridor_mm or 100.0
            corridors += [first / 2, first / 4, first / 8]
        warm = self._neighbour(i, T) if self.settings.warm_start and len(self.units.chains[i]) == 1 else None
        out: Solved | None = None
        chained = len(self.units.chains[i]) > 1 and i not in self.units.within
        near = self._neighbour(i, T) if chained else None
        if near is not None and near.coefficients is not None:  # a chain: from its nearest duration
            g = self.gradient
            refine = replace(g, n_starts=1, coarse_factor=1, continuation=g.continuation[-g.refine_stages :])
            out = self.solve_once(
                m, T, units, corridors[0], gradient=refine, initial=self.time_scaled(i, T, near)
            )
            if out.usable:
                self.cache[key] = out
                return out
        for corridor in corridors:
            out = self.solve_once(m, T, units, corridor, warm)
            if out.usable or not out.limits_ok:
                break
        assert out is not None
        self.cache[key] = out
        return out

    def time_scaled(
        self, i: int, T: float, near: Solved, gradient: GradientSettings | None = None
    ) -> FloatArray:
        """The solve ``near`` of chain ``i`` stretched to ``T`` in the coefficients of a solve at ``T``
        (on ``gradient``'s knots, default the fine ones; flat; least squares on the fine grid, offsets
        from the minimum-jerk move): it passes each target at the same share of the duration, as
        :meth:`waypoints` asks at ``T``."""
        g = self.gradient if gradient is None else gradient
        basis = SplineBasis(T, knot_spacing=g.spacing_for(T), degree=g.degree, dt=STEP)
        fine = basis.grid(STEP / g.check_factor)
        q0, q1 = self.units.by_index[i].path.q0, self.units.by_index[self.units.chains[i][-1]].path.q1
        default = minimum_jerk(q0, q1, T, dt=STEP / g.check_factor)
        t_old = default.t * (near.duration / T)
        q_old = np.column_stack([np.interp(t_old, near.fine.t, near.fine.q[:, j]) for j in range(q0.size)])
        c = np.asarray(np.linalg.lstsq(fine.B, q_old - default.q, rcond=None)[0], dtype=float)
        out: FloatArray = c.ravel()
        return out

    def _neighbour(self, i: int, T: float) -> Solved | None:
        """The usable solve of move ``i`` at the nearest other duration (a warm start), if any."""
        near = [s for (j, _), s in self.cache.items() if j == i and s.usable]
        return min(near, key=lambda s: abs(s.duration - T)) if near else None

    def _warm_problem(
        self, m: PlannedMove, T: float, corridor: float | None, warm: Solved
    ) -> tuple[Any, Any]:
        """The fine-knot problem at ``T`` and the warm path in its coefficients (time-scaled, lstsq)."""
        g = self.gradient
        robot = self.units.robot(m)
        basis = SplineBasis(T, knot_spacing=g.spacing_for(T), degree=g.degree, dt=STEP)
        problem = SplineProblem(
            robot,
            m.path.q0,
            m.path.q1,
            T,
            NOMINAL_FRICTION,
            basis,
            check_factor=g.check_factor,
            max_deviation_m=None if corridor is None else corridor / 1000,
            acceleration_limit=self.units.amax(robot),
            jerk_limit=self.units.jmax(robot),
            energy_measure=self.settings.energy,
            thin_rows=g.is_long(T),
        )
        t_old = problem.fine.t * (warm.duration / T)
        q_old = np.column_stack(
            [np.interp(t_old, warm.fine.t, warm.fine.q[:, j]) for j in range(robot.n_joints)]
        )
        c = np.linalg.lstsq(problem.fine.B, q_old - problem.default_fine.q, rcond=None)[0]
        return problem, c

    def solve_once(
        self,
        m: PlannedMove,
        T: float,
        units: int,
        corridor: float | None,
        warm: Solved | None = None,
        way: Passes | None = None,
        gradient: GradientSettings | None = None,
        initial: FloatArray | None = None,
    ) -> Solved:
        robot = self.units.robot(m)
        amax = self.units.amax(robot)
        seq = np.random.SeedSequence([self.settings.seed, m.index, units])
        rng = np.random.default_rng(seq)
        if m.index in self.units.linear:
            return self._retime_once(m, T)
        inner = m.index in self.units.within
        way = self.waypoints(m.index, T) if way is None else way
        base = self.base(m.index) if inner else None
        q0 = m.path.q0 if base is None else base.q[0]
        q1 = self.units.by_index[self.units.chains[m.index][-1]].path.q1 if base is None else base.q[-1]
        if warm is not None and not inner:  # from the nearest solved duration: the last stages only
            problem, start = self._warm_problem(m, T, corridor, warm)
            g = self.gradient
            refine = replace(g, n_starts=1, continuation=g.continuation[-g.refine_stages :])
            res = optimize_spline(problem, refine, rng=rng, initial=start, deadline=self.deadline)
        else:
            g = self.gradient if gradient is None else gradient
            res, problem = solve_move(
                robot,
                q0,
                q1,
                T,
                friction=NOMINAL_FRICTION,
                settings=g
                if base is None
                else replace(
                    g,
                    knot_spacing=max(g.knot_spacing, WITHIN_KNOTS),
                    coarse_factor=1,
                    energy_every=self.settings.gradient.energy_every,
                ),
                rng=rng,
                acceleration_limit=amax,
                max_deviation_m=None if corridor is None else corridor / 1000,
                waypoints=way,
                jerk_limit=self.units.jmax(robot),
                waypoint_radius=self.units.zone_radius(m.index),
                base=base,
                energy_measure=self.settings.energy,
                deadline=self.deadline,
                initial=initial,
            )
        self.n_solves += 1
        x = res.coefficients.ravel()
        fine = problem.path(x, fine=True)
        report = check_limits(
            robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=self.units.jmax(robot)
        )
        e, e_lab = trajectory_energy(robot, self.plant(robot), fine, self.settings.energy, half_open=inner)
        samples = problem.path(x)
        # the taught move: the joint-interpolated move, or through a chain's targets the smoothest path
        taught = problem.path(problem.origin)
        return Solved(
            T,
            e,
            e_lab,
            report.ok and res.feasible,
            tuple(w.describe() for w in report.worst),
            samples,
            fine,
            tcp_deviation_mm(robot, samples, taught),
            None if self.settings.cell is None else self.units.clearance_mm(m, fine.q),
            corridor,
            passes=tuple(t for t, _ in way) if way else None,
            coefficients=x,
        )

    def _retime_once(self, m: PlannedMove, T: float) -> Solved:
        """A MoveL re-timed along its line at ``T`` (its speeddata's TCP speed a bound), verified."""
        robot = self.units.robot(m)
        assert m.step.speed is not None
        r = retime_on_path(
            robot,
            m.path,
            T,
            acceleration_limit=self.units.amax_array(robot),
            jerk_limit=self.units.jmax(robot),
            tcp_speed_limit=m.step.speed.v_tcp / 1000.0,
            tcp=m.step.tcp,
            energy_measure=self.settings.energy,
        )
        self.n_solves += 1
        e, e_lab = trajectory_energy(robot, self.plant(robot), r.fine, self.settings.energy)
        return Solved(
            T,
            e,
            e_lab,
            r.feasible,
            r.limit_excess,
            r.samples,
            r.fine,
            0.0,
            None if self.settings.cell is None else self.units.clearance_mm(m, r.fine.q),
            None,
        )

    def taught(self, i: int) -> Solved:
        """Unit ``i`` as taught: the default cycle's motion over its window (2.5 ms grid)."""
        key = (i, -1)
        if key in self.cache:
            return self.cache[key]
        win = self.units.segment_of[i]
        fine = self.base(i)
        every = self.gradient.check_factor
        samples = Trajectory(t=fine.t[::every], q=fine.q[::every], qd=fine.qd[::every], qdd=fine.qdd[::every])
        robot = self.units.robot(self.units.by_index[i])
        e, e_lab = trajectory_energy(robot, self.plant(robot), fine, self.settings.energy, half_open=True)
        out = Solved(
            win.span,
            e,
            e_lab,
            True,
            (),
            samples,
            fine,
            0.0,
            None
            if self.settings.cell is None
            else min(self.units.default_clearance.get(j, np.inf) for j in win.moves),
            None,
            taught=True,
        )
        self.cache[key] = out
        return out
