"""The default optimizer against the reference optimum and its peers (issue 11, items 6 and "Done when").

On feasible random tasks (``random_tasks``: lab ranges, T in [1, 3] s, fixed seed)
and on the issue's fixed task, each of these is run on the physics fitness (nominal
rigid body + ``NOMINAL_FRICTION``, acceleration limits ``v_max / ACCEL_TIME`` and jerk limits
``v_max / ACCEL_TIME / --jerk-time``, default ``JERK_TIME``; ``--jerk-time 0``: none, as before
jerk limits existed; every method, the reference included, gets the same limits):

* ``default`` — ``optimize_move`` with ``OptimizeConfig()`` (algorithm "auto": the
  coarse-to-fine constrained gradient search);
* the reference optimum (``_reference.reference_optimum``, IPOPT on a direct
  transcription), twice: from the minimum-jerk move, and from the default's path
  (a local refinement of ours); the best of the two is "the optimum";
* ``cmaes`` — ``optimize_move(algorithm="cmaes")`` (pycma over the B-spline);
* ``scipy-de`` — ``scipy.optimize.differential_evolution`` and ``pymoo-ga`` — pymoo's
  GA, both over the rest-to-rest B-spline coefficients at 0.1 s knot spacing with a
  penalized objective (energy + ``PENALTY`` x limit violation on the samples, the
  same rule as CMA-ES), an initial population of the minimum-jerk move and Gaussian
  perturbations of it with CMA-ES's initial step size, an
  evaluation budget equal to CMA-ES's on the same task and a wall-time cap of 10x
  the default's on the same task;
* ``ga``, ``ma-random``, ``ma-informed`` — the thesis' best GA and both MAs over its
  36 coefficients, thesis protocol: population 100, 200 generations (no early stop),
  random initial population.

Every result's limits are checked with ``check_limits`` on a grid 10x finer than the
samples (acceleration limits included), and its energy is measured on that grid too.
The share of the optimum is ``(E_default - E_method) / (E_default - E_optimum)`` on
the fine grid. Rows go to a CSV as soon as each method finishes, so a run stopped by
``--time-cap-min`` leaves its results.

``--friction none`` runs the same comparison without friction, for the methods that
can: the default's search (``solve_move``, the function ``optimize_move`` calls,
with ``friction=None``; ``OptimizeConfig`` has no friction switch), the reference,
and the scipy/pymoo peers; the package's CMA-ES and thesis searches always use the
nominal friction, so they are skipped there.

The CSVs in benchmarks/results without a ``jerk`` tag in their name were run without jerk limits
(before they existed, or with ``--jerk-time 0``); the report aggregates every CSV of ``--prefix``,
so give runs with jerk limits their own prefix (``benchmarks/optimizer_jerk.py`` measures what
jerk limits cost).

Usage:
    python benchmarks/optimizer_peers.py --tasks 10 --first 0 --fixed --jerk-time 0
    python benchmarks/optimizer_peers.py --tasks 30 --first 20 --methods default,reference
    python benchmarks/optimizer_peers.py --report-only     # aggregate CSVs, write BENCHMARKS.md
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

import joulepath  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION, Robot  # noqa: E402
from joulepath.errors import LimitViolation  # noqa: E402
from joulepath.optimize import (  # noqa: E402
    ACCEL_TIME,
    FINE_FACTOR,
    JERK_TIME,
    PENALTY,
    OptimizeConfig,
    acceleration_limit,
    check_default_feasible,
    check_limits,
    jerk_limit,
    limit_violation,
    optimize_move,
    physics_energy,
    random_tasks,
)
from joulepath.optimize._gradient import GradientSettings, solve_move  # noqa: E402
from joulepath.optimize._reference import _between_samples, reference_optimum  # noqa: E402
from joulepath.optimize._verify import energy_on_samples  # noqa: E402
from joulepath.trajectory import (  # noqa: E402
    DEFAULT_KNOT_SPACING,
    SplineBasis,
    Trajectory,
    minimum_jerk,
    rest_to_rest,
)
from joulepath.units import SAMPLE_PERIOD  # noqa: E402

SECTION = "optimizer_peers"
JERK_PREFIX = "optimizer_peers_jerk"
"""File prefix of the runs with jerk limits (``--prefix optimizer_peers_jerk``), reported in their own section."""
JERK_SECTION = "optimizer_peers_jerk"
TITLE = "## Optimizer: the default against the optimum and its peers (issue 11)"
FIXED_TASK = (
    np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0]),
    np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5]),
    1.6,
)
ALL_METHODS = ("default", "reference", "cmaes", "scipy-de", "pymoo-ga", "ga", "ma-random", "ma-informed")
NO_FRICTION_METHODS = ("default", "reference", "scipy-de", "pymoo-ga")
PEER_KNOT_SPACING = 0.1
"""s between knots of the B-spline the scipy DE and pymoo GA search."""
WALL_CAP_FACTOR = 10.0
"""The scipy DE and pymoo GA stop at this many times the default's wall time on the same task."""
REF_CONTINUATION = (0.3, 0.03, 0.003, 0.0003)
"""Smoothing stages of the reference from the minimum-jerk move (given explicitly: the tight
sequence, ending at 0.0003 x the mean |tau qd|, whatever the package's default)."""
REF_WARM_CONTINUATION = (0.003, 0.0003)
"""Smoothing stages of the reference started from the default's path (a local refinement:
large smoothing would first pull the path away from where it already is)."""
REF_VALID_EXCESS = 1e-3
"""A reference counts as the optimum when its worst limit excess on the 10x grid is below this."""
THESIS = {"ga": "ga", "ma-random": "ma-random", "ma-informed": "ma-informed"}
FIELDS = (
    "task",
    "T_s",
    "friction",
    "method",
    "energy_J",
    "energy_fine_J",
    "energy_default_J",
    "energy_default_fine_J",
    "saved_pct",
    "saved_fine_pct",
    "energy_optimum_fine_J",
    "share_of_optimum",
    "limits_ok",
    "max_excess",
    "evaluations",
    "iterations",
    "wall_s",
    "call_wall_s",
    "call_cpu_s",
    "load1",
    "status",
    "note",
)
METHOD_LABELS = {
    "default": "default: OptimizeConfig() (auto: SLSQP, exact gradients, B-spline 0.1 -> 0.05 s, "
    f"{OptimizeConfig().n_starts} start{'s' if OptimizeConfig().n_starts > 1 else ''})",
    "default-2starts": "the same with n_starts=2 (the default until commit c992d15)",
    "reference": "reference optimum (IPOPT transcription, best of its starts)",
    "reference-mj": "reference from the minimum-jerk move",
    "reference-ours": "reference from the default's path",
    "cmaes": "pycma CMA-ES, B-spline 0.2 s (algorithm cmaes)",
    "scipy-de": "scipy differential_evolution, B-spline 0.1 s",
    "pymoo-ga": "pymoo GA, B-spline 0.1 s",
    "ga": "thesis GA random P(C) 0.95 P(M) 0.05, 36 coef.",
    "ma-random": "thesis MA random local search, 36 coef.",
    "ma-informed": "thesis MA informed local search, 36 coef.",
}


def load1() -> float:
    return float(os.getloadavg()[0])


def run_timed(fn: Callable[[], Any]) -> tuple[Any, float, float]:
    """``fn()`` on one BLAS/OpenMP thread; its result, wall time and process CPU time (s)."""
    with threadpool_limits(limits=1):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        return out, time.perf_counter() - w0, time.process_time() - c0


def worst_excess(report: Any) -> float:
    return max((float(w.excess) for w in report.worst), default=0.0)


def _fine_default(q0: np.ndarray, qf: np.ndarray, T: float) -> Trajectory:
    return minimum_jerk(q0, qf, T, dt=SAMPLE_PERIOD / FINE_FACTOR)


def fine_path_of(result: Any, q0: np.ndarray, qf: np.ndarray, T: float) -> Trajectory | None:
    """The result's path on the 10x grid, rebuilt from its parameters (None if no basis matches)."""
    s = result.summary
    P = np.asarray(result.parameters)
    dt_f = SAMPLE_PERIOD / FINE_FACTOR
    candidates: list[Callable[[], tuple[Trajectory, Trajectory]]] = []
    if s.representation == "bspline":
        # the default spacing, or a long move's wider one (GradientSettings.spacing_for), and the coarse knots
        wide = GradientSettings().spacing_for(T)
        for spacing in dict.fromkeys(k * b for b in (DEFAULT_KNOT_SPACING, wide) for k in (1, 2, 4)):
            basis = SplineBasis(T, knot_spacing=spacing, dt=SAMPLE_PERIOD)
            if basis.n_free == P.shape[0]:
                candidates.append(lambda b=basis: (b.trajectory(P, q0, qf), b.trajectory(P, q0, qf, dt=dt_f)))
    elif s.representation == "rest_to_rest":
        candidates.append(lambda: (rest_to_rest(P, q0, qf, T), rest_to_rest(P, q0, qf, T, dt=dt_f)))
    for make in candidates:
        samples, fine = make()
        if np.allclose(samples.q, result.optimized.q, atol=1e-9, rtol=0):
            return fine
    return None


class SplineObjective:
    """Penalized energy of B-spline coefficient vectors, vectorized over a population."""

    def __init__(
        self,
        robot: Robot,
        q0: np.ndarray,
        qf: np.ndarray,
        T: float,
        amax: np.ndarray,
        friction: Any,
        jmax: np.ndarray | None = None,
    ) -> None:
        self.robot, self.q0, self.qf, self.amax, self.friction = robot, q0, qf, amax, friction
        self.jmax = jmax
        self.basis = SplineBasis(T, knot_spacing=PEER_KNOT_SPACING, dt=SAMPLE_PERIOD)
        self.m, self.n = self.basis.n_free, robot.n_joints
        # box for the coefficients: wide enough to hold the optimum's shapes (the default's
        # largest coefficient is about 0.4 rad on a joint travelling 0.4 rad)
        half = 0.4 + 0.3 * np.abs(qf - q0)
        self.bound = np.tile(half, self.m)
        # the initial spread CMA-ES gets (``_search._cmaes``: sigma0 around the minimum-jerk move)
        self.sigma0 = max(0.02, 0.05 * float(np.max(np.abs(qf - q0))))
        self.n_evaluated = 0

    @property
    def n_var(self) -> int:
        return self.m * self.n

    def __call__(self, X: np.ndarray) -> np.ndarray:
        X = np.atleast_2d(X)
        traj = self.basis.trajectory(X.reshape(-1, self.m, self.n), self.q0, self.qf)
        energy, tau = physics_energy(self.robot, traj, friction=self.friction)
        viol = limit_violation(self.robot, traj, tau, acceleration_limit=self.amax, jerk_limit=self.jmax)
        self.n_evaluated += X.shape[0]
        out: np.ndarray = energy + PENALTY * viol.total
        return out

    def initial(self, size: int, seed: int) -> np.ndarray:
        """The minimum-jerk move and ``size - 1`` Gaussian perturbations of it (CMA-ES's sigma0), in the box."""
        rng = np.random.default_rng(seed)
        X = np.clip(rng.normal(0.0, self.sigma0, size=(size, self.n_var)), -self.bound, self.bound)
        X[0] = 0.0
        return X

    def paths(self, x: np.ndarray) -> tuple[Trajectory, Trajectory]:
        C = np.asarray(x, dtype=float).reshape(self.m, self.n)
        return (
            self.basis.trajectory(C, self.q0, self.qf),
            self.basis.trajectory(C, self.q0, self.qf, dt=SAMPLE_PERIOD / FINE_FACTOR),
        )


def run_scipy_de(obj: SplineObjective, budget: int, cap_s: float, seed: int) -> tuple[np.ndarray, int, int]:
    """scipy DE (best1bin, population = number of variables, started like CMA-ES), within budget and cap."""
    from scipy.optimize import differential_evolution

    N = obj.n_var
    maxiter = max(1, budget // N - 1)
    t0 = time.perf_counter()

    def stop(intermediate_result: Any) -> bool:
        return time.perf_counter() - t0 > cap_s

    res = differential_evolution(
        lambda xT: obj(np.asarray(xT).T),
        bounds=list(zip(-obj.bound, obj.bound, strict=True)),
        maxiter=maxiter,
        popsize=1,
        tol=0.0,
        polish=False,
        init=obj.initial(N, seed),
        vectorized=True,
        updating="deferred",
        rng=seed,
        callback=stop,
    )
    return np.asarray(res.x), obj.n_evaluated, int(res.nit)


def run_pymoo_ga(obj: SplineObjective, budget: int, cap_s: float, seed: int) -> tuple[np.ndarray, int, int]:
    """pymoo GA (SBX, PM, tournament; population 100, started like CMA-ES), within budget and cap."""
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.core.problem import Problem
    from pymoo.core.termination import TerminateIfAny
    from pymoo.optimize import minimize
    from pymoo.termination.max_eval import MaximumFunctionCallTermination
    from pymoo.termination.max_time import TimeBasedTermination

    class P(Problem):  # type: ignore[misc]
        def __init__(self) -> None:
            super().__init__(n_var=obj.n_var, n_obj=1, xl=-obj.bound, xu=obj.bound)

        def _evaluate(self, x: np.ndarray, out: dict[str, Any], *args: Any, **kwargs: Any) -> None:
            out["F"] = obj(x)[:, None]

    pop = 100
    X0 = obj.initial(pop, seed)
    res = minimize(
        P(),
        GA(pop_size=pop, sampling=X0),
        TerminateIfAny(MaximumFunctionCallTermination(budget), TimeBasedTermination(cap_s)),
        seed=seed,
        verbose=False,
    )
    return np.asarray(res.X, dtype=float), obj.n_evaluated, int(res.algorithm.n_gen)


def reference_fine(path: Trajectory, T: float) -> Trajectory:
    """The reference's piecewise-cubic path on the 10x grid."""
    h = path.dt
    q, qd, qdd = _between_samples(path.q, path.qd, path.qdd, h, FINE_FACTOR)
    t = np.linspace(0.0, T, q.shape[0])
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd)


class Bench:
    """Runs the methods on one task and writes a CSV row per method."""

    def __init__(self, robot: Robot, args: argparse.Namespace, out_csv: Path) -> None:
        self.robot, self.args, self.out_csv = robot, args, out_csv
        self.friction = NOMINAL_FRICTION if args.friction == "nominal" else None
        self.amax = acceleration_limit(robot, ACCEL_TIME)
        self.jmax = jerk_limit(robot, ACCEL_TIME, args.jerk_time)
        new = not out_csv.exists()
        self.fh = out_csv.open("a", newline="")
        self.writer = csv.DictWriter(self.fh, fieldnames=FIELDS)
        if new:
            self.writer.writeheader()
            self.fh.flush()

    def energy(self, path: Trajectory) -> float:
        return energy_on_samples(self.robot, path, friction=self.friction)

    def limits(self, fine: Trajectory) -> Any:
        return check_limits(
            self.robot, fine, friction=self.friction, acceleration_limit=self.amax, jerk_limit=self.jmax
        )

    def write(self, row: dict[str, Any]) -> None:
        self.writer.writerow({k: row.get(k, "") for k in FIELDS})
        self.fh.flush()
        e, ef = row.get("energy_J"), row.get("energy_fine_J")
        print(
            f"  {row['task']:>5} {row['method']:<15} E {e:9.4f} fine {ef:9.4f} share {row.get('share_of_optimum', '')!s:>8.8}"
            f" ok {row.get('limits_ok')} wall {row.get('wall_s', 0):7.2f} s load {row.get('load1', 0):.2f}",
            flush=True,
        )

    def task(self, name: str, q0: np.ndarray, qf: np.ndarray, T: float, methods: tuple[str, ...]) -> None:
        robot, seed = self.robot, self.args.seed
        e_def = self.energy(minimum_jerk(q0, qf, T))
        e_def_f = self.energy(_fine_default(q0, qf, T))
        base = {
            "task": name,
            "T_s": round(T, 3),
            "friction": self.args.friction,
            "energy_default_J": e_def,
            "energy_default_fine_J": e_def_f,
        }
        optimum: list[float] = []

        def row(method: str, path: Trajectory, fine: Trajectory, **extra: Any) -> dict[str, Any]:
            e, ef = self.energy(path), self.energy(fine)
            rep = self.limits(fine)
            out = dict(base)
            out.update(
                method=method,
                energy_J=e,
                energy_fine_J=ef,
                saved_pct=100 * (e_def - e) / e_def,
                saved_fine_pct=100 * (e_def_f - ef) / e_def_f,
                limits_ok=rep.ok,
                max_excess=worst_excess(rep),
            )
            if optimum:
                out["energy_optimum_fine_J"] = optimum[0]
                gap = e_def_f - optimum[0]
                out["share_of_optimum"] = (e_def_f - ef) / gap if gap > 0 else float("nan")
            out.update(extra)
            return out

        # 1. the default (skipped when only the reference from the minimum-jerk move is asked for)
        pending: list[dict[str, Any]] = []
        default_path: Trajectory | None = None
        default_wall = float("nan")
        if "default" not in methods:
            pass
        elif self.friction is not None:
            cfg = OptimizeConfig(seed=seed, jerk_time=self.args.jerk_time)
            res, wall, cpu = run_timed(lambda: optimize_move(robot, q0, qf, T, cfg))
            s = res.summary
            fine = fine_path_of(res, q0, qf, T)
            note = f"n_starts={cfg.n_starts}" + ("" if fine is not None else "; fine path not rebuilt")
            if fine is None:
                r = dict(
                    base,
                    method="default",
                    energy_J=s.energy_optimized_J,
                    energy_fine_J=s.energy_optimized_fine_J,
                    limits_ok=s.limits_ok,
                )
            else:
                r = row("default", res.optimized, fine)
                # the package's own verification must agree with this independent one
                if (
                    abs(r["energy_fine_J"] - s.energy_optimized_fine_J) > 1e-6
                    or r["limits_ok"] != s.limits_ok
                ):
                    note += f"; package says fine {s.energy_optimized_fine_J:.6f} J limits_ok {s.limits_ok}"
            r.update(
                evaluations=s.evaluations,
                iterations=s.iterations,
                wall_s=s.wall_s,
                call_wall_s=wall,
                call_cpu_s=cpu,
                load1=load1(),
                note=note,
            )
            default_path, default_wall = res.optimized, s.wall_s
        else:
            settings = GradientSettings(
                knot_spacing=DEFAULT_KNOT_SPACING,
                n_starts=OptimizeConfig().n_starts,
                check_factor=FINE_FACTOR,
            )
            (gres, prob), wall, cpu = run_timed(
                lambda: solve_move(
                    robot,
                    q0,
                    qf,
                    T,
                    friction=None,
                    settings=settings,
                    rng=np.random.default_rng(seed),
                    acceleration_limit=self.amax,
                    jerk_limit=self.jmax,
                    dt=SAMPLE_PERIOD,
                )
            )
            x = gres.coefficients.ravel()
            r = row("default", gres.path, prob.path(x, fine=True))
            r.update(
                evaluations=gres.n_evaluations,
                iterations=gres.n_iterations,
                wall_s=wall,
                call_wall_s=wall,
                call_cpu_s=cpu,
                load1=load1(),
                note=f"solve_move(friction=None), the search optimize_move runs; n_starts={settings.n_starts}",
            )
            default_path, default_wall = gres.path, wall
        if "default" in methods:
            pending.append(r)

        # 2. the reference, from the minimum-jerk move and from the default's path
        starts = [
            (label, kw)
            for label, kw in (
                ("reference-mj", {"continuation": REF_CONTINUATION}),
                ("reference-ours", {"initial": default_path, "continuation": REF_WARM_CONTINUATION}),
            )
            if ("reference" in methods or label in methods)
            and (label == "reference-mj" or default_path is not None)
        ]
        if starts:
            refs = []
            for label, kw in starts:
                ref, wall, cpu = run_timed(
                    lambda kw=kw: reference_optimum(
                        robot,
                        q0,
                        qf,
                        T,
                        friction=self.friction,
                        acceleration_limit=self.amax,
                        jerk_limit=self.jmax,
                        substeps=4,
                        **kw,
                    )
                )
                fine = reference_fine(ref.path, T)
                rr = row(label, ref.path, fine)
                rr.update(
                    wall_s=ref.wall_s,
                    call_wall_s=wall,
                    call_cpu_s=cpu,
                    load1=load1(),
                    status=ref.status,
                    note=f"IPOPT max violation {ref.max_violation:.2e}; fine(4 substeps) {ref.energy_fine_J:.6f} J",
                )
                refs.append(rr)
            valid = [x for x in refs if x["max_excess"] <= REF_VALID_EXCESS]
            if valid:
                optimum.append(min(x["energy_fine_J"] for x in valid))
            pending.extend(refs)
        for p in pending:  # now that the optimum is known
            if optimum:
                gap = e_def_f - optimum[0]
                p["energy_optimum_fine_J"] = optimum[0]
                p["share_of_optimum"] = (e_def_f - p["energy_fine_J"]) / gap if gap > 0 else float("nan")
            self.write(p)

        # 3. the peers
        budget = 6000
        if "cmaes" in methods and self.friction is not None:
            res, wall, cpu = run_timed(
                lambda: optimize_move(
                    robot,
                    q0,
                    qf,
                    T,
                    OptimizeConfig(algorithm="cmaes", seed=seed, jerk_time=self.args.jerk_time),
                )
            )
            budget = res.summary.evaluations
            self._package_row(res, "cmaes", row, wall, cpu, q0, qf, T)
        for name, runner in (("scipy-de", run_scipy_de), ("pymoo-ga", run_pymoo_ga)):
            if name not in methods:
                continue
            obj = SplineObjective(robot, q0, qf, T, self.amax, self.friction, self.jmax)
            cap = WALL_CAP_FACTOR * default_wall
            (x, nfev, nit), wall, cpu = run_timed(lambda r=runner, o=obj, c=cap: r(o, budget, c, seed))
            path, fine = obj.paths(x)
            self.write(
                row(
                    name,
                    path,
                    fine,
                    evaluations=nfev,
                    iterations=nit,
                    wall_s=wall,
                    call_wall_s=wall,
                    call_cpu_s=cpu,
                    load1=load1(),
                    note=f"budget {budget} evals, cap {cap:.1f} s, {obj.n_var} variables"
                    + ("; stopped by the wall cap" if wall > cap else ""),
                )
            )
        for name in ("ga", "ma-random", "ma-informed"):
            if name not in methods or self.friction is None:
                continue
            cfg = OptimizeConfig(
                algorithm=name,
                pop_size=100,
                max_gen=200,
                n_stagnant=200,
                inject_default=False,
                seed=seed,
                jerk_time=self.args.jerk_time,
            )
            res, wall, cpu = run_timed(lambda c=cfg: optimize_move(robot, q0, qf, T, c))
            self._package_row(res, name, row, wall, cpu, q0, qf, T)

    def _package_row(
        self,
        res: Any,
        name: str,
        row: Callable[..., dict[str, Any]],
        wall: float,
        cpu: float,
        q0: np.ndarray,
        qf: np.ndarray,
        T: float,
    ) -> None:
        s = res.summary
        fine = fine_path_of(res, q0, qf, T)
        if fine is None:
            raise RuntimeError(f"{name}: could not rebuild the fine path from the parameters")
        r = row(name, res.optimized, fine)
        note = ""
        if abs(r["energy_fine_J"] - s.energy_optimized_fine_J) > 1e-6 or r["limits_ok"] != s.limits_ok:
            note = f"package says fine {s.energy_optimized_fine_J:.6f} J limits_ok {s.limits_ok}"
        r.update(
            evaluations=s.evaluations,
            iterations=s.iterations,
            wall_s=s.wall_s,
            call_wall_s=wall,
            call_cpu_s=cpu,
            load1=load1(),
            note=note,
        )
        self.write(r)


# ---------------------------------------------------------------------------- report
def _files(out: Path, prefix: str, suffix: str) -> list[Path]:
    """The result files of ``prefix``; the jerk-limited runs (prefix ``JERK_PREFIX``) are not the plain one's."""
    files = sorted(out.glob(f"{prefix}_*{suffix}"))
    if prefix == "optimizer_peers":
        files = [f for f in files if not f.name.startswith(JERK_PREFIX + "_")]
    return files


def _read_rows(out: Path, prefix: str = "optimizer_peers") -> list[dict[str, Any]]:
    rows = []
    for f in _files(out, prefix, ".csv"):
        with f.open() as fh:
            for r in csv.DictReader(fh):
                r["_file"] = f.name
                for k in FIELDS:
                    v = r.get(k, "")
                    if k in ("task", "friction", "method", "status", "note"):
                        continue
                    if k == "limits_ok":
                        r[k] = v == "True"
                    else:
                        r[k] = float(v) if v not in ("", None) else float("nan")
                rows.append(r)
    return rows


def _fmt(v: float, spec: str = ".3f") -> str:
    return "-" if v is None or not np.isfinite(v) else format(v, spec)


def _by_task(rows: list[dict[str, Any]], friction: str) -> dict[str, dict[str, dict[str, Any]]]:
    """Rows by task and method; each row gets ``_base``, the default's row of the same run (file)."""
    out: dict[str, dict[str, dict[str, Any]]] = {}
    base = {
        (r["_file"], r["task"]): r
        for r in rows
        if r["method"] in ("default", "default-2starts") and r["friction"] == friction
    }
    for r in rows:
        if r["friction"] == friction:
            r["_base"] = base.get((r["_file"], r["task"]))
            out.setdefault(r["task"], {})[r["method"]] = r
    return out


def _optimum(methods: dict[str, dict[str, Any]]) -> dict[str, Any] | None:
    refs = [methods[m] for m in ("reference-mj", "reference-ours") if m in methods]
    valid = [r for r in refs if r["max_excess"] <= REF_VALID_EXCESS]
    return min(valid, key=lambda r: r["energy_fine_J"]) if valid else None


def _share(r: dict[str, Any], opt: dict[str, Any]) -> float:
    gap = r["energy_default_fine_J"] - opt["energy_fine_J"]
    return (r["energy_default_fine_J"] - r["energy_fine_J"]) / gap if gap > 0 else float("nan")


def _method_table(
    tasks: dict[str, dict[str, dict[str, Any]]],
    methods: tuple[str, ...],
    require: tuple[str, ...],
    *,
    with_fixed: bool = False,
) -> tuple[list[str], int]:
    """Rows of the per-method table over the tasks that have every method in ``require``."""
    keep = {
        t: m
        for t, m in tasks.items()
        if (with_fixed or t != "fixed") and all(k in m for k in require) and _optimum(m)
    }
    lines = [
        "| method | tasks | mean share of the optimum's saving | median share | min share | mean saving (fine grid) "
        "| within limits | median evaluations | median wall per move | median CPU per move "
        "| median wall / the default's in the same run |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name in methods:
        rs = [(m[name], _optimum(m), m[name]["_base"]) for m in keep.values() if name in m]
        if not rs:
            continue
        if name == "reference":
            continue
        shares = [_share(r, o) for r, o, _ in rs]
        saving = [r["saved_fine_pct"] for r, _, _ in rs]
        ok = [r["limits_ok"] for r, _, _ in rs]
        evals = [r["evaluations"] for r, _, _ in rs if np.isfinite(r["evaluations"])]
        wall = [r["call_wall_s"] for r, _, _ in rs]
        cpu = [r["call_cpu_s"] for r, _, _ in rs]
        ratio = [r["call_wall_s"] / d["call_wall_s"] for r, _, d in rs if d is not None]
        lines.append(
            f"| {METHOD_LABELS.get(name, name)} | {len(rs)} | {100 * statistics.mean(shares):.1f} % "
            f"| {100 * statistics.median(shares):.1f} % | {100 * min(shares):.1f} % "
            f"| {statistics.mean(saving):.1f} % | {100 * sum(ok) / len(ok):.0f} % "
            f"| {_fmt(statistics.median(evals), ',.0f') if evals else '-'} "
            f"| {statistics.median(wall):.2f} s | {statistics.median(cpu):.2f} s "
            f"| {_fmt(statistics.median(ratio) if ratio else float('nan'), '.2f')}x |"
        )
    # the optimum itself
    opts = [_optimum(m) for m in keep.values()]
    sav = [100 * (o["energy_default_fine_J"] - o["energy_fine_J"]) / o["energy_default_fine_J"] for o in opts]
    if opts:
        lines.append(
            f"| {METHOD_LABELS['reference']} | {len(opts)} | 100 % (by definition) | - | - "
            f"| {statistics.mean(sav):.1f} % (min {min(sav):.1f}, max {max(sav):.1f}) "
            f"| {100 * sum(o['limits_ok'] for o in opts) / len(opts):.0f} % | - "
            f"| {statistics.median([o['call_wall_s'] for o in opts]):.1f} s (one start) | - | - |"
        )
    return lines, len(keep)


def _same_energies(timing: list[dict[str, Any]], rows: list[dict[str, Any]]) -> bool:
    first = {(r["task"], r["friction"]): r["energy_J"] for r in rows if r["method"] == "default"}
    return all(abs(first.get((r["task"], r["friction"]), np.inf) - r["energy_J"]) < 1e-9 for r in timing)


def report(out: Path, unmeasured: str = "") -> str:
    rows = _read_rows(out)
    meta = []
    for f in _files(out, "optimizer_peers", ".json"):
        meta.append(json.loads(f.read_text()))
    loads = [r["load1"] for r in rows if np.isfinite(r["load1"])]
    runs: dict[str, list[str]] = {}
    for m in meta:
        runs.setdefault(m.get("commit", "?")[:10], []).append(m.get("started", "?")[11:16])
    by_task = _by_task(rows, "nominal")
    both = [m for m in by_task.values() if "reference-mj" in m and "reference-ours" in m and _optimum(m)]
    n_ours = sum("reference-ours" in m for m in by_task.values())
    mj_share = (
        f"{100 * statistics.mean(_share(m['reference-mj'], _optimum(m)) for m in both):.1f} %"  # type: ignore[arg-type]
        if both
        else "-"
    )
    lines = [
        TITLE,
        "",
        f"Machine: {machine()}; `nproc` {meta[0]['nproc'] if meta else os.cpu_count()}; "
        "one BLAS/OpenMP thread per solve (`threadpool_limits(1)`, `OMP_NUM_THREADS=1`). "
        f"The machine was shared: 1-minute load average during the runs {min(loads):.1f} to {max(loads):.1f} "
        f"(median {statistics.median(loads):.1f}) on 2 cores, with up to two benchmark processes of this "
        "script among it, so wall times are longer than on an idle core; the CPU time of each call "
        "(process time) is given beside it. "
        "Code: "
        + "; ".join(f"commit {c} (runs started {', '.join(sorted(v))} UTC)" for c, v in sorted(runs.items()))
        + " (src/joulepath/optimize as committed unless noted below).",
        "",
        'Physics: nominal rigid body + `NOMINAL_FRICTION` (unless stated "without friction"), acceleration '
        f"limits v_max / {ACCEL_TIME} s, limits checked with `check_limits` on a grid {FINE_FACTOR}x finer than "
        "the 25 ms samples for every result (acceleration included); energies compared on that fine grid "
        "(the reference's path between samples is its exact cubic). Share of the optimum = "
        "(E_default_move - E_method) / (E_default_move - E_optimum), where the default move is the minimum-jerk "
        "path and the optimum is the best IPOPT solve of the reference transcription on the task: from the "
        f"minimum-jerk move (smoothing stages {REF_CONTINUATION} x the mean |tau qd|) on every task, and on "
        f"{n_ours} of them also from an earlier default optimizer's path as a local refinement (stages "
        f"{REF_WARM_CONTINUATION}; the 2-start default's or the 1-start default's of an earlier commit; on "
        "the other tasks the minimum-jerk start alone, which on the tasks with both reached on average "
        f"{mj_share} of the better one's saving). Wall and CPU times are "
        "those of the whole `optimize_move` call (search + verification + lab-plant energy) or of the search "
        "(scipy, pymoo, reference).",
        "",
    ]
    # fixed task
    tasks = _by_task(rows, "nominal")
    fx = tasks.get("fixed")
    if fx and "default" in fx:
        d = fx["default"]
        lines += [
            "**Fixed task of issue 11** (start (0.3, 0.2, -0.4, 0.5, -0.6, 1.0) rad -> end (-0.9, 0.6, 0.3, -1.2, "
            "0.8, -1.5) rad, T = 1.6 s, with friction):",
            "",
            "| path | energy on the samples | energy on the 10x grid | saving (samples) | within limits "
            "| wall | CPU |",
            "|---|---|---|---|---|---|---|",
            f"| minimum-jerk default move | {d['energy_default_J']:.3f} J | {d['energy_default_fine_J']:.3f} J "
            "| - | yes | - | - |",
        ]
        for name in ("default", "default-2starts", "reference-mj", "reference-ours"):
            if name in fx:
                r = fx[name]
                lines.append(
                    f"| {METHOD_LABELS[name]} | {r['energy_J']:.3f} J | {r['energy_fine_J']:.3f} J "
                    f"| {r['saved_pct']:.1f} % | {'yes' if r['limits_ok'] else 'NO'} "
                    f"| {r['call_wall_s']:.1f} s | {r['call_cpu_s']:.1f} s |"
                )
        opt = _optimum(fx)
        if opt is not None:
            gap_pct = 100 * (d["energy_J"] / opt["energy_J"] - 1)
            lines += [
                "",
                f"The default reaches {d['energy_J']:.3f} J on the samples against the optimum's "
                f"{opt['energy_J']:.3f} J ({gap_pct:+.2f} %; goal: <= 10.56 J and within 1 % of the optimum), "
                f"share of the optimum's saving {100 * _share(d, opt):.1f} % (fine grid), "
                f"limits {'held' if d['limits_ok'] else 'VIOLATED'}.",
            ]
        lines.append("")
    # headline: default vs reference, with friction
    head, n_head = _method_table(
        tasks, ("default", "default-2starts", "reference-mj", "reference-ours"), ("default",)
    )
    if n_head:
        keep = {t: m for t, m in tasks.items() if t != "fixed" and "default" in m and _optimum(m)}
        shares = sorted((_share(m["default"], _optimum(m)), t) for t, m in keep.items())
        wall = [m["default"]["call_wall_s"] for m in keep.values()]
        cpu = [m["default"]["call_cpu_s"] for m in keep.values()]
        lines += [
            f"**Default against the optimum, with friction: {n_head} random feasible tasks** "
            "(seed {seed}, lab ranges, T in [1, 3] s; the issue asks for 50):".format(
                seed=meta[0]["seed"] if meta else "?"
            ),
            "",
            *head,
            "",
            f"Default: mean share {100 * statistics.mean(s for s, _ in shares):.1f} %, median "
            f"{100 * statistics.median(s for s, _ in shares):.1f} %, lowest {100 * shares[0][0]:.1f} % (task "
            f"{shares[0][1]}); goal: mean >= 95 %. Median wall per move {statistics.median(wall):.2f} s, "
            f"median CPU per move {statistics.median(cpu):.2f} s (goal: <= 2 s on one core).",
            "",
        ]
    peers = ("default", "default-2starts", "cmaes", "scipy-de", "pymoo-ga", "ga", "ma-random", "ma-informed")
    table, n_peer = _method_table(tasks, peers, tuple(p for p in peers if p != "default-2starts"))
    if n_peer:
        lines += [
            f"**Peers, with friction, side by side on the same {n_peer} tasks** (the first tasks of the same draw; "
            "scipy DE and pymoo GA at CMA-ES's evaluation budget on each task and at most "
            f"{WALL_CAP_FACTOR:g}x the default's wall time; thesis searches at population 100, 200 generations, "
            "no early stop, random initial population):",
            "",
            *table,
            "",
        ]
    nf = _by_task(rows, "none")
    table, n_nf = _method_table(
        nf,
        ("default", "scipy-de", "pymoo-ga", "reference-mj", "reference-ours"),
        ("default",),
        with_fixed=True,
    )
    if n_nf:
        lines += [
            f"**Without friction: {n_nf} task{'s' if n_nf > 1 else ''}** (the fixed task and random tasks of "
            "the same draw; the default's search run as `solve_move(friction=None)` "
            "because `OptimizeConfig` has no friction switch; the package's CMA-ES and thesis searches always "
            "include friction and are not run here):",
            "",
            *table,
            "",
        ]
    # oddities
    notes = []
    for fr, tk in (("with friction", tasks), ("without friction", nf)):
        for t, m in tk.items():
            refs = [m[k] for k in ("reference-mj", "reference-ours") if k in m]
            for r in refs:
                if r["status"] not in ("Solve_Succeeded", "Solved_To_Acceptable_Level"):
                    notes.append(
                        f"task {t} ({fr}): {r['method']} ended with IPOPT status {r['status']} "
                        f"(fine energy {r['energy_fine_J']:.3f} J, max excess {r['max_excess']:.1e})."
                    )
            opt = _optimum(m)
            if refs and opt is None:
                notes.append(f"task {t} ({fr}): no reference within limits; left out of the shares.")
            if opt is not None and "default" in m:
                sh = _share(m["default"], opt)
                if sh < 0.9:
                    mj = m.get("reference-mj")
                    notes.append(
                        f"task {t} ({fr}, T = {m['default']['T_s']:g} s): the default reaches {100 * sh:.1f} % of "
                        f"the optimum's saving ({m['default']['energy_fine_J']:.3f} J vs {opt['energy_fine_J']:.3f} "
                        f"J, default move {m['default']['energy_default_fine_J']:.3f} J)"
                        + (
                            f"; the reference from the minimum-jerk move found {mj['energy_fine_J']:.3f} J"
                            if mj
                            else ""
                        )
                        + "."
                    )
            for r in refs:
                base = m.get("default") or m.get("default-2starts")
                if base is not None and r["energy_fine_J"] > base["energy_fine_J"] + 1e-6:
                    notes.append(
                        f"task {t} ({fr}): {r['method']} ended at {r['energy_fine_J']:.3f} J, above the default "
                        f"optimizer's own {base['energy_fine_J']:.3f} J (IPOPT status {r['status']}): a failed "
                        "solve; the other start is the optimum there."
                    )
            if opt is not None:
                flat = [
                    k
                    for k, r in m.items()
                    if not k.startswith("reference")
                    and r["energy_fine_J"] >= r["energy_default_fine_J"] - 1e-6
                ]
                if flat:
                    notes.append(
                        f"task {t} ({fr}): {', '.join(flat)} returned the minimum-jerk move unchanged (no "
                        "candidate within its budget beat it)."
                    )
            for k, r in m.items():
                if not r["limits_ok"] and not k.startswith("reference"):
                    notes.append(
                        f"task {t} ({fr}): {k} breaks a limit on the 10x grid (worst excess "
                        f"{r['max_excess']:.2e})."
                    )
                if "package says" in r.get("note", ""):
                    notes.append(
                        f"task {t} ({fr}): {k}: the independent check disagrees with the package: {r['note']}."
                    )
    if notes:
        lines += ["Findings per task:", "", *(f"- {n}" for n in notes), ""]
    for fr, tk in (("with friction", tasks), ("without friction", nf)):
        won = [
            min(
                (m[k] for k in ("reference-mj", "reference-ours") if k in m), key=lambda r: r["energy_fine_J"]
            )["method"]
            for t, m in tk.items()
            if t != "fixed" and "reference-mj" in m and "reference-ours" in m
        ]
        if won:
            lines.append(
                f"Reference ({fr}): the start from the minimum-jerk move gave the lower energy on "
                f"{won.count('reference-mj')} of {len(won)} tasks, the refinement of the default's path on "
                f"{won.count('reference-ours')}."
            )
    ref_ex = [r["max_excess"] for r in rows if r["method"].startswith("reference") and not r["limits_ok"]]
    n_ref = sum(r["method"].startswith("reference") for r in rows)
    if ref_ex:
        lines.append(
            f"Reference limits: {len(ref_ex)} of {n_ref} reference paths exceed a limit on the 10x grid between "
            f"the 4 points per sample interval where the transcription constrains them, by at most "
            f"{max(ref_ex):.1e} (relative); they count as the optimum (threshold {REF_VALID_EXCESS:g}); if anything that lowers the "
            "optimum's energy slightly, and with it the other methods' shares."
        )
    dirty = sorted({m["optimize_dirty"] for m in meta if m.get("optimize_dirty")})
    if dirty:
        lines.append(
            "Uncommitted changes in src/joulepath/optimize at the start of a run: " + "; ".join(dirty)
        )
    timing = [r for r in _read_rows(out, "timing") if r["method"] == "default"]
    if timing:
        wall = [r["call_wall_s"] for r in timing]
        cpu = [r["call_cpu_s"] for r in timing]
        tl = [r["load1"] for r in timing]
        lines += [
            "",
            f"**Speed of the default on a quiet machine** (a second pass of the default alone over {len(timing)} "
            "of the moves above, in its own single-threaded process, nothing else running; 1-minute load "
            f"{min(tl):.1f} to {max(tl):.1f} on 2 logical CPUs): "
            f"median wall per move {statistics.median(wall):.2f} s "
            f"(min {min(wall):.2f}, max {max(wall):.2f}), median CPU {statistics.median(cpu):.2f} s "
            f"(max {max(cpu):.2f}); goal: median <= 2 s on one core. Energies identical to the first pass "
            "(same seed): " + ("yes." if _same_energies(timing, rows) else "NO, see the CSVs."),
        ]
    lines += [
        "",
        "Not measured: " + (unmeasured or "-"),
        "",
        f"Raw rows: `benchmarks/results/optimizer_peers_*.csv` (one per task and method, {len(rows)} rows).",
    ]
    return "\n".join(lines)


def report_jerk(out: Path) -> str:
    """The section of the runs with jerk limits: the default's share of the jerk-limited optimum."""
    rows = _read_rows(out, JERK_PREFIX)
    meta = [json.loads(f.read_text()) for f in _files(out, JERK_PREFIX, ".json")]
    jerk_times = sorted({float(m.get("jerk_time", 0.0)) for m in meta})
    loads = [r["load1"] for r in rows if np.isfinite(r["load1"])]
    tasks = _by_task(rows, "nominal")
    lines = [
        "## Optimizer: the default against the jerk-limited optimum (benchmarks/optimizer_peers.py, jerk limits on)",
        "",
        f"Machine: {machine()}; one BLAS/OpenMP thread per solve; the machine was shared with other work "
        + (
            f"(1-minute load average {min(loads):.1f} to {max(loads):.1f}, median {statistics.median(loads):.1f}, "
            "on 2 logical CPUs), so wall times are longer than on an idle core. "
            if loads
            else ". "
        )
        + "Code: "
        + "; ".join(
            f"commit {m.get('commit', '?')[:10]} (run started {m.get('started', '?')} UTC)" for m in meta
        )
        + ".",
        "",
        "Every method, the reference included, plans within the acceleration limits v_max / "
        f"{ACCEL_TIME} s and the jerk limits v_max / {ACCEL_TIME} s / jerk_time (jerk_time "
        + ", ".join(f"{j:g}" for j in jerk_times)
        + " s, the default `--jerk-time`); limits and energies on the 10x grid. Share of the optimum = "
        "(E_default_move - E_method) / (E_default_move - E_optimum), the optimum being the better valid IPOPT "
        "solve of the jerk-limited reference transcription (from the minimum-jerk move, and from the default's "
        "path). Same tasks as the section above (seed 11, lab ranges, T in [1, 3] s), the first ones that fit "
        "the run's time.",
        "",
    ]
    table, n = _method_table(
        tasks, ("default", "reference-mj", "reference-ours"), ("default",), with_fixed=True
    )
    lines += [f"**{n} tasks with jerk limits** (the fixed task of issue 11 included):", "", *table, ""]
    fx = tasks.get("fixed")
    if fx and "default" in fx and _optimum(fx):
        lines.append(
            f"Fixed task: the default reaches {100 * _share(fx['default'], _optimum(fx)):.1f} % of the jerk-limited "
            f"optimum's saving ({fx['default']['energy_fine_J']:.3f} J against {_optimum(fx)['energy_fine_J']:.3f} J; "  # type: ignore[index]
            f"minimum-jerk move {fx['default']['energy_default_fine_J']:.3f} J)."
        )
    lines += ["", f"Raw rows: `benchmarks/results/{JERK_PREFIX}_*.csv` ({len(rows)} rows)."]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--tasks", type=int, default=20, help="random tasks to run (from --first)")
    parser.add_argument("--first", type=int, default=0, help="index of the first task of the draw")
    parser.add_argument("--seed", type=int, default=11, help="seed of the task draw and of every search")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    parser.add_argument("--methods", default=",".join(ALL_METHODS))
    parser.add_argument("--skip-reference", action="store_true")
    parser.add_argument("--friction", choices=("nominal", "none"), default="nominal")
    parser.add_argument("--fixed", action="store_true", help="run the issue's fixed task first")
    parser.add_argument(
        "--jerk-time",
        type=float,
        default=JERK_TIME,
        help="s: jerk limits v_max / ACCEL_TIME / this for every method (0: none, as before jerk limits)",
    )
    parser.add_argument(
        "--time-cap-min", type=float, default=60.0, help="start no new task after this many minutes"
    )
    parser.add_argument("--deadline", type=float, default=None, help="epoch seconds; start no task after it")
    parser.add_argument("--unmeasured", default="", help="a sentence for the report's 'Not measured' line")
    parser.add_argument("--report-only", action="store_true")
    parser.add_argument("--no-report", action="store_true")
    parser.add_argument(
        "--prefix",
        default="optimizer_peers",
        help="file-name prefix of the CSV/JSON; 'timing' marks a speed-only pass the report summarizes apart",
    )
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.report_only:
        if args.prefix == JERK_PREFIX:
            text = report_jerk(args.out)
            write_section(JERK_SECTION, text)
            print(text)
            return
        text = report(args.out, args.unmeasured)
        write_section(SECTION, text)
        print(text)
        return
    methods = tuple(m for m in args.methods.split(",") if m)
    if args.skip_reference:
        methods = tuple(m for m in methods if m != "reference")
    if args.friction == "none":
        methods = tuple(m for m in methods if m in NO_FRICTION_METHODS)
    t_start = time.time()
    deadline = t_start + 60 * args.time_cap_min
    if args.deadline is not None:
        deadline = min(deadline, args.deadline)
    robot = joulepath.load_robot("irb120")
    # the draw as it was before jerk limits (same task numbers); a task whose minimum-jerk move
    # breaks the jerk limit is skipped below
    all_tasks = random_tasks(robot, args.first + args.tasks, seed=args.seed, range_set="lab", jerk_time=0)
    span = f"{args.first:02d}-{args.first + args.tasks - 1:02d}" if args.tasks > 0 else "none"
    jerk_tag = f"jerk{args.jerk_time:g}_" if args.jerk_time > 0 else ""  # untagged: no jerk limit
    tag = f"{args.friction}_{jerk_tag}{'fixed_' if args.fixed else ''}{span}_{'-'.join(methods)}"
    out_csv = args.out / f"{args.prefix}_{tag}.csv"
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    dirty = subprocess.run(
        ["git", "status", "--porcelain", "src/joulepath/optimize"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    meta = {
        "commit": commit,
        "optimize_dirty": dirty,
        "seed": args.seed,
        "first": args.first,
        "tasks": args.tasks,
        "methods": methods,
        "friction": args.friction,
        "jerk_time": args.jerk_time,
        "nproc": os.cpu_count(),
        "machine": machine(),
        "started": time.strftime("%Y-%m-%d %H:%M:%S"),
        "load_at_start": os.getloadavg(),
        "unmeasured": args.unmeasured,
    }
    meta_path = args.out / f"{args.prefix}_{tag}.json"
    meta_path.write_text(json.dumps(meta, indent=2))
    bench = Bench(robot, args, out_csv)
    done, longest = 0, 0.0
    todo: list[tuple[str, np.ndarray, np.ndarray, float]] = []
    if args.fixed:
        todo.append(("fixed", *FIXED_TASK))
    todo += [(str(k), *all_tasks[k]) for k in range(args.first, args.first + args.tasks)]
    for name, q0, qf, T in todo:
        now = time.time()
        if now + 0.5 * longest > deadline:
            print(f"time cap: stopping before task {name} ({done} done)", flush=True)
            break
        try:
            check_default_feasible(robot, q0, qf, T, jerk_time=args.jerk_time)
        except LimitViolation as err:
            print(f"task {name}: skipped, its default move breaks the jerk limit ({err})", flush=True)
            continue
        print(f"task {name}: T = {T:.3f} s", flush=True)
        t0 = time.time()
        bench.task(name, q0, qf, T, methods)
        longest = max(longest, time.time() - t0)
        done += 1
    meta.update(finished=time.strftime("%Y-%m-%d %H:%M:%S"), tasks_done=done, load_at_end=os.getloadavg())
    meta_path.write_text(json.dumps(meta, indent=2))
    if not args.no_report:
        if args.prefix == JERK_PREFIX:
            write_section(JERK_SECTION, report_jerk(args.out))
        else:
            write_section(SECTION, report(args.out))


if __name__ == "__main__":
    main()
