"""The plant report: ``plant.json``, ``cells.csv``, ``report.html`` and each cell's files, from the results.

Per cell: the default and optimized energy per cycle on the measure used (``electrical``,
at the meter, where the robot has drive data; the measure is stated otherwise), cycles
per year (``hours_per_year * share * 3600 / cycle time``), kWh, € and CO₂ saved a year
(the energy per hour of production, default against optimized, times the hours), what
was written or why not, the moves kept and why, where the energy goes (motion, holding at
rest, standby), how long the arm stands still per cycle, and what power-saving modes in
those pauses would save: a recommendation under the drives file's assumed mode powers,
never a saving of the written program. For the plant: totals over the cells measured at
the meter, a ranking by saving, and the shares of the plant's robot energy that motion
reshaping reaches and that the pauses hold.
"""

from __future__ import annotations

import csv
import html
import io
import json
from pathlib import Path
from typing import Any

from joulepath._io import atomic_write_text, finite_json, make_folder, remove_output
from joulepath.plant._config import PlantConfig
from joulepath.plant._run import CACHE, plan_tasks, read_result
from joulepath.plant._task import REPORT_MEASURE, RETURNED_FILES

PLANT_FILES = ("plant.json", "cells.csv", "report.html")
J_PER_KWH = 3.6e6
CSV_COLUMNS = (
    "rank",
    "cell",
    "robot",
    "status",
    "written",
    "measure",
    "default_cycle_s",
    "optimized_cycle_s",
    "default_J_per_cycle",
    "optimized_J_per_cycle",
    "saved_pct",
    "cycles_per_year",
    "default_kWh_per_year",
    "saved_kWh_per_year",
    "saved_EUR_per_year",
    "saved_CO2_kg_per_year",
    "motion_J",
    "holding_J",
    "standby_J",
    "standstill_s_per_cycle",
    "idle_modes_kWh_per_year",
    "moves_kept",
    "reason",
)
IDLE_NOTE = (
    "a recommendation, not a saving of the written program: power-saving modes (brakes engaged, bus power "
    "off) entered in the taught cycle's pauses longer than each mode's entry time, at the powers and entry "
    "times of the robot's drives file (assumed values; the bundled ABB files, the irb120's and each size "
    "class's of the ABB range, scale the per-robot draws that Bukata et al., IEEE TII 2017, measured in a "
    "six-robot welding cell: motors on 567-751 W, brakes engaged 218-278 W, bus power off 153-195 W)"
)


def _cell_row(rec: dict[str, Any], plant: PlantConfig, share: float) -> dict[str, Any]:
    """A cell's figures a year (plain JSON), from its stored result."""
    row: dict[str, Any] = {
        "cell": rec["name"],
        "status": rec["status"],
        "reason": rec.get("reason"),
        "share": share,
        "key": rec["key"],
        "wall_s": rec.get("wall_s"),
    }
    if "default_J" not in rec:  # failed before any figure
        return row
    hours = plant.hours_per_year * share
    d_rate = rec["default_J"] / rec["default_cycle_s"]  # W: J per s of production
    o_rate = rec["optimized_J"] / rec["optimized_cycle_s"]
    d_kwh = d_rate * hours * 3600 / J_PER_KWH
    saved_kwh = (d_rate - o_rate) * hours * 3600 / J_PER_KWH
    idle = rec.get("idle_modes", {})
    idle_kwh = (
        idle["saving_J"] / rec["default_cycle_s"] * hours * 3600 / J_PER_KWH
        if idle.get("available")
        else None
    )
    split = rec["split_default"]
    kept = [m for m in rec.get("moves", []) if not m["optimized"]]
    row.update(
        robot=rec.get("robot"),
        written=rec.get("written"),
        written_note=rec.get("written_note"),
        measure=rec["measure"],
        measure_note=rec.get("measure_note"),
        default_cycle_s=rec["default_cycle_s"],
        optimized_cycle_s=rec["optimized_cycle_s"],
        default_J_per_cycle=rec["default_J"],
        optimized_J_per_cycle=rec["optimized_J"],
        saved_pct=100 * (rec["default_J"] - rec["optimized_J"]) / rec["default_J"]
        if rec["default_J"] > 0
        else 0.0,
        motion_saved_pct=rec.get("motion_saved_pct"),
        optimized_measure=rec.get("optimized_measure"),
        cycles_per_year=hours * 3600 / rec["default_cycle_s"],
        default_kWh_per_year=d_kwh,
        saved_kWh_per_year=saved_kwh,
        saved_EUR_per_year=saved_kwh * plant.tariff_eur_per_kwh,
        saved_CO2_kg_per_year=saved_kwh * plant.co2_kg_per_kwh,
        split_default=split,
        split_optimized=rec["split_optimized"],
        waits_s=rec.get("waits_s"),
        idle_waits_s=rec.get("idle_waits_s"),
        idle_modes=idle,
        idle_modes_kWh_per_year=idle_kwh,
        moves_kept=[{"line": m["line"], "label": m["label"], "why": m["note"]} for m in kept],
        n_moves=len(rec.get("moves", [])),
        timed_out=rec.get("timed_out"),
        drive_data=rec.get("drive_data"),
    )
    return row


def plant_summary(plant: PlantConfig, out: str | Path) -> dict[str, Any]:
    """``plant.json``: the plant's figures, totals, ranking and one entry per cell (from the stored results).

    A cell without a stored result (not run yet, or its last attempt lost) is ``"missing"``.
    """
    root = Path(out)
    cells: list[dict[str, Any]] = []
    for cell, task in zip(plant.cells, plan_tasks(plant), strict=True):
        rec = read_result(root, task.key, attempts=True)
        if rec is None:
            cells.append(
                {"cell": cell.name, "status": "missing", "reason": "not computed yet", "key": task.key}
            )
            continue
        cells.append(_cell_row({**rec, "name": cell.name}, plant, cell.share))
    meter = [c for c in cells if c.get("measure") == REPORT_MEASURE]
    ranked = sorted(
        (c for c in cells if "saved_kWh_per_year" in c),
        key=lambda c: (c["measure"] != REPORT_MEASURE, -c["saved_kWh_per_year"], c["cell"]),
    )
    for k, c in enumerate(ranked, start=1):
        c["rank"] = k
    total = sum(c["default_kWh_per_year"] for c in meter)
    saved = sum(c["saved_kWh_per_year"] for c in meter)
    idle = sum(c["idle_modes_kWh_per_year"] or 0.0 for c in meter)

    def share_of(key: str) -> float | None:
        if total <= 0:
            return None
        part = sum(
            c["split_default"][key] / c["default_J_per_cycle"] * c["default_kWh_per_year"]
            for c in meter
            if c["default_J_per_cycle"] > 0
        )
        return float(100 * part / total)

    statuses = [c["status"] for c in cells]
    summary: dict[str, Any] = finite_json(
        {
            "plant": plant.name,
            "plant_file": str(plant.path),
            "hours_per_year": plant.hours_per_year,
            "tariff_eur_per_kwh": plant.tariff_eur_per_kwh,
            "co2_kg_per_kwh": plant.co2_kg_per_kwh,
            "n_cells": len(cells),
            "n_ok": statuses.count("ok"),
            "n_refused": statuses.count("refused"),
            "n_failed": statuses.count("failed"),
            "n_missing": statuses.count("missing"),
            "totals": {
                "measure": REPORT_MEASURE,
                "cells_at_the_meter": len(meter),
                "note": "totals over the cells measured at the meter (electrical: drive data); the others "
                "are listed with their own measure and not added",
                "default_kWh_per_year": total,
                "saved_kWh_per_year": saved,
                "saved_EUR_per_year": saved * plant.tariff_eur_per_kwh,
                "saved_CO2_kg_per_year": saved * plant.co2_kg_per_kwh,
                "saved_pct": 100 * saved / total if total > 0 else None,
                "motion_share_pct": share_of("motion_J"),
                "holding_share_pct": share_of("holding_J"),
                "standby_share_pct": share_of("standby_J"),
                "idle_modes_kWh_per_year": idle,
                "idle_modes_pct": 100 * idle / total if total > 0 else None,
                "idle_modes_note": IDLE_NOTE,
            },
            "ranking": [c["cell"] for c in ranked],
            "cells": cells,
        }
    )
    return summary


def _csv(summary: dict[str, Any]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for c in summary["cells"]:
        split = c.get("split_default") or {}
        values = {
            **c,
            "motion_J": split.get("motion_J"),
            "holding_J": split.get("holding_J"),
            "standby_J": split.get("standby_J"),
            "standstill_s_per_cycle": split.get("standstill_s"),
            "moves_kept": "; ".join(f"line {m['line']}: {m['why']}" for m in c.get("moves_kept", [])),
        }
        writer.writerow(["" if values.get(k) is None else _fmt_csv(values[k]) for k in CSV_COLUMNS])
    return buf.getvalue()


def _fmt_csv(v: Any) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def _n(v: Any, digits: int = 1) -> str:
    return "–" if v is None else f"{v:,.{digits}f}"


def _bar(split: dict[str, float]) -> str:
    total = split["motion_J"] + split["holding_J"] + split["standby_J"]
    if total <= 0:
        return ""
    parts = [
        (split[k] / total * 100, cls, label)
        for k, cls, label in (
            ("motion_J", "m", "motion"),
            ("holding_J", "h", "holding at rest"),
            ("standby_J", "s", "standby"),
        )
    ]
    spans = "".join(
        f'<span class="{cls}" style="width:{w:.2f}%" title="{label} {w:.1f} %"></span>'
        for w, cls, label in parts
    )
    return f'<div class="bar">{spans}</div>'


_CSS = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1200px;padding:0 1em;color:#222}
table{border-collapse:collapse;width:100%;font-size:0.85em;table-layout:auto}
th,td{border-bottom:1px solid #ddd;padding:3px 6px;text-align:right;vertical-align:top}
th:first-child,td:first-child,td.t{text-align:left}
td.t{max-width:28em;overflow-wrap:anywhere}
.bar{display:flex;width:160px;height:12px;background:#eee}
.bar span{display:block;height:100%}.m{background:#c0392b}.h{background:#e67e22}.s{background:#7f8c8d}
.key span{display:inline-block;width:10px;height:10px;margin:0 4px 0 12px}
.note{color:#555;font-size:0.9em}section{margin-bottom:2em}
"""


def _html(summary: dict[str, Any]) -> str:
    e = html.escape
    t = summary["totals"]
    cells = summary["cells"]
    ranked = {name: k for k, name in enumerate(summary["ranking"])}
    rows = sorted(cells, key=lambda c: ranked.get(c["cell"], len(ranked)))
    ranking = "".join(
        "<tr>"
        f"<td>{c.get('rank', '–')}</td><td class=t>{e(c['cell'])}</td><td class=t>{e(c['status'])}</td>"
        f"<td class=t>{e(str(c.get('written') or '–'))}</td><td class=t>{e(str(c.get('measure', '–')))}</td>"
        f"<td>{_n(c.get('default_cycle_s'), 2)}</td><td>{_n(c.get('default_J_per_cycle'))}</td>"
        f"<td>{_n(c.get('optimized_J_per_cycle'))}</td><td>{_n(c.get('saved_pct'), 2)}</td>"
        f"<td>{_n(c.get('cycles_per_year'), 0)}</td><td>{_n(c.get('saved_kWh_per_year'))}</td>"
        f"<td>{_n(c.get('saved_EUR_per_year'), 2)}</td><td>{_n(c.get('saved_CO2_kg_per_year'))}</td>"
        "</tr>"
        for c in rows
    )
    where = "".join(
        "<tr>"
        f"<td>{e(c['cell'])}</td><td class=t>{_bar(c['split_default'])}</td>"
        f"<td>{_n(c['split_default']['motion_J'])}</td><td>{_n(c['split_default']['holding_J'])}</td>"
        f"<td>{_n(c['split_default']['standby_J'])}</td><td>{_n(c['split_default']['standstill_s'], 2)}</td>"
        f"<td>{_n(c.get('waits_s'), 2)}</td><td>{_n(c.get('idle_modes_kWh_per_year'))}</td>"
        f"<td class=t>{e(_modes_used(c))}</td></tr>"
        for c in rows
        if "split_default" in c
    )
    kept = "".join(
        f"<tr><td>{e(c['cell'])}</td><td class=t>{e(c.get('written_note') or c.get('reason') or '')}</td>"
        f"<td class=t>{'<br>'.join(e(_kept(m)) for m in c.get('moves_kept', []))}</td></tr>"
        for c in rows
    )
    measures = sorted({str(c["measure_note"]) for c in cells if c.get("measure_note")})
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{e(summary["plant"])}: plant energy report</title>
<meta name="viewport" content="width=device-width, initial-scale=1"><style>{_CSS}</style></head>
<body>
<h1>{e(summary["plant"])}: plant energy report</h1>
<section id="summary"><h2>Summary</h2>
<p>{summary["n_cells"]} cell programs: {summary["n_ok"]} optimized, {summary["n_refused"]} refused,
{summary["n_failed"]} failed, {summary["n_missing"]} not computed. {summary["hours_per_year"]:,.0f}
production hours
a year, {summary["tariff_eur_per_kwh"]:.3f} €/kWh, {summary["co2_kg_per_kwh"]:.3f} kg CO₂/kWh.</p>
<p>At the meter ({t["cells_at_the_meter"]} cells with drive data): the robots draw
<b>{_n(t["default_kWh_per_year"], 0)} kWh a year</b> as taught. Reshaping the motions at the same
cycle time saves
<b>{_n(t["saved_kWh_per_year"])} kWh</b> ({_n(t["saved_pct"], 2)} %), {_n(t["saved_EUR_per_year"], 0)} € and
{_n(t["saved_CO2_kg_per_year"], 0)} kg CO₂ a year. Of that energy, motion is
{_n(t["motion_share_pct"])} %, holding the
arm at rest {_n(t["holding_share_pct"])} % and the cabinets' standby {_n(t["standby_share_pct"])} %: motion
reshaping reaches the motion share only. Power-saving modes in the pauses could save about
<b>{_n(t["idle_modes_kWh_per_year"])} kWh a year</b> ({_n(t["idle_modes_pct"], 1)} %):
{e(t["idle_modes_note"])}.</p>
<p class="note">Measures: {e("; ".join(measures))}. {e(t["note"])}.</p>
</section>
<section id="ranking"><h2>Cells ranked by saving</h2>
<table><tr><th>#</th><th>cell</th><th>status</th><th>written</th><th>measure</th><th>cycle s</th>
<th>J/cycle taught</th><th>J/cycle optimized</th><th>saved %</th><th>cycles/year</th><th>kWh/year saved</th>
<th>€/year saved</th><th>kg CO₂/year saved</th></tr>{ranking}</table></section>
<section id="energy"><h2>Where each cell's energy goes (taught cycle)</h2>
<p class="key"><span class="m"></span>motion<span class="h"></span>holding at rest<span
class="s"></span>standby</p>
<table><tr><th>cell</th><th>share</th><th>motion J</th><th>holding J</th><th>standby
J</th><th>standing s/cycle</th>
<th>waits s/cycle</th><th>power-saving modes kWh/year (recommendation)</th><th>modes in
pauses</th></tr>{where}</table>
<p class="note">Standing time: every sample where the arm stands still (waits, I/O handshakes, stops at fine
points). {e(IDLE_NOTE)}.</p></section>
<section id="programs"><h2>What was written, and the moves kept</h2>
<table><tr><th>cell</th><th>written, or why not</th><th>moves kept as taught, and
why</th></tr>{kept}</table>
</section>
</body></html>
"""


def _kept(m: dict[str, Any]) -> str:
    return f"line {m['line']} {m['label']}: {m['why']}"


def _modes_used(c: dict[str, Any]) -> str:
    modes = c.get("idle_modes") or {}
    if not modes.get("available"):
        return str(modes.get("why", ""))
    used = modes.get("pauses_used") or {}
    return ", ".join(f"{m}: {k} pause(s)" for m, k in sorted(used.items())) or "no pause long enough"


def write_plant_report(plant: PlantConfig, out: str | Path) -> dict[str, Path]:
    """Write ``plant.json``, ``cells.csv``, ``report.html`` and ``cells/<name>/`` (each cell's
    ``cycle.json`` and ``optimized.mod``) from the stored results; the paths written, by name."""
    root = make_folder(Path(out))
    summary = plant_summary(plant, root)
    files: dict[str, Path] = {}
    for c in summary["cells"]:
        stored = root / CACHE / c["key"]
        for name in RETURNED_FILES:
            src = stored / name
            dst = root / "cells" / c["cell"] / name
            if src.is_file():
                make_folder(dst.parent)
                atomic_write_text(dst, src.read_text(encoding="utf-8"))
            elif dst.is_file():
                remove_output(dst)
    files["plant.json"] = atomic_write_text(
        root / "plant.json", json.dumps(summary, indent=1, allow_nan=False)
    )
    files["cells.csv"] = atomic_write_text(root / "cells.csv", _csv(summary))
    files["report.html"] = atomic_write_text(root / "report.html", _html(summary))
    return files
