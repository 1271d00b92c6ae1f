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
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import typer
from rich.console import Console

from joulepath._io import check_replaceable
from joulepath.errors import InvalidInput

console = Console(highlight=False, soft_wrap=True)

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
    from joulepath.dynamics._calibration import TWIN_FILES

    if not robot:
        return []
    path = Path(robot)
    if path.is_dir():
        return [robot, *(str(path / name) for name in TWIN_FILES)]
    return [robot] if path.is_file() else []
