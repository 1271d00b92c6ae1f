"""Expressions: one handler per node type of :data:`joulepath.rapid.nodes.Expr`, in
:data:`EXPRESSIONS`, which :meth:`joulepath.rapid._machine.Machine.ev` dispatches by; RAPID's operators.

A value flows with the reasons it is uncertain (its taint): a datum's, its index's, an operand's.
"""

from __future__ import annotations

import math

import numpy as np

from joulepath.errors import RapidError
from joulepath.rapid import geometry as geo
from joulepath.rapid import nodes as n
from joulepath.rapid._functions import call_function
from joulepath.rapid._machine import ExprHandler, Machine
from joulepath.rapid._state import Ref
from joulepath.rapid._trace import CLEAN, Taint
from joulepath.rapid.values import (
    Record,
    Signal,
    TypeErrorRapid,
    Value,
    describe,
    equal,
    make_orient,
    make_pos,
    num,
    pos_values,
)


def _placeholder(ip: Machine, e: n.Placeholder) -> tuple[Value, Taint]:
    raise ip.unfinished(e)


def _constant(ip: Machine, e: n.Num | n.Str | n.Bool) -> tuple[Value, Taint]:
    return e.value, CLEAN


def _aggregate(ip: Machine, e: n.Aggregate) -> tuple[Value, Taint]:
    vals, taint = [], CLEAN
    for item in e.items:
        v, t = ip.ev(item)
        vals.append(v)
        taint |= t
    return tuple(vals), taint


def _datum(ip: Machine, e: n.Name | n.Index | n.Field) -> tuple[Value, Taint]:
    """A datum, an element of an array or a component of a record; a signal named reads its value."""
    ref = ip.ref(e)
    try:
        value = ref.get() if isinstance(ref, Ref) else ref.value
    except (IndexError, KeyError) as err:
        raise RapidError(f"{e.pos}: {err}; correct the index or component") from None
    cell = ref.cell if isinstance(ref, Ref) else ref
    if isinstance(e, n.Name) and not isinstance(ref, Ref):
        given = ip.outside_value(cell, e.pos)
        if given is not None:
            return given, CLEAN
    taint = cell.taint | index_taint(ip, e)
    if isinstance(value, Signal) and value.name:
        return ip.read_signal(value, e.pos)
    return value, taint


def _func_call(ip: Machine, e: n.FuncCall) -> tuple[Value, Taint]:
    ip.tick(e.pos)
    return call_function(ip, e)


def _not(ip: Machine, e: n.Not) -> tuple[Value, Taint]:
    v, t = ip.ev(e.a)
    v = ip.signal_value(v, e.pos)
    if not isinstance(v, bool):
        raise RapidError(f"{e.pos}: NOT needs a bool, not {describe(v)}; correct the expression")
    return (not v), t


def _neg(ip: Machine, e: n.Neg) -> tuple[Value, Taint]:
    v, t = ip.ev(e.a)
    v = ip.signal_value(v, e.pos)
    if isinstance(v, Record) and v.type == "pos":
        x, y, z = pos_values(v)
        return make_pos(-x, -y, -z), t
    return -ip.as_num(v, e.pos), t


def index_taint(ip: Machine, e: n.Expr) -> Taint:
    out: Taint = CLEAN
    while isinstance(e, (n.Index, n.Field)):
        if isinstance(e, n.Index):
            for i in e.indices:
                out |= ip.ev(i)[1]
        e = e.base
    return out


def binop(ip: Machine, e: n.BinOp) -> tuple[Value, Taint]:
    a, ta = ip.ev(e.a)
    op = e.op
    if op in ("AND", "OR") and not (ta or ip.ctx_taint):
        a = ip.signal_value(a, e.pos)
        if op == "AND" and a is False:
            return False, ta
        if op == "OR" and a is True:
            return True, ta
    b, tb = ip.ev(e.b)
    a, b = ip.signal_value(a, e.pos), ip.signal_value(b, e.pos)
    taint = ta | tb
    try:
        result = _apply(op, a, b)
    except (TypeErrorRapid, ZeroDivisionError, ValueError) as err:
        if taint and isinstance(err, (ZeroDivisionError, ValueError)):
            ip.note(f"{e.pos}: {op} of a stand-in value fails ({err}); its result is assumed 0")
            return 0.0, taint
        why = "division by zero" if isinstance(err, ZeroDivisionError) else str(err)
        raise RapidError(
            f"{e.pos}: {describe(a)} {op} {describe(b)}: {why}; correct the expression"
        ) from None
    if isinstance(result, float) and not math.isfinite(result):
        if taint:
            ip.note(f"{e.pos}: {op} of a stand-in value is not finite; its result is assumed 0")
            return 0.0, taint
        raise RapidError(f"{e.pos}: {describe(a)} {op} {describe(b)} is not a finite number; correct it")
    return result, taint


EXPRESSIONS: dict[type, ExprHandler] = {
    n.Placeholder: _placeholder,
    n.Num: _constant,
    n.Str: _constant,
    n.Bool: _constant,
    n.Aggregate: _aggregate,
    n.Name: _datum,
    n.Index: _datum,
    n.Field: _datum,
    n.FuncCall: _func_call,
    n.Not: _not,
    n.Neg: _neg,
    n.BinOp: binop,
}
"""Expression node type -> its handler: one for each type of :data:`joulepath.rapid.nodes.Expr`."""


def _apply(op: str, a: Value, b: Value) -> Value:
    if op in ("=", "<>"):
        same = equal(a, b)
        return same if op == "=" else not same
    if op in ("AND", "OR", "XOR"):
        if not isinstance(a, bool) or not isinstance(b, bool):
            raise TypeErrorRapid(f"{op} needs two bools")
        return (a and b) if op == "AND" else (a or b) if op == "OR" else (a != b)
    if isinstance(a, str) and isinstance(b, str):
        if op == "+":
            return a + b
        raise TypeErrorRapid(f"strings take + and = only, not {op}")
    if isinstance(a, Record) or isinstance(b, Record):
        return _record_op(op, a, b)
    x, y = num(a), num(b)
    if op == "+":
        return x + y
    if op == "-":
        return x - y
    if op == "*":
        return x * y
    if op == "/":
        return x / y
    if op == "DIV":
        if not (math.isfinite(x) and math.isfinite(y)) or x != int(x) or y != int(y):
            raise TypeErrorRapid("DIV needs whole numbers")
        return float(math.trunc(x / y)) if y != 0 else x / y
    if op == "MOD":
        if not (math.isfinite(x) and math.isfinite(y)) or x != int(x) or y != int(y):
            raise TypeErrorRapid("MOD needs whole numbers")
        return float(math.fmod(x, y)) if y != 0 else x / y
    if op == "<":
        return x < y
    if op == "<=":
        return x <= y
    if op == ">":
        return x > y
    if op == ">=":
        return x >= y
    raise TypeErrorRapid(f"unknown operator {op}")


def _record_op(op: str, a: Value, b: Value) -> Value:
    if isinstance(a, Record) and isinstance(b, Record) and a.type == b.type == "pos":
        pa, pb = np.array(pos_values(a)), np.array(pos_values(b))
        if op == "+":
            return make_pos(*(float(v) for v in pa + pb))
        if op == "-":
            return make_pos(*(float(v) for v in pa - pb))
        if op == "*":  # the vector product
            return make_pos(*(float(v) for v in np.cross(pa, pb)))
    if isinstance(a, Record) and a.type == "pos" and not isinstance(b, Record):
        pa, k = np.array(pos_values(a)), num(b)
        if op == "*":
            return make_pos(*(float(v) for v in pa * k))
        if op == "/":
            return make_pos(*(float(v) for v in pa / k))
    if isinstance(b, Record) and b.type == "pos" and not isinstance(a, Record) and op == "*":
        return make_pos(*(float(v) for v in np.array(pos_values(b)) * num(a)))
    if isinstance(a, Record) and isinstance(b, Record) and a.type == b.type == "orient" and op == "*":
        return make_orient(geo.quat_mult(geo.orient_values(a), geo.orient_values(b)))
    if isinstance(a, Record) and isinstance(b, Record) and a.type == b.type == "pose" and op == "*":
        return geo.with_pose(a, geo.pose_matrix(a) @ geo.pose_matrix(b))
    raise TypeErrorRapid(f"{describe(a)} {op} {describe(b)} is not defined")
