"""Via points timed for the controller: each chain of a via-point module re-timed on the emulation.

A plan's motion written as ``MoveAbsJ`` via points with ``\\T`` and large zones is run by the
controller as a timed fly-by chain (:func:`joulepath.sim._timing.chain_corners`): constant joint
velocity between the points, a corner whose width the zone and the TCP distances to the
neighbouring points set, sin² ramps at the acceleration limit from and to rest. The plan's own
times, taken at its samples, ask more of some corners than the acceleration limit allows (the
corner concentrates the velocity change of two segments in part of them) and leave no room for
the ramps; the controller then runs those points as separate moves, slower and dearer, and the
via-point layout (:func:`joulepath.sim._via.layout`) drops points until the chain holds, which
leaves long straight segments that carry little of the plan's shape.

Here the points stay where the plan puts them, at equal TCP arc length about
:data:`VIA_SPACING_S` apart (but next to a taught move that blends into the unit or out of it:
the controller's blend there lasts at most half of either move, so the via point next to it is
kept :data:`BLEND_ROOM` times the taught blend's time away), and the ``\\T`` of each chain is
chosen instead, for the least energy as the emulation runs the chain, such that every corner and
ramp holds with a margin (:data:`MARGIN`, the conditions of
:func:`joulepath.sim._timing._chain_profiles` written as constraints on the times), every segment
on a taught ``MoveL``'s line runs within the line's speed data, and the chain, run on its own from
rest to rest with the move that ends it, takes no longer than the plan gave its unit (or, where no
timing holds in that time, the least it can). When the whole module then runs longer than the
taught cycle, the chains with time to spare give it up, in proportion, and are timed again; when
it runs shorter, the time left over is shared among the chains (at most :data:`FITS` rounds, the
least energy within the taught cycle kept).
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.optimize import minimize

from joulepath._typing import FloatArray
from joulepath.program._levers import _Evaluator
from joulepath.program._line_speed import LineSpeed, blends, chord_floor
from joulepath.program._resolve import CycleSpec
from joulepath.sim import (
    ChainProfile,
    ControllerConfig,
    PlannedCycle,
    acc_share,
    acceleration_limit,
    stops_after,
    tcp_pose,
)

VIA_SPACING_S = 0.05
"""s between the via points of a chain, on average (equal TCP arc length inside each move)."""
MARGIN = 0.03
"""Share of each corner's and ramp's condition kept in reserve, so that the chain holds on the
controller with the times rounded as written (0.1 ms)."""
FITS = 6
"""Rounds, at most, of fitting the chains' budgets to the taught cycle: giving up their spare time
when the module runs over it, sharing the time left over when it runs under it."""
GIVE_S = 0.01
"""s: a module this much under the taught cycle shares the time left over among its chains."""
GIVE_SHARE = 0.95
"""Share of the time left over that is given to the chains (their time on their own is not quite
what they add to the cycle)."""
_MAX_ITER = 30
FREEDOM = 0.02
"""A chain whose shortest time is within this share of its budget is written at its shortest (no
time to spend on a search)."""
BLEND_ROOM = 2.0
"""The via point next to a kept move that blends into a unit (or out of it) is at least this many
times the taught blend's time from the unit's end (the blend lasts at most half of either move)."""
T_ARG = re.compile(r"(\\T\s*:=\s*)(\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)")
"""A move's ``\\T`` argument: the text before its value, and the value (s)."""


@dataclass(frozen=True, slots=True)
class _Run:
    """One timed chain of a via-point module: its steps (indices into the module's cycle), where it
    starts, and the step that ends its unit when that one cannot join the chain (a ``MoveL``)."""

    steps: tuple[int, ...]
    start: FloatArray
    tail: int | None


def chain_runs(spec: CycleSpec, lines: set[int]) -> list[_Run]:
    """The timed chains of the module's added procedures (``lines``): consecutive joint moves with
    ``\\T`` joined by zones, each with the move of the same procedure that ends it where that one
    is not a joint move; a chain whose lines run more than once per cycle is left out (one time
    per written line)."""
    steps = spec.steps
    q = spec.start
    runs: list[_Run] = []
    cur: list[int] = []
    start = q
    for i, s in enumerate(steps):
        if s.kind != "move":
            if s.kind == "wait":  # the robot stops (an instruction kept verbatim takes no time)
                if cur:
                    runs.append(_Run(tuple(cur), start, None))
                cur = []
            continue
        assert s.q is not None
        timed = s.line in lines and s.time_s is not None and not s.linear and s.zone_mm is not None
        if timed and not stops_after(spec, i):
            if not cur:
                start = q
            cur.append(i)
        else:
            if cur:
                last = s.line in lines and s.time_s is not None
                if last and not s.linear:
                    cur.append(i)  # the chain's last point, ending at rest
                    runs.append(_Run(tuple(cur), start, None))
                else:
                    runs.append(_Run(tuple(cur), start, i if last else None))
            cur = []
        q = s.q
    if cur:
        runs.append(_Run(tuple(cur), start, None))
    seen: dict[int, int] = {}
    for r in runs:
        for i in (*r.steps, *(() if r.tail is None else (r.tail,))):
            seen[steps[i].line] = seen.get(steps[i].line, 0) + 1
    return [
        r
        for r in runs
        if len(r.steps) >= 2
        and all(seen[steps[i].line] == 1 for i in (*r.steps, *(() if r.tail is None else (r.tail,))))
    ]


class _Chain:
    """A run on its own, from rest to rest: its conditions on the times, its motion on the emulation."""

    def __init__(
        self,
        spec: CycleSpec,
        run: _Run,
        measure: str,
        config: ControllerConfig,
        lines: tuple[LineSpeed, ...] = (),
    ) -> None:
        self.run = run
        self.base = [spec.steps[i] for i in run.steps]
        self.tail = None if run.tail is None else spec.steps[run.tail]
        self.spec = spec
        self.config = config
        self.measure = measure
        self.evaluator = _Evaluator(spec, [], measure, config)
        self._motions: dict[bytes, tuple[bool, float, float]] = {}
        robot = self.base[0].robot
        assert robot is not None
        self.vmax = np.asarray(robot.velocity_limit, dtype=float)
        amax = acceleration_limit(robot, config.accel_time)
        self.amax = np.full(robot.n_joints, np.inf) if amax is None else np.asarray(amax, dtype=float)
        qs: list[FloatArray] = [run.start]
        for st in self.base:
            assert st.q is not None
            qs.append(st.q)
        self.dq = [np.asarray(qs[j + 1] - qs[j], dtype=float) for j in range(len(self.base))]
        paths = self.evaluator.paths
        self.length = [
            paths.path(s, np.asarray(qs[j]), spec.source).length_mm for j, s in enumerate(self.base)
        ]
        self.share = [acc_share(s) for s in self.base]
        tcp = self.base[0].tcp
        assert tcp is not None
        pos, _ = tcp_pose(robot, np.asarray(qs, dtype=float), tcp)
        # a segment on a taught MoveL's line: no shorter than its length at the line's speed data
        self.floor = np.array(
            [(1.0 + MARGIN) * chord_floor(lines, pos[j], pos[j + 1]) for j in range(len(self.base))]
        )

    def spec_at(self, T: FloatArray) -> CycleSpec:
        timed = [replace(s, time_s=float(t)) for s, t in zip(self.base, T, strict=True)]
        return replace(
            self.spec, steps=(*timed, *(() if self.tail is None else (self.tail,))), start=self.run.start
        )

    def conditions(self, T: FloatArray, extra: float = 0.0) -> FloatArray:
        """Each condition of a held chain (:func:`joulepath.sim._timing._chain_profiles`), >= 0 where it
        holds with :data:`MARGIN` (and ``extra``) to spare."""
        margin = MARGIN + extra
        n = len(T)
        sides = []  # each corner's width as its two segments allow it (the corner takes the lesser)
        for k in range(n - 1):
            La, Lb = self.length[k], self.length[k + 1]
            z = self.base[k].zone_mm
            assert z is not None
            if La > 1e-9 and Lb > 1e-9:
                R = min(z, 0.5 * La, 0.5 * Lb)
                sides.append((2.0 * R / La * T[k], 2.0 * R / Lb * T[k + 1]))
            else:
                sides.append((T[k], T[k + 1]))
        out: list[float] = []
        speed = []
        for j in range(n):
            amax = self.amax * self.share[j]
            m = float(np.max(np.abs(self.dq[j]) / amax))
            if j in (0, n - 1):
                disc = T[j] * T[j] - np.pi * m
                out.append(disc - margin * T[j] * T[j])
                r = T[j] - np.sqrt(max(disc, 0.0))
                w = min(sides[0] if j == 0 else sides[-1])
                out.append(T[j] - 0.5 * w - r - margin * T[j])
                v = self.dq[j] / max(T[j] - 0.5 * r, 1e-9)
            else:
                v = self.dq[j] / T[j]
            speed.append(v)
            out.extend((1.0 - margin) * self.vmax - np.abs(v))
        for k in range(n - 1):  # |dv| <= a * width, as four smooth conditions per joint
            amax = (1.0 - margin) * self.amax * min(self.share[k], self.share[k + 1])
            dv = speed[k + 1] - speed[k]
            for w in sides[k]:
                out.extend(amax * w - dv)
                out.extend(amax * w + dv)
        on_line = self.floor > 0.0
        out.extend((T[on_line] - (1.0 + extra) * self.floor[on_line]).tolist())
        return np.asarray(out)

    def motion(self, T: FloatArray) -> tuple[bool, float, float]:
        """Whether the emulation keeps every corner, the run's time (s) and energy (J); each timing run
        once (the search asks for its energy and its time at the same point)."""
        key = np.asarray(T, dtype=float).tobytes()
        found = self._motions.get(key)
        if found is None:
            plan, t, e = self.evaluator.run(self.spec_at(T))
            held = sum(isinstance(m.profile, ChainProfile) for m in plan.moves[: len(T)]) == len(T)
            found = self._motions[key] = (held, t, e)
        return found


def _fastest(chain: _Chain, T0: FloatArray) -> FloatArray | None:
    """The chain's shortest times within its conditions (from a slowed start that holds them)."""
    scale = 1.0
    while chain.conditions(T0 * scale).min() < 0.0 and scale < 64.0:
        scale *= 1.5
    if chain.conditions(T0 * scale).min() < 0.0:
        return None
    n = T0.size
    sol = minimize(  # solved with a little more margin than asked: its end holds what is asked
        lambda T: float(T.sum()),
        T0 * scale,
        jac=lambda T: np.ones_like(T),
        method="SLSQP",
        bounds=[(1e-3, None)] * n,
        constraints=[{"type": "ineq", "fun": lambda T: chain.conditions(T, 0.005)}],
        options={"maxiter": 200, "ftol": 1e-10},
    )
    for T in (np.asarray(sol.x, dtype=float), T0 * scale):
        if chain.conditions(T).min() >= 0.0 and chain.motion(T)[0]:
            return T
    return None


def _cheapest(chain: _Chain, start: FloatArray, budget: float) -> tuple[FloatArray, float, float]:
    """The least-energy times within the conditions and ``budget`` (s, the run's time on its own),
    from ``start`` (which holds them): the best held evaluation seen."""
    _, t0, e0 = chain.motion(start)
    best: list[tuple[float, FloatArray, float]] = [(e0, start.copy(), t0)]

    def objective(T: FloatArray) -> float:
        ok, t, e = chain.motion(T)
        if not ok:
            return 2.0  # a broken chain: the controller runs it another way (never kept)
        if e < best[0][0] and t <= budget + 1e-9 and chain.conditions(T).min() >= -1e-9:
            best[0] = (e, T.copy(), t)
        return e / e0

    def spare(T: FloatArray) -> float:
        ok, t, _ = chain.motion(T)
        return budget - t if ok else -1.0

    minimize(
        objective,
        start,
        method="SLSQP",
        bounds=[(1e-3, budget)] * start.size,
        constraints=[{"type": "ineq", "fun": chain.conditions}, {"type": "ineq", "fun": spare}],
        options={"maxiter": _MAX_ITER, "ftol": 1e-6},
    )
    e, T, t = best[0]
    return T, t, e


@dataclass(frozen=True, slots=True)
class TimedChains:
    """The module with its chains timed (``text``; as the emulation runs it, ``cycle_s`` and
    ``energy_J``), the runs re-timed and kept as written."""

    text: str
    timed: int
    kept: int
    cycle_s: float
    energy_J: float


def time_chains(
    text: str,
    spec: CycleSpec,
    lines: set[int],
    *,
    measure: str,
    config: ControllerConfig,
    cycle_s: float,
    run_cycle: Callable[[str], tuple[float, float]],
    max_seconds: float | None = None,
    speeds: tuple[LineSpeed, ...] = (),
) -> TimedChains:
    """``text`` (the via-point module read as ``spec``) with the ``\\T`` of each chain of the added
    procedures' ``lines`` timed for the controller (module docstring); ``cycle_s``: the taught
    cycle time the whole module must keep; ``run_cycle(text) -> (cycle s, energy J)``: the whole
    module on the emulation; ``max_seconds``: wall time of the searches (after it, each chain is
    written at its shortest times, stretched over its budget where that holds); ``speeds``: the
    taught ``MoveL`` lines, whose speed data bounds each chain segment on them."""
    deadline = None if max_seconds is None else time.perf_counter() + max_seconds
    chains: list[tuple[_Chain, FloatArray, float, float]] = []  # chain, fastest, its time, the plan's
    kept = 0
    for run in chain_runs(spec, lines):
        chain = _Chain(spec, run, measure, config, speeds)
        T0 = np.asarray([chain.spec.steps[i].time_s for i in run.steps], dtype=float)
        tail_s = 0.0 if chain.tail is None or chain.tail.time_s is None else float(chain.tail.time_s)
        fast = _fastest(chain, T0)
        if fast is None:
            kept += 1
            continue
        planned = float(T0.sum()) + tail_s + config.fine_dwell  # the unit's time as planned, rest to rest
        chains.append((chain, fast, chain.motion(fast)[1], planned))
    budgets = [max(planned, t_fast) for _, _, t_fast, planned in chains]
    tried: list[tuple[float, float, str]] = []  # (cycle s, energy J, text)
    timed: dict[int, tuple[float, FloatArray]] = {}  # per chain: the budget it was timed for, its times
    for _ in range(FITS):
        out = text.splitlines(keepends=True)
        for n, ((chain, fast, t_fast, _), budget) in enumerate(zip(chains, budgets, strict=True)):
            if n not in timed or timed[n][0] != budget:  # else its budget unchanged: the same times
                start = fast
                if t_fast < budget:  # the spare time spread over the chain, where that still holds
                    slow = fast * (1.0 + (budget - t_fast) / max(float(fast.sum()), 1e-9))
                    held, t_slow, _ = chain.motion(slow)
                    if held and chain.conditions(slow).min() >= 0.0 and t_slow <= budget + 1e-9:
                        start = slow
                late = deadline is not None and time.perf_counter() > deadline
                free = not late and t_fast < budget * (1.0 - FREEDOM)
                timed[n] = (budget, _cheapest(chain, start, budget)[0] if free else start)
            for i, t in zip(chain.run.steps, timed[n][1], strict=True):
                k = chain.spec.steps[i].line - 1
                out[k] = T_ARG.sub(_written(float(t)), out[k])
        candidate = "".join(out)
        t_c, e_c = run_cycle(candidate)
        tried.append((t_c, e_c, candidate))
        excess = t_c - cycle_s
        if excess < -GIVE_S and chains:  # under the taught cycle: the time left over shared by the chains
            whole = sum(budgets)
            budgets = [b - GIVE_SHARE * excess * b / whole for b in budgets]
            continue
        spare = [b - tf for b, (_, _, tf, _) in zip(budgets, chains, strict=True)]
        total = sum(s for s in spare if s > 0)
        if excess <= 1e-6 or total <= 1e-9:
            break
        budgets = [
            max(tf, b - 1.05 * excess * s / total) if s > 0 else b
            for b, s, (_, _, tf, _) in zip(budgets, spare, chains, strict=True)
        ]
    fitting = [x for x in tried if x[0] <= cycle_s + 1e-6]
    chosen = min(fitting, key=lambda x: x[1]) if fitting else min(tried, key=lambda x: x[0])
    return TimedChains(chosen[2], len(chains), kept, chosen[0], chosen[1])


def _written(t: float) -> Callable[[re.Match[str]], str]:
    """The replacement of a ``\\T`` argument's value by ``t`` (to 0.1 ms, at least 1 ms)."""
    return lambda m: f"{m.group(1)}{max(0.001, round(t, 4)):.4f}"


def dense_vias(
    plan: Any, spacing: float = VIA_SPACING_S, taught: PlannedCycle | None = None, room: float = BLEND_ROOM
) -> dict[int, tuple[int, ...]]:
    """Per optimized move of ``plan`` (a :class:`~joulepath.program.CycleResult`), via points at equal
    TCP arc length about ``spacing`` s apart (:func:`joulepath.sim._via._leg_indices`), none dropped
    but where a taught move blends into a joint move's unit or out of it (``taught``: the taught
    cycle as the controller runs it). There the controller blends by superposition for at most half
    of either move's time, so the via point next to the kept move is kept at least twice the taught
    blend's time away (:func:`_clear_of_blends`); nearer, the blend shrinks and the kept move runs
    almost to its target first, which costs the cycle the rest of the blend. ``room``: that many
    times the taught blend's time (0: none dropped)."""
    from joulepath.sim import leg_indices as _leg_indices

    steps = plan.spec.steps
    # per move: the taught blends into it and out of it (s)
    taught_blends = {} if taught is None else {m.index: (a, b) for m, a, b in blends(taught)}
    moves = [k for k, st in enumerate(steps) if st.kind == "move"]
    where = {k: n for n, k in enumerate(moves)}
    out: dict[int, tuple[int, ...]] = {}
    for i in plan.vias:
        step = steps[i]
        assert step.robot is not None and step.tcp is not None
        fine = plan.paths[i].fine
        idx = _leg_indices(step.robot, step.tcp, fine, spacing)
        n = where[i]
        before = moves[n - 1] if n > 0 else None
        after = moves[n + 1] if n + 1 < len(moves) else None
        if step.linear or i not in taught_blends:  # a MoveL's via points stay on its line, at its speed data
            out[i] = tuple(idx)
            continue
        into, out_of = taught_blends[i]
        if before is None or before in plan.vias:
            into = 0.0
        if after is None or after in plan.vias:
            out_of = 0.0
        out[i] = _clear_of_blends(fine.t, idx, room * into, room * out_of)
    return out


def _clear_of_blends(t: FloatArray, idx: list[int], head: float, tail: float) -> tuple[int, ...]:
    """``idx`` (sample indices into times ``t``) without the via points in the move's first ``head``
    and last ``tail`` seconds (its target, the last index, always kept)."""
    end = float(t[-1])
    kept = [k for k in idx[:-1] if t[k] >= head - 1e-9 and t[k] <= end - tail + 1e-9]
    return (*kept, idx[-1])
