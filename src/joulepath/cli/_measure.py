"""``joulepath measure``: what ran in a log of path.mod, against the run folder that planned it."""

from __future__ import annotations

from pathlib import Path

import typer

from joulepath.cli._common import check_out_folder, console


def measure(
    log: Path = typer.Argument(
        ..., help="Controller log of a run of path.mod (measured, or `simulate --program`)."
    ),
    plan: Path = typer.Option(
        ..., "--plan", help="The run folder of `joulepath optimize` that wrote path.mod."
    ),
    out: Path = typer.Option(..., "--out", help="Folder for measure.json and power.png."),
) -> int:
    """Measure the default and the optimized move's repetitions: energies, saving, durations, tracking.

    Nothing is written when the log does not match the plan (exit 2, one line).
    """
    from joulepath.measure import MEASURE_FILES, PLAN_FILES, measure_run, write_measure

    check_out_folder(out, files=MEASURE_FILES, inputs=[log, *(plan / name for name in PLAN_FILES)])
    with console.status(f"measuring {log.name} against {plan}..."):
        run = measure_run(log, plan)
        files = write_measure(run, out)
    m = run.measurement
    s = m.saving
    console.print(
        f"{m.default.n} default and {m.optimized.n} optimized moves ({m.classified_by}): "
        f"{m.default.energy_mean_J:.2f} J -> {m.optimized.energy_mean_J:.2f} J, saving {s.pct:.1f} % "
        f"(95 %: {s.ci95_low_pct:.1f} to {s.ci95_high_pct:.1f} %)"
    )
    console.print(
        f"executed {m.default.duration_mean_s:.2f} s (default) and {m.optimized.duration_mean_s:.2f} s "
        f"(optimized) for a planned {m.planned_duration_s:g} s"
    )
    for note in m.notes:
        console.print(f"note: {note}")
    console.print(f"wrote {files['measure.json']} and {files['power.png']}")
    return 0
