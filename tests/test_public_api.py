"""Exported names are sorted and importable; stages import one way only (STYLE.md §2)."""

import ast
import importlib
from pathlib import Path

import pytest

import joulepath

SRC = Path(joulepath.__file__).parent
PACKAGES = [
    "joulepath",
    "joulepath.description",
    "joulepath.kinematics",
    "joulepath.dynamics",
    "joulepath.energy",
    "joulepath.identify",
    "joulepath.trajectory",
    "joulepath.data",
    "joulepath.export",
    "joulepath.sim",
    "joulepath.experiment",
    "joulepath.report",
    "joulepath.program",
    "joulepath.rapid",
    "joulepath.measure",
    "joulepath.egm",
    "joulepath.plant",
]


@pytest.mark.parametrize("name", PACKAGES)
def test_all_is_sorted_and_importable(name):
    module = importlib.import_module(name)
    exported = module.__all__
    assert exported == sorted(exported)
    for attr in exported:
        assert hasattr(module, attr), f"{name}.{attr}"


def test_required_public_api():
    robot = joulepath.load_robot("irb120")
    assert isinstance(robot, joulepath.Robot)
    pose = robot.fk([0.0] * 6)
    for attr in ("position_m", "position_mm", "rotation", "quaternion", "euler_zyx_deg"):
        assert hasattr(pose, attr)
    assert callable(joulepath.energy.joint_energy)


# stage -> stages it may import (besides the foundation modules and itself)
ALLOWED = {
    "description": set(),
    "kinematics": {"description"},
    "dynamics": {"description", "kinematics", "energy"},
    "trajectory": {"description", "kinematics", "dynamics"},
    "data": {"dynamics", "energy"},  # dynamics: annotations only (TYPE_CHECKING)
    "export": {"description", "kinematics", "dynamics", "trajectory", "data"},
    "sim": {"description", "kinematics", "dynamics", "trajectory", "data", "export", "abb", "energy"},
    "learn": {"data", "description", "dynamics", "energy"},
    "identify": {"data", "description", "dynamics", "energy", "trajectory", "sim"},
    "synth": {"data", "description", "kinematics", "dynamics"},
    "evolve": set(),
    "optimize": {
        "data",
        "description",
        "kinematics",
        "dynamics",
        "trajectory",
        "evolve",
        "learn",
        "export",
        "sim",
        "energy",
    },
    "program": {"kinematics", "dynamics", "trajectory", "optimize", "sim", "energy", "export", "rapid"},
    "rapid": set(),  # the language alone: grammar, tree, interpreter (kinematics come through a protocol)
    "measure": {"data", "energy"},  # a log and a run folder's files in, measure.json out
    "energy": set(),
    "units": set(),
    "abb": set(),
    "report": set(),  # reads a run folder's files only
    "egm": {"description", "dynamics", "energy"},  # streams a run folder's path; its robot and energy
    "experiment": None,  # orchestrates every stage, like the CLI
    "plant": {"description", "dynamics", "energy", "program", "optimize"},  # cell programs' cycles, on Dask
    "cli": None,  # may import anything
}
FOUNDATION = {"_typing", "_rng", "_io", "_runfolder", "_work", "errors", "units", "abb", "__version__"}


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("joulepath"):
            parts = node.module.split(".")
            if len(parts) > 1:
                out.add(parts[1])
            else:
                out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] == "joulepath" and len(parts) > 1:
                    out.add(parts[1])
    return out


def test_stages_import_one_way_only():
    problems = []
    for path in SRC.rglob("*.py"):
        rel = path.relative_to(SRC)
        stage = rel.parts[0].removesuffix(".py")
        if stage in FOUNDATION or stage in ("__init__", "__main__"):
            continue
        allowed = ALLOWED.get(stage, set())
        if allowed is None:
            continue
        for imported in _imports(path) - FOUNDATION - {stage}:
            if imported not in allowed:
                problems.append(f"{rel} imports joulepath.{imported}")
    assert problems == []
