"""One robot program from file to robot: :func:`optimize_program`.

The stages, in order (docs/explanation/program-flow.md draws them):

1. **read**: the program's modules run by the RAPID interpreter (or a ``.toml`` cycle file),
   with the I/O scenario and the entry routine: :func:`read_cycle_program`;
2. **cell**: the cell file's obstacles, where one is given;
3. **plan**: the cycle optimized at its own (or a given) cycle time: :func:`optimize_cycle`;
4. **levers**: the controller's own levers (``AccSet``, speed data, zones; the plan's via points
   with them) searched on the controller emulation, for a RAPID export;
5. **check and write**: every result checked against the robot's limits and run by the
   controller emulation, then written: :func:`write_cycle_run`.

``joulepath cycle``, a plant's cell (:mod:`joulepath.plant`) and a study's ``cycle`` stage all
call this one function, so the same program and settings give the same written program.

Every search is bounded by work (plans made, iterations), not by wall time, so the same input
gives the same result on an idle machine and on a loaded one; ``CycleSettings.max_time_s`` (the
CLI's ``--max-time``) is the one setting that makes the result depend on the machine.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput
from joulepath.program._cycle import optimize_cycle
from joulepath.program._cycle_model import CycleResult, CycleSettings, ParetoPoint
from joulepath.program._resolve import CycleSpec, read_cycle_program
from joulepath.trajectory import Trajectory

Export = Literal["auto", "rapid", "egm"]
EXPORTS: tuple[str, ...] = ("auto", "rapid", "egm")

LEVER_PLANS = 1500
"""Cycle plans each search of the controller's levers makes at most by default (a plan is the
controller emulation's run of the whole cycle: milliseconds per move). A bound of work, so that the
written program is the same on any machine; ``--lever-plans`` sets it, 0 turns the searches off.
1,500 is the searches' own bound (``levers_module``), which the 30 s of wall time before cut short:
measured on machine_tending, 400 plans executed 6.2 % in 119 s of CPU, 1,500 executed 8.3 % in
200 s (the 30 s bound before: 8.7 % in 193 s on the same loaded machine; BENCHMARKS.md)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class ProgramSettings:
    """How :func:`optimize_program` runs a program (the CLI's ``cycle`` options, a plant's cell).

    ``export``: ``rapid`` (a RAPID program, written where the controller emulation runs it as the
    checks ask), ``egm`` (the plan streamed through EGM; RAPID too where it passes) or ``auto``
    (RAPID, else EGM). ``lever_plans``: cycle plans each lever search makes at most (0: none).
    ``io``: the I/O scenario (what the program reads while it runs); ``routine``: the routine run
    instead of ``main``; ``idle_waits``: lines of ``WaitTime`` that are idle time; ``given``: RAPID
    values (tools, work objects, targets) for names the task uses and does not give
    (:func:`joulepath.program.read_scenario`).
    """

    cycle: CycleSettings = field(default_factory=CycleSettings)
    export: Export = "auto"
    lever_plans: int = LEVER_PLANS
    write_anyway: bool = False
    pareto_points: int = 0
    io: Mapping[str, float | str | bool] = field(default_factory=dict)
    routine: str | None = None
    idle_waits: tuple[int, ...] = ()
    given: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.export not in EXPORTS:
            raise InvalidInput(f"export {self.export!r}: give auto, rapid or egm")
        if self.lever_plans < 0:
            raise InvalidInput(f"lever_plans {self.lever_plans}: give 0 (no lever search) or more")
        if self.pareto_points and self.pareto_points < 3:
            raise InvalidInput(f"pareto_points {self.pareto_points}: give 0 (none) or 3 or more")


@dataclass(frozen=True, slots=True)
class ProgramResult:
    """What :func:`optimize_program` did with a program: the plan, what was written, and why.

    ``summary`` is ``cycle.json`` as written (its one serialization); ``files`` the paths written
    by name; ``export_choice`` what was written for the robot and why; ``kept`` the moves kept as
    taught and why; ``choices`` what the reader decided or assumed, a line each.
    """

    spec: CycleSpec
    cycle: CycleResult
    rapid: bool
    files: Mapping[str, Path]
    summary: Mapping[str, Any]
    default_trajectory: Trajectory
    optimizable_units: int
    pareto: tuple[ParetoPoint, ...] = ()
    lever_searches: tuple[str, ...] = ()
    wall_s: float = 0.0

    @property
    def written(self) -> Literal["rapid", "egm"] | None:
        """What was written for the robot: a RAPID program, an EGM stream, or nothing."""
        if "optimized.mod" in self.files or "optimized_task" in self.files:
            return "rapid"
        return "egm" if "egm.mod" in self.files else None

    @property
    def export_choice(self) -> str | None:
        value = self.summary.get("export_choice")
        return None if value is None else str(value)

    @property
    def kept(self) -> tuple[tuple[str, str], ...]:
        return self.spec.kept

    @property
    def choices(self) -> tuple[str, ...]:
        return self.spec.choices

    @property
    def assumed(self) -> tuple[Any, ...]:
        """Names the task uses and declares nowhere, with what was taken for each."""
        return self.spec.assumed

    @property
    def every_unit_taught(self) -> bool:
        """Every unit the plan could change is kept as taught (nothing was optimized)."""
        return len(self.cycle.taught_units) == self.optimizable_units


def optimize_program(
    program: str | Path | Sequence[str | Path],
    robot: Robot,
    out: Path,
    settings: ProgramSettings | None = None,
    *,
    cell: Any = None,
    progress: Callable[[str], None] | None = None,
) -> ProgramResult:
    """Read a program, plan its cycle, search the controller's levers, check and write the run folder.

    Parameters
    ----------
    program : path or paths
        A RAPID task (one module, several modules, or a task's folder; an ``EIO.cfg`` names the I/O
        signals) or a plain cycle file (``.toml``).
    robot : Robot
        The robot the program runs on.
    out : Path
        The run folder (:data:`joulepath.program.CYCLE_FILES` are written there).
    settings : ProgramSettings, optional
        The export, the lever search's work bound, the scenario and the cycle's settings.
    cell : Cell, optional
        Obstacles every move must clear (:func:`joulepath.program.read_cell`).
    progress : callable, optional
        Told each stage, a line each.

    Returns
    -------
    ProgramResult
        The plan, the files written and ``cycle.json``'s summary.

    Raises
    ------
    InvalidInput
        The program cannot be read (:class:`~joulepath.errors.RapidError`, one line ``file:line``),
        a target is out of reach, or the cycle time cannot be met.
    """
    from threadpoolctl import threadpool_limits

    # one BLAS thread: sums in the same order on any machine, so the same input gives the same
    # searches and files whatever its cores (a plant's cell runs so too)
    with threadpool_limits(limits=1, user_api="blas"):
        return _optimize_program(program, robot, out, settings, cell, progress)


def _optimize_program(
    program: str | Path | Sequence[str | Path],
    robot: Robot,
    out: Path,
    settings: ProgramSettings | None,
    cell: Any,
    progress: Callable[[str], None] | None,
) -> ProgramResult:
    settings = settings or ProgramSettings()
    t0 = time.perf_counter()
    say = progress or (lambda _: None)
    spec, rapid = read_cycle_program(
        program,
        robot,
        idle_waits=settings.idle_waits,
        progress=progress,
        io=dict(settings.io) or None,
        routine=settings.routine,
        seed=settings.cycle.seed,
        given=dict(settings.given) or None,
    )
    cycle_settings = replace(settings.cycle, cell=cell)
    result = optimize_cycle(spec, cycle_settings, progress=progress, pareto_points=settings.pareto_points)
    front = list(result.pareto) if settings.pareto_points else None
    assert result.default_planned is not None
    searched: list[str] = []
    deadline = None if cycle_settings.max_time_s is None else t0 + cycle_settings.max_time_s
    levers, via = _search_levers(spec, rapid, result, robot, settings, cell, say, searched, deadline)
    say(f"writing {out} (the written program is checked on the controller emulation)")
    from joulepath.program._output import write_cycle_run

    files = write_cycle_run(
        out,
        result,
        pareto=front,
        write_rapid=rapid,
        cell=cell,
        write_anyway=settings.write_anyway,
        egm=_EGM[settings.export],
        levers=levers,
        via_levers=via,
    )
    summary = json.loads(files["cycle.json"].read_text(encoding="utf-8"))
    return ProgramResult(
        spec=spec,
        cycle=result,
        rapid=rapid,
        files=files,
        summary=summary,
        default_trajectory=result.default_planned,
        optimizable_units=len(result.optimizable),
        pareto=tuple(front or ()),
        lever_searches=tuple(searched),
        wall_s=time.perf_counter() - t0,
    )


_EGM = {"egm": "always", "auto": "fallback", "rapid": "never"}


def _search_levers(
    spec: CycleSpec,
    rapid: bool,
    result: CycleResult,
    robot: Robot,
    settings: ProgramSettings,
    cell: Any,
    say: Callable[[str], None],
    searched: list[str],
    deadline: float | None,
) -> tuple[Any, Any]:
    """The lever searches of a RAPID export (none for EGM, a plan past a limit, or ``lever_plans`` 0):
    the program's own statements (a module or a task), and the plan's via points (a module)."""
    if not rapid or settings.export == "egm" or not result.limits_ok or settings.lever_plans == 0:
        return None, None
    cs = settings.cycle
    say("searching the controller's levers (AccSet, speed data, zones) on the controller emulation")
    if spec.module is not None:
        from joulepath.program._levers import levers_module

        levers = levers_module(
            spec,
            robot,
            energy=cs.energy,
            use_waits=cs.use_waits,
            max_evaluations=settings.lever_plans,
            max_seconds=_seconds_left(deadline),
        )
    else:
        from joulepath.program._task_levers import task_levers

        levers = task_levers(
            spec,
            robot,
            energy=cs.energy,
            io=dict(settings.io) or None,
            routine=settings.routine,
            max_evaluations=settings.lever_plans,
            max_seconds=_seconds_left(deadline),
        )
    searched.append("statements")
    via = None
    if spec.module is not None and result.paths:
        from joulepath.program._via_levers import via_levers

        say("searching the levers of the plan's via points on the controller emulation")
        via = via_levers(
            result,
            robot,
            energy=cs.energy,
            corridor_mm=cs.corridor_mm,
            cell=cell,
            max_seconds=_seconds_left(deadline),
            max_plans=settings.lever_plans,
        )
        searched.append("via points")
    return levers, via


def _seconds_left(deadline: float | None) -> float | None:
    """What is left of the user's ``max_time_s`` (None: no wall-time bound, the default)."""
    return None if deadline is None else max(1.0, deadline - time.perf_counter())
