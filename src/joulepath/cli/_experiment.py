"""``joulepath run EXPERIMENT.toml`` and ``joulepath demo``."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import typer

from joulepath.cli._common import check_out_folder, console
from joulepath.errors import InvalidInput

BUNDLED = ("demo", "study", "thesis")
RUNS = Path("runs")
"""Where runs go unless ``--out`` says otherwise: ``runs/<name>`` (``make demo`` too: ``runs/demo``)."""


def default_folder(name: str) -> Path:
    """The run folder of the experiment called ``name`` when no ``--out`` is given."""
    return RUNS / name


def _experiment_path(name: str) -> Path:
    from importlib import resources

    if name in BUNDLED:
        return Path(str(resources.files("joulepath.experiment") / "presets" / f"{name}.toml"))
    return Path(name)


@contextmanager
def _bars(enabled: bool) -> Iterator[object]:
    """Rich progress bars keyed by label; a no-op callback when disabled."""
    if not enabled:
        yield lambda _label, _done, _total: None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(
        TextColumn("{task.description:<22}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        transient=False,
    ) as bars:
        tasks: dict[str, object] = {}

        def update(label: str, done: int, total: int) -> None:
            if label not in tasks:
                tasks[label] = bars.add_task(label, total=total)
            bars.update(tasks[label], completed=done, total=total)  # type: ignore[arg-type]

        yield update


def _run(experiment: str, out: Path | None, quiet: bool, scheduler: str | None) -> int:
    from joulepath.experiment import load_experiment, run_experiment

    exp = load_experiment(_experiment_path(experiment))
    folder = out or default_folder(exp.name)
    from joulepath._runfolder import RUN_FILES, STAGE_FOLDERS

    check_out_folder(folder, files=RUN_FILES, inputs=[str(_experiment_path(experiment))])
    for name in STAGE_FOLDERS:
        stage = folder / name
        if os.path.lexists(stage) and (stage.is_symlink() or not stage.is_dir()):
            raise InvalidInput(
                f"{stage}: is not a folder, but the run keeps its {name} stage there; "
                "move it or choose another --out"
            )
    say = (lambda _t: None) if quiet else (lambda t: console.print(t, markup=False))
    with _bars(not quiet and console.is_terminal) as progress:
        summary = run_experiment(exp, folder, say=say, progress=progress, scheduler=scheduler)  # type: ignore[arg-type]
    saved = summary["mean_saved_pct"]
    if quiet:
        console.print(
            f"{exp.name}: "
            + (f"mean saving {saved:.1f} % at equal cycle time; " if saved is not None else "")
            + f"report: {summary['report']}",
            markup=False,
        )
    return 0  # without --quiet, the run's last line already names the report


def run(
    experiment: str = typer.Argument(
        ...,
        help="Experiment TOML file, or a bundled one: demo (minutes), study (a larger demo), "
        "thesis (the full plan).",
    ),
    out: Path = typer.Option(None, "--out", help="Run folder (default: runs/<name>)."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress; print only the last line."),
    scheduler: str = typer.Option(
        None, "--scheduler", help="Dask scheduler address (tcp://host:8786) for grid search and benchmark."
    ),
) -> int:
    """Run a whole study from one file: data, synthetic data, models, importance, optimized
    moves, benchmark, then report.html. Unchanged stages are skipped."""
    return _run(experiment, out, quiet, scheduler)


def demo(
    out: Path = typer.Option(None, "--out", help="Run folder (default: runs/demo, as `joulepath run demo`)."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress; print only the last line."),
) -> int:
    """The bundled demo study on the IRB 120: the same as ``joulepath run demo``, into the same
    folder (runs/demo), so either reuses what the other computed."""
    return _run("demo", out, quiet, None)
