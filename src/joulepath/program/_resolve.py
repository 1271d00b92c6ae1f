"""From a parsed module (or a plain cycle file) to the cycle: joint targets, speeds, zones, waits.

The cycle is the body of ``main``'s ``WHILE TRUE`` loop, or ``main``'s body when there is
no loop; calls of the module's procedures are followed (their statements join the
cycle where the call stands), and FOR loops with moves are unrolled (each run's
statements in turn; a move inside a loop that runs more than once is ``repeated``).
The robot starts each cycle where the previous one ended:
at the last move's target. Robtargets are solved with the closed-form inverse
kinematics, choosing the solution their ``confdata`` names; a tool's TCP and load
are taken into account (targets are TCP poses, the load is carried in the dynamics).
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._io import finite_number, load_toml, read_capped
from joulepath._typing import FloatArray
from joulepath._work import check_work
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput
from joulepath.kinematics import check_layout, confdata, quaternion_to_rotation, solve_ik
from joulepath.program._model import (
    Branch,
    Call,
    ForLoop,
    JointTarget,
    Module,
    MotionSetting,
    Move,
    RapidError,
    RobTarget,
    Statement,
    TargetRef,
    ToolData,
    Verbatim,
    WaitTime,
    WhileTrue,
    WObjData,
    ZoneData,
)
from joulepath.program._parse import (
    MAX_MODULE_BYTES,
    PREDEFINED_SPEEDS,
    PREDEFINED_ZONES,
    TOOL0,
    WOBJ0,
    parse_module,
)
from joulepath.rapid.interpreter import inputs_read, listed
from joulepath.sim import SpeedData, Step


@dataclass(frozen=True, slots=True, eq=False)
class CycleSpec:
    """The cycle: its steps, where it starts (rad), and where it came from.

    ``choices``: what the reader decided or assumed, a line each (a branch decided by the
    scenario or assumed, an input read with no value given), in program order. ``kept``: the
    moves kept as taught (their target, speed or branch known only at run time ...) and why.
    """

    steps: tuple[Step, ...]
    start: FloatArray
    source: str
    module: Module | None
    fixed_lines: tuple[int, ...]
    robot: Robot
    choices: tuple[str, ...] = field(default=())
    kept: tuple[tuple[str, str], ...] = field(default=())  # (move, why it runs as taught)
    task: object | None = None  # the RAPID task's cycle (joulepath.program._task.TaskCycle)
    assumed: tuple[Any, ...] = field(default=())  # names declared nowhere (joulepath.rapid Assumption)
    static_note: str = ""  # why the via-point writer has no module to edit (module None), in words


def tool_transform(tool: ToolData) -> FloatArray:
    """Flange (tool0) to TCP transform, m."""
    out = np.eye(4)
    out[:3, :3] = quaternion_to_rotation(np.asarray(tool.rotation, dtype=float))
    out[:3, 3] = np.asarray(tool.tcp_mm) / 1000.0
    return out


def target_pose(target: RobTarget) -> FloatArray:
    """The TCP pose of a robtarget in the base frame, m."""
    out = np.eye(4)
    out[:3, :3] = quaternion_to_rotation(np.asarray(target.quaternion, dtype=float))
    out[:3, 3] = np.asarray(target.position_mm) / 1000.0
    return out


RAPID_AXES = 6
"""Robot axes of a RAPID ``jointtarget`` (``robax``): RAPID programs drive six-axis arms."""
MAX_CYCLE_FILE_BYTES = 4 << 20
"""Largest plain cycle file (TOML) read."""
MAX_STEPS = 200_000
"""Most statements a program's run may unroll into (calls and FOR loops followed)."""


def _size(module: Module, body: tuple[Statement, ...], memo: dict[str, int]) -> int:
    """How many statements :func:`_flatten` gives, without building them (each procedure counted once)."""
    n = 0
    for s in body:
        if isinstance(s, Call) and s.body is not None:
            n += _size(module, s.body, memo)
        elif isinstance(s, Branch):
            n += _size(module, s.body, memo)
        elif isinstance(s, Call):
            key = s.name.lower()
            if key not in memo:
                proc = module.procedure(s.name)
                assert proc is not None
                memo[key] = _size(module, proc.body, memo)
            n += memo[key]
        elif isinstance(s, WhileTrue):
            n += _size(module, s.body, memo)
        elif isinstance(s, ForLoop):
            n += sum(_size(module, run, memo) for run in s.runs)
        else:
            n += 1
        if n > MAX_STEPS:
            return n
    return n


def _flatten(module: Module, body: tuple[Statement, ...], notes: list[str]) -> list[Statement]:
    """The statements the cycle runs, in order; ``notes`` gets the branch choices made on the way."""
    out: list[Statement] = []
    for s in body:
        if isinstance(s, Call):
            if s.body is not None:  # read with its arguments bound
                out.extend(_flatten(module, s.body, notes))
                continue
            proc = module.procedure(s.name)
            assert proc is not None
            out.extend(_flatten(module, proc.body, notes))
        elif isinstance(s, WhileTrue):
            out.extend(_flatten(module, s.body, notes))
        elif isinstance(s, Branch):
            if s.note not in notes:
                notes.append(s.note)
            out.extend(_flatten(module, s.body, notes))
        elif isinstance(s, ForLoop):  # unrolled: every run in order
            for run in s.runs:
                out.extend(_flatten(module, run, notes))
        else:
            out.append(s)
    return out


def _lookup(module: Module, name: str, type_: str, line: int) -> object:
    base, _, index = name.partition("{")  # an array element, checked when read: NAME{k}
    d = module.declaration(base)
    if d is not None and index:
        if d.type != type_:
            raise module.error(
                line, f"{base} is a {d.type} array (line {d.line}), but a {type_} is needed here"
            )
        assert isinstance(d.value, tuple)
        return d.value[int(index.rstrip("}")) - 1]
    if d is not None and isinstance(d.value, tuple):
        raise module.error(line, f"{name} is an array (line {d.line}); name one element, e.g. {name}{{1}}")
    if d is None:
        if type_ == "speeddata" and name.lower() in PREDEFINED_SPEEDS:
            return PREDEFINED_SPEEDS[name.lower()]
        if type_ == "zonedata" and name.lower() in PREDEFINED_ZONES:
            return PREDEFINED_ZONES[name.lower()]
        if type_ == "tooldata" and name.lower() == "tool0":
            return TOOL0
        if type_ == "wobjdata" and name.lower() == "wobj0":
            return WOBJ0
        if type_ in ("robtarget", "jointtarget"):
            raise module.error(line, f"unknown target {name!r}: declare it (CONST {type_} {name} := [...])")
        raise module.error(line, f"unknown {type_} {name!r}: declare it or use a predefined one")
    if d.type != type_:
        raise module.error(line, f"{name} is a {d.type} (line {d.line}), but a {type_} is needed here")
    return d.value


def resolve_module(
    module: Module,
    robot: Robot,
    *,
    idle_waits: Collection[int] = (),
    progress: Callable[[str], None] | None = None,
) -> CycleSpec:
    """The cycle of a parsed module on ``robot``; ``RapidError`` naming the line otherwise.

    ``progress`` (optional) is told each move resolved (its target's inverse kinematics),
    once the unrolled cycle is within the moves limit.

    A ``WaitTime`` is idle time (``Step.idle``: an optimizer may spend it on the moves)
    when it is marked ``! joulepath: idle`` or its line is in ``idle_waits``; every run
    of it is (a procedure called twice, a FOR loop).
    """
    if robot.n_joints != RAPID_AXES:
        raise RapidError(
            f"{module.path}: a RAPID module drives a {RAPID_AXES}-axis ABB arm (its jointtargets hold "
            f"{RAPID_AXES} robot axes), but this robot has {robot.n_joints} joints; give a "
            f"{RAPID_AXES}-joint robot, or write the cycle as a plain cycle file (.toml)"
        )
    main = module.procedure("main")
    assert main is not None
    loop = next((s for s in main.body if isinstance(s, WhileTrue)), None)
    body = loop.body if loop is not None else main.body
    size = _size(module, body, {})
    if size > MAX_STEPS:
        raise module.error(
            main.line,
            f"main runs more than {MAX_STEPS} statements once its calls and FOR loops are unrolled; "
            "run fewer repetitions",
        )
    notes: list[str] = []
    flat = _flatten(module, body, notes)
    check_work(
        "moves",
        sum(isinstance(s, Move) for s in flat),
        f"{module.path}:{main.line}",
        "the cycle (calls and FOR loops unrolled) has that many moves; split it into shorter programs",
    )
    wait_lines = {s.line for s in flat if isinstance(s, WaitTime)}
    for line in sorted(set(idle_waits)):
        if line not in wait_lines:
            raise module.error(
                line,
                f"idle_waits names line {line}, which is not a WaitTime the cycle runs; name the line of "
                "a WaitTime (or mark it '! joulepath: idle')",
            )
    lo, hi = robot.joint_ranges()
    counts: dict[int, int] = {}
    for s in flat:
        counts[s.line] = counts.get(s.line, 0) + 1
    robots: dict[str, Robot] = {}
    steps: list[Step] = []
    fixed: list[int] = []
    n_moves, k = sum(isinstance(s, Move) for s in flat), 0
    settings = _settings_at_start(main.body if loop is not None else (), flat)
    for s in flat:
        if isinstance(s, MotionSetting):
            settings[s.text] = s.values
        if isinstance(s, WaitTime):
            idle = s.idle or s.line in idle_waits
            label = ("WaitTime \\InPos, " if s.inpos else "WaitTime ") + f"{s.seconds:g}"
            steps.append(Step("wait", s.line, label, s, seconds=s.seconds, idle=idle))
        elif isinstance(s, Verbatim):
            steps.append(Step("fixed", s.line, s.text, s))
            fixed.append(s.line)
        elif isinstance(s, Move):
            k += 1
            if progress is not None:
                progress(f"reading {module.path}: move {k}/{n_moves}")
            step = _move_step(module, robot, s, lo, hi, robots, counts[s.line] > 1)
            (acc, ramp), (override, vmax) = settings["AccSet"], settings["VelSet"]
            steps.append(
                replace(
                    step,
                    acc_pct=acc,
                    ramp_pct=ramp,
                    vel_override_pct=override,
                    vel_max_mm_s=None if vmax == _NO_CAP else vmax,
                )
            )
    moves = [st for st in steps if st.kind == "move"]
    if not moves:
        where = "main's WHILE TRUE loop" if loop is not None else "main"
        raise module.error(
            loop.line if loop is not None else main.line, f"{where} holds no move; nothing to optimize"
        )
    assert moves[-1].q is not None
    return CycleSpec(tuple(steps), moves[-1].q.copy(), module.path, module, tuple(fixed), robot, tuple(notes))


_NO_CAP = float("inf")


def _settings_at_start(
    before: tuple[Statement, ...], flat: list[Statement]
) -> dict[str, tuple[float, float]]:
    """``AccSet`` and ``VelSet`` in force when the cycle starts (100 %, 100 %, no cap when none is).

    RAPID keeps them until the next: the cycle of a ``WHILE TRUE`` loop starts with the last
    its body sets (from the second run on, the steady state), else with the last ``main``
    sets before the loop (``before``: main's statements, up to the loop).
    """
    out = {"AccSet": (100.0, 100.0), "VelSet": (100.0, _NO_CAP)}
    for s in before:
        if isinstance(s, WhileTrue):
            break
        if isinstance(s, MotionSetting):
            out[s.text] = s.values
    if before:  # a loop: its body's last settings carry over into its next run
        for s in flat:
            if isinstance(s, MotionSetting):
                out[s.text] = s.values
    return out


def _move_step(
    module: Module,
    robot: Robot,
    s: Move,
    lo: FloatArray,
    hi: FloatArray,
    robots: dict[str, Robot],
    repeated: bool,
) -> Step:
    speed = _lookup(module, s.speed, "speeddata", s.line)
    zone = _lookup(module, s.zone, "zonedata", s.line)
    tool = _lookup(module, s.tool, "tooldata", s.line)
    assert isinstance(speed, SpeedData) and isinstance(zone, ZoneData) and isinstance(tool, ToolData)
    if s.v_tcp is not None:
        speed = SpeedData(s.v_tcp, speed.v_ori, speed.v_leax, speed.v_reax)
    zone_mm = None if zone.finep else zone.pzone_tcp
    if s.z_tcp is not None and zone_mm is not None:
        zone_mm = s.z_tcp
    tcp = tool_transform(tool)
    key = s.tool.lower()
    if key not in robots:
        try:
            robots[key] = (
                robot.with_payload(tool.mass_kg, com=np.asarray(tool.cog_mm) / 1000.0, what=f"tool {s.tool}")
                if tool.mass_kg > 0
                else robot
            )
        except InvalidInput as err:
            raise module.error(s.line, str(err)) from err
    if s.instruction == "MoveAbsJ":
        if s.target_ref is not None:
            raise module.error(
                s.line,
                f"MoveAbsJ {s.target}: Offs and RelTool compute robtargets; "
                "MoveAbsJ goes to a jointtarget, so use MoveJ",
            )
        jt = _lookup(module, s.target, "jointtarget", s.line)
        assert isinstance(jt, JointTarget)
        axes = np.radians(np.asarray(jt.joints_deg[: robot.n_joints], dtype=float))
        q = robot.axes_to_joints(axes)  # robax holds the controller's axis values
        bad = np.nonzero((q < lo - 1e-9) | (q > hi + 1e-9))[0]
        if bad.size:
            j = int(bad[0])
            raise module.error(
                s.line,
                f"{s.target}: joint {j + 1} = {np.degrees(q[j]):.2f} deg is outside its range "
                f"[{np.degrees(lo[j]):.1f}, {np.degrees(hi[j]):.1f}] deg",
            )
        why = robot.axes_outside(axes)
        if why is not None:
            raise module.error(s.line, f"{s.target}: {why}")
    else:
        rt, pose = target_in_object(module, s.target_ref or TargetRef(s.target), s.line, ())
        if s.wobj is not None:
            pose = wobj_transform(module, s.wobj, s.line) @ pose
        q = robtarget_joints(module, robot, rt, tcp, s, pose=pose)
    return Step(
        "move",
        s.line,
        f"{s.instruction} {s.target}",
        s,
        q=q,
        linear=s.instruction == "MoveL",
        speed=speed,
        time_s=s.time_s,
        zone_mm=zone_mm,
        tcp=tcp,
        robot=robots[key],
        repeated=repeated,
    )


def _frame(position_mm: tuple[float, ...], quaternion: tuple[float, ...]) -> FloatArray:
    out = np.eye(4)
    out[:3, :3] = quaternion_to_rotation(np.asarray(quaternion, dtype=float))
    out[:3, 3] = np.asarray(position_mm, dtype=float) / 1000.0
    return out


def _rotation(axis: int, deg: float) -> FloatArray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out = np.eye(4)
    out[i, i], out[i, j], out[j, i], out[j, j] = c, -s, s, c
    return out


def target_in_object(
    module: Module, ref: TargetRef, line: int, seen: tuple[str, ...]
) -> tuple[RobTarget, FloatArray]:
    """A robtarget (its confdata) and its TCP pose in its work object (m), ``Offs`` / ``RelTool`` applied.

    ``Offs`` adds its displacement in the work object's frame; ``RelTool`` moves in the
    tool frame of the target and turns about its x, the new y and the new z axis.
    """
    if ref.name.lower() in seen:
        raise module.error(line, f"the robtarget {ref.name} is computed from itself ({' -> '.join(seen)})")
    d = module.declaration(ref.name.partition("{")[0])
    if d is not None and isinstance(d.value, TargetRef) and "{" not in ref.name:
        rt, pose = target_in_object(module, d.value, d.line, (*seen, ref.name.lower()))
    else:
        value = _lookup(module, ref.name, "robtarget", line)
        assert isinstance(value, RobTarget)
        rt, pose = value, target_pose(value)
    for off in ref.offsets:
        shift = np.asarray(off.displacement_mm, dtype=float) / 1000.0
        if off.kind == "Offs":
            pose = pose.copy()
            pose[:3, 3] += shift
        else:
            step = np.eye(4)
            step[:3, 3] = shift
            pose = pose @ step @ _rotation(0, off.rotation_deg[0]) @ _rotation(1, off.rotation_deg[1])
            pose = pose @ _rotation(2, off.rotation_deg[2])
    return rt, pose


def wobj_transform(module: Module, name: str, line: int) -> FloatArray:
    """Base to object frame (``uframe * oframe``, m) of a fixed work object; moving ones are refused."""
    wobj = _lookup(module, name, "wobjdata", line)
    assert isinstance(wobj, WObjData)
    if wobj.moving:
        why = (
            "robhold TRUE" if wobj.robhold else "ufprog FALSE" if not wobj.ufprog else f"ufmec {wobj.ufmec!r}"
        )
        raise module.error(
            line,
            f"work object {name} moves ({why}): coordinated or robot-held work objects are not modelled; "
            'use a fixed wobjdata (robhold FALSE, ufprog TRUE, ufmec "")',
        )
    return _frame(*wobj.uframe) @ _frame(*wobj.oframe)


def robtarget_joints(
    module: Module,
    robot: Robot,
    rt: RobTarget,
    tcp: FloatArray,
    s: Move,
    *,
    pose: FloatArray | None = None,
) -> FloatArray:
    """Joint values of a robtarget with its confdata; ``RapidError`` if unreachable or no solution fits.

    ``pose``: the TCP pose in the base frame (m) when it is not the robtarget's own
    (a work object, ``Offs`` / ``RelTool``).
    """
    try:
        check_layout(robot.chain)
    except InvalidInput as err:
        raise module.error(s.line, str(err)) from err
    lo, hi = robot.joint_ranges()
    if pose is None:
        pose = target_pose(rt)
    flange = pose @ np.linalg.inv(tcp)
    q = solve_ik(robot.chain, flange, rt.conf, lower=lo, upper=hi)
    if q is not None:
        return q
    anyq = solve_ik(robot.chain, flange, None, lower=lo, upper=hi, near=np.zeros(robot.n_joints))
    where = [round(float(v), 3) for v in pose[:3, 3] * 1000.0]
    if anyq is None:
        raise module.error(
            s.line,
            f"{s.target} at {where} mm is out of the robot's reach with this orientation "
            "and tool (no joint solution within the ranges); move the target",
        )
    from joulepath.kinematics import ik_branches

    qs, valid = ik_branches(robot.chain, flange)
    confs = sorted(
        {
            tuple(int(v) for v in confdata(robot.chain, c))
            for c, ok in zip(qs, valid, strict=True)
            if ok and np.all(c >= lo - 1e-9) and np.all(c <= hi + 1e-9)
        }
    )
    raise module.error(
        s.line,
        f"{s.target}: no joint solution matches its confdata {list(rt.conf)}; reachable ones: "
        + ", ".join(str(list(c)) for c in confs),
    )


# ---------------------------------------------------------------- plain cycle file
def read_cycle_toml(
    path: str | Path, robot: Robot, *, progress: Callable[[str], None] | None = None
) -> CycleSpec:
    """A plain cycle file for arms without RAPID (TOML), e.g.::

        start_deg = [0, 0, 0, 0, 30, 0]      # optional: default the last waypoint
        [[step]]
        joints_deg = [60, 20, 10, 0, 40, 0]
        duration_s = 0.9                      # the move's time as the arm runs it
        [[step]]
        wait_s = 0.3

    Every move is a joint move that stops at its waypoint; its default is the
    controller's jerk-limited profile stretched to ``duration_s``. ``progress`` (optional)
    is told each step read once the file is within the moves limit.
    """
    p = Path(path)
    data = load_toml(p, max_bytes=MAX_CYCLE_FILE_BYTES, what="a TOML cycle file")
    unknown = set(data) - {"start_deg", "step"}
    if unknown:
        raise InvalidInput(f"{p}: unknown key(s) {sorted(unknown)}; use start_deg and [[step]]")
    raw = data.get("step")
    if not isinstance(raw, list) or not raw:
        raise InvalidInput(f"{p}: no [[step]] tables; add moves (joints_deg, duration_s) and waits (wait_s)")
    check_work(
        "moves",
        sum(isinstance(st, dict) and "joints_deg" in st for st in raw),
        str(p),
        "split the cycle into shorter files",
    )
    n = robot.n_joints
    lo, hi = robot.joint_ranges()
    steps: list[Step] = []
    for k, st in enumerate(raw, start=1):
        where = f"{p}: step {k}"
        if progress is not None:
            progress(f"reading {p}: step {k}/{len(raw)}")
        if not isinstance(st, dict):
            raise InvalidInput(f"{where}: must be a table")
        if set(st) == {"wait_s"}:
            w = finite_number(st["wait_s"], f"{where}: wait_s", lo=0.0, hi=3600.0, unit="seconds")
            steps.append(Step("wait", k, f"wait {w:g}", None, seconds=w))
            continue
        if set(st) != {"joints_deg", "duration_s"}:
            raise InvalidInput(
                f"{where}: a step is either wait_s or joints_deg + duration_s, got {sorted(st)}"
            )
        q = _joints(st["joints_deg"], n, where)
        T = finite_number(st["duration_s"], f"{where}: duration_s", lo=0.0, hi=60.0, unit="seconds")
        if T == 0:
            raise InvalidInput(f"{where}: duration_s must be a number of seconds in (0, 60], got 0")
        bad = np.nonzero((q < lo - 1e-9) | (q > hi + 1e-9))[0]
        if bad.size:
            j = int(bad[0])
            raise InvalidInput(f"{where}: joint {j + 1} = {np.degrees(q[j]):.2f} deg is outside its range")
        steps.append(
            Step(
                "move",
                k,
                f"step {k}",
                None,
                q=q,
                speed=SpeedData(7000.0, 500.0, 5000.0, 1000.0),
                time_s=float(T),
                zone_mm=None,
                tcp=np.eye(4),
                robot=robot,
            )
        )
    moves = [s for s in steps if s.kind == "move"]
    if not moves:
        raise InvalidInput(f"{p}: no move step; add [[step]] tables with joints_deg and duration_s")
    start = _joints(data["start_deg"], n, f"{p}: start_deg") if "start_deg" in data else moves[-1].q
    assert start is not None
    return CycleSpec(tuple(steps), np.asarray(start, float), str(p), None, (), robot)


def _joints(value: object, n: int, where: str) -> FloatArray:
    if (
        not isinstance(value, list)
        or len(value) != n
        or not all(isinstance(v, int | float) and not isinstance(v, bool) and abs(v) <= 1e6 for v in value)
    ):
        raise InvalidInput(f"{where}: needs a list of {n} joint values in degrees (numbers, not true/false)")
    out: FloatArray = np.radians(np.asarray(value, dtype=float))
    return out


__all__ = ["CycleSpec", "RapidError", "Step", "read_cycle_toml", "resolve_module"]


def check_moves_arm(spec: CycleSpec) -> None:
    """Refuse a cycle in which no move goes anywhere: every target is where the arm already is.

    A zero-length move among others is fine (it takes no time and no energy).

    Raises
    ------
    InvalidInput
        Every move of ``spec`` ends where the arm is when it starts.
    """
    q = spec.start
    for step in spec.steps:
        if step.kind == "move" and step.q is not None:
            if np.abs(step.q - q).max() > 1e-9:
                return
            q = step.q
    unknown = [a for a in spec.assumed if a.role in ("robtarget", "jointtarget", "wobjdata", "tooldata")]
    moves = [st for st in spec.steps if st.kind == "move"]
    why = next((w for st in moves for w in st.kept if "an unknown target" in w), None)
    if not unknown and why is not None and all(st.kept for st in moves):
        said = why.split("; the move to it", 1)[0]
        if len(said) > 200:  # where and why only, never cut in a path: its run-time sources are listed
            said = said.split(" (", 1)[0]
        raise InvalidInput(f"no move of the cycle can be planned: its targets are unknown ({said})")
    if unknown and all(st.kept for st in moves):
        names = ", ".join(sorted({a.name for a in unknown})[:6])
        shared = all(getattr(a, "shared", False) for a in unknown)
        where = (
            "PERS data declared without a value (another task's)"
            if shared
            else "declared nowhere in what was given"
        )
        raise InvalidInput(
            f"{spec.source}: no move of the cycle can be planned: its targets are unknown (they come from "
            f"{names}, {where}); give the module that declares them, or their "
            "values in the scenario file ([targets], [wobj.NAME], [tool.NAME])"
        )
    inputs = sorted(inputs_read(spec.choices))
    hint = (
        f"; it reads inputs taken as 0 ({listed(inputs, 4)}): where they choose its work, give them "
        "with --io NAME=VALUE"
        if inputs
        else ": give targets that differ"
    )
    raise InvalidInput(
        f"{spec.source}: the cycle does not move the arm (every move goes where the arm already is); "
        f"nothing to optimize{hint}"
    )


def read_cycle_program(
    path: str | Path | Sequence[str | Path],
    robot: Robot,
    *,
    idle_waits: Collection[int] = (),
    progress: Callable[[str], None] | None = None,
    io: Mapping[str, float | str | bool] | None = None,
    routine: str | None = None,
    seed: int = 0,
    given: Mapping[str, Any] | None = None,
) -> tuple[CycleSpec, bool]:
    """A program's cycle and whether it is RAPID: a ``.toml`` cycle file, else a RAPID task.

    ``path``: a ``.toml`` cycle file, or a RAPID task: one module, several modules, or a folder
    (the task's modules). The task is run by the RAPID interpreter
    (:func:`joulepath.program._task.read_task_cycle`): ``io`` is the I/O scenario, ``routine``
    the routine to run instead of ``main``, ``seed`` the seed of its random numbers.

    ``idle_waits``: lines of ``WaitTime`` instructions that are idle time (see
    :func:`resolve_module`); for a ``.toml`` file, numbers of ``wait_s`` steps. A module
    joulepath wrote is read as the program it was written from (its targets as they are
    now: re-taught ones included; :func:`joulepath.program._rapid_write.restore_program`).
    ``progress`` (optional) is told each move (or step) read once the cycle is within the
    moves limit.
    """
    paths = [Path(path)] if isinstance(path, (str, Path)) else [Path(p) for p in path]
    if not paths:
        raise InvalidInput("no program given: name a RAPID module, a task's folder or a .toml cycle file")
    if len(paths) == 1 and paths[0].suffix.lower() == ".toml":
        return _read_toml_with_waits(paths[0], robot, idle_waits, progress), False
    if any(p.suffix.lower() == ".toml" for p in paths):
        raise InvalidInput(
            f"{', '.join(map(str, paths))}: a .toml cycle file is a whole program on its own; give it alone"
        )
    restored = _restored(paths)
    spec = read_rapid_cycle(
        [restored] if restored is not None else paths,
        robot,
        idle_waits=idle_waits,
        progress=progress,
        io=io,
        routine=routine,
        seed=seed,
        given=given,
    )
    module, static_note = _static_view(spec, robot, routine, io)
    if restored is not None:
        spec = replace(spec, source=f"{path} (the program it was optimized from)")
    if module is None:
        return replace(spec, static_note=static_note), True
    return replace(spec, steps=module[1], module=module[0]), True


def read_rapid_cycle(
    paths: Sequence[Path],
    robot: Robot,
    *,
    idle_waits: Collection[int] = (),
    progress: Callable[[str], None] | None = None,
    io: Mapping[str, float | str | bool] | None = None,
    routine: str | None = None,
    seed: int = 0,
    given: Mapping[str, Any] | None = None,
) -> CycleSpec:
    """A RAPID task's cycle as the interpreter runs it, as written (a module joulepath wrote included).

    ``paths``: one module, several modules, or a task's folder; the other arguments as for
    :func:`read_cycle_program`. The steps are the interpreter's trace
    (:func:`joulepath.program._task.read_task_cycle`); no static view is attached.
    """
    from joulepath.program._task import read_task_cycle

    tc = read_task_cycle(
        list(paths), robot, io=io, routine=routine, seed=seed, progress=progress, given=given
    )
    steps = _mark_idle(tc, idle_waits)
    moves = [st for st in steps if st.kind == "move"]
    assert moves[-1].q is not None
    fixed = tuple(st.line for st in steps if st.kind == "fixed")
    return CycleSpec(
        steps,
        moves[-1].q.copy(),
        tc.task.source,
        None,
        fixed,
        robot,
        tc.trace.notes,
        kept=tc.kept,
        task=tc,
        assumed=tc.trace.assumed,
    )


def _restored(paths: Sequence[Path]) -> Path | None:
    """A module joulepath wrote, restored as the program it was written from (in a private temp file)."""
    if len(paths) != 1 or not paths[0].is_file():
        return None
    from joulepath.program._rapid_write import restore_program
    from joulepath.rapid import decode

    raw = read_capped(paths[0], max_bytes=MAX_MODULE_BYTES, what="a RAPID module", error=RapidError)
    text, _, _ = decode(raw)
    original = restore_program(text)
    if original is None:
        return None
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="joulepath-restored-"))
    out = folder / paths[0].name
    out.write_text(original, encoding="utf-8")
    return out


def _mark_idle(tc: object, idle_waits: Collection[int]) -> tuple[Step, ...]:
    from joulepath.program._task import TaskCycle
    from joulepath.rapid.interpreter import Wait

    assert isinstance(tc, TaskCycle)
    lines = set(idle_waits)
    waits = {
        st.line
        for st in tc.steps
        if st.kind == "wait" and isinstance(st.statement, Wait) and not st.statement.io
    }
    for line in sorted(lines):
        if line not in waits:
            raise RapidError(
                f"{tc.task.source}:{line}: idle_waits names line {line}, "
                f"which is not a WaitTime the cycle runs; "
                "name the line of a WaitTime (or mark it '! joulepath: idle')"
            )
    out = []
    for st in tc.steps:
        if st.kind == "wait" and isinstance(st.statement, Wait) and not st.statement.io:
            module = tc.task.module_of(st.statement.pos.file)
            source = [] if module is None else module.text.split("\n")
            text = source[st.line - 1] if st.line - 1 < len(source) else ""
            before = source[st.line - 2].strip() if 2 <= st.line <= len(source) else ""
            marked = "joulepath: idle" in text.lower() or (
                before.startswith("!") and "joulepath: idle" in before.lower()
            )
            if marked or st.line in lines:
                st = replace(st, idle=True)
        out.append(st)
    return tuple(out)


def _static_view(
    spec: CycleSpec,
    robot: Robot,
    routine: str | None,
    io: Mapping[str, float | str | bool] | None,
) -> tuple[tuple[Module, tuple[Step, ...]] | None, str]:
    """The static module view the via-point RAPID writer edits, where the task is one module that the
    static subset reader also reads to the same cycle (same statements, same targets to 1e-9 rad);
    the steps then carry its statements. Else None (the task is written as EGM) and why, in words."""
    from joulepath.program._task import TaskCycle

    tc, steps = spec.task, spec.steps
    assert isinstance(tc, TaskCycle)
    modules = len(tc.task.modules)
    why = (
        f"spans {modules} modules"
        if modules != 1
        else f"runs the routine {routine}, not main"
        if routine is not None
        else "reads an I/O scenario"
        if io
        else f"keeps {len(tc.kept)} move(s) as taught"
        if tc.kept
        else ""
    )
    if why:
        return None, why
    m = tc.task.modules[0]
    try:
        module = parse_module(m.text, path=m.path)
        old = resolve_module(module, robot)
    except (RapidError, InvalidInput, AssertionError) as err:
        return None, f"holds what the writer's static reader does not read ({str(err)[:160]})"
    if len(old.steps) != len(steps):
        return None, "runs other steps than the writer's static reader reads (calls, loops or waits)"
    out = []
    for a, b in zip(old.steps, steps, strict=True):
        if a.kind != b.kind or a.line != b.line:
            return None, f"runs other steps than the writer's static reader reads (line {b.line})"
        if a.kind == "move":
            assert a.q is not None and b.q is not None
            if np.abs(a.q - b.q).max() > 1e-9:
                if tc.task.moc is not None and tc.task.moc.moves_the_base:
                    return (
                        None,
                        "has its base frame from MOC.cfg, which the writer's static reader does not apply",
                    )
                return None, f"places line {b.line}'s target elsewhere than the writer's static reader does"
        out.append(replace(b, statement=a.statement))
    return (module, tuple(out)), ""


def _read_toml_with_waits(
    p: Path, robot: Robot, idle_waits: Collection[int], progress: Callable[[str], None] | None
) -> CycleSpec:
    spec = read_cycle_toml(p, robot, progress=progress)
    if not idle_waits:
        return spec
    steps = list(spec.steps)
    for k in sorted(set(idle_waits)):
        if not 1 <= k <= len(steps) or steps[k - 1].kind != "wait":
            raise InvalidInput(
                f"{p}: idle_waits names step {k}, which is not a wait_s step; name a wait step"
            )
        steps[k - 1] = replace(steps[k - 1], idle=True)
    return replace(spec, steps=tuple(steps))
