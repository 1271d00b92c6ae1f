"""``joulepath cycle``: optimize a robot program's whole cycle."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import typer

from joulepath._work import work_limit
from joulepath.cli._common import check_out_folder, console, err_console, progress_lines
from joulepath.cli._robot import load_robot_for_cli, unchecked_option
from joulepath.program import LEVER_PLANS


def _cycle_time(text: str) -> float | None:
    if text.strip().lower() == "same":
        return None
    try:
        value = float(text)
    except ValueError as err:
        raise typer.BadParameter(
            f"{text!r} is neither 'same' nor a number of seconds", param_hint="--cycle-time"
        ) from err
    if not (value > 0 and value < 3600):
        raise typer.BadParameter(
            f"{text!r}: give a positive number of seconds under 3600 (an hour)", param_hint="--cycle-time"
        )
    return value


def _scenario(pairs: list[str], path: Path | None) -> Any:
    """The scenario: the ``--scenario`` file (:func:`joulepath.program.read_scenario`), then ``--io
    NAME=VALUE`` pairs over its ``[io]`` values."""
    from joulepath.program import Scenario, read_scenario

    base = read_scenario(path) if path is not None else Scenario()
    out: dict[str, float | str | bool] = dict(base.io)
    for pair in pairs:
        name, sep, value = pair.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise typer.BadParameter(f"{pair[:60]!r}: give NAME=VALUE, e.g. diPartReady=1", param_hint="--io")
        text = value.strip()
        parsed: float | str | bool
        if text.upper() in ("TRUE", "FALSE"):
            parsed = text.upper() == "TRUE"
        else:
            try:
                parsed = float(text)
            except ValueError:
                parsed = text.strip('"')
        out[name.strip()] = parsed
    return Scenario(out, base.given)


def _robot_of_task(program: list[Path]) -> str:
    """The bundled robot the task's ``MOC.cfg`` names (said on stderr), else the IRB 120."""
    from joulepath.description import DEFAULT_ROBOT, abb_preset
    from joulepath.rapid import find_moc

    moc = find_moc(program)
    name = abb_preset(moc.robot_type) if moc is not None and moc.robot_type else None
    if moc is not None and moc.robot_type:
        said = f"--robot {name}" if name else f"no bundled model of it: --robot {DEFAULT_ROBOT}; give --robot"
        err_console.print(f"robot: {moc.path} names {moc.robot_type}: {said}", markup=False)
    return name or DEFAULT_ROBOT


def cycle(
    program: list[Path] = typer.Argument(
        ...,
        help="The program: a RAPID task (one module, several modules such as main.mod user.sys, or a "
        "folder of a task's modules, e.g. a backup's RAPID/TASK1; an EIO.cfg names the I/O signals), or a "
        "plain cycle file (.toml).",
    ),
    robot: str = typer.Option(
        None,
        help="Robot name or .irml/.urdf path (default: the robot the task's MOC.cfg names where joulepath "
        "bundles it, else irb120).",
    ),
    out: Path = typer.Option(..., "--out", help="Run folder."),
    cycle_time: str = typer.Option("same", "--cycle-time", help="'same' (the default program's) or seconds."),
    use_waits: bool = typer.Option(
        False,
        "--use-waits",
        help="Spend the waits declared idle (a `! joulepath: idle` comment on the WaitTime, or --idle-wait "
        "LINE) on the moves; every other wait is process time and keeps its length.",
    ),
    idle_wait: list[int] = typer.Option(
        [], "--idle-wait", min=1, help="Line of a WaitTime that is idle time (repeatable); see --use-waits."
    ),
    stop_at_targets: bool = typer.Option(
        False,
        "--stop-at-targets",
        help="Optimize only moves that run from rest to rest on their own; default: consecutive "
        "MoveJ/MoveAbsJ joined by zones are optimized as one fly-by chain through their targets.",
    ),
    exact_targets: bool = typer.Option(
        False,
        "--exact-targets",
        help="A fly-by chain passes its targets exactly; default: within each target's zone, as the "
        "controller does.",
    ),
    export: str = typer.Option(
        "auto",
        "--export",
        help="rapid: optimized.mod, written where the controller emulation runs it as the checks ask; "
        "egm: egm.mod and EGM_SETUP.md, to stream cycle_path.csv with `joulepath stream OUT --repeat K` "
        "(and optimized.mod where it passes); auto (default): rapid, else egm.",
    ),
    max_time: float = typer.Option(
        None,
        "--max-time",
        min=1.0,
        help="s of wall time at most for the optimization: then the best verified result so far (the "
        "taught motion for the units not yet solved).",
    ),
    accel_time: float = typer.Option(
        0.25,
        "--accel-time",
        min=0.05,
        max=10.0,
        help="s: each joint's acceleration limit is its speed limit divided by this (longer: gentler moves "
        "that the controller can follow through via points, at a longer cycle time).",
    ),
    jerk_time: float = typer.Option(
        None,
        "--jerk-time",
        help="s for the acceleration to reach its limit at full jerk: each joint's jerk limit is its "
        "acceleration limit divided by this (default 0: no jerk limit, so that the program's own cycle "
        "time stays reachable; the emulated controller's is joulepath.sim.JERK_TIME, 0.125 s).",
    ),
    write_anyway: bool = typer.Option(
        False,
        "--write-anyway",
        help="Write optimized.mod even when the controller emulation does not run it as planned "
        "(a warning goes in its header).",
    ),
    pareto: bool = typer.Option(False, "--pareto", help="Also energy against cycle time (CSV + plot)."),
    points: int = typer.Option(10, "--points", min=3, max=30, help="Points of --pareto."),
    knot_spacing: float = typer.Option(
        0.05, "--knot-spacing", min=0.02, max=1.0, help="s between B-spline knots of the optimized moves."
    ),
    table_points: int = typer.Option(
        4, "--table-points", min=2, max=20, help="Durations solved per move before sharing the time."
    ),
    fast: bool = typer.Option(
        False,
        "--fast",
        help="Interactive preset (joulepath.program.FAST_CYCLE): at most 2 probes per inner target, 3 "
        "durations per move (over --table-points), no re-timing of MoveL segments along their paths. "
        "Measured on the bundled examples: at most 4.4 s of CPU each (the default: 8.4 s), 0-2.1 points "
        "less saving.",
    ),
    lever_plans: int = typer.Option(
        LEVER_PLANS,
        "--lever-plans",
        min=0,
        max=100_000,
        help="Cycle plans each search of the controller's levers makes at most on the emulation (RAPID "
        "export): a bound of work, so the written program is the same on any machine; 0: no lever search.",
    ),
    corridor: float = typer.Option(
        100.0,
        "--corridor",
        min=0.0,
        help="mm: keep tool0 this close to the taught move's path (joint-interpolated); 0: no corridor.",
    ),
    cell: Path = typer.Option(
        None,
        "--cell",
        help="Cell file (TOML: boxes, cylinders, spheres, STL/OBJ meshes, margin; or a URDF of the cell): "
        "every move must clear it.",
    ),
    seed: int = typer.Option(0, min=0, max=2**32 - 1, help="Random seed."),
    energy: str = typer.Option(
        "thesis",
        "--energy",
        help="Energy measure to minimize: thesis, mechanical or electrical (needs the robot's drive data); "
        "every measure the robot has the data for is reported, electrical with the standby over the cycle.",
    ),
    io: list[str] = typer.Option(
        [],
        "--io",
        help="NAME=VALUE: what the program reads while it runs (an input signal, a variable a socket or "
        "the operator fills); repeatable. Moves decided by what is not given are kept as taught.",
    ),
    scenario: Path = typer.Option(
        None,
        "--scenario",
        help="TOML file: [io] NAME = VALUE pairs (as --io); [tool.NAME], [wobj.NAME], [targets], [data] for "
        "what a partial task uses and does not declare (docs/reference/formats.md#scenario-files).",
    ),
    routine: str = typer.Option(
        None, "--routine", help="Run this routine instead of main (a library of paths, or one routine)."
    ),
    unchecked: bool = unchecked_option(),
) -> int:
    """Optimize a program's cycle for energy at the same (or a given) cycle time; verify; write RAPID.

    Exit code 0: written within every limit; 1: no program written (a result breaks a limit or
    the cell's margin, or the controller emulation does not run the via points as planned; see
    --write-anyway); 2: bad input (unreadable program, unreachable target, infeasible cycle time).
    """
    from joulepath.energy import check_measure
    from joulepath.program import (
        CYCLE_FILES,
        FAST_CYCLE,
        CycleSettings,
        ProgramSettings,
        optimize_program,
        read_cell,
    )

    target = _cycle_time(cycle_time)
    if export not in ("auto", "rapid", "egm"):
        raise typer.BadParameter(f"{export!r}: give auto, rapid or egm", param_hint="--export")
    check_out_folder(out, files=CYCLE_FILES, inputs=[*program, *([cell] if cell else [])])
    for p in program:
        if not p.exists():  # anything else but a regular file or folder is refused by name when read
            raise typer.BadParameter(f"{p}: no such file or folder", param_hint="PROGRAM")
    r = load_robot_for_cli(robot or _robot_of_task(program), unchecked=unchecked)
    check_measure(energy, r.drivetrain)  # one line saying what to provide
    given = _scenario(io, scenario)
    cs = CycleSettings(
        cycle_time=target, use_waits=use_waits, fly_by=not stop_at_targets, zones=not exact_targets,
        max_time_s=max_time, accel_time=accel_time, seed=seed, table_points=table_points,
        corridor_mm=corridor or None, energy=energy,
        gradient=replace(CycleSettings().gradient, knot_spacing=knot_spacing),
    )  # fmt: skip
    cs = replace(cs, **FAST_CYCLE) if fast else cs
    cs = replace(cs, jerk_time=jerk_time) if jerk_time is not None else cs  # else the controller's default
    settings = ProgramSettings(
        cycle=cs, export=export, lever_plans=lever_plans, write_anyway=write_anyway,  # type: ignore[arg-type]
        pareto_points=points if pareto else 0, io=given.io, given=given.given, routine=routine,
        idle_waits=tuple(idle_wait),
    )  # fmt: skip
    with progress_lines("optimizing the cycle...") as say:  # on stderr only: stdout keeps the results
        cell_data = read_cell(cell, progress=say) if cell is not None else None
        done = optimize_program(program, r, out, settings, cell=cell_data, progress=say)
    return print_program_result(done, out, r, use_waits=use_waits, cell=cell_data)


def print_program_result(done: Any, out: Path, r: Any, *, use_waits: bool, cell: Any) -> int:
    """Print a :class:`~joulepath.program.ProgramResult` (stdout); the exit code of ``cycle``."""
    result, spec, files, saved, rapid = done.cycle, done.spec, done.files, done.summary, done.rapid
    if use_waits and not any(s.idle for s in spec.steps if s.kind == "wait"):
        console.print(
            "note: --use-waits: no wait is declared idle (`! joulepath: idle` on its line, or --idle-wait "
            "LINE); every wait is process time and keeps its length"
        )
    if not result.limits_ok:
        console.print(
            "REFUSED: the optimized cycle breaks a limit or the cell's margin; no program was written "
            f"and no saving is claimed (default {result.default_energy_J:.2f} J; see cycle.json)"
        )
        console.print(f"wrote {', '.join(sorted(files))} in {out}")
        return 1
    b = result.breakdown
    check = saved.get("written_program_check")
    written_name = "optimized_task/" if "optimized_task" in files else "optimized.mod"
    if ("optimized.mod" in files or "optimized_task" in files) and saved.get(
        "executed_saved_pct"
    ) is not None:
        console.print(
            f"{written_name}, as the controller emulation runs it: cycle {saved['executed_cycle_s']:.3f} s "
            f"(taught {result.default_cycle_s:.3f} s), {saved['executed_optimized_J']:.2f} J per cycle on "
            f"the model ({result.energy_measure} energy, motion) against the taught "
            f"{saved['executed_default_J']:.2f} J: {saved['executed_saved_pct']:.1f} % saved; "
            + (
                f"written with the controller's levers ({saved['rapid_levers']['moves_changed']} move "
                "statements changed: AccSet, speed data, zones)"
                if saved["rapid_written_from"] == "levers"
                else "the plan's via points with the controller's levers "
                f"({saved['rapid_via_levers']['moves_changed']} via-point statements changed: AccSet, \\T, "
                "zones), searched on the controller emulation"
                if saved["rapid_written_from"] == "via points + levers"
                else f"its via points follow {saved['rapid_follows']}"
            )
        )
    if rapid:
        console.print(f"export: {saved['export_choice']}")
    layout = saved.get("rapid_structure")
    if "optimized.mod" in files and layout is not None:
        lines = layout["optimized_lines"]
        per_run = [str(m["line"]) for m in lines if m["selection"] == "per run"]
        console.print(
            f"optimized.mod keeps the program: {len(lines)} optimized move line(s) call added jp_opt_* "
            "procedures"
            + (f" (per run, selected by jpCtx: line(s) {', '.join(per_run)})" if per_run else "")
            + ", the rest is as written"
        )
        for target, again in layout["reteach"].items():
            console.print(
                f"re-teaching {target} asks to optimize line(s) {', '.join(map(str, again))} again (their "
                "via points were planned from it): `joulepath cycle` on the re-taught optimized.mod does"
            )
    lab_pct = saved.get("lab_saved_pct")
    on_lab = "" if lab_pct is None else f", {lab_pct:.1f} % on the lab robot on the same measure"
    if "egm.mod" in files:
        console.print(
            f"egm.mod streams the plan (cycle_path.csv: {result.optimized_cycle_s:.3f} s, "
            f"{result.optimized_energy_J:.2f} J on the model ({result.energy_measure} energy), "
            f"{result.saved_pct:.1f} % saved{on_lab}): `joulepath stream {out} --repeat K`"
        )
    console.print(
        f"the plan: cycle {result.default_cycle_s:.3f} s -> {result.optimized_cycle_s:.3f} s; energy on "
        f"the model ({result.energy_measure}, motion) {result.default_energy_J:.2f} -> "
        f"{result.optimized_energy_J:.2f} J ({result.saved_pct:.1f} % saved)"
        + (
            ""
            if lab_pct is None
            else f"; on the lab robot ({result.energy_measure}, motion) {saved['lab_default_J']:.2f} -> "
            f"{saved['lab_optimized_J']:.2f} J ({lab_pct:.1f} % saved)"
        )
        + (" (every unit kept as taught)" if done.every_unit_taught else "")
    )
    for e in result.energies:
        lab = (
            ""
            if e.lab_saved_pct is None
            else f"; lab {e.lab_default_J:.2f} J -> {e.lab_optimized_J:.2f} J, {e.lab_saved_pct:.1f} %"
        )
        standby = (
            f", standby {e.standby_J:.1f} J included ({100 * e.standby_J / e.default_J:.0f} % of the default)"
            if e.standby_J and e.default_J > 0
            else ""
        )
        console.print(
            f"  {e.measure:<10} (at the {e.stage}): model {e.default_J:.2f} J -> {e.optimized_J:.2f} J per "
            f"cycle, {e.saved_pct:.1f} % saved{lab}{standby}",
            markup=False,
        )
    if any(e.measure == "electrical" for e in result.energies):
        console.print(f"  drive data: {r.drivetrain.drives_source}", markup=False)
    waits = "" if b.by_waits_pct is None else f", idle waits {b.by_waits_pct:.1f} %"
    along = (
        ""
        if b.by_path_retiming_pct is None
        else f", MoveL segments re-timed along their path {b.by_path_retiming_pct:.1f} %"
    )
    console.print(
        f"breakdown: shape {b.by_shape_pct:.1f} %, time allocation {b.by_allocation_pct:.1f} %{waits}{along}"
    )
    for choice in spec.choices:
        console.print(f"read: {choice}", markup=False)
    for a in spec.assumed:
        console.print(f"assumed: {a.line()}", markup=False)
    if spec.kept:
        console.print(
            f"kept as taught: {len(spec.kept)} of {sum(st.kind == 'move' for st in spec.steps)} moves "
            f"(their motion is known only at run time); {saved['open_to_optimization_pct']:.1f} % of the "
            "cycle's motion energy was open to optimization"
        )
        for move, why in spec.kept:
            console.print(f"  {move}: {why}", markup=False)
    if result.long_units:
        console.print(
            f"kept as taught, longer than the {work_limit('move_s'):g} s one optimized unit may take "
            f"(JOULEPATH_MAX_MOVE_S): the unit(s) at line(s) {', '.join(map(str, result.long_units))}"
        )
    if result.timed_out:
        console.print("--max-time reached: the best verified result of the moves solved by then")
    if cell is not None:
        near = [m for m in result.moves if m.default_clearance_mm is not None and m.default_clearance_mm < 0]
        for m in near:
            console.print(
                f"line {m.line}: {m.label}: the default move comes within the cell's margin; not optimized"
            )
    if result.fixed_lines:
        console.print(
            "kept verbatim, run time treated as fixed: line(s) "
            + ", ".join(map(str, sorted(set(result.fixed_lines))))  # a line run several times: once
        )
    if rapid and "optimized.mod" not in files and "optimized_task" not in files:
        console.print(f"NOT WRITTEN: optimized.mod: {saved['rapid_refused']}")
    elif check is not None and not check["within_tolerances"]:
        console.print(
            "WARNING (--write-anyway): optimized.mod, run by the controller emulation, does not keep the "
            f"plan: cycle {check['emulated_cycle_s']:.3f} s, energy {check['emulated_energy_J']:.2f} J, TCP "
            f"path within {check['tcp_path_deviation_mm']:.1f} mm (cycle.json: written_program_check)"
        )
    console.print(f"wrote {', '.join(sorted(files))} in {out}")
    return 0 if ("optimized.mod" in files or "optimized_task" in files or "egm.mod" in files) else 1
