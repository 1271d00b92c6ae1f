"""Shared fixtures."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

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
    # a bundled example program's whole cycle, as the [cycle] stage runs it (the cheapest of the six to plan)
    shutil.copy(EXAMPLES / "payload_tool.mod", base / "cell.mod")
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


# The EGM tests' fixed task (tests/egm, tests/export/test_egm.py, tests/cli/test_stream.py).
EGM_START = (0.3, 0.2, -0.4, 0.5, -0.6, 1.0)
EGM_END = (-0.9, 0.6, 0.3, -1.2, 0.8, -1.5)
EGM_DURATION = 1.6


@pytest.fixture(scope="session")
def egm_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The fixed task optimized with the default settings, written with ``export="egm"``."""
    from joulepath.optimize import OptimizeConfig, optimize_move, write_run

    robot = joulepath.load_robot("irb120")
    result = optimize_move(robot, np.array(EGM_START), np.array(EGM_END), EGM_DURATION, OptimizeConfig())
    out = tmp_path_factory.mktemp("egm_run")
    write_run(result, robot, out, export="egm")
    return out


@pytest.fixture(scope="session")
def via_points_run(irb120: joulepath.Robot, tmp_path_factory: pytest.TempPathFactory) -> tuple[Any, Path]:
    """The same task optimized for RAPID via points (``follow="via-points"``) and written with the
    robot's own export (path.mod): its result and folder (tests/optimize/test_execute.py,
    tests/measure/test_measure.py). Copy the folder before writing into it."""
    from joulepath.optimize import OptimizeConfig, optimize_move, write_run

    result = optimize_move(
        irb120, np.array(EGM_START), np.array(EGM_END), EGM_DURATION, OptimizeConfig(follow="via-points")
    )
    out = tmp_path_factory.mktemp("via_points_run")
    write_run(result, irb120, out)
    return result, out


class Background:
    """Run ``target`` in a thread; ``address`` is set once it listens, ``result``/``error`` when it ends."""

    def __init__(self, target: Callable[[Callable[[tuple[str, int]], None]], Any]) -> None:
        self.address: tuple[str, int] | None = None
        self.result: Any = None
        self.error: BaseException | None = None
        self._listening = threading.Event()

        def run() -> None:
            try:
                self.result = target(self._on_listening)
            except BaseException as err:  # handed to the test
                self.error = err
            finally:
                self._listening.set()

        self._thread = threading.Thread(target=run, daemon=True)
        self._thread.start()

    def _on_listening(self, address: tuple[str, int]) -> None:
        self.address = address
        self._listening.set()

    def wait_listening(self, timeout: float = 30.0) -> tuple[str, int]:
        assert self._listening.wait(timeout), "the server did not start listening"
        if self.error is not None:
            raise self.error
        assert self.address is not None
        return self.address

    def join(self, timeout: float = 60.0) -> None:
        self._thread.join(timeout)
        assert not self._thread.is_alive(), "the server did not stop"


@pytest.fixture
def background() -> Iterator[type[Background]]:
    yield Background


# ------------------------------------------------------------- pytest-xdist: test files to workers
# `make test` runs `pytest -n 2 --dist loadfile`: each test file is one unit of work for one worker.
# Two refinements of that, for `--dist loadfile` only (any other --dist runs as xdist does):
# - files that share a session fixture go to one worker together, so that the fixture is built once
#   per run and not once per worker (a session fixture lives in its worker's process);
# - the slowest units are handed out first (longest first: the last unit handed out then ends near
#   the others instead of running alone at the end); every other file follows in xdist's own order.
# Both only choose where and when a test runs: every test runs, once, as it is written.
SHARED_FIXTURE_FILES: dict[str, tuple[str, ...]] = {
    # name of the unit: files (or folders, ending in "/") that use the fixture
    "tiny_run": (
        "tests/experiment/test_experiment.py",
        "tests/experiment/test_run_folders.py",
        "tests/report/test_report.py",
    ),
    "learn": ("tests/learn/",),  # lab_tables, trained (tests/learn/conftest.py)
    "synth": ("tests/synth/",),  # energy_table, fitted (tests/synth/conftest.py)
    "plant": ("tests/plant/",),  # mini_plant, reference_run (tests/plant/conftest.py)
    "via_points_run": ("tests/optimize/test_execute.py", "tests/measure/test_measure.py"),
    "egm_run": (
        "tests/cli/test_stream.py",
        "tests/egm/test_plan.py",
        "tests/egm/test_server.py",
        "tests/export/test_egm.py",
    ),
}
SLOW_FIRST: tuple[str, ...] = (
    # units by their summed test durations (`pytest --durations=0`, 2 workers), the longest first;
    # a unit not listed follows these
    "tiny_run",
    "tests/program/test_cycle.py",
    "tests/identify/test_currents.py",
    "learn",
    "tests/identify/test_excitation.py",
    "tests/program/test_cycle_units.py",
    "tests/docs/test_site.py",
    "tests/optimize/test_cycle_reference.py",
    "tests/identify/test_experiment_stage.py",
    "synth",
    "tests/program/test_via_levers.py",
    "tests/identify/test_identify.py",
    "tests/identify/test_identify_cli.py",
    "tests/program/test_export_choice.py",
    "tests/optimize/test_segment_reference.py",
    "tests/optimize/test_retime.py",
    "tests/cli/test_synth_commands.py",
    "tests/optimize/test_reference.py",
    "plant",
    "via_points_run",
    "egm_run",
)


def _unit(nodeid: str) -> str:
    """The unit of work of a test: its file, or the name of the files sharing a session fixture."""
    path = nodeid.split("::", 1)[0]
    for name, members in SHARED_FIXTURE_FILES.items():
        if any(path == m or (m.endswith("/") and path.startswith(m)) for m in members):
            return name
    return path


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    if config.getoption("dist") != "loadfile":
        return None  # xdist's own scheduler
    from xdist.scheduler import LoadFileScheduling

    rank = {name: k for k, name in enumerate(SLOW_FIRST)}

    class SharedFixtureFirstSlow(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return _unit(nodeid)

        def _assign_work_unit(self, node: Any) -> None:
            # the slowest unit left goes next (min keeps xdist's order among the others)
            unit = min(self.workqueue, key=lambda u: rank.get(u, len(rank)))
            self.workqueue.move_to_end(unit, last=False)
            super()._assign_work_unit(node)

    return SharedFixtureFirstSlow(config, log)
