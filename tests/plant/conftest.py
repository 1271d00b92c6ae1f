"""A mini plant (three one-module cells of two moves each, one two-module task with a sensor) and its
reference run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

FRONT = "[0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
TOOL = (
    "PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.6, [0, 0, 45], [1, 0, 0, 0], 0, 0, 0]];"
)
CELLS = {  # name: (y of the second target mm, the waits s): short moves, so that a cell solves in seconds
    "alpha": (100, 1.2, 0.3),
    "beta": (120, 0.2, 2.0),
    "gamma": (90, 0.8, 0.8),
}


def tiny_program(name: str, y: float, wait_a: float, wait_b: float) -> str:
    return f"""MODULE {name}
    {TOOL}
    CONST robtarget pA := [[380, 175, 200], {FRONT}];
    CONST robtarget pB := [[380, {y}, 240], {FRONT}];
    PROC main()
        WHILE TRUE DO
            MoveJ pA, v1000, fine, tGripper;
            WaitTime {wait_a};
            MoveJ pB, v1000, fine, tGripper;
            WaitTime {wait_b};
        ENDWHILE
    ENDPROC
ENDMODULE
"""


PLANT_HEAD = """[plant]
name = "Mini plant"
hours_per_year = 6000
tariff_eur_per_kwh = 0.2
co2_kg_per_kwh = 0.35

[defaults]
energy = "electrical"
table_points = 2
knot_spacing = 0.2
pass_search = 0
rapid_plan = false
retime_segments = false
lever_plans = 40
"""


def make_mini_plant(
    folder: Path, *, extra: str = "", cells: dict[str, tuple[float, float, float]] | None = None
) -> Path:
    """Write the mini plant in ``folder``; its plant file."""
    folder.mkdir(parents=True, exist_ok=True)
    parts = [PLANT_HEAD]
    for name, (y, a, b) in (cells or CELLS).items():
        (folder / f"{name}.mod").write_text(tiny_program(name.capitalize(), y, a, b), encoding="utf-8")
        parts.append(f'[[cell]]\nname = "{name}"\nprogram = "{name}.mod"\n')
    task = folder / "task"
    task.mkdir(exist_ok=True)
    main = tiny_program("TaskMain", 110, 0.5, 0.5).replace(f"    {TOOL}\n", "")
    main = main.replace(
        "            WaitTime 0.5;\n", "            WaitDI diPartReady, 1;\n            WaitTime 0.5;\n", 1
    )
    (task / "main.mod").write_text(
        main, encoding="utf-8"
    )  # its tool in the system module, a sensor to wait for
    (task / "lib.sys").write_text(f"MODULE Lib(SYSMODULE)\n    {TOOL}\nENDMODULE\n", encoding="utf-8")
    parts.append('[[cell]]\nname = "task"\nprogram = "task"\nio = { diPartReady = 1 }\n')
    path = folder / "plant.toml"
    path.write_text("\n".join(parts) + extra, encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def mini_plant(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_mini_plant(tmp_path_factory.mktemp("mini-plant"))


@pytest.fixture(scope="session")
def reference_run(mini_plant: Path) -> Path:
    """The mini plant run through the CLI with --jobs 2; its folder."""
    from joulepath.cli import main

    out = mini_plant.parent / "reference"
    assert main(["plant", str(mini_plant), "--out", str(out), "--jobs", "2"]) == 0
    return out


def cell_results(out: Path) -> dict[str, dict]:
    """The cells of a run's plant.json, without the wall times (what must agree between runs)."""
    cells = json.loads((out / "plant.json").read_text())["cells"]
    return {c["cell"]: {k: v for k, v in c.items() if k != "wall_s"} for c in cells}
