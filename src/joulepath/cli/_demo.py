"""``joulepath demo``: what the bundled IRB 120 model gives, in one screen."""

from __future__ import annotations

import typer

from joulepath.cli._common import console


def demo(
    duration: float = typer.Option(1.5, help="Duration of the sample move, s."),
) -> int:
    """Show the IRB 120: summary, tool0 poses, and the energy of one sample move."""
    from joulepath.demo import run_demo

    report = run_demo(duration=duration)
    console.print(report, markup=False)
    return 0
