"""Terms joulepath's identification does not model yet, measured on the KUKA KR300 logs (issue 50, item 2).

A side experiment beside ``benchmarks/identify_real.py --study``: the same held-out runs and the
same reference (each run held out in turn, its raw logged joint torque), but a plain weighted
least-squares fit of the full inertial regressor (Pinocchio's, 10 parameters a link; the
minimum-norm solution, which predicts like the base parameters) plus friction columns, with the
gear efficiency fixed at 1. It reproduces the library's least-squares figure for the friction
model of the study's Stribeck step (0.848 here against 0.849), then adds, one at a time:

* ``armature``: a rotor inertia per joint (``I_a qdd_i`` on joint i alone). The log's own
  parameter file gives ``J_mr u²`` = 609, 844, 751, 488, 574 and 238 kg m² (joint side), far
  above the wrist links' inertias, which the rigid-body model alone cannot carry consistently;
* ``balancer``: a cubic polynomial in ``q2`` on joint 2 (its hydraulic weight counterbalance);
* ``bias``: a constant torque per joint, at rest too (a sensor offset);
* the torque one sample (4 ms) earlier, as in the study.

Nothing here enters a twin: joulepath's dynamics hold no armature and no balancer yet. Writes the
``identify_real_terms`` section of BENCHMARKS.md.

Usage: python benchmarks/identify_real_terms.py [--data FOLDER]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402

import joulepath  # noqa: E402
from joulepath.identify import data_from_logs, inertial_regressor  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from identify_real import START_DEG, kr300_urdf  # noqa: E402
from unknown_arm import DEFAULT_DATA, RUNS, write_generic_log  # noqa: E402

SMOOTHING, STRIBECK = 2e-4, 0.01
"""The study's Stribeck step: Coulomb switch width and Stribeck speed (rad/s)."""


def _diag(values: np.ndarray) -> np.ndarray:
    N, n = values.shape
    out = np.zeros((N, n, n))
    out[:, np.arange(n), np.arange(n)] = values
    return out


def columns(robot: joulepath.Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, terms: tuple[str, ...]):
    """``(N, n, p)``: the inertial regressor, the study's friction, and ``terms``."""
    s = np.tanh(qd / SMOOTHING)
    blocks = [
        inertial_regressor(robot, q, qd, qdd),
        _diag(s),
        _diag(qd),
        _diag(np.abs(s)),
        _diag(qd * s),
        _diag(np.exp(-((qd / STRIBECK) ** 2)) * s),
    ]
    if "armature" in terms:
        blocks.append(_diag(qdd))
    if "bias" in terms:
        blocks.append(_diag(np.ones_like(qd)))
    if "balancer" in terms:
        spring = np.zeros((q.shape[0], q.shape[1], 3))
        spring[:, 1, :] = np.column_stack([q[:, 1], q[:, 1] ** 2, q[:, 1] ** 3])
        blocks.append(spring)
    return np.concatenate(blocks, axis=2)


def _solve(A: np.ndarray, b: np.ndarray, w: np.ndarray) -> np.ndarray:
    N, n, p = A.shape
    Aw = (A * w[None, :, None]).reshape(N * n, p)
    scale = np.linalg.norm(Aw, axis=0)
    scale[scale == 0] = 1.0
    return np.linalg.lstsq(Aw / scale, (b * w).reshape(N * n), rcond=1e-10)[0] / scale


def held_out_r2(robot, data, terms: tuple[str, ...], shift: int) -> np.ndarray:
    """R² per joint (rows: the held-out runs A, B, C) of the weighted least-squares fit."""

    def arrays(d):
        q, qd, qdd, tau = d.q, d.qd, d.qdd, d.tau
        if shift < 0:  # the torque logged one sample before the motion it is paired with
            return q[-shift:], qd[-shift:], qdd[-shift:], tau[:shift]
        return q, qd, qdd, tau

    out = []
    for held in RUNS:
        parts = [arrays(data[r]) for r in RUNS if r != held]
        A = np.concatenate([columns(robot, *p[:3], terms) for p in parts])
        b = np.concatenate([p[3] for p in parts])
        x = _solve(A, b, np.ones(b.shape[1]))
        w = 1.0 / (b - A @ x).std(axis=0)  # the second, weighted pass
        x = _solve(A, b, w)
        q, qd, qdd, tau = arrays(data[held])
        pred = columns(robot, q, qd, qdd, terms) @ x
        out.append(1.0 - ((tau - pred) ** 2).sum(0) / ((tau - tau.mean(0)) ** 2).sum(0))
    return np.array(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    steps = (
        ("the study's Stribeck step (library least squares: 0.849)", (), 0),
        ("+ armature", ("armature",), 0),
        ("+ armature + balancer on joint 2", ("armature", "balancer"), 0),
        ("+ armature + bias", ("armature", "bias"), 0),
        ("+ armature, torque 1 sample earlier", ("armature",), -1),
    )
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "kr300.urdf").write_text(kr300_urdf())
        robot = joulepath.load_robot(d / "kr300.urdf")
        logs = {
            r: write_generic_log(args.data / f"recorded_FF_{r}.mat", d / f"{r}.csv", START_DEG) for r in RUNS
        }
        data = {r: data_from_logs([logs[r]], robot) for r in RUNS}
        for label, terms, shift in steps:
            r2 = held_out_r2(robot, data, terms, shift)
            rows.append((label, r2))
            print(label, np.round(r2.mean(0), 3), round(float(r2.mean()), 3), flush=True)
    lines = [
        "## Terms identification does not model yet: KUKA KR300 (benchmarks/identify_real_terms.py)",
        "",
        f"Machine: {machine()}. Data as in the study above (each run held out, its raw joint torque). "
        "Plain weighted least squares of the full inertial regressor plus the study's friction "
        "(viscous per direction, smoothing 0.0002 rad/s, Stribeck 0.01 rad/s), gear efficiency 1; "
        "not physically constrained, and nothing of it enters a twin.",
        "",
        "| fit | held-out torque R² per joint (mean of 3 runs) | mean | per held-out run (A, B, C) |",
        "|---|---|---|---|",
    ]
    for label, r2 in rows:
        lines.append(
            f"| {label} | {', '.join(f'{v:.3f}' for v in r2.mean(0))} | {r2.mean():.3f} | "
            f"{', '.join(f'{v:.3f}' for v in r2.mean(1))} |"
        )
    write_section("identify_real_terms", "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
