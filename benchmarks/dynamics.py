"""Batched inverse-dynamics throughput on one core (issue: foundation, item 8).

Workload: 4,000 samples = a population of 100 paths x 40 samples of the IRB 120.
Implementations:
  * pinocchio batched  - ``Robot.inverse_dynamics`` (one ``rneaInParallel`` call, 1 thread)
  * pinocchio loop     - baseline: ``pin.rnea`` called once per sample from Python
  * lagrange-euler     - our vectorized NumPy Lagrange-Euler (the cross-check)
Target for the fast path: >= 1,000,000 samples/s on one core.

Usage: python benchmarks/dynamics.py [--repeats N]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, median_time, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402

import joulepath  # noqa: E402

N_PATHS, N_STEPS = 100, 40


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()

    import pinocchio as pin

    robot = joulepath.load_robot("irb120")
    rng = np.random.default_rng(0)
    shape = (N_PATHS, N_STEPS, 6)
    q, qd, qdd = (rng.uniform(-2, 2, size=shape) for _ in range(3))
    n = N_PATHS * N_STEPS
    model = robot.pinocchio_model
    data = model.createData()
    qf, qdf, qddf = (a.reshape(-1, 6) for a in (q, qd, qdd))

    def loop() -> None:
        out = np.empty((n, 6))
        for k in range(n):
            out[k] = pin.rnea(model, data, qf[k], qdf[k], qddf[k])

    rows = [
        (
            "pinocchio batched (Robot.inverse_dynamics)",
            median_time(lambda: robot.inverse_dynamics(q, qd, qdd), repeats=args.repeats),
        ),
        (
            "pinocchio loop, one pin.rnea call per sample (baseline)",
            median_time(loop, repeats=max(3, args.repeats // 3)),
        ),
        (
            "lagrange-euler, NumPy vectorized (cross-check)",
            median_time(
                lambda: robot.inverse_dynamics(q, qd, qdd, method="lagrange-euler"),
                repeats=max(3, args.repeats // 3),
            ),
        ),
    ]
    baseline = rows[1][1]
    lines = [
        "## Inverse dynamics (benchmarks/dynamics.py)",
        "",
        f"Machine: {machine()}; one thread.",
        f"Workload: {n:,} samples of the IRB 120 (population {N_PATHS} paths x {N_STEPS} samples), "
        "random q, qd, qdd. Target for the fast path: >= 1,000,000 samples/s.",
        "",
        "| implementation | median time for 4,000 samples | samples/s | speed vs baseline |",
        "|---|---|---|---|",
    ]
    for name, t in rows:
        lines.append(f"| {name} | {t * 1e3:.3f} ms | {n / t:,.0f} | {baseline / t:.2f}x |")
    fast = n / rows[0][1]
    lines += [
        "",
        f"Fast path: {fast:,.0f} samples/s ({'meets' if fast >= 1e6 else 'MISSES'} the 1,000,000 target).",
    ]
    text = "\n".join(lines)
    print(text)
    write_section("dynamics", text)


if __name__ == "__main__":
    main()
