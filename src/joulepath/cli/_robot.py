"""``joulepath robot ...``: look at a robot description."""

from __future__ import annotations

import typer

from joulepath.cli._common import console, parse_joints

robot_app = typer.Typer(help="Inspect robot descriptions (IRML, URDF, bundled).", no_args_is_help=True)


@robot_app.command("show")
def show(
    robot: str = typer.Argument(..., help="Bundled robot name (irb120) or an .irml/.urdf path."),
    strict: bool = typer.Option(False, help="Exit with code 1 when the physical check finds errors."),
) -> int:
    """Print a robot's description and its physical-validity check."""
    from joulepath import load_robot

    r = load_robot(robot)
    console.print(r.summary())
    home = r.fk(r.home)
    x, y, z = home.position_mm
    w, qx, qy, qz = home.quaternion
    console.print(
        f"tool0 at home: ({x:.1f}, {y:.1f}, {z:.1f}) mm, quaternion ({w:.5f}, {qx:.5f}, {qy:.5f}, {qz:.5f})"
    )
    findings = r.check_physical()
    errors = [f for f in findings if f.severity == "error"]
    if not findings:
        console.print("physical check: no problems found")
    else:
        console.print(f"physical check: {len(errors)} error(s), {len(findings) - len(errors)} warning(s)")
        for f in findings:
            console.print(f"  {f}", markup=False)
    return 1 if strict and errors else 0


@robot_app.command("fk")
def fk(
    robot: str = typer.Argument(..., help="Bundled robot name or an .irml/.urdf path."),
    q: str = typer.Option(..., "--q", help="Joint positions, comma separated."),
    degrees: bool = typer.Option(False, "--degrees", help="--q is in degrees (default rad)."),
) -> int:
    """Print the tool0 pose for one configuration, in the controller's units."""
    from joulepath import load_robot

    r = load_robot(robot)
    values = parse_joints(q, option="--q", degrees=degrees, n=r.n_joints)
    pose = r.fk(values)
    x, y, z = pose.position_mm
    ez, ey, ex = pose.euler_zyx_deg
    console.print(f"position mm   {x:.3f} {y:.3f} {z:.3f}")
    console.print("quaternion    " + " ".join(f"{v:.5f}" for v in pose.quaternion))
    console.print(f"EulerZYX deg  z {ez:.3f}  y {ey:.3f}  x {ex:.3f}")
    return 0
