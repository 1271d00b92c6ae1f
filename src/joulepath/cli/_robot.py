"""``joulepath robot ...``: look at a robot description; the CLI's one way to load a robot."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

import typer

from joulepath.cli._common import console, parse_joints

if TYPE_CHECKING:
    from joulepath.dynamics import Robot

robot_app = typer.Typer(help="Inspect robot descriptions (IRML, URDF, bundled).", no_args_is_help=True)

UNCHECKED_HELP = (
    "For experts: use a robot description that fails the physical check "
    "(negative mass, non-positive-definite inertia, zero axis, missing limits); results may be meaningless."
)


def unchecked_option() -> Any:
    """The ``--unchecked`` option, for any command that takes a robot."""
    return typer.Option(False, "--unchecked", help=UNCHECKED_HELP)


def lock_option() -> Any:
    """The ``--lock JOINT=VALUE`` option (repeatable), for any command that takes a URDF robot."""
    return typer.Option(
        [],
        "--lock",
        help="URDF: fix a joint (a gripper's finger, a mimic joint, a branch) at VALUE "
        "(rad; m if prismatic); "
        "repeat for several.",
    )


def parse_locks(items: list[str] | None) -> dict[str, float]:
    """``["finger=0", "j7=0.5"]`` -> ``{"finger": 0.0, "j7": 0.5}``; BadParameter otherwise."""
    import math

    out: dict[str, float] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not sep or not name.strip() or not math.isfinite(number):
            raise typer.BadParameter(
                f"{item!r} is not JOINT=VALUE (a joint name and a finite number, e.g. finger_joint=0)",
                param_hint="--lock",
            )
        joint = name.strip()
        if joint in out:
            raise typer.BadParameter(
                f"joint {joint!r} is locked twice ({out[joint]:g} and {number:g}); lock it once",
                param_hint="--lock",
            )
        out[name.strip()] = number
    return out


def load_robot_for_cli(name_or_path: str, *, unchecked: bool = False, lock: list[str] | None = None) -> Robot:
    """Load a robot for a command: refused with the finding when it fails the physical check.

    With ``unchecked`` (the ``--unchecked`` option) the robot is used anyway and one
    warning line on stderr names the first error, so that the output of an expert's
    run is never taken for a checked one. Warnings from reading the description (a
    joint named like a gripper, a continuous joint given ±360°) go to stderr too.
    """
    from joulepath import load_robot

    robot = load_robot(name_or_path, checked=not unchecked, lock=parse_locks(lock) or None)
    for where, message in robot.chain.notes:
        print(f"warning: {robot.name}: {where} {message}", file=sys.stderr)
    if unchecked:
        errors = [f for f in robot.check_physical() if f.severity == "error"]
        if errors:
            more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
            print(
                f"warning: --unchecked: using {robot.source}, which fails the physical check: "
                f"{errors[0].where}: {errors[0].message}{more}",
                file=sys.stderr,
            )
    return robot


@robot_app.command("show")
def show(
    robot: str = typer.Argument(
        ..., help="Robot name (irb120, irb4600-40-2.55, irb4600, ur5, panda, ...) or an .irml/.urdf path."
    ),
    strict: bool = typer.Option(False, help="Exit with code 1 when the physical check finds errors."),
    lock: list[str] = lock_option(),
) -> int:
    """Print a robot's description and its physical-validity check (also for a robot that fails it)."""
    from joulepath import load_robot
    from joulepath.export import declared_controller

    r = load_robot(robot, checked=False, lock=parse_locks(lock) or None)  # showing what is wrong is our job
    console.print(r.summary(), markup=False)
    console.print(f"controller: {declared_controller(r)} (--export overrides); friction: {r.friction_note}")
    drives = r.drives
    idle = (
        f": standby {drives.standby_W:g} W ({drives.source('standby_W').split(':')[0]})"
        if drives is not None
        else ""
    )
    console.print(f"drive data: {r.drives_note}{idle}", markup=False)
    home = r.fk(r.home)
    x, y, z = home.position_mm
    w, qx, qy, qz = home.quaternion
    console.print(
        f"tool0 at home: ({x:.1f}, {y:.1f}, {z:.1f}) mm, quaternion ({w:.5f}, {qx:.5f}, {qy:.5f}, {qz:.5f})"
    )
    from joulepath.description import provenance_beside

    provenance = provenance_beside(r.source)
    for where, message in r.chain.notes:
        if where != "model" or provenance is None:
            console.print(f"note: {r.name}: {where} {message}", markup=False)
    if provenance is not None:
        console.print(provenance.headline(), markup=False)
        for line in provenance.lines():
            console.print(line, markup=False)
    findings = r.check_physical()
    errors = [f for f in findings if f.severity == "error"]
    if not findings:
        console.print("physical check: no problems found")
    else:
        console.print(f"physical check: {len(errors)} error(s), {len(findings) - len(errors)} warning(s)")
        for f in findings:
            console.print(f"  {f}", markup=False)
        if errors:
            console.print(
                "  other commands refuse this robot; experts can use it with --unchecked", markup=False
            )
    return 1 if strict and errors else 0


@robot_app.command("fk")
def fk(
    robot: str = typer.Argument(
        ..., help="Robot name (irb120, irb4600-40-2.55, irb4600, ur5, panda, ...) or an .irml/.urdf path."
    ),
    q: str = typer.Option(..., "--q", help="Joint positions, comma separated."),
    degrees: bool = typer.Option(False, "--degrees", help="--q is in degrees (default rad)."),
    lock: list[str] = lock_option(),
    unchecked: bool = unchecked_option(),
) -> int:
    """Print the tool0 pose for one configuration, in the controller's units."""
    r = load_robot_for_cli(robot, unchecked=unchecked, lock=lock)
    values = parse_joints(q, option="--q", degrees=degrees, n=r.n_joints)
    pose = r.fk(values)
    x, y, z = pose.position_mm
    ez, ey, ex = pose.euler_zyx_deg
    console.print(f"position mm   {x:.3f} {y:.3f} {z:.3f}")
    console.print("quaternion    " + " ".join(f"{v:.5f}" for v in pose.quaternion))
    console.print(f"EulerZYX deg  z {ez:.3f}  y {ey:.3f}  x {ex:.3f}")
    return 0
