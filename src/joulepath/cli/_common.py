"""Small helpers shared by the CLI commands (parsing only; no numerics)."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console

from joulepath.errors import InvalidInput

console = Console(highlight=False, soft_wrap=True)


def parse_joints(text: str, *, option: str, degrees: bool, n: int = 6) -> list[float]:
    """``"0,10,20,0,30,0"`` -> floats in rad (``degrees`` converts); BadParameter otherwise."""
    import math

    parts = [p for p in text.replace(";", ",").split(",") if p.strip()]
    try:
        values = [float(p) for p in parts]
    except ValueError as err:
        raise typer.BadParameter(
            f"{text!r} is not a comma-separated list of numbers", param_hint=option
        ) from err
    if len(values) != n:
        raise typer.BadParameter(
            f"expected {n} joint values, got {len(values)} ({text!r})", param_hint=option
        )
    return [math.radians(v) for v in values] if degrees else values


def _no_file_above(path: Path, option: str) -> None:
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise InvalidInput(f"{path}: {parent} is a file, not a folder; choose another {option}")
            return


def check_out_file(path: Path, *, example: str, option: str = "--out") -> None:
    """Refuse, before any work, an output file path that is a folder or lies under a file."""
    if path.is_dir():
        raise InvalidInput(f"{path}: is a folder, but {option} needs a file name; give e.g. {path / example}")
    _no_file_above(path, option)


def check_out_folder(path: Path, *, option: str = "--out") -> None:
    """Refuse, before any work, an output folder path that is a file or lies under a file."""
    if path.exists() and not path.is_dir():
        raise InvalidInput(f"{path}: is a file, but {option} needs a folder; give a new or existing folder")
    _no_file_above(path, option)
