"""Optimize one move: search, verify on physics, and write the run folder."""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._io import atomic_write_text
from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.evolve import DE, GA, MA, Termination, minimize
from joulepath.optimize._problem import (
    FITNESS,
    PARAMETRIZATIONS,
    TrajectoryProblem,
    limit_violation,
    physics_energy,
)
from joulepath.trajectory import Trajectory, minimum_jerk

ALGORITHMS = ("ga", "de", "ma-random", "ma-informed")


@dataclass(frozen=True, slots=True, kw_only=True)
class OptimizeConfig:
    """Settings of one optimization (defaults: the thesis' best GA settings, §4.5).

    ``inject_default`` puts the all-zero chromosome (the minimum-jerk default path of
    ``rest_to_rest``) into the initial population, so the search never returns a
    path its fitness rates worse than the default; the thesis' protocol (and
    ``bench-optimizers``) starts from random chromosomes only.
    """

    algorithm: str = "ma-random"
    fitness: str = "physics"
    parametrization: str = "rest_to_rest"
    pop_size: int = 100
    max_gen: int = 200
    n_stagnant: int = 10
    p_crossover: float = 0.95
    p_mutation: float = 0.05
    recombination: str = "random"
    F: float = 0.05
    n_local: int = 1000
    informed_joints: tuple[int, ...] = ()
    inject_default: bool = True
    seed: int = 0

    def __post_init__(self) -> None:
        if self.algorithm not in ALGORITHMS:
            raise InvalidInput(f"algorithm must be one of {', '.join(ALGORITHMS)}, got {self.algorithm!r}")
        if self.fitness not in FITNESS:
            raise InvalidInput(f"fitness must be one of {', '.join(FITNESS)}, got {self.fitness!r}")
        if self.parametrization not in PARAMETRIZATIONS:
            raise InvalidInput(
                f"parametrization must be one of {PARAMETRIZATIONS}, got {self.parametrization!r}"
            )
        if self.pop_size < 4 or self.max_gen < 1:
            raise InvalidInput("pop_size must be ≥ 4 and max_gen ≥ 1")
        if any(not 1 <= j <= 6 for j in self.informed_joints):
            raise InvalidInput(f"informed_joints are joint numbers 1..6, got {self.informed_joints}")


def make_algorithm(config: OptimizeConfig, joints: tuple[int, ...]) -> GA | DE | MA:
    """The search of ``config`` (``joints``: 1-based, most influential first)."""
    ga = GA(
        pop_size=config.pop_size,
        p_crossover=config.p_crossover,
        p_mutation=config.p_mutation,
        recombination=config.recombination,
        F=config.F,
    )
    if config.algorithm == "ga":
        return ga
    if config.algorithm == "de":
        return DE(pop_size=config.pop_size)
    if config.algorithm == "ma-random":
        return MA(base=ga, local_search="random", n_samples=config.n_local)
    return MA(base=ga, local_search="informed", joints=tuple(j - 1 for j in joints))


@dataclass(frozen=True, slots=True)
class MoveResult:
    """An optimized move, verified on the physics model."""

    summary: dict[str, Any]
    default: Trajectory
    optimized: Trajectory
    history: FloatArray
    chromosome: FloatArray


def rank_joints_by_energy(robot: Robot, path: Trajectory) -> tuple[int, ...]:
    """Joints (1-based) ordered by their share of a path's physics energy (most first)."""
    tau = robot.inverse_dynamics(path.q, path.qd, path.qdd)
    per_joint = (np.abs(tau * path.qd) * path.dt).sum(axis=0)
    return tuple(int(j) + 1 for j in np.argsort(-per_joint))


def _plant_energy(plant: Any, traj: Trajectory) -> float:
    tau = plant.drive_torque(traj.q, traj.qd, traj.qdd)
    return float((np.abs(tau * traj.qd) * traj.dt).sum())


MAX_DURATION = 60.0
"""Longest move :func:`optimize_move` accepts, s (2,400 samples at 40 Hz)."""


def optimize_move(
    robot: Robot,
    q_start: FloatArray,
    q_end: FloatArray,
    duration: float,
    config: OptimizeConfig,
    *,
    models: tuple[Any, ...] = (),
    joints_ranked: tuple[int, ...] | None = None,
) -> MoveResult:
    """Find the path of least energy between two configurations over a fixed duration.

    The search starts from random chromosomes plus the all-zero one (the default
    minimum-jerk path, for ``rest_to_rest``); its result is then checked on the
    physics model (nominal parameters and friction) against the default path, and
    on the emulated lab robot. ``limits_ok`` says whether the path respects the
    joint ranges and speed limits.
    """
    q0 = np.asarray(q_start, dtype=float)
    qf = np.asarray(q_end, dtype=float)
    for name, q in (("start", q0), ("end", qf)):
        lo, hi = robot.joint_ranges()
        if q.shape != (robot.n_joints,):
            raise InvalidInput(f"{name} needs {robot.n_joints} joint values, got {q.shape}")
        bad = np.nonzero((q < lo) | (q > hi))[0]
        if bad.size:
            j = int(bad[0])
            raise LimitViolation(
                f"{name} joint {j + 1} = {np.degrees(q[j]):.2f} deg is outside its range "
                f"[{np.degrees(lo[j]):.1f}, {np.degrees(hi[j]):.1f}] deg; "
                f"move the {name} configuration inside the range"
            )
    if duration > MAX_DURATION:
        raise InvalidInput(
            f"duration {duration:g} s is longer than {MAX_DURATION:g} s; give the move's duration in "
            "seconds (a point-to-point move of an industrial arm takes well under a minute)"
        )
    default = minimum_jerk(q0, qf, duration)
    joints = tuple(config.informed_joints) or joints_ranked or rank_joints_by_energy(robot, default)
    problem = TrajectoryProblem(
        robot=robot,
        q_start=q0,
        q_end=qf,
        duration=duration,
        fitness=config.fitness,
        models=models,
        parametrization=config.parametrization,
    )
    algorithm = make_algorithm(config, joints[:2])
    initial = (
        np.zeros((1, 36)) if config.inject_default and config.parametrization == "rest_to_rest" else None
    )
    t0 = time.perf_counter()
    res = minimize(
        problem,
        algorithm,
        Termination(n_max_gen=config.max_gen, n_stagnant=config.n_stagnant),
        seed=config.seed,
        initial=initial,
    )
    wall = time.perf_counter() - t0
    best = problem.trajectory(res.x_best)
    optimized = Trajectory(t=best.t, q=best.q[0], qd=best.qd[0], qdd=best.qdd[0])
    e_def, _ = physics_energy(robot, default)
    e_opt, tau_opt = physics_energy(robot, optimized)
    viol = limit_violation(robot, optimized, tau_opt)
    surrogate = {}
    if models:
        stack = Trajectory(
            t=default.t,
            q=np.stack([default.q, optimized.q]),
            qd=np.stack([default.qd, optimized.qd]),
            qdd=np.stack([default.qdd, optimized.qdd]),
        )
        fit_problem = TrajectoryProblem(
            robot=robot, q_start=q0, q_end=qf, duration=duration, fitness=config.fitness, models=models
        )
        e_sur, _ = fit_problem.energy(stack)
        surrogate = {
            "energy_default_surrogate_J": float(e_sur[0]),
            "energy_optimized_surrogate_J": float(e_sur[1]),
        }
    from joulepath.sim import make_plant

    lab = make_plant("lab", robot)
    e_lab_def, e_lab_opt = _plant_energy(lab, default), _plant_energy(lab, optimized)
    summary: dict[str, Any] = {
        "robot": robot.name,
        "start_rad": q0.tolist(),
        "end_rad": qf.tolist(),
        "duration_s": duration,
        "algorithm": config.algorithm,
        "fitness": config.fitness,
        "parametrization": config.parametrization,
        "seed": config.seed,
        "chromosome": np.asarray(res.x_best).reshape(6, 6).tolist(),
        "energy_default_physics_J": float(e_def[0]),
        "energy_optimized_physics_J": float(e_opt[0]),
        "energy_optimized_surrogate_J": surrogate.get("energy_optimized_surrogate_J"),
        "energy_default_surrogate_J": surrogate.get("energy_default_surrogate_J"),
        "improvement_physics_pct": float(100 * (e_def[0] - e_opt[0]) / e_def[0]) if e_def[0] > 0 else 0.0,
        "improvement_vs_initial_best_pct": float(100 * (res.f_initial_best - res.f_best) / res.f_initial_best)
        if res.f_initial_best > 0
        else 0.0,
        "energy_default_lab_J": e_lab_def,
        "energy_optimized_lab_J": e_lab_opt,
        "improvement_lab_pct": float(100 * (e_lab_def - e_lab_opt) / e_lab_def)
        if e_lab_def and e_lab_opt is not None
        else None,
        "limits_ok": bool(viol.total[0] == 0.0),
        "limit_violation": {
            "range_rad": float(viol.range[0]),
            "overspeed": float(viol.speed[0]),
            "overtorque": float(viol.torque[0]),
        },
        "informed_joints": list(joints[:2]),
        "generations": int(res.n_gen),
        "evaluations": int(res.n_evals),
        "wall_s": wall,
        "physics_model": "nominal rigid body + NOMINAL_FRICTION; |tau*qd|*dt summed at dt = 0.025 s",
        "config": asdict(config),
    }
    return MoveResult(
        summary=summary,
        default=default,
        optimized=optimized,
        history=np.asarray(res.history),
        chromosome=np.asarray(res.x_best).reshape(6, 6),
    )


def _path_csv(traj: Trajectory) -> str:
    head = [
        "t",
        *(f"q{i}" for i in range(1, 7)),
        *(f"qd{i}" for i in range(1, 7)),
        *(f"qdd{i}" for i in range(1, 7)),
    ]
    data = np.column_stack([traj.t, traj.q, traj.qd, traj.qdd])
    return ",".join(head) + "\n" + "\n".join(",".join(f"{v:.10g}" for v in row) for row in data) + "\n"


def plot_run(result: MoveResult, robot: Robot, out: Path) -> list[Path]:
    """Joint positions, speeds, accelerations, joint power (default vs optimized), convergence."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    d, o = result.default, result.optimized
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    for ax, a, b, label in zip(
        axes, (d.q, d.qd, d.qdd), (o.q, o.qd, o.qdd), ("q [rad]", "qd [rad/s]", "qdd [rad/s²]"), strict=True
    ):
        for j in range(6):
            line = ax.plot(o.t, b[:, j], label=f"J{j + 1}")[0]
            ax.plot(d.t, a[:, j], "--", color=line.get_color(), alpha=0.6)
        ax.set_ylabel(label)
    axes[0].legend(ncol=6, fontsize=7, title="solid: optimized, dashed: default", title_fontsize=7)
    axes[-1].set_xlabel("t [s]")
    fig.tight_layout()
    paths.append(_save(fig, out / "joints.png"))
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for traj, style, name in ((d, "--", "default"), (o, "-", "optimized")):
        tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd)
        ax.plot(traj.t, np.abs(tau * traj.qd).sum(axis=1), style, label=name)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("Σ |τ·qd| [W]")
    ax.legend()
    fig.tight_layout()
    paths.append(_save(fig, out / "power.png"))
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(np.arange(result.history.size), result.history)
    ax.set_xlabel("generation")
    ax.set_ylabel("best fitness [J]")
    fig.tight_layout()
    paths.append(_save(fig, out / "convergence.png"))
    plt.close("all")
    return paths


def _save(fig: Any, path: Path) -> Path:
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=100)
    os.replace(tmp, path)
    return path


def write_run(
    result: MoveResult, robot: Robot, out_dir: str | os.PathLike[str], *, repeats: int = 5
) -> dict[str, Path]:
    """Write result.json, path.csv, convergence.csv, plots and — only when limits hold — path.mod."""
    from joulepath.export import path_module

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files = {}
    summary = dict(result.summary)
    if summary["limits_ok"]:
        text = path_module(
            robot, result.optimized.q, result.optimized.qd, summary["duration_s"], repeats=repeats
        )
        files["path.mod"] = atomic_write_text(out / "path.mod", text)
        summary["rapid"] = "path.mod"
    else:
        summary["rapid"] = None
        summary["rapid_refused"] = "the optimized path violates a joint limit; no RAPID program written"
    files["result.json"] = atomic_write_text(out / "result.json", json.dumps(summary, indent=2))
    files["path.csv"] = atomic_write_text(out / "path.csv", _path_csv(result.optimized))
    files["default_path.csv"] = atomic_write_text(out / "default_path.csv", _path_csv(result.default))
    conv = (
        "generation,best_fitness_J\n"
        + "\n".join(f"{k},{v:.10g}" for k, v in enumerate(result.history))
        + "\n"
    )
    files["convergence.csv"] = atomic_write_text(out / "convergence.csv", conv)
    for p in plot_run(result, robot, out):
        files[p.name] = p
    return files
