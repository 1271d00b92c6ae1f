"""``joulepath train`` and ``joulepath importance``."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import typer

from joulepath.cli._common import check_out_folder, console, err_console


def _split(
    text: str, option: str, allowed: tuple[str, ...], all_value: tuple[str, ...] | None = None
) -> tuple[str, ...]:
    items = tuple(t.strip() for t in text.split(",") if t.strip())
    if all_value is not None and items == ("all",):
        return all_value
    bad = [t for t in items if t not in allowed]
    if bad or not items:
        raise typer.BadParameter(
            f"{', '.join(bad) or 'nothing'} not allowed; use any of {', '.join(allowed)}"
            + (" or all" if all_value else ""),
            param_hint=option,
        )
    return items


@contextmanager
def _progress_lines(label: str) -> Iterator[Callable[[str], None]]:
    """A progress callback: a live status line on a terminal, plain lines on stderr otherwise."""
    if console.is_terminal:
        with console.status(label) as status:
            yield lambda message: status.update(message)
        return

    def line(message: str) -> None:
        print(message, file=sys.stderr, flush=True)

    yield line


def train(
    data: Path = typer.Option(..., "--data", help="Training energy table (.parquet)."),
    test: Path = typer.Option(..., "--test", help="Test table of other moves (.parquet)."),
    family: str = typer.Option("all", help="mlp, svr, par, xgb, bases (comma separated) or all."),
    target: str = typer.Option("E", help="Targets: E, E1..En (comma separated) or all."),
    grid: str = typer.Option("quick", help="quick, or thesis (Tables 2.2-2.5)."),
    cv: int = typer.Option(5, min=2, help="Folds."),
    inputs: str = typer.Option(
        "",
        help="physics (raw + nominal model terms), kinematic (raw + robot-free energy bases) or thesis "
        "(raw); default: physics with a robot known (--robot or the table's), else kinematic. The grid "
        "search's CV is grouped by run (the logs of the table), by contiguous spans of each run's moves "
        "when there are fewer runs than folds, by move for a table of one log.",
    ),
    out: Path = typer.Option(..., "--out", help="Folder for models and reports."),
    seed: int = typer.Option(0, min=0, max=2**32 - 1, help="Random seed."),
    jobs: int = typer.Option(1, min=1, help="Local processes for the grid search."),
    scheduler: str = typer.Option("", help="Dask scheduler address (tcp://HOST:PORT) for the grid search."),
    robot: str = typer.Option(
        "", help="Robot of the data (name, .irml/.urdf or twin folder); default: the table's robot."
    ),
) -> int:
    """Tune (grid search + CV), refit and test energy models; save them with cards and reports."""
    from joulepath import load_robot
    from joulepath.data import MAX_JOINTS, load_table, target_columns
    from joulepath.errors import InvalidInput
    from joulepath.learn import FAMILIES, NO_ROBOT_NOTE, TrainConfig
    from joulepath.learn import train as run

    check_out_folder(  # the names every training writes, before any work
        out, files=("results.csv", "report.json", "importance_E.csv", "importance_E.png", "joints.json")
    )
    config = TrainConfig(
        families=_split(family, "--family", FAMILIES, FAMILIES),
        targets=_split(target, "--target", target_columns(MAX_JOINTS), target_columns(MAX_JOINTS)),
        grid=grid,
        cv=cv,
        inputs=inputs or None,
        seed=seed,
        n_jobs=jobs,
        scheduler=scheduler or None,
        robot=robot or None,
    )
    if robot:
        load_robot(robot)  # an unknown robot fails now, not after the training
    train_table, test_table = load_table(data), load_table(test)
    if target.strip() == "all":  # every target of the table's arm: E1..En and E
        config = replace(config, targets=train_table.targets)
    for path, table, what in ((data, train_table, "--data"), (test, test_table, "--test")):
        if len(table.frame) == 0:
            raise InvalidInput(
                f"{path}: the table has no rows; give {what} a table ingested from logs with moves"
            )
    if train_table.feature_set != test_table.feature_set:
        raise InvalidInput(
            f"{test}: feature set {test_table.feature_set!r}, but {data} has {train_table.feature_set!r}; "
            "ingest both tables the same way (both with --robot, or both without)"
        )
    if train_table.n_moves < cv:
        raise InvalidInput(
            f"{data}: {train_table.n_moves} moves are too few for --cv {cv} grouped folds; "
            f"give --cv {train_table.n_moves} or less, or a table of more moves"
        )
    with _progress_lines("training...") as say:

        def tell(message: str) -> None:  # the choice of inputs stays on screen, the progress passes
            if message == NO_ROBOT_NOTE:
                err_console.print(message, markup=False)
            else:
                say(message)

        report = run(train_table, test_table, config, out, progress=tell)
    cols = [
        "family",
        "target",
        "inputs",
        "cv_groups",
        "cv_grouped_r2",
        "cv_shuffled_r2",
        "test_r2",
        "test_mae",
        "test_outside_range_pct",
        "path_median_pct",
        "path_p95_pct",
        "best_params",
    ]
    console.print(
        report.results[cols].to_string(index=False, float_format=lambda v: f"{v:.4f}"), markup=False
    )
    for b in report.baselines:
        s = b["scores"]["E"]
        console.print(
            f"{b['label']}: R² {s['r2']:.4f}, MAE {s['mae']:.4f} J, path error median "
            f"{s['path_median_pct']:.1f} %, {b['latency_per_row_s_batch'] * 1e6:.2f} µs/row",
            markup=False,
        )
    outside = report.results["test_outside_range_pct"]
    if (outside > 0).any():
        console.print(
            f"note: up to {outside.max():.1f} % of the test rows lie outside the training data's range "
            "(speeds, accelerations, positions, move durations: each card's training_range); their "
            "predictions are extrapolations",
            markup=False,
        )
    console.print(f"models, results.csv, report.json and plots in {out}")
    return 0


def importance(
    data: Path = typer.Option(..., "--data", help="Energy table (.parquet)."),
    target: str = typer.Option("E", help="Target: E or E1..En."),
    out: Path = typer.Option(..., "--out", help="Folder for importance.csv and the plot."),
    seed: int = typer.Option(0, min=0, max=2**32 - 1, help="Random seed."),
) -> int:
    """Rank the inputs (and joints) by their influence on the energy (thesis Figs 4.1-4.2)."""
    from joulepath._io import atomic_write_text, make_folder
    from joulepath.data import load_table
    from joulepath.learn import feature_importance, plot_importance, rank_joints

    check_out_folder(out, files=(f"importance_{target}.csv", f"importance_{target}.png"), inputs=[data])
    table = load_table(data)
    imp = feature_importance(table, target, seed=seed)
    make_folder(out)
    atomic_write_text(out / f"importance_{target}.csv", imp.to_csv())
    plot_importance(imp, out / f"importance_{target}.png", title=f"Feature importance for {target}")
    console.print(imp.head(12).to_string(float_format=lambda v: f"{v:.3f}"), markup=False)
    console.print(f"joints by influence on {target}: {rank_joints(imp)}")
    return 0
