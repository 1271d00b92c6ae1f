"""``joulepath synth`` and ``joulepath compare`` (register with ``app.command("synth")(synth)``)."""

from __future__ import annotations

from pathlib import Path

import typer

from joulepath.cli._common import check_out_file, check_out_folder, console, robot_inputs
from joulepath.description import DEFAULT_ROBOT


def synth(
    method: str = typer.Option("tvae", "--method", help="copula, ctgan, copulagan or tvae (SDV)."),
    source: Path | None = typer.Option(
        None, "--from", help="Real energy table (.parquet) to learn, e.g. the micro set."
    ),
    rows: int = typer.Option(75000, "--rows", min=1, help="Synthetic rows to sample."),
    out: Path = typer.Option(..., "--out", help="Synthetic energy table to write (.parquet)."),
    seed: int = typer.Option(0, "--seed", min=0, max=2**32 - 1, help="Seed of the fit and the sample."),
    epochs: int = typer.Option(300, "--epochs", min=1, help="Training epochs (neural methods)."),
    batch_size: int = typer.Option(500, "--batch-size", min=2, help="Rows per training batch."),
    repair_kinematics: bool = typer.Option(
        False, "--repair-kinematics", help="Recompute the TCP columns from q (and their derivatives)."
    ),
    robot: str = typer.Option(DEFAULT_ROBOT, "--robot", help="Robot for --repair-kinematics."),
    save_model: Path | None = typer.Option(
        None, "--save-model", help="Also save the fitted synthesizer (a pickle + SHA-256 sidecar)."
    ),
    model: Path | None = typer.Option(
        None, "--model", help="Sample from a synthesizer saved with --save-model instead of fitting."
    ),
    progress: bool = typer.Option(True, "--progress/--no-progress", help="Show per-epoch progress."),
) -> int:
    """Grow a small real energy table into a synthetic one (SDV; thesis §3.4)."""
    from joulepath import load_robot
    from joulepath._io import make_folder
    from joulepath.data import load_table, save_table
    from joulepath.errors import InvalidInput
    from joulepath.synth import SynthConfig, Synthesizer, sidecar_path, synthesize
    from joulepath.synth import repair_kinematics as repair

    inputs = [p for p in (source, model) if p is not None] + robot_inputs(robot)
    check_out_file(out, example="synthetic.parquet", inputs=inputs)
    if save_model is not None:
        check_out_file(save_model, example="synthesizer.pkl", option="--save-model", inputs=[*inputs, out])
        check_out_file(sidecar_path(save_model), example="synthesizer.pkl.json", option="--save-model")
    both = "give exactly one of --from TABLE (fit a synthesizer) or --model FILE (sample a saved one)"
    if model is not None:
        if source is not None:
            raise InvalidInput(both)
        synthesizer = Synthesizer.load(model)
        console.print(f"loaded {model} ({synthesizer.config.method})")
        table = synthesizer.sample(rows, progress=console.print)
        if repair_kinematics:
            table = repair(table, load_robot(robot))
    elif source is not None:
        config = SynthConfig(method=method, epochs=epochs, batch_size=batch_size, seed=seed, verbose=progress)
        real = load_table(source)
        if repair_kinematics and real.feature_set != "full40":
            raise InvalidInput(
                f"{source}: feature set {real.feature_set!r} has no TCP columns for --repair-kinematics to "
                "recompute; leave the option out, or use a full40 table (`joulepath ingest --robot`)"
            )
        if save_model is not None:
            make_folder(save_model.parent)
        table = synthesize(
            real,
            n_rows=rows,
            config=config,
            repair=load_robot(robot) if repair_kinematics else None,
            model_path=save_model,
            progress=console.print,
        )
    else:
        raise InvalidInput(both)
    make_folder(out.parent)
    save_table(table, out)
    seeded = f" (seed {seed})" if model is None else f" (sampled from {model})"
    console.print(
        f"wrote {out}: {len(table.frame):,} synthetic rows, feature set {table.feature_set}{seeded}"
        + (", TCP columns recomputed from q" if repair_kinematics else "")
    )
    return 0


def compare(
    tables: list[Path] = typer.Argument(..., help="Energy tables (.parquet); the first is the reference."),
    out: Path = typer.Option(
        Path("compare"),
        "--out",
        help="Folder for the distribution plots (PNG) and the statistics (statistics.csv).",
    ),
    quality: bool = typer.Option(False, "--quality", help="Score each table against the first (SDMetrics)."),
    robot: str = typer.Option(
        "", "--robot", help="Also report the share of rows within 5 mm of this robot's FK(q)."
    ),
) -> int:
    """Print and write per-column statistics of energy tables, and write distribution overlays.

    --out receives statistics.csv (one row per table column and table, one column
    per statistic), scores.csv with --quality or --robot (one row per table), and
    one PNG per feature group.
    """
    from joulepath.data import load_table
    from joulepath.synth import FEATURE_GROUPS, SCORES_FILE, STATISTICS_FILE
    from joulepath.synth import compare as run

    files = (STATISTICS_FILE, SCORES_FILE, *(f"{g}.png" for g in FEATURE_GROUPS))
    check_out_folder(out, files=files, inputs=[*tables, *robot_inputs(robot)])
    named = {}
    for path in tables:
        name = path.stem
        k = 2
        while name in named:
            name, k = f"{path.stem}-{k}", k + 1
        named[name] = load_table(path)
    result = run(named, out_dir=out, quality=quality, robot=robot or None)
    written = result.write(out)
    console.print(result.to_text(), markup=False)
    console.print("\nwrote " + " and ".join(str(p) for p in written), markup=False)
    return 0
