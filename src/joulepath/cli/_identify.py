"""``joulepath identify``: a calibrated twin from a robot's own logs."""

from __future__ import annotations

from pathlib import Path

import typer

from joulepath.cli._common import check_out_folder, console, robot_inputs
from joulepath.cli._robot import load_robot_for_cli, unchecked_option


def identify(
    logs: list[Path] = typer.Argument(..., help="Controller or generic logs of the robot (CSV)."),
    robot: str = typer.Option(
        "irb120",
        help="The logged robot: a bundled name, an .irml path or a twin folder (nominal parameters).",
    ),
    out: Path = typer.Option(
        ..., "--out", help="Twin folder to write (robot.irml, friction.json, card.json)."
    ),
    holdout: float = typer.Option(
        0.2, "--holdout", min=0.0, max=0.8, help="Share of the samples (the last ones) kept out and scored."
    ),
    stribeck_speed: float = typer.Option(
        0.0, "--stribeck-speed", min=0.0, help="rad/s: also identify a Stribeck term of this speed (0: none)."
    ),
    offset: bool = typer.Option(True, "--offset/--no-offset", help="Identify a friction offset per joint."),
    gear_efficiency: float = typer.Option(
        0.0,
        "--gear-efficiency",
        min=0.0,
        max=1.0,
        help="Fixed gear efficiency in (0, 1] (1: the logs hold joint-side torque); 0: estimate it.",
    ),
    max_condition: float = typer.Option(
        1e4, "--max-condition", min=1.0, help="Refuse logs whose stacked regressor is worse conditioned."
    ),
    force: bool = typer.Option(False, "--force", help="Replace a twin already in --out."),
    unchecked: bool = unchecked_option(),
) -> int:
    """Identify the robot's dynamics (base inertial parameters, friction, gear losses) from its logs.

    Writes a twin folder that every command takes as --robot FOLDER. Logs that cannot
    identify the model (too short, a joint that never moves, a badly conditioned
    regressor) are refused with the reason; nothing is written then.
    """
    from joulepath.dynamics import TWIN_CARD_FILE, TWIN_FRICTION_FILE, TWIN_ROBOT_FILE
    from joulepath.errors import InvalidInput
    from joulepath.identify import IdentifyOptions, data_from_logs, write_twin
    from joulepath.identify import identify as run

    files = (TWIN_ROBOT_FILE, TWIN_FRICTION_FILE, TWIN_CARD_FILE)
    check_out_folder(out, files=files, inputs=[*map(str, logs), *robot_inputs(robot)])
    existing = [name for name in files if (out / name).exists()]
    if existing and not force:
        raise InvalidInput(
            f"{out}: already holds a twin ({', '.join(existing)}); pass --force to replace it, "
            "or choose another --out"
        )
    nominal = load_robot_for_cli(robot, unchecked=unchecked)
    options = IdentifyOptions(
        offset=offset,
        stribeck_speed=stribeck_speed or None,
        gear_efficiency=gear_efficiency or None,
        max_condition=max_condition,
        holdout=holdout,
    )
    with console.status(f"reading {len(logs)} log(s)..."):
        data = data_from_logs(logs, nominal)
    with console.status(f"identifying from {data.n_samples:,} samples..."):
        result = run(data, nominal, options)
    write_twin(result, nominal, out)
    f = result.fit
    console.print(
        f"identified {result.base.n} base parameters and friction of {nominal.name} from {f.n_samples:,} "
        f"samples; condition number {result.condition_number:.1f} (least excited: {result.weakest}); "
        f"gear efficiency {result.gear_efficiency:.3f}; physically consistent: {result.consistent}"
    )
    console.print(
        f"fit: torque R² {min(f.torque_r2):.4f} (worst joint), energy R² {f.energy_r2:.4f}",
        markup=False,
    )
    if result.held_out is not None:
        h = result.held_out
        console.print(
            f"held out ({h.n_samples:,} samples): torque R² {min(h.torque_r2):.4f} (worst joint), "
            f"energy R² {h.energy_r2:.4f}, energy error {h.energy_error_pct:.2f} %",
            markup=False,
        )
    console.print(f"wrote {out}/: {', '.join(files)} (use it as --robot {out})")
    return 0
