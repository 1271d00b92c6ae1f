"""Physical-validity checks of robot mass properties and limits.

A finding is an *error* when the numbers cannot describe a rigid body (negative
mass, an inertia tensor that is not symmetric positive definite or violates the
triangle inequality, a rotation matrix where a tensor belongs, a centre of mass
farther from its link than the robot reaches) and a *warning* when they are
possible but suspicious (link masses far below the data sheet's robot mass, two
links with identical mass properties).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath.description._model import Inertial, RobotDescription


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


def check_physical(desc: RobotDescription) -> list[Finding]:
    """List everything not physical about a robot description.

    Returns
    -------
    list of Finding
        Empty when nothing is wrong; errors first.

    Examples
    --------
    >>> from joulepath.description import preset_description
    >>> [f.severity for f in check_physical(preset_description("irb120"))]
    ['warning']
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
        if j.lower is not None and j.upper is not None and not j.lower < j.upper:
            out.append(Finding("error", f"joint {j.id} <limits>", f"lower {j.lower} ≥ upper {j.upper}"))
        if j.velocity is not None and not j.velocity > 0:
            out.append(Finding("error", f"joint {j.id} <limits> <velocity>", "must be positive"))
        if j.effort is not None and not j.effort > 0:
            out.append(Finding("error", f"joint {j.id} <limits> <effort>", "must be positive"))
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
