"""From a RAPID task to the cycle the optimizer and the controller emulation run.

The interpreter (:mod:`joulepath.rapid.interpreter`) runs the task's program on the
robot's kinematics and gives one cycle's events; here each becomes a
:class:`~joulepath.sim._steps.Step`: a move with its joint target (rad), its path kind
(``MoveL`` and ``MoveC`` move the TCP on a line or circle), speed, ``\\T``, zone, tool
(TCP and load, ``GripLoad`` included) and the motion settings in force; a wait; or an
instruction kept as written. A move the interpreter marked (its target, speed, zone or
branch known only at run time, a process instruction, ``\\Conc``) is kept as taught,
with its reasons in ``Step.kept``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from joulepath._typing import FloatArray
from joulepath._work import check_work
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, RapidError
from joulepath.kinematics import check_layout, confdata, solve_ik
from joulepath.rapid import geometry as geo
from joulepath.rapid.interpreter import (
    UNKNOWN_TARGET,
    Action,
    Interpreter,
    Motion,
    Trace,
    Wait,
    inputs_read,
    listed,
)
from joulepath.rapid.interpreter import moves_in as _moves
from joulepath.rapid.task import Task, load_task
from joulepath.rapid.values import Record, num, pos_values
from joulepath.sim import SpeedData, Step

RAPID_AXES = 6


class RobotKinematics:
    """:class:`joulepath.rapid.interpreter.Kinematics` of a robot: closed-form IK, FK of the flange."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.lo, self.hi = robot.joint_ranges()
        self._reach: float | None = None

    def joints(
        self, flange: FloatArray, conf: tuple[int, int, int, int] | None, near: FloatArray | None
    ) -> FloatArray | None:
        if conf is not None:
            return solve_ik(self.robot.chain, flange, conf, lower=self.lo, upper=self.hi)
        start = near if near is not None else np.zeros(self.robot.n_joints)
        return solve_ik(self.robot.chain, flange, None, lower=self.lo, upper=self.hi, near=start)

    def flange(self, q: FloatArray) -> FloatArray:
        pose = self.robot.fk(q)
        out = np.eye(4)
        out[:3, :3] = pose.rotation
        out[:3, 3] = pose.position_m
        return out

    def confdata(self, q: FloatArray) -> tuple[int, int, int, int]:
        c = confdata(self.robot.chain, q)
        return (int(c[0]), int(c[1]), int(c[2]), int(c[3]))

    def in_range(self, q: FloatArray) -> int | None:
        bad = np.nonzero((q < self.lo - 1e-9) | (q > self.hi + 1e-9))[0]
        return int(bad[0]) if bad.size else None

    def axes_to_joints(self, axes: FloatArray) -> FloatArray:
        return self.robot.axes_to_joints(axes)

    def joints_to_axes(self, q: FloatArray) -> FloatArray:
        return self.robot.joints_to_axes(q)

    def axes_outside(self, axes: FloatArray) -> str | None:
        return self.robot.axes_outside(axes)

    def reach_m(self) -> float:
        """The farthest the flange comes from the base (m), over 4,096 seeded configurations within
        the joint ranges (a lower bound of the true reach, within a few mm)."""
        if self._reach is None:
            rng = np.random.default_rng(0)
            q = self.lo + rng.random((4096, self.robot.n_joints)) * (self.hi - self.lo)
            self._reach = max(float(np.linalg.norm(self.robot.fk(qk).position_m)) for qk in q)
        return self._reach


@dataclass(frozen=True, slots=True, eq=False)
class TaskCycle:
    """A task's cycle: the steps, the trace they came from, and what was kept or assumed."""

    task: Task
    trace: Trace
    steps: tuple[Step, ...]
    kept: tuple[tuple[str, str], ...] = field(default=())  # (move "file:line instruction", reason)


def tool_transform(tool: Record) -> FloatArray:
    """Flange to TCP (m) of a ``tooldata``."""
    tframe = tool.get("tframe")
    assert isinstance(tframe, Record)
    return geo.pose_matrix(tframe)


def _load(rec: object) -> tuple[float, FloatArray]:
    assert isinstance(rec, Record)
    return float(num(rec.get("mass"))), np.asarray(pos_values(rec.get("cog"))) / 1000.0


def _robot_for(
    robot: Robot, m: Motion, cache: dict[tuple[float, ...], Robot], notes: list[str] | None = None
) -> Robot:
    """The robot carrying the tool's load and the ``GripLoad`` in force (their centre of mass combined);
    a load above the rated payload is carried, and ``notes`` told so once."""
    mass, cog = _load(m.tool.get("tload")) if bool(m.tool.get("robhold")) else (0.0, np.zeros(3))
    if m.settings.grip_load is not None:
        gm, gc = _load(m.settings.grip_load)
        if gm > 0:
            tcp = tool_transform(m.tool) if bool(m.tool.get("robhold")) else np.eye(4)
            gc_flange = tcp[:3, :3] @ gc + tcp[:3, 3]
            cog = (mass * cog + gm * gc_flange) / (mass + gm)
            mass += gm
    key = (round(mass, 9), *(round(float(v), 9) for v in cog))
    what = f"tool {m.tool_name}" + (
        "" if m.settings.grip_load is None else f" with GripLoad {m.settings.grip_load_name}"
    )
    if key not in cache:
        try:
            cache[key] = robot.with_payload(mass, com=cog, what=what, over_rated=True) if mass > 0 else robot
        except InvalidInput as err:
            raise RapidError(f"{m.pos}: {err}") from err
        note = robot.over_rated_note(mass, what)
        if note is not None and notes is not None:
            notes.append(f"{m.pos}: {note}")
    return cache[key]


def _speed(rec: Record) -> SpeedData:
    return SpeedData(*(float(num(v)) for v in rec.values))


def steps_of(
    trace: Trace,
    robot: Robot,
    *,
    progress: Callable[[str], None] | None = None,
    source: str = "",
    notes: list[str] | None = None,
) -> tuple[tuple[Step, ...], tuple[tuple[str, str], ...]]:
    """The cycle's steps from a trace run on ``robot``'s kinematics, and the kept moves with a reason;
    ``progress`` is told each move (``reading SOURCE: move k/N``) as its step is made; ``notes`` a
    line for each load carried above the rated payload."""
    cycle = trace.cycle
    counts: dict[tuple[str, int], int] = {}
    for e in cycle:
        key = (e.pos.file, e.pos.start)
        counts[key] = counts.get(key, 0) + 1
    robots: dict[tuple[float, ...], Robot] = {}
    steps: list[Step] = []
    kept: list[tuple[str, str]] = []
    n_moves, k = sum(isinstance(e, Motion) for e in cycle), 0
    for e in cycle:
        if isinstance(e, Motion):
            assert e.joints is not None
            k += 1
            if progress is not None:
                progress(f"reading {source}: move {k}/{n_moves}")
            label = f"{e.instruction} {e.target_text}"
            tcp = tool_transform(e.tool) if bool(e.tool.get("robhold")) else np.eye(4)
            zone_mm = None if e.fine else e.zone_mm
            # an unknown target first: it says where the target comes from
            reasons = tuple(sorted(e.kept, key=lambda why: (UNKNOWN_TARGET not in why, why)))
            if reasons:
                kept.append((f"{e.pos} {label}", reasons[0]))
            steps.append(
                Step(
                    "move",
                    e.pos.line,
                    label,
                    e,
                    q=e.joints.copy(),
                    linear=e.kind in ("linear", "circular"),
                    speed=_speed(e.speed),
                    time_s=e.time_s,
                    zone_mm=zone_mm,
                    tcp=tcp,
                    robot=_robot_for(robot, e, robots, notes),
                    repeated=counts[(e.pos.file, e.pos.start)] > 1,
                    kept=reasons,
                    circle_q=None if e.circle_joints is None else e.circle_joints.copy(),
                    file=e.pos.file,
                    acc_pct=e.settings.acc_pct,
                    ramp_pct=e.settings.ramp_pct,
                    vel_override_pct=e.settings.vel_override_pct,
                    vel_max_mm_s=e.settings.vel_max_mm_s,
                )
            )
        elif isinstance(e, Wait):
            text = e.stmt.name + (" \\InPos" if e.inpos else "") + (f" {e.seconds:g}" if not e.io else "")
            steps.append(Step("wait", e.pos.line, text, e, seconds=e.seconds, file=e.pos.file))
        elif isinstance(e, Action):
            steps.append(Step("fixed", e.pos.line, e.name, e, file=e.pos.file))
    return tuple(steps), tuple(kept)


def _unknowns_read(trace: Trace) -> str:
    """What the run read without a value, where a cycle came out empty: values declared nowhere and
    inputs taken as 0 (they may be what skipped its moves), in words; "" where there are none."""
    values = [
        a.name
        for a in trace.assumed
        if a.role in ("value", "num", "bool") and a.value != "the scenario's value"
    ]
    names = list(dict.fromkeys([*values, *inputs_read(trace.notes)]))
    if not names:
        return ""
    return (
        f" with what it reads taken as 0 ({listed(names, 4)}: declared nowhere or read at run time; "
        "give them with --io NAME=VALUE or the scenario file)"
    )


def read_task_cycle(
    paths: Sequence[str | Path],
    robot: Robot,
    *,
    io: Mapping[str, float | str | bool] | None = None,
    routine: str | None = None,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
    given: Mapping[str, object] | None = None,
) -> TaskCycle:
    """Run a task's program (modules and folders) on ``robot`` and give its cycle's steps.

    ``io``: the scenario (values of inputs and run-time data by name). ``routine``: the routine
    to run instead of ``main``. :class:`RapidError` (one line) for what the issue's refusals
    name: text that is not RAPID, a name declared nowhere, no ``main`` and no routine, an
    unreachable target, a program that never finishes its cycle.
    """
    if robot.n_joints != RAPID_AXES:
        raise RapidError(
            f"{', '.join(map(str, paths))}: a RAPID program drives a {RAPID_AXES}-axis ABB arm, "
            "but this robot "
            f"has {robot.n_joints} joints; give a {RAPID_AXES}-joint robot, "
            "or write the cycle as a plain cycle "
            "file (.toml)"
        )
    try:
        check_layout(robot.chain)
    except InvalidInput as err:
        raise RapidError(f"{', '.join(map(str, paths))}: {err}") from err
    task = load_task(paths)
    interp = Interpreter(
        task,
        io=io,
        seed=seed,
        kinematics=RobotKinematics(robot),
        given=given,
        rated_payload_kg=robot.rated_payload_kg,
    )
    try:
        trace = interp.run(routine)
    except RapidError as err:
        fam = task.moc.family if task.moc is not None else None
        if fam is not None and "--robot" in str(err) and f"irb{fam[0]}".lower() not in robot.name.lower():
            raise RapidError(f"{err} (its MOC.cfg names an IRB {fam[0]})") from None
        raise
    moves = [e for e in trace.cycle if isinstance(e, Motion)]
    if not moves:
        if trace.loop is not None:
            where = str(trace.loop)
        else:
            found = next(
                (r for m in task.modules for r in m.routines if r.name.lower() == trace.routine.lower()), None
            )
            where = str(found.pos) if found is not None else task.source
        routines = {r.name.lower(): r for m in task.modules for r in m.routines}
        movers = sorted(
            {
                r.name
                for m in task.modules
                for r in m.routines
                if r.kind == "PROC" and _moves(r, routines) and not r.params
            }
            - {trace.routine}
        )
        if len(movers) == 1 and routine is None:  # a template's empty main beside its one path (Path_10)
            tc = read_task_cycle(
                paths, robot, io=io, routine=movers[0], seed=seed, progress=progress, given=given
            )
            said = (
                f"{where}: the cycle ({trace.routine}) holds no move: {movers[0]}, the one routine that "
                "moves the robot, is run as the cycle (--routine NAME names another)"
            )
            return replace(tc, trace=replace(tc.trace, notes=(said, *tc.trace.notes)))
        hint = (
            f"; give --routine NAME, one of the routines that move the robot: {listed(movers)}"
            if movers
            else "; nothing to optimize"
        )
        raise RapidError(f"{where}: the cycle ({trace.routine}) holds no move{_unknowns_read(trace)}{hint}")
    check_work(
        "moves",
        len(moves),
        task.source,
        "the cycle (calls and loops run) has that many moves; split it into shorter programs",
    )
    loads: list[str] = []
    steps, kept = steps_of(trace, robot, progress=progress, source=task.source, notes=loads)
    unused = sorted(set(k.lower() for k in (io or {})) - interp.io_used)
    notes = [*trace.notes, *loads]
    for k in unused:
        notes.append(f"--io {k}: the cycle never read it")
    trace = replace(trace, notes=tuple(notes))
    return TaskCycle(task, trace, steps, kept)


def read_written(text: str, source: str, robot: Robot) -> TaskCycle:
    """A module joulepath wrote (its text), run by the interpreter as the controller would run it."""
    from joulepath.rapid import parse_module

    module = parse_module(text.replace("\r\n", "\n"), path=source)
    task = Task((module,), frozenset(), source)
    trace = Interpreter(task, kinematics=RobotKinematics(robot)).run(None)
    steps, kept = steps_of(trace, robot)
    return TaskCycle(task, trace, steps, kept)


@dataclass(frozen=True, slots=True, eq=False)
class StepsView:
    """Steps from a start configuration (:class:`joulepath.sim._steps.StepSequence`)."""

    steps: tuple[Step, ...]
    start: FloatArray
    source: str


def as_sequence(tc: TaskCycle) -> StepsView:
    """A task's cycle as what :func:`joulepath.sim.plan_cycle` runs (it starts where it ends)."""
    moves = [st for st in tc.steps if st.kind == "move"]
    assert moves and moves[-1].q is not None
    return StepsView(tc.steps, moves[-1].q.copy(), tc.task.source)
