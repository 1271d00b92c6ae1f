"""Cost of the optimizer engine and of the trajectory parametrizations (issue 6, item 8).

Workload: population 100, 36 genes (a 6 x 6 chromosome per individual) on the thesis'
grid -10:0.05:10.
  * engine overhead per generation - ``algorithm.advance`` for GA (three recombinations),
    DE and both MA variants with a trivial vectorized fitness (sum of squares), so the
    time is the engine's own: selection, operators, grid snapping, replacement and the
    local search's candidate generation (MA random evaluates 1,000 neighbours).
  * trajectory generation - q, qd, qdd for 100 chromosomes at T = 2 s, dt = 0.025 s
    (81 samples): ``rest_to_rest`` and ``thesis_quintic`` batched, against the baseline
    of a plain Python loop generating the trajectories one chromosome at a time.
  * GA generation + rest_to_rest trajectories + a stand-in fitness (sum of qd² dt, no
    model): the part of the issue's 10 ms per generation budget that is not the model.

Usage: python benchmarks/evolve.py [--repeats N]
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, median_time, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402

from joulepath.evolve import DE, GA, MA, FunctionProblem, Population, sample_grid  # noqa: E402
from joulepath.trajectory import (  # noqa: E402
    GRID_HIGH,
    GRID_LOW,
    GRID_STEP,
    rest_to_rest,
    thesis_quintic,
)

N_POP, N_JOINTS, N_COEF = 100, 6, 6
N_VAR = N_JOINTS * N_COEF
DURATION, DT = 2.0, 0.025


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=31)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    xl, xu = np.full(N_VAR, GRID_LOW), np.full(N_VAR, GRID_HIGH)
    q0 = rng.uniform(-1.0, 1.0, N_JOINTS)
    qf = rng.uniform(-1.0, 1.0, N_JOINTS)

    trivial = FunctionProblem(lambda X: (X**2).sum(axis=1) + 1.0, n_var=N_VAR, xl=xl, xu=xu)
    X = sample_grid(N_POP, xl, xu, step=GRID_STEP, rng=rng)
    pop = Population(X=X, F=trivial.evaluate(X))

    algorithms = [
        ("GA random, P(C) 0.95, P(M) 0.05", GA()),
        ("GA average, P(C) 0.90, P(M) 0.05", GA(p_crossover=0.9, recombination="average")),
        ("GA differential, P(C) 0.95, F 0.05", GA(recombination="differential")),
        ("DE/rand/1/bin, F 0.5, CR 0.9", DE()),
        ("MA random (GA + 1,000 neighbours)", MA()),
        ("MA informed (GA + 20 steps on 2 joints)", MA(local_search="informed", joints=(0, 1))),
    ]
    engine_rows = []
    for name, algo in algorithms:
        gen_rng = np.random.default_rng(1)
        t = median_time(lambda a=algo, r=gen_rng: a.advance(trivial, pop, rng=r), repeats=args.repeats)
        engine_rows.append((name, t))

    C = X.reshape(N_POP, N_JOINTS, N_COEF)

    def loop(fn: Callable[..., object]) -> Callable[[], None]:
        def run() -> None:
            for c in C:
                fn(c, q0, qf, DURATION, dt=DT)

        return run

    traj_rows = []
    for name, fn in (("rest_to_rest", rest_to_rest), ("thesis_quintic", thesis_quintic)):
        batched = median_time(lambda f=fn: f(C, q0, qf, DURATION, dt=DT), repeats=args.repeats)
        looped = median_time(loop(fn), repeats=max(5, args.repeats // 3))
        traj_rows.append((name, batched, looped))

    def path_fitness(Xp: np.ndarray) -> np.ndarray:
        tr = rest_to_rest(Xp.reshape(-1, N_JOINTS, N_COEF), q0, qf, DURATION, dt=DT)
        return np.asarray((tr.qd**2).sum(axis=(1, 2)) * DT + 1e-9)

    path_problem = FunctionProblem(path_fitness, n_var=N_VAR, xl=xl, xu=xu)
    path_pop = Population(X=X, F=path_fitness(X))
    ga, ga_rng = GA(), np.random.default_rng(2)
    full = median_time(lambda: ga.advance(path_problem, path_pop, rng=ga_rng), repeats=args.repeats)

    n_steps = round(DURATION / DT) + 1
    lines = [
        "## Optimizer engine and trajectory parametrizations (benchmarks/evolve.py)",
        "",
        f"Machine: {machine()}; one thread.",
        f"Workload: population {N_POP}, {N_VAR} genes ({N_JOINTS} x {N_COEF} chromosome) on the grid "
        f"{GRID_LOW:g}:{GRID_STEP:g}:{GRID_HIGH:g}; trajectories at T = {DURATION:g} s, dt = {DT} s "
        f"({n_steps} samples). Medians of {args.repeats} repeats.",
        "",
        "Engine overhead per generation (`algorithm.advance`, trivial fitness sum(x²) + 1):",
        "",
        "| algorithm | median time per generation |",
        "|---|---|",
    ]
    lines += [f"| {name} | {t * 1e3:.3f} ms |" for name, t in engine_rows]
    lines += [
        "",
        f"Trajectory generation, q/qd/qdd for {N_POP} chromosomes (baseline: a Python loop over the "
        "chromosomes, one call each):",
        "",
        "| parametrization | batched | loop (baseline) | speed vs baseline |",
        "|---|---|---|---|",
    ]
    lines += [
        f"| {name} | {b * 1e3:.3f} ms | {lp * 1e3:.3f} ms | {lp / b:.1f}x |" for name, b, lp in traj_rows
    ]
    lines += [
        "",
        f"GA generation including rest_to_rest trajectories and a stand-in fitness (sum qd² dt, no "
        f"model): {full * 1e3:.3f} ms, i.e. {N_POP / full:,.0f} evaluations/s. The issue's budget is "
        "10 ms per generation with the learned model; what is left of it is the model's.",
    ]
    text = "\n".join(lines)
    print(text)
    write_section("evolve_engine", text)


if __name__ == "__main__":
    main()
