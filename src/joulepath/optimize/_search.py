"""The searches behind ``optimize_move``, one registry entry each.

* ``gradient`` — constrained SLSQP with exact derivatives over the rest-to-rest
  B-spline (physics fitness): :mod:`joulepath.optimize._gradient`;
* ``cmaes`` — pycma's CMA-ES over the same B-spline, derivative-free, for any
  fitness (the learned models included); limits by penalty during the search and a
  hard check of the result;
* ``ga``, ``de``, ``ma-random``, ``ma-informed`` — the thesis' evolutionary searches
  over its 36-coefficient chromosomes (:mod:`joulepath.evolve`).

Every search returns a :class:`SearchOutcome`: the path on the samples and on the
fine verification grid, the parameters, and its own record. Verification and
reporting are not its business. A search reads its settings through
:class:`SearchSettings`, which :class:`joulepath.optimize.OptimizeConfig` satisfies
(this module does not import the one that runs and writes an optimization).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.errors import InvalidInput, MissingDependency
from joulepath.evolve import DE, GA, MA, Termination, minimize
from joulepath.optimize._gradient import MOVE_SEARCH, SEARCH_BEFORE_HULL, GradientSettings, solve_move
from joulepath.optimize._problem import FINE_FACTOR, FITNESS, PENALTY, TrajectoryProblem, limit_violation
from joulepath.trajectory import SplineBasis, Trajectory, minimum_jerk, rest_to_rest, thesis_quintic

CMAES_KNOT_FACTOR = 4
"""CMA-ES searches knots this many times wider apart than ``knot_spacing`` (fewer variables)."""


@dataclass(frozen=True, slots=True)
class SearchOutcome:
    """What a search found: its path (samples and fine grid), parameters and record."""

    path: Trajectory
    fine_path: Trajectory
    parameters: FloatArray
    representation: str
    history: FloatArray
    iterations: int
    evaluations: int
    saved_vs_initial_best_pct: float | None


@dataclass(frozen=True, slots=True)
class SearchTask:
    """One move to search: robot, ends, duration, limits, fitness models, informed joints."""

    robot: Robot
    q_start: FloatArray
    q_end: FloatArray
    duration: float
    acceleration_limit: FloatArray
    models: tuple[Any, ...]
    joints: tuple[int, ...]
    dt: float
    jerk_limit: FloatArray | None = None


class SearchSettings(Protocol):
    """The settings a search reads (:class:`joulepath.optimize.OptimizeConfig` has them all)."""

    @property
    def fitness(self) -> str: ...
    @property
    def energy(self) -> str: ...
    @property
    def parametrization(self) -> str: ...
    @property
    def knot_spacing(self) -> float: ...
    @property
    def n_starts(self) -> int: ...
    @property
    def evaluations(self) -> int: ...
    @property
    def max_deviation_mm(self) -> float | None: ...
    @property
    def pop_size(self) -> int: ...
    @property
    def max_gen(self) -> int: ...
    @property
    def n_stagnant(self) -> int: ...
    @property
    def p_crossover(self) -> float: ...
    @property
    def p_mutation(self) -> float: ...
    @property
    def recombination(self) -> str: ...
    @property
    def F(self) -> float: ...  # the thesis' name of the DE weight
    @property
    def n_local(self) -> int: ...
    @property
    def inject_default(self) -> bool: ...
    @property
    def seed(self) -> int: ...
    @property
    def follow(self) -> str: ...


Search = Callable[["SearchTask", SearchSettings, np.random.Generator], SearchOutcome]


@dataclass(frozen=True, slots=True)
class AlgorithmSpec:
    """A registered search: its name, what it needs and does, and the function that runs it."""

    name: str
    kind: str
    fitness: tuple[str, ...]
    description: str
    run: Search


FAST_KNOT_FACTOR = 2
"""``gradient-fast`` searches knots this many times wider apart than ``knot_spacing``, on one level."""
VIA_KNOT_FACTOR = 2
"""A plan for RAPID via points searches knots this many times wider apart than ``knot_spacing``
(:func:`via_point_settings`)."""


def via_point_settings(config: SearchSettings) -> dict[str, Any]:
    """:class:`GradientSettings` overrides of the plan for RAPID via points (``follow="via-points"``).

    The controller plans its own motion through the written via points, so what counts is the
    saving of the module as the controller emulation runs it, not the plan's. The default search
    (hull rows, preconditioned) on knots ``VIA_KNOT_FACTOR`` times wider apart: measured on 14 tasks
    against the search before (``SEARCH_BEFORE_HULL``, fine-grid rows, on the 0.05 s knots), the executed
    saving on the planning model +0.36 ± 0.45 points (mean ± s.e.; the plans' own saving 0.55 points
    lower), on the lab robot as its servo tracks it -0.32 ± 0.20 points (lower on 11 of 14), for a
    twenty-fifth of the CPU (median 0.35 s against 8.3 s). The default search on the 0.05 s knots:
    -0.26 ± 0.37 and -0.04 ± 0.14 points in 0.87 s, but on the fixed task its chain of via points
    steps its accelerations harder (3.8 % executed on the model, 5.5 % here, 7.6 % before):
    ``benchmarks/via_point_search.py``, BENCHMARKS.md.
    """
    return {"knot_spacing": VIA_KNOT_FACTOR * config.knot_spacing}


def _gradient(task: SearchTask, config: SearchSettings, rng: np.random.Generator) -> SearchOutcome:
    if config.follow == "via-points":
        return _gradient_with(task, config, rng, via_point_settings(config))
    return _gradient_with(task, config, rng, MOVE_SEARCH)


def _gradient_fast(task: SearchTask, config: SearchSettings, rng: np.random.Generator) -> SearchOutcome:
    return _gradient_with(
        task,
        config,
        rng,
        {**MOVE_SEARCH, "knot_spacing": FAST_KNOT_FACTOR * config.knot_spacing, "coarse_factor": 1},
    )


def _gradient_grid(task: SearchTask, config: SearchSettings, rng: np.random.Generator) -> SearchOutcome:
    return _gradient_with(task, config, rng, SEARCH_BEFORE_HULL)


def _gradient_with(
    task: SearchTask, config: SearchSettings, rng: np.random.Generator, overrides: dict[str, Any]
) -> SearchOutcome:
    settings = GradientSettings(
        **{
            "knot_spacing": config.knot_spacing,
            "n_starts": config.n_starts,
            "check_factor": FINE_FACTOR,
            **overrides,
        }
    )
    res, problem = solve_move(
        task.robot,
        task.q_start,
        task.q_end,
        task.duration,
        friction=task.robot.friction,
        settings=settings,
        rng=rng,
        acceleration_limit=task.acceleration_limit,
        max_deviation_m=None if config.max_deviation_mm is None else config.max_deviation_mm / 1000.0,
        dt=task.dt,
        jerk_limit=task.jerk_limit,
        energy_measure=config.energy,
    )
    x = res.coefficients.ravel()
    return SearchOutcome(
        path=res.path,
        fine_path=problem.path(x, fine=True),
        parameters=res.coefficients,
        representation="bspline",
        history=res.history,
        iterations=res.n_iterations,
        evaluations=res.n_evaluations,
        saved_vs_initial_best_pct=None,
    )


def _fitness_problem(task: SearchTask, config: SearchSettings, parametrization: str) -> TrajectoryProblem:
    return TrajectoryProblem(
        robot=task.robot,
        q_start=task.q_start,
        q_end=task.q_end,
        duration=task.duration,
        fitness=config.fitness,
        models=task.models,
        parametrization=parametrization,
        dt=task.dt,
        acceleration_limit=task.acceleration_limit,
        jerk_limit=task.jerk_limit,
        energy_measure=config.energy,
    )


class _FineKinematics:
    """Range, speed, acceleration and jerk excess of spline paths on the grid results are checked on.

    The same relative measure as :func:`limit_violation` (range excess in rad, speed,
    acceleration and jerk excess as shares of the limit, worst instant per joint, summed
    over the joints), on a grid ``FINE_FACTOR`` times finer than the samples, the jerk as
    :func:`joulepath.optimize._verify.path_jerk` measures it there; linear in the
    coefficients, so it costs four matrix products per population.
    """

    def __init__(self, task: SearchTask, basis: SplineBasis) -> None:
        dt = task.dt / FINE_FACTOR
        self.grid = basis.grid(dt)
        self.base = minimum_jerk(task.q_start, task.q_end, task.duration, dt=dt)
        lo, hi = task.robot.joint_ranges()
        self.lo = np.where(np.isfinite(lo), lo, -np.inf)
        self.hi = np.where(np.isfinite(hi), hi, np.inf)
        vmax = np.asarray(task.robot.velocity_limit, dtype=float)
        self.v_inv = np.where(np.isfinite(vmax) & (vmax > 0), 1.0 / np.where(vmax > 0, vmax, 1.0), 0.0)
        amax = task.acceleration_limit
        a = np.full(vmax.shape, np.inf) if amax is None else np.asarray(amax, dtype=float)
        self.a_inv = np.where(np.isfinite(a) & (a > 0), 1.0 / np.where(a > 0, a, 1.0), 0.0)
        jmax = task.jerk_limit
        j = np.full(vmax.shape, np.inf) if jmax is None else np.asarray(jmax, dtype=float)
        self.j_inv = np.where(np.isfinite(j) & (j > 0), 1.0 / np.where(j > 0, j, 1.0), 0.0)
        self.has_jerk = bool(np.any(self.j_inv > 0))
        self.Bddd = np.diff(self.grid.Bdd, axis=0) / dt
        self.base_qddd = np.diff(self.base.qdd, axis=0) / dt

    def __call__(self, C: FloatArray) -> FloatArray:
        g, b = self.grid, self.base
        P, m, n = C.shape
        flat = C.transpose(1, 0, 2).reshape(m, P * n)  # one product per matrix, time along rows

        def extremes(M: FloatArray, base: FloatArray) -> tuple[FloatArray, FloatArray]:
            x = (M @ flat).reshape(-1, P, n) + base[:, None, :]
            return x.max(axis=0), x.min(axis=0)

        q_hi, q_lo = extremes(g.B, b.q)
        over = np.maximum(np.maximum(q_hi - self.hi, self.lo - q_lo), 0.0)
        v_hi, v_lo = extremes(g.Bd, b.qd)
        a_hi, a_lo = extremes(g.Bdd, b.qdd)
        speed = np.maximum(v_hi, -v_lo) * self.v_inv
        accel = np.maximum(a_hi, -a_lo) * self.a_inv
        out: FloatArray = (
            over.sum(axis=1)
            + np.maximum(speed - 1.0, 0.0).sum(axis=1)
            + np.maximum(accel - 1.0, 0.0).sum(axis=1)
        )
        if self.has_jerk:
            j_hi, j_lo = extremes(self.Bddd, self.base_qddd)
            jerk = np.maximum(j_hi, -j_lo) * self.j_inv
            out = out + np.maximum(jerk - 1.0, 0.0).sum(axis=1)
        return out


def _cmaes(task: SearchTask, config: SearchSettings, rng: np.random.Generator) -> SearchOutcome:
    try:
        import cma
    except ImportError as err:  # pragma: no cover - cma is a core dependency
        raise MissingDependency("the cmaes search needs pycma: pip install cma") from err
    basis = SplineBasis(task.duration, knot_spacing=CMAES_KNOT_FACTOR * config.knot_spacing, dt=task.dt)
    fit = _fitness_problem(task, config, "rest_to_rest")
    m, n = basis.n_free, task.robot.n_joints
    travel = float(np.max(np.abs(task.q_end - task.q_start)))
    sigma0 = max(0.02, 0.05 * travel)
    history: list[float] = []

    # ranges, speeds and accelerations are linear in the coefficients: penalize them on the
    # grid the result is checked on (FINE_FACTOR x finer than the samples), not only on the
    # samples, so that a path cannot pass between samples over a limit
    between = _FineKinematics(task, basis)

    def evaluate(X: FloatArray) -> FloatArray:
        C = X.reshape(-1, m, n)
        traj = basis.trajectory(C, task.q_start, task.q_end)
        energy, tau = fit.energy(traj)
        viol = limit_violation(
            task.robot, traj, tau, acceleration_limit=task.acceleration_limit, jerk_limit=task.jerk_limit
        )
        out: FloatArray = energy + PENALTY * (viol.total + between(C))
        return out

    f0 = float(evaluate(np.zeros((1, m * n)))[0])
    history.append(f0)
    es = cma.CMAEvolutionStrategy(
        np.zeros(m * n),
        sigma0,
        {
            "seed": int(rng.integers(1, 2**31 - 1)),
            "maxfevals": config.evaluations,
            "verbose": -9,
            "tolfun": 1e-9,
            "tolx": 1e-9,
        },
    )
    best_x, best_f = np.zeros(m * n), f0
    n_gen = 0
    while not es.stop():
        X = np.asarray(es.ask())
        F = evaluate(X)
        es.tell(list(X), F.tolist())
        n_gen += 1
        k = int(np.argmin(F))
        if F[k] < best_f:
            best_x, best_f = X[k].copy(), float(F[k])
        history.append(best_f)
    C = best_x.reshape(m, n)
    return SearchOutcome(
        path=basis.trajectory(C, task.q_start, task.q_end),
        fine_path=basis.trajectory(C, task.q_start, task.q_end, dt=task.dt / FINE_FACTOR),
        parameters=C,
        representation="bspline",
        history=np.asarray(history),
        iterations=n_gen,
        evaluations=int(es.countevals) + 1,
        saved_vs_initial_best_pct=None,
    )


def _evolutionary(name: str) -> Search:
    def run(task: SearchTask, config: SearchSettings, rng: np.random.Generator) -> SearchOutcome:
        ga = GA(
            pop_size=config.pop_size,
            p_crossover=config.p_crossover,
            p_mutation=config.p_mutation,
            recombination=config.recombination,
            F=config.F,
        )
        algorithm: GA | DE | MA
        if name == "ga":
            algorithm = ga
        elif name == "de":
            algorithm = DE(pop_size=config.pop_size)
        elif name == "ma-random":
            algorithm = MA(base=ga, local_search="random", n_samples=config.n_local)
        else:
            algorithm = MA(base=ga, local_search="informed", joints=tuple(j - 1 for j in task.joints[:2]))
        problem = _fitness_problem(task, config, config.parametrization)
        n_var = problem.n_var
        initial = (
            np.zeros((1, n_var))
            if config.inject_default and config.parametrization == "rest_to_rest"
            else None
        )
        res = minimize(
            problem,
            algorithm,
            Termination(n_max_gen=config.max_gen, n_stagnant=config.n_stagnant),
            seed=config.seed,
            initial=initial,
        )
        chrom = np.asarray(res.x_best).reshape(task.robot.n_joints, -1)
        build = rest_to_rest if config.parametrization == "rest_to_rest" else thesis_quintic
        path = build(chrom, task.q_start, task.q_end, task.duration, dt=task.dt)
        fine = build(chrom, task.q_start, task.q_end, task.duration, dt=task.dt / FINE_FACTOR)
        vs_initial = (
            float(100 * (res.f_initial_best - res.f_best) / res.f_initial_best)
            if res.f_initial_best > 0
            else 0.0
        )
        return SearchOutcome(
            path=path,
            fine_path=fine,
            parameters=chrom,
            representation=config.parametrization,
            history=np.asarray(res.history),
            iterations=int(res.n_gen),
            evaluations=int(res.n_evals),
            saved_vs_initial_best_pct=vs_initial,
        )

    return run


ALL_FITNESS = FITNESS

ALGORITHMS: dict[str, AlgorithmSpec] = {
    spec.name: spec
    for spec in (
        AlgorithmSpec(
            "gradient",
            "gradient",
            ("physics",),
            "SLSQP with exact RNEA derivatives over a rest-to-rest B-spline, limits as constraints",
            _gradient,
        ),
        AlgorithmSpec(
            "cmaes",
            "evolution strategy",
            ALL_FITNESS,
            "pycma CMA-ES over the same B-spline (any fitness, learned models included)",
            _cmaes,
        ),
        AlgorithmSpec(
            "ga", "evolutionary", ALL_FITNESS, "the thesis' genetic algorithm", _evolutionary("ga")
        ),
        AlgorithmSpec(
            "de", "evolutionary", ALL_FITNESS, "differential evolution rand/1/bin", _evolutionary("de")
        ),
        AlgorithmSpec(
            "ma-random",
            "evolutionary",
            ALL_FITNESS,
            "memetic GA, random local search",
            _evolutionary("ma-random"),
        ),
        AlgorithmSpec(
            "ma-informed",
            "evolutionary",
            ALL_FITNESS,
            "memetic GA, local search on the most influential joints",
            _evolutionary("ma-informed"),
        ),
        AlgorithmSpec(
            "gradient-fast",
            "gradient",
            ("physics",),
            "the gradient search on knots twice as wide, without the refinement on the fine knots: "
            "for interactive use, about half the time for a few points less saving (BENCHMARKS.md)",
            _gradient_fast,
        ),
        AlgorithmSpec(
            "gradient-grid",
            "gradient",
            ("physics",),
            "the gradient search before the hull rows: acceleration and jerk limits on every point of "
            "the fine grid (slower; the yardstick of benchmarks/optimizer_speed.py)",
            _gradient_grid,
        ),
    )
}
"""Every search ``optimize_move`` can run, by name (the CLI, experiment files and bench read it)."""

AUTO = "auto"
"""The default: ``gradient`` on the physics fitness, ``cmaes`` on a learned model."""


def resolve_algorithm(name: str, fitness: str) -> AlgorithmSpec:
    """The search for ``name`` (``auto`` picks by fitness); refuses a search that cannot use the fitness."""
    if name == AUTO:
        name = "gradient" if fitness == "physics" else "cmaes"
    spec = ALGORITHMS.get(name)
    if spec is None:
        raise InvalidInput(f"algorithm must be one of {AUTO}, {', '.join(ALGORITHMS)}, got {name!r}")
    if fitness not in spec.fitness:
        raise InvalidInput(
            f"algorithm {name!r} needs fitness {' or '.join(spec.fitness)}, got {fitness!r}; "
            "use --algo cmaes (or auto) with a learned model"
        )
    return spec


def timed(
    run: Search, task: SearchTask, config: SearchSettings, rng: np.random.Generator
) -> tuple[SearchOutcome, float]:
    """Run a search and measure its wall time (s).

    BLAS runs on one thread during the search: its many small matrix products are
    several times faster so than on a thread pool that competes for the same cores.
    """
    from threadpoolctl import threadpool_limits

    t0 = time.perf_counter()
    with threadpool_limits(limits=1, user_api="blas"):
        out = run(task, config, rng)
    return out, time.perf_counter() - t0
