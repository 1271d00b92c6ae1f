"""A RAPID program run on the emulated controller and a plant, logged like the measurement module.

``main`` runs once, as written (a ``WHILE TRUE`` cycle once round): its moves are timed by
the controller emulation (:func:`plan_cycle`, the rules of :mod:`joulepath.sim`), the
commanded motion (:func:`evaluate_cycle`) drives a plant (:func:`joulepath.sim.run_plant`:
the ``sim`` twin, the ``lab`` robot or an identified twin folder), and the measurement
loop samples it (:func:`joulepath.sim.log_times`, the 40 Hz loop's times with its
jitter) into the controller's CSV log (:func:`joulepath.sim.log_text`).

The robot starts at rest at ``start``; by default at the target of the program's first
move (so a program that first moves to its start position, as ``path.mod`` does, runs
from there). The log holds ``ControllerConfig.idle`` s of rest before the first move
and after the last, as :func:`joulepath.sim.simulate` does.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from joulepath._io import atomic_write_text, make_folder
from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput
from joulepath.program._resolve import CycleSpec, read_rapid_cycle
from joulepath.sim import (
    ControllerConfig,
    PlannedCycle,
    check_motion_time,
    evaluate_cycle,
    log_text,
    log_times,
    make_plant,
    plan_cycle,
    run_plant,
)


@dataclass(frozen=True, slots=True, eq=False)
class ProgramMotion:
    """The commanded motion of a planned program, ``offset`` s after the log's first sample.

    A :class:`joulepath.sim.run_plant` input: ``evaluate(t)`` gives the commanded
    ``q, qd, qdd`` at the log times (at rest at the start before the program, at the
    last target after it).
    """

    plan: PlannedCycle
    offset: float

    def evaluate(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        traj = evaluate_cycle(self.plan, np.asarray(t, dtype=float) - self.offset)
        return traj.q, traj.qd, traj.qdd

    @property
    def end_time(self) -> float:
        """s, the time the program's last move has ended and dwelt (from the log's first sample)."""
        return self.offset + self.plan.cycle_time


@dataclass(frozen=True, slots=True)
class ProgramRun:
    """What a simulated run of a program wrote.

    ``program_time_s`` is the time the controller emulation takes to run ``main`` (from
    the first move's start to the last move's end and dwell); ``duration_s`` the time
    the log covers (with the rest before and after); ``said`` what the reading of the program
    decided or assumed (a name declared nowhere, a branch decided at run time), a line each.
    """

    log: Path
    n_rows: int
    n_moves: int
    program_time_s: float
    duration_s: float
    start_rad: tuple[float, ...]
    plant: str
    plant_note: str
    said: tuple[str, ...] = ()  # what the reading decided or assumed, a line each


def program_motion(
    spec: CycleSpec,
    config: ControllerConfig,
    *,
    start: FloatArray | None = None,
    progress: Callable[[str], None] | None = None,
) -> ProgramMotion:
    """The controller's plan of a program's steps from ``start`` (default: the first move's target).

    ``progress`` (optional) is told each move planned.
    """
    first = next(s.q for s in spec.steps if s.kind == "move" and s.q is not None)
    q0 = first.copy() if start is None else np.asarray(start, dtype=float)
    plan = plan_cycle(replace(spec, start=q0), config, progress=progress)
    return ProgramMotion(plan, config.idle)


def _check_start(robot: Robot, start: FloatArray | Sequence[float]) -> FloatArray:
    q = np.asarray(start, dtype=float)
    if q.shape != (robot.n_joints,) or not np.all(np.isfinite(q)):
        raise InvalidInput(
            f"the start configuration needs {robot.n_joints} finite joint values, got shape {q.shape}"
        )
    lo, hi = robot.joint_ranges()
    bad = np.nonzero((q < lo - 1e-9) | (q > hi + 1e-9))[0]
    if bad.size:
        j = int(bad[0])
        raise InvalidInput(
            f"start joint {j + 1} = {np.degrees(q[j]):.2f} deg is outside its range "
            f"[{np.degrees(lo[j]):.1f}, {np.degrees(hi[j]):.1f}] deg"
        )
    return q


def simulate_program(
    program: str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    robot: Robot,
    plant: str = "lab",
    seed: int = 0,
    start: FloatArray | Sequence[float] | None = None,
    config: ControllerConfig | None = None,
    instance_seed: int = 120,
    progress: Callable[[str], None] | None = None,
) -> ProgramRun:
    """Run a RAPID program's ``main`` once on the emulated controller and a plant; write the log.

    Parameters
    ----------
    program : path
        A RAPID module (or a task's folder) as the RAPID interpreter runs it, e.g. the
        ``path.mod`` of ``joulepath optimize`` or the ``optimized.mod`` of ``joulepath cycle``
        (run as written, not as the program it was optimized from).
    out : path
        The controller log (CSV) to write, atomically.
    robot : Robot
        The robot the program drives (``joulepath.load_robot``).
    plant : str
        ``"sim"``, ``"lab"`` or a twin folder (:func:`joulepath.sim.make_plant`).
    seed : int
        Seed of the measurement loop's jitter and of the plant's noise.
    start : ndarray of shape (n_joints,), optional
        Where the robot rests when the program starts, rad (default: the first move's target).
    config : ControllerConfig, optional
        The emulated controller and measurement loop.
    instance_seed : int
        Which lab robot (its perturbations).
    progress : callable, optional
        Told each move read and planned, then when the plant runs (for long programs).

    Raises
    ------
    RapidError
        The module cannot be read (the message names its line).
    InvalidInput
        A start outside the joint ranges, an unknown plant.
    """
    r = robot
    config = config or ControllerConfig()
    q0 = None if start is None else _check_start(r, start)
    spec = read_rapid_cycle([Path(program)], r, progress=progress)
    motion = program_motion(spec, config, start=q0, progress=progress)
    check_motion_time(motion.plan, spec.source)
    if progress is not None:
        progress(f"running {motion.plan.cycle_time:.1f} s of motion on the {plant} plant")
    the_plant = make_plant(plant, r, instance_seed=instance_seed)
    rng = np.random.default_rng(seed)
    t = log_times(motion.end_time + config.idle, config, rng=rng)
    measured = run_plant(the_plant, motion, t, rng=rng)
    path = Path(out)
    make_folder(path.parent)
    atomic_write_text(path, log_text(r, measured))
    return ProgramRun(
        log=path,
        n_rows=int(t.size),
        n_moves=len(motion.plan.moves),
        program_time_s=float(motion.plan.cycle_time),
        duration_s=float(t[-1]),
        start_rad=tuple(float(v) for v in motion.plan.start),
        plant=the_plant.name,
        plant_note=the_plant.note,
        said=(
            *(f"read: {c}" for c in spec.choices),
            *(f"assumed: {a.line()}" for a in spec.assumed),
            *(f"kept as taught (run as written): {move}: {why}" for move, why in spec.kept),
        ),
    )
