"""``joulepath rapid collect``, ``joulepath simulate`` (random moves or a program), ``joulepath ingest``."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from joulepath.cli._common import (
    check_out_file,
    check_out_folder,
    console,
    parse_joints,
    progress_lines,
    robot_inputs,
)
from joulepath.description import DEFAULT_ROBOT

if TYPE_CHECKING:
    from joulepath.dynamics import Robot

COLLECT_FILES = ("JPCollect.mod", "JPMeasure.mod")
EXCITE_FILES = ("JPExcite.mod", "JPMeasure.mod")


def _excitation_programs(robot: Robot, *, range_set: str, seed: int) -> dict[str, str]:
    """JPExcite.mod (an optimised exciting trajectory, one period) and the measurement module."""
    from joulepath.export import excitation_module, measurement_module
    from joulepath.identify import design_excitation

    with console.status("designing an exciting trajectory (condition number of the regressor)..."):
        design = design_excitation(robot, range_set=range_set, seed=seed)
    path = design.trajectory.sample(0.025)
    console.print(
        f"exciting trajectory: {design.trajectory.end_time:g} s, condition number "
        f"{design.condition_number:.1f} (random start {design.condition_number_start:.1f})"
    )
    return {
        "JPExcite.mod": excitation_module(robot, path.q, path.qd, design.trajectory.end_time),
        "JPMeasure.mod": measurement_module(),
    }


rapid_app = typer.Typer(help="Write RAPID programs for the ABB controller.", no_args_is_help=True)


@rapid_app.command("collect")
def rapid_collect(
    out: Path = typer.Option(..., "--out", help="Folder for JPCollect.mod and JPMeasure.mod."),
    robot: str = typer.Option(
        DEFAULT_ROBOT, help="Robot name (irb120, ur5, panda, ...) or .irml/.urdf path."
    ),
    moves: int = typer.Option(1000, min=1, help="Number of random moves."),
    range_set: str = typer.Option("collection", help="Joint bounds: collection (App. D.1), lab, nominal."),
    mode: str = typer.Option(
        "rand",
        help="rand: draw on the controller; table: embed the moves of --seed; excitation: an exciting "
        "trajectory for `joulepath identify` (JPExcite.mod).",
    ),
    seed: int = typer.Option(
        0, min=0, max=2**32 - 1, help="Seed of the moves (table) or of the controller's generator (rand)."
    ),
    force: bool = typer.Option(
        False, "--force", help="Replace JPCollect.mod and JPMeasure.mod if --out already holds them."
    ),
    export: str = typer.Option(
        "", "--export", help="rapid: write ABB RAPID for a robot that is not an ABB arm anyway (warns)."
    ),
) -> int:
    """Write the data-collection programs of thesis Appendix D (collection + measurement).

    Programs already in --out are never replaced silently: the command refuses
    (exit 2, nothing written) unless --force is given. RAPID runs on ABB
    controllers: another vendor's robot is refused unless --export rapid is given.
    """
    from joulepath import load_robot
    from joulepath._io import atomic_write_text, make_folder
    from joulepath.errors import InvalidInput
    from joulepath.export import collection_programs, refuse_foreign

    files = EXCITE_FILES if mode == "excitation" else COLLECT_FILES
    if export not in ("", "rapid"):
        raise typer.BadParameter(f"rapid collect writes RAPID only; got {export!r}", param_hint="--export")
    check_out_folder(out, files=files, inputs=robot_inputs(robot))
    r = load_robot(robot)
    warning = refuse_foreign(r, "rapid", explicit=export == "rapid")
    if warning:
        print(f"warning: {warning}", file=sys.stderr)
    used = r.ranges_for(range_set)[0]
    if used != range_set:
        console.print(f"note: {r.name} has no {range_set!r} range set; the moves use its nominal ranges")
    existing = [name for name in files if (out / name).exists()]
    if existing and not force:
        raise InvalidInput(
            f"{out}: already holds {' and '.join(existing)}; pass --force to replace "
            f"{'them' if len(existing) > 1 else 'it'}, or choose another --out"
        )
    if mode == "excitation":
        programs = _excitation_programs(r, range_set=range_set, seed=seed)
    else:
        programs = collection_programs(r, n_moves=moves, range_set=range_set, mode=mode, seed=seed)
    make_folder(out)
    for name, text in programs.items():
        atomic_write_text(out / name, text)
        console.print(f"wrote {out / name}")
    return 0


def simulate(
    out: Path = typer.Option(..., "--out", help="Log file (.csv) for one run, or a folder for --plan."),
    plant: str = typer.Option(
        "lab", help="sim (nominal twin), lab (emulated real robot) or a twin folder (`joulepath identify`)."
    ),
    moves: int | None = typer.Option(None, min=1, help="Number of random moves (default 1000)."),
    seed: int = typer.Option(
        0, min=0, max=2**32 - 1, help="Seed of the random moves and of the plant's noise."
    ),
    plan: str = typer.Option("", help="'thesis': real, sim, micro and test datasets in one go."),
    program: Path | None = typer.Option(
        None,
        "--program",
        help="Run this RAPID module's (or task folder's) main once, as the RAPID interpreter reads it (e.g. "
        "path.mod of `joulepath optimize`), on the emulated controller and the plant, instead of random "
        "moves; --out is the log file (.csv).",
    ),
    start: str = typer.Option(
        "",
        "--start",
        help="--program: where the robot rests when main starts, q1,...,qn (default: the first move's "
        "target).",
    ),
    degrees: bool = typer.Option(False, "--degrees", help="--start is in degrees (default rad)."),
    robot: str = typer.Option(
        DEFAULT_ROBOT, help="Robot name (irb120, ur5, panda, ...) or .irml/.urdf path."
    ),
    range_set: str | None = typer.Option(
        None,
        "--range-set",
        help="Joint bounds of the moves: collection (App. D.1, the default), lab, nominal; a robot without "
        "the set uses its nominal ranges.",
    ),
    workers: int = typer.Option(2, min=1, help="Processes for --plan."),
    mode: str = typer.Option(
        "moves", help="moves: random moves; excitation: an exciting trajectory for `joulepath identify`."
    ),
    periods: int = typer.Option(3, min=1, help="--mode excitation: periods of the 10 s trajectory."),
    harmonics: int = typer.Option(5, min=1, max=20, help="--mode excitation: harmonics per joint."),
) -> int:
    """Simulate data collection: random moves (or a RAPID program) on a plant, logged like the controller."""
    if program is not None:
        given = [
            name
            for name, used in (
                ("--plan", bool(plan)),
                ("--mode", mode != "moves"),
                ("--moves", moves is not None),
                ("--range-set", range_set is not None),
            )
            if used
        ]
        if given:
            raise typer.BadParameter(
                f"--program runs the program's own moves; drop {', '.join(given)}", param_hint="--program"
            )
        return _simulate_program(
            program, out, plant=plant, robot=robot, seed=seed, start=start, degrees=degrees
        )
    if start:
        raise typer.BadParameter("--start is where a --program starts; give --program", param_hint="--start")
    n_moves = 1000 if moves is None else moves
    range_set = "collection" if range_set is None else range_set
    if mode not in ("moves", "excitation"):
        raise typer.BadParameter(f"unknown mode {mode!r}; use moves or excitation", param_hint="--mode")
    if mode == "excitation" and plan:
        raise typer.BadParameter(
            "--plan runs random moves; drop --plan for --mode excitation", param_hint="--mode"
        )
    from joulepath.data import moves_sidecar_path as sidecar_path
    from joulepath.sim import simulate as run
    from joulepath.sim import simulate_plan

    inputs = robot_inputs(robot)
    if out.suffix == ".csv" and not plan:
        check_out_file(out, example="lab.csv", inputs=inputs)
        check_out_file(sidecar_path(out), example="lab.moves.csv", inputs=inputs)
    elif plan:
        check_out_folder(out, inputs=inputs)
    else:
        name = f"{Path(plant).name if Path(plant).is_dir() else plant}-{seed}.csv"
        check_out_folder(out, files=(name, sidecar_path(Path(name)).name), inputs=inputs)
    if plan:
        if plan != "thesis":
            raise typer.BadParameter(f"unknown plan {plan!r}; the only plan is 'thesis'", param_hint="--plan")
        with console.status("simulating the thesis' datasets (real, sim, micro, test)..."):
            results = simulate_plan(
                out,
                seed=seed,
                robot=robot,
                workers=workers,
                progress=lambda r: console.print(
                    f"  {r['name']:>5}: {r['moves']} {r['plant']} moves, {r['rows']:,} log rows, "
                    f"{r['table_rows']:,} table rows in {r['table_moves']} moves"
                ),
            )
        console.print(f"wrote {len(results)} logs under {out / 'logs'} and tables {out}/<name>.parquet")
        return 0
    target = out if out.suffix == ".csv" else out / name
    if mode == "excitation":
        return _simulate_excitation(
            target, plant=plant, robot=robot, seed=seed, periods=periods, harmonics=harmonics
        )
    with console.status(f"simulating {n_moves} moves on the {plant} plant..."):
        res = run(target, plant=plant, n_moves=n_moves, seed=seed, robot=robot, range_set=range_set)
    if res.range_set != range_set:
        console.print(f"note: {robot} has no {range_set!r} range set; the moves use its nominal ranges")
    if plant == "lab" and not res.plant_note.startswith("emulated IRB 120"):
        console.print(f"note: the lab plant is a {res.plant_note}")
    console.print(
        f"wrote {res.log} ({res.n_rows:,} rows, {res.n_moves} moves: simulated {res.duration_s:.1f} s "
        f"of robot motion) and {res.moves}"
    )
    return 0


def _simulate_program(
    program: Path, out: Path, *, plant: str, robot: str, seed: int, start: str, degrees: bool
) -> int:
    from joulepath import load_robot
    from joulepath.program import simulate_program

    if out.suffix.lower() != ".csv":
        raise typer.BadParameter(f"--program writes one log; give a .csv file, got {out}", param_hint="--out")
    check_out_file(out, example="path-run.csv", inputs=[program, *robot_inputs(robot)])
    r = load_robot(robot)
    q0 = parse_joints(start, option="--start", degrees=degrees, n=r.n_joints) if start else None
    with progress_lines(f"running {program.name} on the emulated controller and the {plant} plant...") as say:
        res = simulate_program(program, out, robot=r, plant=plant, seed=seed, start=q0, progress=say)
    for line in res.said:
        console.print(line, markup=False)
    console.print(
        f"wrote {res.log} ({res.n_rows:,} rows: {res.n_moves} moves of {program.name} in "
        f"{res.program_time_s:.2f} s on the {res.plant} plant, {res.plant_note})"
    )
    return 0


def _simulate_excitation(
    target: Path, *, plant: str, robot: str, seed: int, periods: int, harmonics: int
) -> int:
    from joulepath import load_robot
    from joulepath.identify import design_excitation, simulate_excitation

    r = load_robot(robot)
    with console.status("designing an exciting trajectory (condition number of the regressor)..."):
        design = design_excitation(r, periods=periods, harmonics=harmonics, seed=seed)
    with console.status(f"simulating {design.trajectory.end_time:g} s of excitation on the {plant} plant..."):
        rows, seconds = simulate_excitation(target, design, r, plant=plant, seed=seed)
    console.print(
        f"wrote {target} ({rows:,} rows: simulated {seconds:.1f} s of an exciting trajectory, condition "
        f"number {design.condition_number:.1f}; random start {design.condition_number_start:.1f})"
    )
    return 0


def ingest(
    logs: list[Path] = typer.Argument(..., help="Controller logs (App. D.2) or generic joint CSVs."),
    out: Path = typer.Option(..., "--out", help="Energy table to write (.parquet)."),
    robot: str = typer.Option(
        "",
        help="Robot of the logs: checks controller logs' TCP, gives generic logs all 40 features.",
    ),
) -> int:
    """Turn joint logs into the 40-feature energy table (or the joint-only one).

    The `.moves.csv` files that `joulepath simulate` writes beside its logs are
    skipped with a note, so `ingest logs/*.csv` works on its folder.
    """
    from joulepath import load_robot
    from joulepath._io import make_folder
    from joulepath.data import ingest as run
    from joulepath.data import save_table

    check_out_file(out, example="table.parquet", inputs=[*logs, *robot_inputs(robot)])
    r = load_robot(robot) if robot else None
    table = run([str(p) for p in logs], robot=r, progress=console.print)
    make_folder(out.parent)
    save_table(table, out)
    console.print(
        f"wrote {out}: {len(table.frame):,} rows, {table.n_moves} moves, "
        f"feature set {table.feature_set} ({len(table.features)} inputs)"
    )
    return 0
