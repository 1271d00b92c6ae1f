"""Built-in instructions that do not move the arm: waits, outputs, arithmetic on data, motion
settings, program displacement, and what the outside world writes, each by name in
:data:`INSTRUCTIONS`; an instruction of the documented table (:mod:`joulepath.rapid.builtins`) that
the cycle's model does not run is checked against its signature (:func:`documented_instruction`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from joulepath.errors import RapidError
from joulepath.rapid import builtins
from joulepath.rapid import geometry as geo
from joulepath.rapid import nodes as n
from joulepath.rapid._machine import CallHandler, Machine
from joulepath.rapid._scan import pairs, set_outside
from joulepath.rapid._state import CycleRestart, Ref
from joulepath.rapid._trace import CLEAN, Action, Wait
from joulepath.rapid._vocabulary import INPUT_WRITERS, IO_SETTERS, IO_WAITS, KNOWN_INSTRUCTIONS
from joulepath.rapid.values import Record, Signal, Value, equal, num


def _wait_time(ip: Machine, s: n.Call, key: str) -> None:
    ctx = ip.context()
    args, opt = ip.args_of(s.args)
    if not args:
        raise RapidError(f"{s.pos}: WaitTime needs a time in s")
    secs, t = args[0]
    seconds = ip.as_num(secs, s.pos)
    if seconds < 0:
        raise RapidError(f"{s.pos}: WaitTime {seconds:g} s: a time is not negative")
    note = ""
    if t:
        note = "its time is known only at run time: " + "; ".join(sorted(t))
    ip.events.append(Wait(s, seconds, "inpos" in opt, False, ctx, note))


def _set_output(ip: Machine, s: n.Call, key: str) -> None:
    ctx = ip.context()
    args, _ = ip.args_of(s.args, raw_first=True)
    if args and isinstance(args[0][0], Signal):
        sig = args[0][0]
        value: Value = (
            1.0
            if key in ("set", "pulsedo")
            else 0.0
            if key == "reset"
            else (args[1][0] if len(args) > 1 else 0.0)
        )
        ip.outputs[sig.name.lower()] = value if key != "pulsedo" else 0.0
    ip.events.append(Action(s, s.name, ctx))


def _change_num(ip: Machine, s: n.Call, key: str) -> None:
    """``Incr``, ``Decr``, ``Add`` and ``Clear`` of a num."""
    pos_args = [a for a in s.args if a.kind == "pos"]
    if not pos_args or pos_args[0].value is None:
        raise RapidError(f"{s.pos}: {s.name} needs a variable")
    target = ip.ref(pos_args[0].value)
    r = target if isinstance(target, Ref) else Ref(target)
    cur = ip.as_num(r.get(), s.pos)
    if key == "add":
        d, t = ip.ev(pos_args[1].value) if len(pos_args) > 1 and pos_args[1].value else (0.0, CLEAN)
        r.set(cur + ip.as_num(d, s.pos), r.cell.taint | t | ip.ctx_taint)
    else:
        new = 0.0 if key == "clear" else cur + (1.0 if key == "incr" else -1.0)
        r.set(new, r.cell.taint | ip.ctx_taint)


def _exit_cycle(ip: Machine, s: n.Call, key: str) -> None:
    raise CycleRestart(f"{s.pos}: ExitCycle ends the cycle")


def _other(ip: Machine, s: n.Call, key: str) -> None:
    """An instruction the interpreter knows and runs as no motion and no time (what it writes from the
    outside world marked)."""
    ctx = ip.context()
    if key in ("stop", "break"):
        ip.note(f"{s.pos}: {s.name} stops the program in manual runs; the cycle goes on after it")
    if key in INPUT_WRITERS or key not in KNOWN_INSTRUCTIONS:
        write_inputs(ip, s, key)
    ip.events.append(Action(s, s.name, ctx))


def io_wait(ip: Machine, s: n.Call, key: str) -> None:
    ctx = ip.context()
    args, opt = ip.args_of(s.args)
    if key == "waituntil":
        cond, t = args[0] if args else (True, CLEAN)
        cond = ip.signal_value(cond, s.pos)
        if isinstance(cond, float):
            cond = cond != 0.0
        known = not t
        met = cond is True
    else:
        args, opt = ip.args_of(s.args, raw_first=True)
        sig, t0 = args[0]
        v, t1 = ip.read_signal(sig, s.pos) if isinstance(sig, Signal) else (sig, CLEAN)
        want = args[1][0] if len(args) > 1 else 1.0
        t = t0 | t1 | (args[1][1] if len(args) > 1 else CLEAN)
        known = not t
        met = equal(v, want)
    note = ""
    outside = (
        set_outside(s.args[0].value, ip.globals, ip.signals_used)
        if key == "waituntil" and s.args and known and not met
        else CLEAN
    )
    if outside:  # a wait on data the task's own statements never met: the outside world ends it
        known, t = False, outside
    if known and not met and "maxtime" not in opt:
        raise RapidError(
            f"{s.pos}: {s.name} never ends: the scenario keeps its condition false; give the input's "
            "value in --io"
        )
    if not known:
        note = "the wait ends when the process says (assumed met): " + "; ".join(sorted(t))
        if not ip.ctx_taint:
            ip.note(f"{s.pos}: {s.name}: {note}")
    ip.events.append(Wait(s, 0.0, "inpos" in opt, True, ctx, note))


def setting(ip: Machine, s: n.Call, key: str) -> None:
    args, opt = ip.args_of(s.args)
    taint = CLEAN
    for _, t in args:
        taint |= t
    if taint:
        ip.note(f"{s.pos}: {s.name} takes values known only at run time; the values it holds now assumed")
    st = ip.settings
    vals = [ip.signal_value(v, s.pos) for v, _ in args]
    if key == "accset":
        acc, ramp = ip.as_num(vals[0], s.pos), ip.as_num(vals[1], s.pos)
        if not (0 < acc <= 100 and 0 < ramp <= 100):
            raise RapidError(f"{s.pos}: AccSet {acc:g}, {ramp:g}: both are percent, 1 to 100")
        st = replace(st, acc_pct=acc, ramp_pct=ramp)
    elif key == "velset":
        ov, vmax = ip.as_num(vals[0], s.pos), ip.as_num(vals[1], s.pos)
        if not (0 < ov <= 100) or vmax <= 0:
            raise RapidError(f"{s.pos}: VelSet {ov:g}, {vmax:g}: the override is 1 to 100 %, the max above 0")
        st = replace(st, vel_override_pct=ov, vel_max_mm_s=vmax)
    elif key == "gripload":
        load = ip.types.coerce(vals[0], "loaddata")
        assert isinstance(load, Record)
        name = s.args[0].value.name if s.args and isinstance(s.args[0].value, n.Name) else "load"
        st = replace(st, grip_load=load if num(load.get("mass")) > 0 else None, grip_load_name=name)
    elif key in ("confj", "confl"):
        on = "off" not in opt
        st = replace(st, conf_j=on) if key == "confj" else replace(st, conf_l=on)
    elif key == "singarea":
        mode = next((k for k in ("wrist", "lockaxis4", "off") if k in opt), "off")
        st = replace(st, sing_area=mode.capitalize())
    elif key == "pathacclim":  # PathAccLim AccLim [\AccMax], DecelLim [\DecelMax]: each on when TRUE
        lims = [v is True for v in vals[:2]] + [False, False]
        acc_max = ip.as_num(opt["accmax"][0], s.pos) if lims[0] and "accmax" in opt else None
        dec_max = ip.as_num(opt["decelmax"][0], s.pos) if lims[1] and "decelmax" in opt else None
        for what, lim in (("AccMax", acc_max), ("DecelMax", dec_max)):
            if lim is not None and not lim > 0:
                raise RapidError(f"{s.pos}: PathAccLim \\{what}:={lim:g}: give a positive m/s²")
        st = replace(st, path_acc_lim=(acc_max, dec_max))
    elif key == "worldacclim":
        world = ip.as_num(opt["acc"][0], s.pos) if "acc" in opt else None
        st = replace(st, world_acc_lim=world if world is not None and world > 0 else None)
    ip.settings = st
    ip.events.append(Action(s, s.name, ip.context()))


def displacement(ip: Machine, s: n.Call, key: str) -> None:
    if key == "pdispoff":
        ip.pdisp = None
    elif key == "pdispset":
        args, _ = ip.args_of(s.args)
        p = ip.types.coerce(args[0][0], "pose")
        assert isinstance(p, Record)
        ip.pdisp = geo.pose_matrix(p)
    else:
        raise RapidError(
            f"{s.pos}: PDispOn computes a displacement from the robot's position when it runs; "
            "use PDispSet with a pose, or remove it"
        )
    ip.events.append(Action(s, s.name, ip.context()))


def write_inputs(ip: Machine, s: n.Call, key: str) -> None:
    """Mark what an instruction that reads the outside world writes."""
    indices = INPUT_WRITERS.get(key, ())
    pos_args = [a for a in s.args if a.kind == "pos"]
    targets = [pos_args[i].value for i in indices if i < len(pos_args)]
    targets += [a.value for a in s.args if a.kind == "opt" and a.value is not None]
    why = frozenset({f"{s.pos}: {s.name} writes data known only at run time"})
    for e in targets:
        if isinstance(e, (n.Name, n.Index, n.Field)):
            try:
                target = ip.ref(e)
            except RapidError:
                continue
            r = target if isinstance(target, Ref) else Ref(target)
            if r.cell.storage in ("CONST", "IO"):
                continue
            key_name = r.cell.name.lower()
            if not r.path and ip.give(r):
                continue
            if key_name in ip.io:  # the scenario gives the value
                v = ip.io[key_name]
                ip.io_used.add(key_name)
                cur = r.get()
                if isinstance(cur, float) and isinstance(v, (int, float)):
                    r.set(float(v), CLEAN)
                elif isinstance(cur, str):
                    r.set(str(v), CLEAN)
                continue
            r.set(r.get(), r.cell.taint | why)


def documented_instruction(ip: Machine, s: n.Call, b: builtins.Builtin) -> None:
    """An instruction of RAPID or of an option (:mod:`joulepath.rapid.builtins`) that the cycle's
    model does not run: its arguments checked against its documented signature, what it writes
    from the outside world marked; one that moves the arm makes the next move's start unknown."""
    try:
        matched = builtins.match_arguments(b, pairs(s.args))
    except builtins.ArgumentError as err:
        raise RapidError(f"{s.pos}: {s.name}: {err}; correct its arguments ({b.signature})") from None
    whose = f"the {b.option} option's" if b.option else "a RAPID"
    if b.effect is builtins.Effect.MOVE:
        why = f"{s.pos}: {s.name} ({whose} instruction) moves the arm in a way joulepath does not model"
        ip.note(f"{why}: the move after it starts from where it leaves the arm")
        ip.after_branch = ip.after_branch | frozenset({why})
    elif b.name.lower() not in ip.assumed_routines:
        ip.assumed_routines.add(b.name.lower())
        ip.note(f"{s.pos}: {s.name}: {whose} instruction, run as no motion and no time")
    written = {p.name.lower() for p in b.writes}
    if written:
        _mark_written(ip, s, written, matched)
    ip.events.append(Action(s, s.name, ip.context()))


def _mark_written(ip: Machine, s: n.Call, written: set[str], matched: Mapping[str, n.Expr | None]) -> None:
    """Mark the arguments a documented instruction writes (with data known only at run time);
    ``matched``: its arguments by parameter (:func:`joulepath.rapid.builtins.match_arguments`)."""
    why = frozenset({f"{s.pos}: {s.name} writes data known only at run time"})
    for name, a in matched.items():
        if name.lower() not in written or not isinstance(a, (n.Name, n.Index, n.Field)):
            continue
        try:
            target = ip.ref(a)
        except RapidError:
            continue
        r = target if isinstance(target, Ref) else Ref(target)
        if r.cell.storage in ("CONST", "IO"):
            continue
        if not r.path and ip.give(r):
            continue
        r.set(r.get(), r.cell.taint | why)


INSTRUCTIONS: dict[str, CallHandler] = {
    **dict.fromkeys(sorted(KNOWN_INSTRUCTIONS | set(INPUT_WRITERS)), _other),
    "waittime": _wait_time,
    **dict.fromkeys(sorted(IO_WAITS | {"waituntil"}), io_wait),
    **dict.fromkeys(sorted(IO_SETTERS), _set_output),
    **dict.fromkeys(("incr", "decr", "add", "clear"), _change_num),
    **dict.fromkeys(
        ("accset", "velset", "gripload", "confj", "confl", "singarea", "pathacclim", "worldacclim"), setting
    ),
    **dict.fromkeys(("pdispset", "pdispoff", "pdispon"), displacement),
    "exitcycle": _exit_cycle,
}
"""The instructions the interpreter knows that do not move the arm (by name in lower case) -> their
handler."""
