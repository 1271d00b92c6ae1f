"""``joulepath identify``: a calibrated twin from a robot's own logs."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import typer

from joulepath.cli._common import check_out_folder, console, err_console, robot_inputs
from joulepath.cli._robot import load_robot_for_cli, unchecked_option


def identify(
    logs: list[Path] = typer.Argument(..., help="Controller or generic logs of the robot (CSV)."),
    robot: str = typer.Option(
        "irb120",
        help="The logged robot: a bundled name, a named arm (ur5, panda, ...), an .irml or .urdf path "
        "or a twin folder (nominal parameters).",
    ),
    out: Path = typer.Option(
        ...,
        "--out",
        help="Twin folder to write (robot.irml, or robot.urdf for a URDF arm; friction.json, card.json).",
    ),
    holdout: float = typer.Option(
        0.2, "--holdout", min=0.0, max=0.8, help="Share of the samples (the last ones) kept out and scored."
    ),
    stribeck_speed: float = typer.Option(
        0.0, "--stribeck-speed", min=0.0, help="rad/s: also identify a Stribeck term of this speed (0: none)."
    ),
    offset: bool = typer.Option(True, "--offset/--no-offset", help="Identify a friction offset per joint."),
    viscous_offset: bool = typer.Option(
        False,
        "--viscous-per-direction/--no-viscous-per-direction",
        help="Identify the viscous friction level per direction of motion (a viscous offset per joint).",
    ),
    armature: bool = typer.Option(
        True,
        "--armature/--no-armature",
        help="Identify an armature per joint (the drives' rotor inertia reflected to the joint, kg·m²).",
    ),
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
    payload_log: Path = typer.Option(
        None,
        "--payload-log",
        help="A log of currents (i1..in, A) of the robot carrying a known payload: the scale between "
        "current and torque (default: the description's nominal masses).",
    ),
    payload_mass: float = typer.Option(
        0.0, "--payload-mass", min=0.0, help="kg: the mass of the payload in --payload-log."
    ),
    payload_com: str = typer.Option(
        "",
        "--payload-com",
        help="X,Y,Z: the payload's centre of mass in the flange (tool0) frame, m (e.g. 0.05,0,0.08).",
    ),
    unexcited: str = typer.Option(
        "prior",
        "--unexcited",
        help="prior: keep a parameter the logs do not excite at its prior (the nominal description's, "
        "the robot's friction, else 0), with a warning; refuse: refuse such logs.",
    ),
    speed_cutoff: str = typer.Option(
        "auto",
        "--speed-cutoff",
        help="How accelerations are derived from the logged speeds: HZ low-passes them at HZ (zero phase, "
        "uniform time base) before differentiation; off differentiates them raw; auto: 20 Hz for a "
        "log of 200 Hz or more without ddq columns, else off. Torques and currents stay raw.",
    ),
    force: bool = typer.Option(False, "--force", help="Replace a twin already in --out."),
    unchecked: bool = unchecked_option(),
) -> int:
    """Identify the robot's dynamics (base inertial parameters, friction, gear losses) from its logs.

    Writes a twin folder that every command takes as --robot FOLDER. Logs that cannot
    identify the model (too short, a joint that never moves, a badly conditioned
    regressor) are refused with the reason; nothing is written then.

    Logs of motor currents (i1..in, no torques) also give the drives' joint-side torque
    constants (N·m/A), written to the twin's drives.toml. The scale between current and
    torque comes from --payload-log with --payload-mass and --payload-com (a payload of
    known mass), else from the description's nominal masses; the output says which.
    """
    from joulepath.dynamics import TWIN_CARD_FILE, TWIN_FRICTION_FILE, TWIN_ROBOT_FILE, TWIN_URDF_FILE
    from joulepath.energy import TWIN_DRIVES_FILE
    from joulepath.errors import InvalidInput
    from joulepath.identify import (
        IdentifyOptions,
        PayloadReference,
        UnexcitedParameterWarning,
        data_from_logs,
        identified_drives,
        identify_from_currents,
        logged_signal,
        parameter_report,
        write_twin,
    )
    from joulepath.identify import identify as run

    cutoff = parse_speed_cutoff(speed_cutoff)
    com = _payload_options(payload_log, payload_mass, payload_com)
    inputs = [*map(str, logs), *([str(payload_log)] if payload_log else []), *robot_inputs(robot)]
    signal = "current" if payload_log is not None else logged_signal(logs)
    nominal = load_robot_for_cli(robot, unchecked=unchecked)
    robot_file = TWIN_ROBOT_FILE if nominal.description is not None else TWIN_URDF_FILE
    files: tuple[str, ...] = (robot_file, TWIN_FRICTION_FILE, TWIN_CARD_FILE)
    if signal == "current":
        files = (*files, TWIN_DRIVES_FILE)
    check_out_folder(out, files=files, inputs=inputs)
    twin_files = (TWIN_ROBOT_FILE, TWIN_URDF_FILE, *files[1:])
    existing = [name for name in twin_files if (out / name).exists()]
    if existing and not force:
        raise InvalidInput(
            f"{out}: already holds a twin ({', '.join(existing)}); pass --force to replace it, "
            "or choose another --out"
        )
    options = IdentifyOptions(
        offset=offset,
        viscous_offset=viscous_offset,
        stribeck_speed=stribeck_speed or None,
        gear_efficiency=gear_efficiency or None,
        max_condition=max_condition,
        holdout=holdout,
        unexcited=unexcited,
        armature=armature,
    )
    with console.status(f"reading {len(logs)} log(s)..."):
        data = data_from_logs(logs, nominal, signal=signal, speed_cutoff_hz=cutoff)
        payload = None
        if payload_log is not None and com is not None:
            payload = PayloadReference(
                data=data_from_logs([payload_log], nominal, signal="current", speed_cutoff_hz=cutoff),
                mass=payload_mass,
                com=com,
            )
    if data.motion is not None:
        console.print(data.motion.describe(), markup=False)
    # each parameter kept at its prior is said once below, in one line (not as a Python warning)
    if signal == "current":
        with (
            console.status(f"identifying drive gains and dynamics from {data.n_samples:,} samples..."),
            warnings.catch_warnings(),
        ):
            warnings.simplefilter("ignore", UnexcitedParameterWarning)
            both = identify_from_currents(data, nominal, options, payload=payload)
        result, gains = both.identification, both.gains
        drives = identified_drives(gains, nominal.drives, nominal.n_joints)
        write_twin(result, nominal, out, extra=both.card(), drives=drives, gains=gains)
        for assumed in gains.assumed:
            err_console.print(f"warning: {assumed.warning()}", markup=False)
        pairs = zip(gains.torque_constant, gains.relative_error, strict=True)
        k = ", ".join(
            f"{v:.4g} (assumed)" if gains.status(j + 1) == "assumed" else f"{v:.4g} ± {100 * e:.2g} %"
            for j, (v, e) in enumerate(pairs)
        )
        console.print(f"drive gains k (N·m/A, joint side): {k}", markup=False)
        console.print(f"scale reference: {gains.reference} ({gains.reference_note})", markup=False)
    else:
        with console.status(f"identifying from {data.n_samples:,} samples..."), warnings.catch_warnings():
            warnings.simplefilter("ignore", UnexcitedParameterWarning)
            result = run(data, nominal, options)
        write_twin(result, nominal, out)
        gains, drives = None, None
    for kept in result.kept:
        err_console.print(f"warning: {kept.warning()}", markup=False)
    f = result.fit
    what = "current" if signal == "current" else "torque"
    console.print(
        f"identified {result.base.n} base parameters and friction of {nominal.name} from {f.n_samples:,} "
        f"samples; condition number {result.condition_number:.1f} (least excited: {result.weakest}); "
        f"gear efficiency {result.gear_efficiency:.3f}; physically consistent: {result.consistent}"
    )
    console.print(
        f"fit: {what} R² {min(f.torque_r2):.4f} (worst joint), energy R² {f.energy_r2:.4f}",
        markup=False,
    )
    if result.held_out is not None:
        h = result.held_out
        console.print(
            f"held out ({h.n_samples:,} samples): {what} R² {min(h.torque_r2):.4f} (worst joint), "
            f"energy R² {h.energy_r2:.4f}, energy error {h.energy_error_pct:.2f} %",
            markup=False,
        )
    assumed_rows = [
        f"joint {row['joint']}: {name}"
        for row in parameter_report(result, gains=gains, drives=drives)
        for name, entry in row.items()
        if isinstance(entry, dict) and entry.get("status") == "assumed"
    ]
    console.print(
        "assumed, not identified: "
        + ("; ".join(assumed_rows) if assumed_rows else "nothing")
        + f" (per joint and parameter: {out / TWIN_CARD_FILE}, 'parameters')",
        markup=False,
    )
    console.print(f"wrote {out}/: {', '.join(files)} (use it as --robot {out})")
    return 0


def parse_speed_cutoff(text: str) -> float | str | None:
    """``--speed-cutoff``: ``"auto"``, None for ``off`` (raw), or a frequency in Hz."""
    from joulepath.errors import InvalidInput

    word = text.strip().lower()
    if word == "auto":
        return "auto"
    if word in ("off", "none", "raw"):
        return None
    try:
        hz = float(word.removesuffix("hz"))
    except ValueError:
        hz = float("nan")
    if not (math.isfinite(hz) and hz > 0):
        raise InvalidInput(
            f"--speed-cutoff {text!r}: give a frequency in Hz (e.g. 20), off (differentiate the raw "
            "speeds) or auto (20 Hz for logs of 200 Hz or more)"
        )
    return hz


def _payload_options(log: Path | None, mass: float, com: str) -> tuple[float, float, float] | None:
    """The payload's centre of mass (m), or None without a payload log; one line for what is missing."""
    from joulepath.errors import InvalidInput

    if log is None:
        if mass or com:
            raise InvalidInput(
                "--payload-mass and --payload-com describe the payload of --payload-log; give the log "
                "of currents the robot made carrying it (--payload-log FILE)"
            )
        return None
    if not mass > 0 or not com:
        raise InvalidInput(
            f"--payload-log {log} needs the payload's --payload-mass KG and --payload-com X,Y,Z (m, "
            "flange frame): without them it fixes no scale"
        )
    try:
        values = tuple(float(v) for v in com.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InvalidInput(
            f"--payload-com {com!r}: give three numbers X,Y,Z in m (flange frame), e.g. 0.05,0,0.08"
        )
    return (values[0], values[1], values[2])
