"""Optimizing a cycle: the default as the controller runs it, then shapes and durations.

* The default: :func:`plan_cycle` (the controller emulation), evaluated on a 2.5 ms
  grid; energy per move ``Σ |tau qd| dt`` (:func:`joulepath.energy.path_energy`) on the
  physics model (nominal rigid body with the tool's load, ``NOMINAL_FRICTION``) and
  with the lab plant's drive torque, over each move's time slot (from its start to
  the next move's start; waits are at rest and cost nothing).
* Optimized: every ``MoveAbsJ`` / ``MoveJ`` that occurs once in the cycle is
  reshaped by the single-move gradient optimizer (:func:`joulepath.optimize.solve_move`,
  rest to rest, fixed duration, limits as constraints, tool0 within a corridor of
  the taught joint move); runs of them between stops or inside a segment with a
  ``MoveL`` / ``MoveC`` are reshaped as one unit through their fly-by targets. ``MoveL``
  and ``MoveC`` keep their path (line or circle, tool orientation) and are re-timed
  along it (:func:`joulepath.program._cycle_motion.retime_segments`). Moves that occur more than once
  (unless streamed) and moves the RAPID interpreter marked as known only at run time
  (``Step.kept``) run as taught: same path, same controller profile. An optimized move
  comes to rest at its target; where the original stopped (``fine``, before a wait)
  it dwells as the controller does, where it had a zone the next move starts at once.
  What is lost against the default is the overlap of blended moves.
* Time: the optimized moves share ``budget = cycle time - kept moves - dwells - waits``
  (with ``use_waits`` the waits are set to 0 and their time joins the budget). Each
  optimized move is solved at a few durations from the shortest one whose
  minimum-jerk move respects every limit; ``E_i(T) = a + b/T + c/T²`` (a, b, c ≥ 0)
  is fitted to them; SciPy's SLSQP shares the budget on the fitted curves; the moves
  are solved again at the shared durations (25 ms steps), and the better of that and
  the best combination of the solved table (dynamic programming) is kept.
* Chains through fly-by targets: when the chain passes each target is searched once, at one
  duration (:func:`joulepath.program._cycle_passes.tune_passes`, a pattern search over 25 ms steps,
  each step a solve), and kept as shares of the duration for its other solves.
* Verified: every optimized move's path on a 2.5 ms grid against the joint ranges,
  speed and acceleration limits (and the cell's obstacles, with ``cell``); its energy
  on physics and on the lab plant.

The seams (issue 46): the settings and typed results (:mod:`._cycle_model`); the units and their zone
and limit geometry (:mod:`._cycle_units`, :mod:`._cycle_geometry`); the unit solves and the pass-time
probes (:mod:`._cycle_solve`, :mod:`._cycle_passes`); the time allocation, pure functions over the time
table (:mod:`._cycle_allocation`); the motion and its re-timing (:mod:`._cycle_motion`); the result
(:mod:`._cycle_result`). This module orchestrates them.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from joulepath._work import check_work, work_limit
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.optimize import MeasureSummary
from joulepath.program._cycle_allocation import UnitEntries, fitted_share, least_energy_choice
from joulepath.program._cycle_model import (
    STEP,
    Allocation,
    Breakdown,
    CycleMotion,
    CycleResult,
    CycleSettings,
    ParetoPoint,
    Solved,
    TimeBudgetSpent,
)
from joulepath.program._cycle_motion import (
    PlacedUnit,
    RetimedMotion,
    cycle_motion,
    cycle_robot,
    measures,
    move_energies,
    retime_segments,
)
from joulepath.program._cycle_passes import screened, screens_durations, tune_passes
from joulepath.program._cycle_result import CycleRun, cycle_result
from joulepath.program._cycle_solve import UnitSolver
from joulepath.program._cycle_units import CycleUnits
from joulepath.program._resolve import CycleSpec, check_moves_arm
from joulepath.sim import PlannedCycle, check_motion_time, plan_cycle


class CycleOptimizer:
    """One program's cycle optimization on one robot: its units (:attr:`units`, the layout and its
    geometry), their solves (:attr:`solver`), the time table, the allocations and the motion.

    The default cycle is cut into rest-to-rest segments; each unit is optimized as one move through
    its targets, and its own taught motion stays a candidate at its taught duration, so the taught
    cycle time is always reachable (:mod:`joulepath.program._cycle_units`).
    """

    def __init__(
        self,
        spec: CycleSpec,
        settings: CycleSettings,
        *,
        progress: Callable[[str], None] | None = None,
        deadline: float | None = None,
        plan: PlannedCycle | None = None,
    ) -> None:
        self.spec = spec
        self.settings = settings
        self.progress = progress or (lambda msg: None)
        # ``plan``: the taught cycle as planned for ``spec`` under ``settings.controller`` (one
        # already planned, e.g. by the plan for samples before the plan for via points)
        self.plan: PlannedCycle = (
            plan_cycle(spec, settings.controller, progress=self.progress) if plan is None else plan
        )
        check_motion_time(self.plan, spec.source)  # a unit longer than move_s is kept as taught (units)
        if spec.module is None:
            _refuse_short_durations(spec, self.plan)
        self.units = CycleUnits(spec, settings, self.plan, progress=self.progress)
        self.solver = UnitSolver(self.units, progress=self.progress, deadline=deadline)
        self._default_motion: CycleMotion | None = None
        self._default_energies: dict[int, tuple[float, float, float]] | None = None

    # ------------------------------------------------------------ the motion
    def motion(self, choice: dict[int, Solved], use_waits: bool) -> CycleMotion:
        """The cycle with each unit's chosen entry in place of its window (:func:`cycle_motion`)."""
        units, solver = self.units, self.solver
        placed = [
            PlacedUnit(
                members=units.chains[i],
                window=units.segment_of[i],
                passes=tuple(t for t, _ in solver.passes(i, s)),
                solved=s,
            )
            for i, s in choice.items()
            if not s.taught
        ]
        return cycle_motion(self.plan, self.spec, placed, use_waits=use_waits)

    def retime_segments(self, motion: CycleMotion) -> tuple[CycleMotion, dict[int, Solved]]:
        """``motion`` with every segment that has a ``MoveL`` re-timed along its own joint path in it
        (:func:`~joulepath.program._cycle_motion.retime_segments`), and each re-timed move's piece."""
        solver = self.solver
        r: RetimedMotion = retime_segments(
            self.units, motion, plant=solver.plant, progress=self.progress, deadline=solver.deadline
        )
        solver.n_solves += r.n_solves
        solver.timed_out = solver.timed_out or r.timed_out
        return r.motion, r.pieces

    def move_energies(self, motion: CycleMotion) -> dict[int, tuple[float, float]]:
        """Physics and lab J per move over its slot of ``motion`` (:func:`move_energies`)."""
        robot = cycle_robot(self.spec, self.plan)
        return move_energies(self.plan, robot, self.solver.plant(robot), motion, self.settings.energy)

    def measures(
        self, default: CycleMotion, optimized: CycleMotion
    ) -> tuple[tuple[MeasureSummary, ...], dict[str, str]]:
        """Every measure the robot has the data for, of both cycles' whole motion (:func:`measures`)."""
        robot = cycle_robot(self.spec, self.plan)
        return measures(robot, self.solver.plant(robot), default, optimized)

    def default_motion(self) -> CycleMotion:
        """The default cycle as :meth:`motion` samples it (cached)."""
        if self._default_motion is None:
            self._default_motion = self.motion({}, False)
        return self._default_motion

    def default_energies(self) -> dict[int, tuple[float, float, float]]:
        """Per move (step index): (its duration s, physics J, lab J over its slot) of the default cycle;
        a move's slot runs from its start to the next move's start, so the slots add up to the cycle."""
        if self._default_energies is None:
            e = self.move_energies(self.default_motion())
            self._default_energies = {m.index: (m.profile.duration, *e[m.index]) for m in self.plan.moves}
        return dict(self._default_energies)

    def kept_energy(self) -> tuple[float, float]:
        """Physics and lab J of everything outside the units (the default cycle's, less the units'
        taught motion): what the cycle spends besides its units."""
        default = self.default_energies()
        e0 = sum(v[1] for v in default.values())
        e0_lab = sum(v[2] for v in default.values())
        units = [self.solver.taught(i) for i in self.units.optimizable]
        return e0 - sum(s.energy_J for s in units), e0_lab - sum(s.energy_lab_J for s in units)

    def table(self, budget: float) -> dict[int, list[Solved]]:
        """Each unit: its taught motion, then solved at ``table_points`` durations from its shortest
        to the most the budget leaves it (the others at their shortest), and at its taught duration."""
        k = self.settings.table_points
        shares = np.concatenate([[0.0], np.geomspace(0.06, 1.0, k - 1)])
        floor = {i: min(self.solver.t_lo[i], self.units.span[i]) for i in self.units.optimizable}
        out: dict[int, list[Solved]] = {i: [self.solver.taught(i)] for i in self.units.optimizable}
        if not self._reshape(out, long=False):  # each reshaped from its taught motion (a long chain's
            return out  # after its solves: solve_on_taught)
        for n_move, i in enumerate(self.units.optimizable, start=1):
            hi = budget - (sum(floor.values()) - floor[i])
            # a unit is solved at most as long as the move_s limit (or its own taught duration): idle
            # time beyond what the moves can use stays a wait (a long wait with --use-waits)
            hi = min(hi, max(self.units.span[i], work_limit("move_s")))
            if hi < self.solver.t_lo[i] - 1e-9:
                continue  # the optimizer's shortest does not fit: taught only
            self.progress(f"unit {n_move}/{len(self.units.optimizable)}: solving at up to {k + 1} durations")
            if i in self.units.within:  # its ends are the taught motion's: at its own duration only
                try:
                    tune_passes(self.solver, i, round(self.units.span[i] / STEP) * STEP)
                    out[i].append(self.solver.solve(i, round(self.units.span[i] / STEP) * STEP))
                except TimeBudgetSpent:
                    return out
                continue
            units = {
                int(round((self.solver.t_lo[i] + s * (hi - self.solver.t_lo[i])) / STEP)) for s in shares
            }
            own = int(np.floor(self.units.span[i] / STEP + 1e-9))
            if own * STEP >= self.solver.t_lo[i] - 1e-9 and own * STEP <= hi + 1e-9:
                units.add(own)
            lo_u = int(np.ceil(self.solver.t_lo[i] / STEP - 1e-9))
            units = {max(u, lo_u) for u in units if u * STEP <= hi + 1e-9} or {lo_u}
            try:  # when the chain passes its targets: searched at its own duration (or the middle one)
                tune_passes(self.solver, i, (own if own in units else sorted(units)[len(units) // 2]) * STEP)
            except TimeBudgetSpent:
                return out
            if screens_durations(self.solver, i, max(units)):
                try:
                    out[i].extend(screened(self.solver, i, sorted(units)))
                except TimeBudgetSpent:
                    out[i].extend(s for (j, u), s in self.solver.cache.items() if j == i and u in units)
                    return out
                continue
            for u in sorted(units):
                try:
                    out[i].append(self.solver.solve(i, u * STEP))
                except TimeBudgetSpent:
                    return out
        self._reshape(out, long=True)  # a long chain's, from its solve
        return out

    def _reshape(self, out: dict[int, list[Solved]], *, long: bool) -> bool:
        """The units reshaped from their taught motion (:meth:`UnitSolver.solve_on_taught`) into ``out``:
        those whose reshaping starts from their solve (``long``, :meth:`UnitSolver.long_on_taught`) or the
        others; False where the time budget ran out."""
        for n_unit, i in enumerate(self.units.optimizable, start=1):
            if self.solver.long_on_taught(i) != long:
                continue
            self.progress(f"unit {n_unit}/{len(self.units.optimizable)}: reshaping its taught motion")
            try:
                reshaped = self.solver.solve_on_taught(i)
            except TimeBudgetSpent:
                return False
            if reshaped is not None:
                out[i].append(reshaped)
        return True

    def entries(self, table: dict[int, list[Solved]]) -> tuple[UnitEntries, ...]:
        """The time table as :func:`~joulepath.program._cycle_allocation.least_energy_choice` and
        :func:`~joulepath.program._cycle_allocation.fitted_share` read it (units in order)."""
        return tuple(
            UnitEntries(
                durations=np.array([s.duration for s in table[i]], dtype=float),
                energies=np.array([s.energy_J for s in table[i]], dtype=float),
                usable=np.array([s.usable for s in table[i]], dtype=bool),
                taught=np.array([s.taught for s in table[i]], dtype=bool),
            )
            for i in self.units.optimizable
        )

    def dp(self, table: dict[int, list[Solved]], budget: float) -> dict[int, Solved] | None:
        """The least-energy choice of one usable entry per unit with Σ durations ≤ budget
        (:func:`~joulepath.program._cycle_allocation.least_energy_choice`)."""
        picks = least_energy_choice(self.entries(table), budget)
        if picks is None:
            return None
        return {
            i: table[i][k] for i, k in zip(reversed(self.units.optimizable), reversed(picks), strict=True)
        }

    def continuous(self, table: dict[int, list[Solved]], budget: float) -> dict[int, Solved] | None:
        """Share the budget on the fitted curves ``a + b/T + c/T²`` of the solved entries
        (:func:`~joulepath.program._cycle_allocation.fitted_share`), then solve at the shares; None
        when a unit has no usable solved entry or the budget does not reach every unit's shortest."""
        idx = self.units.optimizable
        lo = np.array([self.solver.t_lo[i] for i in idx], dtype=float)
        fixed = np.array([i in self.units.within for i in idx], dtype=bool)
        units = fitted_share(self.entries(table), lo, fixed, budget, step=STEP)
        if units is None:
            return None
        try:
            return {i: self.solver.solve(i, float(u * STEP)) for i, u in zip(idx, units, strict=True)}
        except TimeBudgetSpent:
            return None

    def evaluate(self, choice: dict[int, Solved], waits: float) -> Allocation:
        """Cycle energies (J) and time (s) of one entry per unit, the kept moves and ``waits`` s."""
        kept, kept_lab = self.kept_energy()
        e = sum(s.energy_J for s in choice.values()) + kept
        e_lab = sum(s.energy_lab_J for s in choice.values()) + kept_lab
        cycle = self.units.fixed_time + waits + sum(s.duration for s in choice.values())
        return Allocation(
            {i: s.duration for i, s in choice.items()}, float(e), float(e_lab), cycle, dict(choice)
        )

    def at_taught_durations(self, table: dict[int, list[Solved]]) -> dict[int, Solved]:
        """Each unit reshaped at its own taught duration (in whole samples), where that was solved
        and is usable; else as taught."""
        out: dict[int, Solved] = {}
        for i in self.units.optimizable:
            own = int(np.floor(self.units.span[i] / STEP + 1e-9))
            same = [s for s in table[i] if not s.taught and s.usable and int(round(s.duration / STEP)) == own]
            out[i] = min([*same, self.solver.taught(i)], key=lambda s: s.energy_J)
        return out

    def best(
        self,
        table: dict[int, list[Solved]],
        budget: float,
        waits: float,
    ) -> Allocation:
        """The least-energy verified allocation within ``budget``: dynamic programming over the
        table, the fitted-curve share, and every unit as taught (where the budget holds it)."""
        candidates = []
        d = self.dp(table, budget)
        if d is not None:
            candidates.append(self.evaluate(d, waits))
        c = self.continuous(table, budget)
        if c is not None and all(s.usable for s in c.values()):
            candidates.append(self.evaluate(c, waits))
        if sum(self.units.span.values()) <= budget + 1e-9:
            candidates.append(
                self.evaluate({i: self.solver.taught(i) for i in self.units.optimizable}, waits)
            )
        if not candidates:
            raise LimitViolation(
                f"{self.spec.source}: no allocation of the durations keeps every optimized move "
                "within its limits"
            )
        return min(candidates, key=lambda a: a.energy_J)


def check_cycle(spec: CycleSpec, settings: CycleSettings) -> None:
    """What :func:`optimize_cycle` refuses before it solves anything, without solving (the default
    cycle is planned; a cycle file's ``duration_s`` the arm cannot keep is refused)."""
    plan = plan_cycle(spec, settings.controller)
    if spec.module is None:
        _refuse_short_durations(spec, plan)


def _refuse_short_durations(spec: CycleSpec, plan: PlannedCycle) -> None:
    """A cycle file's ``duration_s`` is the move's time as the arm runs it: refuse one it cannot keep.

    (A RAPID ``\\T`` shorter than the fastest motion is run at full speed by the controller, as
    the emulation does; a cycle file has no controller that could stand in for it.)
    """
    for m in plan.moves:
        asked = m.step.time_s
        if asked is not None and m.profile.duration > asked * (1 + 1e-9) + 1e-9:
            least = np.ceil(m.profile.duration * 1000) / 1000
            raise InvalidInput(
                f"{spec.source}: step {m.step.line}: duration_s = {asked:g} s is shorter than the fastest "
                f"the arm makes this move within its speed, acceleration and jerk limits "
                f"({m.profile.duration:.3f} s); give duration_s ≥ {least:g}"
            )


def optimize_cycle(
    spec: CycleSpec,
    settings: CycleSettings,
    *,
    progress: Callable[[str], None] | None = None,
    pareto_points: int = 0,
    pareto_span: float = 0.3,
) -> CycleResult:
    """Optimize a cycle at the default's cycle time (or ``settings.cycle_time``); verified.

    Never refused at the taught cycle time: each unit's taught motion is a candidate, so
    in the worst case the taught cycle itself is returned, 0 % saved. ``pareto_points`` (≥ 3):
    also energy against cycle time from the shortest cycle to ``1 + pareto_span`` times it
    (:attr:`CycleResult.pareto`, :func:`pareto`, on the same solves).
    """
    result, opt = _optimize_cycle(spec, settings, progress=progress)
    if pareto_points:
        opt.progress("energy against cycle time...")
        front = pareto(opt, points=pareto_points, span=pareto_span, use_waits=settings.use_waits)
        result = replace(result, pareto=tuple(front))
    return result


def _optimize_cycle(
    spec: CycleSpec,
    settings: CycleSettings,
    *,
    progress: Callable[[str], None] | None = None,
    plan: PlannedCycle | None = None,
) -> tuple[CycleResult, CycleOptimizer]:
    """:func:`optimize_cycle`, on ``plan`` when given (the taught cycle planned under
    ``settings.controller``: the plan for via points takes the one for samples had), and the
    optimizer it ran (its units, solves and time table: for :func:`pareto` and white-box tests)."""
    check_moves_arm(spec)
    t_start = time.perf_counter()
    deadline = None if settings.max_time_s is None else t_start + settings.max_time_s
    opt = CycleOptimizer(spec, settings, progress=progress, deadline=deadline, plan=plan)
    plan = opt.plan
    target = plan.cycle_time if settings.cycle_time is None else settings.cycle_time
    check_work(  # the time the moves may take at this cycle time, before any of them is solved
        "motion_s",
        target - opt.units.waits_kept(settings.use_waits),
        f"{spec.source}: at a cycle time of {target:g} s",
        "give a shorter cycle time, or declare fewer waits idle for --use-waits",
    )
    shortest = opt.solver.shortest_cycle + opt.units.waits_kept(settings.use_waits)
    if target < shortest - 1e-9:
        raise LimitViolation(
            f"{spec.source}: cycle time {target:.3f} s is shorter than the shortest this program "
            "reaches with its optimized moves at their shortest "
            f"({shortest:.3f} s; the default runs {plan.cycle_time:.3f} s); "
            f"give --cycle-time {np.ceil(shortest * 1000) / 1000:.3f} or more"
            + ("" if settings.use_waits or not opt.units.idle_total else ", or allow --use-waits")
        )
    default = opt.default_energies()
    e0 = sum(v[1] for v in default.values())
    b_plain = opt.units.budget(target, use_waits=False)
    b_waits = opt.units.budget(target, use_waits=True)
    table = opt.table(b_waits if settings.use_waits else b_plain)
    opt.progress("sharing the cycle time")
    shape = opt.evaluate(opt.at_taught_durations(table), opt.units.wait_total)
    floor_plain = sum(min(opt.solver.t_lo[i], opt.units.span[i]) for i in opt.units.optimizable)
    plain = opt.best(table, b_plain, opt.units.wait_total) if b_plain >= floor_plain - 1e-9 else None
    final = plain if not settings.use_waits else opt.best(table, b_waits, opt.units.waits_kept(True))
    assert final is not None
    if plain is None:
        plain = final
    breakdown = Breakdown(
        default_J=e0,
        shape_J=shape.energy_J if shape.cycle_time_s <= target + 1e-9 else plain.energy_J,
        allocation_J=plain.energy_J,
        waits_J=final.energy_J if settings.use_waits else None,
    )
    result = _assemble(opt, final, table, breakdown, target=target, shortest=shortest, t_start=t_start)
    if settings.rapid_plan and settings.follow == "samples" and spec.module is not None:
        left = (
            None
            if settings.max_time_s is None
            else max(1.0, settings.max_time_s - (time.perf_counter() - t_start))
        )
        via = replace(settings, follow="via-points", rapid_plan=False, max_time_s=left)
        try:
            rapid, _ = _optimize_cycle(spec, via, progress=progress, plan=plan)
        except LimitViolation:  # no plan for via points at this cycle time: EGM only
            rapid = None
        if rapid is not None and rapid.paths:
            result = replace(result, rapid_plan=rapid)
    return result, opt


def _assemble(
    opt: CycleOptimizer,
    final: Allocation,
    table: dict[int, list[Solved]],
    breakdown: Breakdown,
    *,
    target: float,
    shortest: float,
    t_start: float,
    along_paths: bool = True,
) -> CycleResult:
    """The verified result of one allocation: its motion (``along_paths``: with the segments with a
    ``MoveL`` re-timed along their path, and the result without that as its
    :attr:`CycleResult.unretimed`), the energies on it, and the result built from them
    (:func:`~joulepath.program._cycle_result.cycle_result`)."""
    motion = opt.motion(final.choice, opt.settings.use_waits)
    retimed: dict[int, Solved] = {}
    if along_paths:
        motion, retimed = opt.retime_segments(motion)
    spent = opt.move_energies(motion)  # the reported energies: per move, on the cycle's motion
    energies, unavailable = opt.measures(opt.default_motion(), motion)
    run = CycleRun(
        motion=motion,
        retimed=retimed,
        spent=spent,
        energies=energies,
        unavailable=unavailable,
        default=opt.default_energies(),
        default_planned=opt.default_motion().trajectory,
    )
    result = cycle_result(
        opt.units, opt.solver, final, table, breakdown, run, target=target, shortest=shortest, t_start=t_start
    )
    if retimed:
        before = _assemble(
            opt, final, table, breakdown, target=target, shortest=shortest, t_start=t_start, along_paths=False
        )
        result = replace(
            result,
            breakdown=replace(breakdown, path_retimed_J=result.optimized_energy_J),
            unretimed=before,
            wall_s=time.perf_counter() - t_start,
        )
    return result


def pareto(
    opt: CycleOptimizer, *, points: int = 10, span: float = 0.3, use_waits: bool = False
) -> list[ParetoPoint]:
    """Energy against cycle time from the shortest feasible cycle to ``(1 + span)`` times it.

    One table of solved, verified moves covers the whole range; each point is the
    least-energy combination of table entries within its budget (dynamic programming),
    so every point is made of verified solves.
    """
    waits = opt.units.waits_kept(use_waits)
    c_min = opt.solver.shortest_cycle + waits
    c_max = c_min * (1 + span)
    table = opt.table(opt.units.budget(c_max, use_waits))
    out = []
    for c in np.linspace(c_min, c_max, points):
        d = opt.dp(table, opt.units.budget(float(c), use_waits) + 1e-9)
        if d is None:
            continue
        a = opt.evaluate(d, waits)
        out.append(
            ParetoPoint(
                float(c), a.energy_J, a.energy_lab_J, tuple(d[i].duration for i in opt.units.optimizable)
            )
        )
    return out
