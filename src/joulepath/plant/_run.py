"""Run a plant's cell programs on Dask, storing each result as it finishes, keyed by its input hash.

Each cell is one task (:func:`joulepath.plant._task.run_cell`), submitted with
``client.map`` and collected with ``as_completed``, so results stream back as cells
finish and the client holds one result at a time. The client alone writes, atomically:
``OUT/cache/<key>/`` holds a finished cell's ``cycle.json`` (and ``optimized.mod``), then
its ``result.json``, written last, which marks it done. The key hashes everything the
result depends on: the programs' bytes (and their paths relative to the plant file), the
robot's files, the cell file, the I/O scenario, the settings and the joulepath version.
A rerun, or a run resumed after Ctrl-C, a ``kill -9`` of the client or a lost worker,
computes only the keys without a ``result.json``. A worker lost mid-task has its task
run again by the scheduler.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from joulepath._io import atomic_write_text, finite_json, make_folder, outside_journal
from joulepath.errors import InvalidInput, MissingDependency
from joulepath.plant._config import CellConfig, PlantConfig
from joulepath.plant._task import RETURNED_FILES, CellTask, run_cell

CACHE = "cache"
RESULT = "result.json"
ATTEMPT = "attempt.json"
"""A failure a rerun may not repeat (a lost worker, a reader that cannot read the program yet): shown in
the report, computed again on the next run."""
RETRIES = 2
"""Times a task whose worker was lost is run again by the scheduler (besides its own
``allowed-failures``) before the cell is recorded as failed for this run (and retried on the next)."""
_THREAD_ENV = {
    name: "1"
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS")
}


@dataclass(frozen=True, slots=True)
class PlantProgress:
    """Where a plant run stands: cells done (ok or refused), failed and remaining; the cell just finished."""

    total: int
    done: int
    failed: int
    remaining: int
    cell: str | None = None
    status: str | None = None
    cached: bool = False


@dataclass(frozen=True, slots=True)
class PlantRun:
    """A finished plant run: the cells computed in it, those taken from the cache, those failed."""

    out: Path
    n_cells: int
    computed: tuple[str, ...]
    cached: tuple[str, ...]
    failed: tuple[str, ...]
    wall_s: float


def _file_digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _robot_files(robot: str) -> list[Path]:
    """The files a robot is read from: its description and drives file, or a twin folder's files."""
    p = Path(robot)
    if p.is_dir():
        return sorted(f for f in p.iterdir() if f.is_file())
    from joulepath.dynamics import load_robot

    r = load_robot(robot)
    files = [Path(str(r.source))] if Path(str(r.source)).is_file() else []
    drives = r.drivetrain.drives
    if drives is not None and Path(drives.origin).is_file():
        files.append(Path(drives.origin))
    return files


def cell_key(cell: CellConfig, *, base: Path, robots: dict[str, list[tuple[str, str]]] | None = None) -> str:
    """The input hash of a cell (see the module docstring); ``robots`` caches the robots' file digests."""
    from joulepath import __version__

    robots = {} if robots is None else robots
    if cell.robot not in robots:
        robots[cell.robot] = [(f.name, _file_digest(f)) for f in _robot_files(cell.robot)]
    text = json.dumps(
        {
            "joulepath": __version__,
            "robot": [cell.robot if not Path(cell.robot).is_absolute() else "", robots[cell.robot]],
            "program": [[os.path.relpath(f, base), _file_digest(f)] for f in cell.program],
            "cell": None if cell.cell is None else _file_digest(cell.cell),
            "io": sorted(cell.io.items()),
            "routine": cell.routine,
            "settings": sorted((k, repr(v)) for k, v in cell.settings.items()),
        },
        sort_keys=True,
    )
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def read_result(out: Path, key: str, *, attempts: bool = False) -> dict[str, Any] | None:
    """A finished cell's stored result; None when absent or unreadable (it is computed again).
    ``attempts``: else the last failed attempt that is not kept as a result (for the report)."""
    folder = out / CACHE / key
    path = folder / RESULT
    if attempts and not path.is_file():
        path = folder / ATTEMPT
    try:
        rec = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return rec if isinstance(rec, dict) and rec.get("key") == key else None


def store_result(out: Path, result: dict[str, Any]) -> None:
    """Write a cell's result atomically: its files first, ``result.json`` last (it marks the cell done)."""
    folder = make_folder(out / CACHE / str(result["key"]))
    files = result.pop("files", {}) or {}
    for name in RETURNED_FILES:
        if name in files:
            atomic_write_text(folder / name, files[name])
    result["files"] = sorted(files)
    name = RESULT if result.get("cacheable", False) else ATTEMPT
    atomic_write_text(folder / name, json.dumps(finite_json(result), indent=1, allow_nan=False))
    if name == RESULT and (folder / ATTEMPT).is_file():
        (folder / ATTEMPT).unlink()


def plan_tasks(plant: PlantConfig) -> list[CellTask]:
    """One task per cell, in the plant file's order."""
    robots: dict[str, list[tuple[str, str]]] = {}
    base = plant.path.parent
    return [
        CellTask(
            name=c.name,
            key=cell_key(c, base=base, robots=robots),
            robot=c.robot,
            program=tuple(str(f) for f in c.program),
            io=dict(c.io),
            routine=c.routine,
            cell=None if c.cell is None else str(c.cell),
            settings=dict(c.settings),
        )
        for c in plant.cells
    ]


@contextmanager
def _client(jobs: int | None, scheduler: str | None) -> Iterator[Any]:
    try:
        from distributed import Client, LocalCluster
    except ImportError as err:
        raise MissingDependency(
            "joulepath plant runs on Dask distributed; install it: pip install 'joulepath[dask]'"
        ) from err
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="20s")  # type: ignore[no-untyped-call]
        except (OSError, TimeoutError) as err:
            raise InvalidInput(
                f"--scheduler {scheduler}: no Dask scheduler answers there ({err}); start one with "
                "`dask scheduler` or give --jobs N for a local cluster"
            ) from err
        with client:
            yield client
        return
    with (
        LocalCluster(  # type: ignore[no-untyped-call]
            n_workers=jobs or 1,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",  # the scheduler serves HTTP anyway: on a free port
            silence_logs=logging.ERROR,
            env=_THREAD_ENV,
        ) as cluster,
        Client(cluster) as client,  # type: ignore[no-untyped-call]
    ):
        yield client


def run_plant(
    plant: PlantConfig,
    out: str | Path,
    *,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[PlantProgress], None] | None = None,
    task: Callable[[CellTask], dict[str, Any]] = run_cell,
) -> PlantRun:
    """Run every cell of ``plant`` not yet in ``out``'s cache; store each result as it finishes.

    Parameters
    ----------
    plant : PlantConfig
        From :func:`~joulepath.plant.read_plant`.
    out : path
        The plant's run folder (``out/cache`` keeps the results between runs).
    jobs : int, optional
        Worker processes of a local cluster (one thread each; default 1).
    scheduler : str, optional
        ``tcp://host:port`` of a running Dask scheduler, instead of a local cluster.
    progress : callable, optional
        Told a :class:`PlantProgress` once at the start and after each cell.
    task : callable, default :func:`~joulepath.plant.run_cell`
        The per-cell task (a pure function of a :class:`~joulepath.plant.CellTask`, importable or
        picklable on the workers).

    Returns
    -------
    PlantRun
    """
    t0 = time.perf_counter()
    root = Path(out)
    tasks = plan_tasks(plant)
    say = progress or (lambda p: None)
    status: dict[str, str] = {}
    cached: list[str] = []
    with outside_journal():  # results outlive an interrupted run
        make_folder(root / CACHE)
    todo: dict[str, CellTask] = {}
    for t in tasks:
        rec = read_result(root, t.key)
        if rec is None:
            todo.setdefault(t.key, t)
        else:
            status[t.key] = str(rec["status"])
            cached.append(t.name)
    names_by_key: dict[str, list[str]] = {}
    for t in tasks:
        names_by_key.setdefault(t.key, []).append(t.name)

    def counts(cell: str | None = None, state: str | None = None, hit: bool = False) -> PlantProgress:
        per_cell = [status.get(c.key) for c in tasks]
        failed = sum(s == "failed" for s in per_cell)
        finished = sum(s is not None for s in per_cell)
        return PlantProgress(len(tasks), finished - failed, failed, len(tasks) - finished, cell, state, hit)

    say(counts())
    computed: list[str] = []
    if todo:
        with _client(jobs, scheduler) as client:
            futures = client.map(
                task,
                list(todo.values()),
                key=[f"joulepath-cell-{k}" for k in todo],
                retries=RETRIES,
                pure=False,
            )
            by_key = {f.key: k for f, k in zip(futures, todo, strict=True)}
            from distributed import as_completed

            for future in as_completed(futures):  # type: ignore[no-untyped-call]
                key = by_key[future.key]
                try:
                    result = future.result()
                except Exception as err:  # the task itself catches everything: a lost worker, a cancel
                    result = {
                        "name": todo[key].name,
                        "key": key,
                        "status": "failed",
                        "reason": f"the task did not finish on the cluster ({type(err).__name__}: {err})",
                        "cacheable": False,
                    }
                future.release()
                with outside_journal():
                    store_result(root, result)
                status[key] = str(result["status"])
                computed.extend(names_by_key[key])
                say(counts(todo[key].name, status[key]))
                del result
    failed = tuple(c.name for c in tasks if status.get(c.key) == "failed")
    return PlantRun(
        out=root,
        n_cells=len(tasks),
        computed=tuple(computed),
        cached=tuple(cached),
        failed=failed,
        wall_s=time.perf_counter() - t0,
    )


def progress_json(p: PlantProgress) -> dict[str, Any]:
    """A progress event as plain JSON."""
    return asdict(p)
