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
  along it (:meth:`CycleOptimizer.retime_segments`). Moves that occur more than once
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
  duration (:meth:`CycleOptimizer.tune_passes`, a pattern search over 25 ms steps, each step a
  solve), and kept as shares of the duration for its other solves.
* Verified: every optimized move's path on a 2.5 ms grid against the joint ranges,
  speed and acceleration limits (and the cell's obstacles, with ``cell``); its energy
  on physics and on the lab plant.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
from scipy.interpolate import BPoly

from joulepath._typing import FloatArray
from joulepath._work import check_work, work_limit
from joulepath.dynamics import NOMINAL_FRICTION, Robot
from joulepath.energy import MEASURES, measure_energy
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.optimize import (
    GradientSettings,
    MeasureSummary,
    SplineProblem,
    acceleration_limit,
    check_limits,
    jerk_limit,
    optimize_spline,
    retime_on_path,
    shortest_feasible_duration,
    shortest_on_path,
    solve_move,
    tcp_deviation_mm,
    tcp_velocity,
)
from joulepath.program._cell import clearance
from joulepath.program._cycle_allocation import UnitEntries, fitted_share, least_energy_choice
from joulepath.program._cycle_model import (
    STEP,
    Allocation,
    Breakdown,
    CycleMotion,
    CycleResult,
    CycleSettings,
    MoveOutcome,
    ParetoPoint,
    Segment,
    Solved,
    TimeBudgetSpent,
    sample_power,
    segments,
    trajectory_energy,
    window_energy,
)
from joulepath.program._resolve import CycleSpec, Step, check_moves_arm
from joulepath.sim import (
    FINE_DT,
    RAPID_ACCEL_SHARE,
    PlannedCycle,
    PlannedMove,
    Plant,
    check_motion_time,
    evaluate_cycle,
    make_plant,
    plan_cycle,
    via_layout,
)
from joulepath.sim import tcp_pose as _tcp
from joulepath.trajectory import SplineBasis, Trajectory, minimum_jerk


def _reduced_zone_mm(zone_mm: float, into: PlannedMove, out: PlannedMove) -> float:
    """The zone (mm) the controller keeps at ``into``'s target before ``out``: its radius, reduced to
    half the TCP length of either move."""
    return float(max(0.0, min(zone_mm, 0.5 * into.path.length_mm, 0.5 * out.path.length_mm)))


def _hermite_path(
    t: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray
) -> Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]:
    """A motion's samples as a joint path ``q(s)``, ``s = (t - t0) / T`` in [0, 1]: the quintic Hermite
    interpolation of position, speed and acceleration (C², exact at the samples)."""
    span = float(t[-1] - t[0])
    x = (t - t[0]) / span
    d, dd = qd * span, qdd * span * span
    # its Bernstein coefficients on every interval at once, by the operations, in their order, of
    # ``BPoly.from_derivatives`` (``quintic_hermite``), which builds them one interval at a time:
    # the same coefficients to the bit, in a fiftieth of the time
    h = (x[1:] - x[:-1])[:, None]
    h2 = h**2
    c = np.empty((6, x.size - 1, q.shape[1]))
    c[0] = q[:-1] / 1.0 * 1.0
    c[1] = d[:-1] / 5.0 * h
    c[1] -= -1.0 * c[0]
    c[2] = dd[:-1] / 20.0 * h2
    c[2] -= 1.0 * c[0]
    c[2] -= -2.0 * c[1]
    c[5] = q[1:] / 1.0 * 1 * 1.0
    c[4] = d[1:] / 5.0 * -1 * h
    c[4] -= -1.0 * c[5]
    c[3] = dd[1:] / 20.0 * 1 * h2
    c[3] -= -2.0 * c[4]
    c[3] -= 1.0 * c[5]
    poly = BPoly(c, x)
    d1, d2 = poly.derivative(1), poly.derivative(2)

    def at(s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return poly(s), d1(s), d2(s)

    return at


def _interpolated(x: FloatArray, y: FloatArray) -> Callable[[FloatArray], FloatArray]:
    """``y`` at ``x`` as a function, linear between them."""

    def at(s: FloatArray) -> FloatArray:
        out: FloatArray = np.interp(s, x, y)
        return out

    return at


def _at_rest(qd: FloatArray, qdd: FloatArray) -> bool:
    """A sample of a standstill (no speed, no acceleration)."""
    return bool(np.abs(qd).max() < 1e-9 and np.abs(qdd).max() < 1e-6)


RETIME_MAX_SPAN_S = 4.0
"""s: a segment longer than this keeps its plan's timing (its re-timing along its path, at a control
point per 0.1 s on the 2.5 ms grid, would take minutes)."""

RETIME_GAIN = 1e-3
"""A segment re-timed along its path is kept where it saves at least this share of its energy (else
its plan stays as it is, and RAPID's own moves can follow it)."""

NO_SPEED_BOUND = 1e3
"""m/s: the TCP speed "bound" at a joint move's samples in a segment re-timed along its path (none)."""


ON_TAUGHT_KNOTS = 0.1
"""s between knots, at least, of a shape added to the taught motion: the taught motion runs at the
joints' speed limits, so nearly every speed row is active, and SLSQP's cost grows with their number."""

WITHIN_KNOTS = 0.075
"""s between knots, at least, of a shape added to a unit inside a ``MoveL`` segment (measured on
pick_and_place: 0.1 s saved 11.6 %, 0.075 s 11.7 % in 7 s more, 0.05 s 11.5 % in 50 s more)."""


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
from the best probe's path shifted in time (:meth:`CycleOptimizer._time_warped`); on 0.15 s knots
through the first two stages 2.6 s cold, 0.8-2.6 s (1.5 s on average) from that shifted path, the
same energies as cold to 0.3 mJ, and the probes in the same order as on its own knots (a step of 75 ms
of the first pass time: +0.23 J on 0.15 s knots, +0.29 J on its own)."""
LONG_PROBES = 2
"""Pass-time probes per inner target, at most, in a row without a gain, of a long chain's search (its
first step 1/8 of a leg; ``pass_search`` per target in all, at most). Measured on the long fly-by
chain of issue 36: the pattern search run on to 53 probes (about 1.4 s each) found pass times 0.017 %
better than the untuned ones on the probes' knots, within the scatter of the solves; 14 find none."""

ON_TAUGHT_MARGIN = 0.01
"""Share above a long chain's solve at its taught duration within which its reshaped taught motion,
started from that solve (:meth:`CycleOptimizer.solve_on_taught`), is also solved from the taught
motion. Measured on the long fly-by chain of issue 36 (one BLAS thread): from the taught motion
43.375 J in 10.0 s, from the solve (42.277 J) 43.556 J in 5.0 s, 0.4 % above the one from the
taught motion and 3.0 % above the solve."""


class CycleOptimizer:
    """Default cycle, duration table, allocations and verification of one program on one robot.

    The default cycle is cut into rest-to-rest :class:`Segment` s. A segment of ``MoveJ`` /
    ``MoveAbsJ`` only (each occurring once in the cycle, clear of the cell) is a *unit*: it
    is optimized as one move through its targets (within each target's zone, or exactly),
    and its own taught motion stays a candidate at its taught duration, so the taught cycle
    time is always reachable. Every other segment runs as taught, blended as the controller
    blends it; dwells and waits keep their time (``use_waits``: the waits declared idle are
    spent on the units).
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
        self.deadline = deadline  # time.perf_counter() after which no new move is solved
        self.timed_out = False
        # ``plan``: the taught cycle as planned for ``spec`` under ``settings.controller`` (one
        # already planned, e.g. by the plan for samples before the plan for via points)
        self.plan: PlannedCycle = (
            plan_cycle(spec, settings.controller, progress=self.progress) if plan is None else plan
        )
        self.gradient = replace(settings.gradient, energy_every=settings.energy_every)
        check_motion_time(self.plan, spec.source)  # a unit longer than move_s is kept as taught (below)
        if spec.module is None:
            _refuse_short_durations(spec, self.plan)
        self._plants: dict[int, Plant] = {}
        self._default_motion: CycleMotion | None = None
        self._default_energies: dict[int, tuple[float, float, float]] | None = None
        self.cache: dict[tuple[int, int], Solved] = {}
        self.n_solves = 0
        moves = self.plan.moves
        self.by_index = {m.index: m for m in moves}
        self.default_clearance: dict[int, float] = {}
        if settings.cell is not None:
            self._default_clearance()
        self.segments = segments(self.plan)
        self.chains: dict[int, tuple[int, ...]] = {}
        self.span: dict[int, float] = {}
        self.segment_of: dict[int, Segment] = {}  # by unit: the window of the default cycle it replaces
        self.within: set[int] = set()  # units inside a segment with MoveL: fixed duration, taught ends
        self.linear: set[int] = set()  # MoveL units: re-timed along their line (retime_on_path)
        self.shares: dict[int, tuple[float, ...]] = {}  # by chain: when it passes its targets (tune_passes)
        self.tuned: set[int] = set()  # chains whose pass times were searched
        # a long chain's coarse probes by (chain, duration in samples, pass times in samples)
        self.probes: dict[tuple[int, int, tuple[int, ...]], Solved] = {}
        for seg in self.segments:
            for members, window, inner in self._units_of(seg):
                self.chains[members[0]] = members
                self.span[members[0]] = window.span
                self.segment_of[members[0]] = window
                if inner:
                    self.within.add(members[0])
        # a unit (a move, or a fly-by chain solved as one move) longer than the move_s limit is kept as
        # taught: its solve grows with its duration (joulepath._work); said in the result (long_units)
        limit = work_limit("move_s")
        self.long_units = [i for i in self.chains if self.span[i] > limit + 1e-9]
        for i in self.long_units:
            for table in (self.chains, self.span, self.segment_of):
                del table[i]
            self.within.discard(i)
        self.optimizable = list(self.chains)  # one unit per window, keyed by its first moving move
        in_units = {j for i in self.chains for j in self.segment_of[i].moves}
        self.kept = [m.index for m in moves if m.index not in in_units]
        self.wait_total = float(sum(s for _, _, s in self.plan.waits))
        self.idle_total = float(sum(s for i, _, s in self.plan.waits if spec.steps[i].idle))
        # everything but the units and the waits: the rest as taught (blended), dwells
        self.fixed_time = self.plan.cycle_time - sum(self.span.values()) - self.wait_total
        self.t_lo: dict[int, float] = {}
        self.leg_lo: dict[int, tuple[float, ...]] = {}  # each move's shortest rest-to-rest duration
        for n_unit, (i, members) in enumerate(self.chains.items(), start=1):
            self.progress(f"unit {n_unit}/{len(self.chains)}: its shortest duration")
            if i in self.within:  # its ends are the taught motion's: its duration stays
                self.leg_lo[i] = ()
                self.t_lo[i] = self.span[i]
                continue
            if i in self.linear:
                self.leg_lo[i] = ()
                self.t_lo[i] = self._linear_shortest(self.by_index[i])
                continue
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
        # each unit at its shortest optimized duration, or as taught where that is shorter
        self.shortest_cycle = self.fixed_time + sum(min(self.t_lo[i], self.span[i]) for i in self.chains)

    def _units_of(self, seg: Segment) -> list[tuple[tuple[int, ...], Segment, bool]]:
        """The units of one segment: (moving members, window of the default cycle, inside a MoveL
        segment). A segment of joint moves only is one unit from rest to rest; in a segment with
        a MoveL, each run of consecutive joint moves is one unit over its own motion and the blends
        at its ends (:meth:`_blend_window`, in whole 25 ms samples from its start), its ends the
        taught motion's states."""
        by = self.by_index
        moving = [i for i in seg.moves if by[i].profile.duration > 0]
        if not moving:
            return []
        if all(self._can_optimize(by[i]) for i in seg.moves):
            if len(moving) > 1 and not self.settings.fly_by:
                return []
            return [(tuple(moving), seg, False)]
        if self.settings.follow == "via-points":
            return []  # via points follow only joint moves from rest to rest
        if len(moving) == 1 and self._can_retime(by[moving[0]]):  # a MoveL from rest to rest
            self.linear.add(moving[0])
            return [(tuple(moving), seg, False)]
        if not self.settings.fly_by:
            return []
        out: list[tuple[tuple[int, ...], Segment, bool]] = []
        run: list[int] = []
        done = seg.t0  # where the last window ends
        for k, i in enumerate([*moving, -1]):
            if i >= 0 and self._can_optimize(by[i]):
                run.append(i)
                continue
            if run:
                first, last = moving.index(run[0]), moving.index(run[-1])
                a, b = self._blend_window(seg, moving, first, last, done)
                n = int(np.floor((b - a) / STEP + 1e-9))
                if n >= 6:  # at least 0.15 s to reshape
                    out.append((tuple(run), Segment(tuple(run), a, a + n * STEP), True))
                    done = a + n * STEP
            run = []
            del k
        return out

    def _blend_window(
        self, seg: Segment, moving: list[int], first: int, last: int, done: float
    ) -> tuple[float, float]:
        """The window (default-cycle times) of the run of joint moves ``moving[first..last]`` inside
        a segment with a ``MoveL``: over the blends at its ends, from where the controller starts the
        run's first move to where it ends its last, as far as the TCP there is within the zone of
        the target the blend rounds (:meth:`_within_zone`); where it is not, or the window before
        (ending at ``done``) reaches into the blend, from the blend's end and to its start, as
        before. Its ends are the controller's states; between them only the run's own targets
        bind, so the blends are reshaped with the run."""
        by = self.by_index
        run0, run1 = by[moving[first]], by[moving[last]]
        if first == 0:
            a = seg.t0
        else:
            prev = by[moving[first - 1]]
            if done <= run0.t0:
                a = self._within_zone(run0.t0, max(run0.t0, prev.t_end), prev, run0, earliest=True)
            else:
                a = max(prev.t_end, done)
        if last + 1 == len(moving):
            b = seg.t1
        else:
            nxt = by[moving[last + 1]]
            b = self._within_zone(min(nxt.t0, run1.t_end), run1.t_end, run1, nxt, earliest=False)
        return a, b

    def _within_zone(
        self, lo: float, hi: float, into: PlannedMove, out: PlannedMove, *, earliest: bool
    ) -> float:
        """The earliest (``earliest``: on the 2.5 ms grid from ``lo``) or the latest (from ``hi``) time
        in ``[lo, hi]`` at which the taught TCP is within the zone of ``into``'s target (its radius
        reduced to half of ``into``'s and ``out``'s TCP length, as for a chain's targets); where it
        never is, the other end of the range (the blend then stays the controller's own)."""
        if into.step.zone_mm is None:
            return lo if earliest else hi
        k = np.arange(int(np.floor(max(hi - lo, 0.0) / FINE_DT + 1e-9)) + 1, dtype=float)
        t: FloatArray = lo + FINE_DT * k if earliest else hi - FINE_DT * k
        inside = np.flatnonzero(self._tcp_within(t, into, out))
        if inside.size == 0:
            return hi if earliest else lo
        return float(t[inside[0]])

    def _tcp_within(self, t: FloatArray, into: PlannedMove, out: PlannedMove) -> FloatArray:
        """Whether the taught TCP at times ``t`` is within the zone of ``into``'s target, its radius
        reduced to half of ``into``'s and ``out``'s TCP length (as for a chain's targets)."""
        step = into.step
        assert step.robot is not None and step.tcp is not None and step.zone_mm is not None
        R = _reduced_zone_mm(step.zone_mm, into, out) / 1000.0
        p, _ = _tcp(step.robot, evaluate_cycle(self.plan, t).q, step.tcp)
        corner, _ = _tcp(step.robot, into.path.q1[None, :], step.tcp)
        inside: FloatArray = np.linalg.norm(p - corner, axis=1) <= R + 1e-9
        return inside

    def _before_solve(self) -> None:
        """Raise :class:`TimeBudgetSpent` once ``max_time_s`` is reached (no new solve starts)."""
        if self.deadline is not None and time.perf_counter() > self.deadline:
            self.timed_out = True
            raise TimeBudgetSpent(f"{self.spec.source}: --max-time reached")

    def _can_retime(self, m: PlannedMove) -> bool:
        return (
            not m.step.kept
            and m.step.linear
            and self._once_or_streamed(m)
            and self.settings.retime_linear
            and self.default_clearance.get(m.index, np.inf) >= 0.0
        )

    def _can_optimize(self, m: PlannedMove) -> bool:
        return (
            not m.step.kept
            and not m.step.linear
            and self._once_or_streamed(m)
            and self.default_clearance.get(m.index, np.inf) >= 0.0
        )

    def _once_or_streamed(self, m: PlannedMove) -> bool:
        """A move that runs once in the cycle, or any move of a plan for a streamed trajectory (each
        call of a procedure is its own motion there; via points of one statement hold only one)."""
        return not m.step.repeated or self.settings.follow == "samples"

    def _linear_shortest(self, m: PlannedMove) -> float:
        """A MoveL's shortest duration along its line within the limits and its speeddata (TOPP-RA,
        whole 25 ms samples); its taught duration when toppra (extra ``motion``) is not installed."""
        robot = self._robot(m)
        assert m.step.speed is not None
        try:
            t = shortest_on_path(
                robot,
                m.path,
                acceleration_limit=self._amax_array(robot),
                jerk_limit=self._jmax(robot),
                tcp_speed_limit=m.step.speed.v_tcp / 1000.0,
                tcp=m.step.tcp,
            )
        except ImportError:
            return self.span[m.index]
        return float(np.ceil(t / STEP - 1e-9) * STEP)

    def waits_kept(self, use_waits: bool) -> float:
        """s of waits the cycle keeps: all, or (``use_waits``) all but the idle ones."""
        return self.wait_total - (self.idle_total if use_waits else 0.0)

    # ------------------------------------------------------------ chains
    def waypoints(self, i: int, T: float) -> tuple[tuple[float, FloatArray], ...]:
        """The chain's inner targets and when it passes them, in whole 25 ms samples, each leg at least
        two samples long: at the shares of ``T`` :meth:`tune_passes` found; else (a unit inside a
        MoveL segment) where the taught motion passes them; else ``T`` shared in proportion to each
        move's shortest rest-to-rest duration (at the sum of those durations, each leg gets its own)."""
        members = self.chains[i]
        if len(members) == 1:
            return ()
        units = int(round(T / STEP))
        if i in self.shares:
            edges = np.round(np.asarray(self.shares[i]) * units).astype(int)
        elif i in self.within:
            return self._taught_passes(i)
        else:
            base = np.array(self.leg_lo[i])
            edges = np.round(np.cumsum(base)[:-1] / base.sum() * units).astype(int)
        for k in range(edges.size):  # at least 2 samples per leg
            edges[k] = max(edges[k], (edges[k - 1] if k else 0) + 2)
        for k in range(edges.size - 1, -1, -1):
            edges[k] = min(edges[k], (edges[k + 1] if k + 1 < edges.size else units) - 2)
        return tuple(
            (float(e * STEP), self.by_index[j].path.q1) for e, j in zip(edges, members[:-1], strict=True)
        )

    def tune_passes(self, i: int, T: float) -> None:
        """When chain ``i`` passes its inner targets, searched at duration ``T``: a pattern search over
        the pass times in whole 25 ms samples from those :meth:`waypoints` gives (each candidate a
        solve, ``give_up`` and at most :data:`PROBE_ROUNDS` rounds; a step along one target's time is
        kept when it lowers the verified energy below the best so far, the steps halve down to one
        sample, at most ``pass_search`` probes per target). Pass times that beat the solve at the
        pass times it starts from are kept as shares of the duration (:meth:`waypoints`) for the
        chain's solves at every duration; the better solve at ``T`` is cached. A unit inside a
        ``MoveL`` segment probes on knots :data:`ON_TAUGHT_KNOTS` apart (its own solves:
        :data:`WITHIN_KNOTS`), the probes compared among themselves (each after the first started from
        the best probe's path, through the last :data:`PROBE_WARM_STAGES` continuation stages, as a
        chain's probes are after the first); a probe that beats the one at the untuned pass times is
        kept as the unit's solve at ``T``, else the unit is solved at the untuned pass times as its
        own solves are. A long chain (:meth:`GradientSettings.is_long`) probes on knots
        :data:`LONG_PROBE_KNOTS` apart through the continuation stages but the last, each probe after
        the first from the best probe's path shifted in time to its pass times (:meth:`_time_warped`),
        at most :data:`LONG_PROBES` per target in a row without a gain, its first step 1/8 of a leg;
        the chain is then solved at the untuned pass times and, where a probe won, at the best
        probe's, each from its probe (:meth:`_from_probe`), and the better is kept; the probe at the
        kept pass times screens the time table's shorter durations (:meth:`_screened`) (the long
        fly-by chain of issue 36: 42 probes of 7-9 s each, every one ending at the smoothest path,
        -> 14 of about 1.5 s). Measured on
        pick_and_place (issue 36, with the re-timing's scaled search): 19.9 s at 12.19 %; the best
        pass times solved again on :data:`WITHIN_KNOTS`, kept where that beat the untuned solve
        there (two solves of 144 variables, about 3 s each), as before: 25.0 s at 12.15 %; solved
        again without the untuned solve: 22.3 s at 12.15 %. Nothing for a single move or a MoveL."""
        members = self.chains[i]
        if len(members) < 2 or i in self.linear or i in self.tuned or not self.settings.pass_search:
            return
        self.tuned.add(i)
        units = int(round(T / STEP))
        m = self.by_index[i]
        corridor = self.settings.corridor_mm
        coarse = i in self.within  # probes on wider knots, compared among themselves
        long = not coarse and self.gradient.is_long(units * STEP)  # so too, then solved on its own knots
        # where it passes them untuned (a unit inside a MoveL segment: only where no probe wins)
        first: Solved | None = None if coarse or long else self._solve_once(m, units * STEP, units, corridor)
        untuned = [t for t, _ in self.waypoints(i, units * STEP)]
        start = tuple(int(round(t / STEP)) for t in untuned)
        seen: dict[tuple[int, ...], Solved] = {}
        probe = replace(self.gradient, give_up=True, max_rounds=min(self.gradient.max_rounds, PROBE_ROUNDS))
        if coarse:
            probe = replace(probe, knot_spacing=max(probe.knot_spacing, ON_TAUGHT_KNOTS))
        elif long:
            probe = self._long_probe_settings()
        elif first is not None and all(abs(e * STEP - t) < 1e-9 for e, t in zip(start, untuned, strict=True)):
            seen[start] = first

        warm = replace(probe, continuation=probe.continuation[-PROBE_WARM_STAGES:], coarse_factor=1)

        def way_at(edges: tuple[int, ...]) -> tuple[tuple[float, FloatArray], ...]:
            return tuple(
                (e * STEP, self.by_index[j].path.q1) for e, j in zip(edges, members[:-1], strict=True)
            )

        def energy(edges: tuple[int, ...]) -> float:
            if not self._passes_reachable(i, edges, units):
                return np.inf
            if edges not in seen:
                way = way_at(edges)
                near = seen.get(best) if PROBE_WARM_STAGES else None
                if near is not None and near.usable and near.coefficients is not None:
                    initial = self._time_warped(i, near, edges, probe) if long else near.coefficients
                    seen[edges] = self._solve_once(
                        m, units * STEP, units, corridor, way=way, gradient=warm, initial=initial
                    )
                else:
                    seen[edges] = self._solve_once(m, units * STEP, units, corridor, way=way, gradient=probe)
            s = seen[edges]
            return s.energy_J if s.usable else np.inf

        best = start
        if coarse or long:
            e_best = energy(start)
        else:
            assert first is not None
            e_best = first.energy_J if first.usable else np.inf
        won = False
        cap = self.settings.pass_search * len(start)
        # a long chain: at most LONG_PROBES per target in a row without a gain
        idle_cap = min(self.settings.pass_search, LONG_PROBES) * len(start) if long else cap
        if long:
            step = max(1, units // (8 * len(members)))
        else:
            step = max(1, units // (4 * len(members)) if i not in self.within else 2)
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
        if long:  # on its own knots: at the untuned pass times, and at the best probe's where it won
            first = self._from_probe(i, units, way_at(start), seen.get(start))
            tuned = self._from_probe(i, units, way_at(best), seen[best]) if won else None
            if tuned is not None and tuned.usable and (not first.usable or tuned.energy_J < first.energy_J):
                self.shares[i] = tuple(e / units for e in best)
                self.cache[(i, units)] = tuned
            elif first.usable:
                self.cache[(i, units)] = first
            kept = best if i in self.shares else start  # the pass times of the chain's solves
            if kept in seen:  # the probe there, for the screen of the time table (:meth:`_screened`)
                self.probes[(i, units, kept)] = seen[kept]
            return
        if won:  # the best probe (inside a MoveL segment: on its wider knots), verified as every solve is
            self.shares[i] = tuple(e / units for e in best)
            self.cache[(i, units)] = seen[best]
            return
        if first is None:  # no probe beat the untuned pass times: the unit's own solve there
            first = self._solve_once(m, units * STEP, units, corridor)
        if first.usable:
            self.cache[(i, units)] = first

    def _long_probe_settings(self) -> GradientSettings:
        """The search of a long chain's coarse probes (:meth:`tune_passes`, :meth:`_screened`): knots
        :data:`LONG_PROBE_KNOTS` apart, the continuation stages but the last, ``give_up`` and at most
        :data:`PROBE_ROUNDS` rounds per stage."""
        g = self.gradient
        return replace(
            g,
            give_up=True,
            max_rounds=min(g.max_rounds, PROBE_ROUNDS),
            knot_spacing=max(g.knot_spacing, LONG_PROBE_KNOTS),
            coarse_factor=1,
            continuation=g.continuation[:-1] or g.continuation,
        )

    def _from_probe(
        self, i: int, units: int, way: tuple[tuple[float, FloatArray], ...], probe: Solved | None
    ) -> Solved:
        """Long chain ``i`` solved at ``units`` samples through its targets at ``way`` on its own knots,
        from its coarse ``probe`` there (:meth:`_long_probe_settings`: the stages but the last, on
        wider knots; its path fitted to the chain's knots, :meth:`_time_scaled`) through the last
        ``refine_stages`` continuation stages, as the wide knots of a cold solve hand over to the fine
        ones; a cold solve where the probe or that solve is not usable. Measured on the long fly-by
        chain of issue 36 (one BLAS thread): 7.5 s at 42.277 J, cold 8.9 s at 42.286 J (its own wide
        knots, 0.166 s apart, take the first stages again)."""
        m = self.by_index[i]
        T = units * STEP
        corridor = self.settings.corridor_mm
        if probe is not None and probe.usable and probe.coefficients is not None:
            g = self.gradient
            refine = replace(g, n_starts=1, coarse_factor=1, continuation=g.continuation[-g.refine_stages :])
            start = self._time_scaled(i, T, probe)
            out = self._solve_once(m, T, units, corridor, way=way, gradient=refine, initial=start)
            if out.usable:
                return out
        return self._solve_once(m, T, units, corridor, way=way)

    def _long_probe(self, i: int, units: int) -> Solved:
        """Chain ``i``'s coarse probe at ``units`` samples, through its targets where its solves pass
        them (:meth:`waypoints`), as :meth:`tune_passes` probes a long chain; cached. It starts from
        its nearest probe (at another duration) stretched in time (:meth:`_time_scaled`), through the
        last :data:`PROBE_WARM_STAGES` stages, and cold where that one is not usable."""
        T = units * STEP
        way = self.waypoints(i, T)
        edges = tuple(int(round(t / STEP)) for t, _ in way)
        key = (i, units, edges)
        if key in self.probes:
            return self.probes[key]
        self._before_solve()
        m = self.by_index[i]
        probe = self._long_probe_settings()
        corridor = self.settings.corridor_mm
        near = [
            s for (j, _, _), s in self.probes.items() if j == i and s.usable and s.coefficients is not None
        ]
        out: Solved | None = None
        if near and PROBE_WARM_STAGES:
            nearest = min(near, key=lambda s: abs(s.duration - T))
            warm = replace(probe, continuation=probe.continuation[-PROBE_WARM_STAGES:])
            start = self._time_scaled(i, T, nearest, probe)
            out = self._solve_once(m, T, units, corridor, way=way, gradient=warm, initial=start)
        if out is None or not out.usable:
            out = self._solve_once(m, T, units, corridor, way=way, gradient=probe)
        self.probes[key] = out
        return out

    def _screens_durations(self, i: int, longest: int) -> bool:
        """Whether unit ``i``'s shorter durations in the time table are screened by coarse probes
        (:meth:`_screened`): a long fly-by chain (past the gradient's ``max_knots`` at ``longest``
        samples, :meth:`GradientSettings.is_long`) from rest to rest, alone in its cycle (no other
        unit takes the time its shorter durations leave: they count only where one of them takes
        less energy than its longest duration)."""
        return (
            len(self.optimizable) == 1
            and len(self.chains[i]) > 1
            and i not in self.within
            and i not in self.linear
            and self.gradient.is_long(longest * STEP)
        )

    def _screened(self, i: int, units: list[int]) -> list[Solved]:
        """Unit ``i`` solved at its durations ``units`` (samples, ascending), alone in its cycle
        (:meth:`_screens_durations`): at the longest as every duration is (:meth:`solve`), at a shorter
        one only where its coarse probe (:meth:`_long_probe`) could win, i.e. is below the coarse
        probe at the longest by less than the longest's own gain from its probe to its solve (a
        shorter duration whose probe is above that needs more than twice that gain to win), or where
        either probe is not usable. Measured on the long fly-by chain of issue 36 (5.0, 5.025, 5.075
        and 5.325 s): probes 48.25, 47.77, 47.12 and 44.27 J (about 1 s each), solves 45.20, 44.95,
        44.45 and 42.29 J (14-16 s each under load): the gains 3.05, 2.82, 2.67 and 1.98 J, the
        shorter durations' at most 1.6 times the longest's; the three are screened out."""
        longest = self.solve(i, units[-1] * STEP)
        out = [longest]
        bar = np.inf
        if longest.usable:
            ref = self._long_probe(i, units[-1])
            if ref.usable:
                bar = ref.energy_J + max(ref.energy_J - longest.energy_J, 0.0)
        for u in reversed(units[:-1]):  # the nearest first: each solve starts from its nearest
            if np.isfinite(bar):
                p = self._long_probe(i, u)
                if p.usable and p.energy_J >= bar:
                    continue
            out.append(self.solve(i, u * STEP))
        return sorted(out, key=lambda s: s.duration)

    def _time_warped(
        self, i: int, near: Solved, edges: tuple[int, ...], gradient: GradientSettings
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
        q0, q1 = self.by_index[i].path.q0, self.by_index[self.chains[i][-1]].path.q1
        default = minimum_jerk(q0, q1, T, dt=STEP / gradient.check_factor)
        t_old = np.interp(default.t, [0.0, *(e * STEP for e in edges), T], [0.0, *near.passes, T])
        q_old = np.column_stack([np.interp(t_old, near.fine.t, near.fine.q[:, j]) for j in range(q0.size)])
        c = np.asarray(np.linalg.lstsq(fine.B, q_old - default.q, rcond=None)[0], dtype=float)
        out: FloatArray = c.ravel()
        return out

    def _passes_reachable(self, i: int, edges: tuple[int, ...], units: int) -> bool:
        """Whether chain ``i`` can pass its inner targets at samples ``edges`` of ``units``, by a bound
        from kinematics alone: each leg at least two samples; each joint covers its travel between
        two targets, less their zones' radii, within the speed limit, and from rest (a unit from
        rest to rest: its first and last leg) within the acceleration limit, ``d ≤ a t² / 2``."""
        cuts = (0, *edges, units)
        if np.any(np.diff(cuts) < 2):
            return False
        members = self.chains[i]
        robot = self._robot(self.by_index[i])
        v = np.asarray(robot.velocity_limit, dtype=float)
        a = self._amax_array(robot)
        radius = [np.zeros(robot.n_joints), *self.zone_radius(i), np.zeros(robot.n_joints)]
        rest = i not in self.within  # else its ends are the taught motion's, inside the first and last legs
        for k, j in enumerate(members):
            if not rest and k in (0, len(members) - 1):
                continue
            path = self.by_index[j].path
            d = np.maximum(np.abs(path.q1 - path.q0) - radius[k] - radius[k + 1], 0.0)
            t = (cuts[k + 1] - cuts[k]) * STEP
            if np.any(d > v * t + 1e-12):
                return False
            if rest and k in (0, len(members) - 1) and np.any(d > 0.5 * a * t * t + 1e-12):
                return False
        return True

    def _taught_passes(self, i: int, traj: Trajectory | None = None) -> tuple[tuple[float, FloatArray], ...]:
        """Inner targets of a unit at the times (from the window's start, on the 2.5 ms grid of
        ``traj``, default :meth:`base`) the taught motion comes closest to each (TCP)."""
        traj = self.base(i) if traj is None else traj
        step = self.by_index[i].step
        assert step.robot is not None and step.tcp is not None
        p, _ = _tcp(step.robot, traj.q, step.tcp)
        targets = [self.by_index[j].path.q1 for j in self.chains[i][:-1]]
        if not targets:
            return ()
        dist = np.stack(
            [np.linalg.norm(p - _tcp(step.robot, q[None, :], step.tcp)[0], axis=1) for q in targets]
        )
        ks = _ordered_closest(dist, lo=2, hi=p.shape[0] - 3, gap=2)
        return tuple((float(traj.t[k]), q) for k, q in zip(ks, targets, strict=True))

    def base(self, i: int, n_steps: int | None = None) -> Trajectory:
        """The taught motion over unit ``i``'s window (or its first ``n_steps`` 25 ms samples), on
        the optimizer's fine grid (from 0)."""
        win = self.segment_of[i]
        h = STEP / self.gradient.check_factor
        length = win.span if n_steps is None else n_steps * STEP
        n = int(round(length / h)) + 1
        t = np.linspace(0.0, (n - 1) * h, n)
        tr = evaluate_cycle(self.plan, win.t0 + t)
        return Trajectory(t=t, q=tr.q, qd=tr.qd, qdd=tr.qdd)

    def passes(self, i: int, s: Solved) -> tuple[tuple[float, FloatArray], ...]:
        """When the entry ``s`` of unit ``i`` passes the unit's inner targets, and the targets."""
        if s.passes is None:
            return self.waypoints(i, s.duration)
        members = self.chains[i]
        return tuple((t, self.by_index[j].path.q1) for t, j in zip(s.passes, members[:-1], strict=True))

    def solve_on_taught(self, i: int) -> Solved | None:
        """A unit from rest to rest reshaped from its taught motion at its taught duration: the shape
        is added to the taught motion over its whole 25 ms samples (the rest of it, less than one
        sample to the stop, stays taught), through its targets where the taught motion passes them.
        It starts where the controller's own motion is, within every limit. None: under 0.15 s.

        A long fly-by chain (:meth:`_long_on_taught`) with a usable solve at those whole samples
        starts from that solve instead, shifted in time to the taught pass times, through the last
        ``refine_stages`` continuation stages; it is solved from the taught motion as well only where
        that start ends within :data:`ON_TAUGHT_MARGIN` of the solve, and the lower of the two is kept."""
        key = (i, -2)
        if key in self.cache:
            return self.cache[key]
        win = self.segment_of[i]
        n = int(np.floor(win.span / STEP + 1e-9))
        if n < 6 or i in self.within or i in self.linear or self.settings.follow == "via-points":
            return None  # (via points: planned within a lower acceleration limit than taught)
        self._before_solve()
        near = self.cache.get((i, n)) if self._long_on_taught(i) else None
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

    def _long_on_taught(self, i: int) -> bool:
        """Whether unit ``i`` is a long fly-by chain from rest to rest (past the gradient's
        ``max_knots`` at its taught duration, :meth:`GradientSettings.is_long`): its reshaped taught
        motion (:meth:`solve_on_taught`) comes after its solves in the time table and starts from
        the one at its taught duration."""
        return (
            len(self.chains[i]) > 1
            and i not in self.within
            and i not in self.linear
            and self.gradient.is_long(self.span[i])
        )

    def _on_taught_once(self, i: int, n: int, near: Solved | None = None) -> Solved:
        """:meth:`solve_on_taught` over ``n`` samples: from the taught motion, or from the solve
        ``near`` of the chain at ``n`` samples shifted in time to the taught pass times (each leg
        stretched linearly in time; fitted by least squares) through the last ``refine_stages``
        continuation stages."""
        win = self.segment_of[i]
        m = self.by_index[i]
        robot = self._robot(m)
        base = self.base(i, n)
        way = self._taught_passes(i, base)
        amax, jmax = self._amax(robot), self._jmax(robot)
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
            waypoint_radius=self.zone_radius(i),
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
            fine = self._taught_after(window, win.t0, win.span)
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
            None if self.settings.cell is None else self._clearance_mm(m, fine.q),
            corridor,
            passes=tuple(t for t, _ in way),
        )

    def to_stop(self, i: int, piece: Solved) -> Solved:
        """The last move's ``piece`` of unit ``i`` (inside a ``MoveL`` segment, its run ending at a
        stop) with the taught motion after its window, less than one 25 ms sample, to the stop: so
        that it ends at its target, at rest (its energy with it)."""
        win = self.segment_of[i]
        m = self.by_index[self.chains[i][-1]]
        if m.t_end - win.t1 <= 1e-9:
            return piece
        f = piece.fine
        fine = self._taught_after(f, win.t1 - f.t[-1], f.t[-1] + m.t_end - win.t1)
        sm = piece.samples
        samples = Trajectory(
            t=np.append(sm.t, fine.t[-1]),
            q=np.vstack([sm.q, fine.q[-1:]]),
            qd=np.vstack([sm.qd, fine.qd[-1:]]),
            qdd=np.vstack([sm.qdd, fine.qdd[-1:]]),
        )
        robot = self._robot(m)
        e, e_lab = window_energy(robot, self.plant(robot), fine, self.settings.energy)
        return replace(
            piece,
            duration=round(float(fine.t[-1]), 9),
            energy_J=e,
            energy_lab_J=e_lab,
            samples=samples,
            fine=fine,
        )

    def _taught_after(self, traj: Trajectory, origin: float, end: float) -> Trajectory:
        """``traj`` (its times from ``origin`` in the default cycle) continued to ``end`` (from
        ``origin`` too) with the taught motion, every 2.5 ms and at ``end``."""
        tail_t = np.append(np.arange(traj.t[-1] + FINE_DT, end - 1e-9, FINE_DT), end)
        tail = evaluate_cycle(self.plan, origin + tail_t)
        return Trajectory(
            t=np.concatenate([traj.t, tail_t]),
            q=np.vstack([traj.q, tail.q]),
            qd=np.vstack([traj.qd, tail.qd]),
            qdd=np.vstack([traj.qdd, tail.qdd]),
        )

    def zone_mm(self, j: int) -> float:
        """The zone (mm) the controller keeps at move ``j``'s target inside a chain: its zone radius,
        reduced to half the TCP length of this move and of the next (0: exactly)."""
        if not self.settings.zones:
            return 0.0
        members = next(c for c in self.chains.values() if j in c)
        k = members.index(j)
        z = self.by_index[j].step.zone_mm
        if z is None or k + 1 >= len(members):
            return 0.0
        return _reduced_zone_mm(z, self.by_index[j], self.by_index[members[k + 1]])

    def zone_radius(self, i: int) -> tuple[FloatArray, ...]:
        """Per inner target of chain ``i``, the joint box (rad, the same for every joint) whose
        every point keeps the TCP within :meth:`zone_mm` of the target, to first order with a
        margin of 1/4: ``r = 0.75 R / Σ_j |dp/dq_j|`` (the TCP moves at most Σ_j |dp/dq_j| |dq_j|)."""
        members = self.chains[i]
        out: list[FloatArray] = []
        for j in members[:-1]:
            step = self.by_index[j].step
            R = self.zone_mm(j) / 1000.0
            if R <= 0.0:
                out.append(np.zeros(step.q.size if step.q is not None else 0))
                continue
            assert step.q is not None and step.robot is not None and step.tcp is not None
            h = 1e-6
            n = step.q.size
            eye = np.eye(n) * h
            plus, _ = _tcp(step.robot, step.q[None, :] + eye, step.tcp)
            minus, _ = _tcp(step.robot, step.q[None, :] - eye, step.tcp)
            norm = float(np.linalg.norm((plus - minus) / (2 * h), axis=1).sum())
            out.append(np.full(n, 0.75 * R / max(norm, 1e-9)))
        return tuple(out)

    def zone_miss_mm(self, i: int, s: Solved) -> float:
        """Largest TCP distance (mm) beyond its zone of the chain's path from an inner target, at
        the time it passes it (0: within every zone)."""
        members = self.chains[i]
        if len(members) == 1:
            return 0.0
        step = self.by_index[i].step
        assert step.robot is not None and step.tcp is not None
        worst = 0.0
        for (t, q), j in zip(self.passes(i, s), members[:-1], strict=True):
            k = int(np.argmin(np.abs(s.fine.t - t)))
            p, _ = _tcp(step.robot, s.fine.q[k][None, :], step.tcp)
            p0, _ = _tcp(step.robot, q[None, :], step.tcp)
            worst = max(worst, 1000.0 * float(np.linalg.norm(p - p0)) - self.zone_mm(j))
        return worst

    def _chain_problem(self, i: int, T: float) -> SplineProblem:
        """The chain's problem at ``T``: fine knots, no corridor (its smoothest path is ``origin``)."""
        m0, m1 = self.by_index[i], self.by_index[self.chains[i][-1]]
        robot = self._robot(m0)
        g = self.gradient
        return SplineProblem(
            robot,
            m0.path.q0,
            m1.path.q1,
            T,
            NOMINAL_FRICTION,
            SplineBasis(T, knot_spacing=g.spacing_for(T), degree=g.degree, dt=STEP),
            check_factor=g.check_factor,
            acceleration_limit=self._amax(robot),
            waypoints=self.waypoints(i, T),
            jerk_limit=self._jmax(robot),
            waypoint_radius=self.zone_radius(i),
        )

    def _chain_shortest(self, i: int, upper: float) -> float:
        """Shortest whole-sample chain duration: the first from half the sum of its moves' shortest
        rest-to-rest durations (``upper``) whose smoothest path through the targets keeps every limit,
        else ``upper`` (the moves back to back, each from rest to rest, are feasible there). Found by
        bisection (the smoothest path at a longer duration is the same path slower, its pass times
        at the same shares up to whole samples): inspection's chain 72 checks -> 7 (issue 36)."""
        robot = self._robot(self.by_index[i])
        amax = self._amax(robot)
        n_legs = len(self.chains[i])

        def keeps_limits(units: int) -> bool:
            if units * STEP >= upper - 1e-9:
                return True
            problem = self._chain_problem(i, units * STEP)
            fine = problem.path(problem.origin, fine=True)
            return check_limits(
                robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=self._jmax(robot)
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

    def split(self, i: int, s: Solved) -> dict[int, Solved]:
        """A chain's solve cut at its targets into one piece per move (times from 0 in each piece;
        neighbouring pieces share their boundary sample)."""
        members = self.chains[i]
        if len(members) == 1:
            return {i: s}
        cuts = [0.0, *(t for t, _ in self.passes(i, s)), s.duration]
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
            w = np.full(f.t.size, s.fine.dt)
            if k > 0:
                w[0] *= 0.5
            if k < len(members) - 1:
                w[-1] *= 0.5
            p, p_lab = sample_power(robot, plant, f, self.settings.energy)
            e, e_lab = float((w * p).sum()), float((w * p_lab).sum())
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
        for k, m in enumerate(plan.moves, start=1):
            self.progress(f"clearance of the taught cycle to the cell: move {k}/{len(plan.moves)}")
            if m.profile.duration == 0:
                continue
            t = np.linspace(m.t0, m.t_end, max(2, int(np.ceil(m.profile.duration / FINE_DT)) + 1))
            self.default_clearance[m.index] = self._clearance_mm(m, evaluate_cycle(plan, t).q)

    def _robot(self, m: PlannedMove) -> Robot:
        assert m.step.robot is not None
        return m.step.robot

    def _amax(self, robot: Robot) -> FloatArray | None:
        a = acceleration_limit(robot, self.settings.accel_time)
        if a is not None and self.settings.follow == "via-points":
            a = a * RAPID_ACCEL_SHARE
        return a

    def _amax_array(self, robot: Robot) -> FloatArray:
        a = self._amax(robot)
        return np.full(robot.n_joints, np.inf) if a is None else a

    def _jmax(self, robot: Robot) -> FloatArray | None:
        return jerk_limit(robot, self.settings.accel_time, self.settings.jerk_time)

    def plant(self, robot: Robot) -> Plant:
        key = id(robot)
        if key not in self._plants:
            self._plants[key] = make_plant("lab", robot)
        return self._plants[key]

    def solve(self, i: int, duration: float) -> Solved:
        """The optimized move ``i`` at ``duration`` (a whole number of 25 ms samples), verified; cached.

        A fly-by chain (not inside a ``MoveL`` segment) with a usable solve at another duration starts
        from it, stretched to ``duration`` (:meth:`_time_scaled`), on its fine knots through the last
        continuation stages, and is solved as usual where that is not usable. Measured on
        pick_and_place (issue 36): its 2-move chain at its shortest duration 5.6 -> 0.6 s of CPU, at
        the next 0.3 -> 0.2 s, the same energies (to 1 mJ); the cold solve there ended SLSQP's rounds
        with incompatible constraints."""
        units = int(round(duration / STEP))
        key = (i, units)
        if key in self.cache:
            return self.cache[key]
        self._before_solve()
        m = self.by_index[i]
        T = units * STEP
        corridors: list[float | None] = [self.settings.corridor_mm]
        if self.settings.cell is not None:  # tighter corridors around the (clear) taught move
            first = self.settings.corridor_mm or 100.0
            corridors += [first / 2, first / 4, first / 8]
        warm = self._neighbour(i, T) if self.settings.warm_start and len(self.chains[i]) == 1 else None
        out: Solved | None = None
        chained = len(self.chains[i]) > 1 and i not in self.within
        near = self._neighbour(i, T) if chained else None
        if near is not None and near.coefficients is not None:  # a chain: from its nearest duration
            g = self.gradient
            refine = replace(g, n_starts=1, coarse_factor=1, continuation=g.continuation[-g.refine_stages :])
            out = self._solve_once(
                m, T, units, corridors[0], gradient=refine, initial=self._time_scaled(i, T, near)
            )
            if out.usable:
                self.cache[key] = out
                return out
        for corridor in corridors:
            out = self._solve_once(m, T, units, corridor, warm)
            if out.usable or not out.limits_ok:
                break
        assert out is not None
        self.cache[key] = out
        return out

    def _time_scaled(
        self, i: int, T: float, near: Solved, gradient: GradientSettings | None = None
    ) -> FloatArray:
        """The solve ``near`` of chain ``i`` stretched to ``T`` in the coefficients of a solve at ``T``
        (on ``gradient``'s knots, default the fine ones; flat; least squares on the fine grid, offsets
        from the minimum-jerk move): it passes each target at the same share of the duration, as
        :meth:`waypoints` asks at ``T``."""
        g = self.gradient if gradient is None else gradient
        basis = SplineBasis(T, knot_spacing=g.spacing_for(T), degree=g.degree, dt=STEP)
        fine = basis.grid(STEP / g.check_factor)
        q0, q1 = self.by_index[i].path.q0, self.by_index[self.chains[i][-1]].path.q1
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
        robot = self._robot(m)
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
            acceleration_limit=self._amax(robot),
            jerk_limit=self._jmax(robot),
            energy_measure=self.settings.energy,
            thin_rows=g.is_long(T),
        )
        t_old = problem.fine.t * (warm.duration / T)
        q_old = np.column_stack(
            [np.interp(t_old, warm.fine.t, warm.fine.q[:, j]) for j in range(robot.n_joints)]
        )
        c = np.linalg.lstsq(problem.fine.B, q_old - problem.default_fine.q, rcond=None)[0]
        return problem, c

    def _solve_once(
        self,
        m: PlannedMove,
        T: float,
        units: int,
        corridor: float | None,
        warm: Solved | None = None,
        way: tuple[tuple[float, FloatArray], ...] | None = None,
        gradient: GradientSettings | None = None,
        initial: FloatArray | None = None,
    ) -> Solved:
        robot = self._robot(m)
        amax = self._amax(robot)
        seq = np.random.SeedSequence([self.settings.seed, m.index, units])
        rng = np.random.default_rng(seq)
        if m.index in self.linear:
            return self._retime_once(m, T)
        inner = m.index in self.within
        way = self.waypoints(m.index, T) if way is None else way
        base = self.base(m.index) if inner else None
        q0 = m.path.q0 if base is None else base.q[0]
        q1 = self.by_index[self.chains[m.index][-1]].path.q1 if base is None else base.q[-1]
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
                jerk_limit=self._jmax(robot),
                waypoint_radius=self.zone_radius(m.index),
                base=base,
                energy_measure=self.settings.energy,
                deadline=self.deadline,
                initial=initial,
            )
        self.n_solves += 1
        x = res.coefficients.ravel()
        fine = problem.path(x, fine=True)
        report = check_limits(
            robot, fine, friction=NOMINAL_FRICTION, acceleration_limit=amax, jerk_limit=self._jmax(robot)
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
            None if self.settings.cell is None else self._clearance_mm(m, fine.q),
            corridor,
            passes=tuple(t for t, _ in way) if way else None,
            coefficients=x,
        )

    def _retime_once(self, m: PlannedMove, T: float) -> Solved:
        """A MoveL re-timed along its line at ``T`` (its speeddata's TCP speed a bound), verified."""
        robot = self._robot(m)
        assert m.step.speed is not None
        r = retime_on_path(
            robot,
            m.path,
            T,
            acceleration_limit=self._amax_array(robot),
            jerk_limit=self._jmax(robot),
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
            None if self.settings.cell is None else self._clearance_mm(m, r.fine.q),
            None,
        )

    # ------------------------------------------------------------ default
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

    def taught(self, i: int) -> Solved:
        """Unit ``i`` as taught: the default cycle's motion over its window (2.5 ms grid)."""
        key = (i, -1)
        if key in self.cache:
            return self.cache[key]
        win = self.segment_of[i]
        fine = self.base(i)
        every = self.gradient.check_factor
        samples = Trajectory(t=fine.t[::every], q=fine.q[::every], qd=fine.qd[::every], qdd=fine.qdd[::every])
        robot = self._robot(self.by_index[i])
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
            else min(self.default_clearance.get(j, np.inf) for j in win.moves),
            None,
            taught=True,
        )
        self.cache[key] = out
        return out

    def kept_energy(self) -> tuple[float, float]:
        """Physics and lab J of everything outside the units (the default cycle's, less the units'
        taught motion): what the cycle spends besides its units."""
        default = self.default_energies()
        e0 = sum(v[1] for v in default.values())
        e0_lab = sum(v[2] for v in default.values())
        units = [self.taught(i) for i in self.optimizable]
        return e0 - sum(s.energy_J for s in units), e0_lab - sum(s.energy_lab_J for s in units)

    # ------------------------------------------------------------ allocation
    def budget(self, cycle_time: float, use_waits: bool) -> float:
        """s the units may take in a cycle of ``cycle_time``."""
        return cycle_time - self.fixed_time - self.waits_kept(use_waits)

    def table(self, budget: float) -> dict[int, list[Solved]]:
        """Each unit: its taught motion, then solved at ``table_points`` durations from its shortest
        to the most the budget leaves it (the others at their shortest), and at its taught duration."""
        k = self.settings.table_points
        shares = np.concatenate([[0.0], np.geomspace(0.06, 1.0, k - 1)])
        floor = {i: min(self.t_lo[i], self.span[i]) for i in self.optimizable}
        out: dict[int, list[Solved]] = {i: [self.taught(i)] for i in self.optimizable}
        if not self._reshape(out, long=False):  # each reshaped from its taught motion (a long chain's
            return out  # after its solves: solve_on_taught)
        for n_move, i in enumerate(self.optimizable, start=1):
            hi = budget - (sum(floor.values()) - floor[i])
            # a unit is solved at most as long as the move_s limit (or its own taught duration): idle
            # time beyond what the moves can use stays a wait (a long wait with --use-waits)
            hi = min(hi, max(self.span[i], work_limit("move_s")))
            if hi < self.t_lo[i] - 1e-9:
                continue  # the optimizer's shortest does not fit: taught only
            self.progress(f"unit {n_move}/{len(self.optimizable)}: solving at up to {k + 1} durations")
            if i in self.within:  # its ends are the taught motion's: at its own duration only
                try:
                    self.tune_passes(i, round(self.span[i] / STEP) * STEP)
                    out[i].append(self.solve(i, round(self.span[i] / STEP) * STEP))
                except TimeBudgetSpent:
                    return out
                continue
            units = {int(round((self.t_lo[i] + s * (hi - self.t_lo[i])) / STEP)) for s in shares}
            own = int(np.floor(self.span[i] / STEP + 1e-9))
            if own * STEP >= self.t_lo[i] - 1e-9 and own * STEP <= hi + 1e-9:
                units.add(own)
            lo_u = int(np.ceil(self.t_lo[i] / STEP - 1e-9))
            units = {max(u, lo_u) for u in units if u * STEP <= hi + 1e-9} or {lo_u}
            try:  # when the chain passes its targets: searched at its own duration (or the middle one)
                self.tune_passes(i, (own if own in units else sorted(units)[len(units) // 2]) * STEP)
            except TimeBudgetSpent:
                return out
            if self._screens_durations(i, max(units)):
                try:
                    out[i].extend(self._screened(i, sorted(units)))
                except TimeBudgetSpent:
                    out[i].extend(s for (j, u), s in self.cache.items() if j == i and u in units)
                    return out
                continue
            for u in sorted(units):
                try:
                    out[i].append(self.solve(i, u * STEP))
                except TimeBudgetSpent:
                    return out
        self._reshape(out, long=True)  # a long chain's, from its solve
        return out

    def _reshape(self, out: dict[int, list[Solved]], *, long: bool) -> bool:
        """The units reshaped from their taught motion (:meth:`solve_on_taught`) into ``out``: those whose
        reshaping starts from their solve (``long``, :meth:`_long_on_taught`) or the others; False where
        the time budget ran out."""
        for n_unit, i in enumerate(self.optimizable, start=1):
            if self._long_on_taught(i) != long:
                continue
            self.progress(f"unit {n_unit}/{len(self.optimizable)}: reshaping its taught motion")
            try:
                reshaped = self.solve_on_taught(i)
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
            for i in self.optimizable
        )

    def dp(self, table: dict[int, list[Solved]], budget: float) -> dict[int, Solved] | None:
        """The least-energy choice of one usable entry per unit with Σ durations ≤ budget
        (:func:`~joulepath.program._cycle_allocation.least_energy_choice`)."""
        picks = least_energy_choice(self.entries(table), budget)
        if picks is None:
            return None
        return {i: table[i][k] for i, k in zip(reversed(self.optimizable), reversed(picks), strict=True)}

    def continuous(self, table: dict[int, list[Solved]], budget: float) -> dict[int, Solved] | None:
        """Share the budget on the fitted curves ``a + b/T + c/T²`` of the solved entries
        (:func:`~joulepath.program._cycle_allocation.fitted_share`), then solve at the shares; None
        when a unit has no usable solved entry or the budget does not reach every unit's shortest."""
        idx = self.optimizable
        lo = np.array([self.t_lo[i] for i in idx], dtype=float)
        fixed = np.array([i in self.within for i in idx], dtype=bool)
        units = fitted_share(self.entries(table), lo, fixed, budget, step=STEP)
        if units is None:
            return None
        try:
            return {i: self.solve(i, float(u * STEP)) for i, u in zip(idx, units, strict=True)}
        except TimeBudgetSpent:
            return None

    def evaluate(self, choice: dict[int, Solved], waits: float) -> Allocation:
        """Cycle energies (J) and time (s) of one entry per unit, the kept moves and ``waits`` s."""
        kept, kept_lab = self.kept_energy()
        e = sum(s.energy_J for s in choice.values()) + kept
        e_lab = sum(s.energy_lab_J for s in choice.values()) + kept_lab
        cycle = self.fixed_time + waits + sum(s.duration for s in choice.values())
        return Allocation(
            {i: s.duration for i, s in choice.items()}, float(e), float(e_lab), cycle, dict(choice)
        )

    def at_taught_durations(self, table: dict[int, list[Solved]]) -> dict[int, Solved]:
        """Each unit reshaped at its own taught duration (in whole samples), where that was solved
        and is usable; else as taught."""
        out: dict[int, Solved] = {}
        for i in self.optimizable:
            own = int(np.floor(self.span[i] / STEP + 1e-9))
            same = [s for s in table[i] if not s.taught and s.usable and int(round(s.duration / STEP)) == own]
            out[i] = min([*same, self.taught(i)], key=lambda s: s.energy_J)
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
        if sum(self.span.values()) <= budget + 1e-9:
            candidates.append(self.evaluate({i: self.taught(i) for i in self.optimizable}, waits))
        if not candidates:
            raise LimitViolation(
                f"{self.spec.source}: no allocation of the durations keeps every optimized move "
                "within its limits"
            )
        return min(candidates, key=lambda a: a.energy_J)

    # ------------------------------------------------------------ the whole cycle
    def motion(self, choice: dict[int, Solved], use_waits: bool) -> CycleMotion:
        """The cycle with each unit's chosen entry in place of its window and, with ``use_waits``,
        the idle waits left out: every piece sampled every 2.5 ms from its own start (the taught
        pieces from the controller emulation, the units' from their solves), and the cycle's last
        sample at its end; where each move starts in it."""
        plan = self.plan
        cut: list[tuple[float, float, Solved | None]] = [
            (self.segment_of[i].t0, self.segment_of[i].t1, s) for i, s in choice.items() if not s.taught
        ]
        if use_waits:
            cut += [(t0, t0 + sec, None) for k, t0, sec in plan.waits if self.spec.steps[k].idle and sec > 0]
        cut.sort(key=lambda c: c[0])
        pieces: list[tuple[float, float, Solved | None, bool]] = []  # default from, to; entry; kept
        c = 0.0
        for a, b, s in cut:
            if a > c + 1e-12:
                pieces.append((c, a, None, True))
            pieces.append((a, b, s, False))
            c = b
        if c < plan.cycle_time - 1e-12:
            pieces.append((c, plan.cycle_time, None, True))
        ts, qs, qds, qdds = [], [], [], []
        starts: dict[int, float] = {}
        off = 0.0
        by_first = {self.segment_of[i].t0: i for i, s in choice.items() if not s.taught}
        for a, b, s, keep in pieces:
            if keep:
                local = np.arange(0.0, b - a - 1e-9, FINE_DT)
                part = evaluate_cycle(plan, a + local)
                ts.append(off + local)
                qs.append(part.q)
                qds.append(part.qd)
                qdds.append(part.qdd)
                for m in plan.moves:
                    if a - 1e-12 <= m.t0 < b - 1e-12 or (m.t0 >= b - 1e-12 and b >= plan.cycle_time - 1e-12):
                        starts.setdefault(m.index, off + min(m.t0, b) - a)
                off += b - a
                continue
            if s is None:  # a wait left out
                continue
            i = by_first[a]
            f = s.fine
            k = f.t.size - 1
            ts.append(off + f.t[:k])
            qs.append(f.q[:k])
            qds.append(f.qd[:k])
            qdds.append(f.qdd[:k])
            cuts = [0.0, *(t for t, _ in self.passes(i, s))]
            for j, tc in zip(self.chains[i], cuts, strict=True):
                starts.setdefault(j, off + tc)
            for j in self.segment_of[i].moves:  # moves without motion inside the window
                starts.setdefault(j, off)
            off += s.duration
            for m in plan.moves:  # a move the window's blend starts (a MoveL after it): from its end
                if a + 1e-12 < m.t0 < b - 1e-12:
                    starts.setdefault(m.index, off)
        end = evaluate_cycle(plan, np.array([plan.cycle_time]))
        ts.append(np.array([off]))
        qs.append(end.q)
        qds.append(np.zeros_like(end.q))
        qdds.append(np.zeros_like(end.q))
        traj = Trajectory(t=np.concatenate(ts), q=np.vstack(qs), qd=np.vstack(qds), qdd=np.vstack(qdds))
        order = [m.index for m in plan.moves]
        mono = np.maximum.accumulate([starts.get(j, 0.0) for j in order]) if order else np.zeros(0)
        return CycleMotion(traj, {j: float(v) for j, v in zip(order, mono, strict=True)}, off)

    def retime_segments(self, motion: CycleMotion) -> tuple[CycleMotion, dict[int, Solved]]:
        """``motion`` with every segment that has a ``MoveL`` re-timed along its own joint path in it.

        Each such segment of ``motion`` (its units' chosen entries and the taught moves between
        them) is one path ``q(s)``, a quintic Hermite interpolation of its samples (position, speed
        and acceleration), re-timed by :func:`joulepath.optimize.retime_on_path` from its own
        timing (``start="identity"``): the same joint path, so every ``MoveL`` keeps its line
        and its tool orientation, every zone and blend its geometry, and the segment its
        duration and its speed and acceleration at both ends; only when the robot is where
        along it changes, so that time moves between the lines, the blends and the joint moves.
        Samples of a ``MoveL`` keep its speeddata: a TCP speed within ``v_tcp`` and the
        reorientation within ``v_ori`` (their bound on the TCP speed along the line), or the
        controller's own speed there where that is higher (a blend). A segment's new timing is
        kept only where it holds every limit and its energy on the cycle's measure is lower.

        Returns
        -------
        tuple
            The new motion (the same cycle time) and, by step index, each re-timed move's piece of
            it (a :class:`Solved` whose samples start at 0).
        """
        st = self.settings
        if not st.retime_segments or st.follow != "samples":
            return motion, {}
        traj = motion.trajectory
        order = [m.index for m in self.plan.moves]
        starts = dict(motion.starts)
        ts, qs, qds, qdds = [traj.t], [traj.q], [traj.qd], [traj.qdd]
        done: list[tuple[Segment, tuple[int, ...]]] = []
        for seg in self.segments:
            moving = tuple(j for j in seg.moves if self.by_index[j].profile.duration > 0)
            if not moving or not any(self.by_index[j].step.linear for j in moving):
                continue
            if len(moving) == 1 and moving[0] in self.linear:
                continue  # a MoveL from rest to rest: its own unit re-times it along its line
            if any(self.default_clearance.get(j, np.inf) < 0.0 for j in moving):
                continue  # a taught move within the cell's margin: reported, left as it is
            if any(self.by_index[j].step.kept for j in moving):
                continue  # a move known only at run time (the RAPID interpreter's mark) runs as taught
            if seg.span > RETIME_MAX_SPAN_S:
                continue  # SLSQP's dense QP grows with the rows (2.5 ms samples) times variables squared
            first = self.by_index[moving[0]].step
            robot, tcp = self._robot(self.by_index[moving[0]]), first.tcp
            if tcp is None or any(
                self.by_index[j].step.robot is not robot
                or not np.array_equal(np.asarray(self.by_index[j].step.tcp), tcp)
                for j in moving
            ):
                continue  # a tool change inside the segment: left as it is
            if self.deadline is not None and time.perf_counter() > self.deadline:
                self.timed_out = True
                break
            t = ts[-1]
            a = motion.starts[moving[0]]
            i0 = int(np.searchsorted(t, a + 1e-9)) - 1  # the last sample at or before its start
            i1 = int(np.searchsorted(t, a + seg.span - 1e-9))  # the first at or after its end
            if i0 < 0 or i1 >= t.size or i1 - i0 < 8:
                continue
            sel = slice(i0, i1 + 1)
            tt, q, qd, qdd = t[sel], qs[-1][sel], qds[-1][sel], qdds[-1][sel]
            span = float(tt[-1] - tt[0])
            bound = self._line_bounds(robot, tcp, seg, tt, q, qd)
            self.progress(f"re-timing the segment of line {first.line} along its path")
            self.n_solves += 1
            try:
                r = retime_on_path(
                    robot,
                    _hermite_path(tt, q, qd, qdd),
                    span,
                    acceleration_limit=self._amax_array(robot),
                    jerk_limit=self._jmax(robot),
                    tcp_speed_limit=_interpolated((tt - tt[0]) / span, bound),
                    tcp=tcp,
                    energy_measure=st.energy,
                    start="identity",
                    free_ends=(_at_rest(qd[0], qdd[0]), _at_rest(qd[-1], qdd[-1])),
                    deadline=self.deadline,
                )
            except InvalidInput:
                continue  # a segment that does not move
            if not r.feasible:
                continue
            plant = self.plant(robot)
            old = Trajectory(t=tt, q=q, qd=qd, qdd=qdd)
            new = replace(r.fine, t=r.fine.t + tt[0])
            e_new, e_old = (window_energy(robot, plant, x, st.energy)[0] for x in (new, old))
            if e_new >= e_old * (1.0 - RETIME_GAIN):
                continue
            s_new = np.maximum.accumulate(r.s) + np.arange(r.s.size) * 1e-15
            for j in seg.moves:
                if tt[0] - 1e-9 <= starts[j] <= tt[-1] + 1e-9:
                    starts[j] = float(tt[0] + np.interp((starts[j] - tt[0]) / span, s_new, r.fine.t))
            ts.append(np.concatenate([t[:i0], new.t, t[i1 + 1 :]]))
            qs.append(np.concatenate([qs[-1][:i0], new.q, qs[-1][i1 + 1 :]]))
            qds.append(np.concatenate([qds[-1][:i0], new.qd, qds[-1][i1 + 1 :]]))
            qdds.append(np.concatenate([qdds[-1][:i0], new.qdd, qdds[-1][i1 + 1 :]]))
            done.append((seg, moving))
        if not done:
            return motion, {}
        out = CycleMotion(
            Trajectory(t=ts[-1], q=qs[-1], qd=qds[-1], qdd=qdds[-1]),
            {j: starts[j] for j in order},
            motion.cycle_time,
        )
        return out, self._pieces_of(out, done)

    def _line_bounds(
        self, robot: Robot, tcp: FloatArray, seg: Segment, t: FloatArray, q: FloatArray, qd: FloatArray
    ) -> FloatArray:
        """The TCP speed bound (m/s) at each sample of a segment that starts at ``t[0]`` (its samples
        before it is re-timed): on a ``MoveL``'s line, between the blends at its ends, its speeddata's
        (``v_tcp``, and ``v_ori`` over its turn as a TCP speed along its line; the controller's own
        speed there where that is higher); elsewhere, in the zones' blends and the joint moves, none
        (a large number: the joints' limits bound them)."""
        speed = np.linalg.norm(tcp_velocity(robot, q, qd, tcp), axis=1)
        out = np.full(t.size, NO_SPEED_BOUND)
        moving = [self.by_index[j] for j in seg.moves if self.by_index[j].profile.duration > 0]
        for k, m in enumerate(moving):
            if not m.step.linear or m.step.speed is None:
                continue
            a = max(m.t0, moving[k - 1].t_end) if k > 0 else m.t0  # after the blend into it
            b = min(m.t_end, moving[k + 1].t0) if k + 1 < len(moving) else m.t_end  # before the next
            on = (t >= t[0] + a - seg.t0 - 1e-9) & (t <= t[0] + b - seg.t0 + 1e-9)
            v = m.step.speed.v_tcp
            if m.path.angle_deg > 1e-6 and m.path.length_mm > 1e-6:
                v = min(v, m.step.speed.v_ori * m.path.length_mm / m.path.angle_deg)
            out[on] = v / 1000.0
        # one sample wider on each side (the bound is interpolated between samples), never below the
        # speed the motion already has there
        wide = np.minimum(out, np.minimum(np.roll(out, 1), np.roll(out, -1)))
        wide[[0, -1]] = out[[0, -1]]
        bound: FloatArray = np.maximum(wide, speed * (1.0 + 1e-6))
        return bound

    def _pieces_of(
        self, motion: CycleMotion, done: list[tuple[Segment, tuple[int, ...]]]
    ) -> dict[int, Solved]:
        """Each move of the re-timed segments as its own piece of ``motion``: its samples from its
        start to the next move's (times from 0), its energies over the same half-open window as
        :meth:`move_energies`, and its samples every 25 ms (interpolated)."""
        traj = motion.trajectory
        order = [m.index for m in self.plan.moves]
        nxt = dict(zip(order, [*order[1:], None], strict=True))
        out: dict[int, Solved] = {}
        for _, moving in done:
            robot = self._robot(self.by_index[moving[0]])
            plant = self.plant(robot)
            for j in moving:
                k = nxt[j]
                a, b = motion.starts[j], (motion.cycle_time if k is None else motion.starts[k])
                sel = (traj.t >= a - 1e-9) & (traj.t <= b + 1e-9)
                if np.count_nonzero(sel) < 2:
                    continue
                tt = traj.t[sel]
                fine = Trajectory(t=tt - tt[0], q=traj.q[sel], qd=traj.qd[sel], qdd=traj.qdd[sel])
                e, e_lab = window_energy(robot, plant, fine, self.settings.energy)
                grid = np.append(np.arange(0.0, fine.t[-1] - 1e-9, STEP), fine.t[-1])

                def at(x: FloatArray, f: Trajectory = fine, g: FloatArray = grid) -> FloatArray:
                    return np.column_stack([np.interp(g, f.t, x[:, c]) for c in range(x.shape[1])])

                samples = Trajectory(t=grid, q=at(fine.q), qd=at(fine.qd), qdd=at(fine.qdd))
                out[j] = Solved(
                    round(float(fine.t[-1]), 9),
                    e,
                    e_lab,
                    True,
                    (),
                    samples,
                    fine,
                    0.0,
                    self.default_clearance.get(j),
                )
        return out

    def move_energies(self, motion: CycleMotion) -> dict[int, tuple[float, float]]:
        """Physics and lab J per move over its slot of ``motion`` (its start to the next move's
        start, the last to the cycle's end): ``Σ_k |tau_k · qd_k| (t_{k+1} - t_k)``."""
        traj = motion.trajectory
        robot = self.spec.robot
        moves = self.plan.moves
        if moves and moves[0].step.robot is not None:
            robot = moves[0].step.robot
        plant = self.plant(robot)
        w = np.append(np.diff(traj.t), 0.0)
        p, p_lab = sample_power(robot, plant, traj, self.settings.energy)
        p, p_lab = p * w, p_lab * w
        bounds = [motion.starts[m.index] for m in moves] + [motion.cycle_time + 1.0]
        out: dict[int, tuple[float, float]] = {}
        for k, m in enumerate(moves):
            sel = (traj.t >= bounds[k] - 1e-12) & (traj.t < bounds[k + 1] - 1e-12)
            out[m.index] = (float(p[sel].sum()), float(p_lab[sel].sum()))
        return out

    def measures(
        self, default: CycleMotion, optimized: CycleMotion
    ) -> tuple[tuple[MeasureSummary, ...], dict[str, str]]:
        """Every measure the robot has the data for, of the default and the optimized cycle's whole
        motion (model and lab plant, like for like; the standby power over each one's cycle time
        included where the measure counts it: the meter-level figure); why not, for the rest."""
        robot = self.spec.robot
        moves = self.plan.moves
        if moves and moves[0].step.robot is not None:
            robot = moves[0].step.robot
        plant = self.plant(robot)
        out: list[MeasureSummary] = []
        unavailable: dict[str, str] = {}
        for name, spec in MEASURES.items():
            why = spec.missing(robot.drivetrain)
            if why is not None:
                unavailable[name] = why
                continue
            model: list[float] = []
            lab: list[float | None] = []
            standby = 0.0
            lab_ok = spec.missing(plant.drivetrain) is None
            for motion in (default, optimized):
                traj = motion.trajectory
                w = np.append(np.diff(traj.t), 0.0)
                tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
                e = measure_energy(name, tau, traj.qd, w, robot.drivetrain, duration=motion.cycle_time)
                model.append(e.total_J)
                standby = standby or e.standby_J
                if lab_ok:
                    lab_tau = plant.joint_torque(traj.q, traj.qd, traj.qdd)
                    el = measure_energy(
                        name, lab_tau, traj.qd, w, plant.drivetrain, duration=motion.cycle_time
                    )
                    lab.append(el.total_J)
                else:
                    lab.append(None)
            ld, lo = lab
            out.append(
                MeasureSummary(
                    measure=name,
                    stage=spec.stage,
                    source=spec.source(robot.drivetrain),
                    default_J=model[0],
                    optimized_J=model[1],
                    saved_pct=100 * (model[0] - model[1]) / model[0] if model[0] > 0 else 0.0,
                    standby_J=standby,
                    lab_default_J=ld,
                    lab_optimized_J=lo,
                    lab_saved_pct=None if ld is None or lo is None or ld <= 0 else 100 * (ld - lo) / ld,
                    lab_source=spec.source(plant.drivetrain)
                    if lab_ok
                    else str(spec.missing(plant.drivetrain)),
                )
            )
        return tuple(out), unavailable


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
) -> tuple[CycleResult, CycleOptimizer]:
    """Optimize a cycle at the default's cycle time (or ``settings.cycle_time``); verified.

    Never refused at the taught cycle time: each unit's taught motion is a candidate, so
    in the worst case the taught cycle itself is returned, 0 % saved.
    """
    return _optimize_cycle(spec, settings, progress=progress)


def _optimize_cycle(
    spec: CycleSpec,
    settings: CycleSettings,
    *,
    progress: Callable[[str], None] | None = None,
    plan: PlannedCycle | None = None,
) -> tuple[CycleResult, CycleOptimizer]:
    """:func:`optimize_cycle`, on ``plan`` when given (the taught cycle planned under
    ``settings.controller``: the plan for via points takes the one for samples had)."""
    check_moves_arm(spec)
    t_start = time.perf_counter()
    deadline = None if settings.max_time_s is None else t_start + settings.max_time_s
    opt = CycleOptimizer(spec, settings, progress=progress, deadline=deadline, plan=plan)
    plan = opt.plan
    target = plan.cycle_time if settings.cycle_time is None else settings.cycle_time
    check_work(  # the time the moves may take at this cycle time, before any of them is solved
        "motion_s",
        target - opt.waits_kept(settings.use_waits),
        f"{spec.source}: at a cycle time of {target:g} s",
        "give a shorter cycle time, or declare fewer waits idle for --use-waits",
    )
    shortest = opt.shortest_cycle + opt.waits_kept(settings.use_waits)
    if target < shortest - 1e-9:
        raise LimitViolation(
            f"{spec.source}: cycle time {target:.3f} s is shorter than the shortest this program "
            "reaches with its optimized moves at their shortest "
            f"({shortest:.3f} s; the default runs {plan.cycle_time:.3f} s); "
            f"give --cycle-time {np.ceil(shortest * 1000) / 1000:.3f} or more"
            + ("" if settings.use_waits or not opt.idle_total else ", or allow --use-waits")
        )
    default = opt.default_energies()
    e0 = sum(v[1] for v in default.values())
    b_plain = opt.budget(target, use_waits=False)
    b_waits = opt.budget(target, use_waits=True)
    table = opt.table(b_waits if settings.use_waits else b_plain)
    opt.progress("sharing the cycle time")
    shape = opt.evaluate(opt.at_taught_durations(table), opt.wait_total)
    floor_plain = sum(min(opt.t_lo[i], opt.span[i]) for i in opt.optimizable)
    plain = opt.best(table, b_plain, opt.wait_total) if b_plain >= floor_plain - 1e-9 else None
    final = plain if not settings.use_waits else opt.best(table, b_waits, opt.waits_kept(True))
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
    """The verified result of one allocation: per-move outcomes, pieces, via points, the motion
    (``along_paths``: with :meth:`CycleOptimizer.retime_segments`, and the result without it as its
    :attr:`CycleResult.unretimed`)."""
    spec, settings, plan = opt.spec, opt.settings, opt.plan
    default = opt.default_energies()
    e0 = breakdown.default_J
    e0_lab = sum(v[2] for v in default.values())
    motion = opt.motion(final.choice, settings.use_waits)
    retimed: dict[int, Solved] = {}
    if along_paths:
        motion, retimed = opt.retime_segments(motion)
    spent = opt.move_energies(motion)  # the reported energies: per move, on the cycle's motion
    energies, unavailable = opt.measures(opt.default_motion(), motion)
    outcomes: list[MoveOutcome] = []
    paths: dict[int, Solved] = {}
    ok = True
    pieces: dict[int, Solved] = {}
    notes: dict[int, str] = {}
    taught_units = [i for i, s in final.choice.items() if s.taught]
    for i, whole in final.choice.items():
        members = opt.chains[i]
        if whole.taught:
            for j in opt.segment_of[i].moves:
                notes[j] = (
                    "kept as taught: no reshaped motion of this segment saves energy in the time it is given"
                    if len(table[i]) > 1
                    else "kept as taught: the optimizer's shortest motion of this segment is longer than "
                    "the taught one" + (" (or --max-time was reached first)" if opt.timed_out else "")
                )
            continue
        ok = ok and whole.usable
        pieces.update(opt.split(i, whole))
        last = opt.chains[i][-1]
        if i in opt.within and opt.by_index[last].stops:
            pieces[last] = opt.to_stop(i, pieces[last])
        for j in opt.chains[i]:  # the unit's pieces as re-timed along their segment's path
            if j in retimed:
                pieces[j] = replace(
                    retimed[j], corridor_dev_mm=pieces[j].corridor_dev_mm, clearance_mm=pieces[j].clearance_mm
                )
        for j in members:
            zones = any(opt.zone_mm(k) > 0 for k in members[:-1])
            notes[j] = (
                "MoveL re-timed along its line (its speeddata's TCP speed a bound)"
                if j in opt.linear
                else "reshaped and re-timed"
                if len(members) == 1
                else "reshaped and re-timed in one fly-by chain with lines "
                + ", ".join(str(opt.by_index[k].step.line) for k in members)
                + (
                    " (passes each fly-by target within its zone, without stopping)"
                    if zones
                    else " (passes the zone targets exactly, without stopping)"
                )
            )
    for j, piece in retimed.items():  # the moves of the segments re-timed along their path
        if j in notes:
            notes[j] += "; then re-timed along its segment's path with the segment's MoveL"
            continue
        pieces[j] = piece
        notes[j] = (
            "MoveL re-timed along its segment's path: its line and tool orientation kept, its speeddata "
            "a bound"
            if spec.steps[j].linear
            else "its taught path kept, re-timed along its segment's path with the segment's MoveL"
        )
    vias: dict[int, tuple[int, ...]] = {}
    for i, whole in final.choice.items():
        if whole.taught:
            continue
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
            n_via, dev_q, dev_mm = (
                via_deviation(m.step, s, vias[m.index]) if m.index in vias else (0, 0.0, 0.0)
            )
            outcomes.append(
                MoveOutcome(
                    m.step.line,
                    m.step.label,
                    True,
                    notes[m.index],
                    d_T,
                    s.duration,
                    d_e,
                    spent[m.index][0],
                    d_lab,
                    spent[m.index][1],
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
            continue
        if m.index in notes:
            note = notes[m.index]
        elif m.profile.duration == 0:
            note = "no motion"
        elif opt.default_clearance.get(m.index, np.inf) < 0.0:
            note = "the default move comes closer to the cell than the margin: reported, not optimized"
        elif m.step.kept:
            note = "kept as taught: " + m.step.kept[0]
        elif m.step.repeated:
            note = "occurs more than once in the cycle: kept as taught"
        elif any(opt.by_index[j].step.linear for j in _segment_with(opt, m.index).moves):
            note = (
                "MoveL: kept as taught (straight line, controller timing)"
                if m.step.linear
                else "kept as taught: blended with a MoveL (the segment runs as the controller runs it)"
            )
        else:
            note = "kept as taught: part of a fly-by chain (--stop-at-targets)"
        outcomes.append(
            MoveOutcome(
                m.step.line,
                m.step.label,
                False,
                note,
                d_T,
                m.profile.duration,
                d_e,
                spent[m.index][0],
                d_lab,
                spent[m.index][1],
                True,
                (),
                0,
                0.0,
                0.0,
                0.0,
                opt.default_clearance.get(m.index),
                opt.default_clearance.get(m.index),
            )
        )
    waits = tuple(
        (spec.steps[i].line, sec, 0.0 if settings.use_waits and spec.steps[i].idle else sec)
        for i, _, sec in plan.waits
    )
    result = CycleResult(
        moves=tuple(outcomes),
        default_cycle_s=plan.cycle_time,
        target_cycle_s=target,
        optimized_cycle_s=motion.cycle_time,
        default_energy_J=e0,
        optimized_energy_J=float(sum(v[0] for v in spent.values())),
        default_lab_J=e0_lab,
        optimized_lab_J=float(sum(v[1] for v in spent.values())),
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
        chains={i: c for i, c in opt.chains.items() if len(c) > 1 and i in pieces},
        vias=vias,
        planned=motion.trajectory,
        taught_units=tuple(spec.steps[i].line for i in taught_units),
        long_units=tuple(spec.steps[i].line for i in opt.long_units),
        timed_out=opt.timed_out,
        open_ends=frozenset(
            opt.chains[i][-1]
            for i, s in final.choice.items()
            if not s.taught and i in opt.within and spec.steps[opt.chains[i][-1]].zone_mm is not None
        ),
        zone_miss_mm=max(
            [opt.zone_miss_mm(i, s) for i, s in final.choice.items() if not s.taught], default=0.0
        ),
        energy_measure=settings.energy,
        energies=energies,
        energies_unavailable=unavailable,
        path_retimed=tuple(sorted(retimed)),
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


def _ordered_closest(dist: FloatArray, *, lo: int, hi: int, gap: int) -> list[int]:
    """Sample indices ``k_0 < k_1 < ...`` (at least ``gap`` apart, within ``[lo, hi]``) that
    minimize the summed distances ``dist[j, k_j]``: when the motion passes each target in order.

    A target the chain visits twice is matched to its own pass, not to the closer other one (a
    greedy nearest match could take a later pass and leave no samples for the targets after it).
    Too few samples for the targets: spread evenly over the window."""
    m, n = dist.shape
    hi = min(hi, n - 1)
    if m == 0:
        return []
    if hi - lo < gap * (m - 1):
        return [int(round(v)) for v in np.linspace(0, n - 1, m + 2)[1:-1]]
    cost = np.full((m, n), np.inf)
    arg = np.zeros((m, n), dtype=int)
    cost[0, lo : hi + 1] = dist[0, lo : hi + 1]
    for j in range(1, m):
        prev = cost[j - 1]
        # best predecessor at or before k - gap: a running minimum and where it is
        run = np.minimum.accumulate(prev)
        where = np.maximum.accumulate(np.where(prev == run, np.arange(n), 0))
        ks = np.arange(lo + gap * j, hi + 1)
        cost[j, ks] = dist[j, ks] + run[ks - gap]
        arg[j, ks] = where[ks - gap]
    ks_out = [int(np.argmin(cost[-1]))]
    for j in range(m - 1, 0, -1):
        ks_out.append(int(arg[j, ks_out[-1]]))
    return ks_out[::-1]


def _segment_with(opt: CycleOptimizer, index: int) -> Segment:
    return next(seg for seg in opt.segments if index in seg.moves)


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
    waits = opt.waits_kept(use_waits)
    c_min = opt.shortest_cycle + waits
    c_max = c_min * (1 + span)
    table = opt.table(opt.budget(c_max, use_waits))
    out = []
    for c in np.linspace(c_min, c_max, points):
        d = opt.dp(table, opt.budget(float(c), use_waits) + 1e-9)
        if d is None:
            continue
        a = opt.evaluate(d, waits)
        out.append(
            ParetoPoint(float(c), a.energy_J, a.energy_lab_J, tuple(d[i].duration for i in opt.optimizable))
        )
    return out
