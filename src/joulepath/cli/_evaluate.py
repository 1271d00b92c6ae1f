"""``joulepath evaluate``: score any robot model on any joint log."""

from __future__ import annotations

from pathlib import Path

import typer

from joulepath.cli._common import check_out_folder, console, robot_inputs
from joulepath.cli._robot import load_robot_for_cli, unchecked_option


def evaluate(
    log: Path = typer.Argument(..., help="A controller or generic log (CSV; may hold currents i1..in, A)."),
    robot: str = typer.Option(..., "--robot", help="The model: robot name, .irml/.urdf path or twin folder."),
    out: Path = typer.Option(..., "--out", help="Folder for evaluate.json, predictions.csv and plots."),
    drives: Path = typer.Option(
        None,
        "--drives",
        help="Drives file with torque_constant = [...] (N·m/A, joint side); default: <stem>.drives.toml "
        "beside the description, or drives.toml in a twin folder, if there.",
    ),
    speed_cutoff: str = typer.Option(
        None,
        "--speed-cutoff",
        help="How accelerations are derived from the logged speeds (as identify's option: HZ, off or "
        "auto); default: what a twin's card says it was identified with, else auto. The logged torques "
        "and currents are scored raw.",
    ),
    unchecked: bool = unchecked_option(),
) -> int:
    """Score a model on a log: per joint R² of torque and current, per-move energy, holding at rest.

    Currents need the drives' joint-side torque constants; without them the current
    scores say what to provide. Nothing is written for a log or model that is refused.
    The motion that predicts is derived as the twin was identified (its card), or as
    --speed-cutoff says; the output says in one line what was applied.
    """
    from joulepath.cli._identify import parse_speed_cutoff
    from joulepath.identify import (
        EVALUATE_FILES,
        EvaluateConfig,
        drives_path,
        evaluate_model,
        read_drive_gains,
        twin_speed_cutoff,
        write_evaluation,
    )

    if speed_cutoff is not None:
        cutoff, origin = parse_speed_cutoff(speed_cutoff), f"--speed-cutoff {speed_cutoff}"
    else:
        on_card, cutoff = twin_speed_cutoff(robot)
        origin = "as the twin's card says it was identified" if on_card else "the default, auto"
        if not on_card:
            cutoff = "auto"
    inputs = [str(log), *robot_inputs(robot), *([str(drives)] if drives else [])]
    check_out_folder(out, files=EVALUATE_FILES, inputs=inputs)
    model = load_robot_for_cli(robot, unchecked=unchecked)
    found = drives if drives is not None else drives_path(robot, model)
    gains = read_drive_gains(found, model.n_joints) if drives is not None or found.is_file() else None
    with console.status(f"evaluating {model.name} on {log}..."):
        result = evaluate_model(
            log, model, robot_source=robot, drives=gains, config=EvaluateConfig(speed_cutoff_hz=cutoff)
        )
    files = write_evaluation(result, out)
    if result.motion is not None:
        console.print(f"{result.motion.describe()} [{origin}]", markup=False)
    s = result.summary()
    for name, key in (("torque", "torque"), ("current", "current")):
        if s[key] is not None:
            r2 = ", ".join("n/a" if v is None else f"{v:.3f}" for v in s[key]["r2"])
            console.print(f"{name} R² per joint: {r2} (mean {s[key]['r2_mean']:.3f})", markup=False)
    if s["energy"] is not None and s["energy"]["n_moves"]:
        e = s["energy"]
        console.print(
            f"energy of {e['n_moves']} moves (from {e['measured_from']}): median error "
            f"{e['median_error_pct']:.2f} %, total {e['total_error_pct']:.2f} %",
            markup=False,
        )
    console.print(f"holding poses at rest: {s['holding']['n_poses']}", markup=False)
    if gains is not None:
        console.print(f"drive data: {gains.origin} (torque constants: {gains.source})", markup=False)
    for note in result.notes:
        console.print(f"note: {note}", markup=False)
    console.print(f"wrote {out}/: {', '.join(files)}")
    return 0
