"""A plan for RAPID made on the controller emulation: the plan's via points, and the controller's levers
searched on them.

The via-point module of a cycle's plan (:func:`joulepath.program._output.written_rapid`: each optimized
move a call of an added procedure of ``MoveAbsJ`` via points with ``\\T`` and zones) carries a shape
the controller's own planning of the taught statements cannot make. The controller runs it its own
way: the zones cut the corners between the via points, its ramps start and end each chain. So the
module rarely keeps the plan's path to the 5 mm of the written-program check; it makes a motion of its
own, whose cycle time and energy the controller emulation measures.

Here that motion is the plan, and it is improved where it stands: the module, read as written, is
run by the controller emulation, and the controller's levers (``AccSet``, speed data or ``\\T``,
zones; :func:`joulepath.program.levers_module`) are searched on it for the least energy within the
taught program's cycle time (the module often runs shorter than the taught cycle: that time is
spent too), twice: on every move statement, and on the via points alone (each search within
``max_seconds``); the better as executed is kept. A statement of the program the levers change is
written on one line under ``! joulepath: was:`` lines of what stood there, so that the module still
reads back as the program it was written from (:func:`joulepath.program._rapid_write.restore_program`).

Before it is offered, the written text (with its header) is read again by the RAPID interpreter and
run again by the emulation, and must give the searched cycle time and energy; its tool0 (the flange,
the point whose corridor the cycle's plan keeps) must stay within ``corridor_mm`` of the taught
cycle's tool0 path, at every step of the lever search too (a module past it is first brought within
by the levers of the statements that run where it is farthest), and, with a cell, clear the cell's
margin. The figures are those of the module as executed, against the taught
program run by the same emulation, on the run's energy measure.

A ``MoveL``'s speed data is the programmer's bound on its line (an approach to a part at ``v200``),
and the plan keeps it; via points that replace a line run at whatever speed their ``\\T`` give. So
each via-point module searched on runs every taught ``MoveL`` line no faster than its speed data
(:mod:`joulepath.program._line_speed`; outside the blends the controller makes between a taught
statement and the next, as in the taught cycle): a layout's ``\\T`` are not shortened past it, a
unit that breaks it goes back as taught, and a timed chain's segments on a line are timed within
it. The levers never make a line faster (they stretch ``\\T``, lower ``AccSet``, and never raise a
``MoveL``'s speed data); a zone they enlarge lets the controller blend further into the line.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from joulepath import __version__
from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, JoulepathError, LimitViolation
from joulepath.optimize import tcp_velocity
from joulepath.program._levers import LeverResult, _Evaluator, cycle_motion, levers_module
from joulepath.program._line_speed import SPEED_TOL, LineSpeed, fastest_on_lines, line_speeds
from joulepath.program._parse import parse_module
from joulepath.program._resolve import CycleSpec, resolve_module
from joulepath.program._via_timing import BLEND_ROOM, T_ARG, _written, dense_vias, time_chains
from joulepath.sim import ControllerConfig, PlannedCycle, tcp_pose

_TOL_S = 1e-6
_TOL_REL = 1e-6
TIME_FITS = 4
"""Tries, at most, to fit a via-point module that runs longer than the taught cycle into its time by
shortening every via point's ``\\T`` by the same factor."""
MAX_PLANS = 4000
"""Cycle plans the lever search of the via points makes at most (each a few ms per move; ``max_seconds``
bounds it too): a via-point module has many more statements than the program it was written from."""


@dataclass(frozen=True, slots=True)
class ViaLevers:
    """The via-point module with levers (``levers``, ``base`` ``"via points"``), or None and why not.

    ``via_cycle_s``/``via_energy_J``: the via-point module before the levers, as executed;
    ``deviation_mm``: the largest distance of the written module's tool0 from the taught cycle's
    path; ``clearance_mm``: from the cell's margin (None without a cell); ``taught_units``: optimized
    moves put back as taught (their statement instead of the via points) to keep the cycle time."""

    levers: LeverResult | None
    note: str
    via_cycle_s: float | None = None
    via_energy_J: float | None = None
    deviation_mm: float | None = None
    clearance_mm: float | None = None
    taught_units: int = 0


def _plain(text: str) -> str:
    """The module without joulepath's header lines: read as itself, not as the program it came from."""
    from joulepath.program._rapid_write import HEADERS

    return "".join(ln for ln in text.splitlines(keepends=True) if not ln.strip().startswith(HEADERS))


def _added_lines(spec: CycleSpec) -> set[int]:
    """Lines of the procedures the via-point writer added (``jp_opt_*``)."""
    module = spec.module
    assert module is not None
    out: set[int] = set()
    for p in module.procedures:
        if p.name.lower().startswith("jp_opt_"):
            out.update(range(p.line, p.end_line + 1))
    return out


def _scaled(text: str, lines: set[int], factor: float) -> str:
    """``text`` with every ``\\T`` on ``lines`` times ``factor`` (to 0.1 ms, at least 1 ms)."""

    def times(m: re.Match[str]) -> str:
        return _written(float(m.group(2)) * factor)(m)

    out = text.splitlines(keepends=True)
    for k in lines:
        if 1 <= k <= len(out):
            out[k - 1] = T_ARG.sub(times, out[k - 1])
    return "".join(out)


def _fitted(
    text: str,
    spec: CycleSpec,
    t: float,
    e: float,
    t_taught: float,
    run: Callable[[str], tuple[CycleSpec, float, float]],
    keeps: Callable[[str], bool],
) -> tuple[str, CycleSpec, float, float]:
    """A module over the taught cycle time with every via point's ``\\T`` shortened by one factor,
    until it fits (at most :data:`TIME_FITS` tries; as it was where shortening does not help, or
    where it runs a ``MoveL``'s line faster than its speed data: ``keeps(module)`` false)."""
    as_planned, factor = text, 1.0
    added = _added_lines(spec)
    for _ in range(TIME_FITS):
        if t <= t_taught + _TOL_S:
            break
        factor *= t_taught / t * (1.0 - 1e-3)
        scaled = _scaled(as_planned, added, factor)
        spec_s, t_s, e_s = run(scaled)
        if t_s >= t or not keeps(scaled):
            break
        text, spec, t, e = scaled, spec_s, t_s, e_s
    return text, spec, t, e


_CALL = re.compile(r"^\s*jp_opt_\w+(?:\s+[\w\s,]*)?;\s*$", re.IGNORECASE)


def _units(text: str) -> list[int]:
    """The via-point calls that can go back to the taught statement: line indices (0-based) of calls
    of an added procedure standing directly under the ``! joulepath: was:`` lines of what they replace."""
    from joulepath.program._rapid_write import WAS

    lines = text.splitlines()
    return [k for k, ln in enumerate(lines) if _CALL.match(ln) and k and lines[k - 1].strip().startswith(WAS)]


def _reverted(text: str, call: int) -> str:
    """``text`` with the call on line index ``call`` replaced by the taught statement it replaced."""
    from joulepath.program._rapid_write import WAS

    lines = text.splitlines(keepends=True)
    first = call
    while first and lines[first - 1].strip().startswith(WAS):
        first -= 1
    raw = lines[first]
    indent = raw[: len(raw) - len(raw.lstrip())]
    end = "\r\n" if raw.endswith("\r\n") else "\n"
    taught = [indent + ln.strip()[len(WAS) :] + end for ln in lines[first:call]]
    return "".join([*lines[:first], *taught, *lines[call + 1 :]])


_BLOCK_WORDS = re.compile(
    r"^\s*(PROC|ENDPROC|FUNC|ENDFUNC|TRAP|ENDTRAP|MODULE|ENDMODULE|WHILE|ENDWHILE|FOR|ENDFOR|IF|ELSEIF|ELSE|"
    r"ENDIF|TEST|CASE|DEFAULT|ENDTEST|ERROR|UNDO|BACKWARD)\b",
    re.IGNORECASE,
)


def _is_statement(line: str) -> bool:
    s = line.strip()
    return bool(s) and not s.startswith("!") and not _BLOCK_WORDS.match(s)


def _code_and_comment(line: str) -> tuple[str, str]:
    """A line's code and its comment (from a ``!`` outside a string)."""
    quoted = False
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == "!" and not quoted:
            return line[:i].strip(), line[i:].strip()
    return line.strip(), ""


def _marked(before: str, after: str, added: set[int]) -> tuple[str, dict[int, int]]:
    """``after`` (``before`` with levers written) with each edit of the program's own statements made
    restorable: the lines that stood there as ``! joulepath: was:`` comments, and what stands now on
    the one line under them (what :func:`joulepath.program._rapid_write.restore_program` drops);
    edits inside the added procedures (``added``: their lines in ``before``) as they are. Also where
    each line of ``before`` stands in the result (1-based)."""
    from joulepath.program._rapid_write import WAS

    a = before.splitlines(keepends=True)
    b = after.splitlines(keepends=True)
    now: list[list[str]] = [[ln] for ln in a]  # what stands for each line of ``before``
    touched = [False] * len(a)
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=a, b=b, autojunk=False).get_opcodes():
        if tag == "equal":
            continue
        if tag in ("replace", "delete"):
            for i in range(i1, i2):
                now[i], touched[i] = [], True
            now[i1] = list(b[j1:j2])
            continue
        at = i1 if i1 < len(a) and _is_statement(a[i1]) else i1 - 1  # an insertion: to its statement
        now[at] = [*b[j1:j2], *now[at]] if at == i1 else [*now[at], *b[j1:j2]]
        touched[at] = True
    out: list[str] = []
    where: dict[int, int] = {}
    i = 0
    while i < len(a):
        if not touched[i] or (i + 1) in added:
            for ln in now[i]:
                out.append(ln)
            where[i + 1] = len(out)
            i += 1
            continue
        j = i
        while j + 1 < len(a) and touched[j + 1] and (j + 2) not in added:
            j += 1
        first = a[i]
        indent = first[: len(first) - len(first.lstrip())]
        end = "\r\n" if first.endswith("\r\n") else "\n"
        for raw in a[i : j + 1]:
            body = raw.rstrip("\r\n")
            body = body[len(indent) :] if body.startswith(indent) else body.lstrip()
            out.append(indent + WAS + body + end)
        parts = [_code_and_comment(ln) for k in range(i, j + 1) for ln in now[k]]
        code = " ".join(c for c, _ in parts if c)
        comment = " ".join(c for _, c in parts if c)
        out.append(indent + " ".join(x for x in (code, comment) if x) + end)
        for k in range(i, j + 1):
            where[k + 1] = len(out)
        i = j + 1
    return "".join(out), where


def _with_header(text: str, header: list[str]) -> str:
    lines = text.splitlines(keepends=True)
    at = next(k for k, ln in enumerate(lines) if re.match(r"\s*MODULE\b", ln, re.IGNORECASE))
    nxt = lines[at + 1] if at + 1 < len(lines) else "    "
    indent = nxt[: len(nxt) - len(nxt.lstrip())] or "    "
    newline = "\r\n" if lines[at].endswith("\r\n") else "\n"
    return "".join([*lines[: at + 1], *(indent + h + newline for h in header), *lines[at + 1 :]])


def _fastest_on_lines(
    lines: tuple[LineSpeed, ...], plan: PlannedCycle, added: set[int]
) -> tuple[float, LineSpeed | None]:
    """The largest ratio of the cycle's TCP speed to the speed data of the taught ``MoveL`` line it
    runs on (:func:`joulepath.program._line_speed.fastest_on_lines`), and that line; outside the
    blends the controller makes between a statement of the program and the next (superposed, as in
    the taught cycle), inside those between two statements added on ``added`` lines (a via-point
    chain's corners, whose times were chosen here)."""
    if not lines:
        return 1.0, None
    traj = cycle_motion(plan)
    first = plan.moves[0].step
    assert first.robot is not None and first.tcp is not None
    own = np.ones(traj.t.size, dtype=bool)
    moving = [m for m in plan.moves if m.profile.duration > 0]
    for a, b in zip(moving, moving[1:], strict=False):
        if b.t0 < a.t_end and not (a.step.line in added and b.step.line in added):
            own &= (traj.t < b.t0) | (traj.t > a.t_end)
    pos, _ = tcp_pose(first.robot, traj.q[own], first.tcp)
    vel = tcp_velocity(first.robot, traj.q[own], traj.qd[own], first.tcp)
    return fastest_on_lines(lines, pos, vel)


def _left(dev_mm: float, corridor_mm: float) -> str:
    return f"its tool0 leaves the taught path by {dev_mm:.1f} mm (the corridor is {corridor_mm:g} mm)"


def _tool0_path(plan: PlannedCycle) -> FloatArray:
    """The cycle's tool0 (flange) positions (m) on the 2.5 ms grid (the first move's robot): the point
    whose corridor the cycle's plan keeps (:class:`joulepath.program.CycleSettings` ``corridor_mm``)."""
    first = plan.moves[0].step
    assert first.robot is not None
    return first.robot.fk(cycle_motion(plan).q).position_m


@dataclass(frozen=True, slots=True, eq=False)
class _Searched:
    """:meth:`_ViaSearch.search`'s result: the best program with levers (None: none) and why not,
    its corridor deviation and clearance (``kept``) and base; the last deviation and clearance
    measured, and the last base searched (None: none)."""

    found: LeverResult | None
    why: str
    kept: tuple[float | None, float | None]
    found_base: Any
    dev: float | None
    clear: float | None
    last: Any


class _ViaSearch:
    """The via-point modules of one :func:`via_levers` run on the controller emulation (each read and
    planned once, checked against the taught cycle's time, its MoveL speed data and its tool0 path),
    and the lever search on them."""

    def __init__(
        self,
        robot: Robot,
        energy: str,
        config: ControllerConfig,
        path: str,
        plan_t: PlannedCycle,
        t_taught: float,
        corridor_mm: float | None,
    ) -> None:
        self.robot = robot
        self.energy = energy
        self.config = config
        self.path = path
        self.plan_t = plan_t
        self.t_taught = t_taught
        self.corridor_mm = corridor_mm
        self.lines = line_speeds(plan_t)
        self.runs: dict[str, tuple[CycleSpec, PlannedCycle]] = {}  # per module run: read as, its plan
        self.on_lines: dict[str, float] = {}  # per module asked: its fastest on a MoveL line (to its speed)
        self._taught_tree: Any = None

    def run(self, candidate: str) -> tuple[CycleSpec, float, float]:
        spec_c = resolve_module(parse_module(candidate, path=self.path), self.robot)
        plan_c, t_c, e_c = _Evaluator(spec_c, [], self.energy, self.config)(())
        self.runs[candidate] = (spec_c, plan_c)
        return spec_c, t_c, e_c

    def line_ratio(self, candidate: str) -> float:
        if candidate not in self.on_lines:  # the motion's TCP, only for the modules whose lines are asked
            spec_c, plan_c = self.runs[candidate]
            self.on_lines[candidate] = _fastest_on_lines(self.lines, plan_c, _added_lines(spec_c))[0]
        return self.on_lines[candidate]

    def keeps_lines(self, candidate: str) -> bool:
        return self.line_ratio(candidate) <= 1.0 + SPEED_TOL

    def in_time_first(self, t: float, e: float) -> tuple[bool, float]:  # within the taught time, least energy
        return (t > self.t_taught + _TOL_S, e if t <= self.t_taught + _TOL_S else t)  # else the least over it

    def fit(self, candidate: str) -> tuple[str, CycleSpec, float, float, int]:
        """The module within the taught cycle time: its ``\\T`` shortened, else units put back as taught
        (the cheapest that fits, else the one that saves most time)."""
        spec_v, t_v, e_v = self.run(candidate)
        back = 0
        while not self.keeps_lines(candidate):  # units running a MoveL's line over its speed data go back
            backs = [(_reverted(candidate, u), *self.run(_reverted(candidate, u))) for u in _units(candidate)]
            if not backs:
                break
            keep = [x for x in backs if self.keeps_lines(x[0])]
            candidate, spec_v, t_v, e_v = (
                min(keep, key=lambda x: x[3]) if keep else min(backs, key=lambda x: self.line_ratio(x[0]))
            )
            back += 1
        candidate, spec_v, t_v, e_v = _fitted(
            candidate, spec_v, t_v, e_v, self.t_taught, self.run, self.keeps_lines
        )
        while t_v > self.t_taught + _TOL_S:
            tries = [self.run(_reverted(candidate, u)) + (u,) for u in _units(candidate)]
            if not tries:
                break
            fits = [x for x in tries if x[1] <= self.t_taught + _TOL_S]
            spec_r, t_r, e_r, u = min(fits, key=lambda x: x[2]) if fits else min(tries, key=lambda x: x[1])
            if t_r >= t_v - _TOL_S:
                break
            candidate, spec_v, t_v, e_v = _fitted(
                _reverted(candidate, u), spec_r, t_r, e_r, self.t_taught, self.run, self.keeps_lines
            )
            back += 1
        return candidate, spec_v, t_v, e_v, back

    def farthest(self, plan_c: PlannedCycle) -> tuple[float, float]:
        """The farthest the cycle's tool0 comes from the taught cycle's (mm), and when (s)."""
        from scipy.spatial import cKDTree

        if self._taught_tree is None:
            self._taught_tree = cKDTree(_tool0_path(self.plan_t))
        d = self._taught_tree.query(_tool0_path(plan_c))[0]
        k = int(np.argmax(d))
        return 1000.0 * float(d[k]), plan_c.cycle_time * k / max(1, d.size - 1)  # its 2.5 ms grid

    def past_corridor(self, plan_c: PlannedCycle) -> tuple[float, float]:
        """How far (mm) the cycle's tool0 comes past the corridor (negative: within it), and when (s)."""
        dev_c, at_s = self.farthest(plan_c)
        return dev_c - (np.inf if self.corridor_mm is None else self.corridor_mm), at_s

    def bases(
        self, plan: Any, plan_t: PlannedCycle, text: str, *, timed_chains: bool, max_seconds: float | None
    ) -> tuple[list[Any], int]:
        """The via-point modules the levers are searched on: ``text`` (the plan's via points, fitted into
        the taught cycle time; its levers searched on every statement, then on the via points' alone) and,
        with ``timed_chains``, its points at equal arc length with each chain's ``\\T`` timed for the
        controller; and how many chains that timed."""
        from joulepath.program._output import written_rapid

        timed_n = 0
        old = self.fit(text)  # the via-point layout the plan was checked with (fitted into the taught time)
        only_sets: tuple[set[int] | None, ...] = (None, _added_lines(old[1]))
        bases = [(*old, only_sets)]
        if timed_chains:  # the plan's points kept at equal arc length, their \T timed for the controller
            timings = []
            for room in (BLEND_ROOM, 0.0):  # clear of the taught blends, or every point kept
                dense = _plain(
                    written_rapid(replace(plan, vias=dense_vias(plan, taught=plan_t, room=room))).text
                )
                spec_d = resolve_module(parse_module(dense, path=self.path), self.robot)
                timed = time_chains(
                    dense,
                    spec_d,
                    _added_lines(spec_d),
                    measure=self.energy,
                    config=self.config,
                    cycle_s=self.t_taught,
                    run_cycle=lambda c: self.run(c)[1:],
                    max_seconds=max_seconds,
                    speeds=self.lines,
                )
                if self.keeps_lines(
                    timed.text
                ):  # its chains on a MoveL's line are timed within its speed data
                    timings.append(timed)
            if timings:  # within the taught cycle for the least energy, else the least over it
                timed = min(timings, key=lambda x: self.in_time_first(x.cycle_s, x.energy_J))
                # not fitted by shortening its \T (that breaks its chains): over the taught time, the lever
                # search brings it in
                spec_t = resolve_module(parse_module(timed.text, path=self.path), self.robot)
                bases.append(
                    (timed.text, spec_t, timed.cycle_s, timed.energy_J, 0, (None,))
                )  # every statement
                timed_n = timed.timed
        return bases, timed_n

    def search(
        self,
        bases: list[Any],
        *,
        spec: CycleSpec,
        e_taught: float,
        lab_taught: float,
        cell: Any,
        max_seconds: float | None,
        max_plans: int,
    ) -> _Searched:
        """The levers searched on each of the ``bases`` (every move statement, then the via points'
        alone), each result written, restored, read again by the interpreter and run again, and kept
        where it runs within the taught cycle time for less energy and keeps the corridor and the cell:
        the one that saves most as executed (:class:`_Searched`)."""
        from joulepath.program._cell import clearance
        from joulepath.program._rapid_write import HEADERS, restore_program
        from joulepath.program._task import as_sequence, read_written

        assert spec.module is not None
        original = list(spec.module.source)
        dev: float | None = None
        clear: float | None = None
        header: list[str] = []
        found: LeverResult | None = None
        why = "no lever search ran"
        kept: tuple[float | None, float | None] = (None, None)
        found_base = bases[0]
        last: Any = None
        searches = [
            (b, only) for b in bases for only in b[5] if b[2] <= self.t_taught + _TOL_S or b is not bases[0]
        ]
        for (
            base,
            only,
        ) in searches:  # per base, every move statement and the via points' alone: the best as executed
            last = base
            text, via_spec, t_via, e_via, reverted, _ = base
            added = _added_lines(via_spec)
            try:
                lv = levers_module(
                    via_spec,
                    self.robot,
                    energy=self.energy,
                    text=text,
                    config=self.config,
                    max_seconds=max_seconds,
                    max_evaluations=max_plans,
                    baseline=(self.t_taught, e_taught, lab_taught),
                    only_lines=only,
                    bound=None
                    if self.corridor_mm is None
                    else self.past_corridor,  # each step keeps the corridor
                )
            except InvalidInput as err:
                why = f"the levers of the via points: {err}"
                continue
            if self.corridor_mm is not None:  # where the search could not bring it within the corridor
                self.run(lv.written_text)
                dev = self.farthest(self.runs[lv.written_text][1])[0]
                if dev > self.corridor_mm:
                    why = _left(dev, self.corridor_mm)
                    continue
            if not (lv.cycle_s <= self.t_taught + _TOL_S and lv.energy_J < e_taught):
                why = (
                    f"the via-point module runs {lv.cycle_s:.3f} s for {lv.energy_J:.2f} J against the "
                    f"taught {self.t_taught:.3f} s and {e_taught:.2f} J"
                )
                continue
            body, where = _marked(text, lv.written_text, added) if only is None else (lv.written_text, None)
            saved = 100.0 * (1.0 - lv.energy_J / e_taught)
            header = [
                f"{HEADERS[0]} {__version__} for energy: the plan's via points and the controller's levers "
                f"(AccSet, speed data or \\T, zones), as the controller emulation runs this module: "
                f"{lv.cycle_s:.3f} s per cycle (taught {self.t_taught:.3f} s), {lv.energy_J:.2f} J against "
                f"the taught {e_taught:.2f} J on {self.energy} energy ({saved:.1f} % saved). "
                "See cycle.json.",
                f"{HEADERS[1]} each optimized move calls jp_opt_<proc>_<n> (at the module's end), each "
                "changed statement stands under its 'was:' lines. Re-teaching a target: optimize the "
                "re-taught module again.",
            ]
            written = _with_header(body, header)
            restored = restore_program(written)
            if restored is None or restored.splitlines() != original:
                why = "the written module does not restore to the program it was written from"
                continue
            # read again by the other reader (the interpreter) and run again: the searched motion, or nothing
            again = read_written(written, f"{spec.module.path} (optimized)", self.robot)
            plan_a, t_again, e_again = _Evaluator(as_sequence(again), [], self.energy, self.config)(())  # type: ignore[arg-type]
            if abs(t_again - lv.cycle_s) > 1e-3 or abs(e_again - lv.energy_J) > _TOL_REL * max(1.0, e_taught):
                why = (
                    f"the written module, read again, runs {t_again:.3f} s and {e_again:.3f} J against the "
                    f"searched {lv.cycle_s:.3f} s and {lv.energy_J:.3f} J; not written"
                )
                continue
            dev = self.farthest(plan_a)[0]
            clear = None
            if cell is not None:
                first = plan_a.moves[0].step
                assert first.robot is not None and first.tcp is not None
                q = cycle_motion(plan_a).q
                clear = 1000.0 * (clearance(cell, first.robot, q, first.tcp).distance - cell.margin)
            if self.corridor_mm is not None and dev > self.corridor_mm:
                why = _left(dev, self.corridor_mm)
                continue
            if clear is not None and clear < 0.0:
                why = f"it comes {-clear:.1f} mm inside the cell's margin"
                continue
            shift = len(header)
            moves = tuple(
                replace(m, line=(m.line if where is None else where.get(m.line, m.line)) + shift)
                for m in lv.moves
            )
            if found is None or lv.energy_J < found.energy_J:
                found = replace(lv, written_text=written, moves=moves, base="via points")
                kept = (dev, clear)
                found_base = base
        return _Searched(found, why, kept, found_base, dev, clear, last)


def via_levers(
    result: Any,
    robot: Robot,
    *,
    energy: str,
    corridor_mm: float | None = 100.0,
    cell: Any = None,
    max_seconds: float | None = None,
    config: ControllerConfig | None = None,
    timed_chains: bool = True,
    max_plans: int = MAX_PLANS,
) -> ViaLevers:
    """The via-point module of ``result``'s plan with the controller's levers of its via points,
    as the controller emulation runs it (module docstring).

    Parameters
    ----------
    result : CycleResult
        The optimized cycle of a one-module RAPID program (``result.spec.module``).
    robot : Robot
        The robot the program was read on.
    energy : str
        The energy measure minimised (the run's).
    corridor_mm : float, optional
        The written module's tool0 stays within this distance (mm) of the taught cycle's tool0 path
        (None: not checked), and the lever search keeps it at every step.
    cell : Cell, optional
        Obstacles: the written module's motion must keep the cell's margin.
    max_seconds : float, optional
        Wall time of the lever search (what it found by then is written).
    config : ControllerConfig, optional
        The emulated controller.
    max_plans : int, optional
        Cycle plans each lever search makes at most (the bound of work that ends it).
    timed_chains : bool, optional
        Also the plan's via points at equal arc length with each chain's ``\\T`` timed for the
        controller (:mod:`joulepath.program._via_timing`); the module that runs the taught cycle
        time for less energy is the one the levers are searched on.

    Returns
    -------
    ViaLevers
        ``levers`` None (and ``note`` why) where no such module runs within the taught cycle time
        for less energy, reads back as searched, and keeps the corridor and the cell.
    """
    from joulepath.program._output import written_rapid

    config = config or ControllerConfig()
    spec = result.spec
    if spec.module is None:
        return ViaLevers(None, "not a program of one module")
    plan = result.unretimed or result
    if not plan.paths or not result.limits_ok:
        return ViaLevers(None, "no optimized move within the limits to write as via points")
    try:
        text = _plain(written_rapid(plan).text)
    except LimitViolation as err:
        return ViaLevers(None, str(err))
    taught = _Evaluator(spec, [], energy, config)
    plan_t, t_taught, _ = taught(())
    e_taught, lab_taught = taught.energies(plan_t)
    path = f"{spec.module.path} (via points)"
    search = _ViaSearch(robot, energy, config, path, plan_t, t_taught, corridor_mm)
    try:
        bases, timed_n = search.bases(plan, plan_t, text, timed_chains=timed_chains, max_seconds=max_seconds)
    except JoulepathError as err:
        return ViaLevers(None, f"the via-point module cannot be read: {err}")
    text, via_spec, t_via, e_via, reverted, _ = min(bases, key=lambda b: search.in_time_first(b[2], b[3]))
    if not any(b[2] <= t_taught + _TOL_S for b in bases) and not timed_chains:
        return ViaLevers(
            None,
            f"the via-point module takes {t_via:.3f} s per cycle, longer than the taught {t_taught:.3f} s",
            t_via,
            e_via,
        )
    searched = search.search(
        bases,
        spec=spec,
        e_taught=e_taught,
        lab_taught=lab_taught,
        cell=cell,
        max_seconds=max_seconds,
        max_plans=max_plans,
    )
    found, why, kept, found_base = searched.found, searched.why, searched.kept, searched.found_base
    dev, clear = searched.dev, searched.clear
    if searched.last is not None:  # the last base searched
        _, _, t_via, e_via, reverted, _ = searched.last
    if found is not None:
        dev, clear = kept
        _, _, t_via, e_via, reverted, _ = found_base
    if found is None:
        return ViaLevers(None, why, t_via, e_via, dev, clear, reverted)
    saved = 100.0 * (1.0 - found.energy_J / e_taught)
    return ViaLevers(
        found,
        f"via points with levers: {saved:.1f} % saved as executed"
        + (
            f" (the plan's via points with the \\T of their {timed_n} chain(s) timed for the controller)"
            if found_base is not bases[0]
            else ""
        )
        + (f" ({reverted} optimized move(s) kept as taught to keep the cycle time)" if reverted else ""),
        t_via,
        e_via,
        dev,
        clear,
        reverted,
    )
