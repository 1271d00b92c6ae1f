"""Render a run folder into one self-contained ``report.html`` (images embedded as data URIs)."""

from __future__ import annotations

import base64
import html
import json
import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from joulepath._io import atomic_write_text
from joulepath._runfolder import IDENTIFY_LOOP, IDENTIFY_SCORES, IDENTIFY_STAGE, IDENTIFY_TWIN
from joulepath.report._thesis import HYPOTHESES, ThesisItem, items_for_stage, thesis_item

SECTIONS = (
    ("overview", "Overview"),
    ("hypotheses", "The thesis' hypotheses"),
    ("data", "Data"),
    ("synth", "Synthetic data"),
    ("train", "Energy models"),
    ("importance", "Feature importance"),
    ("optimize", "Optimized moves"),
    ("bench", "Optimizer benchmark"),
    ("identify", "Calibrated twin"),
    ("cycle", "Whole cycle"),
    ("differences", "What differs from the thesis"),
    ("settings", "Settings and provenance"),
)
"""Section ids and titles, in page order; every report has all of them."""

THESIS_DATASETS = {
    "train": "real, 1000 random moves: 75,792 rows",
    "test": "test, 100 other moves: 7,297 rows",
    "micro": "micro-real, 100 moves: 6,998 rows",
    "sim": "simulated, 1000 moves: 75,141 rows",
}
"""Thesis §4.3.1 dataset sizes, beside ours."""

DIFFERENCES = (
    (
        "Trajectory derivatives",
        "App. F rescales positions affinely but takes q̇, q̈ from the unscaled polynomial (and divides by "
        "zero when p(T) = p(0)). Here the path, its derivatives and the rest-to-rest boundary conditions "
        "agree exactly.",
    ),
    (
        "Fitness sampling",
        "App. F samples 10 points whatever the duration; here the path is sampled at the data rate "
        "(25 ms) so that the sum of predicted row energies is the path energy.",
    ),
    (
        "Baseline of the improvement",
        "Tables 4.5–4.6 measure against the best random initial individual. Here the headline is the "
        "saving against the controller-like minimum-jerk move of the same duration, on the physics "
        "model and on an emulated lab robot.",
    ),
    (
        "Cross-validation",
        "The thesis' folds shuffle rows, so rows of one move sit in training and validation folds. "
        "Here folds are grouped by move (the headline) and the shuffled score is shown beside it.",
    ),
    (
        "Dynamics",
        "App. B's Lagrange–Euler listing has a sum where a product is meant and wraps torques in "
        "abs(); here RNEA (Pinocchio) and a corrected Lagrange–Euler agree to about 1e-14 N·m.",
    ),
    (
        "Robot description",
        "App. C's inertias are rotation matrices, its centres of mass world coordinates, joint 6 "
        "repeats joint 5; the bundled IRB 120 uses the public ROS-Industrial parameters instead.",
    ),
    (
        "Informed local search",
        "The thesis hard-codes joints 1–2; here the joints come from the importance ranking of the "
        "data at hand (importance/joints.json).",
    ),
    (
        "Model files",
        "Models are saved with skops and an explicit type allowlist (XGBoost as JSON); loading never "
        "executes code. The thesis used pickle.",
    ),
    (
        "Limits",
        "Every optimized path is checked against joint range, speed and torque limits; a RAPID "
        "program is written only for a path within them.",
    ),
)

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0;color:#1d2330;
background:#f7f7f9;line-height:1.45}
header{background:#1f3a5f;color:#fff;padding:18px 28px}
header h1{margin:0 0 4px 0;font-size:1.6em}
nav{background:#fff;border-bottom:1px solid #ddd;padding:8px 28px;position:sticky;top:0;z-index:2}
nav a{margin-right:14px;color:#1f3a5f;text-decoration:none;font-size:.92em}
main{padding:0 28px 40px 28px;max-width:1500px}
section{background:#fff;border:1px solid #e1e1e6;border-radius:6px;margin:22px 0;padding:6px 22px 18px}
h2{border-bottom:2px solid #1f3a5f;padding-bottom:4px}
.pair{display:grid;grid-template-columns:minmax(0,3fr) minmax(0,2fr);gap:20px;margin:18px 0;
align-items:start}
.ours{min-width:0}
.thesis{background:#fbf6ea;border-left:4px solid #c79a2b;padding:8px 14px;font-size:.92em}
.thesis h4{margin:4px 0}
img{max-width:100%;height:auto;border:1px solid #eee}
figure{margin:8px 0}
figcaption{font-size:.85em;color:#555}
table{border-collapse:collapse;margin:8px 0;font-size:.86em}
th,td{border:1px solid #d5d5dc;padding:3px 7px;text-align:right}
th{background:#eef1f6}
td:first-child,th:first-child{text-align:left}
.verdict{border-radius:6px;padding:10px 14px;margin:12px 0;border:1px solid #ccc}
.supported{background:#e9f6ec;border-color:#6bb37a}
.partly{background:#fff6df;border-color:#d6a53a}
.not-supported{background:#fbeaea;border-color:#cc6b6b}
.untested{background:#f0f0f3}
.tag{font-weight:700}
.note{color:#555;font-size:.9em}
.headline{font-size:1.15em}
code{background:#f0f0f3;padding:0 3px}
.scroll{overflow-x:auto;max-width:100%}
pre{white-space:pre-wrap;font-size:.82em;background:#f6f6f8;padding:8px}
"""


@dataclass(frozen=True, slots=True)
class Verdict:
    """Our verdict on one of the thesis' hypotheses."""

    key: str
    hypothesis: str
    verdict: str  # "supported", "partly supported", "not supported", "not tested"
    evidence: str
    thesis: str


class _Run:
    """Read-only access to a run folder's files (missing files give None)."""

    def __init__(self, root: Path) -> None:
        self.root = root

    def path(self, rel: str) -> Path:
        return self.root / rel

    def json(self, rel: str) -> Any:
        p = self.root / rel
        return json.loads(p.read_text(encoding="utf-8")) if p.is_file() else None

    def csv(self, rel: str, **kwargs: Any) -> pd.DataFrame | None:
        p = self.root / rel
        if not p.is_file() or p.stat().st_size == 0:
            return None
        try:
            return pd.read_csv(p, **kwargs)
        except pd.errors.EmptyDataError:
            return None

    def ran(self, stage_folder: str) -> bool:
        return (self.root / stage_folder / "stage.json").is_file()


# ----------------------------------------------------------------------------- html helpers
def _e(text: Any) -> str:
    return html.escape(str(text))


def _fmt(value: Any, digits: int = 4) -> str:
    if isinstance(value, float):
        if math.isnan(value):
            return "–"
        return f"{value:.{digits}g}"
    return str(value)


def _table(frame: pd.DataFrame, *, digits: int = 4, index: bool = False) -> str:
    data = frame.reset_index() if index else frame
    head = "".join(f"<th>{_e(c)}</th>" for c in data.columns)
    body = "".join(
        "<tr>" + "".join(f"<td>{_e(_fmt(v, digits))}</td>" for v in row) + "</tr>"
        for row in data.itertuples(index=False)
    )
    return f'<div class="scroll"><table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>'


def _image(path: Path, caption: str) -> str:
    if not path.is_file():
        return f'<p class="note">({_e(path.name)} was not produced in this run.)</p>'
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (
        f'<figure><img src="data:image/png;base64,{data}" alt="{_e(caption)}">'
        f"<figcaption>{_e(caption)}</figcaption></figure>"
    )


def _thesis_box(item: ThesisItem, note: str = "") -> str:
    numbers = ""
    if item.numbers:
        rows = "".join(f"<tr><td>{_e(k)}</td><td>{_e(v)}</td></tr>" for k, v in item.numbers)
        numbers = f"<table><tbody>{rows}</tbody></table>"
    extra = f'<p class="note">{note}</p>' if note else ""
    return (
        f'<aside class="thesis" data-thesis="{_e(item.key)}"><h4>Thesis {_e(item.key)} '
        f"(§{_e(item.section)})</h4><p><em>{_e(item.caption)}</em></p><p>{_e(item.shows)}</p>"
        f"{numbers}{extra}</aside>"
    )


def _pair(ours: str, keys: tuple[str, ...], note: str = "") -> str:
    boxes = "".join(_thesis_box(thesis_item(k), note if i == 0 else "") for i, k in enumerate(keys))
    return f'<div class="pair"><div class="ours">{ours}</div><div>{boxes}</div></div>'


def _not_run(what: str, how: str, stage: str) -> str:
    keys = tuple(item.key for item in items_for_stage(stage))
    ours = f'<p class="note">{_e(what)} was not run in this experiment. {_e(how)}</p>'
    return _pair(ours, keys) if keys else ours


# ----------------------------------------------------------------------------- verdicts
def verdicts(run_dir: str | os.PathLike[str]) -> list[Verdict]:
    """Our verdict on each of the thesis' hypotheses from the evidence in a run folder."""
    run = _Run(Path(run_dir))
    return [_h1(run), _h2(run), _h3(run)]


def _h1(run: _Run) -> Verdict:
    text, thesis = (
        HYPOTHESES[0].text,
        ("MLP R² 1.00 on every output; the Lagrange–Euler model took 1.06 s per prediction (§4.4)."),
    )
    report, latency = run.json("models/report.json"), run.json("models/latency.json")
    if not report or not any(r["target"] == "E" for r in report["results"]):
        return Verdict("H1", text, "not tested", "No model of E was trained in this run.", thesis)
    rows = [r for r in report["results"] if r["target"] == "E"]
    best = max(rows, key=lambda r: r["test_r2"])
    base = max(report["baselines"], key=lambda b: b["scores"]["E"]["r2"])
    inputs = report["config"]["inputs"]
    ml, phys = best["test_r2"], base["scores"]["E"]["r2"]
    kind = (
        "the thesis' raw inputs"
        if inputs == "thesis"
        else "grey-box inputs: raw features plus the nominal model's energy terms"
    )
    evidence = (
        f"On {report['test']['moves']} held-out moves, the best learned model ({best['family']}, {kind}) "
        f"scores R² {ml:.3f}; the analytical model ({base['label']}) scores {phys:.3f}."
    )
    if latency:
        evidence += (
            f" One prediction takes {latency['learned_single_s'] * 1e3:.2f} ms (learned) against "
            f"{latency['physics_single_s'] * 1e3:.2f} ms (analytical); in a batch "
            f"{latency['learned_batch_per_row_s'] * 1e6:.1f} µs against "
            f"{latency['physics_batch_per_row_s'] * 1e6:.1f} µs per row. Both are fast: the thesis' "
            "1.06 s came from its symbolic implementation, not from the analytical method."
        )
    if ml <= phys:
        verdict = "not supported"
        evidence += " The learned model is not more accurate than the analytical one on unseen moves."
    elif inputs == "physics":
        verdict = "partly supported"
        evidence += (
            " It is more accurate, but only as a grey box that contains the analytical model: "
            "learning corrects the nominal model (friction, plant error) rather than replacing it. "
            "Run with [train] inputs = 'thesis' to test the pure data-driven claim."
        )
    else:
        verdict = "supported"
        evidence += " The data-driven model is more accurate than the analytical one on unseen moves."
    return Verdict("H1", text, verdict, evidence, thesis)


def _h2(run: _Run) -> Verdict:
    text = HYPOTHESES[1].text
    thesis = "TVAE column shapes 0.93, column pair trends 0.98; models on synthetic data scored R² ≈ 1.00."
    scores, base = run.csv("synth/scores.csv"), run.csv("synth/utility_baselines.csv")
    if scores is None or not len(scores):
        return Verdict("H2", text, "not tested", "Synthesis was not run in this experiment.", thesis)
    col = "study_mlp_test_r2" if "study_mlp_test_r2" in scores.columns else "utility_test_r2"
    best = scores.sort_values(col, ascending=False).iloc[0]
    evidence = (
        f"Trained on {int(best['rows']):,} synthetic rows ({best['method']}: column shapes "
        f"{best['column_shapes']:.3f}, pair trends {best['column_pair_trends']:.3f}), the study's MLP "
        f"scores R² {best[col]:.3f} on held-out real moves (the fixed raw-input utility MLP: "
        f"{best['utility_test_r2']:.3f})."
    )
    real = None
    if base is not None and "train" in set(base["train_on"]) and col in base.columns:
        real = float(base.loc[base["train_on"] == "train", col].iloc[0])
        evidence += f" The same MLP trained on the real training set scores {real:.3f}"
        if "micro" in set(base["train_on"]):
            micro = float(base.loc[base["train_on"] == "micro", col].iloc[0])
            evidence += f", and on the small real sample the synthesizers grew from {micro:.3f}"
        evidence += "."
    share = best.get("tcp_consistent_share")
    if share is not None and not (isinstance(share, float) and math.isnan(share)):
        evidence += (
            f" {float(share):.0%} of the raw synthetic rows have a TCP within 5 mm of FK(q): the "
            "synthesizers do not learn the robot's kinematics."
        )
    if real is None:
        verdict = "not tested"
    elif best[col] >= real - 0.01:
        verdict = "supported"
    elif best[col] >= real - 0.1:
        verdict = "partly supported"
    else:
        verdict = "not supported"
    return Verdict("H2", text, verdict, evidence, thesis)


def _h3(run: _Run) -> Verdict:
    text = HYPOTHESES[2].text
    thesis = (
        "MA random local search 52.59 % ± 0.21, informed 59.79 % ± 0.18, best GA 51.96 % ± 0.21 "
        "(improvement over the best random initial individual)."
    )
    table = run.csv("bench/table.csv")
    summary = run.json("summary.json") or {}
    if table is None or not len(table):
        return Verdict(
            "H3", text, "not tested", "The optimizer benchmark was not run ([bench] tasks = 0).", thesis
        )
    n = int(summary.get("experiment", {}).get("bench", {}).get("tasks", 1)) or 1
    # H3 is about the thesis' evolutionary searches: joulepath's own default is not one of them
    table = table[~table["configuration"].str.startswith("joulepath")]
    is_ma = table["configuration"].str.startswith("MA")
    ma, ea = table[is_ma], table[~is_ma]
    if not len(ma) or not len(ea):
        return Verdict("H3", text, "not tested", "The benchmark lacked MA or GA/DE configurations.", thesis)
    bm = ma.sort_values("vs_default_mean", ascending=False).iloc[0]
    be = ea.sort_values("vs_default_mean", ascending=False).iloc[0]
    diff = float(bm["vs_default_mean"] - be["vs_default_mean"])
    runs = run.csv("bench/runs.csv")
    paired = ""
    if runs is not None and {"task", "vs_default"} <= set(runs.columns):
        per_task = runs.pivot_table(index="task", columns="configuration", values="vs_default")
        d = (per_task[bm["configuration"]] - per_task[be["configuration"]]).dropna()
        n = len(d)
        se = float(d.std(ddof=1) / math.sqrt(n)) if n > 1 else float("nan")
        diff = float(d.mean())
        paired = f"; MA better on {int((d > 0).sum())} of {n} tasks"
    else:
        se = math.hypot(float(bm["vs_default_std"] or 0), float(be["vs_default_std"] or 0)) / math.sqrt(n)
    se = 0.0 if math.isnan(se) else se
    evidence = (
        f"On {n} random tasks, the best MA ({bm['configuration']}) saves {bm['vs_default_mean']:.1f} % "
        f"against the default move of equal duration, the best GA/DE ({be['configuration']}) "
        f"{be['vs_default_mean']:.1f} % (difference {diff:+.1f} points on the same tasks, standard error "
        f"{se:.1f}{paired}). By the thesis' metric: {bm['vs_initial_mean']:.1f} % and "
        f"{be['vs_initial_mean']:.1f} %."
    )
    if diff > 2 * se:
        verdict = "supported"
    elif diff > 0:
        verdict = "partly supported"
        evidence += " MA is ahead, but not by two standard errors: more tasks would settle it."
    else:
        verdict = "not supported"
    return Verdict("H3", text, verdict, evidence, thesis)


def _verdict_html(v: Verdict) -> str:
    css = {
        "supported": "supported",
        "partly supported": "partly",
        "not supported": "not-supported",
        "not tested": "untested",
    }[v.verdict]
    return (
        f'<div class="verdict {css}" data-hypothesis="{_e(v.key)}"><p><span class="tag">{_e(v.key)}: '
        f"{_e(v.verdict.upper())}</span> — <em>{_e(v.hypothesis)}</em></p><p>{_e(v.evidence)}</p>"
        f'<p class="note">Thesis: {_e(v.thesis)}</p></div>'
    )


# ----------------------------------------------------------------------------- sections
def _overview(run: _Run) -> str:
    s = run.json("summary.json") or {}
    parts = [
        f"<p>Experiment <b>{_e(s.get('name', '?'))}</b> on robot <code>{_e(s.get('robot', '?'))}</code>, "
    ]
    parts.append(f"seed {_e(s.get('seed', '?'))}, from <code>{_e(s.get('source') or '?')}</code>.</p>")
    saved, lab = s.get("mean_saved_pct"), s.get("mean_saved_lab_pct")
    if saved is not None:
        parts.append(
            f'<p class="headline">Energy saved at equal cycle time, mean over {s.get("tasks")} feasible '
            f"random tasks ({s.get('tasks_within_limits')} optimized paths within every limit; a refused "
            f"path counts as no saving): <b>{saved:.1f} %</b> on the physics model, <b>{lab:.1f} %</b> on "
            "the emulated lab robot (against the controller-like minimum-jerk move of the same "
            "duration).</p>"
        )
    optimum, share = s.get("mean_optimum_saved_pct"), s.get("mean_share_of_optimum_pct")
    if optimum is not None and share is not None:
        parts.append(
            f'<p class="headline">The optimum (reference solver) saves <b>{optimum:.1f} %</b> on the same '
            f"tasks; the optimizer reached <b>{share:.0f} %</b> of that saving on average.</p>"
        )
    report = run.json("models/report.json")
    if report:
        best = max(report["results"], key=lambda r: r["test_r2"])
        parts.append(
            f"<p>Best energy model: {_e(best['family'])} for {_e(best['target'])}, test R² "
            f"{best['test_r2']:.3f} on {report['test']['moves']} held-out moves (grouped CV R² "
            f"{best['cv_grouped_r2']:.3f}).</p>"
        )
    stages = s.get("stages", {})
    rows = [{"stage": k, "wall time (s)": float(v.get("wall_s", float("nan")))} for k, v in stages.items()]
    if rows:
        parts.append(
            "<p>Stage timings (of the run that produced each stage):</p>" + _table(pd.DataFrame(rows))
        )
    parts.append(
        '<p class="note">Every saving is verified on the physics model, never taken from the learned '
        "model; the thesis' own metric is shown beside the honest one.</p>"
    )
    return "".join(parts)


def _hypotheses(run: _Run) -> str:
    return "".join(_verdict_html(v) for v in verdicts(run.root))


def _data(run: _Run) -> str:
    stage = run.json("data/stage.json") or {}
    sets = stage.get("datasets", {})
    rows = [
        {
            "dataset": name,
            "rows": info["rows"],
            "moves": info["moves"],
            "origin": info["origin"],
            "thesis": THESIS_DATASETS.get(name, ""),
        }
        for name, info in sets.items()
    ]
    body = "<p>Each row is one 25 ms sample of the controller's joint log (40 Hz), with its energy.</p>"
    body += _table(pd.DataFrame(rows)) if rows else '<p class="note">No dataset recorded.</p>'
    keys = tuple(item.key for item in items_for_stage("data"))
    return _pair(body, keys) if keys else body


def _synth(run: _Run) -> str:
    if not run.ran("synth"):
        return _not_run("Synthesis", "Add a [synth] section with methods = [...] to run it.", "synth")
    scores = run.csv("synth/scores.csv")
    base = run.csv("synth/utility_baselines.csv")
    stage = run.json("synth/stage.json") or {}
    best = stage.get("best_method", "")
    ours = (
        "<p>Synthesizers fitted on the small real sample; quality by SDMetrics against it. Utility: "
        "an MLP trained on each table and tested on the held-out real moves, both the fixed raw-input "
        "MLP of <code>joulepath.synth.utility</code> and the study's MLP (the quick grid's 50 ReLU "
        "units on the study's [train] inputs).</p>"
    )
    if scores is not None:
        ours += _table(scores)
    if base is not None and len(base):
        ours += "<p>The same MLP trained on real tables:</p>" + _table(base)
    ours += _image(run.path("synth/quality.png"), "Quality and utility per method (cf. thesis Fig 4.3)")
    out = _pair(ours, ("Figure 4.3",))
    groups = (
        ("Figure 4.4", "joint_positions"),
        ("Figure 4.5", "joint_speeds"),
        ("Figure 4.6", "joint_accelerations"),
        ("Figure 4.7", "tcp_derivatives"),
        ("Figure 4.8", "orientation_derivatives"),
        ("Figure 4.9", "energies"),
    )
    for key, group in groups:
        figs = _image(
            run.path(f"synth/plots/{group}.png"), f"{group.replace('_', ' ')}: real, simulated, {best}"
        )
        if group == "tcp_derivatives":
            figs = _image(run.path("synth/plots/tcp_position.png"), "TCP position") + figs
        if group == "orientation_derivatives":
            figs = _image(run.path("synth/plots/orientation.png"), "TCP orientation") + figs
        out += _pair(figs, (key,))
    out += _pair(
        _image(run.path("synth/statistics.png"), "Statistics of each table relative to the real one")
        + _stats_excerpt(run),
        ("Figure 4.10",),
    )
    return out


def _stats_excerpt(run: _Run) -> str:
    stats = run.csv("synth/statistics.csv")
    if stats is None:
        return ""
    sub = stats[stats["column"].isin(["E", "E1", "E2", "dq1", "q2"])]
    keep = [c for c in ("column", "table", "mean", "std", "skewness", "kurtosis") if c in sub.columns]
    return "<p>Excerpt of the statistics (all in synth/statistics.csv):</p>" + _table(sub[keep])


_FAMILY_TABLE = {"mlp": "Table 4.1", "par": "Table 4.2", "svr": "Table 4.3", "xgb": "Table 4.4"}
_TARGET_FIGURE = {f"E{i}": f"Figure 4.{10 + i}" for i in range(1, 7)} | {"E": "Figure 4.17"}


def _train(run: _Run) -> str:
    if not run.ran("models"):
        return _not_run("Training", "Give [train] families to train energy models.", "train")
    results = run.csv("models/results.csv")
    report = run.json("models/report.json") or {}
    cfg = report.get("config", {})
    intro = (
        f"<p>{len(cfg.get('families', []))} families, grid <code>{_e(cfg.get('grid'))}</code>, "
        f"{_e(cfg.get('cv'))} folds grouped by move (headline) and shuffled (the thesis' protocol), inputs "
        f"<code>{_e(cfg.get('inputs'))}</code>; trained on {report.get('train', {}).get('moves', '?')} "
        f"moves, tested on {report.get('test', {}).get('moves', '?')} other moves. "
        "Path error: relative error of the summed energy of each test move.</p>"
    )
    subs = report.get("substitutions", {})
    for fam, why in subs.items():
        intro += f'<p class="note">{_e(fam)}: {_e(why)}</p>'
    out = intro
    if results is None:
        return out
    cols = [
        "target",
        "cv_grouped_r2",
        "cv_grouped_r2_std",
        "cv_shuffled_r2",
        "cv_grouped_mae",
        "test_r2",
        "test_mae",
        "path_median_pct",
        "path_p95_pct",
        "best_params",
    ]
    for family, table_key in _FAMILY_TABLE.items():
        rows = results[results["family"] == family]
        if len(rows):
            ours = f"<h3>{_e(family.upper())}</h3>" + _table(rows[cols])
        else:
            ours = (
                f'<p class="note">No {_e(family.upper())} model in this run; '
                f'add "{family}" to [train] families.</p>'
            )
        out += _pair(ours, (table_key,))
    trained = set(results["target"])
    for target, fig_key in _TARGET_FIGURE.items():
        if target in trained:
            ours = _image(run.path(f"models/test_scores_{target}.png"), f"Test scores for {target}")
        else:
            ours = f'<p class="note">No model of {target} in this run; add "{target}" to [train] targets.</p>'
        out += _pair(ours, (fig_key,))
    latency = run.json("models/latency.json")
    comp = _image(
        run.path("models/comparison.png"), "Learned and analytical model on a section of the test data"
    )
    if latency:
        comp += _table(
            pd.DataFrame(
                [
                    {
                        "model": f"learned ({latency['model']})",
                        "one prediction (ms)": latency["learned_single_s"] * 1e3,
                        "per row in a batch (µs)": latency["learned_batch_per_row_s"] * 1e6,
                    },
                    {
                        "model": "dynamics + nominal friction",
                        "one prediction (ms)": latency["physics_single_s"] * 1e3,
                        "per row in a batch (µs)": latency["physics_batch_per_row_s"] * 1e6,
                    },
                ]
            )
        )
    baselines = report.get("baselines", [])
    if baselines:
        comp += _table(
            pd.DataFrame(
                [
                    {
                        "analytical model": b["label"],
                        "test R² (E)": b["scores"]["E"]["r2"],
                        "test MAE (E)": b["scores"]["E"]["mae"],
                    }
                    for b in baselines
                ]
            )
        )
    out += _pair(comp, ("Figure 4.18",))
    return out


def _importance(run: _Run) -> str:
    if not run.ran("importance"):
        return _not_run("Feature importance", "It runs by default; check run.log.", "importance")
    joints = run.json("importance/joints.json") or {}
    ours = (
        "<p>Five methods (Pearson, Spearman, Kendall, random-forest impurity, permutation), each scaled "
        f"to sum 1, on the training data. Joints by influence on {_e(joints.get('target', 'E'))}: "
        f"<b>{_e(joints.get('joints_by_influence', []))}</b> (used by the informed local search).</p>"
    )
    ours += _image(run.path("importance/heatmap.png"), "Mean importance of every input for every target")
    top = []
    for path in sorted(run.root.glob("importance/importance_*.csv")):
        frame = pd.read_csv(path, index_col=0)
        target = path.stem.removeprefix("importance_")
        top.append({"target": target, **{f"#{k + 1}": name for k, name in enumerate(frame.index[:5])}})
    if top:
        ours += "<p>Five most important inputs per target:</p>" + _table(pd.DataFrame(top))
    out = _pair(ours, ("Figure 4.1",))
    target = joints.get("target", "E")
    out += _pair(
        _image(run.path(f"importance/importance_{target}.png"), f"Importance for {target} by method"),
        ("Figure 4.2",),
    )
    return out


def _optimize(run: _Run) -> str:
    tasks = run.csv("optimize/tasks.csv")
    summary = run.json("summary.json") or {}
    o = summary.get("experiment", {}).get("optimize", {})
    ours = (
        f"<p>{_e(o.get('tasks', '?'))} random feasible tasks (start, end in the "
        f"<code>{_e(o.get('range_set', '?'))}</code> range set, duration 1–3 s, redrawn until the default "
        f"move respects every limit), algorithm {_e(o.get('algorithm', '?'))} with "
        f"{_e(o.get('fitness', '?'))} fitness. Savings are measured on the physics model and on the "
        "emulated lab robot against the minimum-jerk move of the same duration; a path that breaks a "
        "limit (checked on a grid ten times finer than the samples, acceleration included) is refused "
        "and counts as no saving; 'vs initial' is the thesis' metric (evolutionary searches only).</p>"
    )
    if tasks is not None and "share_of_optimum_pct" in tasks:
        ours += (
            f"<p>The reference optimum (a direct transcription solved by IPOPT, energies on the fine grid) "
            f"saves {tasks['optimum_saved_pct'].mean():.1f} % on average; the optimizer reached "
            f"{tasks['share_of_optimum_pct'].mean():.0f} % of that saving (lowest "
            f"{tasks['share_of_optimum_pct'].min():.0f} %).</p>"
        )
    elif tasks is not None:
        ours += (
            '<p class="note">The optimum was not computed in this run (set <code>[optimize] reference = '
            "true</code>, physics fitness, with the <code>reference</code> extra installed).</p>"
        )
    if tasks is not None and len(tasks):
        ours += _table(tasks.drop(columns=["generations", "iterations", "wall_s"], errors="ignore"), digits=4)
        ours += _image(run.path("optimize/tasks.png"), "Default and optimized energy per task")
        ok = tasks[tasks["limits_ok"].astype(bool)]
        if len(ok):
            first = f"optimize/task-{int(ok['task'].iloc[0]):03d}"
            ours += _image(
                run.path(f"{first}/joints.png"),
                f"Joint paths of task {int(ok['task'].iloc[0])} (default vs optimized)",
            )
            ours += _image(
                run.path(f"{first}/power.png"), f"Mechanical power along task {int(ok['task'].iloc[0])}"
            )
            ours += (
                f'<p class="note">RAPID program of each task within the limits: '
                f"<code>{_e(first)}/path.mod</code> (and the other task folders).</p>"
            )
    return _pair(ours, ("Table 4.7",))


def _bench(run: _Run) -> str:
    if not run.ran("bench"):
        return _not_run("The optimizer benchmark", "Set [bench] tasks ≥ 1 to run it.", "bench")
    table = run.csv("bench/table.csv")
    summary = run.json("summary.json") or {}
    b = summary.get("experiment", {}).get("bench", {})
    ours = (
        f"<p>Every configuration on the same {_e(b.get('tasks', '?'))} random tasks, "
        f"{_e(b.get('fitness', '?'))} fitness, population {_e(b.get('population', '?'))}, at most "
        f"{_e(b.get('generations', '?'))} generations, random initial populations (the thesis' protocol). "
        "Improvement in %: mean and σ over tasks, against the best initial individual (thesis) and "
        "against the default move (honest).</p>"
    )
    if table is not None:
        ours += _table(table)
    note = ""
    if b.get("fitness") != "surrogate-joints":
        note = (
            "Table 4.6 (the thesis' multi-objective fitness, one model per joint) corresponds to "
            "[bench] fitness = 'surrogate-joints'; this run used "
            f"{_e(b.get('fitness', '?'))}."
        )
    out = _pair(ours, ("Table 4.5", "Table 4.6"), note)
    fig = _image(run.path("bench/improvement.png"), "Improvement per configuration, both metrics")
    if table is not None:
        ma = table[table["configuration"].str.startswith("MA")]
        if len(ma):
            fig += _table(ma)
    return out + _pair(fig, ("Figure 4.19",))


def _identify(run: _Run) -> str:
    if not run.ran(IDENTIFY_STAGE):
        return (
            '<p class="note">Dynamic identification (a calibrated twin) was not run in this experiment. '
            "Set [identify] enabled = true to run it.</p>"
        )
    scores = run.csv(f"{IDENTIFY_STAGE}/{IDENTIFY_SCORES}")
    loop = run.csv(f"{IDENTIFY_STAGE}/{IDENTIFY_LOOP}")
    st = (run.json("summary.json") or {}).get("stages", {}).get(IDENTIFY_STAGE, {})
    out = (
        "<p>The twin is identified from the training logs (base inertial parameters from Pinocchio's "
        "joint torque regressor, per-joint friction, gear efficiency; physically consistent links). "
        "Condition number of the stacked regressor "
        f"{_fmt(st.get('condition_number'), 3)}, gear efficiency {_fmt(st.get('gear_efficiency'), 3)}. "
        f"The twin folder is <code>{IDENTIFY_STAGE}/{IDENTIFY_TWIN}/</code> "
        "(<code>--robot</code> accepts it).</p>"
    )
    if scores is not None:
        out += (
            "<p>Five models side by side on the same test sets: the twin and the nominal physics predict "
            "torque (R² of the worst joint) and energy; the learned model of E "
            f"({_e(st.get('learned_model', '?'))}) predicts energy only (–), and is refitted with the "
            "same hyperparameters on rows simulated on the twin and on SDV rows. Test sets: the held-out "
            "moves, moves of another kind (other joint ranges) and the loop's optimized paths, each run "
            "on the data's plant. Row energy R² on the test rows; path error: median over the moves of "
            "|ΣE predicted − ΣE measured| / ΣE measured.</p>" + _table(scores)
        )
    if loop is not None and len(loop):
        out += (
            "<p>Closing the loop: moves optimized on the twin, the saving it predicts against the saving "
            "realized on the emulated lab robot.</p>" + _table(loop)
        )
    return out


def _cycle(run: _Run) -> str:
    from joulepath._runfolder import CYCLE_JSON, CYCLE_PARETO_PNG, CYCLE_STAGE

    data = run.json(f"{CYCLE_STAGE}/{CYCLE_JSON}") if run.ran(CYCLE_STAGE) else None
    if not data:
        return (
            '<p class="note">No robot program was optimized in this experiment. Set [cycle] program = '
            '"….mod" (a RAPID module, or a plain cycle TOML) to run what <code>joulepath cycle</code> '
            "runs.</p>"
        )
    b = data.get("breakdown") or {}
    ok = bool(data.get("limits_ok"))
    out = (
        f'<p class="headline">Cycle {_fmt(data.get("default_cycle_s"), 4)} s → '
        f"{_fmt(data.get('optimized_cycle_s'), 4)} s; energy on physics "
        f"{_fmt(data.get('energy_default_J'), 4)} → {_fmt(data.get('energy_optimized_J'), 4)} J "
        f"(<b>{_fmt(data.get('saved_pct'), 3)} %</b> saved), on the emulated lab robot "
        f"{_fmt(data.get('saved_lab_pct'), 3)} % saved.</p>"
        if ok
        else '<p class="headline">REFUSED: the optimized cycle breaks a limit or the cell\'s margin; no '
        "program was written and no saving is claimed.</p>"
    )
    waits = b.get("saved_by_waits_pct")
    along = b.get("saved_by_path_retiming_pct")
    out += (
        f"<p>Breakdown of the saving: shape {_fmt(b.get('saved_by_shape_pct'), 3)} %, time allocation "
        f"{_fmt(b.get('saved_by_time_allocation_pct'), 3)} %"
        + ("" if waits is None else f", waits spent {_fmt(waits, 3)} %")
        + ("" if along is None else f", segments with MoveL re-timed along their path {_fmt(along, 3)} %")
        + ". The default is the program as the emulated controller runs it; MoveL moves keep their line "
        "and tool orientation (re-timed along it within their speeddata).</p>"
    )
    measures = data.get("energies") or {}
    if measures:
        out += (
            f"<p>Optimized on the <b>{html.escape(str(data.get('energy_measure', 'thesis')))}</b> energy. "
            "The whole cycle on every energy measure (the stage each is taken at; standby over the cycle "
            "time included where counted): "
            + "; ".join(
                f"{html.escape(str(name))} ({html.escape(str(m.get('stage')))}) "
                f"{_fmt(m.get('default_J'), 4)} → {_fmt(m.get('optimized_J'), 4)} J, "
                f"{_fmt(m.get('saved_pct'), 3)} % saved"
                for name, m in measures.items()
                if isinstance(m, dict)
            )
            + ".</p>"
        )
    moves = pd.DataFrame(data.get("moves") or [])
    if len(moves):
        cols = [
            c
            for c in (
                "line",
                "label",
                "optimized",
                "default_duration_s",
                "optimized_duration_s",
                "default_energy_J",
                "optimized_energy_J",
                "default_lab_J",
                "optimized_lab_J",
                "limits_ok",
                "note",
            )
            if c in moves
        ]
        out += _table(moves[cols])
    check = data.get("written_program_check")
    if check:
        verdict = "within" if check.get("within_tolerances") else "<b>outside</b>"
        tol = check.get("tolerances") or {}
        out += (
            f"<p>The {'written' if data.get('rapid') else 'would-be (not written)'} module "
            "(<code>optimized.mod</code>) run by the controller emulation: cycle "
            f"{_fmt(check.get('emulated_cycle_s'), 4)} s against the planned "
            f"{_fmt(check.get('planned_cycle_s'), 4)} s ({_fmt(check.get('cycle_diff_pct'), 3)} %), energy "
            f"{_fmt(check.get('emulated_energy_J'), 4)} J against {_fmt(check.get('planned_energy_J'), 4)} J "
            f"({_fmt(check.get('energy_diff_pct'), 3)} %), "
            f"TCP path within {_fmt(check.get('tcp_path_deviation_mm'), 3)} mm: {verdict} the tolerances "
            f"({_e(tol.get('cycle_pct'))} % cycle, {_e(tol.get('energy_pct'))} % energy, "
            f"{_e(tol.get('path_mm'))} mm). The savings above are those of the planned motion.</p>"
        )
    if data.get("rapid_refused") and data.get("limits_ok"):
        out += f'<p class="note">optimized.mod not written: {_e(data["rapid_refused"])}</p>'
    if data.get("pareto"):
        out += _image(run.path(f"{CYCLE_STAGE}/{CYCLE_PARETO_PNG}"), "Energy against cycle time")
    if data.get("kept_verbatim_lines"):
        out += (
            f'<p class="note">Kept verbatim, run time treated as fixed: line(s) '
            f"{_e(', '.join(map(str, data['kept_verbatim_lines'])))}.</p>"
        )
    return out


def _differences(run: _Run) -> str:
    rows = "".join(
        f"<tr><td>{_e(a)}</td><td style='text-align:left'>{_e(b)}</td></tr>" for a, b in DIFFERENCES
    )
    return f"<table><thead><tr><th>what</th><th>thesis → here</th></tr></thead><tbody>{rows}</tbody></table>"


def _settings(run: _Run) -> str:
    s = run.json("summary.json") or {}
    exp = json.dumps(s.get("experiment", {}), indent=2)
    files = sorted(
        str(p.relative_to(run.root))
        for p in run.root.rglob("*")
        if p.is_file() and ".gridcache" not in p.parts and p.name != "report.html"
    )
    listing = "\n".join(files[:300]) + (f"\n… {len(files) - 300} more" if len(files) > 300 else "")
    return (
        f"<p>Rendered {time.strftime('%Y-%m-%d %H:%M')} from <code>{_e(run.root)}</code>.</p>"
        f"<h3>Experiment (as run)</h3><pre>{_e(exp)}</pre>"
        f"<h3>Files of the run</h3><pre>{_e(listing)}</pre>"
    )


_RENDERERS: dict[str, Callable[[_Run], str]] = {
    "overview": _overview,
    "hypotheses": _hypotheses,
    "data": _data,
    "synth": _synth,
    "train": _train,
    "importance": _importance,
    "optimize": _optimize,
    "bench": _bench,
    "identify": _identify,
    "cycle": _cycle,
    "differences": _differences,
    "settings": _settings,
}


def render_report(run_dir: str | os.PathLike[str], *, out: str | os.PathLike[str] | None = None) -> Path:
    """Write ``report.html`` for a run folder (see :func:`joulepath.experiment.run_experiment`).

    Parameters
    ----------
    run_dir : path
        The run folder; stages it lacks get a section saying so.
    out : path, optional
        Where to write (default ``<run_dir>/report.html``).

    Returns
    -------
    Path
        The HTML file: self-contained (inline CSS, images as data URIs, no script).
    """
    run = _Run(Path(run_dir))
    summary = run.json("summary.json") or {}
    title = f"joulepath study: {summary.get('name', run.root.name)}"
    nav = "".join(f'<a href="#{sid}">{_e(name)}</a>' for sid, name in SECTIONS)
    body = "".join(
        f'<section id="{sid}" data-section="{sid}"><h2>{_e(name)}</h2>{_RENDERERS[sid](run)}</section>'
        for sid, name in SECTIONS
    )
    page = (
        "<!DOCTYPE html>\n"
        f'<html lang="en"><head><meta charset="utf-8"><title>{_e(title)}</title>'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<style>{_CSS}</style></head><body>"
        f"<header><h1>{_e(title)}</h1><div>Energy-optimal point-to-point moves: our results beside "
        "the thesis' (thesis boxes in yellow).</div></header>"
        f"<nav>{nav}</nav><main>{body}</main></body></html>\n"
    )
    path = Path(out) if out is not None else run.root / "report.html"
    atomic_write_text(path, page)
    return path
