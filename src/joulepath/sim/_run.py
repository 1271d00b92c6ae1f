"""Simulated data collection: random moves -> controller -> plant -> controller log."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from joulepath._io import atomic_write_text, check_replaceable, expect_outputs, make_folder
from joulepath.data import (
    MOVES_SIDECAR_COLUMNS,
    controller_log_text,
    generic_log_text,
    ingest,
    moves_sidecar_path,
    save_table,
    write_controller_log,
)
from joulepath.description import DEFAULT_ROBOT
from joulepath.dynamics import Robot, load_robot
from joulepath.export import Move, draw_moves
from joulepath.sim._controller import ControllerConfig, MotionPlan, log_times, plan_moves
from joulepath.sim._plants import Measured, make_plant, run_plant


@dataclass(frozen=True, slots=True)
class SimulatedLog:
    """What a simulated run wrote; ``duration_s`` is the simulated robot time (s) the log covers."""

    log: Path
    moves: Path
    n_rows: int
    n_moves: int
    duration_s: float
    range_set: str = "collection"
    plant_note: str = ""


def measure(
    robot: Robot,
    plant_name: str,
    moves: Sequence[Move],
    *,
    rng: np.random.Generator,
    config: ControllerConfig | None = None,
    start: np.ndarray | None = None,
    instance_seed: int = 120,
) -> tuple[MotionPlan, Measured]:
    """Plan ``moves`` from ``start`` (default home) and measure them on a plant."""
    q0 = robot.home if start is None else np.asarray(start, float)
    config = config or ControllerConfig()
    plan = plan_moves(robot, q0, moves, config)
    t = log_times(plan.end_time, config, rng=rng)
    plant = make_plant(plant_name, robot, instance_seed=instance_seed)
    return plan, run_plant(plant, plan, t, rng=rng)


def log_text(robot: Robot, m: Measured) -> str:
    """The measurement as the controller's CSV text (a generic joint log for an arm not of 6 joints).

    The controller logs its axis values: for an arm whose axis 3 is coupled to axis 2 the
    positions, speeds and torques are converted from the model's joints
    (:meth:`~joulepath.dynamics.Robot.joints_to_axes`, ``joint_torques_to_axes``).
    """
    if robot.n_joints != 6:
        return generic_log_text(m.t, m.q, m.qd, m.tau)
    pose = robot.fk(m.q)
    quat = pose.quaternion
    euler = pose.euler_zyx_deg  # (z, y, x)
    axes, axes_d = np.degrees(robot.joints_to_axes(m.q)), np.degrees(robot.joints_to_axes(m.qd))
    return controller_log_text(
        m.t, axes, axes_d, robot.joint_torques_to_axes(m.tau), pose.position_mm, quat, euler[:, ::-1]
    )


def moves_text(plan: MotionPlan) -> str:
    """Sidecar CSV with the programmed moves (ground truth for tests and plots)."""
    head = [*MOVES_SIDECAR_COLUMNS, *(f"j{i + 1}_deg" for i in range(plan.start.size))]
    lines = [",".join(head)]
    for k, seg in enumerate(plan.segments):
        target = ",".join(f"{v:.5f}" for v in np.degrees(seg.move.target))
        lines.append(f"{k},{seg.t0:.5f},{seg.t_end:.5f},{seg.move.speed},{seg.move.zone},{target}")
    return "\n".join(lines) + "\n"


def simulate(
    out: str | os.PathLike[str],
    *,
    plant: str = "lab",
    n_moves: int = 1000,
    seed: int | np.random.SeedSequence = 0,
    robot: str = DEFAULT_ROBOT,
    range_set: str = "collection",
    config: ControllerConfig | None = None,
) -> SimulatedLog:
    """Run ``n_moves`` random moves (thesis Appendix D.1) on a plant and write the log.

    Writes ``out`` (the controller CSV) and its sidecar ``<name>.moves.csv`` with the
    programmed moves (:func:`joulepath.data.moves_sidecar_path`), which
    :func:`joulepath.data.ingest` recognises and skips. ``duration_s`` of the result
    is simulated robot time, not the time the simulation took.
    """
    r = load_robot(robot)
    rng = np.random.default_rng(seed)
    used, _, _ = r.ranges_for(range_set)
    moves = draw_moves(r, n_moves, range_set=range_set, rng=rng)
    plan, measured = measure(r, plant, moves, rng=rng, config=config)
    path = Path(out)
    make_folder(path.parent)
    side = moves_sidecar_path(path)
    check_replaceable(side)
    write_controller_log(path, log_text(r, measured))
    atomic_write_text(side, moves_text(plan))
    note = make_plant(plant, r).note
    return SimulatedLog(
        path, side, int(measured.t.size), len(plan.segments), float(measured.t[-1]), used, note
    )


THESIS_PLAN = (
    ("real", "lab", 1000),
    ("sim", "sim", 1000),
    ("micro", "lab", 100),
    ("test", "lab", 100),
)
"""The thesis' datasets (§4.3.1): name, plant, number of moves."""


def _plan_job(
    name: str, plant: str, n_moves: int, seed: np.random.SeedSequence, out: str, robot: str
) -> dict[str, object]:
    out_dir = Path(out)
    res = simulate(out_dir / "logs" / f"{name}.csv", plant=plant, n_moves=n_moves, seed=seed, robot=robot)
    table = ingest([res.log], robot=load_robot(robot))
    save_table(table, out_dir / f"{name}.parquet")
    return {
        "name": name,
        "plant": plant,
        "moves": n_moves,
        "rows": res.n_rows,
        "table_rows": len(table.frame),
        "table_moves": table.n_moves,
        "duration_s": res.duration_s,
    }


def simulate_plan(
    out: str | os.PathLike[str],
    *,
    seed: int = 0,
    robot: str = DEFAULT_ROBOT,
    plan: Sequence[tuple[str, str, int]] = THESIS_PLAN,
    workers: int = 2,
    progress: Callable[[dict[str, object]], None] | None = None,
) -> list[dict[str, object]]:
    """Simulate a dataset plan in parallel; write ``logs/<name>.csv`` and ``<name>.parquet``.

    Each dataset draws from its own child of ``SeedSequence(seed)``, so the test
    set never repeats the micro set's moves.
    """
    children = np.random.SeedSequence(seed).spawn(len(plan))
    results: list[dict[str, object]] = []
    make_folder(out)
    if workers <= 1:
        for (name, plant, n), child in zip(plan, children, strict=True):
            results.append(_plan_job(name, plant, n, child, str(out), robot))
            if progress:
                progress(results[-1])
        return results
    expect_outputs(  # the workers write outside this command's journal
        path
        for name, _, _ in plan
        for log in [Path(out) / "logs" / f"{name}.csv"]
        for path in (log, moves_sidecar_path(log), Path(out) / f"{name}.parquet")
    )
    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = [
            pool.submit(_plan_job, name, plant, n, child, str(out), robot)
            for (name, plant, n), child in zip(plan, children, strict=True)
        ]
        for fut in as_completed(futures):
            results.append(fut.result())
            if progress:
                progress(results[-1])
    order = [p[0] for p in plan]
    return sorted(results, key=lambda r: order.index(str(r["name"])))
