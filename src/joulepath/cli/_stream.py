"""``joulepath stream``: the PC side of an ABB EGM session (serves a run folder's path over UDP)."""

from __future__ import annotations

from pathlib import Path

import typer

from joulepath.cli._common import check_out_folder, console


def stream(
    run_folder: Path = typer.Argument(
        ..., help="Run folder of `joulepath optimize` (path.csv) or `joulepath cycle` (cycle_path.csv)."
    ),
    port: int = typer.Option(6510, "--port", min=0, max=65535, help="UDP port to listen on."),
    host: str = typer.Option(
        "127.0.0.1", "--host", help="Address to listen on (the PC's address the controller sends to)."
    ),
    timeout: float = typer.Option(
        10.0, "--timeout", min=0.01, max=3600.0, help="s of silence from the controller before giving up."
    ),
    repeat: int = typer.Option(1, "--repeat", min=1, max=1000, help="Runs of the path to stream."),
    robot: str = typer.Option(
        "", "--robot", help="Robot name or file (default: the robot of the folder's result.json)."
    ),
) -> int:
    """Stream the run's path to an ABB controller through EGM; write stream.csv and stream.json.

    Answers every EgmRobot with an EgmSensor on the controller's clock: holds the start until
    EGM runs with the robot there, runs the path, holds the end until the robot converged (and
    again for --repeat). Exit code 0: every run done; 2: refused or stopped on a fault (a
    reference outside the limits, the robot away from the start, silence over --timeout).
    """
    from joulepath.egm import STREAM_FILES, ServeConfig, StreamSettings, stream_run

    check_out_folder(run_folder, option="RUN_FOLDER", files=STREAM_FILES)
    config = ServeConfig(host=host, port=port, timeout_s=timeout, settings=StreamSettings(repeats=repeat))

    def listening(address: tuple[str, int]) -> None:
        print(f"listening on udp {address[0]}:{address[1]}", flush=True)

    outcome = stream_run(run_folder, config, robot=robot or None, on_listening=listening)
    s = outcome.summary
    d = s["datagrams"]
    console.print(
        f"{s['repetitions_executed']}/{s['repetitions_asked']} runs streamed; executed "
        f"{s['executed_duration_s']:.3f} s (planned {s['planned_duration_s']:.3f} s); tracking error max "
        f"{s['executed_tracking_error_max_deg']:.3f} deg, RMS {s['executed_tracking_error_rms_deg']:.3f} deg"
    )
    if s["saved_executed_pct"] is not None and s["saved_planned_pct"] is not None:
        console.print(
            f"energy executed {s['energy_executed_J']:.3f} J: {s['saved_executed_pct']:.2f} % saved "
            f"against the default {s['energy_default_J']:.3f} J (planned {s['saved_planned_pct']:.2f} %)"
        )
    elif s["energy_executed_J"] is not None:
        console.print(f"energy executed {s['energy_executed_J']:.3f} J (no result.json energies to compare)")
    console.print(
        f"datagrams: {d['received']} received, {d['parsed']} parsed, {d['ignored']} ignored, "
        f"{d['late']} late, {d['foreign']} foreign"
    )
    console.print(f"wrote {', '.join(sorted(outcome.files))} in {run_folder}")
    return 0
