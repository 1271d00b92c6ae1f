"""Energy models of an arm joulepath does not know, judged on real logs held out by run (issue 50, item 3).

Data: the KUKA KR300 R2500 ultra logs of Weigand et al. (MIT; ``--data`` folder, default
``../shared/datasets/kuka-kr300-weigand`` beside the repository): three excitation runs
(A, B, C) of 10 s at 250 Hz; positions and speeds of the motor encoders (joint side),
motor torque (``act_torque_abs_nm``) times the gear ratio ``para.u`` as the joint torque.
Each run is written as a generic joint log (rad, rad/s, N·m) cut into 0.5 s moves (a
``move`` column: the excitation never rests), and ingested without a robot.

For each run held out, the other two train energy models these ways:

* ``thesis, CV by move``: the quick MLP on the raw inputs, grid search grouped by move
  (the default before commit 4cf0295);
* ``physics (IRB 120), CV by move``: the quick MLP on the grey-box inputs of the IRB 120,
  which the version before commit 0b4c37a computed for any table;
* ``kinematic, CV by run``: the quick MLP on the kinematic inputs, CV by run (two folds:
  the default of the last measure, 0.790);
* each family of this version with its defaults (no robot: kinematic inputs; CV grouped
  by contiguous spans of each run's moves, 5 folds);
* ``default``: ``train`` with every family, the model with the best grouped-CV R² (what
  ``best_model`` and the optimizer take).

Each line gives the CV estimate of the chosen candidate beside the held-out R² (per row,
and of the moves' energies). Writes the ``unknown_arm`` section of BENCHMARKS.md.

Usage: python benchmarks/unknown_arm.py [--data FOLDER]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import warnings
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import scipy.io  # noqa: E402

from joulepath.data import EnergyTable, ingest  # noqa: E402
from joulepath.learn import TrainConfig, train  # noqa: E402

RUNS = "ABC"
MOVE_S = 0.5
DEFAULT_DATA = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "kuka-kr300-weigand"


def write_generic_log(mat: Path, out: Path, start_deg: tuple[float, ...] = (0.0,) * 6) -> Path:
    """One KR300 run as a generic joint log with 0.5 s moves; ``start_deg`` added to the positions
    (the logs give them from the run's start pose)."""
    m = scipy.io.loadmat(mat, squeeze_me=True, struct_as_record=False)
    rec, gear = m["rec"], np.asarray(m["para"].u, dtype=float)
    t = np.asarray(rec.time_cont, dtype=float)
    q = np.radians(np.asarray(rec.act_pos_mot_deg, dtype=float).T + np.asarray(start_deg))
    qd = np.radians(np.asarray(rec.act_vel_mot_deg_per_s, dtype=float).T)
    tau = np.asarray(rec.act_torque_abs_nm, dtype=float).T * gear
    move = np.minimum(np.floor(t / MOVE_S), np.floor(t[-1] / MOVE_S) - 1).astype(int)
    frame = pd.DataFrame({"t": t})
    for i in range(6):
        frame[f"q{i + 1}"], frame[f"dq{i + 1}"], frame[f"tau{i + 1}"] = q[:, i], qd[:, i], tau[:, i]
    frame["move"] = move
    frame.to_csv(out, index=False, float_format="%.10g")
    return out


def one_log(table: EnergyTable) -> EnergyTable:
    """The table as if ingested from one log: its CV groups are its moves (the earlier behaviour)."""
    n = int(table.frame["move_id"].nunique())
    return replace(table, sources=({"file": "joined", "first_move_id": 0, "moves": n},))


def move_r2(table: EnergyTable, model_folder: Path) -> float:
    from joulepath.learn import EnergyModel

    model = EnergyModel.load(model_folder)
    frame = table.frame
    per_move = pd.DataFrame({"m": frame["move_id"], "y": frame["E"], "p": model.predict(frame)})
    sums = per_move.groupby("m").sum()
    return float(1.0 - ((sums.p - sums.y) ** 2).sum() / ((sums.y - sums.y.mean()) ** 2).sum())


def _row(held: str, way: str, r: pd.Series, test_table: EnergyTable, folder: Path) -> dict[str, object]:
    return {
        "held out": held,
        "way": way,
        "family": r["family"],
        "inputs": r["inputs"],
        "cv_r2": float(r["cv_grouped_r2"]),
        "cv": f"{r['cv_grouped_r2']:.3f} (by {r['cv_groups']})",
        "held-out R² (rows)": float(r["test_r2"]),
        "held-out R² (moves)": move_r2(test_table, folder),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    earlier = {
        "thesis, CV by move": (dict(inputs="thesis", cv=5), True),
        "physics (IRB 120), CV by move": (dict(inputs="physics", robot="irb120", cv=5), True),
        "kinematic, CV by run (last measure's default)": (dict(inputs="kinematic", cv=2), False),
    }
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        logs = {r: write_generic_log(args.data / f"recorded_FF_{r}.mat", d / f"kr300_{r}.csv") for r in RUNS}
        for held in RUNS:
            train_table = ingest([logs[r] for r in RUNS if r != held])
            test_table = ingest([logs[held]])
            for k, (way, (options, by_move)) in enumerate(earlier.items()):
                config = TrainConfig(families=("mlp",), targets=("E",), seed=0, **options)
                out = d / f"{held}-earlier-{k}"
                report = train(one_log(train_table) if by_move else train_table, test_table, config, out)
                rows.append(_row(held, way, report.results.iloc[0], test_table, report.models["mlp-E"]))
                print(rows[-1], flush=True)
            report = train(train_table, test_table, TrainConfig(targets=("E",), seed=0), d / f"{held}-now")
            now = []
            for _, r in report.results.iterrows():
                now.append(
                    _row(
                        held, f"{r['family']}, this version", r, test_table, report.models[f"{r['family']}-E"]
                    )
                )
                print(now[-1], flush=True)
            best = max(now, key=lambda row: float(row["cv_r2"]))  # type: ignore[arg-type]
            rows += now + [{**best, "way": f"default: every family, best by CV ({best['family']})"}]
    table = pd.DataFrame(rows)
    table["way_key"] = table["way"].str.replace(r" \(.*\)$", "", regex=True)
    mean = table.groupby("way_key", sort=False)[["held-out R² (rows)", "held-out R² (moves)"]].mean()
    lines = [
        "## Energy models of an arm joulepath does not know (benchmarks/unknown_arm.py)",
        "",
        f"Machine: {machine()}; one thread. Data: KUKA KR300 R2500 ultra, Weigand et al. (MIT), three "
        "10 s excitation runs at 250 Hz, cut into 0.5 s moves (19 a run); each run held out in turn, the "
        "other two train (`train`, quick grids).",
        "",
        "| held out | way | family | inputs | CV estimate | held-out R² (rows) | held-out R² (move energies) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['held out']} | {r['way']} | {r['family']} | {r['inputs']} | {r['cv']} | "
            f"{r['held-out R² (rows)']:.3f} | {r['held-out R² (moves)']:.3f} |"
        )
    lines += ["", "Mean over the three held-out runs:", ""]
    for way, m in mean.iterrows():
        lines.append(f"- {way}: rows {m.iloc[0]:.3f}, move energies {m.iloc[1]:.3f}")
    write_section("unknown_arm", "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
