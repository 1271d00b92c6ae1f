"""``joulepath plant``: every cell program of a plant optimized on Dask, with the plant's report."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import typer

from joulepath.cli._common import check_out_folder, console, err_console


@contextmanager
def _progress(total_hint: str) -> Iterator[Callable[[Any], None]]:
    """A bar of cells done, failed and remaining on a terminal; else one plain line per cell (stderr)."""
    if err_console.is_terminal:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        with Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[tally]}"),
            TimeElapsedColumn(),
            console=err_console,
        ) as bar:
            task = bar.add_task(total_hint, total=None, tally="")

            def update(p: Any) -> None:
                bar.update(
                    task,
                    total=p.total,
                    completed=p.done + p.failed,
                    tally=f"{p.done} done, {p.failed} failed, {p.remaining} remaining",
                )

            yield update
        return

    def line(p: Any) -> None:
        where = f"{p.cell}: {p.status}; " if p.cell is not None else ""
        print(
            f"plant: {where}{p.done} done, {p.failed} failed, {p.remaining} remaining of {p.total}",
            file=sys.stderr,
            flush=True,
        )

    yield line


def plant(
    plant_file: Path = typer.Argument(
        ..., help="Plant file (TOML): [plant], [defaults] and one [[cell]] per program."
    ),
    out: Path = typer.Option(..., "--out", help="Run folder (its cache/ keeps finished cells between runs)."),
    jobs: int = typer.Option(
        None, "--jobs", min=1, max=512, help="Worker processes of a local Dask cluster (default 1)."
    ),
    scheduler: str = typer.Option(
        None, "--scheduler", help="tcp://HOST:PORT of a running Dask scheduler, instead of a local cluster."
    ),
) -> int:
    """Optimize every cell program of a plant on Dask; write plant.json, cells.csv and report.html.

    Each cell runs as `joulepath cycle` would, as one task; finished cells are kept in OUT/cache
    by their input hash, so a rerun (or a run resumed after an interruption) computes only the
    rest. Exit code 0: every cell optimized or refused with its reason; 1: a cell failed (see
    the report); 2: a bad plant file (one line per problem, nothing computed).
    """
    from joulepath.plant import PlantFileError, read_plant, run_plant, write_plant_report

    if jobs is not None and scheduler is not None:
        raise typer.BadParameter("give --jobs (a local cluster) or --scheduler (a running one), not both")
    if scheduler is not None and not scheduler.startswith(
        ("tcp://", "tls://", "inproc://", "ws://", "wss://")
    ):
        raise typer.BadParameter(f"{scheduler!r}: give tcp://HOST:PORT", param_hint="--scheduler")
    if not plant_file.is_file():
        raise typer.BadParameter(f"{plant_file}: no such file", param_hint="PLANT_FILE")
    check_out_folder(out, files=("plant.json", "cells.csv", "report.html"), inputs=[plant_file])
    try:
        config = read_plant(plant_file)
    except PlantFileError as err:
        for problem in err.problems:
            print(f"error: {problem}", file=sys.stderr)
        print(f"error: {len(err.problems)} problem(s) in {plant_file}; nothing was computed", file=sys.stderr)
        raise typer.Exit(2) from None
    try:
        with _progress(f"{config.name}: cells") as say:
            run = run_plant(config, out, jobs=jobs, scheduler=scheduler, progress=say)
    except KeyboardInterrupt:
        print(
            f"interrupted: the cells finished so far are kept in {out / 'cache'}; run the same command "
            "again to compute the rest",
            file=sys.stderr,
        )
        raise typer.Exit(130) from None
    files = write_plant_report(config, out)
    import json

    summary = json.loads(files["plant.json"].read_text(encoding="utf-8"))
    t = summary["totals"]
    console.print(
        f"{config.name}: {run.n_cells} cells, {len(run.computed)} computed in this run, "
        f"{len(run.cached)} from the cache ({run.wall_s:.0f} s); {summary['n_ok']} optimized, "
        f"{summary['n_refused']} refused, "
        f"{summary['n_failed']} failed",
        markup=False,
    )
    if t["cells_at_the_meter"]:
        console.print(
            f"at the meter: {t['default_kWh_per_year']:.0f} kWh a year as taught; motion reshaping saves "
            f"{t['saved_kWh_per_year']:.1f} kWh ({t['saved_pct']:.2f} %), "
            f"{t['saved_EUR_per_year']:.0f} EUR and "
            f"{t['saved_CO2_kg_per_year']:.0f} kg CO2 a year; power-saving modes in the pauses could save "
            f"{t['idle_modes_kWh_per_year']:.0f} kWh more (a recommendation under assumed mode powers)",
            markup=False,
        )
    for c in summary["cells"]:
        if c["status"] == "failed":
            console.print(f"FAILED {c['cell']}: {c['reason']}", markup=False)
    console.print(f"wrote {', '.join(sorted(files))} and cells/ in {out}", markup=False)
    return 1 if summary["n_failed"] else 0
