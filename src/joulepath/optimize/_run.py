"""Optimize one move: search, verify on physics, and write the run folder."""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._io import atomic_write_text, finite_json, make_folder, remove_output, save_figure
from joulepath._typing import FloatArray
from joulepath.dynamics import Robot
from joulepath.energy import (
    DEFAULT_MEASURE,
    MEASURES,
    check_measure,
    energy_measure,
    joint_power,
    path_energy,
)
from joulepath.errors import InvalidInput, InvalidModel, LimitViolation
from joulepath.optimize._figures import (
    RESULT_DEPRECATED,
    EnergyPair,
    figures_json,
    headline_keys,
    lab_pair,
)
from joulepath.optimize._problem import FITNESS, PARAMETRIZATIONS, TrajectoryProblem
from joulepath.optimize._search import (
    AUTO,
    AlgorithmSpec,
    SearchOutcome,
    SearchTask,
    resolve_algorithm,
    timed,
)
from joulepath.optimize._verify import (
    check_limits,
    default_fine,
    measured_energy,
    path_jerk,
    plant_energy,
    plant_measured,
    shortest_feasible_duration,
    tcp_deviation_mm,
)
from joulepath.sim import ACCEL_TIME, JERK_TIME, acceleration_limit, jerk_limit
from joulepath.trajectory import DEFAULT_KNOT_SPACING, Trajectory, minimum_jerk, sample_times
from joulepath.units import SAMPLE_PERIOD

FOLLOW = ("samples", "via-points")
"""How a program's controller runs a path (:attr:`joulepath.export.Exporter.follows`)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class OptimizeConfig:
    """Settings of one optimization.

    ``algorithm`` is a name of :data:`ALGORITHMS` or ``"auto"`` (default): the
    constrained gradient search on the physics fitness, CMA-ES on a learned model.
    ``knot_spacing``, ``n_starts`` and ``evaluations`` set the B-spline searches;
    ``pop_size`` … ``informed_joints`` the thesis' evolutionary ones (defaults: its
    best GA settings, §4.5). ``accel_time`` sets the acceleration limits
    (``v_max / accel_time``; 0 disables them) and ``jerk_time`` the jerk limits
    (``v_max / accel_time / jerk_time``; 0 disables them, as does ``accel_time = 0``):
    the emulated controller's, :mod:`joulepath.sim` (defaults ``ACCEL_TIME``, ``JERK_TIME``).
    ``max_deviation_mm`` keeps the TCP within that distance of the default move's TCP
    at every sample (gradient search).

    ``inject_default`` puts the all-zero chromosome (the minimum-jerk default path of
    ``rest_to_rest``) into the initial population of the evolutionary searches, so
    they never return a path their fitness rates worse than the default; the thesis'
    protocol (and ``bench-optimizers``) starts from random chromosomes only.

    ``energy`` is the energy measure minimized and reported first (a name of
    :data:`joulepath.energy.MEASURES`: ``thesis``, ``mechanical`` or ``electrical``);
    every other measure the robot has the data for is reported too.

    ``follow`` is how the program's controller runs the path (:attr:`Exporter.follows`):
    ``"samples"`` (servoj, a JointTrajectory, EGM) follows the samples, so the path may use
    the whole acceleration limit; ``"via-points"`` (RAPID ``MoveAbsJ`` via points) plans
    the controller's own ramps from and to rest through them, so the path is planned within
    :data:`joulepath.sim.RAPID_ACCEL_SHARE` of the acceleration limit, the share whose
    first and last via segments fit the controller's ramp.
    """

    algorithm: str = AUTO
    fitness: str = "physics"
    parametrization: str = "rest_to_rest"
    knot_spacing: float = DEFAULT_KNOT_SPACING
    n_starts: int = 1
    evaluations: int = 6000
    accel_time: float = ACCEL_TIME
    jerk_time: float = JERK_TIME
    max_deviation_mm: float | None = None
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
    follow: str = "samples"
    energy: str = DEFAULT_MEASURE

    def __post_init__(self) -> None:
        if self.fitness not in FITNESS:
            raise InvalidInput(f"fitness must be one of {', '.join(FITNESS)}, got {self.fitness!r}")
        energy_measure(self.energy)
        if self.energy != DEFAULT_MEASURE and self.fitness != "physics":
            raise InvalidInput(
                f"energy {self.energy!r} needs fitness 'physics': the learned models predict the thesis' "
                "energy; drop --energy, or use --fitness physics"
            )
        resolve_algorithm(self.algorithm, self.fitness)
        if self.parametrization not in PARAMETRIZATIONS:
            raise InvalidInput(
                f"parametrization must be one of {PARAMETRIZATIONS}, got {self.parametrization!r}"
            )
        if self.follow not in FOLLOW:
            raise InvalidInput(f"follow must be one of {', '.join(FOLLOW)}, got {self.follow!r}")
        if self.pop_size < 4 or self.max_gen < 1:
            raise InvalidInput("pop_size must be ≥ 4 and max_gen ≥ 1")
        if not (np.isfinite(self.knot_spacing) and 0.02 <= self.knot_spacing <= 1.0):
            raise InvalidInput(f"knot_spacing must be 0.02..1 s, got {self.knot_spacing}")
        if not 1 <= self.n_starts <= 50 or not 10 <= self.evaluations <= 10_000_000:
            raise InvalidInput("n_starts must be 1..50 and evaluations 10..10,000,000")
        if not (np.isfinite(self.accel_time) and 0 <= self.accel_time <= 10):
            raise InvalidInput(
                f"accel_time must be 0..10 s (0: no acceleration limit), got {self.accel_time}"
            )
        if not (np.isfinite(self.jerk_time) and 0 <= self.jerk_time <= 10):
            raise InvalidInput(f"jerk_time must be 0..10 s (0: no jerk limit), got {self.jerk_time}")
        if self.max_deviation_mm is not None and not (
            np.isfinite(self.max_deviation_mm) and self.max_deviation_mm > 0
        ):
            raise InvalidInput(
                f"max_deviation_mm must be a positive number of mm, got {self.max_deviation_mm}"
            )
        if any(not 1 <= j for j in self.informed_joints):
            raise InvalidInput(f"informed_joints are joint numbers 1..n, got {self.informed_joints}")

    @property
    def search(self) -> AlgorithmSpec:
        """The registered search this configuration runs."""
        return resolve_algorithm(self.algorithm, self.fitness)


@dataclass(frozen=True, slots=True)
class MeasureSummary:
    """One energy measure of a move (J): default and optimized path, on the model and on the lab plant.

    ``stage`` is where the measure is taken (:data:`joulepath.energy.STAGES`); ``source``
    and ``lab_source`` say where the data beyond the joint come from (the gears, the
    drives). ``standby_J`` is the standby energy over the move's duration, included in
    every figure of a measure that counts it (the same for both paths).
    """

    measure: str
    stage: str
    source: str
    default_J: float
    optimized_J: float
    saved_pct: float
    standby_J: float
    lab_default_J: float | None
    lab_optimized_J: float | None
    lab_saved_pct: float | None
    lab_source: str


def _saved(before: float, after: float) -> float:
    return 100 * (before - after) / before if before > 0 else 0.0


@dataclass(frozen=True, slots=True)
class MoveSummary:
    """Everything measured about one optimized move (``result.json``, one key per field).

    Energies ``energy_*_J`` are on the measure ``energy_measure`` (the one optimized;
    default ``thesis``: ``Σ |tau qd| dt``; with ``electrical`` the standby over the
    move's duration is included) on the physics model (nominal rigid body and the
    robot's friction, :attr:`Robot.friction`; ``physics_model`` says which) at the 25 ms
    samples; ``*_fine_J`` is the same on a grid ten
    times finer (the integral the samples approximate). ``saved_pct`` compares the
    optimized path with the controller-like minimum-jerk move of the same duration.
    ``energy_*_lab_J`` are the lab plant's on ``energy_lab_measure`` (``mechanical``:
    its drive torque, gears included, times speed: what its torque log integrates to);
    they and ``energy_*_J`` are deprecated in ``result.json``, where the headline keys
    ``planned_*``, ``lab_*`` and ``executed_*`` and the block ``energy_figures`` pair each
    stage's figures on ``energy_measure`` (:meth:`to_json`, :mod:`joulepath.optimize._figures`).
    ``energies`` holds every measure the robot has the data for
    (:class:`MeasureSummary`: model and lab, like for like), ``energies_unavailable``
    why each other one is not computed.
    Limits are checked on the fine grid. ``saved_vs_initial_best_pct`` is the thesis'
    metric (evolutionary searches only). ``jerk_limit_rad_s3`` is the jerk limit the
    search and the check used (None: none), ``max_jerk_rad_s3`` the optimized path's
    largest jerk on the fine grid (:func:`joulepath.optimize._verify.path_jerk`, any joint).
    ``surrogate_outside_range_pct``: with learned models, the share of the optimized path's
    samples outside their training data (:func:`outside_training_range_pct`; their energies
    there are extrapolations), None without models or without a range on their cards.
    """

    robot: str
    start_rad: tuple[float, ...]
    end_rad: tuple[float, ...]
    duration_s: float
    algorithm: str
    fitness: str
    representation: str
    seed: int
    energy_default_J: float
    energy_optimized_J: float
    saved_pct: float
    energy_default_fine_J: float
    energy_optimized_fine_J: float
    energy_default_surrogate_J: float | None
    energy_optimized_surrogate_J: float | None
    saved_vs_initial_best_pct: float | None
    energy_default_lab_J: float | None
    energy_optimized_lab_J: float | None
    saved_lab_pct: float | None
    limits_ok: bool
    limit_violation: dict[str, float]
    limit_excess: tuple[str, ...]
    acceleration_limit_rad_s2: tuple[float, ...] | None
    jerk_limit_rad_s3: tuple[float, ...] | None
    max_jerk_rad_s3: float
    max_tcp_deviation_mm: float
    max_deviation_mm: float | None
    iterations: int
    evaluations: int
    wall_s: float
    physics_model: str
    config: dict[str, Any]
    lab_plant: str = ""
    energy_measure: str = DEFAULT_MEASURE
    energy_lab_measure: str = "mechanical"
    energies: tuple[MeasureSummary, ...] = ()
    energies_unavailable: dict[str, str] = field(default_factory=dict)
    surrogate_outside_range_pct: float | None = None

    def measure(self, name: str) -> MeasureSummary | None:
        """The summary of measure ``name``, or None when it was not computed."""
        return next((m for m in self.energies if m.measure == name), None)

    def energy_pairs(self) -> tuple[EnergyPair, EnergyPair]:
        """The planned and the lab stage's energies, both on ``energy_measure`` (see :mod:`._figures`)."""
        planned = EnergyPair(
            stage="planned",
            measure=self.energy_measure,
            on=self.physics_model,
            default_J=self.energy_default_J,
            optimized_J=self.energy_optimized_J,
        )
        return planned, lab_pair(self.energy_measure, self.energies, on=self.lab_plant or "the lab robot")

    def to_json(self, executed: EnergyPair | None = None) -> dict[str, Any]:
        """Plain JSON types; non-finite numbers become ``null`` (strict JSON); ``energies`` by measure.

        Adds the headline keys ``planned_*``, ``lab_*`` (and ``executed_*`` with ``executed``),
        all on ``energy_measure``, the ``energy_figures`` block and ``deprecated_keys``.
        """
        out: dict[str, Any] = finite_json(asdict(self))
        out["energies"] = {m["measure"]: m for m in out["energies"]}
        pairs = (*self.energy_pairs(), *(() if executed is None else (executed,)))
        out.update(finite_json(headline_keys(pairs)))
        out["energy_figures"] = finite_json(figures_json(self.energy_measure, pairs))
        out["deprecated_keys"] = dict(RESULT_DEPRECATED)
        return out


def outside_training_range_pct(models: Sequence[Any], path: Trajectory) -> float | None:
    """Share (%) of ``path``'s samples outside the training data of any of ``models``.

    A sample is outside when :meth:`joulepath.learn.EnergyModel.outside_training_range`
    flags it for one of the models (a position, speed or acceleration beyond the trained
    range, or a move longer or shorter than every trained one): the learned energy there is
    an extrapolation. None when no model carries a training range on its card.
    """
    import pandas as pd

    flagged = [m for m in models if isinstance(getattr(m, "card", {}).get("training_range"), dict)]
    if not flagged:
        return None
    n = path.q.shape[1]
    frame = pd.DataFrame({"move_id": np.zeros(path.t.size, dtype=np.int64), "t": path.t})
    for i in range(n):
        frame[f"q{i + 1}"], frame[f"dq{i + 1}"], frame[f"ddq{i + 1}"] = (
            path.q[:, i],
            path.qd[:, i],
            path.qdd[:, i],
        )
    outside = np.zeros(path.t.size, dtype=bool)
    for m in flagged:
        outside |= m.outside_training_range(frame)
    return 100.0 * float(outside.mean())


@dataclass(frozen=True, slots=True)
class MoveResult:
    """An optimized move, verified on the physics model (and the lab plant)."""

    summary: MoveSummary
    default: Trajectory
    optimized: Trajectory
    history: FloatArray
    parameters: FloatArray


def rank_joints_by_energy(robot: Robot, path: Trajectory) -> tuple[int, ...]:
    """Joints (1-based) ordered by their share of a path's physics energy (most first)."""
    tau = robot.inverse_dynamics(path.q, path.qd, path.qdd)
    per_joint = path_energy(tau, path.qd, path.dt).per_joint
    return tuple(int(j) + 1 for j in np.argsort(-per_joint))


MAX_DURATION = 60.0
"""Longest move :func:`optimize_move` accepts, s (2,400 samples at 40 Hz)."""


def _check_ends(robot: Robot, q0: FloatArray, qf: FloatArray, duration: float) -> None:
    lo, hi = robot.joint_ranges()
    for name, q in (("start", q0), ("end", qf)):
        if q.shape != (robot.n_joints,):
            raise InvalidInput(f"{name} needs {robot.n_joints} joint values, got {q.shape}")
        if not np.all(np.isfinite(q)):
            raise InvalidInput(f"{name} holds a value that is not a finite number: {q.tolist()}")
        bad = np.nonzero((q < lo) | (q > hi))[0]
        if bad.size:
            j = int(bad[0])
            raise LimitViolation(
                f"{name} joint {j + 1} = {np.degrees(q[j]):.2f} deg is outside its range "
                f"[{np.degrees(lo[j]):.1f}, {np.degrees(hi[j]):.1f}] deg; "
                f"move the {name} configuration inside the range"
            )
    if not (np.isfinite(duration) and duration > 0):
        raise InvalidInput(f"duration must be a positive number of seconds, got {duration}")
    if duration > MAX_DURATION:
        raise InvalidInput(
            f"duration {duration:g} s is longer than {MAX_DURATION:g} s; give the move's duration in "
            "seconds (a point-to-point move of an industrial arm takes well under a minute)"
        )
    if np.allclose(q0, qf, rtol=0.0, atol=1e-9):
        raise InvalidInput("start and end are the same configuration: there is no move to optimize")


def check_default_feasible(
    robot: Robot,
    q0: FloatArray,
    qf: FloatArray,
    duration: float,
    *,
    accel_time: float = ACCEL_TIME,
    jerk_time: float = JERK_TIME,
) -> None:
    """Refuse a move whose default (minimum-jerk) path already breaks a limit.

    The message names the joint, the limit and the excess, and the shortest duration
    whose default move respects every limit.
    """
    dt = SAMPLE_PERIOD
    amax = acceleration_limit(robot, accel_time)
    jmax = jerk_limit(robot, accel_time, jerk_time)
    report = check_limits(
        robot,
        default_fine(q0, qf, duration, dt),
        friction=robot.friction,
        acceleration_limit=amax,
        jerk_limit=jmax,
    )
    if report.ok:
        return
    shortest = shortest_feasible_duration(
        robot,
        q0,
        qf,
        dt=dt,
        friction=robot.friction,
        acceleration_limit=amax,
        jerk_limit=jmax,
        longest=MAX_DURATION,
    )
    hint = (
        f"the shortest duration whose default move respects every limit is {shortest:.3f} s: "
        f"give a duration of at least {shortest:.3f} s"
        if shortest is not None
        else f"no duration up to {MAX_DURATION:g} s makes it feasible"
    )
    raise LimitViolation(
        f"infeasible task: in {duration:g} s the default move already breaks a limit: "
        f"{report.worst[0].describe()}; {hint}"
    )


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

    Refuses a task whose default move already breaks a limit (``LimitViolation``).
    Runs the configured search, then verifies its result independently
    (:func:`verify_move`): physics energy against the default path, the fine-grid
    limit check, the emulated lab robot, the TCP deviation.
    """
    q0 = np.asarray(q_start, dtype=float)
    qf = np.asarray(q_end, dtype=float)
    check_measure(config.energy, robot.drivetrain)  # one line saying what to provide
    _check_ends(robot, q0, qf, duration)
    sample_times(duration, SAMPLE_PERIOD)
    check_default_feasible(robot, q0, qf, duration, accel_time=config.accel_time, jerk_time=config.jerk_time)
    default = minimum_jerk(q0, qf, duration)
    if any(j > robot.n_joints for j in config.informed_joints):
        raise InvalidInput(
            f"informed_joints are joint numbers 1..{robot.n_joints} for {robot.name}, "
            f"got {config.informed_joints}"
        )
    joints = tuple(config.informed_joints) or joints_ranked or rank_joints_by_energy(robot, default)
    amax = acceleration_limit(robot, config.accel_time)
    if amax is not None and config.follow == "via-points":
        from joulepath.sim import RAPID_ACCEL_SHARE

        amax = amax * RAPID_ACCEL_SHARE
    task = SearchTask(
        robot=robot,
        q_start=q0,
        q_end=qf,
        duration=duration,
        acceleration_limit=amax if amax is not None else np.full(robot.n_joints, np.inf),
        models=models,
        joints=joints,
        dt=SAMPLE_PERIOD,
        jerk_limit=jerk_limit(robot, config.accel_time, config.jerk_time),
    )
    spec = config.search
    outcome, wall = timed(spec.run, task, config, np.random.default_rng(config.seed))
    return verify_move(robot, task, default, outcome, config, spec.name, wall)


def verify_move(
    robot: Robot,
    task: SearchTask,
    default: Trajectory,
    outcome: SearchOutcome,
    config: OptimizeConfig,
    algorithm: str,
    wall: float,
) -> MoveResult:
    """Measure a search's result: physics energy, fine-grid limits, lab plant, TCP deviation."""
    optimized = outcome.path
    amax = None if not np.all(np.isfinite(task.acceleration_limit)) else task.acceleration_limit
    friction = robot.friction
    fine_def = default_fine(task.q_start, task.q_end, task.duration, task.dt)
    measure = config.energy
    e_def, e_opt, e_def_fine, e_opt_fine = (
        measured_energy(robot, path, friction=friction, measure=measure).total_J
        for path in (default, optimized, fine_def, outcome.fine_path)
    )
    jmax = task.jerk_limit
    report = check_limits(
        robot, outcome.fine_path, friction=friction, acceleration_limit=amax, jerk_limit=jmax
    )
    e_sur_def = e_sur_opt = outside_pct = None
    if task.models:
        stack = Trajectory(
            t=default.t,
            q=np.stack([default.q, optimized.q]),
            qd=np.stack([default.qd, optimized.qd]),
            qdd=np.stack([default.qdd, optimized.qdd]),
        )
        fit = TrajectoryProblem(
            robot=robot,
            q_start=task.q_start,
            q_end=task.q_end,
            duration=task.duration,
            fitness=config.fitness,
            models=task.models,
        )
        e_sur, _ = fit.energy(stack)
        if not np.all(np.isfinite(e_sur)):
            raise InvalidModel(
                "the learned model predicts a non-finite energy for this move; retrain it or use "
                "--fitness physics"
            )
        e_sur_def, e_sur_opt = float(e_sur[0]), float(e_sur[1])
        outside_pct = outside_training_range_pct(task.models, optimized)
    from joulepath.sim import make_plant

    lab = make_plant("lab", robot)  # a twin: the lab robot it twins
    e_lab_def, e_lab_opt = plant_energy(lab, default), plant_energy(lab, optimized)
    energies, unavailable = measure_summaries(robot, lab, default, optimized)
    summary = MoveSummary(
        robot=robot.name,
        start_rad=tuple(float(v) for v in task.q_start),
        end_rad=tuple(float(v) for v in task.q_end),
        duration_s=float(task.duration),
        algorithm=algorithm,
        fitness=config.fitness,
        representation=outcome.representation,
        seed=config.seed,
        energy_default_J=e_def,
        energy_optimized_J=e_opt,
        saved_pct=100 * (e_def - e_opt) / e_def if e_def > 0 else 0.0,
        energy_default_fine_J=e_def_fine,
        energy_optimized_fine_J=e_opt_fine,
        energy_default_surrogate_J=e_sur_def,
        energy_optimized_surrogate_J=e_sur_opt,
        saved_vs_initial_best_pct=outcome.saved_vs_initial_best_pct,
        energy_default_lab_J=e_lab_def,
        energy_optimized_lab_J=e_lab_opt,
        saved_lab_pct=100 * (e_lab_def - e_lab_opt) / e_lab_def if e_lab_def > 0 else None,
        limits_ok=report.ok,
        limit_violation={
            "range_rad": report.range_rad,
            "overspeed": report.overspeed,
            "overtorque": report.overtorque,
        },
        limit_excess=tuple(w.describe() for w in report.worst),
        acceleration_limit_rad_s2=None if amax is None else tuple(float(a) for a in amax),
        jerk_limit_rad_s3=None if jmax is None else tuple(float(j) for j in jmax),
        max_jerk_rad_s3=float(np.abs(path_jerk(outcome.fine_path)[1]).max(initial=0.0)),
        max_tcp_deviation_mm=tcp_deviation_mm(robot, optimized, default),
        max_deviation_mm=config.max_deviation_mm,
        iterations=outcome.iterations,
        evaluations=outcome.evaluations,
        wall_s=wall,
        physics_model=_physics_model(robot),
        config=asdict(config),
        lab_plant=lab.note,
        energy_measure=measure,
        energies=energies,
        energies_unavailable=unavailable,
        surrogate_outside_range_pct=outside_pct,
    )
    return MoveResult(
        summary=summary,
        default=default,
        optimized=optimized,
        history=np.asarray(outcome.history),
        parameters=np.asarray(outcome.parameters),
    )


def measure_summaries(
    robot: Robot, lab: Any, default: Trajectory, optimized: Trajectory
) -> tuple[tuple[MeasureSummary, ...], dict[str, str]]:
    """Each measure the robot has the data for, on its model and the lab plant; why not, for the rest.

    Model and lab are measured alike: the model's joint torque through the robot's
    gears and drives (:attr:`Robot.drivetrain`; a twin's identified gear efficiency),
    the lab plant's through its own gears and the same drives.
    """
    out: list[MeasureSummary] = []
    unavailable: dict[str, str] = {}
    for name, spec in MEASURES.items():
        why = spec.missing(robot.drivetrain)
        if why is not None:
            unavailable[name] = why
            continue
        d, o = (
            measured_energy(robot, p, friction=robot.friction, measure=name) for p in (default, optimized)
        )
        lab_ok = spec.missing(lab.drivetrain) is None
        ld, lo = (
            (plant_measured(lab, p, measure=name) for p in (default, optimized)) if lab_ok else (None, None)
        )
        out.append(
            MeasureSummary(
                measure=name,
                stage=spec.stage,
                source=d.source,
                default_J=d.total_J,
                optimized_J=o.total_J,
                saved_pct=_saved(d.total_J, o.total_J),
                standby_J=d.standby_J,
                lab_default_J=None if ld is None else ld.total_J,
                lab_optimized_J=None if lo is None else lo.total_J,
                lab_saved_pct=None if ld is None or lo is None else _saved(ld.total_J, lo.total_J),
                lab_source=ld.source if ld is not None else str(spec.missing(lab.drivetrain)),
            )
        )
    return tuple(out), unavailable


def _physics_model(robot: Robot) -> str:
    """The physics model in words, for ``result.json``."""
    if robot.calibration is not None:
        return (
            f"identified twin of {robot.calibration.twin_of} (rigid body + identified friction, "
            "joint side); |tau*qd|*dt summed at dt = 0.025 s"
        )
    if robot.friction is None:
        return (
            f"nominal rigid body only, no friction (friction: {robot.friction_note}); "
            "|tau*qd|*dt at dt = 0.025 s"
        )
    if robot.friction_note.startswith("NOMINAL_FRICTION"):
        return "nominal rigid body + NOMINAL_FRICTION; |tau*qd|*dt summed at dt = 0.025 s"
    return f"nominal rigid body + {robot.friction_note}; |tau*qd|*dt summed at dt = 0.025 s"


def _path_csv(traj: Trajectory) -> str:
    n = traj.q.shape[-1]
    head = [
        "t",
        *(f"q{i}" for i in range(1, n + 1)),
        *(f"qd{i}" for i in range(1, n + 1)),
        *(f"qdd{i}" for i in range(1, n + 1)),
    ]
    data = np.column_stack([traj.t, traj.q, traj.qd, traj.qdd])
    return ",".join(head) + "\n" + "\n".join(",".join(f"{v:.10g}" for v in row) for row in data) + "\n"


def plot_run(result: MoveResult, robot: Robot, out: Path) -> list[Path]:
    """Joint positions, speeds, accelerations, joint power (default vs optimized), convergence."""
    from matplotlib.figure import Figure

    paths = []
    d, o = result.default, result.optimized
    n = robot.n_joints
    fig = Figure(figsize=(8, 8))
    axes = fig.subplots(3, 1, sharex=True)
    for ax, a, b, label in zip(
        axes, (d.q, d.qd, d.qdd), (o.q, o.qd, o.qdd), ("q [rad]", "qd [rad/s]", "qdd [rad/s²]"), strict=True
    ):
        for j in range(n):
            line = ax.plot(o.t, b[:, j], label=f"J{j + 1}")[0]
            ax.plot(d.t, a[:, j], "--", color=line.get_color(), alpha=0.6)
        ax.set_ylabel(label)
    axes[0].legend(ncol=n, fontsize=7, title="solid: optimized, dashed: default", title_fontsize=7)
    axes[-1].set_xlabel("t [s]")
    _margins(fig, hspace=0.09)
    paths.append(_save(fig, out / "joints.png"))
    fig = Figure(figsize=(8, 3.5))
    ax = fig.subplots()
    for traj, style, name in ((d, "--", "default"), (o, "-", "optimized")):
        tau = robot.inverse_dynamics(traj.q, traj.qd, traj.qdd, friction=robot.friction)
        ax.plot(traj.t, joint_power(tau, traj.qd).sum(axis=1), style, label=name)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("Σ |τ·qd| [W]")
    ax.legend()
    _margins(fig)
    paths.append(_save(fig, out / "power.png"))
    fig = Figure(figsize=(6, 3.5))
    ax = fig.subplots()
    ax.plot(np.arange(result.history.size), result.history)
    ax.set_xlabel("iteration" if result.summary.representation == "bspline" else "generation")
    ax.set_ylabel("best fitness [J]")
    _margins(fig)
    paths.append(_save(fig, out / "convergence.png"))
    return paths


def _margins(fig: Any, *, hspace: float = 0.2) -> None:
    """Fixed margins in inches (room for the tick labels and an axis label), in place of ``tight_layout``:
    that lays a figure out by drawing it once more before it is saved (a third of the plots' time)."""
    w, h = fig.get_size_inches()
    fig.subplots_adjust(left=0.8 / w, right=1 - 0.15 / w, bottom=0.6 / h, top=1 - 0.15 / h, hspace=hspace)


def _save(fig: Any, path: Path) -> Path:
    return save_figure(fig, path, dpi=100)


RUN_FILES = (
    "result.json",
    "path.csv",
    "default_path.csv",
    "convergence.csv",
    "joints.png",
    "power.png",
    "convergence.png",
    "path.mod",
)
"""What :func:`write_run` writes in a run folder for the IRB 120 (``path.mod`` only for a path
within the limits); another exporter writes its own program files instead of ``path.mod``."""


def write_run(
    result: MoveResult,
    robot: Robot,
    out_dir: str | os.PathLike[str],
    *,
    export: str | None = None,
) -> dict[str, Path]:
    """Write result.json, path.csv, convergence.csv, plots and — only when limits hold — the program.

    The program is the exporter ``export`` renders (:data:`joulepath.export.EXPORTERS`;
    None: the controller the robot declares, e.g. ``path.mod`` for the IRB 120).
    ``result.json`` names the exporter and its files, or why none was written, and
    any warning (another vendor's program). A refused path also removes program files
    an earlier run left in the folder, so the folder never offers a program for a
    result that was refused.
    """
    from joulepath.export import EXPORTERS, select_exporter

    exporter, warning = select_exporter(robot, export)
    out = make_folder(out_dir)
    files = {}
    s = result.summary
    summary = s.to_json()  # the executed figures are added below, once the program has run
    summary["export"] = exporter.name
    programs: dict[str, str] = {}
    refused = None
    execution = None
    if not s.limits_ok:
        refused = "the optimized path violates a limit: " + "; ".join(s.limit_excess)
    else:
        try:
            written = result.optimized
            if exporter.follows == "via-points":
                from joulepath.optimize._execute import rapid_execution

                exporter.render(robot, result.optimized, s.duration_s)  # the plan's own limit check
                execution, written = rapid_execution(
                    robot, result.optimized, s.energy_optimized_fine_J, measure=s.energy_measure
                )
                refused = execution.refusal()
            if refused is None:
                programs = exporter.render(robot, written, s.duration_s)
        except (LimitViolation, InvalidInput) as err:
            refused = str(err)
    if execution is not None:
        summary.update(execution.to_json())
        executed = EnergyPair(
            stage="executed",
            measure=s.energy_measure,
            on="the written program run by the controller emulation, on the planning model",
            default_J=execution.executed_energy_default_J,
            optimized_J=execution.executed_energy_optimized_J,
            lab_default_J=execution.executed_lab_default_J,
            lab_optimized_J=execution.executed_lab_optimized_J,
        )
        full = s.to_json(executed)
        for key in ("executed_default_J", "executed_optimized_J", "executed_saved_pct", "energy_figures"):
            summary[key] = full[key]
    if refused is None:
        for name, text in programs.items():
            files[name] = atomic_write_text(out / name, text)
    else:
        for name in sorted({f for e in EXPORTERS.values() for f in e.files}):
            stale = out / name
            if stale.is_file() and not stale.is_symlink():
                remove_output(stale)
    summary["program"] = sorted(programs) if refused is None else None
    summary["rapid"] = "path.mod" if "path.mod" in files else None
    if refused is not None:
        summary["program_refused"] = refused
        if exporter.name == "rapid":
            summary["rapid_refused"] = refused
    if warning is not None:
        summary["export_warning"] = warning
    files["result.json"] = atomic_write_text(
        out / "result.json", json.dumps(summary, indent=2, allow_nan=False)
    )
    files["path.csv"] = atomic_write_text(out / "path.csv", _path_csv(result.optimized))
    files["default_path.csv"] = atomic_write_text(out / "default_path.csv", _path_csv(result.default))
    conv = "step,best_fitness_J\n" + "\n".join(f"{k},{v:.10g}" for k, v in enumerate(result.history)) + "\n"
    files["convergence.csv"] = atomic_write_text(out / "convergence.csv", conv)
    for p in plot_run(result, robot, out):
        files[p.name] = p
    return files
