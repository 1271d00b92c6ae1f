"""Physical-validity checks of robot mass properties and limits.

A finding is an *error* when the numbers cannot describe a rigid body (negative
mass, an inertia tensor that is not symmetric positive definite or violates the
triangle inequality, a rotation matrix where a tensor belongs, a centre of mass
farther from its link than the robot reaches) and a *warning* when they are
possible but suspicious (link masses far below the data sheet's robot mass, two
links with identical mass properties).

Limits: a joint without a range (lower and upper) or a speed limit is an *error*,
because every command that plans or checks motion needs them (random tasks, the
optimizer's bounds, the limit check before a RAPID program is written); a robot
without torque (effort) limits only draws a *warning*, since the torque check is
then skipped. A joint whose rotation axis is zero (or not finite) is an *error*.
:func:`joulepath.load_robot` refuses a robot with any error unless
``checked=False``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray
from joulepath.description._model import Chain, Inertial, RobotDescription


@dataclass(frozen=True, slots=True)
class Finding:
    """One problem found by :func:`check_physical`."""

    severity: str
    where: str
    message: str

    def __str__(self) -> str:
        return f"{self.severity}: {self.where}: {self.message}"


def _fmt(a: np.ndarray) -> str:
    return "[" + ", ".join(f"{x:.4g}" for x in np.ravel(a)) + "]"


def check_inertial(where: str, inertial: Inertial, *, reach: float | None = None) -> list[Finding]:
    """Check one body's mass, centre of mass and inertia tensor.

    Parameters
    ----------
    where : str
        Label for the findings, e.g. ``"joint 3 <dynamics>"``.
    inertial : Inertial
    reach : float, optional
        The robot's reach in m: no link's centre of mass lies farther than this
        from the link's own frame.
    """
    out: list[Finding] = []
    m = inertial.mass
    inertia = inertial.inertia_array
    com = inertial.com_array
    if not np.isfinite(m) or m <= 0.0:
        out.append(Finding("error", f"{where} <link-mass>", f"mass {m} kg is not positive"))
    if not np.all(np.isfinite(inertia)):
        out.append(Finding("error", f"{where} <inertia>", "has non-finite entries"))
        return out
    scale = max(float(np.abs(inertia).max()), 1e-12)
    if np.abs(inertia - inertia.T).max() > 1e-6 * scale:
        out.append(
            Finding(
                "error",
                f"{where} <inertia>",
                f"is not symmetric (xy={inertia[0, 1]:.4g} vs yx={inertia[1, 0]:.4g}, "
                f"xz={inertia[0, 2]:.4g} vs zx={inertia[2, 0]:.4g}, "
                f"yz={inertia[1, 2]:.4g} vs zy={inertia[2, 1]:.4g})",
            )
        )
    ortho = np.abs(inertia.T @ inertia - np.eye(3)).max()
    if ortho < 0.05 and abs(abs(np.linalg.det(inertia)) - 1.0) < 0.05:
        out.append(
            Finding(
                "error",
                f"{where} <inertia>",
                "is a rotation matrix (orthonormal, determinant "
                f"{np.linalg.det(inertia):+.3f}), not an inertia tensor in kg·m²",
            )
        )
    sym = 0.5 * (inertia + inertia.T)
    eig = np.linalg.eigvalsh(sym)
    if eig.min() <= 0.0:
        out.append(
            Finding(
                "error",
                f"{where} <inertia>",
                f"is not positive definite (principal moments {_fmt(eig)} kg·m²)",
            )
        )
    else:
        a, b, c = np.sort(eig)
        if a + b < c * (1.0 - 1e-9):
            out.append(
                Finding(
                    "error",
                    f"{where} <inertia>",
                    f"violates the triangle inequality: {a:.4g} + {b:.4g} < {c:.4g} kg·m²",
                )
            )
    if reach is not None and np.isfinite(com).all():
        dist = float(np.linalg.norm(com))
        if dist > reach:
            out.append(
                Finding(
                    "error",
                    f"{where} <center>",
                    f"centre of mass {_fmt(com)} m lies {dist:.3f} m from the link frame, "
                    f"beyond the robot's reach of {reach:g} m; <center> must be given in the "
                    "link's own frame (world coordinates at the zero pose?)",
                )
            )
        if m > 0 and eig.max() > m * reach**2:
            out.append(
                Finding(
                    "warning",
                    f"{where} <inertia>",
                    f"largest principal moment {eig.max():.4g} kg·m² exceeds mass × reach² = "
                    f"{m * reach**2:.4g} kg·m²",
                )
            )
    return out


def _joint_list(labels: list[str]) -> str:
    return labels[0] if len(labels) == 1 else ", ".join(labels[:-1]) + " and " + labels[-1]


def check_limits(
    labels: list[str],
    lower: FloatArray,
    upper: FloatArray,
    velocity: FloatArray,
    effort: FloatArray,
    *,
    tag: str = "<limits>",
) -> list[Finding]:
    """Check joint limits: a range and a speed limit for every joint, in order and positive.

    Parameters
    ----------
    labels : list of str
        One label per joint, e.g. ``"joint 3"`` or ``"joint 'joint_3'"``.
    lower, upper, velocity, effort : ndarray of shape (n,)
        rad, rad/s, N·m; NaN where the description gives none.
    tag : str
        How the file calls its limits element (``"<limits>"`` in IRML, ``"<limit>"`` in URDF).

    Returns
    -------
    list of Finding
        Errors for a missing or empty range and a missing or non-positive speed or
        torque limit; one warning naming every joint without a torque limit.

    Examples
    --------
    >>> import numpy as np
    >>> nan = float("nan")
    >>> findings = check_limits(["joint 1"], np.array([-1.0]), np.array([1.0]),
    ...                         np.array([nan]), np.array([10.0]))
    >>> [(f.severity, f.where) for f in findings]
    [('error', 'joint 1 <limits>')]
    """
    out: list[Finding] = []
    no_effort: list[str] = []
    for label, lo, hi, v, e in zip(labels, lower, upper, velocity, effort, strict=True):
        where = f"{label} {tag}"
        if not (np.isfinite(lo) and np.isfinite(hi)):
            missing = " and ".join(n for n, x in (("lower", lo), ("upper", hi)) if not np.isfinite(x))
            out.append(
                Finding(
                    "error",
                    where,
                    f"no {missing} range limit; the optimizer, the random tasks and the limit check "
                    "before a RAPID program need the joint range: give it in rad",
                )
            )
        elif not lo < hi:
            out.append(Finding("error", where, f"lower {lo:.6g} ≥ upper {hi:.6g} rad: the range is empty"))
        if np.isnan(v):
            out.append(
                Finding(
                    "error",
                    where,
                    "no speed limit (velocity); the optimizer and the limit check need the joint's "
                    "maximum speed: give it in rad/s (the data sheet's axis speed)",
                )
            )
        elif not v > 0:
            out.append(Finding("error", where, f"velocity {v:.6g} rad/s must be positive"))
        if np.isnan(e):
            no_effort.append(label)
        elif not e > 0:
            out.append(Finding("error", where, f"effort {e:.6g} N·m must be positive"))
    if no_effort:
        out.append(
            Finding(
                "warning",
                f"{'every joint' if no_effort == list(labels) else _joint_list(no_effort)} {tag}",
                "no torque (effort) limit, so the torque check is skipped; give it in N·m to enable it",
            )
        )
    return out


def check_axes(labels: list[str], axes: FloatArray) -> list[Finding]:
    """An error for every joint whose rotation axis is zero or not finite (shape ``(n, 3)``)."""
    out: list[Finding] = []
    for label, axis in zip(labels, axes, strict=True):
        norm = float(np.linalg.norm(axis)) if np.all(np.isfinite(axis)) else float("nan")
        if not norm > 1e-9:
            out.append(
                Finding(
                    "error",
                    f"{label} <axis>",
                    f"rotation axis {_fmt(axis)} is {'zero' if norm == 0 else 'not a direction'}; "
                    'give the unit axis the joint turns about, e.g. xyz="0 0 1"',
                )
            )
    return out


def check_armature(labels: list[str], armature: FloatArray) -> list[Finding]:
    """An error for each joint whose armature (reflected rotor inertia, kg·m²) is negative or not finite."""
    return [
        Finding(
            "error",
            label,
            f"armature {float(a):g} kg·m² is not a finite number ≥ 0 (a rotating inertia cannot be "
            "negative); identify the twin again or remove the value",
        )
        for label, a in zip(labels, armature, strict=True)
        if not (np.isfinite(a) and a >= 0)
    ]


def check_chain(chain: Chain) -> list[Finding]:
    """List everything not physical about a :class:`Chain` (e.g. one read from a URDF).

    Checks every link's mass properties (:func:`check_inertial`), the joint axes
    (:func:`check_axes`) and the limits (:func:`check_limits`). Errors first.
    """
    labels = [f"joint {name!r}" for name in chain.joint_names]
    out: list[Finding] = []
    for i, label in enumerate(labels):
        body = Inertial.from_arrays(chain.masses[i], chain.coms[i], chain.inertias[i])
        out += check_inertial(f"link of {label}", body)
    out += check_axes(labels, chain.axes)
    out += check_armature(labels, chain.joint_armature)
    out += check_limits(labels, chain.lower, chain.upper, chain.velocity, chain.effort, tag="<limit>")
    out += [Finding("warning", where, message) for where, message in chain.notes]
    out.sort(key=lambda f: f.severity != "error")
    return out


def check_physical(desc: RobotDescription) -> list[Finding]:
    """List everything not physical about a robot description.

    Returns
    -------
    list of Finding
        Empty when nothing is wrong; errors first.

    Examples
    --------
    >>> from joulepath.description import preset_description
    >>> [f.where for f in check_physical(preset_description("irb120"))]
    ['every joint <limits>', '<manipulator-mass>']
    """
    out: list[Finding] = []
    reach = desc.reach_m
    for j in desc.joints:
        where = f"joint {j.id} <dynamics>"
        out += check_inertial(where, j.inertial, reach=reach)
        for prev in desc.joints:
            if prev.id == j.id:
                break
            if prev.inertial == j.inertial:
                out.append(
                    Finding(
                        "warning",
                        where,
                        f"repeats joint {prev.id}'s dynamics block exactly (copy-paste?)",
                    )
                )
                break
    nan = float("nan")

    def arr(values: list[float | None]) -> FloatArray:
        return np.array([nan if v is None else v for v in values], dtype=float)

    js = desc.joints
    out += check_limits(
        [f"joint {j.id}" for j in js],
        arr([j.lower for j in js]),
        arr([j.upper for j in js]),
        arr([j.velocity for j in js]),
        arr([j.effort for j in js]),
    )
    for rs in desc.range_sets:
        for j, lo, hi in zip(desc.joints, rs.lower, rs.upper, strict=True):
            if not lo < hi:
                out.append(Finding("error", f"range-set {rs.name!r} joint {j.id}", f"{lo} ≥ {hi}"))
            if j.lower is not None and j.upper is not None and (lo < j.lower or hi > j.upper):
                out.append(
                    Finding(
                        "error",
                        f"range-set {rs.name!r} joint {j.id}",
                        f"[{lo:.4g}, {hi:.4g}] rad leaves the joint's range "
                        f"[{j.lower:.4g}, {j.upper:.4g}] rad",
                    )
                )
    if desc.payload is not None:
        out += check_inertial("<payload>", desc.payload, reach=reach)
    if desc.base is not None:
        out += check_inertial("<base>", desc.base)
    spec = desc.spec_mass_kg
    links = sum(j.inertial.mass for j in desc.joints)
    total = links + (desc.base.mass if desc.base is not None else 0.0)
    if spec is not None and spec > 0:
        parts = f"links {links:.3f} kg" + (
            f" + base {desc.base.mass:.3f} kg" if desc.base is not None else ", no <base> given"
        )
        if total > spec * 1.02:
            out.append(
                Finding(
                    "error",
                    "<manipulator-mass>",
                    f"the masses sum to {total:.3f} kg ({parts}), more than the robot's {spec:g} kg",
                )
            )
        elif total < spec * 0.9:
            out.append(
                Finding(
                    "warning",
                    "<manipulator-mass>",
                    f"the masses sum to {total:.3f} kg ({parts}), {spec - total:.3f} kg "
                    f"({100 * (spec - total) / spec:.0f} %) short of the robot's {spec:g} kg; "
                    "the missing mass (cables, motors, gearboxes) is not in the model",
                )
            )
    out.sort(key=lambda f: f.severity != "error")
    return out
