"""Dynamic identification (issue 13): a twin identified on the lab robot's logs, against the baselines.

* Train: 100 random moves of the emulated lab robot (controller log, 40 Hz, noise,
  tracking lag, gear losses, Stribeck friction); identify the twin from that log.
* Held out: 100 other lab moves: row energy R² and median path-energy error of the
  twin, the nominal physics (+ nominal friction) and the grey-box learned models
  (``inputs="physics"``, quick grids, trained on the same 100 moves).
* Out of distribution: ~20 paths optimized on the nominal physics (gradient search),
  and their minimum-jerk default moves, run on the lab plant; each model's
  path-energy error there.
* Closing the loop: ~10 tasks optimized on the twin; the twin's predicted saving
  (motor side, its gear efficiency included) against the saving realized on the lab
  plant; the same for the nominal physics.

* ``--rows N...``: models trained on twin-generated rows against models trained on
  the same number of real lab moves, tested on held-out lab moves (its own section).

Usage: python benchmarks/identify.py [--tasks 20] [--loop 10]
       python benchmarks/identify.py --rows 100 1000
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
from sklearn.metrics import r2_score  # noqa: E402

import joulepath  # noqa: E402
from joulepath.data import EnergyTable, ingest  # noqa: E402
from joulepath.dynamics import NOMINAL_FRICTION, Robot  # noqa: E402
from joulepath.energy import joint_energy, path_energy  # noqa: E402
from joulepath.identify import IdentifyOptions, data_from_logs, identify, twin_robot, write_twin  # noqa: E402
from joulepath.learn import EnergyModel, TrainConfig, path_errors, physics_predict, train  # noqa: E402
from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks  # noqa: E402
from joulepath.optimize._features import path_features  # noqa: E402
from joulepath.sim import make_plant, simulate  # noqa: E402
from joulepath.trajectory import Trajectory  # noqa: E402


def twin_rows(table: EnergyTable, twin: Robot) -> np.ndarray:
    """The twin's row energies ``E`` (motor side: its gear efficiency included)."""
    f = table.frame
    q, qd, qdd = (f[[f"{p}{i}" for i in range(1, 7)]].to_numpy() for p in ("q", "dq", "ddq"))
    assert twin.calibration is not None
    tau = twin.calibration.motor_torque(twin.inverse_dynamics(q, qd, qdd, friction=twin.friction), qd)
    out: np.ndarray = joint_energy(tau, qd, f["dt"].to_numpy()).sum(axis=1)
    return out


def twin_path_energy(twin: Robot, path: Trajectory) -> float:
    assert twin.calibration is not None
    tau = twin.inverse_dynamics(path.q, path.qd, path.qdd, friction=twin.friction)
    return float(path_energy(twin.calibration.motor_torque(tau, path.qd), path.qd, path.dt).total)


def lab_path_energy(lab: object, path: Trajectory) -> float:
    tau = lab.drive_torque(path.q, path.qd, path.qdd)  # type: ignore[attr-defined]
    return float(path_energy(tau, path.qd, path.dt).total)


def model_path_energy(model: EnergyModel, robot: Robot, path: Trajectory) -> float:
    return float(model.predict_rows(path_features(robot, path, model.input_columns)).sum())


def pct(a: float, b: float) -> float:
    return 100.0 * abs(a - b) / b


def main(n_tasks: int, n_loop: int) -> None:
    robot = joulepath.load_robot("irb120")
    lab = make_plant("lab", robot)
    lines = [
        "## Dynamic identification: a calibrated twin (benchmarks/identify.py, issue 13)",
        "",
        f"Machine: {machine()}; one thread.",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        tr_log = simulate(d / "tr.csv", plant="lab", n_moves=100, seed=131).log
        te_log = simulate(d / "te.csv", plant="lab", n_moves=100, seed=132).log
        tr, te = ingest([tr_log], robot=robot), ingest([te_log], robot=robot)
        variants = {
            "twin (Coulomb + viscous + offset, gear efficiency)": IdentifyOptions(),
            "twin (+ Stribeck, 0.05 rad/s)": IdentifyOptions(stribeck_speed=0.05),
        }
        twins: dict[str, Robot] = {}
        idents = {}
        t_ident = {}
        for label, options in variants.items():
            t0 = time.perf_counter()
            ident = identify(data_from_logs([tr_log], robot), robot, options)
            t_ident[label] = time.perf_counter() - t0
            idents[label] = ident
            twins[label] = twin_robot(robot, ident)
        t0 = time.perf_counter()
        report = train(tr, te, TrainConfig(families=("par", "mlp"), cv=3, inputs="physics"), d / "models")
        t_train = time.perf_counter() - t0
        grey = {fam: EnergyModel.load(report.models[f"{fam}-E"]) for fam in ("par", "mlp")}
        lines += [
            f"Data: lab plant, train {len(tr.frame):,} rows / {tr.n_moves} moves (one log, seed 131), "
            f"held out {len(te.frame):,} rows / {te.n_moves} moves (seed 132). Accelerations of the twin's "
            "data: central differences of the logged speeds.",
            "",
        ]
        for label, ident in idents.items():
            lines.append(
                f"- {label}: identified in {t_ident[label]:.1f} s from {ident.fit.n_samples:,} samples; "
                f"{ident.base.n} base parameters, condition number {ident.condition_number:.1f}, gear "
                f"efficiency {ident.gear_efficiency:.4f} (lab plant: 0.88), physically consistent: "
                f"{ident.consistent}"
            )
        lines += [
            f"- grey-box models (quick grids, par and mlp, physics inputs, 3 grouped folds): trained in "
            f"{t_train:.0f} s",
            "",
            "### Held-out lab moves (100), rows and paths",
            "",
            "| model | row energy R² | path-energy error median % | p95 % |",
            "|---|---|---|---|",
        ]
        y = te.frame["E"].to_numpy()
        moves = te.frame["move_id"].to_numpy()
        preds = {label: twin_rows(te, tw) for label, tw in twins.items()}
        preds["nominal physics + nominal friction"] = physics_predict(te, robot, friction=NOMINAL_FRICTION)[
            "E"
        ]
        preds["nominal physics, no friction"] = physics_predict(te, robot)["E"]
        for fam, model in grey.items():
            cols = list(model.input_columns)
            preds[f"grey-box {fam}"] = model.predict_rows(te.frame[cols].to_numpy())
        for label, p in preds.items():
            err = path_errors(moves, y, p)
            lines.append(
                f"| {label} | {r2_score(y, p):.4f} | {100 * np.median(err):.2f} | "
                f"{100 * np.percentile(err, 95):.2f} |"
            )

        # ---------------------------------------------- out of distribution
        tasks = random_tasks(robot, n_tasks, seed=133)
        results = []
        t0 = time.perf_counter()
        for q0, qf, T in tasks:
            results.append(optimize_move(robot, q0, qf, T, OptimizeConfig()))
        t_opt = time.perf_counter() - t0
        kinds = {
            "optimized on nominal physics": [r.optimized for r in results],
            "minimum-jerk defaults": [r.default for r in results],
        }
        lines += [
            "",
            f"### Out of distribution: {len(tasks)} random tasks (lab range set, 1-3 s), run on the lab plant",
            "",
            f"Paths optimized with the default search on the nominal physics ({t_opt:.0f} s in all), and "
            "their minimum-jerk defaults; lab energy = Σ |τ_motor qd| dt of the lab plant's drives.",
            "",
            "| model | path kind | path-energy error median % | max % |",
            "|---|---|---|---|",
        ]
        for kind, paths in kinds.items():
            measured = [lab_path_energy(lab, p) for p in paths]
            models: dict[str, list[float]] = {}
            for label, tw in twins.items():
                models[label] = [twin_path_energy(tw, p) for p in paths]
            models["nominal physics + nominal friction"] = [
                float(
                    path_energy(
                        robot.inverse_dynamics(p.q, p.qd, p.qdd, friction=NOMINAL_FRICTION), p.qd, p.dt
                    ).total
                )
                for p in paths
            ]
            for fam, model in grey.items():
                models[f"grey-box {fam}"] = [model_path_energy(model, robot, p) for p in paths]
            for label, est in models.items():
                errs = [pct(e, m) for e, m in zip(est, measured, strict=True)]
                lines.append(f"| {label} | {kind} | {np.median(errs):.2f} | {np.max(errs):.2f} |")

        # ---------------------------------------------- closing the loop
        label = next(iter(twins))
        twin = twins[label]
        lines += [
            "",
            f"### Closing the loop: {n_loop} tasks optimized on the twin ({label}), run on the lab plant",
            "",
            "Predicted saving: the twin's motor-side energies (gear efficiency included) of the default "
            "and the optimized path; realized: the lab plant's. The optimizer's fitness on a twin is its "
            "joint-side energy with identified friction (the gear efficiency is not in the search).",
            "",
            "| planned on | predicted saving median % | realized on lab median % | gap predicted vs realized "
            "median pp | max pp |",
            "|---|---|---|---|---|",
        ]
        rows = {"twin": [], "nominal physics": []}  # type: dict[str, list[tuple[float, float]]]
        for (q0, qf, T), r_nom in zip(tasks[:n_loop], results[:n_loop], strict=True):
            r = optimize_move(twin, q0, qf, T, OptimizeConfig())
            e_def, e_opt = twin_path_energy(twin, r.default), twin_path_energy(twin, r.optimized)
            s = r.summary
            assert s.saved_lab_pct is not None and r_nom.summary.saved_lab_pct is not None
            rows["twin"].append((100 * (e_def - e_opt) / e_def, s.saved_lab_pct))
            rows["nominal physics"].append((r_nom.summary.saved_pct, r_nom.summary.saved_lab_pct))
        for name, pairs in rows.items():
            arr = np.array(pairs)
            gap = np.abs(arr[:, 0] - arr[:, 1])
            lines.append(
                f"| {name} | {np.median(arr[:, 0]):.2f} | {np.median(arr[:, 1]):.2f} | {np.median(gap):.2f} | "
                f"{gap.max():.2f} |"
            )
    lines += [
        "",
        "Not in this section: models trained on SDV rows (the synthetic-data section measures them on their "
        "own data), the grey-box models' torque R² (they predict energy only; the twin's torque R² on held-out "
        "samples is on its card.json), and lab runs with the plant's tracking lag and noise for the optimized "
        "paths (their lab energy is the lab drives' torque on the planned motion, as `optimize` verifies it).",
    ]
    text = "\n".join(lines)
    print(text)
    write_section("identify", text)


def twin_rows_section(sizes: tuple[int, ...]) -> None:
    """Models trained on twin-generated rows against models trained on real (lab) rows."""
    robot = joulepath.load_robot("irb120")
    lines = [
        "## Training rows from the twin (benchmarks/identify.py --rows, issue 13)",
        "",
        f"Machine: {machine()}; one thread.",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        tr_log = simulate(d / "tr.csv", plant="lab", n_moves=100, seed=131).log
        te = ingest([simulate(d / "te.csv", plant="lab", n_moves=100, seed=132).log], robot=robot)
        ident = identify(data_from_logs([tr_log], robot), robot, IdentifyOptions())
        write_twin(ident, robot, d / "twin")
        lines += [
            f"Twin identified from 100 lab moves (seed 131). Test: {len(te.frame):,} rows / {te.n_moves} held-out "
            "lab moves (seed 132). Training sets: real = the lab plant, twin = `simulate --plant twin/` (the "
            "twin's identified physics, no sensor noise, no tracking lag), same random moves per size "
            "(seeds 141 + size). Quick grids, 3 grouped folds; test R² of the row energy E.",
            "",
            "| training rows | moves | rows | inputs | mlp test R² | xgb test R² | path error median % (best) | "
            "wall s |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for n in sizes:
            for source in ("real", "twin"):
                plant = "lab" if source == "real" else str(d / "twin")
                log = simulate(d / f"{source}{n}.csv", plant=plant, n_moves=n, seed=141 + n).log
                table = ingest([log], robot=robot)
                for inputs in ("physics", "thesis"):
                    t0 = time.perf_counter()
                    rep = train(
                        table,
                        te,
                        TrainConfig(families=("mlp", "xgb"), cv=3, inputs=inputs),
                        d / f"m-{source}-{n}-{inputs}",
                    )
                    wall = time.perf_counter() - t0
                    res = rep.results.set_index("family")
                    best = res["test_r2"].idxmax()
                    lines.append(
                        f"| {source} | {n} | {len(table.frame):,} | {inputs} | {res.loc['mlp', 'test_r2']:.4f} | "
                        f"{res.loc['xgb', 'test_r2']:.4f} | {res.loc[best, 'path_median_pct']:.1f} | {wall:.0f} |"
                    )
                    print(lines[-1], flush=True)
    text = "\n".join(lines)
    print(text)
    write_section("identify-rows", text)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", type=int, default=20)
    parser.add_argument("--loop", type=int, default=10)
    parser.add_argument(
        "--rows", type=int, nargs="*", help="only the twin-rows section, with these training sizes"
    )
    args = parser.parse_args()
    if args.rows:
        twin_rows_section(tuple(args.rows))
    else:
        main(args.tasks, args.loop)
