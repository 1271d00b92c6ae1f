"""Small helpers shared by the CLI commands (parsing only; no numerics)."""

from __future__ import annotations

import typer
from rich.console import Console

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
