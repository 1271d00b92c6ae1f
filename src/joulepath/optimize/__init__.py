"""The energy-optimal trajectory optimizer: fitness problems, one-move optimization, benchmarks."""

from joulepath.optimize._bench import bench_optimizers, random_tasks, summarize_bench, thesis_configurations
from joulepath.optimize._features import path_features
from joulepath.optimize._problem import (
    FITNESS,
    PARAMETRIZATIONS,
    PENALTY,
    TrajectoryProblem,
    Violation,
    limit_violation,
    physics_energy,
)
from joulepath.optimize._run import (
    ALGORITHMS,
    MoveResult,
    OptimizeConfig,
    make_algorithm,
    optimize_move,
    rank_joints_by_energy,
    write_run,
)

__all__ = [
    "ALGORITHMS",
    "FITNESS",
    "MoveResult",
    "OptimizeConfig",
    "PARAMETRIZATIONS",
    "PENALTY",
    "TrajectoryProblem",
    "Violation",
    "bench_optimizers",
    "limit_violation",
    "make_algorithm",
    "optimize_move",
    "path_features",
    "physics_energy",
    "random_tasks",
    "rank_joints_by_energy",
    "summarize_bench",
    "thesis_configurations",
    "write_run",
]
