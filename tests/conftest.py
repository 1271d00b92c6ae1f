"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.description import preset_path

FIXTURES = Path(__file__).parent / "fixtures"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="session")
def irb120() -> joulepath.Robot:
    return joulepath.load_robot("irb120")


@pytest.fixture(scope="session")
def irb120_urdf() -> joulepath.Robot:
    return joulepath.load_robot(preset_path("irb120", fmt="urdf"))


@pytest.fixture(scope="session")
def appendix_c_path() -> Path:
    return FIXTURES / "thesis_appendix_c.irml"


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20251125)


# The bundled demo experiment at a tiny scale: every stage, in well under a minute.
TINY_DEMO = {
    "jobs": "1",
    "train_moves": "12",
    "test_moves": "5",
    "micro_moves": "4",
    "sim_moves": "6",
    "methods": '["copula"]',
    "rows": "300",
    "families": '["par", "mlp"]',
    "cv": "2",
    "max_rows": "400",
    "targets": '["E", "E1"]',
    "tasks": "2",
    "generations": "5",
    "population": "12",
    "loop_tasks": "1",
    "reference": "false",  # the reference solver has its own tests (tests/optimize/test_reference.py)
}


def _tiny_demo_toml(out_dir: Path, **changes: str) -> Path:
    """demo.toml with every size shrunk (``TINY_DEMO``, then ``changes``), written to ``out_dir``."""
    import re
    from importlib import resources

    text = (resources.files("joulepath.experiment") / "presets" / "demo.toml").read_text()
    section = ""
    lines = []
    for line in text.splitlines():
        m = re.match(r"^\[(\w+)\]", line)
        if m:
            section = m[1]
        key = line.split("=")[0].strip()
        values = {**TINY_DEMO, **changes}
        if "=" in line and not line.lstrip().startswith("#"):
            value = values.get(f"{section}.{key}", values.get(key))
            if value is not None and not (
                section == "train" and key == "targets" and "train.targets" not in values
            ):
                line = f"{key} = {value}"
        lines.append(line)
    path = out_dir / "tiny-demo.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture
def tiny_demo_toml():
    """``tiny_demo_toml(folder, **changes) -> Path``: the bundled demo.toml shrunk to seconds."""
    return _tiny_demo_toml


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny demo run through the CLI (``joulepath run FILE --out DIR --quiet``); its folder."""
    import shutil

    from joulepath.cli import main

    base = tmp_path_factory.mktemp("tiny-demo")
    toml = _tiny_demo_toml(base, **{"train.targets": '["E", "E1"]'})
    # the bundled example program's whole cycle, as the [cycle] stage runs it
    shutil.copy(EXAMPLES / "pick_and_place.mod", base / "cell.mod")
    toml.write_text(toml.read_text() + '\n[cycle]\nprogram = "cell.mod"\n')
    assert main(["run", str(toml), "--out", str(base / "run"), "--quiet"]) == 0
    return base / "run"


@pytest.fixture
def dask_scheduler():
    """Address of an in-process Dask LocalCluster (one worker thread) on tcp://127.0.0.1."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        host="127.0.0.1",
        protocol="tcp://",
        dashboard_address=None,
    ) as cluster:
        yield cluster.scheduler_address
