"""Built-in functions: RAPID's maths, strings, poses and signal reads, and what is known only at run
time, each by name in :data:`FUNCTIONS`; a name none of them has is looked up in the documented table
(:mod:`joulepath.rapid.builtins`), else taken as a function declared nowhere, said once.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from joulepath.errors import RapidError
from joulepath.rapid import _standins as standins
from joulepath.rapid import builtins
from joulepath.rapid import geometry as geo
from joulepath.rapid import nodes as n
from joulepath.rapid._machine import Machine
from joulepath.rapid._motion import joints_of, jointtarget, robtarget_at, solve
from joulepath.rapid._routines import invoke
from joulepath.rapid._state import UNKNOWN_TARGET, Ref, parse_literal, show
from joulepath.rapid._trace import CLEAN, Taint
from joulepath.rapid._vocabulary import KNOWN_FUNCTIONS_UNKNOWN_RESULT, SIGNAL_FUNCS, STANDIN_RESULT
from joulepath.rapid.values import (
    Array,
    Record,
    Signal,
    TypeErrorRapid,
    Value,
    describe,
    make_orient,
    make_pos,
    num,
    pos_values,
)


def call_function(ip: Machine, e: n.FuncCall) -> tuple[Value, Taint]:
    """A function call: a FUNC of the task, else a built-in function (:data:`FUNCTIONS`, then the
    documented table of :mod:`joulepath.rapid.builtins`), else a function declared nowhere."""
    e = replace(e, args=ip.conditionals(e.args))
    found = ip.routine(e.name, e.pos)
    if found is not None:
        r, m = found
        if r.kind != "FUNC":
            raise RapidError(f"{e.pos}: {e.name} is a {r.kind}, not a FUNC; call it as an instruction")
        return invoke(ip, r, m, e.args, e.pos)
    key = e.name.lower()
    unevaluated = UNEVALUATED.get(key)
    if unevaluated is not None:
        return unevaluated(ip, e)
    pos, opt = ip.args_of(e.args, raw_first=key in SIGNAL_FUNCS)
    taint = CLEAN
    for _, t in pos:
        taint |= t
    for _, t in opt.values():
        taint |= t
    vals = [ip.signal_value(v, e.pos) if key not in SIGNAL_FUNCS else v for v, _ in pos]
    try:
        result = builtin_function(ip, key, e, vals, {k: v for k, (v, _) in opt.items()})
    except (TypeErrorRapid, IndexError, ValueError, ZeroDivisionError) as err:
        if not taint and not ip.ctx_taint:
            raise RapidError(f"{e.pos}: {e.name}: {err}; correct the arguments") from None
        # a stand-in of run-time data the function cannot take (or a value met only in a branch
        # taken on run-time data): its result is a stand-in too
        ip.note(f"{e.pos}: {e.name} of a stand-in value fails ({err}); its result is assumed")
        why = f"{e.pos}: {e.name} of a value met in a branch taken on run-time data: known only at run time"
        return _stand_in_result(ip, key), taint or frozenset({why})
    value, extra = result
    return value, taint | extra


def _stand_in_result(ip: Machine, key: str) -> Value:
    """The result a built-in function's failed call on a stand-in takes: its stated stand-in, else
    the zero value of the type the function returns (:mod:`joulepath.rapid.builtins`), else 0."""
    if key in STANDIN_RESULT:
        return STANDIN_RESULT[key]
    found = builtins.lookup(key)
    if found is None or found.returns is None:
        return 0.0
    try:
        return ip.types.default(found.returns)
    except RapidError:
        return 0.0


def _present(ip: Machine, e: n.FuncCall) -> tuple[Value, Taint]:
    if not e.args or not isinstance(e.args[0].value, n.Name):
        raise RapidError(f"{e.pos}: Present needs a parameter's name")
    name = e.args[0].value.name.lower()
    frame = ip.stack[-1]
    return (name in frame.present), CLEAN


def _dim(ip: Machine, e: n.FuncCall) -> tuple[Value, Taint]:
    if len(e.args) != 2 or e.args[0].value is None or e.args[1].value is None:
        raise RapidError(f"{e.pos}: Dim needs an array and a dimension number")
    arr, t = ip.ev(e.args[0].value)
    d, _ = ip.ev(e.args[1].value)
    if not isinstance(arr, Array):
        raise RapidError(f"{e.pos}: Dim of {describe(arr)}, which is not an array")
    k = int(ip.as_num(d, e.pos))
    if not 1 <= k <= len(arr.dims):
        raise RapidError(f"{e.pos}: Dim asks for dimension {k} of an array of {len(arr.dims)}")
    return float(arr.dims[k - 1]), t


def builtin_function(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    """A built-in function of evaluated arguments: its handler in :data:`FUNCTIONS`; else one the
    documented table knows, its value unknown; else a function declared nowhere, said once."""
    handler = FUNCTIONS.get(key)
    if handler is not None:
        return handler(ip, key, e, a, opt)
    pos = e.pos
    documented = builtins.lookup(key)
    if documented is not None and documented.kind is builtins.Kind.FUNCTION:
        why = f"{pos}: {e.name}() " + (
            "is known only while the program runs"
            if documented.runtime
            else "is a RAPID function joulepath does not evaluate: its value is taken as unknown"
        )
        type_ = ip.types.resolve(documented.returns or "num")
        try:
            return ip.types.default(type_), frozenset({why})
        except (TypeErrorRapid, KeyError):
            return 0.0, frozenset({why})
    role = ip.roles.get(key, "value")
    if key not in ip.assumed_routines:
        ip.assumed_routines.add(key)
        said = (
            f"{UNKNOWN_TARGET} (its value is known only at run time)"
            if role in standins.TARGET_TYPES
            else "a value known only at run time (0 taken, and what it decides is marked)"
        )
        ip.assumed.append(standins.Assumption(e.name, "function", said, pos))
    reason = f"{pos}: the function {e.name} is declared nowhere in what was given: " + (
        UNKNOWN_TARGET if role in standins.TARGET_TYPES else "known only at run time"
    )
    if role in standins.TARGET_TYPES:
        return ip.types.default(role), frozenset({reason})
    return 0.0, frozenset({reason})


def _math(ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]) -> tuple[Value, Taint]:
    return _MATH[key](a, opt), CLEAN


def _string(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    return _STRING_FUNCS[key](a, opt), CLEAN


def _offs(ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]) -> tuple[Value, Taint]:
    p = ip.types.coerce(a[0], "robtarget")
    assert isinstance(p, Record)
    x, y, z = pos_values(p.get("trans"))
    return p.replace("trans", make_pos(x + num(a[1]), y + num(a[2]), z + num(a[3]))), CLEAN


def _reltool(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    p = ip.types.coerce(a[0], "robtarget")
    assert isinstance(p, Record)
    m = geo.pose_matrix(p)
    step = np.eye(4)
    step[:3, 3] = np.array([num(a[1]), num(a[2]), num(a[3])]) / 1000.0
    m = m @ step @ geo.rotation(0, num(opt.get("rx", 0.0))) @ geo.rotation(1, num(opt.get("ry", 0.0)))
    m = m @ geo.rotation(2, num(opt.get("rz", 0.0)))
    return geo.with_pose(p, m), CLEAN


def _orient_zyx(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    return make_orient(geo.orient_zyx(num(a[0]), num(a[1]), num(a[2]))), CLEAN


def _euler_zyx(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    o = ip.types.coerce(a[0], "orient")
    r = geo.quat_to_matrix(geo.orient_values(o))
    zyx = geo.euler_zyx_deg(r)
    k = 0 if "z" in opt else 1 if "y" in opt else 2
    return float(zyx[k]), CLEAN


def _n_orient(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    q = geo.orient_values(ip.types.coerce(a[0], "orient"))
    norm = math.sqrt(sum(v * v for v in q))
    return make_orient(tuple(v / norm for v in q)), CLEAN  # type: ignore[arg-type]


def _pose(ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]) -> tuple[Value, Taint]:
    t = ip.types
    p1 = t.coerce(a[0], "pose")
    assert isinstance(p1, Record)
    m1 = geo.pose_matrix(p1)
    if key == "poseinv":
        return geo.with_pose(p1, np.asarray(np.linalg.inv(m1), dtype=float)), CLEAN
    if key == "posemult":
        p2 = t.coerce(a[1], "pose")
        assert isinstance(p2, Record)
        return geo.with_pose(p1, m1 @ geo.pose_matrix(p2)), CLEAN
    v = np.array([*pos_values(t.coerce(a[1], "pos")), 1000.0]) / 1000.0
    v[3] = 1.0
    w = (m1 @ v)[:3] * 1000.0
    return make_pos(float(w[0]), float(w[1]), float(w[2])), CLEAN


def _read_input(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    sig = a[0]
    if not isinstance(sig, Signal):
        raise TypeErrorRapid(f"needs an I/O signal, not {describe(sig)}")
    level, taint = ip.read_signal(sig, e.pos)
    if key == "testdi":
        return (num(level) == 1.0), taint
    return level, taint


def _rand(ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]) -> tuple[Value, Taint]:
    why = f"{e.pos}: Rand() is a random number (the run's seed {ip.seed} gives the stand-in)"
    return float(ip.rng.random()), frozenset({why})


def _known_at_run_time(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    why = f"{e.pos}: {e.name}() is known only while the program runs"
    return KNOWN_FUNCTIONS_UNKNOWN_RESULT[key], frozenset({why})


def str_to_val(ip: Machine, e: n.FuncCall) -> tuple[Value, Taint]:
    """``StrToVal(Str, Val)``: the string read as a value of ``Val``'s type into ``Val``; TRUE if it
    reads. The string is parsed by the grammar as a RAPID literal, never executed."""
    args = [a for a in e.args if a.kind == "pos"]
    if len(args) != 2 or args[0].value is None or args[1].value is None:
        raise RapidError(f"{e.pos}: StrToVal needs a string and a variable")
    text, t = ip.ev(args[0].value)
    if not isinstance(text, str):
        raise RapidError(f"{e.pos}: StrToVal reads a string, not {describe(text)}")
    target = ip.ref(args[1].value)
    r = target if isinstance(target, Ref) else Ref(target)
    cur = r.get()
    ok = False
    value: Value = cur
    if len(text) <= 512 and not any(c in text for c in ";%\n"):
        try:
            node = parse_literal(text)
            v, _ = ip.ev(node)
            if isinstance(cur, Record):
                value = ip.types.coerce(v, cur.type)
            elif isinstance(cur, (float, bool, str)):
                value = ip.types.coerce(
                    v,
                    "num"
                    if isinstance(cur, float) and not isinstance(cur, bool)
                    else "bool"
                    if isinstance(cur, bool)
                    else "string",
                )
            ok = True
        except (RapidError, TypeErrorRapid):
            ok = False
    if t and not r.path and ip.give(r):  # the scenario gives what the string brings
        return True, CLEAN
    if ok:
        r.set(value, t | ip.ctx_taint)
    elif t:
        r.set(cur, r.cell.taint | t)
    return ok, t


def kinematic_function(
    ip: Machine, key: str, e: n.FuncCall, a: list[Value], opt: dict[str, Value]
) -> tuple[Value, Taint]:
    t = ip.types
    tool = t.coerce(opt.get("tool", ip.predefined["tool0"].value), "tooldata")
    wobj = t.coerce(opt.get("wobj", ip.predefined["wobj0"].value), "wobjdata")
    assert isinstance(tool, Record) and isinstance(wobj, Record)
    if key in ("calcjointt", "calcrobt"):
        tool = t.coerce(a[1], "tooldata") if len(a) > 1 else tool
        assert isinstance(tool, Record)
    if ip.kin is None:
        why = frozenset({f"{e.pos}: {e.name} needs the robot's kinematics (none given)"})
        if key in ("cjointt", "calcjointt"):
            return ip.types.default("jointtarget"), why
        stand_in = ip.types.default("robtarget")
        assert isinstance(stand_in, Record)
        stand_in = stand_in.replace("rot", make_orient((1.0, 0.0, 0.0, 0.0)))
        return (stand_in.get("trans") if key == "cpos" else stand_in), why
    if key == "calcjointt":
        rt = t.coerce(a[0], "robtarget")
        assert isinstance(rt, Record)
        q = solve(ip, rt, tool, wobj, e.pos, "CalcJointT")
        return jointtarget(ip, q), CLEAN
    if key == "calcrobt":
        jt = t.coerce(a[0], "jointtarget")
        assert isinstance(jt, Record)
        q = joints_of(ip, jt)
        return robtarget_at(ip, q, tool, wobj), CLEAN
    taint = ip.current_taint
    if ip.current_q is None:
        taint = frozenset({f"{e.pos}: {e.name} before any move: where the robot stands at the start"})
        q = np.zeros(6)
    else:
        q = ip.current_q
    if key == "cjointt":
        return jointtarget(ip, q), taint
    rt = robtarget_at(ip, q, tool, wobj)
    if key == "cpos":
        return rt.get("trans"), taint
    return rt, taint


def _round(a: list[Value], opt: dict[str, Value], f: Callable[[float], float]) -> float:
    dec = int(num(opt.get("dec", 0.0)))
    k = 10.0**dec
    return f(num(a[0]) * k) / k


def _round_half_away(x: float) -> float:
    return float(math.floor(abs(x) + 0.5)) * (1.0 if x >= 0 else -1.0)


_MATH: dict[str, Callable[[list[Value], dict[str, Value]], Value]] = {
    "abs": lambda a, o: abs(num(a[0])),
    "absdnum": lambda a, o: abs(num(a[0])),
    "sqrt": lambda a, o: math.sqrt(num(a[0])),
    "sin": lambda a, o: math.sin(math.radians(num(a[0]))),
    "cos": lambda a, o: math.cos(math.radians(num(a[0]))),
    "tan": lambda a, o: math.tan(math.radians(num(a[0]))),
    "asin": lambda a, o: math.degrees(math.asin(num(a[0]))),
    "acos": lambda a, o: math.degrees(math.acos(num(a[0]))),
    "atan": lambda a, o: math.degrees(math.atan(num(a[0]))),
    "atan2": lambda a, o: math.degrees(math.atan2(num(a[0]), num(a[1]))),
    "exp": lambda a, o: math.exp(num(a[0])),
    "pow": lambda a, o: math.pow(num(a[0]), num(a[1])),
    "round": lambda a, o: _round(a, o, _round_half_away),
    "trunc": lambda a, o: _round(a, o, lambda x: float(math.trunc(x))),
    "vectmagn": lambda a, o: float(np.linalg.norm(pos_values(a[0]))),
    "dotprod": lambda a, o: float(np.dot(pos_values(a[0]), pos_values(a[1]))),
    "numtodnum": lambda a, o: num(a[0]),
    "dnumtonum": lambda a, o: num(a[0]),
}


def _num_to_str(a: list[Value], o: dict[str, Value]) -> str:
    dec = int(num(a[1])) if len(a) > 1 else 0
    return f"{num(a[0]):.{dec}f}"


def _str_part(a: list[Value], o: dict[str, Value]) -> str:
    s = str(a[0])
    start, length = int(num(a[1])), int(num(a[2]))
    if start < 1 or length < 0 or start - 1 + length > len(s):
        raise IndexError(f"StrPart({start}, {length}) outside a string of {len(s)} characters")
    return s[start - 1 : start - 1 + length]


_STRING_FUNCS: dict[str, Callable[[list[Value], dict[str, Value]], Value]] = {
    "numtostr": _num_to_str,
    "dnumtostr": _num_to_str,
    "strlen": lambda a, o: float(len(str(a[0]))),
    "strpart": _str_part,
    "strfind": lambda a, o: float(str(a[0]).find(str(a[2]), int(num(a[1])) - 1) + 1 or len(str(a[0])) + 1),
    "strmatch": lambda a, o: float(str(a[0]).find(str(a[2]), int(num(a[1])) - 1) + 1 or len(str(a[0])) + 1),
    "strmemb": lambda a, o: str(a[0])[int(num(a[1])) - 1] in str(a[2]),
    "strmap": lambda a, o: str(a[0]).translate(str.maketrans(str(a[1]), str(a[2]))),
    "valtostr": lambda a, o: show(a[0]),
    "booltostr": lambda a, o: "TRUE" if a[0] is True else "FALSE",
    "strtobyte": lambda a, o: float(int(str(a[0]))),
    "bytetostr": lambda a, o: str(int(num(a[0]))),
    "strorder": lambda a, o: str(a[0]) < str(a[1]),
    "stroneupper": lambda a, o: str(a[0]).upper(),
}


FunctionHandler = Callable[[Machine, str, n.FuncCall, list[Value], dict[str, Value]], tuple[Value, Taint]]
"""The handler of a built-in function: the machine, its name in lower case, the call, the values of its
positional and of its optional arguments; its value and the reasons it is uncertain."""

FUNCTIONS: dict[str, FunctionHandler] = {
    **dict.fromkeys(_MATH, _math),
    "offs": _offs,
    "reltool": _reltool,
    "orientzyx": _orient_zyx,
    "eulerzyx": _euler_zyx,
    "norient": _n_orient,
    **dict.fromkeys(("posemult", "poseinv", "posevect"), _pose),
    **dict.fromkeys(("crobt", "cjointt", "calcjointt", "calcrobt", "cpos"), kinematic_function),
    **dict.fromkeys(("dinput", "doutput", "ginput", "goutput", "ainput", "aoutput", "testdi"), _read_input),
    "rand": _rand,
    **dict.fromkeys(KNOWN_FUNCTIONS_UNKNOWN_RESULT, _known_at_run_time),
    **dict.fromkeys(_STRING_FUNCS, _string),
}
"""Built-in functions of evaluated arguments (by name in lower case) -> their handler."""

UNEVALUATED: dict[str, Callable[[Machine, n.FuncCall], tuple[Value, Taint]]] = {
    "strtoval": str_to_val,
    "present": _present,
    "dim": _dim,
}
"""Built-in functions that read their arguments as written (a variable to write, a parameter's name,
an array): by name in lower case -> their handler, given the call."""
