"""``joulepath demo``: the whole method on the bundled IRB 120, small and fast."""

from __future__ import annotations

from pathlib import Path

import typer

from joulepath.cli._common import console


def demo(
    out: Path = typer.Option(Path("demo-out"), "--out", help="Folder for the demo's data, models and run."),
    quick: bool = typer.Option(False, help="Smaller data, two model families, fewer generations."),
) -> int:
    """Robot, data, energy models and one optimized move, end to end."""
    from joulepath.demo import run_demo

    run_demo(out, quick=quick, say=lambda text: console.print(text, markup=False))
    return 0
