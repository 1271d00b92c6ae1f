"""Draw docs/assets/program-flow.png: a program's way from file to robot, stage by stage, with the
module of each stage (docs/explanation/program-flow.md). Run: python scripts/draw_program_flow.py"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch  # noqa: E402

STAGES = [
    ("read", "RAPID text → typed tree", "rapid/_parse.py\nrapid.lark, rapid/task.py"),
    (
        "trace",
        "run as the controller\ndoes: one cycle",
        "rapid/interpreter.py\nrapid/builtins.py, _standins.py",
    ),
    ("cell", "steps: joints, TCP,\nload, settings", "program/_task.py\nprogram/_cell.py"),
    ("plan", "each unit reshaped,\nthe time shared", "program/_cycle.py\noptimize/"),
    ("levers", "AccSet, speeds, zones,\nvia points (emulated)", "program/_levers.py\n_via_levers.py"),
    ("check", "limits, the emulated\ncontroller runs it", "program/_output.py\nsim/"),
    ("write", "optimized.mod or\negm.mod, cycle.json", "rapid/writer.py\nprogram/_output.py"),
]


def main(out: Path = Path(__file__).parents[1] / "docs" / "assets" / "program-flow.png") -> None:
    fig, ax = plt.subplots(figsize=(13.5, 3.3), dpi=120)
    ax.set_xlim(0, len(STAGES) * 2.0)
    ax.set_ylim(0, 3.3)
    ax.axis("off")
    for k, (name, what, where) in enumerate(STAGES):
        x = 0.15 + 2.0 * k
        ax.add_patch(
            FancyBboxPatch((x, 1.25), 1.7, 1.5, boxstyle="round,pad=0.04", fc="#e8eaf6", ec="#3949ab", lw=1.4)
        )
        ax.text(x + 0.85, 2.45, name, ha="center", va="center", fontsize=12, weight="bold", color="#1a237e")
        ax.text(x + 0.85, 1.78, what, ha="center", va="center", fontsize=8.2)
        ax.text(
            x + 0.85, 0.72, where, ha="center", va="center", fontsize=7.4, family="monospace", color="#37474f"
        )
        if k + 1 < len(STAGES):
            ax.add_patch(
                FancyArrowPatch(
                    (x + 1.78, 2.0), (x + 2.07, 2.0), arrowstyle="-|>", mutation_scale=14, color="#3949ab"
                )
            )
    ax.text(
        0.15,
        3.12,
        "joulepath.program.optimize_program(program, robot, out, ProgramSettings) -> ProgramResult",
        fontsize=9.5,
        family="monospace",
    )
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    print(out)


if __name__ == "__main__":
    main()
