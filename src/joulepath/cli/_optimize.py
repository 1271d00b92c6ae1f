"""``joulepath optimize`` and ``joulepath bench-optimizers``."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import typer

from joulepath.cli._common import check_out_folder, console, parse_joints


def _models(
    model_dir: Path | None, fitness: str, family: str, robot_name: str
) -> tuple[tuple[object, ...], tuple[int, ...] | None]:
    from joulepath.errors import InvalidModel
    from joulepath.learn import best_model

    if fitness == "physics":
        return (), None
    if model_dir is None:
        raise typer.BadParameter(
            f"--fitness {fitness} needs --model (a `joulepath train` output folder)", param_hint="--model"
        )
    targets = ("E",) if fitness == "surrogate" else tuple(f"E{i}" for i in range(1, 7))
    models = tuple(best_model(model_dir, t, family=family or None) for t in targets)
    for m in models:
        if m.card.get("robot") not in (None, robot_name):
            raise InvalidModel(
                f"{model_dir}: the {m.family} model for {m.target} was trained on data of robot "
                f"{m.card.get('robot')!r}, not {robot_name!r}; train a model on this robot's data"
            )
    joints = None
    jf = model_dir / "joints.json"
    if jf.exists():
        joints = tuple(int(j) for j in json.loads(jf.read_text())["joints_by_influence"])
    return models, joints


def _check_reachable(robot: Any, q0: np.ndarray, qf: np.ndarray, duration: float) -> None:
    """Refuse a duration in which no path can make the move within the joint speed limits."""
    from joulepath.errors import LimitViolation
    from joulepath.units import SAMPLE_PERIOD

    lo, hi = robot.joint_ranges()
    outside = any(np.any((q < lo) | (q > hi)) for q in (q0, qf))
    if outside or not (np.isfinite(duration) and duration > 0):
        return  # optimize_move reports these
    vmax = robot.velocity_limit
    need = np.abs(qf - q0) / np.where(np.isfinite(vmax) & (vmax > 0), vmax, np.inf)
    j = int(np.argmax(need))
    if need[j] > duration:
        jerk = np.ceil(1.875 * need[j] / SAMPLE_PERIOD - 1e-9) * SAMPLE_PERIOD
        raise LimitViolation(
            f"--duration {duration:g} s is too short: joint {j + 1} must turn "
            f"{np.degrees(abs(qf[j] - q0[j])):.1f} deg, and at its speed limit of "
            f"{np.degrees(vmax[j]):.0f} deg/s no path does that in less than {need[j]:.3f} s; "
            f"give a longer --duration (the minimum-jerk path needs {jerk:.3f} s)"
        )


def _status(status: object, label: str) -> Callable[[int, int], None]:
    def update(done: int, total: int) -> None:
        status.update(f"{label}: {done}/{total} runs")  # type: ignore[attr-defined]

    return update


def optimize(
    start: str = typer.Option(..., "--start", help="Start configuration q1,...,q6."),
    end: str = typer.Option(..., "--end", help="End configuration q1,...,q6."),
    duration: float = typer.Option(..., "--duration", help="Duration T in s (a multiple of 0.025)."),
    degrees: bool = typer.Option(False, "--degrees", help="--start/--end are in degrees (default rad)."),
    model: Path = typer.Option(None, "--model", help="Folder of trained models (`joulepath train --out`)."),
    family: str = typer.Option("", help="Model family to use (default: best grouped-CV score)."),
    fitness: str = typer.Option("surrogate", help="surrogate, surrogate-joints or physics."),
    algo: str = typer.Option("ma-random", "--algo", help="ga, de, ma-random or ma-informed."),
    parametrization: str = typer.Option("rest_to_rest", help="rest_to_rest (default) or thesis."),
    generations: int = typer.Option(200, min=1, help="Generation cap."),
    population: int = typer.Option(100, min=4),
    seed: int = typer.Option(0, min=0, max=2**32 - 1, help="Random seed."),
    robot: str = typer.Option("irb120", help="Robot name or .irml/.urdf path."),
    out: Path = typer.Option(..., "--out", help="Run folder."),
) -> int:
    """Find the least-energy path between two configurations in a fixed time; verify; export RAPID."""
    from joulepath import load_robot
    from joulepath.optimize import OptimizeConfig, optimize_move, write_run

    check_out_folder(out)
    r = load_robot(robot)
    q0 = parse_joints(start, option="--start", degrees=degrees, n=r.n_joints)
    qf = parse_joints(end, option="--end", degrees=degrees, n=r.n_joints)
    config = OptimizeConfig(
        algorithm=algo,
        fitness=fitness,
        parametrization=parametrization,
        max_gen=generations,
        pop_size=population,
        seed=seed,
    )
    _check_reachable(r, np.array(q0), np.array(qf), duration)
    models, joints = _models(model, fitness, family, r.name)
    with console.status(f"optimizing with {algo} on the {fitness} fitness..."):
        result = optimize_move(
            r, np.array(q0), np.array(qf), duration, config, models=models, joints_ranked=joints
        )
    files = write_run(result, r, out)
    s = result.summary
    console.print(
        f"default path {s['energy_default_physics_J']:.3f} J, "
        f"optimized {s['energy_optimized_physics_J']:.3f} J "
        f"on physics: {s['improvement_physics_pct']:.1f} % saved at equal cycle time "
        f"({s['generations']} generations, {s['evaluations']:,} evaluations, {s['wall_s']:.2f} s)"
    )
    if s["energy_optimized_lab_J"] is not None:
        console.print(f"on the emulated lab robot: {s['improvement_lab_pct']:.1f} % saved")
    if not s["limits_ok"]:
        console.print("the optimized path violates a joint limit: path.mod was NOT written")
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
    robot: str = typer.Option("irb120"),
    out: Path = typer.Option(..., "--out", help="Folder for the results CSV."),
) -> int:
    """The thesis' optimizer benchmark (§4.5.1): every GA/DE/MA configuration on random tasks."""
    from joulepath._io import atomic_write_text
    from joulepath.optimize import bench_optimizers as run

    check_out_folder(out)
    if quick:
        tasks, generations, population = 10, 30, 30
    variants = (
        [("physics", "single")] if model is None else [("surrogate", "single"), ("surrogate-joints", "multi")]
    )
    for fitness, kind in variants:
        models, joints = _models(model, fitness, "", robot) if model else ((), None)
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
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_text(out / f"optimizers_{kind}.csv", frame.to_csv(index=False))
        console.print(f"{kind}-objective, fitness {fitness}:")
        console.print(frame.to_string(index=False, float_format=lambda v: f"{v:.2f}"), markup=False)
    return 0
