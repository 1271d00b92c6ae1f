"""The demo behind ``make demo``: the bundled IRB 120, its poses and one move's energy."""

from __future__ import annotations

import numpy as np

from joulepath.dynamics import ElastoPlasticFriction, load_robot
from joulepath.trajectory import minimum_jerk
from joulepath.units import DEG, SAMPLE_PERIOD

DEMO_POSE_DEG = (30.0, 20.0, -10.0, 45.0, 30.0, 60.0)


def run_demo(*, duration: float = 1.5) -> str:
    """Return the demo's text: robot summary, tool0 poses, per-joint energy of a move."""
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
    friction = robot.path_energy(move.q, move.qd, move.qdd, SAMPLE_PERIOD, friction=ElastoPlasticFriction())
    lines.append(
        f"sample move: minimum-jerk from home to the pose above in {duration:g} s, "
        f"{move.t.size} samples at {1 / SAMPLE_PERIOD:g} Hz"
    )
    lines.append("  E_i = sum |tau_i * qd_i| * dt     rigid body    + thesis friction")
    for i in range(robot.n_joints):
        lines.append(
            f"  joint {i + 1}                        {rigid.per_joint[i]:8.3f} J    "
            f"{friction.per_joint[i]:8.3f} J"
        )
    lines.append(
        f"  total                          {float(rigid.total):8.3f} J    {float(friction.total):8.3f} J"
    )
    return "\n".join(lines)
