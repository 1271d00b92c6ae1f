"""path.mod as the controller emulation runs it: executed against planned saving (issue: run as planned).

For the fixed task, the README's move and random tasks (IRB 120), the move is optimized for RAPID
(``follow="via-points"``: within ``RAPID_ACCEL_SHARE`` of the acceleration limit and the jerk limit),
written by ``write_run`` and the written module run by the controller emulation; beside it, the same
task planned for a sampled interface (EGM, URScript: the full limits) as the saving a streaming
export carries. Energies on physics (2.5 ms grid); the RAPID default is the controller's own
``MoveAbsJ \\T``, the planned default the minimum-jerk move.

Usage: python benchmarks/rapid_execution.py [N_RANDOM]
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_core, write_section  # noqa: E402
from _tasks import NAMED_TASKS  # noqa: E402

single_core()


import joulepath  # noqa: E402
from joulepath.optimize import OptimizeConfig, optimize_move, random_tasks, write_run  # noqa: E402

TASKS = NAMED_TASKS


def main() -> None:
    n_random = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    robot = joulepath.load_robot("irb120")
    tasks = list(TASKS)
    for k, (q0, qf, T) in enumerate(random_tasks(robot, n_random, seed=21)):
        tasks.append((f"random {k}", q0, qf, T))
    rows = []
    for name, q0, qf, T in tasks:
        t0 = time.perf_counter()
        rapid = optimize_move(robot, q0, qf, T, OptimizeConfig(follow="via-points"))
        wall = time.perf_counter() - t0
        sampled = optimize_move(robot, q0, qf, T, OptimizeConfig())
        with tempfile.TemporaryDirectory() as tmp:
            write_run(rapid, robot, tmp)
            s = json.loads((Path(tmp) / "result.json").read_text())
        rows.append(
            f"| {name} | {T:g} s | {sampled.summary.saved_pct:.1f} % | {rapid.summary.saved_pct:.1f} % | "
            f"{s['executed_saved_pct']:.1f} % | {s['executed_saved_lab_pct']:.1f} % | "
            f"{s['executed_duration_s']:.3f} s | {s['executed_via_points']} | {s['executed_tcp_deviation_mm']:.1f} mm | "
            f"{'written' if s['rapid'] else 'refused'} | {wall:.1f} s |"
        )
        print(rows[-1], flush=True)
    body = (
        f"""## path.mod as the controller runs it (benchmarks/rapid_execution.py)

Machine: {machine()}.

Per task: the plan for a sampled interface (EGM, URScript, ROS 2: the full acceleration and jerk limits)
and the plan for RAPID (within 3/(2π) of the acceleration limit; the search of
`via_point_settings`: hull rows on 0.1 s knots), both against the minimum-jerk move;
then the written path.mod run by the controller emulation: its optimized move against the controller's
own `MoveAbsJ \\T` at the same duration, on physics and on the emulated lab robot (the motion
its servo runs: the plant's tracking lag). Written when the
module runs at most 2 % slower than planned, within 5 mm of the planned TCP path, with a saving.

| task | duration | planned, sampled export | planned, RAPID | executed (path.mod), physics | executed, lab | executed duration | via points | TCP off plan | path.mod | RAPID plan wall |
|---|---|---|---|---|---|---|---|---|---|---|
"""
        + "\n".join(rows)
        + "\n"
    )
    write_section("rapid_execution", body)


if __name__ == "__main__":
    main()
