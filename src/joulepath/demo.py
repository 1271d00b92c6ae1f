"""The demo behind ``make demo``: the whole method on the bundled IRB 120, small and fast.

1. the robot: description, physical check, tool0 poses, one move's energy;
2. data: random moves on the emulated lab robot (train and test sets), ingested;
3. energy models: quick grids of the four families, grouped CV, test on other moves;
4. optimizer: one move optimized on the best learned model, verified on the
   physics model and the emulated lab robot, exported as RAPID.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from joulepath.dynamics import NOMINAL_FRICTION, load_robot
from joulepath.trajectory import minimum_jerk
from joulepath.units import DEG, SAMPLE_PERIOD

DEMO_POSE_DEG = (30.0, 20.0, -10.0, 45.0, 30.0, 60.0)
DEMO_TASK_DEG = ((-60.0, 10.0, -30.0, 40.0, 20.0, 0.0), (70.0, 30.0, 10.0, -50.0, -40.0, 90.0), 1.5)


def robot_section(*, duration: float = 1.5) -> str:
    """Robot summary, physical check, tool0 poses and the per-joint energy of one move."""
    robot = load_robot("irb120")
    lines = [robot.summary(), ""]
    findings = robot.check_physical()
    lines.append(f"physical check: {sum(f.severity == 'error' for f in findings)} error(s)")
    lines += [f"  {f}" for f in findings]
    lines.append("")
    other = np.array(DEMO_POSE_DEG) * DEG
    for label, q in (("home (q = 0)", robot.home), (f"q = {DEMO_POSE_DEG} deg", other)):
        pose = robot.fk(q)
        x, y, z = pose.position_mm
        w, qx, qy, qz = pose.quaternion
        ez, ey, ex = pose.euler_zyx_deg
        lines.append(f"tool0 at {label}:")
        lines.append(f"  position   ({x:8.2f}, {y:8.2f}, {z:8.2f}) mm")
        lines.append(f"  quaternion ({w:.5f}, {qx:.5f}, {qy:.5f}, {qz:.5f})  [w, x, y, z]")
        lines.append(f"  EulerZYX   z {ez:.2f}°, y {ey:.2f}°, x {ex:.2f}°")
    lines.append("")
    move = minimum_jerk(robot.home, other, duration)
    rigid = robot.path_energy(move.q, move.qd, move.qdd, SAMPLE_PERIOD)
    friction = robot.path_energy(move.q, move.qd, move.qdd, SAMPLE_PERIOD, friction=NOMINAL_FRICTION)
    lines.append(
        f"sample move: minimum-jerk from home to the pose above in {duration:g} s, "
        f"{move.t.size} samples at {1 / SAMPLE_PERIOD:g} Hz"
    )
    lines.append("  E_i = sum |tau_i * qd_i| * dt     rigid body    + nominal friction")
    for i in range(robot.n_joints):
        lines.append(
            f"  joint {i + 1}                        {rigid.per_joint[i]:8.3f} J    {friction.per_joint[i]:8.3f} J"
        )
    lines.append(
        f"  total                          {float(rigid.total):8.3f} J    {float(friction.total):8.3f} J"
    )
    return "\n".join(lines)


def run_demo(
    out: str | Path = "demo-out", *, quick: bool = False, say: Callable[[str], None] = print
) -> Path:
    """Run the whole method into ``out`` and report each stage through ``say``."""
    from joulepath.data import ingest, save_table
    from joulepath.learn import TrainConfig, best_model, train
    from joulepath.optimize import OptimizeConfig, optimize_move, write_run
    from joulepath.sim import simulate

    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)
    say("== 1. robot ==")
    say(robot_section())
    robot = load_robot("irb120")
    n_train, n_test, generations = (20, 8, 20) if quick else (40, 15, 100)
    families = ("par", "xgb") if quick else ("mlp", "svr", "par", "xgb")
    say(f"\n== 2. data: {n_train} + {n_test} random moves on the emulated lab robot ==")
    tables = {}
    for name, n, seed in (("train", n_train, 1), ("test", n_test, 2)):
        res = simulate(root / "logs" / f"{name}.csv", plant="lab", n_moves=n, seed=seed)
        tables[name] = ingest([res.log], robot=robot)
        save_table(tables[name], root / f"{name}.parquet")
        say(
            f"{name}: {res.n_rows:,} log rows -> {len(tables[name].frame):,} table rows, {tables[name].n_moves} moves"
        )
    say(f"\n== 3. energy models: quick grids of {', '.join(families)}, 3 grouped folds ==")
    report = train(
        tables["train"],
        tables["test"],
        TrainConfig(families=families, cv=3),
        root / "models",
        progress=lambda m: None,
    )
    cols = ["family", "cv_grouped_r2", "cv_shuffled_r2", "test_r2", "path_median_pct", "path_p95_pct"]
    say(report.results[cols].to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    for b in report.baselines:
        s = b["scores"]["E"]
        say(f"{b['label']}: test R² {s['r2']:.3f}, path error median {s['path_median_pct']:.1f} %")
    model = best_model(root / "models", "E")
    (start, end, duration) = DEMO_TASK_DEG
    say(f"\n== 4. optimizer: MA (informed) on the {model.family} model, {duration} s move ==")
    result = optimize_move(
        robot,
        np.radians(start),
        np.radians(end),
        duration,
        OptimizeConfig(algorithm="ma-informed", fitness="surrogate", max_gen=generations, seed=0),
        models=(model,),
    )
    write_run(result, robot, root / "run")
    s = result.summary
    say(
        f"default path (minimum jerk, same {duration} s): {s['energy_default_physics_J']:.3f} J on physics, "
        f"{s['energy_default_lab_J']:.3f} J on the lab robot"
    )
    say(
        f"optimized path:                       {s['energy_optimized_physics_J']:.3f} J on physics, "
        f"{s['energy_optimized_lab_J']:.3f} J on the lab robot"
    )
    say(
        f"saved at equal cycle time: {s['improvement_physics_pct']:.1f} % (physics), "
        f"{s['improvement_lab_pct']:.1f} % (lab); limits ok: {s['limits_ok']}; "
        f"{s['generations']} generations, {s['wall_s']:.1f} s"
    )
    say(
        f"\noutputs in {root}/: tables, models/ (cards, results.csv, plots), run/ (result.json, path.csv, path.mod)"
    )
    return root
