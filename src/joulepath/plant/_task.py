"""One cell program's work, as one pure task: plain inputs in, a small plain result out.

:func:`run_cell` does what ``joulepath cycle`` does for one program (read it, optimize
its cycle at the same cycle time, write and check the program) in a scratch folder of
its own, and returns a JSON-able dict: energies and times, what was written or why
not, the moves kept and why, where the energy goes, and the text of the small files
(``cycle.json``, ``optimized.mod``), never a sample. It keeps no state between calls
and writes nothing shared: the client stores its result (:mod:`joulepath.plant._run`).
"""

from __future__ import annotations

import json
import tempfile
import time
import traceback
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from joulepath.errors import JoulepathError
from joulepath.plant._idle import EnergySplit, mode_saving, split_energy

REPORT_MEASURE = "electrical"
"""The plant's energies are at the meter (standby included) where the robot has drive data."""
RETURNED_FILES = ("cycle.json", "optimized.mod")
"""Files of a cell's run that come back with its result; ``cycle_path.csv`` (every sample of the
plan) does not: ``joulepath cycle`` on the cell's program writes it for an EGM stream."""


@dataclass(frozen=True, slots=True, kw_only=True)
class CellTask:
    """A cell's plain inputs: its name, input hash, robot (name or path), program files,
    I/O scenario, entry routine, cell file and settings (:data:`~joulepath.plant._config.CELL_SETTINGS`)."""

    name: str
    key: str
    robot: str
    program: tuple[str, ...]
    io: dict[str, float | str] = field(default_factory=dict)
    routine: str | None = None
    cell: str | None = None
    settings: dict[str, Any] = field(default_factory=dict)


def cycle_settings(settings: Mapping[str, Any]) -> Any:
    """The :class:`~joulepath.program.CycleSettings` of a cell's settings (as ``joulepath cycle`` does).

    Raises
    ------
    InvalidInput
        A value out of its range (one line).
    """
    from joulepath.program import CycleSettings

    s = dict(settings)
    cycle_time = s.get("cycle_time", "same")
    corridor = float(s.get("corridor", 100.0))
    out = CycleSettings(
        cycle_time=None if cycle_time == "same" else float(cycle_time),
        use_waits=bool(s.get("use_waits", False)),
        fly_by=not s.get("stop_at_targets", False),
        zones=not s.get("exact_targets", False),
        max_time_s=None if s.get("max_time") is None else float(s["max_time"]),
        accel_time=float(s.get("accel_time", 0.25)),
        seed=int(s.get("seed", 0)),
        table_points=int(s.get("table_points", 4)),
        pass_search=int(s.get("pass_search", 8)),
        rapid_plan=bool(s.get("rapid_plan", True)),
        retime_segments=bool(s.get("retime_segments", True)),
        corridor_mm=corridor or None,
        # the cycle's own search, as `joulepath cycle` builds it (only the knot spacing set)
        gradient=replace(CycleSettings().gradient, knot_spacing=float(s.get("knot_spacing", 0.05))),
        energy=str(s.get("energy", "thesis")),
    )
    if "jerk_time" in s:
        out = replace(out, jerk_time=float(s["jerk_time"]))
    return out


def program_settings(task: CellTask) -> Any:
    """The :class:`~joulepath.program.ProgramSettings` of a cell (as ``joulepath cycle`` builds them
    from the same options): its cycle settings, export, lever search, I/O scenario and routine."""
    from joulepath.program import LEVER_PLANS, ProgramSettings

    s = task.settings
    return ProgramSettings(
        cycle=cycle_settings(s),
        export=str(s.get("export", "auto")),  # type: ignore[arg-type]
        lever_plans=int(s.get("lever_plans", LEVER_PLANS)),
        write_anyway=bool(s.get("write_anyway", False)),
        io=dict(task.io),
        routine=None if task.routine in (None, "main") else task.routine,
        idle_waits=tuple(int(k) for k in s.get("idle_wait", [])),
    )


def _split(robot: Any, traj: Any, cycle_time: float, measure: str) -> EnergySplit:
    from joulepath.dynamics import NOMINAL_FRICTION
    from joulepath.energy import measure_power

    tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=NOMINAL_FRICTION)
    power = measure_power(measure, tau, traj.qd, robot.drivetrain).value
    drives = robot.drivetrain.drives
    standby = drives.standby_W if (measure == REPORT_MEASURE and drives is not None) else 0.0
    return split_energy(traj.t, power, traj.qd, cycle_time=cycle_time, standby_W=standby)


def _split_json(s: EnergySplit) -> dict[str, Any]:
    return {
        "motion_J": s.motion_J,
        "holding_J": s.holding_J,
        "standby_J": s.standby_J,
        "standstill_s": s.standstill_s,
        "pauses": len(s.pauses),
        "longest_pause_s": max((p.duration_s for p in s.pauses), default=0.0),
    }


def _idle_modes(robot: Any, split: EnergySplit, measure: str) -> dict[str, Any]:
    from joulepath.energy import IDLE_MODES

    drives = robot.drivetrain.drives
    if measure != REPORT_MEASURE or drives is None:
        return {"available": False, "why": "no drive data: the standby and the modes' power are unknown"}
    modes = {
        m: (float(getattr(drives, f"{m}_W")), float(getattr(drives, f"{m}_entry_s")))
        for m in IDLE_MODES
        if getattr(drives, f"{m}_W") is not None
    }
    if not modes:
        return {
            "available": False,
            "why": f"{drives.origin} gives no power-saving mode (brakes_W, bus_off_W)",
        }
    saving = mode_saving(split.pauses, standby_W=drives.standby_W, modes=modes)
    return {
        "available": True,
        "saving_J": saving.saving_J,
        "pauses_used": saving.pauses_used,
        "time_in_mode_s": saving.time_in_mode_s,
        "modes": {
            m: {"power_W": p, "entry_s": e, "source": drives.source(f"{m}_W")} for m, (p, e) in modes.items()
        },
        "standby_W": drives.standby_W,
    }


def _moves(result: Any) -> list[dict[str, Any]]:
    return [
        {"line": m.line, "label": m.label, "optimized": m.optimized, "note": m.note} for m in result.moves
    ]


def run_cell(task: CellTask) -> dict[str, Any]:
    """Optimize one cell program's cycle; a plain result (see the module docstring).

    A program that cannot be read or optimized gives ``status`` ``"failed"`` with its
    ``reason``; one whose optimized cycle breaks a limit gives ``"refused"`` (no saving
    claimed); ``cacheable`` is False for a failure a rerun may not repeat (an unexpected
    error, a reader that cannot read the program yet).
    """
    from threadpoolctl import threadpool_limits

    t0 = time.perf_counter()
    base: dict[str, Any] = {"name": task.name, "key": task.key}
    try:
        with threadpool_limits(limits=1):
            body = _run(task)
    except JoulepathError as err:
        body = {"status": "failed", "reason": f"{type(err).__name__}: {err}", "cacheable": True}
    except Exception as err:  # a bug: recorded with its place, retried on the next run
        where = traceback.extract_tb(err.__traceback__)[-1]
        body = {
            "status": "failed",
            "reason": f"unexpected {type(err).__name__}: {err} ({Path(where.filename).name}:{where.lineno})",
            "cacheable": False,
        }
    return {**base, **body, "wall_s": time.perf_counter() - t0}


def _run(task: CellTask) -> dict[str, Any]:
    from joulepath.dynamics import load_robot
    from joulepath.program import optimize_program, read_cell

    robot = load_robot(task.robot)
    cell = read_cell(task.cell) if task.cell is not None else None
    with tempfile.TemporaryDirectory(prefix="joulepath-cell-") as scratch:
        done = optimize_program(list(task.program), robot, Path(scratch), program_settings(task), cell=cell)
        files = done.files
        texts = {n: files[n].read_text(encoding="utf-8") for n in RETURNED_FILES if n in files}
    result, spec = done.cycle, done.spec
    saved = json.loads(texts["cycle.json"])
    energies = {e.measure: e for e in result.energies}
    measure = REPORT_MEASURE if REPORT_MEASURE in energies else result.energy_measure
    e = energies.get(measure)
    default_J = e.default_J if e is not None else result.default_energy_J
    if not result.limits_ok:
        status, written, why = "refused", None, "the optimized cycle breaks a limit or the cell's margin"
    elif "optimized.mod" in files:
        status, written, why = "ok", "rapid", "optimized.mod, checked on the controller emulation"
    elif "egm.mod" in files:
        status, written = "ok", "egm"
        refused = saved.get("rapid_refused") or "not a RAPID program"
        why = f"the plan streams over EGM (RAPID not written: {refused})"
    else:
        status, written = "refused", None
        why = f"nothing written: {saved.get('rapid_refused') or 'no program written'}"
    claimed = written is not None
    optimized_J = (e.optimized_J if e is not None else result.optimized_energy_J) if claimed else default_J
    optimized_cycle = result.optimized_cycle_s if claimed else result.default_cycle_s
    carrying = next((s.robot for s in spec.steps if s.kind == "move" and s.robot is not None), robot)
    split_default = _split(carrying, done.default_trajectory, result.default_cycle_s, measure)
    split_optimized = (
        _split(carrying, result.planned, result.optimized_cycle_s, measure)
        if claimed and result.planned is not None
        else split_default
    )
    waits = [s for s in spec.steps if s.kind == "wait"]
    return {  # the robot carrying the tool's load, as the cycle's energies are taken
        "status": status,
        "reason": None if status == "ok" else why,
        "cacheable": True,
        "written": written,
        "written_note": why,
        "measure": measure,
        "measure_note": (
            "at the meter: the drives' bus power plus the cabinet's standby"
            if measure == REPORT_MEASURE
            else f"{measure} (no drive data for {robot.name}: no meter-level figure, standby not counted)"
        ),
        "drive_data": robot.drivetrain.drives_source if measure == REPORT_MEASURE else None,
        "optimized_measure": result.energy_measure,
        "robot": robot.name,
        "default_cycle_s": result.default_cycle_s,
        "optimized_cycle_s": optimized_cycle,
        "default_J": default_J,
        "optimized_J": optimized_J,
        "motion_saved_pct": result.saved_pct if claimed else 0.0,
        "timed_out": result.timed_out,
        "moves": _moves(result),
        "waits_s": sum(float(w.seconds) for w in waits),
        "idle_waits_s": sum(float(w.seconds) for w in waits if w.idle),
        "split_default": _split_json(split_default),
        "split_optimized": _split_json(split_optimized),
        "idle_modes": _idle_modes(robot, split_default, measure),
        "choices": [str(c) for c in spec.choices],
        "files": texts,
    }
