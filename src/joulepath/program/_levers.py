"""The controller's own levers: ``AccSet``, the speed data or ``\\T``, and the zones of a RAPID program.

A cell that runs RAPID alone (no PC streaming EGM) can still be made to spend less: the
controller plans every move itself, with settings integrators know and trust. This module
searches them on the one controller model (:func:`joulepath.sim.plan_cycle`, which applies
``AccSet`` and ``VelSet`` as ABB documents them) and writes them into the program as
written, where its statements stand.

* **Levers**, per move statement (a source line; every run of it in the cycle gets the
  same): ``AccSet Acc, Ramp`` (Acc in :data:`ACC_CHOICES`, Ramp in :data:`RAMP_CHOICES`);
  the speed data, from RAPID's predefined ``v``-list within two steps of the taught speed
  (a ``MoveL`` never faster than taught: its speed along the line is often the process'),
  or a ``\\T`` that stretches the move (:data:`T_STRETCH` times its duration, whole ms);
  the zone of a fly-by target, from the predefined ``z``-list up to :data:`ZONE_CAP_MM`
  (or the taught zone, where larger). ``fine`` points stay stop points. A lever is open
  only where the statement can be edited in place: the argument written as a plain name
  (no ``\\V`` / ``\\Z``, not a procedure's parameter), the statement alone on its lines.
* **Search**: coordinate descent with exchanges, bounded by ``max_evaluations`` cycle plans.
  Each lever of each statement in turn: every other value of it is planned, and the one
  that lowers the energy most while the cycle stays within the taught cycle time (+0 s)
  is taken. After a pass where none is, pairs of a change that gains time and one that
  spends it for less energy are ranked by their single effects and the best taken in turn
  where the two planned together keep the cycle time and lower the energy; the search
  stops when neither helps or the plans are spent. A cycle that starts over its time (a module
  written from a plan, :func:`joulepath.program.via_levers`) is first brought into it: each step
  the change that gets it there for the least energy, else the one that buys time cheapest.
* **Energy**: the cycle as the controller emulation runs it (:func:`joulepath.sim.evaluate_cycle`
  on the 2.5 ms grid), on the run's energy measure, with the model the written-program
  check uses (:func:`joulepath.program._output.check_written`): the whole cycle's motion,
  the dynamics of the first move's robot (its tool's load).
* **Writing**: ``AccSet a, r;`` is inserted before a run of adjacent move statements that
  share their settings and the taught ones restored after it (or the ``AccSet`` that stands
  directly before the run changed in place, and restored after); a move's speed argument
  or ``\\T`` and its zone argument are changed in place. Every other byte stays as it was
  (encoding and line ends). The written text is read back with the module reader, checked
  to give the same targets, waits and the levers' settings, and run again through the
  controller emulation: its executed cycle time and energy are what :class:`LeverResult`
  reports. Where it does not read back so, the program is returned as taught.
* **Idle waits** (``use_waits``): the waits marked ``! joulepath: idle`` may be spent on the
  moves; the cycle may then move longer by up to their time, and they are shortened by as
  much (whole ms, rounded down), their seconds argument changed in place.

Not searched: ``VelSet`` (the controller model applies it where a program has one), ``\\V``
and ``\\Z``, and statements inside procedures whose arguments name the speed or zone.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Collection
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Robot
from joulepath.energy import measure_power
from joulepath.errors import InvalidInput
from joulepath.program._model import Module, MotionSetting, Move, WaitTime
from joulepath.program._parse import PREDEFINED_SPEEDS, PREDEFINED_ZONES, _statements, parse_module
from joulepath.program._resolve import CycleSpec, resolve_module
from joulepath.rapid.interpreter import Motion
from joulepath.sim import (
    FINE_DT,
    ControllerConfig,
    PathCache,
    PlannedCycle,
    PlannedMove,
    Plant,
    Step,
    evaluate_cycle,
    make_plant,
    plan_cycle,
    stops_after,
)
from joulepath.trajectory import Trajectory

ACC_CHOICES = (100.0, 70.0, 50.0, 35.0, 25.0)
"""``AccSet Acc`` values searched (% of the controller's acceleration)."""
RAMP_CHOICES = (100.0, 50.0, 25.0)
"""``AccSet Ramp`` values searched (% of the controller's rate of change of acceleration)."""
T_STRETCH = (1.05, 1.1, 1.2, 1.35)
"""``\\T`` searched for a move: its current duration times these (rounded to whole ms)."""
ZONE_CAP_MM = 50.0
"""Largest zone radius offered to a fly-by target whose taught zone is smaller (mm): a larger
zone rounds the corner farther from the taught target."""
SPEED_STEPS = 2
"""Speeds searched: the predefined ``v``-list within this many entries of the taught speed."""
_SPEED_LIST = sorted(
    ((name, data) for name, data in PREDEFINED_SPEEDS.items() if name != "vmax"), key=lambda x: x[1].v_tcp
)
_ZONE_LIST = sorted(
    ((name, data) for name, data in PREDEFINED_ZONES.items() if not data.finep), key=lambda x: x[1].pzone_tcp
)
_TOL_S = 1e-9


@dataclass(frozen=True, slots=True)
class Setting:
    """How one move statement is timed: ``AccSet`` (%), speed data name, ``\\T`` (s), zone name."""

    acc_pct: float
    ramp_pct: float
    speed: str
    time_s: float | None
    zone: str


@dataclass(frozen=True, slots=True)
class MoveLever:
    """One move statement: its line and label, its taught and chosen settings, the levers open to it
    (``acc``, ``speed``, ``zone``) and why the others are not."""

    line: int
    label: str
    taught: Setting
    chosen: Setting
    open: tuple[str, ...]
    closed: tuple[str, ...]

    @property
    def changed(self) -> bool:
        return self.chosen != self.taught


@dataclass(frozen=True, slots=True)
class LeverResult:
    """The levers found for a program and the program written with them, as executed.

    ``default_*``: the taught program run by the controller emulation; ``cycle_s`` and
    ``energy_J``: the written program read back and run by the same emulation (its own
    motion), on ``energy_measure`` (``*_lab_J``: the emulated lab robot's, on the same
    motion); ``searched_*``: what the search planned (the same model, so the same figures
    unless the written text reads back differently:
    ``reads_back`` then says what differs and the program is not written with levers).
    ``waits``: (line, taught s, written s) of each idle wait shortened (``use_waits``).
    """

    source: str
    energy_measure: str
    taught_cycle_s: float
    default_energy_J: float
    cycle_s: float
    energy_J: float
    default_lab_J: float
    energy_lab_J: float
    searched_cycle_s: float
    searched_energy_J: float
    moves: tuple[MoveLever, ...]
    written_text: str
    encoding: str
    reads_back: str | None
    n_evaluations: int
    wall_s: float
    waits: tuple[tuple[int, float, float], ...] = ()
    written_files: tuple[tuple[str, bytes], ...] = ()  # a task's modules (path, bytes); else written_text
    base: str = "taught"
    """What the levers were searched on: ``"taught"`` (the program as written) or ``"via points"`` (the
    plan's via-point module, :func:`joulepath.program.via_levers`; ``default_*`` and ``taught_cycle_s``
    are then still the taught program's)."""

    @property
    def saved_pct(self) -> float:
        """% of the taught program's energy the written program saves, as executed."""
        return 100.0 * (1.0 - self.energy_J / self.default_energy_J) if self.default_energy_J else 0.0

    @property
    def n_changed(self) -> int:
        return sum(m.changed for m in self.moves)

    def written_bytes(self) -> bytes:
        """The written module in the original file's encoding."""
        return self.written_text.encode(self.encoding)


# ---------------------------------------------------------------- the statements as written
@dataclass(frozen=True, slots=True)
class _Written:
    """A move statement's text (its lines, line ends kept) and where its speed and zone arguments are."""

    line: int
    end_line: int
    text: str
    speed_span: tuple[int, int]
    zone_span: tuple[int, int]
    speed_primary: str
    speed_switches: str
    zone_primary: str
    zone_switches: str


def _split_top(text: str, start: int) -> tuple[list[tuple[int, int]], int] | None:
    """Top-level argument spans of a statement's text from ``start`` and the index of its ``;``;
    None where a comment stands inside the statement or it does not end with ``;``."""
    spans: list[tuple[int, int]] = []
    depth, i, a, n = 0, start, start, len(text)
    while i < n:
        ch = text[i]
        if ch == '"':
            j = text.find('"', i + 1)
            if j < 0:
                return None
            i = j + 1
            continue
        if ch == "!":
            return None
        if ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
        elif ch == "," and depth == 0:
            spans.append((a, i))
            a = i + 1
        elif ch == ";" and depth == 0:
            spans.append((a, i))
            return spans, i
        i += 1
    return None


def _written(move: Move, lines: list[str]) -> _Written | str:
    """Where the move's arguments stand in its source lines, or why it cannot be edited in place."""
    text = "".join(lines[move.line - 1 : move.end_line])
    m = re.match(r"\s*([A-Za-z]\w*)", text)
    if m is None or m.group(1).lower() != move.instruction.lower():
        return "another statement stands before it on its line"
    found = _split_top(text, m.end())
    if found is None:
        return "a comment stands inside the statement"
    spans, end = found
    rest = text[end + 1 :]
    if rest.strip() and not rest.strip().startswith("!"):
        return "another statement follows it on its line"
    if len(spans) != 4:
        return "its arguments are not target, speed, zone, tool"

    def parts(span: tuple[int, int]) -> tuple[str, str]:
        arg = text[span[0] : span[1]].strip()
        cut = arg.find("\\")
        return (arg, "") if cut < 0 else (arg[:cut].strip(), arg[cut:].strip())

    sp, ss = parts(spans[1])
    zp, zs = parts(spans[2])
    return _Written(move.line, move.end_line, text, spans[1], spans[2], sp, ss, zp, zs)


# ---------------------------------------------------------------- the levers of a cycle
@dataclass(frozen=True, slots=True)
class _Slot:
    """A move statement in the search: its steps (indices), what it is written as, its open levers."""

    line: int
    label: str
    instruction: str
    linear: bool
    steps: tuple[int, ...]
    written: _Written | None
    taught: Setting
    open: tuple[str, ...]
    closed: tuple[str, ...]


def _key(step: Step) -> tuple[int, str]:
    """A move statement: its line and instruction (two on one line are told apart, and not edited);
    a statement the RAPID interpreter ran (a task of several modules): its source position's."""
    if isinstance(step.statement, Motion):
        m = step.statement
        return (hash((m.pos.file, m.pos.start)) & 0x7FFFFFFF, m.instruction)
    assert isinstance(step.statement, Move)
    return step.line, step.statement.instruction


def _slots(spec: CycleSpec, lines: list[str]) -> list[_Slot]:
    by_key: dict[tuple[int, str], list[int]] = {}
    for i, s in enumerate(spec.steps):
        if s.kind == "move":
            by_key.setdefault(_key(s), []).append(i)
    out: list[_Slot] = []
    for (line, _), idx in by_key.items():
        steps = [spec.steps[i] for i in idx]
        first = steps[0]
        move = first.statement
        assert isinstance(move, Move)
        written = _written(move, lines)
        closed: list[str] = []
        open_: list[str] = []
        if isinstance(written, str):
            closed = [f"acc, speed, zone: {written}"]
            written_ok = None
        else:
            written_ok = written
            if len({(s.acc_pct, s.ramp_pct) for s in steps}) == 1:
                open_.append("acc")
            else:
                closed.append("acc: its runs start under different AccSet")
            same_speed = all(
                isinstance(s.statement, Move) and s.statement.speed.lower() == written.speed_primary.lower()
                for s in steps
            )
            if not same_speed or move.v_tcp is not None:
                closed.append("speed: written as a parameter or with \\V")
            elif written.speed_switches and not re.fullmatch(r"\\\s*T\s*:=.*", written.speed_switches, re.S):
                closed.append("speed: other optional arguments")
            else:
                open_.append("speed")
            same_zone = all(
                isinstance(s.statement, Move) and s.statement.zone.lower() == written.zone_primary.lower()
                for s in steps
            )
            if first.zone_mm is None:
                closed.append("zone: a stop point (fine) stays one")
            elif any(stops_after(spec, i) for i in idx):
                closed.append("zone: the robot stops there (a wait or the cycle's end follows)")
            elif not same_zone or written.zone_switches:
                closed.append("zone: written as a parameter or with \\Z")
            else:
                open_.append("zone")
        taught = Setting(first.acc_pct, first.ramp_pct, move.speed, move.time_s, move.zone)
        out.append(
            _Slot(
                line,
                first.label,
                move.instruction,
                first.linear,
                tuple(idx),
                written_ok,
                taught,
                tuple(open_),
                tuple(closed),
            )
        )
    return out


def _idle_waits(spec: CycleSpec, lines: list[str]) -> dict[int, tuple[float, int, tuple[int, int], str]]:
    """Idle waits whose time may be spent on the moves, by line: (seconds, runs in the cycle, the span
    of the seconds argument in the statement's text, that text); only those alone on their lines."""
    out: dict[int, tuple[float, int, tuple[int, int], str]] = {}
    for st in spec.steps:
        if st.kind != "wait" or not st.idle or not isinstance(st.statement, WaitTime):
            continue
        if st.line in out:
            sec, n, span, text = out[st.line]
            out[st.line] = (sec, n + 1, span, text)
            continue
        w = st.statement
        text = "".join(lines[w.line - 1 : w.end_line])
        m = re.match(r"\s*WaitTime\b", text, re.IGNORECASE)
        found = None if m is None else _split_top(text, m.end())
        if found is None or (
            text[found[1] + 1 :].strip() and not text[found[1] + 1 :].strip().startswith("!")
        ):
            continue
        out[st.line] = (st.seconds, 1, found[0][-1], text)
    return out


def _speed_options(slot: _Slot, spec: CycleSpec) -> list[str]:
    speed = spec.steps[slot.steps[0]].speed
    assert speed is not None
    k = min(range(len(_SPEED_LIST)), key=lambda j: abs(_SPEED_LIST[j][1].v_tcp - speed.v_tcp))
    out = []
    for name, data in _SPEED_LIST[max(0, k - SPEED_STEPS) : k + SPEED_STEPS + 1]:
        if slot.linear and data.v_tcp > speed.v_tcp:
            continue
        out.append(name)
    return out


def _zone_options(slot: _Slot, spec: CycleSpec) -> list[str]:
    taught = spec.steps[slot.steps[0]].zone_mm
    assert taught is not None
    cap = max(ZONE_CAP_MM, taught)
    return [name for name, data in _ZONE_LIST if data.pzone_tcp <= cap]


# ---------------------------------------------------------------- evaluation
class _Evaluator:
    """The cycle with settings, as the controller emulation runs it: its plan, time and energy."""

    def __init__(
        self,
        spec: CycleSpec,
        slots: list[_Slot],
        measure: str,
        config: ControllerConfig,
        *,
        by_runs: bool = False,
    ) -> None:
        self.spec = spec
        self.slots = slots
        self.measure = measure
        self.config = config
        self.paths = PathCache()
        self.n = 0
        self.memo: dict[tuple[Setting, ...], tuple[PlannedCycle, float, float]] = {}
        self._plant: Plant | None = None
        self.runs = RunEnergy(measure) if by_runs else None

    def spec_with(self, state: tuple[Setting, ...]) -> CycleSpec:
        steps = list(self.spec.steps)
        for slot, setting in zip(self.slots, state, strict=True):
            if setting == slot.taught:
                continue
            for i in slot.steps:
                steps[i] = _apply(steps[i], setting, slot.taught)
        return replace(self.spec, steps=tuple(steps))

    deadline: float | None = None
    """``time.perf_counter()`` past which no new plan counts as within the budget: the search stops
    at its next check (``n`` is set past any ``max_evaluations``)."""

    def __call__(self, state: tuple[Setting, ...]) -> tuple[PlannedCycle, float, float]:
        found = self.memo.get(state)
        if found is None:
            self.n += 1
            found = self.memo[state] = self.run(self.spec_with(state))
            if self.deadline is not None and time.perf_counter() > self.deadline:
                self.n = max(self.n, 1 << 40)
        return found

    def run(self, spec: CycleSpec) -> tuple[PlannedCycle, float, float]:
        plan = plan_cycle(spec, self.config, paths=self.paths)
        return plan, plan.cycle_time, self.energy(plan)

    def energy(self, plan: PlannedCycle) -> float:
        """The physics energy of :func:`joulepath.program._output.check_written` (without the lab's); with
        ``by_runs`` (a search that plans the cycle many times), as :class:`RunEnergy` sums it: each run
        of moves between stops on its own grid, found once."""
        return self.whole_energy(plan) if self.runs is None else self.runs(plan)

    def whole_energy(self, plan: PlannedCycle) -> float:
        """The physics energy on the cycle's one 2.5 ms grid, as the written-program check takes it."""
        traj = cycle_motion(plan)
        robot = plan.moves[0].step.robot
        assert robot is not None
        tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
        return float(measure_power(self.measure, tau, traj.qd, robot.drivetrain).value.sum() * traj.dt)

    def energies(self, plan: PlannedCycle) -> tuple[float, float]:
        """Physics and lab J of the cycle, as the written-program check computes them."""
        from joulepath.program._cycle_model import trajectory_energy

        robot = plan.moves[0].step.robot
        assert robot is not None
        if self._plant is None:
            self._plant = make_plant("lab", robot)
        return trajectory_energy(robot, self._plant, cycle_motion(plan), self.measure)


class RunEnergy:
    """A cycle's energy as the sum of its runs: the moves between two stops (a fine point, a wait),
    each sampled on its own 2.5 ms grid from its first move's start and found once per run (its
    moves' paths, profiles and times in it, and where it starts), and the rests between them at the
    power of holding the arm still there.

    A lever changes the runs it touches; the others keep their energy. The sum is the cycle's energy
    on the one grid of :func:`cycle_motion` but for where the samples fall (each run's grid starts
    at its own start): the two differ by the sampling alone (a test bounds it)."""

    def __init__(self, measure: str) -> None:
        self.measure = measure
        self._runs: dict[tuple[object, ...], float] = {}
        self._rests: dict[tuple[int, bytes], float] = {}

    def __call__(self, plan: PlannedCycle) -> float:
        total, t_free, q_rest = 0.0, 0.0, plan.start
        robot = plan.moves[0].step.robot
        for run in _runs(plan):
            robot = run[0].step.robot
            total += self.rest_power(robot, q_rest) * max(run[0].t0 - t_free, 0.0)
            total += self.run(run, q_rest)
            t_free = max(m.t_end for m in run)
            q_rest = run[-1].path.q1
        return total + self.rest_power(robot, q_rest) * max(plan.cycle_time - t_free, 0.0)

    def run(self, run: tuple[PlannedMove, ...], q0: FloatArray) -> float:
        ta = run[0].t0
        key = (q0.tobytes(), *((m.path, m.profile, round(m.t0 - ta, 12), id(m.step.robot)) for m in run))
        found = self._runs.get(key)
        if found is None:
            span = max(m.t_end for m in run) - ta
            n = max(2, int(np.ceil(span / FINE_DT)) + 1)
            moves = tuple(replace(m, t0=m.t0 - ta) for m in run)
            traj = evaluate_cycle(PlannedCycle(moves, (), span, q0), np.linspace(0.0, span, n))
            robot = run[0].step.robot
            assert robot is not None
            tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
            power = measure_power(self.measure, tau, traj.qd, robot.drivetrain).value
            h = span / (n - 1)  # the trapezoid: the run's first and last samples are at its rests' ends
            found = self._runs[key] = float((power.sum() - 0.5 * (power[0] + power[-1])) * h)
        return found

    def rest_power(self, robot: Robot | None, q: FloatArray) -> float:
        """W of holding the arm still at ``q`` (0 on the mechanical measures)."""
        assert robot is not None
        key = (id(robot), q.tobytes())
        found = self._rests.get(key)
        if found is None:
            z = np.zeros((1, q.size))
            tau = robot.inverse_dynamics(q[None], z, z, friction=NOMINAL_FRICTION)
            found = self._rests[key] = float(measure_power(self.measure, tau, z, robot.drivetrain).value[0])
        return found


def _runs(plan: PlannedCycle) -> list[tuple[PlannedMove, ...]]:
    """The plan's moves in runs, each ending at a move that stops (or the last); a run that the next
    overlaps (it would not, after a stop) is joined to it."""
    runs: list[list[PlannedMove]] = []
    cur: list[PlannedMove] = []
    for m in plan.moves:
        if not cur and runs and m.t0 < max(x.t_end for x in runs[-1]) - 1e-12:
            cur = runs.pop()
        cur.append(m)
        if m.stops:
            runs.append(cur)
            cur = []
    if cur:
        runs.append(cur)
    return [tuple(r) for r in runs]


def cycle_motion(plan: PlannedCycle) -> Trajectory:
    """The cycle's commanded motion on the 2.5 ms grid, its last sample at its end (as checked)."""
    n = int(np.ceil(plan.cycle_time / FINE_DT)) + 1
    return evaluate_cycle(plan, np.linspace(0.0, plan.cycle_time, n))


def _apply(step: Step, setting: Setting, taught: Setting) -> Step:
    speed = step.speed
    if setting.speed != taught.speed:
        speed = PREDEFINED_SPEEDS[setting.speed.lower()]
    zone_mm = step.zone_mm
    if setting.zone != taught.zone:
        zone_mm = PREDEFINED_ZONES[setting.zone.lower()].pzone_tcp
    return replace(
        step,
        acc_pct=setting.acc_pct,
        ramp_pct=setting.ramp_pct,
        speed=speed,
        time_s=setting.time_s,
        zone_mm=zone_mm,
    )


def _durations(plan: PlannedCycle) -> dict[tuple[int, str], float]:
    out: dict[tuple[int, str], float] = {}
    for m in plan.moves:
        out.setdefault(_key(m.step), m.profile.duration)
    return out


def _options(
    state: tuple[Setting, ...], k: int, kind: str, slot: _Slot, spec: CycleSpec, duration: float
) -> list[Setting]:
    """The settings of slot ``k`` that change lever ``kind`` of ``state[k]`` (``duration``: its move's, s)."""
    s = state[k]
    out: list[Setting] = []
    if kind == "acc":
        out = [replace(s, acc_pct=acc) for acc in ACC_CHOICES]
    elif kind == "ramp":
        out = [replace(s, ramp_pct=ramp) for ramp in RAMP_CHOICES]
    elif kind == "speed":
        if slot.taught.time_s is None:
            out = [replace(s, speed=name, time_s=None) for name in _speed_options(slot, spec)]
        else:
            out = [replace(s, time_s=slot.taught.time_s)]
        if duration > 0.0:
            out += [replace(s, time_s=round(duration * f, 3)) for f in T_STRETCH]
    elif kind == "zone":
        out = [replace(s, zone=name) for name in _zone_options(slot, spec)]
    return [o for o in out if o != s]


def _kinds(slot: _Slot) -> tuple[str, ...]:
    return (("acc", "ramp") if "acc" in slot.open else ()) + tuple(
        k for k in ("speed", "zone") if k in slot.open
    )


_FIELDS = {"acc": ("acc_pct",), "ramp": ("ramp_pct",), "speed": ("speed", "time_s"), "zone": ("zone",)}


def _combine(base: Setting, other: Setting, kind: str) -> Setting:
    """``base`` with the fields of lever ``kind`` taken from ``other``."""
    return replace(base, **{f: getattr(other, f) for f in _FIELDS[kind]})


def _with(state: tuple[Setting, ...], k: int, setting: Setting) -> tuple[Setting, ...]:
    return (*state[:k], setting, *state[k + 1 :])


Tried = tuple[tuple[int, str], Setting, float, float]
"""A single change tried: (slot, lever), the slot's new setting, its change of cycle time and energy."""


Bound = Callable[[PlannedCycle], tuple[float, float]]
"""A bound of the caller's on a cycle's motion: how far its plan is past it (0 or less: within) and when
in the cycle (s) it is farthest past (or nearest to it)."""


def _near(plan: PlannedCycle, at_s: float) -> set[int]:
    """The steps of the moves that run at ``at_s`` in ``plan``, and of the move before and after each."""
    runs = [i for i, m in enumerate(plan.moves) if m.t0 - _TOL_S <= at_s <= m.t_end + _TOL_S]
    ends = {j for i in runs for j in (i - 1, i, i + 1) if 0 <= j < len(plan.moves)}
    return {plan.moves[j].index for j in ends}


def _search(
    ev: _Evaluator,
    slots: list[_Slot],
    target_s: float,
    max_evaluations: int,
    pairs: int,
    bound: Bound | None = None,
) -> tuple[Setting, ...]:
    """Coordinate descent with exchanges (module docstring), within ``max_evaluations`` plans.

    With ``bound``, a change is taken only where its plan is within the bound (asked only of changes
    that would be taken, once per setting); a start past it is first brought within, by the levers of
    the statements that run where it is farthest past (each step the change that gets it within the
    time for the least energy, else in the least time, else the one that comes nearest), then into
    the time."""
    return _Descent(ev, slots, target_s, max_evaluations, pairs, bound).run()


class _Descent:
    """One lever search (:func:`_search`): the settings it stands at, their plan, time and energy,
    and its phases: within the caller's bound, into the cycle time, then down in energy."""

    def __init__(
        self,
        ev: _Evaluator,
        slots: list[_Slot],
        target_s: float,
        max_evaluations: int,
        pairs: int,
        bound: Bound | None,
    ) -> None:
        self.ev, self.slots, self.target_s = ev, slots, target_s
        self.max_evaluations, self.pairs, self.bound = max_evaluations, pairs, bound
        self.past: dict[tuple[Setting, ...], tuple[float, float]] = {}
        self.take(tuple(s.taught for s in slots))

    def take(self, state: tuple[Setting, ...]) -> None:
        self.state = state
        self.plan, self.t, self.e = self.ev(state)

    def over(self, trial: tuple[Setting, ...]) -> tuple[float, float]:
        if self.bound is None:
            return (0.0, 0.0)
        if trial not in self.past:
            self.past[trial] = self.bound(self.ev(trial)[0])
        return self.past[trial]

    def ok(self, trial: tuple[Setting, ...]) -> bool:
        return self.over(trial)[0] <= 0.0

    def spent(self) -> bool:
        return self.ev.n >= self.max_evaluations

    def options(self, k: int, slot: _Slot, kind: str) -> list[Setting]:
        duration = _durations(self.plan).get((slot.line, slot.instruction), 0.0)
        return _options(self.state, k, kind, slot, self.ev.spec, duration)

    def run(self) -> tuple[Setting, ...]:
        while not self.ok(self.state) and not self.spent():  # past the caller's bound: first within it
            if not self.into_bound():
                break
        while self.t > self.target_s + _TOL_S and not self.spent():  # over the cycle time (a module
            # written from a plan): first into it
            if not self.into_time():
                break
        while not self.spent():
            improved, tried = self.sweep()
            if improved:
                continue
            if not self.exchange(tried):
                break
        return self.state

    def into_bound(self) -> bool:
        """One step toward the bound, by the levers of the statements that run where the plan is
        farthest past it; False where no change helps."""
        ev, target_s = self.ev, self.target_s
        x_now, at_s = self.over(self.state)
        near = _near(self.plan, at_s)
        steps: list[tuple[tuple[int, float], tuple[Setting, ...]]] = []
        for k, slot in enumerate(self.slots):
            if near.isdisjoint(slot.steps):
                continue
            for kind in _kinds(slot):
                for option in self.options(k, slot, kind):
                    trial = _with(self.state, k, option)
                    if self.spent() and trial not in ev.memo:
                        break
                    _, t_new, e_new = ev(trial)
                    x = self.over(trial)[0]
                    if x <= 0.0:
                        steps.append(((0, e_new) if t_new <= target_s + _TOL_S else (1, t_new), trial))
                    elif x < x_now and t_new <= max(self.t, target_s) + _TOL_S:
                        steps.append(((2, x), trial))
        if not steps:
            return False
        self.take(min(steps, key=lambda r: r[0])[1])
        return True

    def into_time(self) -> bool:
        """One step into the cycle time: the change that gets there for the least energy, else the
        one that buys time cheapest (energy per second); False where none does."""
        ev, target_s = self.ev, self.target_s
        into: tuple[float, tuple[Setting, ...]] | None = None
        cheap: tuple[float, tuple[Setting, ...]] | None = None
        for k, slot in enumerate(self.slots):
            for kind in _kinds(slot):
                for option in self.options(k, slot, kind):
                    trial = _with(self.state, k, option)
                    _, t_new, e_new = ev(trial)
                    if t_new <= target_s + _TOL_S and (into is None or e_new < into[0]):
                        if self.ok(trial):
                            into = (e_new, trial)
                    elif t_new < self.t - 1e-6:
                        rate = (e_new - self.e) / (self.t - t_new)
                        if (cheap is None or rate < cheap[0]) and self.ok(trial):
                            cheap = (rate, trial)
        step = into or cheap
        if step is None:
            return False
        self.take(step[1])
        return True

    def better(self, t_new: float, e_new: float, best: tuple[float, object] | None) -> bool:
        """Within the cycle time, less energy than now, and than ``best``."""
        return (
            t_new <= self.target_s + _TOL_S
            and e_new < self.e * (1.0 - 1e-9)
            and (best is None or e_new < best[0])
        )

    def sweep(self) -> tuple[bool, list[Tried]]:
        """Each slot's each lever in turn, the best single change taken; whether one was, and every
        change tried with its effect from the settings it was tried on."""
        ev = self.ev
        improved = False
        tried: list[Tried] = []
        for k, slot in enumerate(self.slots):
            for kind in _kinds(slot):
                best: tuple[float, Setting] | None = None
                for option in self.options(k, slot, kind):
                    if self.spent() and _with(self.state, k, option) not in ev.memo:
                        break
                    _, t_new, e_new = ev(_with(self.state, k, option))
                    tried.append(((k, kind), option, t_new - self.t, e_new - self.e))
                    if self.better(t_new, e_new, best) and self.ok(_with(self.state, k, option)):
                        best = (e_new, option)
                if best is not None:
                    self.take(_with(self.state, k, best[1]))
                    improved = True
        return improved, tried

    def exchange(self, tried: list[Tried]) -> bool:
        """No single change helps (every change tried from this state): exchange time between two
        levers; whether an exchange was taken."""
        slack = self.target_s - self.t
        gain = [x for x in tried if x[2] < 0.0]
        spend = [x for x in tried if x[3] < 0.0 and x[2] > slack]
        ranked = sorted(
            (
                (g[3] + s[3], g, s)
                for g in gain
                for s in spend
                if g[0] != s[0] and g[2] + s[2] <= slack and g[3] + s[3] < 0.0
            ),
            key=lambda x: x[0],
        )
        # the pairs in turn, each on the settings as the pairs taken so far left them; a slot's lever
        # is changed once per exchange step (the effects measured from ``state`` hold for it alone)
        used: set[tuple[int, str]] = set()
        taken = False
        for _, g, s in ranked[: self.pairs * 4]:
            if self.spent():
                break
            if g[0] in used or s[0] in used:
                continue
            (kg, kind_g), (ks, kind_s) = g[0], s[0]
            both = _with(self.state, kg, _combine(self.state[kg], g[1], kind_g))
            both = _with(both, ks, _combine(both[ks], s[1], kind_s))
            _, t_new, e_new = self.ev(both)
            if self.better(t_new, e_new, None) and self.ok(both):
                self.take(both)
                used |= {g[0], s[0]}
                taken = True
        return taken


# ---------------------------------------------------------------- writing
def _num(value: float) -> str:
    text = f"{value:.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _line_end(line: str) -> str:
    return line[len(line.rstrip("\r\n")) :]


def _blank(line: str) -> bool:
    stripped = line.strip()
    return not stripped or stripped.startswith("!")


def _edit_move(w: _Written, taught: Setting, chosen: Setting) -> str:
    text = w.text
    edits: list[tuple[tuple[int, int], str]] = []
    if (chosen.speed, chosen.time_s) != (taught.speed, taught.time_s):
        new = chosen.speed + ("" if chosen.time_s is None else f" \\T:={_num(chosen.time_s)}")
        edits.append((w.speed_span, new))
    if chosen.zone != taught.zone:
        edits.append((w.zone_span, chosen.zone))
    for (a, b), new in sorted(edits, reverse=True):
        arg = text[a:b]
        lead = arg[: len(arg) - len(arg.lstrip())]
        trail = arg[len(arg.rstrip()) :]
        text = text[:a] + lead + new + trail + text[b:]
    return text


def write_levers(
    module: Module,
    text: str,
    slots: list[_Slot],
    chosen: tuple[Setting, ...],
    waits: dict[int, tuple[tuple[int, int], str, float]] | None = None,
) -> tuple[str, dict[int, int]]:
    """``text`` (the module's source) with the chosen settings written in place (and the idle waits
    ``waits``: line -> (span of the seconds, statement text, new seconds)), and where each original
    line stands in it (1-based, old -> new)."""
    lines = text.splitlines(keepends=True)
    if tuple(text.splitlines()) != module.source:
        raise InvalidInput(f"{module.path}: the text given is not the module's source; give the file as read")
    default_end = next((_line_end(ln) for ln in lines if _line_end(ln)), "\n")
    replace_at: dict[int, tuple[int, str]] = {}  # first line -> (last line, new text)
    before: dict[int, list[str]] = {}
    after: dict[int, list[str]] = {}
    settings = {
        s.line: s
        for p in module.procedures
        for s in _statements(p.body)
        if isinstance(s, MotionSetting) and s.text == "AccSet"
    }
    changed = [(slot, c) for slot, c in zip(slots, chosen, strict=True) if c != slot.taught]
    for slot, c in changed:
        assert slot.written is not None
        if (c.speed, c.time_s, c.zone) != (slot.taught.speed, slot.taught.time_s, slot.taught.zone):
            replace_at[slot.line] = (slot.written.end_line, _edit_move(slot.written, slot.taught, c))
    for line, (span, wtext, seconds) in (waits or {}).items():
        arg = wtext[span[0] : span[1]]
        lead, trail = arg[: len(arg) - len(arg.lstrip())], arg[len(arg.rstrip()) :]
        replace_at[line] = (
            line + wtext.count("\n") - (1 if wtext.endswith("\n") else 0),
            wtext[: span[0]] + lead + _num(seconds) + trail + wtext[span[1] :],
        )
    # AccSet: runs of adjacent moves with the same new and taught settings
    acc = sorted(
        (
            (slot, c)
            for slot, c in changed
            if (c.acc_pct, c.ramp_pct) != (slot.taught.acc_pct, slot.taught.ramp_pct)
        ),
        key=lambda x: x[0].line,
    )
    runs: list[list[tuple[_Slot, Setting]]] = []
    for slot, c in acc:
        if runs:
            prev, pc = runs[-1][-1]
            assert prev.written is not None
            between = lines[prev.written.end_line : slot.line - 1]
            same = (pc.acc_pct, pc.ramp_pct, prev.taught.acc_pct, prev.taught.ramp_pct) == (
                c.acc_pct,
                c.ramp_pct,
                slot.taught.acc_pct,
                slot.taught.ramp_pct,
            )
            if same and all(_blank(ln) for ln in between):
                runs[-1].append((slot, c))
                continue
        runs.append([(slot, c)])
    for n_run, run in enumerate(runs):
        first, c = run[0]
        last = run[-1][0]
        assert last.written is not None
        head = lines[first.line - 1]
        indent = head[: len(head) - len(head.lstrip())]
        end = _line_end(head) or default_end
        new = f"AccSet {_num(c.acc_pct)}, {_num(c.ramp_pct)};"
        restore = f"{indent}AccSet {_num(first.taught.acc_pct)}, {_num(first.taught.ramp_pct)};{end}"
        k = first.line - 1  # the statement directly before the run (blank and comment lines between)
        while k >= 1 and _blank(lines[k - 1]):
            k -= 1
        existing = next((s for s in settings.values() if s.end_line == k and s.line == k), None)
        if existing is not None and re.fullmatch(
            r"\s*AccSet\b[^;!]*;\s*", lines[k - 1].rstrip("\r\n") + "\n"
        ):
            old = lines[k - 1]
            lead = old[: len(old) - len(old.lstrip())]
            replace_at[k] = (k, f"{lead}{new}{_line_end(old) or default_end}")
        else:
            before.setdefault(first.line, []).append(f"{indent}{new}{end}")
        nxt = runs[n_run + 1][0][0] if n_run + 1 < len(runs) else None
        if (
            nxt is None
            or (nxt.taught.acc_pct, nxt.taught.ramp_pct) != (first.taught.acc_pct, first.taught.ramp_pct)
            or not all(_blank(ln) for ln in lines[last.written.end_line : nxt.line - 1])
        ):  # restored unless the next run starts right after with its own AccSet
            after.setdefault(last.written.end_line, []).append(restore)
    out: list[str] = []
    where: dict[int, int] = {}
    at = 1  # the line of the written text that comes next

    def put(piece: str) -> None:
        nonlocal at
        out.append(piece)
        at += piece.count("\n")

    i = 1
    while i <= len(lines):
        for extra in before.get(i, []):
            put(extra)
        where[i] = at
        last_line, new_text = replace_at.get(i, (i, lines[i - 1]))
        for j in range(i + 1, last_line + 1):  # lines of a statement edited in place
            where[j] = at + (j - i)
        if after.get(last_line) and not _line_end(new_text):
            new_text += default_end
        put(new_text)
        for extra in after.get(last_line, []):
            put(extra)
        i = last_line + 1
    return "".join(out), where


def _reads_back(
    spec: CycleSpec,
    again: CycleSpec,
    slots: list[_Slot],
    chosen: tuple[Setting, ...],
    where: dict[int, int],
    waits: dict[int, float],
) -> str | None:
    """None when the written module's cycle has the same targets and waits with the chosen settings."""
    want = [s for s in spec.steps if s.kind in ("move", "wait")]
    got = [s for s in again.steps if s.kind in ("move", "wait")]
    if len(want) != len(got):
        return f"{len(got)} moves and waits, not {len(want)}"
    by_key = {(slot.line, slot.instruction): c for slot, c in zip(slots, chosen, strict=True)}
    for a, b in zip(want, got, strict=True):
        if a.kind != b.kind or where.get(a.line) != b.line:
            return f"line {a.line}: {a.label} reads back as {b.label} at line {b.line}"
        if a.kind == "wait":
            if waits.get(a.line, a.seconds) != b.seconds:
                return f"line {a.line}: the wait reads back as {b.seconds} s"
            continue
        assert a.q is not None and b.q is not None
        if not np.allclose(a.q, b.q, rtol=0.0, atol=1e-9):
            return f"line {a.line}: the target reads back elsewhere"
        c = by_key[_key(a)]
        speed = (
            a.speed if c.speed.lower() == a.statement.speed.lower() else PREDEFINED_SPEEDS[c.speed.lower()]
        )
        zone = (
            a.zone_mm
            if c.zone.lower() == a.statement.zone.lower()
            else PREDEFINED_ZONES[c.zone.lower()].pzone_tcp
        )
        have = (b.acc_pct, b.ramp_pct, b.speed, b.time_s, b.zone_mm, b.vel_override_pct, b.vel_max_mm_s)
        if have != (c.acc_pct, c.ramp_pct, speed, c.time_s, zone, a.vel_override_pct, a.vel_max_mm_s):
            return f"line {a.line}: {a.label} reads back with other settings {have}"
    return None


def _source_text(spec: CycleSpec) -> tuple[str, str]:
    module = spec.module
    assert module is not None
    p = Path(module.path)
    if not p.is_file():
        raise InvalidInput(
            f"{module.path}: the module's file cannot be read again; give its text (text=...) to write "
            "the levers"
        )
    raw = p.read_bytes()
    try:  # a byte-order mark (as Windows editors save) is read, and written back, as it was
        encoding = "utf-8-sig" if raw.startswith(b"\xef\xbb\xbf") else "utf-8"
        return raw.decode(encoding), encoding
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "latin-1"


def _only(slots: list[_Slot], lines: set[int]) -> list[_Slot]:
    """The slots on ``lines`` open, the others kept as written."""
    closed = ("acc, speed, zone: kept as written",)
    return [s if s.line in lines else replace(s, open=(), closed=closed) for s in slots]


def _spend_idle(
    idle: dict[int, tuple[float, int, tuple[int, int], str]], idle_s: float, t_search: float, target: float
) -> tuple[dict[int, float], float]:
    """The idle waits shortened by what the moves spend past ``target`` (in whole ms, down), and the
    cycle time with them."""
    spent = max(0.0, t_search - target)
    if not (spent > 0.0 and idle_s > 0.0):
        return {}, t_search
    keep = 1.0 - spent / idle_s
    new_waits = {
        line: float(np.floor(sec * keep * 1000.0 + 1e-9) / 1000.0) for line, (sec, _, _, _) in idle.items()
    }
    t_search -= sum(n * (sec - new_waits[line]) for line, (sec, n, _, _) in idle.items())
    return new_waits, t_search


def _run_written(
    ev: _Evaluator,
    robot: Robot,
    written: str,
    where: dict[int, int],
    chosen: tuple[Setting, ...],
    new_waits: dict[int, float],
    target: float,
    taught: tuple[float, float],
) -> tuple[str | None, tuple[float, float, float] | None]:
    """The written module read again and run on the controller emulation: why it does not read back
    as searched or runs past the time or the taught energy (None: it does), and its cycle time,
    energy and lab energy."""
    spec = ev.spec
    assert spec.module is not None
    try:
        again = resolve_module(
            parse_module(written, path=f"{spec.module.path} (levers)"),
            robot,
            idle_waits=[where[s.line] for s in spec.steps if s.kind == "wait" and s.idle],
        )
        differs = _reads_back(spec, again, ev.slots, chosen, where, new_waits)
    except InvalidInput as err:
        return f"it cannot be read: {err}", None
    if differs is not None:
        return differs, None
    plan_x, t_exec, _ = ev.run(again)
    e_exec, lab_exec = ev.energies(plan_x)
    t0, e0 = taught
    if t_exec > target + _TOL_S or e_exec > (e0 if t0 <= target + _TOL_S else np.inf):
        return f"run again it takes {t_exec:.3f} s and {e_exec:.3f} J", (t_exec, e_exec, lab_exec)
    return None, (t_exec, e_exec, lab_exec)


def _module_text(spec: CycleSpec, text: str | None, encoding: str, max_evaluations: int) -> tuple[str, str]:
    """The module's source and the encoding to write it in (:func:`levers_module`'s ``text``)."""
    if spec.module is None:
        raise InvalidInput(
            f"{spec.source}: the controller's levers are written into a RAPID module; give a .mod file"
        )
    if max_evaluations < 1:
        raise InvalidInput(f"max_evaluations must be at least 1, got {max_evaluations}")
    if text is None:
        text, encoding = _source_text(spec)
    if tuple(text.splitlines()) != spec.module.source:
        raise InvalidInput(
            f"{spec.module.path}: the text given is not the module's source; give the file's text as read"
        )
    return text, encoding


def levers_module(
    spec: CycleSpec,
    robot: Robot,
    *,
    energy: str,
    cycle_time_s: float | None = None,
    text: str | None = None,
    encoding: str = "utf-8",
    max_evaluations: int = 1500,
    pairs: int = 8,
    use_waits: bool = False,
    config: ControllerConfig | None = None,
    max_seconds: float | None = None,
    baseline: tuple[float, float, float] | None = None,
    only_lines: Collection[int] | None = None,
    bound: Bound | None = None,
) -> LeverResult:
    """Search the controller's levers of a RAPID program's cycle and write them into its text.

    Parameters
    ----------
    spec : CycleSpec
        The cycle (:func:`joulepath.program.read_cycle_program` of a RAPID module).
    robot : Robot
        The robot the module is read on (its targets are solved again on it).
    energy : str
        The energy measure (:data:`joulepath.energy.MEASURES`) minimised.
    cycle_time_s : float, optional
        The cycle time to keep (s); never more than the taught cycle's (default: the taught).
    text : str, optional
        The module's source as read (default: the file ``spec.module.path``, UTF-8 or Latin-1);
        ``encoding`` is then the encoding :meth:`LeverResult.written_bytes` writes.
    max_evaluations : int
        Most cycle plans the search makes (each a plan and its energy: milliseconds per move).
    pairs : int
        Exchanges planned per round when no single change helps.
    use_waits : bool
        Spend the waits declared idle (``! joulepath: idle``) on the moves: the cycle may move
        longer by up to their time, and they are shortened by as much (in whole ms, down),
        their argument changed in place.
    config : ControllerConfig, optional
        The emulated controller (default: :class:`joulepath.sim.ControllerConfig`).
    max_seconds : float, optional
        Wall time (s) after which the search takes no new step (what it found by then is written).
    baseline : (cycle s, energy J, lab J), optional
        The program this module replaces, as the controller emulation runs it (the taught one, where
        ``spec`` is a rewrite of it): the cycle may run up to its cycle time (also where the module
        itself runs shorter; where it runs longer, the search first brings it in, and where it cannot,
        the result runs longer than ``taught_cycle_s``, for the caller to refuse), and the result's
        ``taught_cycle_s`` and ``default_*`` are its.
    only_lines : collection of int, optional
        Only the move statements on these lines get levers; the others stay as written.
    bound : callable, optional
        A bound of the caller's on the motion (for example, a corridor around the taught path):
        :data:`Bound`. The search takes a change only where the plan with it is within; a module that
        starts past it is first brought within where its levers can (else it is returned as given,
        for the caller to refuse).

    Returns
    -------
    LeverResult
        The levers, the written text and its executed cycle time and energy.

    Raises
    ------
    InvalidInput
        ``spec`` is not a RAPID module's cycle, ``cycle_time_s`` is not positive, or the
        module's text cannot be read again.
    """
    start = time.perf_counter()
    text, encoding = _module_text(spec, text, encoding, max_evaluations)
    assert spec.module is not None
    config = config or ControllerConfig()
    lines = text.splitlines(keepends=True)
    slots = _slots(spec, lines) if only_lines is None else _only(_slots(spec, lines), set(only_lines))
    ev = _Evaluator(spec, slots, energy, config, by_runs=True)
    taught_state = tuple(s.taught for s in slots)
    plan0, t0, _ = ev(taught_state)
    e0, lab0 = ev.energies(plan0)
    ev.deadline = None if max_seconds is None else start + max_seconds
    own = t0 if baseline is None else baseline[0]  # a module over it is first brought into it
    target = own if cycle_time_s is None else min(cycle_time_s, own)
    if cycle_time_s is not None and not cycle_time_s > 0:
        raise InvalidInput(f"cycle_time_s must be positive, got {cycle_time_s}")
    idle = _idle_waits(spec, lines) if use_waits else {}
    idle_s = sum(sec * n for sec, n, _, _ in idle.values())
    chosen = _search(ev, slots, target + idle_s, max_evaluations, pairs, bound)
    plan_s, t_search, _ = ev(chosen)  # its energy reported as the check takes it (the whole grid)
    new_waits, t_search = _spend_idle(idle, idle_s, t_search, target)
    edits = {line: (idle[line][2], idle[line][3], sec) for line, sec in new_waits.items()}
    written, where = write_levers(spec.module, text, slots, chosen, edits)
    differs, executed = _run_written(ev, robot, written, where, chosen, new_waits, target, (t0, e0))
    if differs is None and executed is not None:
        t_exec, e_exec, lab_exec = executed
    else:  # not written with levers: the program as taught
        chosen, written, t_exec, e_exec, lab_exec, new_waits = taught_state, text, t0, e0, lab0, {}
    moves = tuple(
        MoveLever(s.line, s.label, s.taught, c, s.open, s.closed) for s, c in zip(slots, chosen, strict=True)
    )
    if baseline is not None:  # reported against the program this module replaces
        t0, e0, lab0 = baseline
    return LeverResult(
        source=spec.source,
        energy_measure=energy,
        taught_cycle_s=t0,
        default_energy_J=e0,
        cycle_s=t_exec,
        energy_J=e_exec,
        default_lab_J=lab0,
        energy_lab_J=lab_exec,
        searched_cycle_s=t_search,
        searched_energy_J=ev.whole_energy(plan_s),
        moves=moves,
        written_text=written,
        encoding=encoding,
        reads_back=differs,
        n_evaluations=len(ev.memo),  # the plans made (ev.n is set past the budget when time runs out)
        wall_s=time.perf_counter() - start,
        waits=tuple((line, idle[line][0], sec) for line, sec in sorted(new_waits.items())),
    )
