"""A taught cycle cut into the units the optimizer reshapes (its layout; nothing is solved here).

The default cycle is cut into rest-to-rest :class:`~joulepath.program._cycle_model.Segment` s. A
segment of ``MoveJ`` / ``MoveAbsJ`` only (each occurring once in the cycle, clear of the cell) is a
*unit*: it is optimized as one move through its targets (within each target's zone, or exactly). A
``MoveL`` from rest to rest is a unit re-timed along its line; in a segment with a ``MoveL``, each run
of joint moves is a unit over its own window (its ends the taught motion's). Every other move runs as
taught; dwells and waits keep their time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from joulepath._typing import FloatArray
from joulepath._work import work_limit
from joulepath.dynamics import Robot
from joulepath.program._cycle_geometry import (
    acceleration_bound,
    acceleration_bound_array,
    clearance_mm,
    jerk_bound,
    joint_zone_box,
    move_robot,
    passes_reachable,
    reduced_zone_mm,
    within_zone,
)
from joulepath.program._cycle_model import STEP, CycleSettings, Segment, segments
from joulepath.program._resolve import CycleSpec
from joulepath.sim import FINE_DT, PlannedCycle, PlannedMove, evaluate_cycle

UnitOf = tuple[tuple[int, ...], Segment, bool]
"""A unit of a segment: its moving members (step indices), its window of the default cycle, and
whether it lies inside a segment with a ``MoveL`` (its ends the taught motion's)."""


class CycleUnits:
    """The units of one planned cycle under one set of settings, and their zone and limit geometry.

    Attributes (by unit, keyed by its first moving move's step index): ``chains`` its members,
    ``span`` its taught duration (s), ``segment_of`` the window of the default cycle it replaces;
    ``within`` the units inside a segment with a ``MoveL``, ``linear`` the ``MoveL`` units;
    ``long_units`` those longer than the ``move_s`` limit (kept as taught); ``optimizable`` the units
    in order, ``kept`` the moves outside them; ``fixed_time`` everything but the units and the waits.
    """

    def __init__(
        self,
        spec: CycleSpec,
        settings: CycleSettings,
        plan: PlannedCycle,
        *,
        progress: Callable[[str], None],
    ) -> None:
        self.spec = spec
        self.settings = settings
        self.plan = plan
        self.progress = progress
        moves = plan.moves
        self.by_index = {m.index: m for m in moves}
        self.default_clearance: dict[int, float] = {}
        if settings.cell is not None:
            self._default_clearance()
        self.segments = segments(plan)
        self.chains: dict[int, tuple[int, ...]] = {}
        self.span: dict[int, float] = {}
        self.segment_of: dict[int, Segment] = {}  # by unit: the window of the default cycle it replaces
        self.within: set[int] = set()  # units inside a segment with MoveL: fixed duration, taught ends
        self.linear: set[int] = set()  # MoveL units: re-timed along their line (retime_on_path)
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
        self.wait_total = float(sum(s for _, _, s in plan.waits))
        self.idle_total = float(sum(s for i, _, s in plan.waits if spec.steps[i].idle))
        # everything but the units and the waits: the rest as taught (blended), dwells
        self.fixed_time = plan.cycle_time - sum(self.span.values()) - self.wait_total

    # ------------------------------------------------------------ the units
    def _units_of(self, seg: Segment) -> list[UnitOf]:
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
        out: list[UnitOf] = []
        run: list[int] = []
        done = seg.t0  # where the last window ends
        for i in [*moving, -1]:
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
        return out

    def _blend_window(
        self, seg: Segment, moving: list[int], first: int, last: int, done: float
    ) -> tuple[float, float]:
        """The window (default-cycle times) of the run of joint moves ``moving[first..last]`` inside
        a segment with a ``MoveL``: over the blends at its ends, from where the controller starts the
        run's first move to where it ends its last, as far as the TCP there is within the zone of
        the target the blend rounds (:func:`~joulepath.program._cycle_geometry.within_zone`); where it
        is not, or the window before (ending at ``done``) reaches into the blend, from the blend's end
        and to its start, as before. Its ends are the controller's states; between them only the
        run's own targets bind, so the blends are reshaped with the run."""
        by = self.by_index
        run0, run1 = by[moving[first]], by[moving[last]]
        if first == 0:
            a = seg.t0
        else:
            prev = by[moving[first - 1]]
            if done <= run0.t0:
                a = within_zone(self.plan, run0.t0, max(run0.t0, prev.t_end), prev, run0, earliest=True)
            else:
                a = max(prev.t_end, done)
        if last + 1 == len(moving):
            b = seg.t1
        else:
            nxt = by[moving[last + 1]]
            b = within_zone(self.plan, min(nxt.t0, run1.t_end), run1.t_end, run1, nxt, earliest=False)
        return a, b

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

    def segment_with(self, index: int) -> Segment:
        """The segment of the default cycle that holds move ``index``."""
        return next(seg for seg in self.segments if index in seg.moves)

    # ------------------------------------------------------------ time
    def waits_kept(self, use_waits: bool) -> float:
        """s of waits the cycle keeps: all, or (``use_waits``) all but the idle ones."""
        return self.wait_total - (self.idle_total if use_waits else 0.0)

    def budget(self, cycle_time: float, use_waits: bool) -> float:
        """s the units may take in a cycle of ``cycle_time``."""
        return cycle_time - self.fixed_time - self.waits_kept(use_waits)

    # ------------------------------------------------------------ limits and the cell
    def robot(self, m: PlannedMove) -> Robot:
        """The robot that runs move ``m``."""
        return move_robot(m)

    def amax(self, robot: Robot) -> FloatArray | None:
        """The optimized moves' acceleration limit (:func:`~._cycle_geometry.acceleration_bound`)."""
        return acceleration_bound(robot, self.settings)

    def amax_array(self, robot: Robot) -> FloatArray:
        """:meth:`amax`, infinite where there is none."""
        return acceleration_bound_array(robot, self.settings)

    def jmax(self, robot: Robot) -> FloatArray | None:
        """The optimized moves' jerk limit (None: none)."""
        return jerk_bound(robot, self.settings)

    def clearance_mm(self, m: PlannedMove, q: FloatArray) -> float:
        """Smallest distance (mm) beyond the margin to the cell along ``q``; negative: too close."""
        assert self.settings.cell is not None
        return clearance_mm(self.settings.cell, m, q)

    def _default_clearance(self) -> None:
        plan = self.plan
        for k, m in enumerate(plan.moves, start=1):
            self.progress(f"clearance of the taught cycle to the cell: move {k}/{len(plan.moves)}")
            if m.profile.duration == 0:
                continue
            t = np.linspace(m.t0, m.t_end, max(2, int(np.ceil(m.profile.duration / FINE_DT)) + 1))
            self.default_clearance[m.index] = self.clearance_mm(m, evaluate_cycle(plan, t).q)

    # ------------------------------------------------------------ zones
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
        return reduced_zone_mm(z, self.by_index[j], self.by_index[members[k + 1]])

    def zone_radius(self, i: int) -> tuple[FloatArray, ...]:
        """Per inner target of chain ``i``, the joint box (rad) that keeps the TCP within
        :meth:`zone_mm` of the target (:func:`~._cycle_geometry.joint_zone_box`)."""
        return tuple(
            joint_zone_box(self.by_index[j].step, self.zone_mm(j) / 1000.0) for j in self.chains[i][:-1]
        )

    def passes_reachable(self, i: int, edges: tuple[int, ...], units: int) -> bool:
        """Whether chain ``i`` can pass its inner targets at samples ``edges`` of ``units``, by a bound
        from kinematics alone (:func:`~._cycle_geometry.passes_reachable`)."""
        if np.any(np.diff((0, *edges, units)) < 2):
            return False
        robot = self.robot(self.by_index[i])
        legs = [(self.by_index[j].path.q0, self.by_index[j].path.q1) for j in self.chains[i]]
        return passes_reachable(
            robot,
            self.amax_array(robot),
            legs,
            self.zone_radius(i),
            edges,
            units,
            rest=i
            not in self.within,  # else its ends are the taught motion's, inside the first and last legs
        )
