"""A cycle's motion: the units' chosen entries in place of their windows of the default cycle, the
segments with a ``MoveL`` re-timed along their own joint path, and the energies over it.

:func:`cycle_motion` joins the pieces (the taught ones from the controller emulation, the units' from
their solves, every 2.5 ms); :func:`retime_segments` re-times every segment with a ``MoveL`` along its
path (:func:`joulepath.optimize.retime_on_path`); :func:`move_energies` and :func:`measures` sum the
energies per move and per measure.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.interpolate import BPoly

from joulepath._typing import FloatArray
from joulepath.dynamics import NOMINAL_FRICTION, Robot
from joulepath.energy import MEASURES, measure_energy
from joulepath.errors import InvalidInput
from joulepath.optimize import MeasureSummary, retime_on_path, tcp_velocity
from joulepath.program._cycle_geometry import move_robot
from joulepath.program._cycle_model import STEP, CycleMotion, Segment, Solved, sample_power, window_energy
from joulepath.program._cycle_units import CycleUnits
from joulepath.program._resolve import CycleSpec
from joulepath.sim import FINE_DT, PlannedCycle, PlannedMove, Plant, evaluate_cycle
from joulepath.trajectory import Trajectory

RETIME_MAX_SPAN_S = 4.0
"""s: a segment longer than this keeps its plan's timing (its re-timing along its path, at a control
point per 0.1 s on the 2.5 ms grid, would take minutes)."""

RETIME_GAIN = 1e-3
"""A segment re-timed along its path is kept where it saves at least this share of its energy (else
its plan stays as it is, and RAPID's own moves can follow it)."""

NO_SPEED_BOUND = 1e3
"""m/s: the TCP speed "bound" at a joint move's samples in a segment re-timed along its path (none)."""


@dataclass(frozen=True, slots=True, eq=False)
class PlacedUnit:
    """A unit's chosen entry in place of its ``window`` of the default cycle: its ``members`` (step
    indices), when it passes its inner targets (s from its start) and the entry."""

    members: tuple[int, ...]
    window: Segment
    passes: tuple[float, ...]
    solved: Solved


@dataclass(frozen=True, slots=True, eq=False)
class RetimedMotion:
    """:func:`retime_segments`'s result: the motion, each re-timed move's piece of it (by step index),
    the solves it made and whether its deadline stopped it."""

    motion: CycleMotion
    pieces: dict[int, Solved] = field(default_factory=dict)
    n_solves: int = 0
    timed_out: bool = False


def cycle_robot(spec: CycleSpec, plan: PlannedCycle) -> Robot:
    """The robot whose energies a cycle's figures are: its first move's, else the program's."""
    moves = plan.moves
    if moves and moves[0].step.robot is not None:
        return moves[0].step.robot
    return spec.robot


def cycle_motion(
    plan: PlannedCycle, spec: CycleSpec, placed: Sequence[PlacedUnit], *, use_waits: bool
) -> CycleMotion:
    """The cycle ``plan`` with each unit's chosen entry (``placed``) in place of its window and, with
    ``use_waits``, the idle waits left out: every piece sampled every 2.5 ms from its own start (the taught
    pieces from the controller emulation, the units' from their solves), and the cycle's last
    sample at its end; where each move starts in it."""
    cut: list[tuple[float, float, Solved | None]] = [(u.window.t0, u.window.t1, u.solved) for u in placed]
    if use_waits:
        cut += [(t0, t0 + sec, None) for k, t0, sec in plan.waits if spec.steps[k].idle and sec > 0]
    cut.sort(key=lambda c: c[0])
    pieces: list[tuple[float, float, Solved | None, bool]] = []  # default from, to; entry; kept
    c = 0.0
    for a, b, s in cut:
        if a > c + 1e-12:
            pieces.append((c, a, None, True))
        pieces.append((a, b, s, False))
        c = b
    if c < plan.cycle_time - 1e-12:
        pieces.append((c, plan.cycle_time, None, True))
    ts, qs, qds, qdds = [], [], [], []
    starts: dict[int, float] = {}
    off = 0.0
    by_first = {u.window.t0: u for u in placed}
    for a, b, s, keep in pieces:
        if keep:
            local = np.arange(0.0, b - a - 1e-9, FINE_DT)
            part = evaluate_cycle(plan, a + local)
            ts.append(off + local)
            qs.append(part.q)
            qds.append(part.qd)
            qdds.append(part.qdd)
            for m in plan.moves:
                if a - 1e-12 <= m.t0 < b - 1e-12 or (m.t0 >= b - 1e-12 and b >= plan.cycle_time - 1e-12):
                    starts.setdefault(m.index, off + min(m.t0, b) - a)
            off += b - a
            continue
        if s is None:  # a wait left out
            continue
        unit = by_first[a]
        f = s.fine
        k = f.t.size - 1
        ts.append(off + f.t[:k])
        qs.append(f.q[:k])
        qds.append(f.qd[:k])
        qdds.append(f.qdd[:k])
        cuts = [0.0, *unit.passes]
        for j, tc in zip(unit.members, cuts, strict=True):
            starts.setdefault(j, off + tc)
        for j in unit.window.moves:  # moves without motion inside the window
            starts.setdefault(j, off)
        off += s.duration
        for m in plan.moves:  # a move the window's blend starts (a MoveL after it): from its end
            if a + 1e-12 < m.t0 < b - 1e-12:
                starts.setdefault(m.index, off)
    end = evaluate_cycle(plan, np.array([plan.cycle_time]))
    ts.append(np.array([off]))
    qs.append(end.q)
    qds.append(np.zeros_like(end.q))
    qdds.append(np.zeros_like(end.q))
    traj = Trajectory(t=np.concatenate(ts), q=np.vstack(qs), qd=np.vstack(qds), qdd=np.vstack(qdds))
    order = [m.index for m in plan.moves]
    mono = np.maximum.accumulate([starts.get(j, 0.0) for j in order]) if order else np.zeros(0)
    return CycleMotion(traj, {j: float(v) for j, v in zip(order, mono, strict=True)}, off)


def taught_after(plan: PlannedCycle, traj: Trajectory, origin: float, end: float) -> Trajectory:
    """``traj`` (its times from ``origin`` in the default cycle ``plan``) continued to ``end`` (from
    ``origin`` too) with the taught motion, every 2.5 ms and at ``end``."""
    tail_t = np.append(np.arange(traj.t[-1] + FINE_DT, end - 1e-9, FINE_DT), end)
    tail = evaluate_cycle(plan, origin + tail_t)
    return Trajectory(
        t=np.concatenate([traj.t, tail_t]),
        q=np.vstack([traj.q, tail.q]),
        qd=np.vstack([traj.qd, tail.qd]),
        qdd=np.vstack([traj.qdd, tail.qdd]),
    )


def split_chain(
    s: Solved, members: tuple[int, ...], passes: Sequence[float], robot: Robot, plant: Plant, measure: str
) -> dict[int, Solved]:
    """A chain's solve ``s`` (its ``members``, passing its inner targets at ``passes``) cut at its
    targets into one piece per move (times from 0 in each piece; neighbouring pieces share their
    boundary sample)."""
    if len(members) == 1:
        return {members[0]: s}
    cuts = [0.0, *passes, s.duration]
    out: dict[int, Solved] = {}
    for k, (j, a, b) in enumerate(zip(members, cuts[:-1], cuts[1:], strict=True)):
        pieces = []
        for tr in (s.samples, s.fine):
            sel = (tr.t >= a - 1e-9) & (tr.t <= b + 1e-9)
            pieces.append(Trajectory(t=tr.t[sel] - a, q=tr.q[sel], qd=tr.qd[sel], qdd=tr.qdd[sel]))
        f = pieces[1]
        # the shared sample at a target counts half in each piece: the pieces sum to the chain
        w = np.full(f.t.size, s.fine.dt)
        if k > 0:
            w[0] *= 0.5
        if k < len(members) - 1:
            w[-1] *= 0.5
        p, p_lab = sample_power(robot, plant, f, measure)
        e, e_lab = float((w * p).sum()), float((w * p_lab).sum())
        out[j] = replace(
            s, duration=round(b - a, 9), energy_J=e, energy_lab_J=e_lab, samples=pieces[0], fine=f
        )
    return out


def to_stop(
    plan: PlannedCycle, window: Segment, last: PlannedMove, piece: Solved, plant: Plant, measure: str
) -> Solved:
    """The ``last`` move's ``piece`` of a unit over ``window`` (inside a ``MoveL`` segment, its run
    ending at a stop) with the taught motion after its window, less than one 25 ms sample, to the stop: so
    that it ends at its target, at rest (its energy with it)."""
    win, m = window, last
    if m.t_end - win.t1 <= 1e-9:
        return piece
    f = piece.fine
    fine = taught_after(plan, f, win.t1 - f.t[-1], f.t[-1] + m.t_end - win.t1)
    sm = piece.samples
    samples = Trajectory(
        t=np.append(sm.t, fine.t[-1]),
        q=np.vstack([sm.q, fine.q[-1:]]),
        qd=np.vstack([sm.qd, fine.qd[-1:]]),
        qdd=np.vstack([sm.qdd, fine.qdd[-1:]]),
    )
    e, e_lab = window_energy(move_robot(m), plant, fine, measure)
    return replace(
        piece,
        duration=round(float(fine.t[-1]), 9),
        energy_J=e,
        energy_lab_J=e_lab,
        samples=samples,
        fine=fine,
    )


def retime_segments(
    units: CycleUnits,
    motion: CycleMotion,
    *,
    plant: Callable[[Robot], Plant],
    progress: Callable[[str], None],
    deadline: float | None,
) -> RetimedMotion:
    """``motion`` with every segment that has a ``MoveL`` re-timed along its own joint path in it.

    Each such segment of ``motion`` (its units' chosen entries and the taught moves between
    them) is one path ``q(s)``, a quintic Hermite interpolation of its samples (position, speed
    and acceleration), re-timed by :func:`joulepath.optimize.retime_on_path` from its own
    timing (``start="identity"``): the same joint path, so every ``MoveL`` keeps its line
    and its tool orientation, every zone and blend its geometry, and the segment its
    duration and its speed and acceleration at both ends; only when the robot is where
    along it changes, so that time moves between the lines, the blends and the joint moves.
    Samples of a ``MoveL`` keep its speeddata: a TCP speed within ``v_tcp`` and the
    reorientation within ``v_ori`` (their bound on the TCP speed along the line), or the
    controller's own speed there where that is higher (a blend). A segment's new timing is
    kept only where it holds every limit and its energy on the cycle's measure is lower.

    Returns
    -------
    RetimedMotion
        The new motion (the same cycle time) and, by step index, each re-timed move's piece of
        it (a :class:`Solved` whose samples start at 0); the solves made, and whether the
        ``deadline`` stopped it.
    """
    st = units.settings
    by_index = units.by_index
    if not st.retime_segments or st.follow != "samples":
        return RetimedMotion(motion, {})
    traj = motion.trajectory
    order = [m.index for m in units.plan.moves]
    starts = dict(motion.starts)
    ts, qs, qds, qdds = [traj.t], [traj.q], [traj.qd], [traj.qdd]
    done: list[tuple[Segment, tuple[int, ...]]] = []
    n_solves = 0
    timed_out = False
    for seg in units.segments:
        moving = tuple(j for j in seg.moves if by_index[j].profile.duration > 0)
        if not moving or not any(by_index[j].step.linear for j in moving):
            continue
        if len(moving) == 1 and moving[0] in units.linear:
            continue  # a MoveL from rest to rest: its own unit re-times it along its line
        if any(units.default_clearance.get(j, np.inf) < 0.0 for j in moving):
            continue  # a taught move within the cell's margin: reported, left as it is
        if any(by_index[j].step.kept for j in moving):
            continue  # a move known only at run time (the RAPID interpreter's mark) runs as taught
        if seg.span > RETIME_MAX_SPAN_S:
            continue  # SLSQP's dense QP grows with the rows (2.5 ms samples) times variables squared
        first = by_index[moving[0]].step
        robot, tcp = move_robot(by_index[moving[0]]), first.tcp
        if tcp is None or any(
            by_index[j].step.robot is not robot or not np.array_equal(np.asarray(by_index[j].step.tcp), tcp)
            for j in moving
        ):
            continue  # a tool change inside the segment: left as it is
        if deadline is not None and time.perf_counter() > deadline:
            timed_out = True
            break
        t = ts[-1]
        a = motion.starts[moving[0]]
        i0 = int(np.searchsorted(t, a + 1e-9)) - 1  # the last sample at or before its start
        i1 = int(np.searchsorted(t, a + seg.span - 1e-9))  # the first at or after its end
        if i0 < 0 or i1 >= t.size or i1 - i0 < 8:
            continue
        sel = slice(i0, i1 + 1)
        tt, q, qd, qdd = t[sel], qs[-1][sel], qds[-1][sel], qdds[-1][sel]
        span = float(tt[-1] - tt[0])
        bound = line_bounds(units, robot, tcp, seg, tt, q, qd)
        progress(f"re-timing the segment of line {first.line} along its path")
        n_solves += 1
        try:
            r = retime_on_path(
                robot,
                hermite_path(tt, q, qd, qdd),
                span,
                acceleration_limit=units.amax_array(robot),
                jerk_limit=units.jmax(robot),
                tcp_speed_limit=interpolated((tt - tt[0]) / span, bound),
                tcp=tcp,
                energy_measure=st.energy,
                start="identity",
                free_ends=(at_rest(qd[0], qdd[0]), at_rest(qd[-1], qdd[-1])),
                deadline=deadline,
            )
        except InvalidInput:
            continue  # a segment that does not move
        if not r.feasible:
            continue
        lab = plant(robot)
        old = Trajectory(t=tt, q=q, qd=qd, qdd=qdd)
        new = replace(r.fine, t=r.fine.t + tt[0])
        e_new, e_old = (window_energy(robot, lab, x, st.energy)[0] for x in (new, old))
        if e_new >= e_old * (1.0 - RETIME_GAIN):
            continue
        s_new = np.maximum.accumulate(r.s) + np.arange(r.s.size) * 1e-15
        for j in seg.moves:
            if tt[0] - 1e-9 <= starts[j] <= tt[-1] + 1e-9:
                starts[j] = float(tt[0] + np.interp((starts[j] - tt[0]) / span, s_new, r.fine.t))
        ts.append(np.concatenate([t[:i0], new.t, t[i1 + 1 :]]))
        qs.append(np.concatenate([qs[-1][:i0], new.q, qs[-1][i1 + 1 :]]))
        qds.append(np.concatenate([qds[-1][:i0], new.qd, qds[-1][i1 + 1 :]]))
        qdds.append(np.concatenate([qdds[-1][:i0], new.qdd, qdds[-1][i1 + 1 :]]))
        done.append((seg, moving))
    if not done:
        return RetimedMotion(motion, {}, n_solves, timed_out)
    out = CycleMotion(
        Trajectory(t=ts[-1], q=qs[-1], qd=qds[-1], qdd=qdds[-1]),
        {j: starts[j] for j in order},
        motion.cycle_time,
    )
    return RetimedMotion(out, pieces_of(units, out, done, plant=plant), n_solves, timed_out)


def line_bounds(
    units: CycleUnits,
    robot: Robot,
    tcp: FloatArray,
    seg: Segment,
    t: FloatArray,
    q: FloatArray,
    qd: FloatArray,
) -> FloatArray:
    """The TCP speed bound (m/s) at each sample of a segment that starts at ``t[0]`` (its samples
    before it is re-timed): on a ``MoveL``'s line, between the blends at its ends, its speeddata's
    (``v_tcp``, and ``v_ori`` over its turn as a TCP speed along its line; the controller's own
    speed there where that is higher); elsewhere, in the zones' blends and the joint moves, none
    (a large number: the joints' limits bound them)."""
    speed = np.linalg.norm(tcp_velocity(robot, q, qd, tcp), axis=1)
    out = np.full(t.size, NO_SPEED_BOUND)
    moving = [units.by_index[j] for j in seg.moves if units.by_index[j].profile.duration > 0]
    for k, m in enumerate(moving):
        if not m.step.linear or m.step.speed is None:
            continue
        a = max(m.t0, moving[k - 1].t_end) if k > 0 else m.t0  # after the blend into it
        b = min(m.t_end, moving[k + 1].t0) if k + 1 < len(moving) else m.t_end  # before the next
        on = (t >= t[0] + a - seg.t0 - 1e-9) & (t <= t[0] + b - seg.t0 + 1e-9)
        v = m.step.speed.v_tcp
        if m.path.angle_deg > 1e-6 and m.path.length_mm > 1e-6:
            v = min(v, m.step.speed.v_ori * m.path.length_mm / m.path.angle_deg)
        out[on] = v / 1000.0
    # one sample wider on each side (the bound is interpolated between samples), never below the
    # speed the motion already has there
    wide = np.minimum(out, np.minimum(np.roll(out, 1), np.roll(out, -1)))
    wide[[0, -1]] = out[[0, -1]]
    bound: FloatArray = np.maximum(wide, speed * (1.0 + 1e-6))
    return bound


def pieces_of(
    units: CycleUnits,
    motion: CycleMotion,
    done: list[tuple[Segment, tuple[int, ...]]],
    *,
    plant: Callable[[Robot], Plant],
) -> dict[int, Solved]:
    """Each move of the re-timed segments as its own piece of ``motion``: its samples from its
    start to the next move's (times from 0), its energies over the same half-open window as
    :func:`move_energies`, and its samples every 25 ms (interpolated)."""
    traj = motion.trajectory
    order = [m.index for m in units.plan.moves]
    nxt = dict(zip(order, [*order[1:], None], strict=True))
    out: dict[int, Solved] = {}
    for _, moving in done:
        robot = move_robot(units.by_index[moving[0]])
        lab = plant(robot)
        for j in moving:
            k = nxt[j]
            a, b = motion.starts[j], (motion.cycle_time if k is None else motion.starts[k])
            sel = (traj.t >= a - 1e-9) & (traj.t <= b + 1e-9)
            if np.count_nonzero(sel) < 2:
                continue
            tt = traj.t[sel]
            fine = Trajectory(t=tt - tt[0], q=traj.q[sel], qd=traj.qd[sel], qdd=traj.qdd[sel])
            e, e_lab = window_energy(robot, lab, fine, units.settings.energy)
            grid = np.append(np.arange(0.0, fine.t[-1] - 1e-9, STEP), fine.t[-1])

            def at(x: FloatArray, f: Trajectory = fine, g: FloatArray = grid) -> FloatArray:
                return np.column_stack([np.interp(g, f.t, x[:, c]) for c in range(x.shape[1])])

            samples = Trajectory(t=grid, q=at(fine.q), qd=at(fine.qd), qdd=at(fine.qdd))
            out[j] = Solved(
                round(float(fine.t[-1]), 9),
                e,
                e_lab,
                True,
                (),
                samples,
                fine,
                0.0,
                units.default_clearance.get(j),
            )
    return out


def move_energies(
    plan: PlannedCycle, robot: Robot, plant: Plant, motion: CycleMotion, measure: str
) -> dict[int, tuple[float, float]]:
    """Physics (on ``measure``) and lab J per move of ``plan`` over its slot of ``motion`` (its start to
    the next move's start, the last to the cycle's end): ``Σ_k |tau_k · qd_k| (t_{k+1} - t_k)``."""
    traj = motion.trajectory
    moves = plan.moves
    w = np.append(np.diff(traj.t), 0.0)
    p, p_lab = sample_power(robot, plant, traj, measure)
    p, p_lab = p * w, p_lab * w
    bounds = [motion.starts[m.index] for m in moves] + [motion.cycle_time + 1.0]
    out: dict[int, tuple[float, float]] = {}
    for k, m in enumerate(moves):
        sel = (traj.t >= bounds[k] - 1e-12) & (traj.t < bounds[k + 1] - 1e-12)
        out[m.index] = (float(p[sel].sum()), float(p_lab[sel].sum()))
    return out


def measures(
    robot: Robot, plant: Plant, default: CycleMotion, optimized: CycleMotion
) -> tuple[tuple[MeasureSummary, ...], dict[str, str]]:
    """Every measure the robot has the data for, of the default and the optimized cycle's whole
    motion (model and lab plant, like for like; the standby power over each one's cycle time
    included where the measure counts it: the meter-level figure); why not, for the rest."""
    out: list[MeasureSummary] = []
    unavailable: dict[str, str] = {}
    for name, spec in MEASURES.items():
        why = spec.missing(robot.drivetrain)
        if why is not None:
            unavailable[name] = why
            continue
        model: list[float] = []
        lab: list[float | None] = []
        standby = 0.0
        lab_ok = spec.missing(plant.drivetrain) is None
        for motion in (default, optimized):
            traj = motion.trajectory
            w = np.append(np.diff(traj.t), 0.0)
            tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
            e = measure_energy(name, tau, traj.qd, w, robot.drivetrain, duration=motion.cycle_time)
            model.append(e.total_J)
            standby = standby or e.standby_J
            if lab_ok:
                lab_tau = plant.joint_torque(traj.q, traj.qd, traj.qdd)
                el = measure_energy(name, lab_tau, traj.qd, w, plant.drivetrain, duration=motion.cycle_time)
                lab.append(el.total_J)
            else:
                lab.append(None)
        ld, lo = lab
        out.append(
            MeasureSummary(
                measure=name,
                stage=spec.stage,
                source=spec.source(robot.drivetrain),
                default_J=model[0],
                optimized_J=model[1],
                saved_pct=100 * (model[0] - model[1]) / model[0] if model[0] > 0 else 0.0,
                standby_J=standby,
                lab_default_J=ld,
                lab_optimized_J=lo,
                lab_saved_pct=None if ld is None or lo is None or ld <= 0 else 100 * (ld - lo) / ld,
                lab_source=spec.source(plant.drivetrain) if lab_ok else str(spec.missing(plant.drivetrain)),
            )
        )
    return tuple(out), unavailable


def hermite_path(
    t: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray
) -> Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]:
    """A motion's samples as a joint path ``q(s)``, ``s = (t - t0) / T`` in [0, 1]: the quintic Hermite
    interpolation of position, speed and acceleration (C², exact at the samples)."""
    span = float(t[-1] - t[0])
    x = (t - t[0]) / span
    d, dd = qd * span, qdd * span * span
    # its Bernstein coefficients on every interval at once, by the operations, in their order, of
    # ``BPoly.from_derivatives`` (``quintic_hermite``), which builds them one interval at a time:
    # the same coefficients to the bit, in a fiftieth of the time
    h = (x[1:] - x[:-1])[:, None]
    h2 = h**2
    c = np.empty((6, x.size - 1, q.shape[1]))
    c[0] = q[:-1] / 1.0 * 1.0
    c[1] = d[:-1] / 5.0 * h
    c[1] -= -1.0 * c[0]
    c[2] = dd[:-1] / 20.0 * h2
    c[2] -= 1.0 * c[0]
    c[2] -= -2.0 * c[1]
    c[5] = q[1:] / 1.0 * 1 * 1.0
    c[4] = d[1:] / 5.0 * -1 * h
    c[4] -= -1.0 * c[5]
    c[3] = dd[1:] / 20.0 * 1 * h2
    c[3] -= -2.0 * c[4]
    c[3] -= 1.0 * c[5]
    poly = BPoly(c, x)
    d1, d2 = poly.derivative(1), poly.derivative(2)

    def at(s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return poly(s), d1(s), d2(s)

    return at


def interpolated(x: FloatArray, y: FloatArray) -> Callable[[FloatArray], FloatArray]:
    """``y`` at ``x`` as a function, linear between them."""

    def at(s: FloatArray) -> FloatArray:
        out: FloatArray = np.interp(s, x, y)
        return out

    return at


def at_rest(qd: FloatArray, qdd: FloatArray) -> bool:
    """A sample of a standstill (no speed, no acceleration)."""
    return bool(np.abs(qd).max() < 1e-9 and np.abs(qdd).max() < 1e-6)
