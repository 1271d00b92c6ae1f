"""``joulepath optimize`` and ``joulepath bench-optimizers``."""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import typer

from joulepath.cli._common import check_out_folder, console, parse_joints, robot_inputs
from joulepath.cli._robot import load_robot_for_cli, lock_option, unchecked_option
from joulepath.description import DEFAULT_ROBOT

if TYPE_CHECKING:
    from joulepath.dynamics import Robot
    from joulepath.optimize import MoveResult


def _models(
    model_dir: Path | None, fitness: str, family: str, robot_name: str, n_joints: int, robot_arg: str = ""
) -> tuple[tuple[object, ...], tuple[int, ...] | None]:
    from joulepath.optimize import fitness_kind

    targets = fitness_kind(fitness).model_targets(n_joints)
    if not targets:
        if model_dir is not None:
            raise typer.BadParameter(
                "--fitness physics does not use a learned model; drop --model, or add --fitness surrogate",
                param_hint="--model",
            )
        return (), None
    if model_dir is None:
        raise typer.BadParameter(
            f"--fitness {fitness} needs --model (a `joulepath train` output folder)", param_hint="--model"
        )
    from joulepath.errors import InvalidModel
    from joulepath.learn import best_model, read_joints_json  # scikit-learn: only with a learned model

    models = tuple(best_model(model_dir, t, family=family or None) for t in targets)
    for m in models:
        on_card, source = m.card.get("robot"), m.card.get("robot_source")
        if not on_card and not source:
            raise InvalidModel(
                f"{model_dir}: the {m.family} model for {m.target} names no robot on its card; "
                "retrain it with `joulepath train --robot ...` (cards name the robot of their data)"
            )
        if not on_card and source not in (robot_arg, robot_name):
            raise InvalidModel(
                f"{model_dir}: the {m.family} model for {m.target} was trained for robot {source!r}, "
                f"not {robot_arg!r}; train a model on this robot's data"
            )
        if on_card and on_card != robot_name:
            raise InvalidModel(
                f"{model_dir}: the {m.family} model for {m.target} was trained on data of robot "
                f"{m.card.get('robot')!r}, not {robot_name!r}; train a model on this robot's data"
            )
    joints = None
    jf = model_dir / "joints.json"
    if jf.exists():
        joints = read_joints_json(jf, n_joints)
    return models, joints


def _status(status: object, label: str) -> Callable[[int, int], None]:
    def update(done: int, total: int) -> None:
        status.update(f"{label}: {done}/{total} runs")  # type: ignore[attr-defined]

    return update


def optimize(
    start: str = typer.Option(..., "--start", help="Start configuration q1,...,qn."),
    end: str = typer.Option(..., "--end", help="End configuration q1,...,qn."),
    duration: float = typer.Option(..., "--duration", help="Duration T in s (a multiple of 0.025)."),
    degrees: bool = typer.Option(False, "--degrees", help="--start/--end are in degrees (default rad)."),
    model: Path = typer.Option(None, "--model", help="Folder of trained models (`joulepath train --out`)."),
    family: str = typer.Option("", help="Model family to use (default: best grouped-CV score)."),
    fitness: str = typer.Option("physics", help="physics (default), surrogate or surrogate-joints."),
    algo: str = typer.Option(
        "auto",
        "--algo",
        help="auto (gradient on physics, cmaes on a learned model), gradient, gradient-fast (about half "
        "the time for a few points less saving), gradient-grid (the gradient search before its hull rows, "
        "slower), cmaes, ga, de, ma-random or ma-informed.",
    ),
    parametrization: str = typer.Option("rest_to_rest", help="GA/DE/MA chromosomes: rest_to_rest or thesis."),
    knot_spacing: float = typer.Option(
        0.05, "--knot-spacing", help="s between B-spline knots (gradient, cmaes)."
    ),
    starts: int = typer.Option(1, "--starts", min=1, max=50, help="Starting paths of the gradient search."),
    max_deviation: float = typer.Option(
        None, "--max-deviation", help="mm: keep the TCP this close to the default move's TCP (gradient)."
    ),
    accel_time: float = typer.Option(
        0.25,
        "--accel-time",
        help="s to reach the speed limit at full acceleration (0: no acceleration limit).",
    ),
    jerk_time: float = typer.Option(
        None,
        "--jerk-time",
        help="s for the acceleration to reach its limit at full jerk: jerk limit = acceleration limit / this "
        "(0: no jerk limit; default: the emulated controller's, joulepath.sim.JERK_TIME, 0.125 s).",
    ),
    generations: int = typer.Option(200, min=1, help="Generation cap (ga, de, ma-*)."),
    population: int = typer.Option(100, min=4, help="Population (ga, de, ma-*)."),
    seed: int = typer.Option(0, min=0, max=2**32 - 1, help="Random seed."),
    robot: str = typer.Option(
        DEFAULT_ROBOT, help="Robot name (irb120, ur5, panda, ...) or .irml/.urdf path."
    ),
    export: str = typer.Option(
        "",
        "--export",
        help="Program to write: rapid, egm (ABB EGM streaming), urscript, urscript-cb3 or ros2 "
        "(default: the robot's own controller).",
    ),
    energy: str = typer.Option(
        "thesis",
        "--energy",
        help="Energy measure to minimize: thesis (Σ|τ·qd| at the joints), mechanical (at the motor side of "
        "the gears) or electrical (at the cabinet; needs the robot's drive data). Every measure the robot "
        "has the data for is reported.",
    ),
    lock: list[str] = lock_option(),
    unchecked: bool = unchecked_option(),
    robust: bool = typer.Option(
        False,
        "--robust",
        help="For a model of estimates (a .provenance.toml beside it, e.g. irb4600): minimize the expected "
        "energy over 16 models drawn within its stated uncertainty (CMA-ES; thesis energy), not the nominal "
        "model's.",
    ),
    out: Path = typer.Option(..., "--out", help="Run folder."),
) -> int:
    """Find the least-energy path between two configurations in a fixed time; verify; export the program.

    The program is that of the robot's own controller (IRB 120: RAPID path.mod; UR:
    URScript path.script; other arms: ROS 2 trajectory.yaml + trajectory.csv), or the
    one --export names. Exit code 0: the optimized path respects every limit and the
    program was written; 1: it ran, but the result breaks a limit and no program was
    written; 2: bad input (an infeasible task included).
    """
    from joulepath.energy import check_measure
    from joulepath.export import EXPORTERS, select_exporter
    from joulepath.optimize import MAX_DURATION, RUN_FILES, OptimizeConfig, optimize_move, write_run
    from joulepath.trajectory import sample_times

    check_out_folder(out)
    r = load_robot_for_cli(robot, unchecked=unchecked, lock=lock)
    exporter, warning = select_exporter(r, export or None)
    programs = {f for e in EXPORTERS.values() for f in e.files}
    check_out_folder(  # every name written inside --out, before any work
        out,
        files=sorted({*(f for f in RUN_FILES if f not in programs), *exporter.files}),
        inputs=robot_inputs(robot),
    )
    if warning is not None:
        print(f"warning: {warning}", file=sys.stderr)
    q0 = parse_joints(start, option="--start", degrees=degrees, n=r.n_joints)
    qf = parse_joints(end, option="--end", degrees=degrees, n=r.n_joints)
    config = OptimizeConfig(
        algorithm=algo,
        fitness=fitness,
        parametrization=parametrization,
        knot_spacing=knot_spacing,
        n_starts=starts,
        max_deviation_mm=max_deviation,
        accel_time=accel_time,
        max_gen=generations,
        pop_size=population,
        seed=seed,
        follow=exporter.follows,
        energy=energy,
    )
    check_measure(energy, r.drivetrain)  # refused before any model is loaded: one line, what to provide
    robust_models = (
        _robust_models(r, seed=seed, fitness=fitness, model=model, energy=energy) if robust else ()
    )
    if robust:
        config = replace(config, fitness="surrogate")
    if jerk_time is not None:  # else the controller's default (OptimizeConfig's)
        config = replace(config, jerk_time=jerk_time)
    if np.isfinite(duration) and 0 < duration <= MAX_DURATION:
        sample_times(duration)  # a whole number of samples: checked before any model is loaded
    models, joints = (
        (robust_models, None) if robust else _models(model, fitness, family, r.name, r.n_joints, robot)
    )
    with console.status(f"optimizing with {config.search.name} on the {fitness} fitness..."):
        result = optimize_move(
            r, np.array(q0), np.array(qf), duration, config, models=models, joints_ranked=joints
        )
    files = write_run(result, r, out, export=exporter.name)
    s = result.summary
    program = ", ".join(exporter.files)
    if not s.limits_ok:
        console.print(
            f"REFUSED: the optimized path breaks a limit ({'; '.join(s.limit_excess)}); "
            f"{program} was NOT written and no saving is claimed (default {s.energy_default_J:.3f} J)"
        )
        console.print(f"wrote {', '.join(sorted(files))} in {out}")
        return 1
    if not all(name in files for name in exporter.files):
        import json

        why = json.loads((out / "result.json").read_text()).get("program_refused", "")
        console.print(f"REFUSED: {program} was NOT written: {why}")
        console.print(f"wrote {', '.join(sorted(files))} in {out}")
        return 1
    import json

    written = json.loads((out / "result.json").read_text())
    figures = written["energy_figures"]
    m = figures["measure"]
    plan = (
        f"planned on the model ({m} energy): default {s.energy_default_J:.3f} J, optimized "
        f"{s.energy_optimized_J:.3f} J, {s.saved_pct:.1f} % saved at equal cycle time "
        f"({s.algorithm}, {s.iterations} iterations, {s.evaluations:,} evaluations, {s.wall_s:.2f} s); "
        f"within every limit; largest TCP deviation {s.max_tcp_deviation_mm:.1f} mm, "
        f"largest jerk {s.max_jerk_rad_s3:.0f} rad/s³"
    )
    if exporter.follows == "via-points":
        e, x = written, figures["executed"]
        lab_x = (
            "" if x["lab_saved_pct"] is None else f", {x['lab_saved_pct']:.1f} % on the emulated lab robot"
        )
        console.print(
            f"{program} as the controller emulation runs it ({m} energy): {x['saved_pct']:.1f} % saved on "
            f"the model ({x['default_J']:.3f} J -> {x['optimized_J']:.3f} J){lab_x}; the optimized move "
            "takes "
            f"{e['executed_duration_s']:.3f} s (planned {s.duration_s:g} s), {e['executed_via_points']} via "
            f"points, TCP within {e['executed_tcp_deviation_mm']:.1f} mm of the plan"
        )
        console.print(f"the plan: {plan}")
    else:
        console.print(plan)
    if s.surrogate_outside_range_pct:
        console.print(
            f"learned model: {s.surrogate_outside_range_pct:.1f} % of the optimized path's samples lie "
            "outside "
            "its training data (positions, speeds, accelerations or move duration; the card's "
            "training_range): its energies there are extrapolations",
            markup=False,
        )
    _state_over_uncertainty(r, result, seed=seed, measure=energy)
    if r.friction is None:
        console.print(f"physics: no friction modelled for {r.name}; friction: {r.friction_note}")
    lab, vs = figures["lab"], figures["planned_vs_lab"]
    if lab is not None and lab["saved_pct"] is not None:
        what = "the plan" if exporter.follows == "via-points" else "the optimized path"
        where = "the emulated lab robot" if s.lab_plant.startswith("emulated IRB 120") else f"a {s.lab_plant}"
        off = (
            ""
            if vs is None or vs["default_pct"] is None
            else f"; the model's figures {vs['default_pct']:+.2f} % (default) and "
            f"{vs['optimized_pct']:+.2f} % (optimized) off the lab's, the saving "
            f"{vs['saved_points']:+.2f} points"
        )
        console.print(
            f"{what} on {where} ({m} energy): default {lab['default_J']:.3f} J, optimized "
            f"{lab['optimized_J']:.3f} J, {lab['saved_pct']:.1f} % saved{off}",
            markup=False,
        )
    for ms in s.energies:
        on_lab = (
            ""
            if ms.lab_saved_pct is None
            else f"; lab {ms.lab_default_J:.3f} J -> {ms.lab_optimized_J:.3f} J, {ms.lab_saved_pct:.1f} %"
        )
        standby = f", standby {ms.standby_J:.3f} J included" if ms.standby_J else ""
        console.print(
            f"  {ms.measure:<10} (at the {ms.stage}): model {ms.default_J:.3f} J -> {ms.optimized_J:.3f} J, "
            f"{ms.saved_pct:.1f} % saved{on_lab}{standby}",
            markup=False,
        )
    for name in s.energies_unavailable:
        console.print(f"  {name:<10} not computed: no data (see energies_unavailable in result.json)")
    if s.measure("electrical") is not None:
        console.print(f"  drive data: {r.drivetrain.drives_source}", markup=False)
    console.print(f"wrote {', '.join(sorted(files))} in {out}")
    return 0


def bench_optimizers(
    tasks: int = typer.Option(500, min=1, help="Random tasks (thesis: 500)."),
    generations: int = typer.Option(250, min=1, help="Generation cap (thesis: 250)."),
    population: int = typer.Option(100, min=4),
    quick: bool = typer.Option(False, help="10 tasks, 30 generations, population 30."),
    model: Path = typer.Option(None, "--model", help="Trained models: surrogate fitness (single and multi)."),
    seed: int = typer.Option(0, min=0, max=2**32 - 1, help="Random seed."),
    jobs: int = typer.Option(2, min=1, help="Local processes."),
    scheduler: str = typer.Option("", help="Dask scheduler address."),
    robot: str = typer.Option(DEFAULT_ROBOT),
    out: Path = typer.Option(..., "--out", help="Folder for the results CSV."),
) -> int:
    """The thesis' optimizer benchmark (§4.5.1): every GA/DE/MA configuration on random tasks."""
    from joulepath._io import atomic_write_text, make_folder
    from joulepath.optimize import bench_optimizers as run

    check_out_folder(out, files=["optimizers_single.csv", *(["optimizers_multi.csv"] if model else [])])
    if quick:
        tasks, generations, population = 10, 30, 30
    variants = (
        [("physics", "single")] if model is None else [("surrogate", "single"), ("surrogate-joints", "multi")]
    )
    for fitness, kind in variants:
        r = load_robot_for_cli(robot)
        models, joints = _models(model, fitness, "", r.name, r.n_joints, robot) if model else ((), None)
        with console.status(f"{kind}-objective ({fitness}): {tasks} tasks...") as status:
            frame = run(
                robot=robot,
                n_tasks=tasks,
                generations=generations,
                population=population,
                fitness=fitness,
                models=models,
                joints=joints,
                seed=seed,
                n_jobs=jobs,
                scheduler=scheduler or None,
                progress=_status(status, f"{kind}-objective ({fitness})"),
            )
        make_folder(out)
        atomic_write_text(out / f"optimizers_{kind}.csv", frame.to_csv(index=False))
        console.print(f"{kind}-objective, fitness {fitness}:")
        console.print(frame.to_string(index=False, float_format=lambda v: f"{v:.2f}"), markup=False)
    return 0


def _state_over_uncertainty(r: Robot, result: MoveResult, *, seed: int, measure: str) -> None:
    """For a model of estimates, one line: the planned saving over the model's stated uncertainty."""
    from joulepath.description import provenance_beside
    from joulepath.optimize import saving_over_uncertainty

    provenance = provenance_beside(r.source)
    if provenance is None or not provenance.is_estimate:
        return
    stated = saving_over_uncertainty(
        r, result.default, result.optimized, provenance.uncertainty, seed=seed, measure=measure
    )
    console.print(stated.line(), markup=False)
    console.print(provenance.headline(), markup=False)


def _robust_models(
    r: Robot, *, seed: int, fitness: str, model: Path | None, energy: str
) -> tuple[object, ...]:
    """``--robust``: the expected-energy objective over models within the robot's stated uncertainty."""
    import numpy as np

    from joulepath.description import provenance_beside
    from joulepath.optimize import ROBUST_SAMPLES, ExpectedEnergy

    if fitness != "physics" or model is not None or energy != "thesis":
        raise typer.BadParameter(
            "--robust is its own objective on the thesis energy; drop --fitness, --model and --energy",
            param_hint="--robust",
        )
    provenance = provenance_beside(r.source)
    if provenance is None or provenance.uncertainty.is_zero:
        raise typer.BadParameter(
            f"robot {r.name!r} states no uncertainty (no .provenance.toml beside {r.source}); "
            "--robust needs one, e.g. --robot irb4600",
            param_hint="--robust",
        )
    # its own stream, apart from the statement's (seeded by --seed): the saving is then stated on
    # models the path was not fitted to
    stream = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])
    console.print(
        f"robust objective: expected energy over {ROBUST_SAMPLES} models within the stated uncertainty",
        markup=False,
    )
    return (ExpectedEnergy(r, provenance.uncertainty, rng=stream),)
