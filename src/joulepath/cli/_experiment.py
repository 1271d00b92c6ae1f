"""``joulepath run EXPERIMENT.toml``."""

from __future__ import annotations

from pathlib import Path

import typer

from joulepath.cli._common import console


def run(
    experiment: str = typer.Argument(..., help="Experiment TOML file, or a bundled one: demo."),
    out: Path = typer.Option(None, "--out", help="Run folder (default: runs/<name>)."),
    quiet: bool = typer.Option(False, "--quiet", help="Print only the last line."),
) -> int:
    """Run a whole study (data, models, optimized moves); unchanged stages are skipped."""
    from importlib import resources

    from joulepath.experiment import load_experiment, run_experiment

    path = Path(experiment)
    if experiment == "demo":
        path = Path(str(resources.files("joulepath.experiment") / "presets" / "demo.toml"))
    exp = load_experiment(path)
    folder = out or Path("runs") / exp.name
    summary = run_experiment(
        exp, folder, say=(lambda _t: None) if quiet else (lambda t: console.print(t, markup=False))
    )
    if quiet:
        console.print(f"{exp.name}: mean saving {summary['mean_saved_pct']:.1f} %; outputs in {folder}")
    return 0
