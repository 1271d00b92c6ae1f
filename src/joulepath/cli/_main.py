"""Entry point: parse, dispatch, and turn user errors into one line and exit code 2.

A command either finishes or leaves nothing of its own behind: it runs inside an
:class:`~joulepath._io.OutputJournal`, undone when it fails (``run`` keeps its own
stage-by-stage recovery). Warnings that libraries raise while it runs (NumPy's
RuntimeWarnings, ...) are held back: after an error only the error line is printed,
after success they are shown as usual.
"""

from __future__ import annotations

import errno
import os
import re
import sys
import warnings
from collections.abc import Callable, Sequence

import typer

from joulepath.cli._cycle import cycle
from joulepath.cli._data import ingest, rapid_app, simulate
from joulepath.cli._evaluate import evaluate
from joulepath.cli._experiment import demo, run
from joulepath.cli._identify import identify
from joulepath.cli._learn import importance, train
from joulepath.cli._measure import measure
from joulepath.cli._optimize import bench_optimizers, optimize
from joulepath.cli._plant import plant
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
app.command("plant")(plant)
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


SELF_RECOVERING = frozenset({"run", "demo"})
"""Commands whose stages keep or drop their own folders (``experiment``), not undone as a whole."""

ERROR_LINE_CHARS = 300
"""Longest error line printed as it is: a longer one names its files shorter (:func:`short_paths`)."""
_SHORT = 80
_PATH = re.compile(r"/[^\s:;,()'\"]+(?:/[^\s:;,()'\"]+)+")


def short_paths(text: str, limit: int = ERROR_LINE_CHARS) -> str:
    """``text`` with its file paths written shorter where it is longer than ``limit``: relative to
    the working folder where that is below it (and short), else the last three parts after an ellipsis (the
    file stays recognisable; a task's modules differ in their last parts), else its name alone."""
    if len(text) <= limit:
        return text

    def shorter(keep: int) -> Callable[[re.Match[str]], str]:
        def one(m: re.Match[str]) -> str:
            path = m.group(0)
            try:
                rel = os.path.relpath(path)
            except ValueError:
                rel = path
            if not rel.startswith("..") and len(rel) <= _SHORT:
                return rel
            parts = path.split("/")
            return path if len(parts) <= keep + 1 else "…/" + "/".join(parts[-keep:])

        return one

    out = text
    for keep in (3, 1):  # the last three parts of each path, else its name alone
        out = _PATH.sub(shorter(keep), text)
        if len(out) <= limit:
            break
    return out


_FULL = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})
_DENIED = frozenset({errno.EROFS, errno.EACCES, errno.EPERM})
"""OSErrors that say something about the machine (a full disk, a read-only folder), not about joulepath:
one line, wherever they are raised."""


def _command(args: Sequence[str]) -> str:
    return next((a for a in args if not a.startswith("-")), "")


def _replay(caught: list[warnings.WarningMessage]) -> None:
    """Show the held-back warnings as the filters outside ``main`` say (once per message)."""
    seen: set[tuple[type[Warning], str]] = set()
    for w in caught:
        key = (w.category, str(w.message))
        if key not in seen:
            seen.add(key)
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)


def _one_line(err: BaseException, debug: bool) -> tuple[str, int] | None:
    """The error line and exit code of an error the user can fix; None for a bug (traceback)."""
    if isinstance(err, JoulepathError):
        return None if debug else (f"error: {err}", 2)
    if isinstance(err, typer.Abort):
        return "aborted", 130
    if isinstance(err, typer.TyperException):  # usage errors: bad option values, missing arguments
        message = getattr(err, "format_message", None)
        if message is None or debug:
            return None
        ctx = getattr(err, "ctx", None)
        where = ctx.command_path if ctx is not None else "joulepath"
        return f"error: {message().rstrip('.')}; see '{where} --help'", 2
    if isinstance(err, OSError) and err.errno in _FULL | _DENIED and not debug:
        where = f"{err.filename}: " if err.filename else ""
        fix = "free some space and run it again" if err.errno in _FULL else "check its permissions"
        return f"error: {where}{err.strerror or err}; {fix}", 2
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``); return the exit code."""
    from contextlib import AbstractContextManager, nullcontext

    from joulepath._io import OutputJournal, output_journal

    args = list(sys.argv[1:] if argv is None else argv)
    if not args:
        print("error: no command given; see 'joulepath --help' for the commands", file=sys.stderr)
        return 2
    debug = "--debug" in args
    if debug:  # accepted anywhere on the line, handled as a root option
        args = ["--debug", *(a for a in args if a != "--debug")]
    journal = None if _command(args) in SELF_RECOVERING else OutputJournal()
    journaled: AbstractContextManager[object] = nullcontext() if journal is None else output_journal(journal)
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught, journaled:
            warnings.simplefilter("default")  # once per place: bounded
            try:
                result = app(args=args, prog_name="joulepath", standalone_mode=False)
            except typer.Exit as err:  # a command that chose its exit code: its files stay
                result = int(err.exit_code)
    except BaseException as err:  # the journal is undone already
        line = _one_line(err, debug)
        if line is None:
            _replay(caught)
            raise
        text, code = line
        if journal is not None and journal.undone:
            text += (
                f"; nothing of this run was kept (the {journal.undone} file(s) it had written were "
                "removed, and any it had replaced put back)"
            )
        print(short_paths(text), file=sys.stderr)
        return code
    _replay(caught)
    return int(result) if isinstance(result, int) else 0
