"""Motion: the move instructions (:data:`MOTIONS`, by name), and where the robot is and goes.

A move's arguments are classified by their values' types (target, speed, zone, tool, work object);
what it does not know (a target declared nowhere or given at run time, a process's speed, a search's
end, a coordinated work object) keeps it as taught. With a robot model, a target is solved to joints
as the controller reaches it (:func:`solve`); the functions that ask where the robot is (``CRobT``,
``CJointT``, ``CalcJointT`` ...) read it here too (:func:`robtarget_at`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.errors import RapidError
from joulepath.rapid import geometry as geo
from joulepath.rapid import nodes as n
from joulepath.rapid._machine import CallHandler, Machine
from joulepath.rapid._state import UNKNOWN_TARGET
from joulepath.rapid._trace import CLEAN, Motion, Taint, run_time
from joulepath.rapid._vocabulary import (
    ABSJ_MOTIONS,
    CIRCULAR_MOTIONS,
    EGM_MOTIONS,
    JOINT_MOTIONS,
    LINEAR_MOTIONS,
    PROCESS_CIRCULAR,
    PROCESS_LINEAR,
    RAPID_AXES,
    SEARCH_MOTIONS,
)
from joulepath.rapid.values import Record, TypeErrorRapid, Value, num


@dataclass(slots=True)
class _Move:
    """A move's arguments, classified by their values' types, each with the reasons it is uncertain."""

    targets: list[tuple[Record, Taint, str]]
    speed: Record
    speed_t: Taint
    zone: Record
    zone_t: Taint
    tool: Record
    tool_t: Taint
    tool_name: str
    opt: dict[str, n.Arg]
    wobj: Record
    wobj_t: Taint = CLEAN
    wobj_name: str = "wobj0"
    time_s: float | None = None


def _kind(key: str) -> str:
    if key in JOINT_MOTIONS:
        return "joint"
    if key in LINEAR_MOTIONS or key in PROCESS_LINEAR or key == "searchl":
        return "linear"
    if key in CIRCULAR_MOTIONS or key in PROCESS_CIRCULAR or key == "searchc":
        return "circular"
    if key in ABSJ_MOTIONS:
        return "absjoint"
    return "joint"


def _arguments(ip: Machine, s: n.Call, key: str, kind: str) -> _Move:
    """The move's target(s), speed, zone and tool, by the types of its positional arguments' values."""
    targets: list[tuple[Record, Taint, str]] = []
    speed = zone = tool = None
    speed_t = zone_t = tool_t = CLEAN
    tool_name = "tool0"
    for a in s.args:
        if a.kind != "pos" or a.value is None:
            continue
        v, t = ip.ev(a.value)
        text = _text_of(a, s.pos)
        want = "jointtarget" if kind == "absjoint" else "robtarget"
        if isinstance(v, tuple) and len(targets) < (2 if kind == "circular" else 1):
            try:
                v = ip.types.coerce(v, want)
            except TypeErrorRapid:
                pass
        if isinstance(v, Record):
            if v.type in ("robtarget", "jointtarget") and len(targets) < (2 if kind == "circular" else 1):
                targets.append((v, t, text))
            elif v.type == "speeddata" and speed is None:
                speed, speed_t = v, t
            elif v.type == "zonedata" and zone is None:
                zone, zone_t = v, t
            elif v.type == "tooldata" and tool is None:
                tool, tool_t, tool_name = v, t, text
    args_opt = {a.name.lower(): a for a in s.args if a.kind == "opt" and a.name}
    if not targets or speed is None or tool is None or (zone is None and key not in SEARCH_MOTIONS):
        missing = (
            "a target"
            if not targets
            else "a speeddata"
            if speed is None
            else ("a tooldata" if tool is None else "a zonedata")
        )
        raise RapidError(f"{s.pos}: {s.name} needs {missing}; correct the instruction")
    if zone is None:
        fine = ip.predefined["fine"].value
        assert isinstance(fine, Record)
        zone = fine
    if (speed_t or ip.ctx_taint) and not all(isinstance(v, float) and v > 0 for v in speed.values[:2]):
        fallback = ip.predefined["v1000"].value
        assert isinstance(fallback, Record)
        how = "comes at run time" if speed_t else "is set in a branch taken on run-time data"
        ip.note(f"{s.pos}: {s.name}: its speed {how} and its stand-in is not a speed: v1000 taken")
        speed = fallback
    _check_motion_data(speed, zone, s)
    if kind == "circular" and len(targets) < 2:
        raise RapidError(f"{s.pos}: {s.name} needs a circle point and a target; correct the instruction")
    wobj = ip.predefined["wobj0"].value
    assert isinstance(wobj, Record)
    return _Move(targets, speed, speed_t, zone, zone_t, tool, tool_t, tool_name, args_opt, wobj)


def _optional_arguments(ip: Machine, s: n.Call, mv: _Move) -> None:
    """``\\WObj``, ``\\V``, ``\\T`` and ``\\Z`` applied to the move."""
    for name, a in mv.opt.items():
        if a.value is None:
            continue
        v, t = ip.ev(a.value)
        v = ip.signal_value(v, a.pos)
        if name == "wobj":
            wobj = ip.types.coerce(v, "wobjdata")
            assert isinstance(wobj, Record)
            mv.wobj, mv.wobj_t, mv.wobj_name = wobj, t, _text_of(a, s.pos, value=True)
        elif name == "v":
            mv.speed = mv.speed.replace("v_tcp", ip.as_num(v, a.pos))
            mv.speed_t |= t
        elif name == "t":
            mv.time_s = ip.as_num(v, a.pos)
            if mv.time_s <= 0:
                raise RapidError(f"{a.pos}: \\T:={mv.time_s:g}: a move's time is positive")
            mv.speed_t |= t
        elif name == "z":
            mv.zone = mv.zone.replace("pzone_tcp", ip.as_num(v, a.pos))
            mv.zone_t |= t


def _check_targets(s: n.Call, kind: str, targets: list[tuple[Record, Taint, str]]) -> None:
    """Each target of the type the move goes to, with a unit quaternion; one never given an orientation
    is marked as an unknown target."""
    want = "jointtarget" if kind == "absjoint" else "robtarget"
    for rec, _, text in targets:
        if rec.type != want:
            fix = "use MoveAbsJ" if want == "robtarget" else "use MoveJ (or give a jointtarget)"
            raise RapidError(f"{s.pos}: {s.name} goes to a {want}; {text} is a {rec.type}: {fix}")
    for k, (rec, t, text) in enumerate(targets):
        if rec.type == "robtarget" and not t:
            q = geo.orient_values(rec.get("rot"))
            norm = math.sqrt(sum(v * v for v in q))
            if norm == 0.0:  # no orientation at all: never given a value here (filled at run time)
                why = f"{s.pos}: {text} has no orientation, never given a value here: {UNKNOWN_TARGET}"
                targets[k] = (rec, frozenset({why}), text)
                continue
            if abs(norm - 1.0) > 1e-3:
                raise RapidError(
                    f"{s.pos}: {text}: its orientation {list(q)} is not a unit quaternion "
                    f"(norm {norm:.4g}); "
                    "correct it (or NOrient it)"
                )


def _kept(s: n.Call, key: str, mv: _Move, taint: Taint, circular: bool) -> set[str]:
    """Why the move must stay as taught, but for an unknown target (empty: it is known)."""
    kept = set(run_time(taint | mv.targets[-1][1] | mv.speed_t | mv.zone_t | mv.tool_t | mv.wobj_t))
    if circular:
        kept |= run_time(mv.targets[0][1])
    if key in EGM_MOTIONS:
        kept.add(f"{s.pos}: {s.name}: its path is corrected by a sensor through EGM while it runs")
    elif key in PROCESS_LINEAR or key in PROCESS_CIRCULAR:
        kept.add(f"{s.pos}: {s.name} is a process instruction: its speed is the process's")
    if key in SEARCH_MOTIONS:
        kept.add(f"{s.pos}: {s.name} stops where its signal comes: its end is known only at run time")
    if bool(mv.wobj.get("robhold")) and bool(mv.tool.get("robhold")):
        raise RapidError(f"{s.pos}: both the tool and the work object are held by the robot; one must stand")
    if str(mv.wobj.get("ufmec")).strip() or not bool(mv.wobj.get("ufprog")):
        kept.add(f"{s.pos}: the work object {mv.wobj_name} moves with a mechanical unit (coordinated)")
    if "conc" in mv.opt:
        kept.add(f"{s.pos}: \\Conc: the instructions after it run while it moves")
    return kept


def _joints(
    ip: Machine, s: n.Call, kind: str, mv: _Move, target: Record, circle: Record | None, target_text: str
) -> tuple[FloatArray | None, FloatArray | None]:
    """The joints (rad) of a known move's target and circle point, where a robot model is given."""
    joints = circle_joints = None
    if ip.kin is None:
        return None, None
    if kind == "absjoint":
        axes = np.radians(robax(target))
        joints = ip.kin.axes_to_joints(axes)
        bad = ip.kin.in_range(joints)
        why = (
            ip.kin.axes_outside(axes)
            if bad is None
            else f"joint {bad + 1} = {math.degrees(joints[bad]):.2f} deg is outside this robot's range"
        )
        if why is not None:
            raise RapidError(
                f"{s.pos}: {target_text}: {why}: correct the jointtarget, or give the robot it was "
                "taught on with --robot"
            )
    else:
        linear = kind in ("linear", "circular")
        joints = solve(ip, target, mv.tool, mv.wobj, s.pos, f"{s.name} {target_text}", linear=linear)
        if circle is not None:
            circle_joints = solve(ip, circle, mv.tool, mv.wobj, s.pos, f"{s.name} circle point", linear=True)
    return joints, circle_joints


def motion(ip: Machine, s: n.Call, key: str) -> None:
    """A move: its target, speed, zone, tool and work object, classified by the values' types."""
    kind = _kind(key)
    taint = ip.ctx_taint | ip.after_branch
    start_taint = ip.current_taint  # the move starts where the last one ended
    ip.after_branch = CLEAN
    mv = _arguments(ip, s, key, kind)
    inpos = "inpos" in mv.opt
    _optional_arguments(ip, s, mv)
    circle = mv.targets[0][0] if kind == "circular" else None
    target, _, target_text = mv.targets[-1]
    _check_targets(s, kind, mv.targets)
    target_t = mv.targets[-1][1]
    kept = _kept(s, key, mv, taint | start_taint, circle is not None)
    process = s.name if key in PROCESS_LINEAR or key in PROCESS_CIRCULAR else None
    joints = circle_joints = None
    unknown = _unknown_target(ip, mv.targets, mv.tool, mv.wobj, s, kind, mv.tool_name, mv.wobj_name)
    if unknown is not None:
        kept.add(unknown)
        joints = _where_the_arm_is(ip)
        if joints is not None:
            circle_joints = joints if circle is not None else None
            target = (
                jointtarget(ip, joints) if kind == "absjoint" else robtarget_at(ip, joints, mv.tool, mv.wobj)
            )
            circle = target if circle is not None else None
    else:
        joints, circle_joints = _joints(ip, s, kind, mv, target, circle, target_text)
    m = Motion(
        instruction=s.name,
        kind=kind,
        target=target,
        circle=circle,
        speed=mv.speed,
        time_s=mv.time_s,
        zone=mv.zone,
        inpos=inpos,
        tool=mv.tool,
        wobj=mv.wobj,
        tool_name=mv.tool_name,
        wobj_name=mv.wobj_name,
        settings=ip.settings,
        conc="conc" in mv.opt,
        process=process,
        stmt=s,
        context=ip.context(),
        kept=frozenset(kept),
        joints=joints,
        circle_joints=circle_joints,
        target_text=target_text,
    )
    ip.events.append(m)
    if joints is not None:
        ip.current_q = joints
    ip.current_taint = target_t | ip.ctx_taint | mv.wobj_t | mv.tool_t
    if unknown is not None:
        ip.current_taint = ip.current_taint | frozenset({unknown})
    if ip.progress is not None and len(ip.events) % 50 == 0:
        ip.progress(f"reading the program: {_moves(ip)} moves")


def _check_motion_data(speed: Record, zone: Record, s: n.Call) -> None:
    """A move's speed data positive and its zone sizes not negative, as the controller checks them."""
    for k, v in enumerate(speed.values[:2]):
        if isinstance(v, float) and not v > 0:
            what = ("v_tcp", "v_ori")[k]
            raise RapidError(f"{s.pos}: {s.name}: its speed data's {what} is {v:g}; a speed is positive")
    for name, v in zip(zone.names, zone.values, strict=True):
        if isinstance(v, float) and v < 0:
            raise RapidError(
                f"{s.pos}: {s.name}: its zone data's {name} is {v:g}; a zone's size is 0 or more"
            )


def _where_the_arm_is(ip: Machine) -> FloatArray | None:
    """The arm's joints now: the last move's end, else every joint at 0 (the calibration position)."""
    if ip.kin is None:
        return None
    if ip.current_q is not None:
        return ip.current_q.copy()
    q = np.zeros(RAPID_AXES)
    return q if ip.kin.in_range(q) is None else None


def _unknown_target(
    ip: Machine,
    targets: list[tuple[Record, Taint, str]],
    tool: Record,
    wobj: Record,
    s: n.Call,
    kind: str,
    tool_name: str = "",
    wobj_name: str = "",
) -> str | None:
    """Why the move's target is unknown (None: it is known): declared nowhere, or known only at run
    time and its stand-in out of reach. Such a move is placed where the arm is and kept as taught."""
    for _rec, t, _text in targets:
        marked = next((w for w in sorted(t) if UNKNOWN_TARGET in w), None)
        if marked is not None:
            return f"{marked}; the move to it and the one after it are kept as taught"
    if ip.kin is None or kind == "absjoint":
        return None
    stand_in = next(
        (a for a in ip.assumed if a.role in ("wobjdata", "tooldata") and a.name in (tool_name, wobj_name)),
        None,
    )
    for rec, t, text in targets:
        if rec.type != "robtarget":
            continue
        if not t and stand_in is not None:  # placed by a stand-in frame: where it lies is not known
            try:
                solve(ip, rec, tool, wobj, s.pos, f"{s.name} {text}")
            except (RapidError, ValueError):
                return (
                    f"{s.pos}: {text} is {UNKNOWN_TARGET}: it lies in {stand_in.name}, declared nowhere "
                    f"in what was given ({stand_in.role}, give it in the scenario file); the move to it "
                    "and the one after it are kept as taught"
                )
            continue
        if not t:
            continue
        try:
            solve(ip, rec, tool, wobj, s.pos, f"{s.name} {text}")
        except (RapidError, ValueError):  # out of reach, or no orientation at all
            return (
                f"{s.pos}: {text} is {UNKNOWN_TARGET}: its value comes at run time "
                f"({'; '.join(sorted(t))}); the move to it and the one after it are kept as taught"
            )
    return None


def solve(
    ip: Machine, rt: Record, tool: Record, wobj: Record, pos: n.Pos, what: str, *, linear: bool = False
) -> FloatArray:
    """Joint values (rad) of a robtarget in ``wobj`` with ``tool``, as the controller reaches it.

    A joint move with ``ConfJ \\On`` goes to the target's confdata; where no solution matches it
    exactly, the solution nearest the arm whose quadrants of axes 1, 4 and 6 lie within one of the
    programmed ones and whose ``cfx`` is the programmed one is taken, with a warning (the
    controller's configuration monitoring allows a quadrant's change); else the controller stops,
    and so is the program refused. With ``ConfJ \\Off`` it goes to the programmed configuration
    where that is reachable, else to the solution nearest the arm. A linear or circular move's
    configuration follows its path from where the arm is (``ConfL`` only monitors it): the
    solution nearest the arm, with a warning where its confdata is not the programmed one. Out of
    reach: refused, saying how far the target lies beyond the robot's reach (a program for a
    larger arm).
    """
    assert ip.kin is not None
    flange = np.linalg.inv(ip.base) @ target_flange(rt, tool, wobj, ip.pdisp)
    conf = conf_of(rt) if (ip.settings.conf_l if linear else ip.settings.conf_j) else None
    if not linear and conf is None:
        # ConfJ \Off: "the closest axis configuration", which ABB says differs from the programmed one
        # only where that is wrong (written by hand, or displaced): the programmed one where it is
        # reachable, else the solution nearest the arm
        q = ip.kin.joints(flange, conf_of(rt), ip.current_q)
        q = ip.kin.joints(flange, None, ip.current_q) if q is None else q
        if q is None:
            raise RapidError(f"{pos}: {what}: {_beyond_reach(ip, rt, flange)}")
        return q
    q = ip.kin.joints(flange, conf, ip.current_q)
    if q is None:
        q = ip.kin.joints(flange, None, ip.current_q)
        if q is not None and conf is not None:
            q = _toward_quadrants(ip, q, conf)
            got = ip.kin.confdata(q)
            if not linear and (got[3] != conf[3] or any(abs(got[k] - conf[k]) > 1 for k in range(3))):
                raise RapidError(
                    f"{pos}: {what}: no joint solution matches the target's confdata {list(conf)} (the "
                    f"reachable one nearest the arm is {list(got)}); the controller stops here with "
                    "ConfJ \\On: correct the confdata, or ConfJ \\Off"
                )
            if got != conf:
                ip.note(
                    f"{pos}: {what}: its confdata {list(conf)} matches no joint solution exactly; "
                    f"moved as the controller moves it, to {list(got)} (the solution nearest the arm)"
                )
    if q is None:
        raise RapidError(f"{pos}: {what}: {_beyond_reach(ip, rt, flange)}")
    return q


def _toward_quadrants(ip: Machine, q: FloatArray, conf: tuple[int, int, int, int]) -> FloatArray:
    """``q`` with axes 1, 4 and 6 turned by whole turns toward the programmed quadrants (``cf1``,
    ``cf4``, ``cf6``), where the turned value stays within the axis' range: the same pose."""
    assert ip.kin is not None
    out = q.copy()
    for axis, cf in ((0, conf[0]), (3, conf[1]), (5, conf[2])):
        centre = (cf + 0.5) * (math.pi / 2)
        turns = round((centre - out[axis]) / (2 * math.pi))
        if turns:
            trial = out.copy()
            trial[axis] += turns * 2 * math.pi
            if ip.kin.in_range(trial) is None:
                out = trial
    return out


def _beyond_reach(ip: Machine, rt: Record, flange: FloatArray) -> str:
    where = [round(float(v), 1) for v in (geo.pose_matrix(rt)[:3, 3] * 1000.0)]
    reach = ip.kin.reach_m() if ip.kin is not None else None
    far = float(np.linalg.norm(flange[:3, 3]))
    if reach is not None and far > reach:
        return (
            f"{1000 * far:.0f} mm from the robot's base, {1000 * (far - reach):.0f} mm beyond its reach "
            f"({1000 * reach:.0f} mm): probably a program for a larger arm; give it with --robot"
        )
    return (
        f"the target at {where} mm (in its work object) is out of the robot's reach with this "
        "orientation and tool; move the target (or give the robot it was taught on with --robot)"
    )


def robtarget_at(ip: Machine, q: FloatArray, tool: Record, wobj: Record) -> Record:
    assert ip.kin is not None
    flange = ip.base @ ip.kin.flange(q)
    tcp = flange @ geo.pose_matrix(_as_record(tool.get("tframe")))
    obj = _wobj_matrix(wobj)
    in_obj = np.linalg.inv(obj) @ tcp
    rt = ip.types.default("robtarget")
    assert isinstance(rt, Record)
    rt = geo.with_pose(rt, in_obj)
    conf = ip.kin.confdata(q)
    rt = rt.replace("robconf", ip.types.coerce(tuple(float(c) for c in conf), "confdata"))
    ext = ip.types.coerce((9e9,) * 6, "extjoint")
    return rt.replace("extax", ext)


def _moves(ip: Machine) -> int:
    return sum(isinstance(e, Motion) for e in ip.events)


MOTIONS: dict[str, CallHandler] = {
    key: motion
    for key in (
        *JOINT_MOTIONS,
        *LINEAR_MOTIONS,
        *CIRCULAR_MOTIONS,
        *ABSJ_MOTIONS,
        *sorted(PROCESS_LINEAR),
        *sorted(PROCESS_CIRCULAR),
        *SEARCH_MOTIONS,
    )
}
"""The move instructions (by name in lower case) -> their handler."""


def _as_record(v: Value) -> Record:
    assert isinstance(v, Record)
    return v


def robax(jt: Record) -> FloatArray:
    """A ``jointtarget``'s ``robax`` as written: the controller's axis values (deg)."""
    rob = _as_record(jt.get("robax"))
    return np.array([num(v) for v in rob.values], dtype=float)


def joints_of(ip: Machine, jt: Record) -> FloatArray:
    """The model's serial joints (rad) of a ``jointtarget``: its axis values converted (a robot given)."""
    assert ip.kin is not None
    return ip.kin.axes_to_joints(np.radians(robax(jt)))


def jointtarget(ip: Machine, q: FloatArray) -> Record:
    """The ``jointtarget`` of serial joints ``q`` (rad): the controller's axis values (deg) in ``robax``."""
    axes = q if ip.kin is None else ip.kin.joints_to_axes(q)
    deg = tuple(float(v) for v in np.degrees(axes)[:6])
    deg = deg + (0.0,) * (6 - len(deg))
    out = ip.types.coerce((deg, (9e9,) * 6), "jointtarget")
    assert isinstance(out, Record)
    return out


def conf_of(rt: Record) -> tuple[int, int, int, int]:
    c = _as_record(rt.get("robconf"))
    return tuple(int(round(num(v))) for v in c.values)  # type: ignore[return-value]


def _wobj_matrix(wobj: Record) -> FloatArray:
    return geo.pose_matrix(_as_record(wobj.get("uframe"))) @ geo.pose_matrix(_as_record(wobj.get("oframe")))


def target_flange(rt: Record, tool: Record, wobj: Record, pdisp: FloatArray | None = None) -> FloatArray:
    """Where the flange must be (base frame, m) for the TCP of ``tool`` to be at ``rt`` in ``wobj``.

    A robot-held tool (the usual case): ``flange = uframe oframe [pdisp] target tframe^-1``. A
    stationary tool with a robot-held work object: the target is fixed to the work object on the
    flange, the TCP stands in the world: ``flange = tframe target^-1 (uframe oframe)^-1``.
    """
    target = geo.pose_matrix(rt)
    if pdisp is not None:
        target = pdisp @ target
    tframe = geo.pose_matrix(_as_record(tool.get("tframe")))
    obj = _wobj_matrix(wobj)
    if bool(wobj.get("robhold")) and not bool(tool.get("robhold")):
        out: FloatArray = tframe @ np.linalg.inv(target) @ np.linalg.inv(obj)
        return out
    result: FloatArray = obj @ target @ np.linalg.inv(tframe)
    return result


def _text_of(a: n.Arg, pos: n.Pos, *, value: bool = False) -> str:
    e = a.value
    if isinstance(e, n.Name):
        return e.name
    if isinstance(e, n.FuncCall):
        inner = e.args[0].value if e.args else None
        return f"{e.name}({inner.name if isinstance(inner, n.Name) else '...'}, ...)"
    if isinstance(e, n.Index) and isinstance(e.base, n.Name):
        return f"{e.base.name}{{...}}"
    if isinstance(e, n.Aggregate):
        return "[...]"
    return "(expression)"
