"""Routines: a call of a PROC or a FUNC of the task, its arguments bound to its parameters (by
reference for ``INOUT`` / ``VAR`` / ``PERS``, by value for ``IN``), in a frame of its own."""

from __future__ import annotations

from joulepath.errors import RapidError
from joulepath.rapid import nodes as n
from joulepath.rapid._machine import Machine
from joulepath.rapid._state import MAX_DEPTH, Cell, Frame, ReturnValue
from joulepath.rapid._trace import CLEAN, Taint
from joulepath.rapid.values import SIGNAL_TYPES, Array, TypeErrorRapid, Value, describe

MENU_REENTRIES = 2
"""Entries of a procedure that calls itself from branches decided at run time before the last call is
taken as the way out (:func:`invoke`)."""


def invoke(
    ip: Machine, r: n.Routine, m: n.Module, args: tuple[n.Arg, ...], pos: n.Pos
) -> tuple[Value, Taint]:
    if len(ip.stack) - 1 >= MAX_DEPTH:  # (the module's frame, then one per routine entered)
        if any(f.routine is r for f in ip.stack):
            raise RapidError(
                f"{pos}: {r.name} calls itself, and calls nest more than {MAX_DEPTH} deep: a recursion "
                "that never ends; check its end condition"
            )
        raise RapidError(
            f"{pos}: {r.name}: calls nest more than {MAX_DEPTH} deep (a chain of routines); call fewer "
            "routines from each other"
        )
    if r.kind == "PROC" and ip.ctx_taint and sum(f.routine is r for f in ip.stack) >= MENU_REENTRIES:
        # a procedure that calls itself again from a branch decided at run time: an operator's menu
        # shown again after each choice; the operator is taken to leave it here
        ip.note(
            f"{pos}: {r.name} calls itself again from a choice made at run time (a menu shown again): "
            f"taken to be left after {MENU_REENTRIES} entries"
        )
        return 0.0, CLEAN
    frame = Frame(r, m, {}, set(), f"{r.name} ({pos.file}:{pos.line})")
    positional = [p for p in r.params if not p.optional]
    given = [a for a in args if a.kind == "pos"]
    if len(given) != len(positional):
        names = ", ".join(p.name for p in positional) or "none"
        raise RapidError(
            f"{pos}: {r.name} takes {len(positional)} required argument(s) ({names}), "
            f"this call gives {len(given)}; correct the call"
        )
    bindings: list[tuple[n.Param, n.Arg]] = list(zip(positional, given, strict=True))
    for a in args:
        if a.kind == "pos":
            continue
        p = next((p for p in r.params if a.name is not None and p.name.lower() == a.name.lower()), None)
        if p is None:
            raise RapidError(f"{pos}: {r.name} has no parameter {a.name}; correct the call")
        if a.kind == "named":
            bindings = [(q, a) if q is p else (q, b) for q, b in bindings]
        else:
            bindings.append((p, a))
    for p, a in bindings:
        key = p.name.lower()
        frame.present.add(key)
        if a.value is None:  # a switch
            frame.locals[key] = Cell(p.name, "switch", "IN", True, CLEAN, None)
            continue
        if p.access in ("INOUT", "VAR", "PERS") and isinstance(a.value, (n.Name, n.Index, n.Field)):
            frame.locals[key] = ip.ref(a.value)
            continue
        value, taint = ip.ev(a.value)
        type_ = ip.types.resolve(p.type)
        if type_ not in SIGNAL_TYPES:
            value = ip.signal_value(value, a.pos)
        try:
            if p.dims:
                if not isinstance(value, Array):
                    raise TypeErrorRapid(f"an array is needed for {p.name}, not {describe(value)}")
            else:
                value = ip.types.coerce(value, type_)
        except TypeErrorRapid as err:
            raise RapidError(f"{a.pos}: {r.name}, argument {p.name}: {err}; correct the call") from None
        frame.locals[key] = Cell(p.name, type_, "IN", value, taint, None)
    ip.stack.append(frame)
    try:
        for d in (s for s in r.body if isinstance(s, n.DataDecl)):
            frame.locals[d.name.lower()] = ip.declare(d)
        ip.exec_body(r.body)
    except ReturnValue as ret:
        if r.kind == "FUNC":
            assert r.type is not None
            try:
                value = ip.types.coerce(ret.value, r.type)
            except TypeErrorRapid as err:
                raise RapidError(f"{r.pos}: {r.name} returns {err}; correct its RETURN") from None
            return value, ret.taint
        return None, CLEAN
    finally:
        ip.stack.pop()
    if r.kind == "FUNC":
        raise RapidError(f"{r.pos}: the function {r.name} ends without RETURN; add RETURN value;")
    return None, CLEAN
