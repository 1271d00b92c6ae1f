"""RAPID's vocabulary as data: the instructions, functions and data types ABB documents, with their
parameters and their effect on the cycle, and the matching of a call's arguments to a signature.

The table lives in :mod:`joulepath.rapid._builtin_table` (the standard set of RobotWare 6 and 7)
and :mod:`joulepath.rapid._builtin_options` (the options: SmartGripper, Integrated Vision, socket
messaging, Arc, Dispense, Force Control, Multitasking, Conveyor tracking, ...). Each entry is a
signature written in a compact notation close to the manuals' own syntax diagrams:

================================  =============================================================
``Name:type``                     a required argument, given in its place (or as ``Name:=v``)
``[\\Name:type]``                 an optional argument, given as ``\\Name:=value``
``[\\Name]``                      a switch, given as ``\\Name``
``[\\A:num|\\B|\\C:bool]``        optional and mutually exclusive: at most one of them
``<\\A|\\B>``                     mutually exclusive and one of them required (``ConfL \\On``)
``type&``                         the routine writes this argument (``INOUT``, ``VAR``, ``PERS``)
``type!``                         the routine writes it with data known only at run time
``type{*}``                       an array
``num/dnum``                      one of these types
``anytype``                       a value of any type
================================  =============================================================

The interpreter calls :func:`lookup` for a name no module of the task declares, then
:func:`match_arguments` with the call's arguments as plain ``(name or None, value)`` pairs, so
this module knows nothing of the tree's node classes.

Examples
--------
>>> b = lookup("movel")
>>> b.name, b.kind.value, b.effect.value, b.motion.kind.value if b.motion else None
('MoveL', 'instruction', 'move', 'linear')
>>> match_arguments(b, [(None, "p10"), (None, "v500"), (None, "z10"), (None, "tool1"), ("WObj", "wobj1")])
{'ToPoint': 'p10', 'Speed': 'v500', 'Zone': 'z10', 'Tool': 'tool1', 'WObj': 'wobj1'}
>>> [c for c, _ in data_type("robtarget").components]
['trans', 'rot', 'robconf', 'extax']
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import TypeVar

from joulepath.errors import RapidError
from joulepath.rapid import _builtin_options, _builtin_table

__all__ = [
    "ArgumentError",
    "BASE_TYPES",
    "Builtin",
    "DataType",
    "Effect",
    "Kind",
    "Motion",
    "MotionKind",
    "Param",
    "ParamKind",
    "ROBOT_MOTIONS",
    "all_builtins",
    "all_data_types",
    "data_type",
    "lookup",
    "match_arguments",
    "parse_signature",
]

V = TypeVar("V")


class Kind(StrEnum):
    """What a built-in routine is: called as a statement, or used in an expression."""

    INSTRUCTION = "instruction"
    FUNCTION = "function"


class Effect(StrEnum):
    """What a routine does to the cycle."""

    MOVE = "move"
    """Moves the arm (or an axis): see :attr:`Builtin.motion`."""
    TIME = "time"
    """Takes a time given by an argument (:attr:`Builtin.duration`), as ``WaitTime``."""
    WAIT = "wait"
    """Waits on the outside world: a signal, a condition, another task, an operator, a device."""
    SETTING = "setting"
    """Sets a motion setting in force for the moves after it (``AccSet``, ``ConfL``, ...)."""
    IO = "io"
    """Writes an output signal, without waiting."""
    NONE = "none"
    """None on the motion or the cycle's time (data, text, files, interrupts, ...)."""


class MotionKind(StrEnum):
    """The interpolation of a move."""

    JOINT = "joint"
    LINEAR = "linear"
    CIRCULAR = "circular"
    ABSJOINT = "absjoint"
    """To a jointtarget, joint-interpolated (``MoveAbsJ``)."""
    EXTERNAL = "external"
    """External axes only, no TCP (``MoveExtJ``)."""
    INDEPENDENT = "independent"
    """One axis in independent mode (``IndAMove``, ...)."""
    GUIDED = "guided"
    """Guided by an external sensor's stream (``EGMRunPose``): no target in the program."""


ROBOT_MOTIONS = frozenset({MotionKind.JOINT, MotionKind.LINEAR, MotionKind.CIRCULAR, MotionKind.ABSJOINT})
"""Motions of the robot's TCP: each names its target, speed, zone and tool."""


class ParamKind(StrEnum):
    REQUIRED = "required"
    """Given in its place, or by name as ``Name:=value``."""
    OPTIONAL = "optional"
    """Given as ``\\Name:=value``."""
    SWITCH = "switch"
    """Given as ``\\Name``, without a value."""


@dataclass(frozen=True, slots=True)
class Param:
    """One parameter of a built-in routine."""

    name: str
    kind: ParamKind
    type: str
    """The data type, ``"switch"`` for a switch, or alternatives separated by ``/``."""
    group: int | None = None
    """The mutually exclusive group it belongs to (an index into :attr:`Builtin.groups`)."""
    array: bool = False
    writes: bool = False
    """The routine writes this argument (``INOUT``/``VAR``/``PERS``)."""
    runtime: bool = False
    """What it writes is known only at run time (an operator's answer, a socket's data, ...)."""

    @property
    def required(self) -> bool:
        return self.kind is ParamKind.REQUIRED

    @property
    def types(self) -> tuple[str, ...]:
        return tuple(self.type.split("/"))


@dataclass(frozen=True, slots=True)
class Motion:
    """Which parameters of a move carry what: each a parameter's name, or None where it has none."""

    kind: MotionKind
    target: str | None
    circle: str | None = None
    speed: str | None = None
    zone: str | None = None
    tool: str | None = None
    wobj: str | None = None
    time: str | None = None
    """``\\T``: the move's time in s, in place of its speed."""
    velocity: str | None = None
    """``\\V``: the TCP speed in mm/s, in place of the speeddata's."""
    zone_size: str | None = None
    """``\\Z``: the zone's radius in mm, in place of the zonedata's."""
    inpos: str | None = None
    conc: str | None = None
    process: bool = False
    """The speed along the path is the process's (a weld, a bead), not only the speeddata's."""
    search: bool = False
    """The move stops where a signal comes: its end is known only at run time."""


@dataclass(frozen=True, slots=True)
class Builtin:
    """A RAPID instruction or function as documented."""

    name: str
    kind: Kind
    params: tuple[Param, ...]
    effect: Effect
    option: str | None = None
    """None for standard RAPID, else the RobotWare option (or product) that brings it."""
    motion: Motion | None = None
    returns: str | None = None
    """A function's return type."""
    runtime: bool = False
    """A function whose value is known only at run time (the robot's position, an input, ...)."""
    duration: str | None = None
    """The parameter giving the time it takes in s (``WaitTime``'s ``Time``)."""
    max_time: str | None = None
    """The parameter bounding a wait in s (``\\MaxTime``, ``\\TimeOut``)."""
    complete: bool = True
    """False where the table holds only the parameters it could confirm: a call with others is
    then matched leniently (an unknown optional argument, or an extra positional one, is kept)."""
    source: str = ""
    signature: str = ""

    required_group_ids: frozenset[int] = frozenset()
    """The exclusive groups of which one member must be given (``<\\On|\\Off>``)."""

    def param(self, name: str) -> Param | None:
        """The parameter of this name (case-insensitive), or None."""
        key = name.lower()
        return next((p for p in self.params if p.name.lower() == key), None)

    @property
    def required(self) -> tuple[Param, ...]:
        return tuple(p for p in self.params if p.required)

    @property
    def groups(self) -> tuple[tuple[Param, ...], ...]:
        """The mutually exclusive groups, in order of their index."""
        n_groups = 1 + max((p.group for p in self.params if p.group is not None), default=-1)
        return tuple(tuple(p for p in self.params if p.group == k) for k in range(n_groups))

    @property
    def required_groups(self) -> tuple[tuple[Param, ...], ...]:
        """Groups of which one member must be given (``<\\On|\\Off>``)."""
        return tuple(g for k, g in enumerate(self.groups) if k in self.required_group_ids)

    @property
    def writes(self) -> tuple[Param, ...]:
        """The parameters it writes with data known only at run time."""
        return tuple(p for p in self.params if p.runtime)


@dataclass(frozen=True, slots=True)
class DataType:
    """A RAPID data type: an atomic type, a record with its components, or an alias."""

    name: str
    kind: str
    """``"atomic"``, ``"record"`` or ``"alias"``."""
    components: tuple[tuple[str, str], ...] = ()
    alias_of: str | None = None
    value: bool = True
    """False for a non-value or semi-value type (a signal, a device, a clock): it holds a
    reference to something outside the program, not a value one can write as a literal."""
    option: str | None = None
    complete: bool = True
    """False where the components are not all known."""
    source: str = ""


BASE_TYPES = frozenset({"anytype", "switch"})
"""Pseudo-types of parameters that are not data types: a value of any type, a switch."""


class ArgumentError(RapidError):
    """A call's arguments do not fit the routine's signature (the caller adds ``file:line:``)."""


# ---------------------------------------------------------------- the notation
_TOKEN = re.compile(r"\[[^\]]*\]|<[^>]*>|[^\s\[<]+")
_MEMBER = re.compile(r"^(\\?)([A-Za-z_][A-Za-z0-9_]*)(?::([A-Za-z0-9_/]+)(\{\*\})?([&!]?))?$")


def _required_group_ids(signature: str) -> list[int]:
    out, k = [], 0
    for tok in _TOKEN.findall(signature):
        members = tok[1:-1].split("|") if tok[0] in "[<" else [tok]
        if tok[0] in "[<" and len(members) > 1:
            if tok[0] == "<":
                out.append(k)
            k += 1
        elif tok[0] == "<":
            out.append(k)
            k += 1
    return out


def parse_signature(signature: str) -> tuple[Param, ...]:
    """The parameters of a signature written in the table's notation (see the module's docstring).

    Raises
    ------
    ValueError
        If the text is not in the notation.

    Examples
    --------
    >>> [(p.name, p.kind.value, p.group) for p in parse_signature(r"<\\On|\\Off>")]
    [('On', 'switch', 0), ('Off', 'switch', 0)]
    >>> p = parse_signature(r"TPAnswer:num! TPText:string [\\MaxTime:num]")
    >>> [(x.name, x.kind.value, x.runtime) for x in p]
    [('TPAnswer', 'required', True), ('TPText', 'required', False), ('MaxTime', 'optional', False)]
    """
    params: list[Param] = []
    group = 0
    rest = _TOKEN.sub("", signature).strip()
    if rest:
        raise ValueError(f"signature {signature!r}: cannot read {rest!r}")
    for tok in _TOKEN.findall(signature):
        bracketed = tok[0] in "[<"
        members = tok[1:-1].split("|") if bracketed else [tok]
        exclusive = bracketed and (len(members) > 1 or tok[0] == "<")
        for member in members:
            m = _MEMBER.match(member.strip())
            if m is None:
                raise ValueError(f"signature {signature!r}: cannot read {member!r}")
            backslash, name, type_, arr, mark = m.groups()
            if bracketed != bool(backslash):
                raise ValueError(f"signature {signature!r}: {member!r}: a \\ goes with [...] or <...>")
            if not bracketed and type_ is None:
                raise ValueError(f"signature {signature!r}: the required {name} has no type")
            kind = ParamKind.REQUIRED if not bracketed else ParamKind.OPTIONAL if type_ else ParamKind.SWITCH
            params.append(
                Param(
                    name=name,
                    kind=kind,
                    type=type_ or "switch",
                    group=group if exclusive else None,
                    array=bool(arr),
                    writes=bool(mark),
                    runtime=mark == "!",
                )
            )
        if exclusive:
            group += 1
    names = [p.name.lower() for p in params]
    if len(set(names)) != len(names):
        raise ValueError(f"signature {signature!r}: a parameter's name twice")
    return tuple(params)


# ---------------------------------------------------------------- the table
def _motion(kind: MotionKind, params: tuple[Param, ...], flags: set[str]) -> Motion:
    targets = [
        p.name for p in params if p.required and not p.writes and p.type in ("robtarget", "jointtarget")
    ]
    by_type: dict[str, str] = {}
    for p in params:
        if p.type in ("speeddata", "zonedata", "tooldata", "wobjdata") and p.type not in by_type:
            by_type[p.type] = p.name
    names = {p.name for p in params}

    def opt(name: str) -> str | None:
        return name if name in names else None

    return Motion(
        kind=kind,
        target=targets[-1] if targets else None,
        circle=targets[0] if kind is MotionKind.CIRCULAR and len(targets) > 1 else None,
        speed=by_type.get("speeddata"),
        zone=by_type.get("zonedata"),
        tool=by_type.get("tooldata"),
        wobj=by_type.get("wobjdata"),
        time=opt("T"),
        velocity=opt("V"),
        zone_size=opt("Z"),
        inpos=opt("Inpos"),
        conc=opt("Conc"),
        process="process" in flags,
        search="search" in flags,
    )


def _builtin(row: Sequence[str], kind: Kind, option: str | None, source: str, complete: bool) -> Builtin:
    name, signature, spec = row[0], row[1], row[2]
    params = parse_signature(signature)
    words = spec.split()
    motion = returns = duration = None
    runtime = False
    if kind is Kind.FUNCTION:
        returns, flags = words[0], set(words[1:])
        runtime = "runtime" in flags
        effect = Effect.WAIT if "wait" in flags else Effect.NONE
        unknown = flags - {"runtime", "wait"}
    else:
        effect = Effect(words[0])
        flags = set(words[1:])
        unknown = set()
        if effect is Effect.MOVE:
            kinds = [f for f in flags if f in {m.value for m in MotionKind}]
            if len(kinds) != 1:
                raise ValueError(f"{name}: a move names one motion kind, not {spec!r}")
            motion = _motion(MotionKind(kinds[0]), params, flags)
            unknown = flags - {kinds[0], "process", "search"}
        elif effect is Effect.TIME:
            duration = words[1] if len(words) > 1 else None
            unknown = flags - {duration} if duration else flags
        else:
            unknown = flags
    if unknown:
        raise ValueError(f"{name}: unknown words {sorted(unknown)} in {spec!r}")
    max_time = next((p.name for p in params if p.name.lower() in ("maxtime", "timeout")), None)
    return Builtin(
        name=name,
        kind=kind,
        params=params,
        effect=effect,
        option=option,
        motion=motion,
        returns=returns,
        runtime=runtime,
        duration=duration,
        max_time=max_time,
        complete=complete and (len(row) < 4 or row[3] != "partial"),
        source=source,
        signature=signature,
        required_group_ids=frozenset(_required_group_ids(signature)),
    )


def _data_type(row: Sequence[str], option: str | None, source: str) -> DataType:
    name, spec = row[0], row[1]
    partial = len(row) > 2 and row[2] == "partial"
    head, _, body = spec.partition(":")
    words = head.split()
    value = "nonvalue" not in words
    if words[0] == "record":
        comps = tuple((c.split()[0], c.split()[1]) for c in (x.strip() for x in body.split(",")) if c.strip())
        return DataType(name, "record", comps, None, value, option, not partial, source)
    if words[0] == "alias":
        return DataType(name, "alias", (), words[1], value, option, not partial, source)
    if words[0] == "atomic":
        return DataType(name, "atomic", (), None, value, option, not partial, source)
    raise ValueError(f"data type {name}: cannot read {spec!r}")


@functools.cache
def _table() -> tuple[dict[str, Builtin], dict[str, DataType]]:
    routines: dict[str, Builtin] = {}
    types: dict[str, DataType] = {}
    for block in (*_builtin_table.BLOCKS, *_builtin_options.BLOCKS):
        kind_word, option, source, rows = block
        complete = not kind_word.endswith("partial")
        kind_word = kind_word.removesuffix(" partial")
        for row in rows:
            key = row[0].lower()
            if kind_word == "type":
                if key in types or key in routines:
                    raise ValueError(f"the table has {row[0]} twice")
                types[key] = _data_type(row, option, source)
                continue
            if key in routines or key in types:
                raise ValueError(f"the table has {row[0]} twice")
            routines[key] = _builtin(row, Kind(kind_word), option, source, complete)
    return routines, types


def lookup(name: str) -> Builtin | None:
    """The built-in instruction or function of this name (RAPID is case-insensitive), or None.

    Examples
    --------
    >>> lookup("PATHACCLIM").name
    'PathAccLim'
    >>> lookup("CRobT").runtime
    True
    >>> lookup("no_such_routine") is None
    True
    """
    return _table()[0].get(name.lower())


def data_type(name: str) -> DataType | None:
    """The data type of this name (case-insensitive), or None."""
    return _table()[1].get(name.lower())


def all_builtins(*, kind: Kind | None = None, option: str | None | bool = False) -> tuple[Builtin, ...]:
    """Every routine of the table, in the table's order; ``kind`` picks instructions or functions,
    ``option`` one option's (None: standard RAPID only; False, the default: all)."""
    return tuple(
        b
        for b in _table()[0].values()
        if (kind is None or b.kind is kind) and (option is False or b.option == option)
    )


def all_data_types() -> tuple[DataType, ...]:
    """Every data type of the table, in the table's order."""
    return tuple(_table()[1].values())


# ---------------------------------------------------------------- matching a call
def match_arguments(builtin: Builtin, args: Iterable[tuple[str | None, V]]) -> dict[str, V]:
    """The call's arguments by parameter name (the table's spelling).

    ``args`` are the call's arguments as written, in order: ``(None, value)`` for a positional
    one; ``(name, value)`` for ``\\Name:=value`` and for a required one given as
    ``Name:=value``; ``(name, None)`` for a switch ``\\Name``. A conditional argument
    ``\\Name?Par`` is given as ``(name, value)`` where the calling routine's ``Par`` is present,
    and left out where it is not (it is then absent, as RAPID has it). The values are opaque here:
    expressions, evaluated values, or placeholders.

    A switch given maps to its value (None). Where the entry is not :attr:`~Builtin.complete`,
    an unknown optional argument is kept under its own name and an extra positional one under
    ``"#k"`` (its 1-based place among the positional arguments).

    Raises
    ------
    ArgumentError
        A required argument missing, one too many, an unknown optional argument, a switch given
        a value or an optional argument given none, two of one exclusive group, none of a
        required group, or one argument twice.

    Examples
    --------
    >>> b = lookup("PathAccLim")
    >>> match_arguments(b, [(None, "FALSE"), ("AccMax", 4), (None, "TRUE"), ("DecelMax", 4)])
    {'AccLim': 'FALSE', 'AccMax': 4, 'DecelLim': 'TRUE', 'DecelMax': 4}
    >>> match_arguments(lookup("ConfL"), [("On", None)])
    {'On': None}
    """
    out: dict[str, V] = {}
    positional: list[V] = []
    given_order: list[str] = []
    what = builtin.name
    for name, value in args:
        if name is None:
            positional.append(value)
            continue
        p = builtin.param(name)
        if p is None:
            if builtin.complete:
                known = ", ".join(f"\\{q.name}" for q in builtin.params if not q.required) or "none"
                raise ArgumentError(f"{what} has no argument \\{name} (its optional ones: {known})")
            key = name
        else:
            key = p.name
            if p.kind is ParamKind.SWITCH and value is not None:
                raise ArgumentError(f"{what}: \\{p.name} is a switch; give it without a value")
            if p.kind is ParamKind.OPTIONAL and value is None:
                raise ArgumentError(f"{what}: \\{p.name} needs a value (\\{p.name}:=...)")
        if key in out:
            raise ArgumentError(f"{what}: {key} is given twice")
        out[key] = value
        given_order.append(key)
    free = [p for p in builtin.params if p.required and p.name not in out]
    if len(positional) > len(free):
        if builtin.complete:
            raise ArgumentError(
                f"{what} takes {len(builtin.required)} argument(s) in place "
                f"({', '.join(p.name for p in builtin.required) or 'none'}); "
                f"{len(positional) + len(builtin.required) - len(free)} given"
            )
    for k, value in enumerate(positional):
        if k < len(free):
            out[free[k].name] = value
        else:
            out[f"#{k + 1}"] = value
    missing = [p.name for p in free[len(positional) :]]
    if missing:
        raise ArgumentError(
            f"{what} needs {', '.join(missing)} ({_describe(builtin, missing)}); correct the call"
        )
    for k, group in enumerate(builtin.groups):
        given = [p.name for p in group if p.name in out]
        if len(given) > 1:
            raise ArgumentError(
                f"{what}: {' and '.join(chr(92) + g for g in given)} exclude each other; give one"
            )
        if not given and k in builtin.required_group_ids:
            choices = " or ".join("\\" + p.name for p in group)
            raise ArgumentError(f"{what} needs one of {choices}")
    ordered = {p.name: out[p.name] for p in builtin.params if p.name in out}
    ordered.update((k, v) for k, v in out.items() if k not in ordered)
    return ordered


def _describe(builtin: Builtin, names: Sequence[str]) -> str:
    types: Mapping[str, str] = {p.name: p.type for p in builtin.params}
    return ", ".join(f"{types[n]}" for n in names)
