"""RAPID's values and data types: atomic values, records, arrays, signals, with RAPID's rules.

Values are plain and immutable: ``num`` (and ``dnum``) a ``float``, ``bool`` a ``bool``,
``string`` a ``str``; a record a :class:`Record` (its type and its components in order),
an array an :class:`Array` (row-major, 1 to 3 dimensions), an I/O signal a
:class:`Signal`, a value of a type joulepath does not model (``triggdata``,
``socketdev`` ...) an :class:`Opaque`. An aggregate ``[a, b, c]`` evaluates to a
``tuple`` that takes its type where it is stored or passed (:func:`coerce`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Value = object
"""A RAPID value: float, bool, str, Record, Array, Signal, Opaque, or an untyped aggregate (tuple)."""


@dataclass(frozen=True, slots=True)
class Record:
    """A record value: its type name (as declared, lower case) and its components in order."""

    type: str
    names: tuple[str, ...]
    values: tuple[Value, ...]

    def get(self, name: str) -> Value:
        key = name.lower()
        for k, v in zip(self.names, self.values, strict=True):
            if k == key:
                return v
        raise KeyError(name)

    def replace(self, name: str, value: Value) -> Record:
        key = name.lower()
        if key not in self.names:
            raise KeyError(name)
        return Record(
            self.type,
            self.names,
            tuple(value if k == key else v for k, v in zip(self.names, self.values, strict=True)),
        )


@dataclass(frozen=True, slots=True)
class Array:
    """An array: ``dims`` (1 to 3) and its elements row-major."""

    type: str
    dims: tuple[int, ...]
    items: tuple[Value, ...]

    def offset(self, index: tuple[int, ...]) -> int:
        """Row-major offset of a 1-based index; ``IndexError`` outside the array."""
        if len(index) != len(self.dims):
            raise IndexError(f"{len(index)} indices for an array of {len(self.dims)} dimension(s)")
        k = 0
        for i, d in zip(index, self.dims, strict=True):
            if not 1 <= i <= d:
                raise IndexError(f"index {i} outside 1..{d}")
            k = k * d + (i - 1)
        return k


@dataclass(frozen=True, slots=True)
class Signal:
    """An I/O signal (``signaldi``, ``signaldo``, ``signalgi`` ...), declared in the controller's
    I/O configuration: its name and, where known, its kind (``di``, ``do``, ``gi`` ...)."""

    name: str
    kind: str = ""


@dataclass(frozen=True, slots=True)
class Opaque:
    """A value of a type the interpreter carries but does not compute with (``triggdata`` ...)."""

    type: str
    note: str = ""


NUM_TYPES = frozenset({"num", "dnum", "intnum", "errnum", "errdomain", "errtype", "bool_num", "byte"})
SIGNAL_TYPES = frozenset(
    {"signaldi", "signaldo", "signalgi", "signalgo", "signalai", "signalao", "signalorigin"}
)

BUILTIN_RECORDS: dict[str, tuple[tuple[str, str], ...]] = {
    "pos": (("x", "num"), ("y", "num"), ("z", "num")),
    "orient": (("q1", "num"), ("q2", "num"), ("q3", "num"), ("q4", "num")),
    "pose": (("trans", "pos"), ("rot", "orient")),
    "confdata": (("cf1", "num"), ("cf4", "num"), ("cf6", "num"), ("cfx", "num")),
    "extjoint": tuple((f"eax_{c}", "num") for c in "abcdef"),
    "robjoint": tuple((f"rax_{k}", "num") for k in range(1, 7)),
    "robtarget": (("trans", "pos"), ("rot", "orient"), ("robconf", "confdata"), ("extax", "extjoint")),
    "jointtarget": (("robax", "robjoint"), ("extax", "extjoint")),
    "speeddata": (("v_tcp", "num"), ("v_ori", "num"), ("v_leax", "num"), ("v_reax", "num")),
    "zonedata": (
        ("finep", "bool"),
        ("pzone_tcp", "num"),
        ("pzone_ori", "num"),
        ("pzone_eax", "num"),
        ("zone_ori", "num"),
        ("zone_leax", "num"),
        ("zone_reax", "num"),
    ),
    "loaddata": (
        ("mass", "num"),
        ("cog", "pos"),
        ("aom", "orient"),
        ("ix", "num"),
        ("iy", "num"),
        ("iz", "num"),
    ),
    "tooldata": (("robhold", "bool"), ("tframe", "pose"), ("tload", "loaddata")),
    "wobjdata": (
        ("robhold", "bool"),
        ("ufprog", "bool"),
        ("ufmec", "string"),
        ("uframe", "pose"),
        ("oframe", "pose"),
    ),
    "stoppointdata": (
        ("type", "num"),
        ("progsynch", "bool"),
        ("inpos_position", "num"),
        ("inpos_speed", "num"),
        ("inpos_mintime", "num"),
        ("inpos_maxtime", "num"),
        ("stoptime", "num"),
        ("followtime", "num"),
        ("signal", "string"),
        ("relation", "num"),
        ("checkvalue", "num"),
    ),
}
"""The record types of the RAPID kernel that moves are made of, with their components."""


class TypeErrorRapid(Exception):
    """A value that does not fit the type asked for (the interpreter adds the position)."""


class Types:
    """The task's types: RAPID's built-in records plus the task's ``RECORD`` definitions and ``ALIAS``."""

    def __init__(self) -> None:
        self.records: dict[str, tuple[tuple[str, str], ...]] = dict(BUILTIN_RECORDS)
        self.aliases: dict[str, str] = {}
        from joulepath.rapid.builtins import all_data_types  # the options' records (cameratarget ...)

        for dt in all_data_types():
            if dt.kind == "record" and dt.components and dt.name.lower() not in self.records:
                self.records[dt.name.lower()] = tuple((c.lower(), ty.lower()) for c, ty in dt.components)
            elif dt.kind == "alias" and dt.alias_of:  # socketstatus, errnum-like aliases of num ...
                self.aliases.setdefault(dt.name.lower(), dt.alias_of.lower())

    def resolve(self, type_: str) -> str:
        t = type_.lower()
        seen = set()
        while t in self.aliases and t not in seen:
            seen.add(t)
            t = self.aliases[t]
        return t

    def default(self, type_: str) -> Value:
        """The value a ``VAR`` of this type holds before it is assigned."""
        t = self.resolve(type_)
        if t in NUM_TYPES:
            return 0.0
        if t == "bool":
            return False
        if t == "string":
            return ""
        if t in self.records:
            fields = self.records[t]
            return Record(t, tuple(f for f, _ in fields), tuple(self.default(ft) for _, ft in fields))
        if t in SIGNAL_TYPES:
            return Signal("", t[6:])
        return Opaque(t)

    def coerce(self, value: Value, type_: str) -> Value:
        """``value`` as a ``type_`` (an aggregate built into its record); :class:`TypeErrorRapid`
        where it does not fit."""
        t = self.resolve(type_)
        if t in NUM_TYPES:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeErrorRapid(f"a {type_} is needed here, not {describe(value)}")
            return float(value)
        if t == "bool":
            if not isinstance(value, bool):
                raise TypeErrorRapid(f"a bool is needed here, not {describe(value)}")
            return value
        if t == "string":
            if not isinstance(value, str):
                raise TypeErrorRapid(f"a string is needed here, not {describe(value)}")
            return value
        if t in self.records:
            fields = self.records[t]
            if isinstance(value, Record):
                if value.type == t:
                    return value
                raise TypeErrorRapid(f"a {type_} is needed here, not a {value.type}")
            if isinstance(value, tuple):
                if len(value) != len(fields):
                    raise TypeErrorRapid(
                        f"a {type_} has {len(fields)} components ({', '.join(f for f, _ in fields)}), "
                        f"this aggregate {len(value)}"
                    )
                return Record(
                    t,
                    tuple(f for f, _ in fields),
                    tuple(self.coerce(v, ft) for v, (_, ft) in zip(value, fields, strict=True)),
                )
            raise TypeErrorRapid(f"a {type_} is needed here, not {describe(value)}")
        if t in SIGNAL_TYPES:
            if isinstance(value, Signal):
                return value
            raise TypeErrorRapid(f"a {type_} (an I/O signal) is needed here, not {describe(value)}")
        return value  # a type joulepath carries without computing (triggdata, intnum ...)

    def array(self, value: Value, type_: str, dims: tuple[int, ...]) -> Array:
        """An aggregate of aggregates as an array of ``dims`` of ``type_``."""

        def flat(v: Value, level: int) -> list[Value]:
            if level == len(dims):
                return [self.coerce(v, type_)]
            if not isinstance(v, tuple) or len(v) != dims[level]:
                n = len(v) if isinstance(v, tuple) else 1
                raise TypeErrorRapid(f"dimension {level + 1} holds {dims[level]} elements, the aggregate {n}")
            out: list[Value] = []
            for item in v:
                out.extend(flat(item, level + 1))
            return out

        if isinstance(value, Array):
            if value.dims != dims:
                raise TypeErrorRapid(f"an array {{{dims}}} is needed here, not {{{value.dims}}}")
            return value
        return Array(self.resolve(type_), dims, tuple(flat(value, 0)))


def describe(value: Value) -> str:
    """A value's kind in a message (``a num``, ``a robtarget`` ...)."""
    if isinstance(value, bool):
        return "a bool"
    if isinstance(value, (int, float)):
        return f"the num {value:g}"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, Record):
        return f"a {value.type}"
    if isinstance(value, Array):
        return f"an array of {value.type}"
    if isinstance(value, tuple):
        return "an aggregate"
    if isinstance(value, Signal):
        return f"the signal {value.name}"
    if isinstance(value, Opaque):
        return f"a {value.type}"
    return type(value).__name__


def equal(a: Value, b: Value) -> bool:
    """RAPID's ``=``: numbers to RAPID's precision (relative 1e-9), records component-wise."""
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b or a == b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
    if isinstance(a, Record) and isinstance(b, Record):
        return a.type == b.type and all(equal(x, y) for x, y in zip(a.values, b.values, strict=True))
    return a == b


def num(value: Value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeErrorRapid(f"a num is needed here, not {describe(value)}")
    return float(value)


def pos_values(rec: Value) -> tuple[float, float, float]:
    assert isinstance(rec, Record)
    return (num(rec.values[0]), num(rec.values[1]), num(rec.values[2]))


def make_pos(x: float, y: float, z: float) -> Record:
    return Record("pos", ("x", "y", "z"), (float(x), float(y), float(z)))


def make_orient(q: tuple[float, float, float, float]) -> Record:
    return Record("orient", ("q1", "q2", "q3", "q4"), tuple(float(v) for v in q))
