"""``bench-optimizers``: the thesis' benchmark protocol (§4.5.1) for every GA/DE/MA configuration."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from joulepath.description import DEFAULT_ROBOT
from joulepath.dynamics import Robot, load_robot
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.optimize._run import OptimizeConfig, check_default_feasible, optimize_move
from joulepath.sim import ACCEL_TIME, JERK_TIME

if TYPE_CHECKING:  # imported where used: `joulepath optimize` needs no data frames
    import pandas as pd

MAX_DRAWS_PER_TASK = 1000
"""Draws :func:`random_tasks` may spend on one feasible task before it gives up."""


def random_tasks(
    robot: Robot,
    n_tasks: int,
    *,
    seed: int,
    range_set: str = "lab",
    accel_time: float = ACCEL_TIME,
    jerk_time: float = JERK_TIME,
    durations: tuple[float, float] = (1.0, 3.0),
) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """Feasible random tasks: start, end (uniform in the range set), duration (uniform, whole samples).

    A draw whose default (minimum-jerk) move breaks a limit — range, speed,
    acceleration (``v_max / accel_time``), jerk (that over ``jerk_time``) or effort — is
    redrawn, so every task can be done within the limits and every saving is measured against a feasible move.
    """
    rng = np.random.default_rng(seed)
    _, lo, hi = robot.ranges_for(range_set)
    tasks = []
    for k in range(n_tasks):
        for _ in range(MAX_DRAWS_PER_TASK):
            q0 = lo + rng.random(lo.size) * (hi - lo)
            qf = lo + rng.random(lo.size) * (hi - lo)
            T = round(rng.uniform(*durations) / 0.025) * 0.025
            try:
                check_default_feasible(robot, q0, qf, float(T), accel_time=accel_time, jerk_time=jerk_time)
            except LimitViolation:
                continue
            tasks.append((q0, qf, float(T)))
            break
        else:
            raise InvalidInput(
                f"no feasible task {k} in {MAX_DRAWS_PER_TASK} draws from range set {range_set!r} and "
                f"durations {durations} s; allow longer durations"
            )
    return tasks


def thesis_configurations(fitness: str) -> list[tuple[str, OptimizeConfig]]:
    """Every GA configuration of Tables 4.5/4.6, DE, and both MA variants."""
    out = []
    for rec in ("random", "average", "differential"):
        for pc in (0.90, 0.95):
            for pm in (0.01, 0.05):
                for F in (0.05, 0.15) if rec == "differential" else (0.05,):
                    label = f"GA {rec} P(C)={pc} P(M)={pm}" + (f" F={F}" if rec == "differential" else "")
                    out.append(
                        (
                            label,
                            OptimizeConfig(
                                algorithm="ga",
                                fitness=fitness,
                                recombination=rec,
                                p_crossover=pc,
                                p_mutation=pm,
                                F=F,
                            ),
                        )
                    )
    out.append(("DE rand/1/bin", OptimizeConfig(algorithm="de", fitness=fitness)))
    out.append(("MA random local search", OptimizeConfig(algorithm="ma-random", fitness=fitness)))
    out.append(("MA informed local search", OptimizeConfig(algorithm="ma-informed", fitness=fitness)))
    return out


def default_configuration(fitness: str) -> tuple[str, OptimizeConfig]:
    """joulepath's default search for a fitness, labelled for the bench tables."""
    cfg = OptimizeConfig(fitness=fitness)
    return (f"joulepath default ({cfg.search.name})", cfg)


def _run_one(
    robot_name: str,
    task: tuple[np.ndarray, np.ndarray, float],
    config: OptimizeConfig,
    models: tuple[Any, ...],
    joints: tuple[int, ...] | None,
) -> dict[str, float]:
    robot = load_robot(robot_name)
    res = optimize_move(robot, task[0], task[1], task[2], config, models=models, joints_ranked=joints)
    s = res.summary
    return {
        "vs_initial": np.nan if s.saved_vs_initial_best_pct is None else s.saved_vs_initial_best_pct,
        "vs_default": s.saved_pct if s.limits_ok else 0.0,  # refused: the default move runs
        "wall_s": s.wall_s,
        "generations": s.iterations,
        "limits_ok": float(s.limits_ok),
    }


def bench_optimizers(
    *,
    robot: str = DEFAULT_ROBOT,
    n_tasks: int = 500,
    generations: int = 250,
    population: int = 100,
    fitness: str = "physics",
    models: tuple[Any, ...] = (),
    joints: tuple[int, ...] | None = None,
    configurations: Sequence[tuple[str, OptimizeConfig]] | None = None,
    seed: int = 0,
    n_jobs: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int], None] | None = None,
    per_run: bool = False,
) -> pd.DataFrame:
    """Run every configuration on the same random tasks; improvement % (mean, σ) both ways.

    With ``per_run`` the result has one row per (configuration, task) instead (see
    :func:`summarize_bench`), for paired comparisons of configurations on the same tasks.

    ``vs_initial`` is the thesis' metric (relative to the best individual of the
    random initial population); ``vs_default`` is the honest one (relative to the
    minimum-jerk path over the same duration, on the physics model). Runs start from
    random chromosomes only (the thesis' protocol), seeded per task.
    """
    from joblib import Parallel, delayed, parallel_config

    r = load_robot(robot)
    tasks = random_tasks(r, n_tasks, seed=seed)
    configs = list(configurations or thesis_configurations(fitness))
    jobs = []
    for label, cfg in configs:
        cfg = replace(cfg, fitness=fitness, pop_size=population, max_gen=generations, inject_default=False)
        for k, task in enumerate(tasks):
            jobs.append((label, replace(cfg, seed=seed + k), task))
    total = len(jobs)
    calls = (delayed(_run_one)(robot, task, cfg, models, joints) for _, cfg, task in jobs)
    out = []
    if scheduler:
        from joulepath.learn import connect_scheduler

        with connect_scheduler(scheduler), parallel_config(backend="dask"):
            results = list(Parallel(return_as="generator")(calls))
    else:
        results = []
        for i, res in enumerate(Parallel(n_jobs=n_jobs, return_as="generator")(calls)):
            results.append(res)
            if progress:
                progress(i + 1, total)
    for (label, cfg, _), res in zip(jobs, results, strict=True):
        out.append({"configuration": label, "task": cfg.seed - seed, **res})
    import pandas as pd

    frame = pd.DataFrame(out)
    return frame if per_run else summarize_bench(frame)


def summarize_bench(frame: pd.DataFrame) -> pd.DataFrame:
    """Per configuration: mean and σ of both improvements, wall time, generations, share within limits."""
    summary = frame.groupby("configuration", sort=False).agg(
        vs_initial_mean=("vs_initial", "mean"),
        vs_initial_std=("vs_initial", "std"),
        vs_default_mean=("vs_default", "mean"),
        vs_default_std=("vs_default", "std"),
        wall_s_mean=("wall_s", "mean"),
        generations_mean=("generations", "mean"),
        limits_ok_share=("limits_ok", "mean"),
    )
    return summary.reset_index()
