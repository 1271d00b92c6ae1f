"""Energy models (issue: models, item 10).

* the thesis grids' sizes (fits = candidates x 5 folds) and their estimated cost on
  this machine (median fit time of a sample of candidates, measured here, times the
  number of fits);
* the quick grid's wall time per family;
* ``predict_rows`` latency for 4,000 rows (target <= 1 ms for the MLP), against
  ``pipeline.predict`` on a DataFrame as the baseline;
* grouped-CV and path-level figures of each family's best quick model on simulated
  lab data (train: 100 lab moves, test: 50 other lab moves), both input kinds.

Usage: python benchmarks/learn.py
       python benchmarks/learn.py --tour DATA TEST   (the full-size train command of
       docs/tutorials/thesis-method.md: time ``joulepath train --family all --grid quick``
       on DATA/TEST, e.g. the tables of ``simulate --plan thesis``; prints the timed
       progress lines, wall and CPU time; writes nothing)
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, median_time, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402
from sklearn.model_selection import ParameterGrid  # noqa: E402

import joulepath  # noqa: E402
from joulepath.data import ingest  # noqa: E402
from joulepath.learn import (  # noqa: E402
    FAMILIES,
    THESIS_GRIDS,
    EnergyModel,
    TrainConfig,
    input_columns,
    make_pipeline,
    make_splits,
    train,
)
from joulepath.learn._search import cross_validate_candidate  # noqa: E402
from joulepath.sim import simulate  # noqa: E402


def main() -> None:
    robot = joulepath.load_robot("irb120")
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        tr = ingest([simulate(d / "tr.csv", plant="lab", n_moves=100, seed=21).log], robot=robot)
        te = ingest([simulate(d / "te.csv", plant="lab", n_moves=50, seed=22).log], robot=robot)
        lines = [
            "## Energy models (benchmarks/learn.py)",
            "",
            f"Machine: {machine()}; one thread.",
            f"Data: simulated lab robot, train {len(tr.frame):,} rows / {tr.n_moves} moves, "
            f"test {len(te.frame):,} rows / {te.n_moves} other moves; target E.",
            "",
            "### Quick grids, 3 grouped folds (headline) and the thesis' shuffled folds",
            "",
            "| inputs | family | grouped CV R² | shuffled CV R² | test R² | test MAE (J/row) | "
            "path error median % | path error p95 % | search wall s |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        folders = {}
        for inputs in ("physics", "thesis"):
            t0 = time.perf_counter()
            rep = train(tr, te, TrainConfig(cv=3, inputs=inputs), d / inputs)
            folders[inputs] = rep.models
            for r in rep.results.itertuples():
                lines.append(
                    f"| {inputs} | {r.family} | {r.cv_grouped_r2:.4f} | {r.cv_shuffled_r2:.4f} | {r.test_r2:.4f} | "
                    f"{r.test_mae:.4f} | {r.path_median_pct:.1f} | {r.path_p95_pct:.1f} | {r.search_s:.1f} |"
                )
            del t0
        lines += ["", "Analytical baseline on the same test rows (thesis §4.4):", ""]
        for b in rep.baselines:
            s = b["scores"]["E"]
            lines.append(
                f"- {b['label']}: R² {s['r2']:.4f}, MAE {s['mae']:.4f} J, path error median "
                f"{s['path_median_pct']:.1f} % (p95 {s['path_p95_pct']:.1f} %), "
                f"{b['latency_per_row_s_batch'] * 1e6:.2f} µs per row in a batch, "
                f"{b['latency_single_prediction_s'] * 1e3:.2f} ms for a single prediction, "
                f"description file {b['size_bytes'] / 1e3:.1f} kB"
            )
        lines += [
            "",
            "### predict_rows latency, 4,000 rows",
            "",
            "| model | predict_rows | DataFrame predict (baseline) | speed vs baseline | model files |",
            "|---|---|---|---|---|",
        ]
        rows = te.frame.iloc[:4000]
        for inputs in ("thesis", "physics"):
            for family in FAMILIES:
                folder = folders[inputs][f"{family}-E"]
                model = EnergyModel.load(folder)
                X = rows[list(model.input_columns)].to_numpy()
                fast = median_time(lambda m=model, x=X: m.predict_rows(x), repeats=30)
                slow = median_time(
                    lambda m=model: m.pipeline.predict(rows[list(m.input_columns)]), repeats=10
                )
                size = sum(p.stat().st_size for p in Path(folder).iterdir())
                lines.append(
                    f"| {family} ({inputs} inputs) | {fast * 1e3:.3f} ms | {slow * 1e3:.3f} ms | "
                    f"{slow / fast:.1f}x | {size / 1e3:.0f} kB |"
                )
        lines += [
            "",
            "### The thesis grids (Tables 2.2–2.5): size and estimated cost here",
            "",
            "| family | candidates | fits (5 folds) | median s per fit (sample of 3 candidates) | "
            "estimated single-core hours |",
            "|---|---|---|---|---|",
        ]
        cols = input_columns("full40", "thesis")
        sub = tr.frame.sample(n=min(3000, len(tr.frame)), random_state=0)
        X = sub[list(cols)].to_numpy()
        y = sub["E"].to_numpy()
        splits = make_splits(len(y), sub["move_id"].to_numpy(), split="grouped", n_splits=5, seed=0)[:1]
        for family, grid in THESIS_GRIDS.items():
            points = list(ParameterGrid(grid))
            pick = rng.choice(len(points), size=min(3, len(points)), replace=False)
            pipe = make_pipeline(family, seed=0, inputs="thesis", columns=cols)
            times = [cross_validate_candidate(pipe, points[i], X, y, splits)[2] for i in pick]
            per_fit = float(np.median(times))
            fits = 5 * len(points)
            lines.append(
                f"| {family} | {len(points):,} | {fits:,} | {per_fit:.3f} | {fits * per_fit / 3600:.1f} |"
            )
        lines += [
            "",
            f"(cost sampled on {len(y):,} training rows; the thesis' 75k-row sets cost more per fit)",
        ]
    text = "\n".join(lines)
    print(text)
    write_section("learn", text)


def tour(data: str, test: str) -> None:
    """Time the full-size train command (docs/tutorials/thesis-method.md) as a user runs it."""
    import os
    import resource
    import subprocess

    with tempfile.TemporaryDirectory() as tmp:
        argv = [sys.executable, "-m", "joulepath", "train", "--data", data, "--test", test]
        argv += ["--family", "all", "--grid", "quick", "--out", str(Path(tmp) / "models")]
        t0 = time.perf_counter()
        threads = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
        env = {k: v for k, v in os.environ.items() if k not in threads}  # as a user runs it
        proc = subprocess.Popen(argv, stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
        assert proc.stderr is not None
        for line in proc.stderr:
            print(f"[{time.perf_counter() - t0:6.0f} s] {line.rstrip()}", flush=True)
        out = proc.communicate()[0]
        wall = time.perf_counter() - t0
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(out)
    print(
        f"exit {proc.returncode}; wall {wall:.0f} s, CPU {usage.ru_utime + usage.ru_stime:.0f} s "
        f"({(usage.ru_utime + usage.ru_stime) / wall:.0%} of one core); machine: {machine()}"
    )


if __name__ == "__main__":
    if sys.argv[1:2] == ["--tour"] and len(sys.argv) == 4:
        tour(sys.argv[2], sys.argv[3])
    else:
        main()
