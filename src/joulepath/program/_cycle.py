"""Optimizing a cycle: the default as the controller runs it, then shapes and durations.

* The default: :func:`plan_cycle` (the controller emulation), evaluated on a 2.5 ms
  grid; energy per move ``Σ |tau qd| dt`` (:func:`joulepath.energy.path_energy`) on the
  physics model (nominal rigid body with the tool's load, ``NOMINAL_FRICTION``) and
  with the lab plant's drive torque, over each move's time slot (from its start to
  the next move's start; waits are at rest and cost nothing).
* Optimized: every ``MoveAbsJ`` / ``MoveJ`` that occurs once in the cycle is
  reshaped by the single-move gradient optimizer (:func:`joulepath.optimize.solve_move`,
  rest to rest, fixed duration, limits as constraints, tool0 within a corridor of
  the taught joint move). ``MoveL`` moves and moves that occur more than once are
  kept: same path, same controller profile, run on their own. An optimized move
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
* Verified: every optimized move's path on a 2.5 ms grid against the joint ranges,
  speed and acceleration limits (and the cell's obstacles, with ``cell``); its energy
  on physics and on the lab plant.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Robot
from joulepath.energy import joint_energy, path_energy
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.optimize import (
    ACCEL_TIME,
    GradientSettings,
    acceleration_limit,
    check_limits,
    jerk_limit,
)
from joulepath.optimize._gradient import SplineProblem, optimize_spline, solve_move
from joulepath.optimize._verify import shortest_feasible_duration, tcp_deviation_mm
from joulepath.program._cell import Cell, clearance
from joulepath.program._resolve import CycleSpec, Step
from joulepath.sim import ControllerConfig, Plant, make_plant
from joulepath.sim._timing import (
    FINE_DT,
    PlannedCycle,
    PlannedMove,
    evaluate_cycle,
    plan_cycle,
    standalone,
)
from joulepath.sim._via import layout as via_layout
from joulepath.trajectory import SplineBasis, Trajectory
from joulepath.units import SAMPLE_PERIOD

STEP = SAMPLE_PERIOD
"""s: optimized durations are whole numbers of 25 ms samples."""


@dataclass(frozen=True, slots=True, kw_only=True)
class CycleSettings:
    """Settings of a cycle optimization.

    ``cycle_time``: s, or None for the default program's cycle time. ``use_waits``:
    spend ``WaitTime`` slack on the moves. ``table_points``: durations solved per
    move; ``via_every``: average spacing, in 25 ms samples, of the via points written per
    optimized move (:func:`joulepath.sim._via.layout`). ``corridor_mm``: tool0 stays
    within this distance of the joint-interpolated taught move (the path ``MoveJ`` itself
    follows) at every sample (None: none). ``accel_time`` and ``jerk_time`` set the
    optimized moves' acceleration and jerk limits (:mod:`joulepath.sim`'s; ``jerk_time``
    0, the default for now: no jerk limit — under the controller's jerk limit,
    :data:`joulepath.sim.JERK_TIME`, an optimized move starts from a minimum-jerk move, slower
    than the controller's own ramps, and a program's own cycle time is out of reach).
    ``cell``: obstacles every optimized move must clear (a move too close is solved
    again in corridors of 1/2, 1/4, 1/8 of ``corridor_mm``, else not used).
    ``warm_start``: start each solve of a move from its nearest solved duration
    (time-scaled) and run only the last continuation stages; measured not faster and
    slightly worse (BENCHMARKS.md), so off by default. ``fly_by``: consecutive
    optimizable moves joined by a zone (a fly-by target) are solved as one chain that
    passes each such target exactly, at whatever speed saves most, instead of stopping
    there; False: every optimized move runs rest to rest.
    """

    cycle_time: float | None = None
    use_waits: bool = False
    table_points: int = 4
    via_every: int = 2
    accel_time: float = ACCEL_TIME
    jerk_time: float = 0.0
    corridor_mm: float | None = 100.0
    cell: Cell | None = None
    warm_start: bool = False
    fly_by: bool = True
    gradient: GradientSettings = field(default_factory=GradientSettings)
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    seed: int = 0

    def __post_init__(self) -> None:
        if self.cycle_time is not None and not (np.isfinite(self.cycle_time) and 0 < self.cycle_time <= 3600):
            raise InvalidInput(f"cycle time must be a positive number of seconds, got {self.cycle_time}")
        if not 2 <= self.table_points <= 20:
            raise InvalidInput(f"table_points must be 2..20, got {self.table_points}")
        if not 1 <= self.via_every <= 40:
            raise InvalidInput(f"via_every must be 1..40, got {self.via_every}")
        if self.corridor_mm is not None and not (np.isfinite(self.corridor_mm) and self.corridor_mm > 0):
            raise InvalidInput(f"corridor must be a positive number of mm, got {self.corridor_mm}")
        if not 0 < self.accel_time <= 10:
            raise InvalidInput(f"accel_time must be in (0, 10] s, got {self.accel_time}")
        if not 0 <= self.jerk_time <= 10:
            raise InvalidInput(f"jerk_time must be in [0, 10] s (0: no jerk limit), got {self.jerk_time}")


@dataclass(frozen=True, slots=True, eq=False)
class Solved:
    """One optimized move at one duration, verified."""

    duration: float
    energy_J: float
    energy_lab_J: float
    limits_ok: bool
    limit_excess: tuple[str, ...]
    samples: Trajectory  # 25 ms
    fine: Trajectory  # 2.5 ms
    corridor_dev_mm: float  # tool0 from the joint-interpolated taught move, largest
    clearance_mm: float | None = None  # smallest distance to the cell's obstacles (None: no cell)
    corridor_used_mm: float | None = None

    @property
    def usable(self) -> bool:
        return self.limits_ok and (self.clearance_mm is None or self.clearance_mm >= 0.0)


@dataclass(frozen=True, slots=True)
class MoveOutcome:
    """One move of the cycle: default against optimized (s, J)."""

    line: int
    label: str
    optimized: bool
    note: str
    default_duration_s: float
    optimized_duration_s: float
    default_energy_J: float
    optimized_energy_J: float
    default_lab_J: float
    optimized_lab_J: float
    limits_ok: bool
    limit_excess: tuple[str, ...]
    via_points: int
    via_max_joint_dev_deg: float
    via_max_tcp_dev_mm: float
    corridor_dev_mm: float
    default_clearance_mm: float | None = None
    optimized_clearance_mm: float | None = None


@dataclass(frozen=True, slots=True)
class Allocation:
    """Durations (s) of the optimized moves, by step index, and the verified cycle energies (J)."""

    durations: dict[int, float]
    energy_J: float
    energy_lab_J: float
    cycle_time_s: float


@dataclass(frozen=True, slots=True)
class Breakdown:
    """Where the saving comes from (J on physics): E0 default, E1 shapes at the default's
    proportions of time, E2 re-allocated durations, E3 with the waits spent."""

    default_J: float
    shape_J: float
    allocation_J: float
    waits_J: float | None

    @property
    def by_shape_pct(self) -> float:
        return 100 * (self.default_J - self.shape_J) / self.default_J

    @property
    def by_allocation_pct(self) -> float:
        return 100 * (self.shape_J - self.allocation_J) / self.default_J

    @property
    def by_waits_pct(self) -> float | None:
        return None if self.waits_J is None else 100 * (self.allocation_J - self.waits_J) / self.default_J


@dataclass(frozen=True, slots=True, eq=False)
class CycleResult:
    """A verified cycle optimization."""

    moves: tuple[MoveOutcome, ...]
    default_cycle_s: float
    target_cycle_s: float
    optimized_cycle_s: float
    default_energy_J: float
    optimized_energy_J: float
    default_lab_J: float
    optimized_lab_J: float
    breakdown: Breakdown
    waits: tuple[tuple[int, float, float], ...]  # (line, default s, optimized s)
    fixed_lines: tuple[int, ...]
    limits_ok: bool
    corridor_mm: float | None
    cell: dict[str, object] | None
    shortest_cycle_s: float
    wall_s: float
    n_solves: int
    paths: dict[int, Solved]  # by step index: the optimized moves
    spec: CycleSpec
    chains: dict[int, tuple[int, ...]] = field(default_factory=dict)  # fly-by chains (step indices)
    vias: dict[int, tuple[int, ...]] = field(default_factory=dict)  # per optimized move: indices into .fine

    @property
    def saved_pct(self) -> float:
        return 100 * (self.default_energy_J - self.optimized_energy_J) / self.default_energy_J

    @property
    def saved_lab_pct(self) -> float:
        return 100 * (self.default_lab_J - self.optimized_lab_J) / self.default_lab_J


@dataclass(frozen=True, slots=True)
class ParetoPoint:
    """Energy at one cycle time (every move a verified solve of the table)."""

    cycle_time_s: float
    energy_J: float
    energy_lab_J: float
    durations: tuple[float, ...]


def _energy(robot: Robot, plant: Plant, traj: Trajectory) -> tuple[float, float]:
    tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
    lab = plant.drive_torque(traj.q, traj.qd, traj.qdd)
    return float(path_energy(tau, traj.qd, traj.dt).total), float(path_energy(lab, traj.qd, traj.dt).total)


class CycleOptimizer:
    """Default cycle, duration table, allocations and verification of one program on one robot."""

    def __init__(
        self,
        spec: CycleSpec,
        settings: CycleSettings,
        *,
        progress: Callable[[str], None] | None = None,
    ) -> None:
        self.spec = spec
        self.settings = settings
        self.progress = progress or (lambda msg: None)
        self.plan: PlannedCycle = plan_cycle(spec, settings.controller)
        self._plants: dict[int, Plant] = {}
        self.cache: dict[tuple[int, int], Solved] = {}
        self.n_solves = 0
        moves = self.plan.moves
        self.by_index = {m.index: m for m in moves}
        self.default_clearance: dict[int, float] = {}
        if settings.cell is not None:
            self._default_clearance()
        self.optimizable = [
            m.index
            for m in moves
            if not m.step.linear
            and not m.step.repeated
            and m.profile.duration > 0
            and self.default_clearance.get(m.index, np.inf) >= 0.0
        ]
        self.kept = [m.index for m in moves if m.index not in self.optimizable]
        self.chains = self._chains() if settings.fly_by else {i: (i,) for i in self.optimizable}
        self.optimizable = list(self.chains)  # one unit per chain, keyed by its first move
        self.dwell = settings.controller.fine_dwell
        self.wait_total = float(sum(s for _, _, s in self.plan.waits))
        self.kept_time = float(sum(self.by_index[i].profile.duration for i in self.kept))
        self.n_stops = sum(1 for m in moves if m.stops)
        self.fixed_time = self.n_stops * self.dwell + self.kept_time
        self.t_lo: dict[int, float] = {}
        self.leg_lo: dict[int, tuple[float, ...]] = {}  # each move's shortest rest-to-rest duration
        for i, members in self.chains.items():
            single: list[float] = []
            for j in members:
                m = self.by_index[j]
                robot = self._robot(m)
                shortest = shortest_feasible_duration(
                    robot,
                    m.path.q0,
                    m.path.q1,
                    dt=STEP,
                    friction=NOMINAL_FRICTION,
                    acceleration_limit=self._amax(robot),
                    jerk_limit=self._jmax(robot),
                )
                if shortest is None:
                    raise LimitViolation(
                        f"{spec.source}:{m.step.line}: {m.step.label}: no feasible duration found"
                    )
                single.append(shortest)
            self.leg_lo[i] = tuple(single)
            self.t_lo[i] = single[0] if len(members) == 1 else self._chain_shortest(i, sum(single))
        self.shortest_cycle = self.fixed_time + sum(self.t_lo.values())

    # ------------------------------------------------------------ chains
    def _chains(self) -> dict[int, tuple[int, ...]]:
        """Runs of consecutive optimizable moves joined by fly-by targets (zones), by first move."""
        ok = set(self.optimizable)
        out: dict[int, tuple[int, ...]] = {}
        run: list[int] = []
        for m in self.plan.moves:
            if m.index in ok and run and not self.by_index[run[-1]].stops:
                run.append(m.index)
                continue
            if run:
                out[run[0]] = tuple(run)
            run = [m.index] if m.index in ok else []
        if run:
            out[run[0]] = tuple(run)
        return out

    def waypoints(self, i: int, T: float) -> tuple[tuple[float, FloatArray], ...]:
        """The chain's inner targets and when it passes them: ``T`` shared in proportion to each
        move's shortest rest-to-rest duration, in whole 25 ms samples, each leg at least two
        samples long (at the sum of those durations, each leg gets its own)."""
        members = self.chains[i]
        if len(members) == 1:
            return ()
        base = np.array(self.leg_lo[i])
        units = int(round(T / STEP))
        edges = np.round(np.cumsum(base)[:-1] / base.sum() * units).astype(int)
        for k in range(edges.size):  # at least 2 samples per leg
            edges[k] = max(edges[k], (edges[k - 1] if k else 0) + 2)
        for k in range(edges.size - 1, -1, -1):
            edges[k] = min(edges[k], (edges[k + 1] if k + 1 < edges.size else units) - 2)
        return tuple(
            (float(e * STEP), self.by_index[j].path.q1) for e, j in zip(edges, members[:-1], strict=True)
        )

    def _chain_problem(self, i: int, T: float) -> SplineProblem:
        """The chain's problem at ``T``: fine knots, no corridor (its smoothest path is ``origin``)."""
        m0, m1 = self.by_index[i], self.by_index[self.chains[i][-1]]
        robot = self._robot(m0)
        g = self.settings.gradient
        return SplineProblem(
            robot,
            m0.path.q0,
            m1.path.q1,
            T,
            NOMINAL_FRICTION,
            SplineBasis(T, knot_spacing=g.knot_spacing, degree=g.degree, dt=STEP),
            check_factor=g.check_factor,
            acceleration_limit=self._amax(robot),
            waypoints=self.waypoints(i, T),
            jerk_limit=self._jmax(robot),
        )

    def _chain_shortest(self, i: int, upper: float) -> float:
        """Shortest whole-sample chain duration: the first from half the sum of its moves' shortest
        rest-to-rest durations (``upper``) whose smoothest path through the targets keeps every limit,
        else ``upper`` (the moves back to back, each from rest to rest, are feasible there)."""
        robot = self._robot(self.by_index[i])
        amax = self._amax(robot)
        n_legs = len(self.chains[i])
        units = max(2 * n_legs + 2, int(np.floor(0.5 * upper / STEP)))
        while units * STEP < upper - 1e-9:
            T = units * STEP
            problem = self._chain_problem(i, T)
            fine = problem.path(problem.origin, fine=True)
            report = check_limits(
                robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=self._jmax(robot)
            )
            if report.ok:
                return round(T, 9)
            units += 1
        return round(upper, 9)

    def split(self, i: int, s: Solved) -> dict[int, Solved]:
        """A chain's solve cut at its targets into one piece per move (times from 0 in each piece;
        neighbouring pieces share their boundary sample)."""
        members = self.chains[i]
        if len(members) == 1:
            return {i: s}
        cuts = [0.0, *(t for t, _ in self.waypoints(i, s.duration)), s.duration]
        robot = self._robot(self.by_index[i])
        plant = self.plant(robot)
        out: dict[int, Solved] = {}
        for k, (j, a, b) in enumerate(zip(members, cuts[:-1], cuts[1:], strict=True)):
            pieces = []
            for tr in (s.samples, s.fine):
                sel = (tr.t >= a - 1e-9) & (tr.t <= b + 1e-9)
                pieces.append(Trajectory(t=tr.t[sel] - a, q=tr.q[sel], qd=tr.qd[sel], qdd=tr.qdd[sel]))
            f = pieces[1]
            # the shared sample at a target counts half in each piece: the pieces sum to the chain
            w = np.ones((f.t.size, 1))
            if k > 0:
                w[0] = 0.5
            if k < len(members) - 1:
                w[-1] = 0.5
            tau = robot.inverse_dynamics(f.q, f.qd, f.qdd, friction=NOMINAL_FRICTION)
            e = float((w * joint_energy(tau, f.qd, s.fine.dt)).sum())
            e_lab = float((w * joint_energy(plant.drive_torque(f.q, f.qd, f.qdd), f.qd, s.fine.dt)).sum())
            out[j] = replace(
                s, duration=round(b - a, 9), energy_J=e, energy_lab_J=e_lab, samples=pieces[0], fine=f
            )
        return out

    # ------------------------------------------------------------ helpers
    def _clearance_mm(self, m: PlannedMove, q: FloatArray) -> float:
        """Smallest distance (mm) beyond the margin to the cell along ``q``; negative: too close."""
        cell = self.settings.cell
        assert cell is not None and m.step.tcp is not None
        c = clearance(cell, self._robot(m), q, m.step.tcp)
        return 1000.0 * (c.distance - cell.margin)

    def _default_clearance(self) -> None:
        plan = self.plan
        for m in plan.moves:
            if m.profile.duration == 0:
                continue
            t = np.linspace(m.t0, m.t_end, max(2, int(np.ceil(m.profile.duration / FINE_DT)) + 1))
            self.default_clearance[m.index] = self._clearance_mm(m, evaluate_cycle(plan, t).q)

    def _robot(self, m: PlannedMove) -> Robot:
        assert m.step.robot is not None
        return m.step.robot

    def _amax(self, robot: Robot) -> FloatArray | None:
        return acceleration_limit(robot, self.settings.accel_time)

    def _jmax(self, robot: Robot) -> FloatArray | None:
        return jerk_limit(robot, self.settings.accel_time, self.settings.jerk_time)

    def plant(self, robot: Robot) -> Plant:
        key = id(robot)
        if key not in self._plants:
            self._plants[key] = make_plant("lab", robot)
        return self._plants[key]

    def solve(self, i: int, duration: float) -> Solved:
        """The optimized move ``i`` at ``duration`` (a whole number of 25 ms samples), verified; cached."""
        units = int(round(duration / STEP))
        key = (i, units)
        if key in self.cache:
            return self.cache[key]
        m = self.by_index[i]
        T = units * STEP
        corridors: list[float | None] = [self.settings.corridor_mm]
        if self.settings.cell is not None:  # tighter corridors around the (clear) taught move
            first = self.settings.corridor_mm or 100.0
            corridors += [first / 2, first / 4, first / 8]
        warm = self._neighbour(i, T) if self.settings.warm_start and len(self.chains[i]) == 1 else None
        out: Solved | None = None
        for corridor in corridors:
            out = self._solve_once(m, T, units, corridor, warm)
            if out.usable or not out.limits_ok:
                break
        assert out is not None
        self.cache[key] = out
        return out

    def _neighbour(self, i: int, T: float) -> Solved | None:
        """The usable solve of move ``i`` at the nearest other duration (a warm start), if any."""
        near = [s for (j, _), s in self.cache.items() if j == i and s.usable]
        return min(near, key=lambda s: abs(s.duration - T)) if near else None

    def _warm_problem(
        self, m: PlannedMove, T: float, corridor: float | None, warm: Solved
    ) -> tuple[Any, Any]:
        """The fine-knot problem at ``T`` and the warm path in its coefficients (time-scaled, lstsq)."""
        g = self.settings.gradient
        robot = self._robot(m)
        basis = SplineBasis(T, knot_spacing=g.knot_spacing, degree=g.degree, dt=STEP)
        problem = SplineProblem(
            robot,
            m.path.q0,
            m.path.q1,
            T,
            NOMINAL_FRICTION,
            basis,
            check_factor=g.check_factor,
            max_deviation_m=None if corridor is None else corridor / 1000,
            acceleration_limit=self._amax(robot),
            jerk_limit=self._jmax(robot),
        )
        t_old = problem.fine.t * (warm.duration / T)
        q_old = np.column_stack(
            [np.interp(t_old, warm.fine.t, warm.fine.q[:, j]) for j in range(robot.n_joints)]
        )
        c = np.linalg.lstsq(problem.fine.B, q_old - problem.default_fine.q, rcond=None)[0]
        return problem, c

    def _solve_once(
        self, m: PlannedMove, T: float, units: int, corridor: float | None, warm: Solved | None = None
    ) -> Solved:
        robot = self._robot(m)
        amax = self._amax(robot)
        seq = np.random.SeedSequence([self.settings.seed, m.index, units])
        rng = np.random.default_rng(seq)
        if warm is not None:  # from the nearest solved duration: the last continuation stages only
            problem, start = self._warm_problem(m, T, corridor, warm)
            g = self.settings.gradient
            refine = replace(g, n_starts=1, continuation=g.continuation[-g.refine_stages :])
            res = optimize_spline(problem, refine, rng=rng, initial=start)
        else:
            res, problem = solve_move(
                robot,
                m.path.q0,
                self.by_index[self.chains[m.index][-1]].path.q1,
                T,
                friction=NOMINAL_FRICTION,
                settings=self.settings.gradient,
                rng=rng,
                acceleration_limit=amax,
                max_deviation_m=None if corridor is None else corridor / 1000,
                waypoints=self.waypoints(m.index, T),
                jerk_limit=self._jmax(robot),
            )
        self.n_solves += 1
        x = res.coefficients.ravel()
        fine = problem.path(x, fine=True)
        report = check_limits(
            robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=self._jmax(robot)
        )
        e, e_lab = _energy(robot, self.plant(robot), fine)
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
            None if self.settings.cell is None else self._clearance_mm(m, fine.q),
            corridor,
        )

    # ------------------------------------------------------------ default
    def default_energies(self) -> dict[int, tuple[float, float, float]]:
        """Per move (step index): (slot duration s, physics J, lab J) of the default cycle."""
        plan = self.plan
        n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
        t = np.linspace(0.0, plan.cycle_time, n)
        traj = evaluate_cycle(plan, t)
        starts = [m.t0 for m in plan.moves] + [plan.cycle_time]
        out: dict[int, tuple[float, float, float]] = {}
        for k, m in enumerate(plan.moves):
            a = int(np.searchsorted(t, starts[k], side="left"))
            b = int(np.searchsorted(t, starts[k + 1], side="left"))
            if b - a < 2:
                out[m.index] = (m.profile.duration, 0.0, 0.0)
                continue
            sl = slice(a, b)
            part = Trajectory(t=t[sl], q=traj.q[sl], qd=traj.qd[sl], qdd=traj.qdd[sl])
            robot = self._robot(m)
            e, e_lab = _energy(robot, self.plant(robot), part)
            out[m.index] = (m.profile.duration, e, e_lab)
        return out

    def kept_energies(self) -> dict[int, tuple[float, float]]:
        """Kept moves run on their own (rest to rest): physics and lab J."""
        out = {}
        for i in self.kept:
            m = self.by_index[i]
            if m.profile.duration == 0:
                out[i] = (0.0, 0.0)
                continue
            robot = self._robot(m)
            out[i] = _energy(robot, self.plant(robot), standalone(m))
        return out

    # ------------------------------------------------------------ allocation
    def budget(self, cycle_time: float, use_waits: bool) -> float:
        return cycle_time - self.fixed_time - (0.0 if use_waits else self.wait_total)

    def table(self, extra: float) -> dict[int, list[Solved]]:
        """Each optimized move solved at ``table_points`` durations, shortest to shortest + ``extra``."""
        k = self.settings.table_points
        shares = np.concatenate([[0.0], np.geomspace(0.06, 1.0, k - 1)])
        out: dict[int, list[Solved]] = {}
        for n_move, i in enumerate(self.optimizable, start=1):
            self.progress(f"move {n_move}/{len(self.optimizable)}: solving at {k} durations")
            units = sorted({int(round((self.t_lo[i] + s * extra) / STEP)) for s in shares})
            units = [u for u in units if u * STEP >= self.t_lo[i] - 1e-9] or [int(round(self.t_lo[i] / STEP))]
            out[i] = [self.solve(i, u * STEP) for u in units]
        return out

    def dp(self, table: dict[int, list[Solved]], budget: float) -> dict[int, float] | None:
        """The least-energy choice of one solved duration per move with Σ ≤ budget (feasible solves only)."""
        cap = int(np.floor(budget / STEP + 1e-9))
        if cap < 0:
            return None
        best = np.full(cap + 1, np.inf)
        best[0] = 0.0
        choice: list[np.ndarray] = []
        for i in self.optimizable:
            new = np.full(cap + 1, np.inf)
            pick = np.full(cap + 1, -1)
            for k, s in enumerate(table[i]):
                if not s.usable:
                    continue
                u = int(round(s.duration / STEP))
                if u > cap:
                    continue
                cand = np.full(cap + 1, np.inf)
                cand[u:] = best[: cap + 1 - u] + s.energy_J
                better = cand < new
                new[better] = cand[better]
                pick[better] = k
            choice.append(pick)
            best = new
        end = int(np.argmin(best))
        if not np.isfinite(best[end]):
            return None
        out: dict[int, float] = {}
        u = end
        for i, pick in zip(reversed(self.optimizable), reversed(choice), strict=True):
            s = table[i][int(pick[u])]
            out[i] = s.duration
            u -= int(round(s.duration / STEP))
        return out

    def continuous(self, table: dict[int, list[Solved]], budget: float) -> dict[int, float]:
        """Share the budget on the fitted curves ``a + b/T + c/T²`` (SLSQP), in 25 ms steps."""
        from scipy.optimize import minimize, nnls

        idx = self.optimizable
        coef = []
        for i in idx:
            pts = [(s.duration, s.energy_J) for s in table[i] if s.usable]
            T = np.array([p[0] for p in pts])
            E = np.array([p[1] for p in pts])
            A = np.column_stack([np.ones_like(T), 1 / T, 1 / T**2])
            c, _ = nnls(A, E) if T.size >= 2 else (np.array([E[0], 0.0, 0.0]), 0.0)
            coef.append(c)
        C = np.array(coef)
        lo = np.array([self.t_lo[i] for i in idx])
        hi = np.array([max(s.duration for s in table[i]) for i in idx])
        hi = np.maximum(hi, lo)

        def f(T: FloatArray) -> tuple[float, FloatArray]:
            e = C[:, 0] + C[:, 1] / T + C[:, 2] / T**2
            g = -C[:, 1] / T**2 - 2 * C[:, 2] / T**3
            return float(e.sum()), g

        x0 = np.clip(lo + (budget - lo.sum()) * (hi - lo) / max((hi - lo).sum(), 1e-9), lo, hi)
        res = minimize(
            f,
            x0,
            jac=True,
            method="SLSQP",
            bounds=list(zip(lo, hi, strict=True)),
            constraints=[
                {"type": "ineq", "fun": lambda T: budget - T.sum(), "jac": lambda T: -np.ones_like(T)}
            ],
            options={"maxiter": 200, "ftol": 1e-10},
        )
        T = np.clip(np.asarray(res.x, dtype=float), lo, hi)
        units = np.maximum(np.floor(T / STEP + 1e-9), np.ceil(lo / STEP - 1e-9)).astype(int)
        spare = int(np.floor(budget / STEP + 1e-9)) - int(units.sum())
        while spare > 0:  # hand the remaining 25 ms steps to the steepest curves
            _, g = f(units * STEP)
            k = int(np.argmin(g))
            units[k] += 1
            spare -= 1
        return {i: float(u * STEP) for i, u in zip(idx, units, strict=True)}

    def evaluate(
        self, durations: dict[int, float], kept: dict[int, tuple[float, float]], waits: float
    ) -> Allocation:
        """Verified cycle energies for given durations of the optimized moves."""
        e = e_lab = 0.0
        for i, T in durations.items():
            s = self.solve(i, T)
            e += s.energy_J
            e_lab += s.energy_lab_J
        for a, b in kept.values():
            e += a
            e_lab += b
        cycle = self.fixed_time + waits + sum(durations.values())
        return Allocation(dict(durations), e, e_lab, cycle)

    def proportional(self, budget: float) -> dict[int, float]:
        """The default's durations scaled by one factor to fill the budget (never below the shortest)."""
        base = {i: sum(self.by_index[j].profile.duration for j in self.chains[i]) for i in self.optimizable}

        def total(k: float) -> float:
            return sum(max(self.t_lo[i], k * base[i]) for i in base)

        lo, hi = 0.0, 100.0
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if total(mid) <= budget else (lo, mid)
        return {
            i: max(
                STEP * np.ceil(self.t_lo[i] / STEP - 1e-9),
                STEP * np.floor(max(self.t_lo[i], lo * base[i]) / STEP + 1e-9),
            )
            for i in base
        }

    def best(
        self,
        table: dict[int, list[Solved]],
        budget: float,
        kept: dict[int, tuple[float, float]],
        waits: float,
    ) -> Allocation:
        candidates = []
        d = self.dp(table, budget)
        if d is not None:
            candidates.append(self.evaluate(d, kept, waits))
        c = self.continuous(table, budget)
        alloc = self.evaluate(c, kept, waits)
        if all(self.solve(i, T).usable for i, T in c.items()):
            candidates.append(alloc)
        if not candidates:
            raise LimitViolation(
                f"{self.spec.source}: no allocation of the durations keeps every optimized move "
                "within its limits"
            )
        return min(candidates, key=lambda a: a.energy_J)


def optimize_cycle(
    spec: CycleSpec,
    settings: CycleSettings,
    *,
    progress: Callable[[str], None] | None = None,
) -> tuple[CycleResult, CycleOptimizer]:
    """Optimize a cycle at the default's cycle time (or ``settings.cycle_time``); verified."""
    t_start = time.perf_counter()
    opt = CycleOptimizer(spec, settings, progress=progress)
    plan = opt.plan
    target = plan.cycle_time if settings.cycle_time is None else settings.cycle_time
    if not opt.optimizable:
        raise InvalidInput(f"{spec.source}: the cycle has no MoveJ or MoveAbsJ that can be optimized")
    shortest = opt.shortest_cycle + (0.0 if settings.use_waits else opt.wait_total)
    if target < shortest - 1e-9:
        raise LimitViolation(
            f"{spec.source}: cycle time {target:.3f} s is shorter than the shortest this program "
            "reaches with its optimized moves at their shortest "
            f"({shortest:.3f} s; the default runs {plan.cycle_time:.3f} s); "
            f"give --cycle-time {np.ceil(shortest * 1000) / 1000:.3f} or more"
            + ("" if settings.use_waits else ", or allow --use-waits")
        )
    default = opt.default_energies()
    kept = opt.kept_energies()
    e0 = sum(v[1] for v in default.values())
    e0_lab = sum(v[2] for v in default.values())
    b_plain = opt.budget(target, use_waits=False)
    b_waits = opt.budget(target, use_waits=True)
    b_max = b_waits if settings.use_waits else b_plain
    lo_sum = sum(opt.t_lo.values())
    table = opt.table(max(b_max - lo_sum, 0.0))
    opt.progress("sharing the cycle time")
    shape: Allocation | None = None
    if b_plain >= lo_sum - 1e-9:
        shape = opt.evaluate(opt.proportional(b_plain), kept, opt.wait_total)
        plain = opt.best(table, b_plain, kept, opt.wait_total)
    final = plain if not settings.use_waits else opt.best(table, b_waits, kept, 0.0)
    if settings.use_waits and shape is None:
        shape = opt.evaluate(opt.proportional(b_waits), kept, 0.0)
        plain = final
    assert shape is not None
    breakdown = Breakdown(
        default_J=e0,
        shape_J=shape.energy_J,
        allocation_J=plain.energy_J,
        waits_J=final.energy_J if settings.use_waits else None,
    )
    outcomes: list[MoveOutcome] = []
    paths: dict[int, Solved] = {}
    ok = True
    pieces: dict[int, Solved] = {}
    notes: dict[int, str] = {}
    for i, T in final.durations.items():
        whole = opt.solve(i, T)
        ok = ok and whole.usable
        pieces.update(opt.split(i, whole))
        members = opt.chains[i]
        for j in members:
            notes[j] = (
                "reshaped and re-timed"
                if len(members) == 1
                else "reshaped and re-timed in one fly-by chain with lines "
                + ", ".join(str(opt.by_index[k].step.line) for k in members)
                + " (passes the zone targets exactly, without stopping)"
            )
    vias: dict[int, tuple[int, ...]] = {}
    for i in final.durations:
        members = opt.chains[i]
        step = spec.steps[i]
        assert step.robot is not None and step.tcp is not None
        legs = [pieces[j].fine for j in members]
        placed = via_layout(
            step.robot,
            step.tcp,
            legs,
            spacing=settings.via_every * STEP,
            config=settings.controller,
            target_zones=[*(spec.steps[j].zone_mm for j in members[:-1]), None],
        )
        vias.update({j: tuple(idx) for j, idx in zip(members, placed, strict=True)})
    for m in plan.moves:
        d_T, d_e, d_lab = default[m.index]
        if m.index in pieces:
            s = pieces[m.index]
            paths[m.index] = s
            n_via, dev_q, dev_mm = via_deviation(m.step, s, vias[m.index])
            outcomes.append(
                MoveOutcome(
                    m.step.line,
                    m.step.label,
                    True,
                    notes[m.index],
                    d_T,
                    s.duration,
                    d_e,
                    s.energy_J,
                    d_lab,
                    s.energy_lab_J,
                    s.limits_ok,
                    s.limit_excess,
                    n_via,
                    dev_q,
                    dev_mm,
                    s.corridor_dev_mm,
                    opt.default_clearance.get(m.index),
                    s.clearance_mm,
                )
            )
        else:
            note = (
                "MoveL: kept unchanged (straight line, controller timing)"
                if m.step.linear
                else "occurs more than once in the cycle: kept unchanged"
                if m.step.repeated
                else "no motion"
            )
            if opt.default_clearance.get(m.index, np.inf) < 0.0:
                note = "the default move comes closer to the cell than the margin: reported, not optimized"
            kept_clear = None
            if settings.cell is not None and m.profile.duration > 0:
                kept_clear = opt._clearance_mm(m, standalone(m).q)
            a, b = kept[m.index]
            outcomes.append(
                MoveOutcome(
                    m.step.line,
                    m.step.label,
                    False,
                    note,
                    d_T,
                    m.profile.duration,
                    d_e,
                    a,
                    d_lab,
                    b,
                    True,
                    (),
                    0,
                    0.0,
                    0.0,
                    0.0,
                    opt.default_clearance.get(m.index),
                    kept_clear,
                )
            )
    waits = tuple((spec.steps[i].line, sec, 0.0 if settings.use_waits else sec) for i, _, sec in plan.waits)
    result = CycleResult(
        moves=tuple(outcomes),
        default_cycle_s=plan.cycle_time,
        target_cycle_s=target,
        optimized_cycle_s=final.cycle_time_s,
        default_energy_J=e0,
        optimized_energy_J=final.energy_J,
        default_lab_J=e0_lab,
        optimized_lab_J=final.energy_lab_J,
        breakdown=breakdown,
        waits=waits,
        fixed_lines=spec.fixed_lines,
        limits_ok=ok,
        corridor_mm=settings.corridor_mm,
        cell=None
        if settings.cell is None
        else {"source": settings.cell.source, "margin_mm": 1000 * settings.cell.margin},
        shortest_cycle_s=shortest,
        wall_s=time.perf_counter() - t_start,
        n_solves=opt.n_solves,
        paths=paths,
        spec=spec,
        chains={i: c for i, c in opt.chains.items() if len(c) > 1 and i in final.durations},
        vias=vias,
    )
    return result, opt


def via_deviation(step: Step, solved: Solved, idx: Sequence[int]) -> tuple[int, float, float]:
    """Via points (indices into ``solved.fine``), and the largest joint (deg) and TCP (mm) distance
    of their joint-linear interpolation from the optimized path (what the controller's
    interpolation between via points departs from it, before its zones round the corners)."""
    assert step.robot is not None and step.tcp is not None
    fine = solved.fine
    at = [0, *idx]
    tv, qv = fine.t[at], fine.q[at]
    lin = np.column_stack([np.interp(fine.t, tv, qv[:, j]) for j in range(qv.shape[1])])
    dev_q = float(np.degrees(np.abs(lin - fine.q).max()))
    a = step.robot.fk(lin)
    b = step.robot.fk(fine.q)
    pa = a.position_m + np.einsum("kij,j->ki", a.rotation, step.tcp[:3, 3])
    pb = b.position_m + np.einsum("kij,j->ki", b.rotation, step.tcp[:3, 3])
    return len(idx), dev_q, float(1000 * np.linalg.norm(pa - pb, axis=1).max())


def pareto(
    opt: CycleOptimizer, *, points: int = 10, span: float = 0.3, use_waits: bool = False
) -> list[ParetoPoint]:
    """Energy against cycle time from the shortest feasible cycle to ``(1 + span)`` times it.

    One table of solved, verified moves covers the whole range; each point is the
    least-energy combination of table entries within its budget (dynamic programming),
    so every point is made of verified solves.
    """
    waits = 0.0 if use_waits else opt.wait_total
    c_min = opt.shortest_cycle + waits
    kept = opt.kept_energies()
    lo_sum = sum(opt.t_lo.values())
    c_max = c_min * (1 + span)
    table = opt.table(opt.budget(c_max, use_waits) - lo_sum)
    out = []
    for c in np.linspace(c_min, c_max, points):
        d = opt.dp(table, opt.budget(float(c), use_waits) + 1e-9)
        if d is None:
            continue
        a = opt.evaluate(d, kept, waits)
        out.append(ParetoPoint(float(c), a.energy_J, a.energy_lab_J, tuple(d[i] for i in opt.optimizable)))
    return out
