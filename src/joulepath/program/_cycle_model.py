"""The cycle optimizer's settings, its typed results and the energies it sums (issue 46: one module
each seam reads; :mod:`joulepath.program._cycle` orchestrates)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Robot
from joulepath.energy import DEFAULT_MEASURE, energy_measure, measure_power
from joulepath.errors import InvalidInput
from joulepath.optimize import ACCEL_TIME, GRID_SEARCH, GradientSettings, MeasureSummary
from joulepath.program._cell import Cell
from joulepath.program._resolve import CycleSpec
from joulepath.sim import ControllerConfig, PlannedCycle, PlannedMove, Plant
from joulepath.trajectory import Trajectory
from joulepath.units import SAMPLE_PERIOD

STEP = SAMPLE_PERIOD
"""s: optimized durations are whole numbers of 25 ms samples."""


@dataclass(frozen=True, slots=True, kw_only=True)
class CycleSettings:
    """Settings of a cycle optimization.

    ``gradient``: the single-move search's settings, by default
    :data:`joulepath.optimize._gradient.GRID_SEARCH` (the rows on the fine grid, plain SLSQP: on the
    bundled examples the single move's faster default saved less, payload_tool 12.0 % against 12.7 %,
    palletizing 22.0 % against 22.3 %, in about the same CPU time; BENCHMARKS.md).
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
    optimizable moves joined by a zone (a fly-by target) are solved as one chain through
    those targets, at whatever speed saves most; False: only a move that runs from rest
    to rest on its own is optimized (the taught chains are kept). ``zones``: a chain
    passes each fly-by target within its zone (the controller's zone: its radius,
    reduced to half of either move's TCP length), False: exactly. ``max_time_s``: a
    bound on the wall time; when it is reached no further move is solved and the best
    verified allocation of what was solved is returned (taught motion elsewhere).
    ``retime_linear``: a ``MoveL`` that runs from rest to rest on its own is re-timed along
    its line (:func:`joulepath.optimize.retime_on_path`; its speeddata's TCP speed a bound).
    ``follow``: what the controller follows: ``"samples"`` (a streamed trajectory, EGM) or
    ``"via-points"`` (RAPID via points: only the units from rest to rest of joint moves, planned
    within :data:`joulepath.sim._via.RAPID_ACCEL_SHARE` of the acceleration limit, as for a
    single move's ``path.mod``). ``rapid_plan``: with ``"samples"`` and a RAPID program, also
    plan for via points (:attr:`CycleResult.rapid_plan`), the module written where the
    emulation runs the plan itself as the checks ask. ``energy_every``: the gradient search of a
    unit from rest to rest sums its objective on a grid this many times finer than the 25 ms
    samples (a divisor of the ``gradient``'s ``check_factor``; on the samples alone it places power
    peaks between them, and the verified energy, on 2.5 ms, is up to about 0.5 % higher than it
    planned). A shape added to the taught motion keeps the ``gradient``'s own (measured: on the
    bundled examples the finer grid there saved less, e.g. payload_tool 3.8 % against 4.2 %). ``pass_search``:
    solves per inner target, at most, of the search for when a chain passes its targets
    (:func:`~joulepath.program._cycle_passes.tune_passes`; a long chain's probes, on wider knots, stop after
    :data:`LONG_PROBES` per target in a row without a gain; 0: no search, the targets passed in
    proportion to each move's shortest duration).
    ``retime_segments``: with ``"samples"``, every segment with a ``MoveL`` is at last re-timed
    along its own joint path in the chosen cycle (:func:`~joulepath.program._cycle_motion.retime_segments`:
    the lines, blends and zones as they are, the speeddata a bound, the segment's duration kept).
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
    zones: bool = True
    retime_linear: bool = True
    max_time_s: float | None = None
    follow: str = "samples"
    rapid_plan: bool = True
    energy_every: int = 2
    pass_search: int = 8
    retime_segments: bool = True
    gradient: GradientSettings = field(default_factory=lambda: GradientSettings(**GRID_SEARCH))
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    seed: int = 0
    energy: str = DEFAULT_MEASURE

    def __post_init__(self) -> None:
        energy_measure(self.energy)
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
        if self.energy_every < 1 or self.gradient.check_factor % self.energy_every:
            raise InvalidInput(
                f"energy_every must divide the gradient's check_factor ({self.gradient.check_factor}), "
                f"got {self.energy_every}"
            )
        if not 0 <= self.pass_search <= 20:
            raise InvalidInput(f"pass_search must be 0..20 solves per target, got {self.pass_search}")
        if self.follow not in ("samples", "via-points"):
            raise InvalidInput(f"follow must be samples or via-points, got {self.follow!r}")
        if self.max_time_s is not None and not (np.isfinite(self.max_time_s) and self.max_time_s > 0):
            raise InvalidInput(f"max_time_s must be a positive number of seconds, got {self.max_time_s}")


FAST_CYCLE: dict[str, Any] = {"pass_search": 2, "table_points": 3, "retime_segments": False}
""":class:`CycleSettings` for interactive use (``CycleSettings(**FAST_CYCLE)``; issue 36): at most 2 probes
per inner target in the pass-time search, 3 durations per unit in the time table, and no re-timing of
the segments with a ``MoveL`` along their paths. Measured on the bundled examples (one BLAS thread,
CPU s and saving, default -> fast, one run each on the same code): pick_and_place 7.0 -> 2.3 s, 12.19 ->
10.9 %; palletizing 8.4 -> 4.4 s, 22.37 -> 20.3 %; machine_tending 3.1 -> 1.4 s, 12.70 -> 11.2 %;
inspection 3.7 -> 3.8 s, 17.46 % both; approach_depart 2.3 -> 0.7 s, 13.65 -> 12.7 %; payload_tool 2.9
-> 1.7 s, 12.66 -> 12.3 % (BENCHMARKS.md, benchmarks/cycle_examples.py with ``FAST=1``)."""


class TimeBudgetSpent(Exception):
    """Internal: the wall-time bound was reached before a solve (never leaves this module)."""


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
    taught: bool = False  # the taught motion of the unit, as the controller runs it (not re-solved)
    passes: tuple[float, ...] | None = None  # s: when it passes the inner targets (None: waypoints())
    coefficients: FloatArray | None = None  # the gradient search's (flat), a warm start for its neighbours

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
    choice: dict[int, Solved] = field(default_factory=dict)  # by unit: the entry chosen


@dataclass(frozen=True, slots=True)
class Breakdown:
    """Where the saving comes from (J on physics): E0 default, E1 shapes at the default's
    proportions of time, E2 re-allocated durations, E3 with the waits spent, E4 with the segments
    that have a ``MoveL`` re-timed along their path
    (:func:`~joulepath.program._cycle_motion.retime_segments`)."""

    default_J: float
    shape_J: float
    allocation_J: float
    waits_J: float | None
    path_retimed_J: float | None = None

    @property
    def by_shape_pct(self) -> float:
        return 100 * (self.default_J - self.shape_J) / self.default_J

    @property
    def by_allocation_pct(self) -> float:
        return 100 * (self.shape_J - self.allocation_J) / self.default_J

    @property
    def by_waits_pct(self) -> float | None:
        return None if self.waits_J is None else 100 * (self.allocation_J - self.waits_J) / self.default_J

    @property
    def by_path_retiming_pct(self) -> float | None:
        if self.path_retimed_J is None:
            return None
        before = self.allocation_J if self.waits_J is None else self.waits_J
        return 100 * (before - self.path_retimed_J) / self.default_J


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
    planned: Trajectory | None = None  # the whole optimized cycle, 2.5 ms grid
    taught_units: tuple[int, ...] = ()  # first lines of the units kept as taught
    long_units: tuple[int, ...] = ()  # first lines of units longer than the move_s limit, kept as taught
    timed_out: bool = False  # max_time_s was reached before every solve
    zone_miss_mm: float = 0.0  # largest TCP distance beyond a fly-by target's zone (0: within all)
    open_ends: frozenset[int] = frozenset()  # optimized moves whose piece ends blended into a kept move
    rapid_plan: CycleResult | None = None  # the same with the units inside MoveL segments as taught
    path_retimed: tuple[int, ...] = ()  # step indices re-timed along their segment's path (retime_segments)
    unretimed: CycleResult | None = None  # the same plan before that (what RAPID's own moves can follow)
    energy_measure: str = DEFAULT_MEASURE  # the measure of the *_energy_J figures (motion, no standby)
    energies: tuple[MeasureSummary, ...] = ()  # every measure the robot has data for, whole cycle
    energies_unavailable: dict[str, str] = field(default_factory=dict)  # why not, for the others
    optimizable: tuple[int, ...] = ()  # the units reshaped or kept (step index of each one's first move)
    default_planned: Trajectory | None = None  # the taught cycle as the controller runs it, 2.5 ms grid
    pareto: tuple[ParetoPoint, ...] = ()  # energy against cycle time (optimize_cycle's pareto_points)

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


@dataclass(frozen=True, slots=True, eq=False)
class CycleMotion:
    """A cycle's motion (``t`` from 0, strictly increasing, pieces 2.5 ms apart inside), where each
    move starts in it (s, by step index) and its cycle time (s)."""

    trajectory: Trajectory
    starts: dict[int, float]
    cycle_time: float


def sample_power(robot: Robot, plant: Plant, traj: Trajectory, measure: str) -> tuple[FloatArray, FloatArray]:
    """Per-sample power (W) of ``traj``: on the physics model (nominal rigid body with the tool's load
    and NOMINAL_FRICTION, the robot's gears and drives) on ``measure``, standby excluded; and the lab
    plant's logged power ``Σ |drive torque · qd|`` (its ``mechanical`` energy, gears included)."""
    tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
    p = measure_power(measure, tau, traj.qd, robot.drivetrain).value
    lab = plant.joint_torque(traj.q, traj.qd, traj.qdd)
    return p, measure_power(LAB_MEASURE, lab, traj.qd, plant.drivetrain).value


LAB_MEASURE = "mechanical"
"""The lab plant's energies are what its torque log integrates to: its drive torque times speed."""


def trajectory_energy(
    robot: Robot, plant: Plant, traj: Trajectory, measure: str = DEFAULT_MEASURE, *, half_open: bool = False
) -> tuple[float, float]:
    """Physics (on ``measure``) and lab J of ``traj``; ``half_open``: without its last sample (a window
    that the rest of the cycle continues from, so that windows and their surroundings add up)."""
    if half_open:
        k = traj.t.size - 1
        traj = Trajectory(t=traj.t[:k], q=traj.q[:k], qd=traj.qd[:k], qdd=traj.qdd[:k])
    p, p_lab = sample_power(robot, plant, traj, measure)
    return float(p.sum() * traj.dt), float(p_lab.sum() * traj.dt)


@dataclass(frozen=True, slots=True)
class Segment:
    """Moves of the default cycle from rest to rest: the robot stands still before the first
    (at the cycle's start, or after a stop point's dwell or a wait) and after the last."""

    moves: tuple[int, ...]  # step indices, in order
    t0: float  # s, in the default cycle
    t1: float

    @property
    def span(self) -> float:
        return self.t1 - self.t0


def segments(plan: PlannedCycle) -> list[Segment]:
    """The default cycle cut at every stop of the robot (:class:`Segment`)."""
    out: list[Segment] = []
    run: list[PlannedMove] = []
    for m in plan.moves:
        run.append(m)
        if m.stops:
            out.append(Segment(tuple(x.index for x in run), run[0].t0, max(x.t_end for x in run)))
            run = []
    if run:
        out.append(Segment(tuple(x.index for x in run), run[0].t0, max(x.t_end for x in run)))
    return out


def window_energy(robot: Robot, plant: Plant, traj: Trajectory, measure: str) -> tuple[float, float]:
    """Physics (on ``measure``) and lab J of a window of a cycle's motion, summed as
    :func:`~joulepath.program._cycle_motion.move_energies` sums them: each sample's power times the step to
    the next (the last sample's weight 0)."""
    w = np.append(np.diff(traj.t), 0.0)
    p, p_lab = sample_power(robot, plant, traj, measure)
    return float((p * w).sum()), float((p_lab * w).sum())
