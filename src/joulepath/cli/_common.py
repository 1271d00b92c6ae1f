"""Small helpers shared by the CLI commands (parsing and output checks only; no numerics).

Output checks run before any work, so a refused ``--out`` writes nothing:

* an output file must be a regular file or not exist yet (never a folder, a device
  such as ``/dev/null``, a FIFO or a socket), must not lie under a file, and must not
  be one of the command's inputs (compared with :func:`os.path.samefile` when both
  exist, by resolved path otherwise);
* an output folder must be a folder or not exist yet; the files a command writes in
  it are checked like output files;
* no output, and no folder above it, may be a symbolic link to nothing (a dangling link);
* the nearest existing folder above the output must be writable.

Progress of long work (:func:`progress_lines`) goes to stderr and never to stdout: a
live status line when stderr is a terminal, else plain lines, at most one per
``JOULEPATH_PROGRESS_S`` seconds (default 1; the first after one interval of work, so
a quick command, or a quick refusal, prints only its result or its one error line).
"""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

import typer
from rich.console import Console

from joulepath._io import check_replaceable
from joulepath.errors import InvalidInput

console = Console(highlight=False, soft_wrap=True)
err_console = Console(stderr=True, highlight=False, soft_wrap=True)
"""Progress only (a live status on a terminal); results go to ``console`` (stdout)."""

PROGRESS_ENV = "JOULEPATH_PROGRESS_S"
"""Environment variable: seconds between two progress lines when stderr is not a terminal."""
DEFAULT_PROGRESS_S = 1.0

PathLike = str | os.PathLike[str]


def parse_joints(text: str, *, option: str, degrees: bool, n: int = 6) -> list[float]:
    """``"0,10,20,0,30,0"`` -> floats in rad (``degrees`` converts); BadParameter otherwise (nan, inf too)."""
    import math

    parts = [p for p in text.replace(";", ",").split(",") if p.strip()]
    try:
        values = [float(p) for p in parts]
    except ValueError as err:
        raise typer.BadParameter(
            f"{text!r} is not a comma-separated list of numbers", param_hint=option
        ) from err
    bad = [p.strip() for p, v in zip(parts, values, strict=True) if not math.isfinite(v)]
    if bad:
        raise typer.BadParameter(
            f"{', '.join(bad)} in {text!r} is not a finite number; give {n} joint values", param_hint=option
        )
    if len(values) != n:
        raise typer.BadParameter(
            f"expected {n} joint values, got {len(values)} ({text!r})", param_hint=option
        )
    return [math.radians(v) for v in values] if degrees else values


def _not_dangling(path: Path, option: str) -> None:
    if path.is_symlink() and not path.exists():
        raise InvalidInput(
            f"{path}: is a symbolic link to {os.readlink(path)}, which does not exist; "
            f"remove the link or choose another {option}"
        )


def _no_file_above(path: Path, option: str) -> None:
    for parent in path.parents:
        _not_dangling(parent, option)
        if parent.exists():
            if not parent.is_dir():
                raise InvalidInput(f"{path}: {parent} is a file, not a folder; choose another {option}")
            if not os.access(parent, os.W_OK | os.X_OK):
                raise InvalidInput(
                    f"{path}: the folder {parent} is not writable (permission denied); "
                    f"choose another {option}"
                )
            return


def same_file(a: PathLike, b: PathLike) -> bool:
    """Whether two paths name the same file (samefile when both exist, resolved paths otherwise)."""
    pa, pb = Path(a), Path(b)
    try:
        if pa.exists() and pb.exists():
            return os.path.samefile(pa, pb)
        return pa.resolve() == pb.resolve()
    except OSError:
        return False


def _not_an_input(path: Path, inputs: Iterable[PathLike], option: str) -> None:
    for given in inputs:
        if str(given) and same_file(path, given):
            raise InvalidInput(
                f"{path}: is also an input of this command ({given}); writing there would destroy it: "
                f"choose another {option}"
            )


def check_out_file(
    path: Path, *, example: str, option: str = "--out", inputs: Iterable[PathLike] = ()
) -> None:
    """Refuse, before any work, an output file path that cannot or must not be written.

    Refused: a folder, anything else that is not a regular file (``/dev/null``, a
    FIFO, a socket), a path under a file or in an unwritable folder, and any of
    ``inputs`` (the files the command reads).
    """
    if path.is_dir():
        raise InvalidInput(f"{path}: is a folder, but {option} needs a file name; give e.g. {path / example}")
    _not_dangling(path, option)
    _no_file_above(path, option)
    try:
        check_replaceable(path)
    except InvalidInput as err:
        raise InvalidInput(f"{err} ({option})") from err
    _not_an_input(path, inputs, option)


def check_out_folder(
    path: Path,
    *,
    option: str = "--out",
    files: Iterable[str] = (),
    inputs: Iterable[PathLike] = (),
) -> None:
    """Refuse, before any work, an output folder path that is not a folder or lies under a file.

    ``files`` are the names the command will write inside the folder: each is
    checked like :func:`check_out_file` against ``inputs``.
    """
    if path.exists() and not path.is_dir():
        raise InvalidInput(f"{path}: is a file, but {option} needs a folder; give a new or existing folder")
    _not_dangling(path, option)
    _no_file_above(path / "x", option)
    inputs = list(inputs)
    _not_an_input(path, inputs, option)
    for name in files:
        target = path / name
        _not_dangling(target, option)
        if target.is_dir():
            raise InvalidInput(
                f"{target}: is a folder where a file must be written; move it or choose another {option}"
            )
        try:
            check_replaceable(target)
        except InvalidInput as err:
            raise InvalidInput(f"{err} ({option})") from err
        _not_an_input(target, inputs, option)


def robot_inputs(robot: str) -> list[str]:
    """The robot argument as input paths: the file it names, or a twin folder and its files (else nothing)."""
    from joulepath.dynamics import TWIN_FILES

    if not robot:
        return []
    path = Path(robot)
    if path.is_dir():
        return [robot, *(str(path / name) for name in TWIN_FILES)]
    return [robot] if path.is_file() else []


def progress_interval() -> float:
    """Seconds between progress lines: ``JOULEPATH_PROGRESS_S`` if set (0: every message), else 1.

    Raises
    ------
    InvalidInput
        The variable is set but is not a finite number of seconds ≥ 0.
    """
    raw = os.environ.get(PROGRESS_ENV, "")
    if not raw.strip():
        return DEFAULT_PROGRESS_S
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise InvalidInput(f"{PROGRESS_ENV}={raw[:40]!r}: give a number of seconds ≥ 0 (or unset it)")
    return value


class ProgressLines:
    """A progress callback that prints plain lines on stderr, at most one per ``interval`` seconds.

    A message is printed when ``interval`` seconds have passed since the last line (or since
    the start, for the first), prefixed with the seconds since the start; the others are
    dropped. So a command that ends within one interval prints no progress at all.
    """

    def __init__(self, interval: float, clock: Callable[[], float] = time.monotonic) -> None:
        self.interval = interval
        self.clock = clock
        self.start = clock()
        self.last = self.start
        self.printed = 0

    def __call__(self, message: str) -> None:
        """Print ``message`` if the interval has passed since the last line."""
        now = self.clock()
        if now - self.last < self.interval:
            return
        print(f"[{now - self.start:.0f} s] {message}", file=sys.stderr, flush=True)
        self.last = now
        self.printed += 1


@contextmanager
def progress_lines(label: str) -> Iterator[Callable[[str], None]]:
    """A progress callback for long work, shown on stderr only (stdout keeps the results alone).

    On a terminal: a live status line that starts with ``label`` and shows each message (gone
    when the block ends). Otherwise: :class:`ProgressLines` at :func:`progress_interval`.
    """
    if err_console.is_terminal:
        from rich.text import Text

        with err_console.status(label) as status:
            yield lambda message: status.update(Text(message))
        return
    yield ProgressLines(progress_interval())
