"""Turn an IRML description into a generic :class:`Chain`; combine rigid bodies."""

from __future__ import annotations

import numpy as np

from joulepath._typing import FloatArray
from joulepath.description._model import Chain, Inertial, RobotDescription


def rot_z(theta: float) -> FloatArray:
    c, s = np.cos(theta), np.sin(theta)
    out = np.eye(4)
    out[:2, :2] = [[c, -s], [s, c]]
    return out


def dh_link(d: float, r: float, alpha: float) -> FloatArray:
    """Constant part of a standard DH transform: ``Tz(d) @ Tx(r) @ Rx(alpha)``."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0, r], [0.0, ca, -sa, 0.0], [0.0, sa, ca, d], [0.0, 0.0, 0.0, 1.0]])


def dh_transform(theta: float, d: float, r: float, alpha: float) -> FloatArray:
    """Thesis eq. 2.10: ``Rz(theta) Tz(d) Tx(r) Rx(alpha)``."""
    return rot_z(theta) @ dh_link(d, r, alpha)


def transform_inertial(inertial: Inertial, transform: FloatArray) -> Inertial:
    """Express a body's mass properties in another frame (``p_new = T @ p_old``)."""
    rot = transform[:3, :3]
    return Inertial.from_arrays(
        inertial.mass,
        rot @ inertial.com_array + transform[:3, 3],
        rot @ inertial.inertia_array @ rot.T,
    )


def combine_inertials(a: Inertial, b: Inertial) -> Inertial:
    """Mass properties of two rigid bodies fixed together (same frame)."""
    m = a.mass + b.mass
    if m <= 0:
        raise ValueError("combined mass must be positive")
    c = (a.mass * a.com_array + b.mass * b.com_array) / m
    total = np.zeros((3, 3))
    for body in (a, b):
        d = body.com_array - c
        total += body.inertia_array + body.mass * (d @ d * np.eye(3) - np.outer(d, d))
    return Inertial.from_arrays(m, c, total)


def _nan_if_none(values: list[float | None]) -> FloatArray:
    return np.array([np.nan if v is None else v for v in values], dtype=float)


def chain_from_description(
    desc: RobotDescription, *, gravity: float = 9.80665, payload: Inertial | None = None
) -> Chain:
    """Build the kinematic/dynamic chain of an IRML description.

    Joint frame ``i`` is DH frame ``i-1`` rotated by ``offset_i + sign_i * q_i``
    about its z axis; link ``i``'s mass properties, given in DH frame ``i``, are
    moved into joint frame ``i`` by the constant ``Tz(d_i) Tx(r_i) Rx(alpha_i)``;
    the tool frame is DH frame ``n``. A payload (given in the tool frame) is added
    to the last link; ``payload`` overrides the description's own.
    """
    n = len(desc.joints)
    placements = np.empty((n, 4, 4))
    coms = np.empty((n, 3))
    inertias = np.empty((n, 3, 3))
    prev = np.eye(4)
    links = []
    for i, j in enumerate(desc.joints):
        placements[i] = prev @ rot_z(j.offset)
        link = dh_link(j.d, j.r, j.alpha)
        links.append(transform_inertial(j.inertial, link))
        prev = link
    tool = prev
    load = payload if payload is not None else desc.payload
    if load is not None and load.mass > 0:
        links[-1] = combine_inertials(links[-1], transform_inertial(load, tool))
    for i, body in enumerate(links):
        coms[i] = body.com_array
        inertias[i] = body.inertia_array
    return Chain(
        name=desc.name,
        joint_names=tuple(f"joint_{j.id}" for j in desc.joints),
        placements=placements,
        axes=np.array([[0.0, 0.0, j.sign] for j in desc.joints]),
        masses=np.array([b.mass for b in links]),
        coms=coms,
        inertias=inertias,
        tool=tool,
        lower=_nan_if_none([j.lower for j in desc.joints]),
        upper=_nan_if_none([j.upper for j in desc.joints]),
        velocity=_nan_if_none([j.velocity for j in desc.joints]),
        effort=_nan_if_none([j.effort for j in desc.joints]),
        gravity=np.array([0.0, 0.0, -gravity]),
        notes=description_notes(desc),
    )


def dynamics_fingerprint(desc: RobotDescription) -> str:
    """A short hash of the links' mass properties (9 significant digits), so that a statement
    about them (``<model>estimated ...``) is known to be about these values and not others."""
    import hashlib

    values = []
    for j in desc.joints:
        b = j.inertial
        values += [b.mass, *b.com, *(v for row in b.inertia for v in row)]
    text = " ".join(f"{v:.9g}" for v in values)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def description_notes(desc: RobotDescription) -> tuple[tuple[str, str], ...]:
    """What every result computed on this description must say: an estimated model (the IRML
    ``<model>`` entry when it is not published or identified, while ``<model-fingerprint>`` still
    matches the links' mass properties: a twin or an edited copy with other values is not that
    estimate), and the family name that stands for this variant (``<family-default>``)."""
    notes = []
    model = desc.info_value("model")
    fingerprint = desc.info_value("model-fingerprint")
    same = fingerprint is None or fingerprint == dynamics_fingerprint(desc)
    if model and same and not model.startswith(("published", "identified")):
        notes.append(("model", model))
    family = desc.info_value("family-default")
    if family and same:
        notes.append(
            ("robot", f"is the variant that the family name {family!r} stands for (--robot {family})")
        )
    return tuple(notes)
