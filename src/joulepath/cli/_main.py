"""Entry point: parse, dispatch, and turn user errors into one line and exit code 2."""

from __future__ import annotations

import sys
from collections.abc import Sequence

import typer

from joulepath.cli._cycle import cycle
from joulepath.cli._data import ingest, rapid_app, simulate
from joulepath.cli._evaluate import evaluate
from joulepath.cli._experiment import demo, run
from joulepath.cli._identify import identify
from joulepath.cli._learn import importance, train
from joulepath.cli._measure import measure
from joulepath.cli._optimize import bench_optimizers, optimize
from joulepath.cli._robot import robot_app
from joulepath.cli._stream import stream
from joulepath.cli._synth import compare, synth
from joulepath.errors import JoulepathError

app = typer.Typer(
    name="joulepath",
    help="Energy-optimal point-to-point moves for six-axis industrial robot arms.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
app.add_typer(robot_app, name="robot")
app.add_typer(rapid_app, name="rapid")
app.command("simulate")(simulate)
app.command("ingest")(ingest)
app.command("identify")(identify)
app.command("evaluate")(evaluate)
app.command("train")(train)
app.command("importance")(importance)
app.command("synth")(synth)
app.command("compare")(compare)
app.command("optimize")(optimize)
app.command("bench-optimizers")(bench_optimizers)
app.command("cycle")(cycle)
app.command("measure")(measure)
app.command("stream")(stream)
app.command("run")(run)
app.command("demo")(demo)


def _version(value: bool) -> None:
    if value:
        from joulepath import __version__

        typer.echo(f"joulepath {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show tracebacks of errors."),
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Energy-optimal point-to-point moves for six-axis industrial robot arms."""


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``); return the exit code."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not args:
        print("error: no command given; see 'joulepath --help' for the commands", file=sys.stderr)
        return 2
    debug = "--debug" in args
    if debug:  # accepted anywhere on the line, handled as a root option
        args = ["--debug", *(a for a in args if a != "--debug")]
    try:
        result = app(args=args, prog_name="joulepath", standalone_mode=False)
    except JoulepathError as err:
        if debug:
            raise
        print(f"error: {err}", file=sys.stderr)
        return 2
    except typer.Exit as err:
        return int(err.exit_code)
    except typer.Abort:
        print("aborted", file=sys.stderr)
        return 130
    except typer.TyperException as err:  # usage errors: bad option values, missing arguments
        message = getattr(err, "format_message", None)
        if message is None or debug:
            raise
        ctx = getattr(err, "ctx", None)
        where = ctx.command_path if ctx is not None else "joulepath"
        print(f"error: {message().rstrip('.')}; see '{where} --help'", file=sys.stderr)
        return 2
    return int(result) if isinstance(result, int) else 0
