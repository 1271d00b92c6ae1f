"""The energy-optimal trajectory optimizer: fitness problems, one-move optimization, benchmarks."""

from joulepath.optimize._bench import (
    bench_optimizers,
    default_configuration,
    random_tasks,
    summarize_bench,
    thesis_configurations,
)
from joulepath.optimize._features import path_features
from joulepath.optimize._gradient import GradientResult, GradientSettings, SplineProblem, optimize_spline
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
    ACCEL_TIME,
    MAX_DURATION,
    RUN_FILES,
    MoveResult,
    MoveSummary,
    OptimizeConfig,
    acceleration_limit,
    check_default_feasible,
    optimize_move,
    rank_joints_by_energy,
    verify_move,
    write_run,
)
from joulepath.optimize._search import ALGORITHMS, AUTO, AlgorithmSpec, SearchOutcome, resolve_algorithm
from joulepath.optimize._verify import (
    FINE_FACTOR,
    LimitExcess,
    LimitReport,
    check_limits,
    shortest_feasible_duration,
)

__all__ = [
    "ACCEL_TIME",
    "ALGORITHMS",
    "AUTO",
    "AlgorithmSpec",
    "FINE_FACTOR",
    "FITNESS",
    "GradientResult",
    "GradientSettings",
    "LimitExcess",
    "LimitReport",
    "MAX_DURATION",
    "MoveResult",
    "MoveSummary",
    "OptimizeConfig",
    "PARAMETRIZATIONS",
    "PENALTY",
    "RUN_FILES",
    "SearchOutcome",
    "SplineProblem",
    "TrajectoryProblem",
    "Violation",
    "acceleration_limit",
    "bench_optimizers",
    "check_default_feasible",
    "check_limits",
    "default_configuration",
    "limit_violation",
    "optimize_move",
    "optimize_spline",
    "path_features",
    "physics_energy",
    "random_tasks",
    "rank_joints_by_energy",
    "resolve_algorithm",
    "shortest_feasible_duration",
    "summarize_bench",
    "thesis_configurations",
    "verify_move",
    "write_run",
]
