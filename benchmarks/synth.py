"""Synthetic data from the micro set: time, quality, utility and physical consistency (issue 4, item 6).

Data: the thesis plan simulated with ``simulate_plan(seed=0)`` (``joulepath simulate
--plan thesis``): real = 1000 lab moves, micro = 100 lab moves, test = 100 other lab
moves, each from its own child of ``SeedSequence(0)``.

For each SDV method (GaussianCopula, CTGAN, CopulaGAN, TVAE; SDV's default 300
epochs, batch 500, seed 0, one thread): fit on micro, sample 75,000 rows, then
* SDMetrics quality against micro (the data the synthesizer saw, as in the thesis):
  column shapes, column pair trends over all pairs (the thesis' definition) and over
  pairs whose real |correlation| > 0.5 (recent SDMetrics' default), overall;
* the share of rows whose TCP position is within 5 mm of FK(q);
* train-on-synthetic / test-on-real: the fixed MLP (StandardScaler + MLP (64, 64),
  early stopping) trained on the 75,000 rows, tested on the test moves, R² and MAE
  of E; also after ``repair_kinematics``.
Baselines in the same run: the same MLP trained on the real 1000-move set and on micro.

Usage: python benchmarks/synth.py [--epochs N] [--methods tvae,ctgan,...] [--rows N]
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

import joulepath  # noqa: E402
from joulepath.data import load_table  # noqa: E402
from joulepath.sim import THESIS_PLAN, simulate_plan  # noqa: E402
from joulepath.synth import (  # noqa: E402
    METHODS,
    SynthConfig,
    Synthesizer,
    _sdv,
    kinematic_consistency,
    model_columns,
    quality_report,
    repair_kinematics,
    utility,
)

GOAL_SHAPES, GOAL_PAIRS, GOAL_R2_GAP = 0.93, 0.98, 0.01


def log(msg: str) -> None:
    print(msg, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--epochs", type=int, default=300, help="epochs of the neural methods (SDV: 300)")
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--rows", type=int, default=75000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    methods = [m for m in args.methods.split(",") if m]
    robot = joulepath.load_robot("irb120")
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        simulate_plan(tmp, seed=0, plan=THESIS_PLAN, workers=2)
        real, micro, test = (load_table(Path(tmp) / f"{n}.parquet") for n in ("real", "micro", "test"))
    log(f"data: real {len(real.frame):,} rows, micro {len(micro.frame):,}, test {len(test.frame):,}")
    base_real = utility(real, test, seed=args.seed)
    base_micro = utility(micro, test, seed=args.seed)
    log(f"train-on-real R2 {base_real.r2:.4f}, train-on-micro R2 {base_micro.r2:.4f}")

    rows = []
    worst = {}
    for method in methods:
        config = SynthConfig(method=method, epochs=args.epochs, batch_size=500, seed=args.seed)
        t0 = time.perf_counter()
        synth = Synthesizer(config).fit(micro)
        t_fit = time.perf_counter() - t0
        t0 = time.perf_counter()
        synthetic = synth.sample(args.rows)
        t_sample = time.perf_counter() - t0
        cols = [*model_columns(micro.feature_set), "E"]
        shapes, pairs, overall, details = _sdv.quality_scores(micro.frame, synthetic.frame, cols)
        strong = quality_report(micro, synthetic, correlation_threshold=0.5)["column_pair_trends"]
        worst[method] = details.sort_values("Score").head(4)[["Column", "Score"]].to_records(index=False)
        share = kinematic_consistency(synthetic, robot)
        raw = utility(synthetic, test, seed=args.seed)
        fixed = utility(repair_kinematics(synthetic, robot), test, seed=args.seed)
        row = {
            "method": method,
            "epochs": "-" if method == "copula" else str(args.epochs),
            "fit": t_fit,
            "sample": t_sample,
            "shapes": shapes,
            "pairs": pairs,
            "strong": strong,
            "overall": overall,
            "share": share,
            "r2": raw.r2,
            "mae": raw.mae,
            "r2_fixed": fixed.r2,
            "mae_fixed": fixed.mae,
        }
        rows.append(row)
        log(
            f"{method}: fit {t_fit:.1f} s, sample {t_sample:.1f} s, shapes {shapes:.3f}, pairs {pairs:.3f} "
            f"(|r|>0.5: {strong:.3f}), TCP ok {share:.1%}, TSTR R2 {raw.r2:.4f} (repaired {fixed.r2:.4f})"
        )
    total = time.perf_counter() - t_start

    lines = [
        "## Synthetic data (benchmarks/synth.py)",
        "",
        f"Machine: {machine()}; one thread (torch, BLAS).",
        f"Data: thesis plan, seed 0 — micro {len(micro.frame):,} rows (100 lab moves) to learn from, "
        f"real {len(real.frame):,} rows (1000 lab moves), test {len(test.frame):,} rows "
        "(100 other lab moves).",
        f"Each method: fit on micro ({args.epochs} epochs for the neural methods, batch 500, seed "
        f"{args.seed}), sample {args.rows:,} rows; one run each (no repeats). Quality: SDMetrics "
        f"{_sdv.versions()['sdmetrics']} against micro, on the {len(cols)} modelled columns. "
        "Utility: StandardScaler + MLP (64, 64), early stopping, trained on the table, tested on "
        "the test moves (R², MAE of E per row, J).",
        "",
        "| method | epochs | fit | sample | column shapes | pair trends, all pairs "
        "| pair trends, real abs(r) > 0.5 | overall | rows within 5 mm of FK(q) "
        "| train-on-synthetic R² (E) | MAE (J) | R² after repair_kinematics | MAE after repair |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['method']} | {r['epochs']} | {r['fit']:.1f} s | {r['sample']:.1f} s | {r['shapes']:.3f} "
            f"| {r['pairs']:.3f} | {r['strong']:.3f} | {r['overall']:.3f} | {r['share']:.1%} "
            f"| {r['r2']:.4f} | {r['mae']:.4f} | {r['r2_fixed']:.4f} | {r['mae_fixed']:.4f} |"
        )
    lines += [
        f"| train on real (1000 moves, baseline) | | | | | | | | 100.0% | {base_real.r2:.4f} "
        f"| {base_real.mae:.4f} | | |",
        f"| train on micro (100 moves, baseline) | | | | | | | | 100.0% | {base_micro.r2:.4f} "
        f"| {base_micro.mae:.4f} | | |",
        "",
        "Lowest column-shape scores: "
        + "; ".join(f"{m}: " + ", ".join(f"{c} {s:.2f}" for c, s in recs) for m, recs in worst.items())
        + ".",
        "",
    ]
    goals = []
    tvae = next((r for r in rows if r["method"] == "tvae"), None)
    if tvae is not None:
        ok = tvae["shapes"] >= GOAL_SHAPES and tvae["pairs"] >= GOAL_PAIRS
        goals.append(
            f"Goal TVAE column shape >= {GOAL_SHAPES} and pair >= {GOAL_PAIRS} (thesis, all pairs): "
            f"{tvae['shapes']:.3f} / {tvae['pairs']:.3f} — {'meets' if ok else 'MISSES'}."
        )
    if rows:
        best = max(rows, key=lambda r: max(r["r2"], r["r2_fixed"]))
        best_r2 = max(best["r2"], best["r2_fixed"])
        gap = base_real.r2 - best_r2
        goals.append(
            f"Goal best train-on-synthetic R² within {GOAL_R2_GAP} of train-on-real: {best['method']} "
            f"{best_r2:.4f} vs {base_real.r2:.4f} (gap {gap:+.4f}) — "
            f"{'meets' if gap <= GOAL_R2_GAP else 'MISSES'}."
        )
    lines += goals
    lines += ["", f"Whole benchmark: {total / 60:.1f} min."]
    text = "\n".join(lines)
    print(text)
    write_section("synth", text)


if __name__ == "__main__":
    main()
