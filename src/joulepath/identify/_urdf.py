"""A :class:`~joulepath.description.Chain` written as a serial URDF: the robot file of a URDF arm's twin.

The twin of an arm read from a URDF (a named arm such as ``ur5``, or a ``.urdf``
file) keeps that arm's kinematics and limits exactly as joulepath reads them
(locked joints fixed, links joined by fixed joints merged into their moving body)
and carries the identified mass properties. It is written as the simplest URDF that
:func:`joulepath.description.chain_from_urdf` reads back into the same chain::

    base_link -[joint 1]-> <joint 1>_link -[joint 2]-> ... -[fixed]-> tool0

Each joint's ``<origin>`` is the chain's placement, its ``<axis>`` the chain's axis,
its ``<limit>`` the chain's range, speed and torque (0 where unknown, which the
reader takes as unknown again); each link's ``<inertial>`` is the link's mass,
centre of mass and inertia about it, in the joint frame. Meshes are not copied: the
twin is a model of the dynamics (the nominal URDF, named by the card's ``twin_of``,
keeps the visuals).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from joulepath._typing import FloatArray
from joulepath.description import Chain

TOOL_LINK = "tool0"
BASE_LINK = "base_link"


def _num(value: float) -> str:
    return repr(float(value))


def _vec(values: FloatArray) -> str:
    return " ".join(_num(v) for v in values)


def _rpy(rotation: FloatArray) -> FloatArray:
    """URDF roll, pitch, yaw (fixed axes X, Y, Z) of a rotation matrix (Pinocchio's convention)."""
    import pinocchio as pin

    out: FloatArray = np.asarray(pin.rpy.matrixToRpy(np.asarray(rotation, dtype=float)), dtype=float)
    return out


def _origin(parent: ET.Element, transform: FloatArray) -> None:
    ET.SubElement(parent, "origin", xyz=_vec(transform[:3, 3]), rpy=_vec(_rpy(transform[:3, :3])))


def _known(value: float) -> str:
    """A limit the URDF reader takes back as the same number, or as unknown (0) for NaN."""
    return _num(value) if np.isfinite(value) else "0"


def _unique(name: str, taken: set[str]) -> str:
    out, k = name, 1
    while out in taken:
        k += 1
        out = f"{name}_{k}"
    taken.add(out)
    return out


def chain_urdf_string(chain: Chain, *, comment: str = "") -> str:
    """The URDF text of ``chain`` (see the module docstring); reading it back gives the same chain.

    Parameters
    ----------
    chain : Chain
    comment : str
        Written as an XML comment under ``<robot>`` (e.g. where the twin comes from).

    Returns
    -------
    str
    """
    root = ET.Element("robot", name=chain.name)
    if comment:
        root.append(ET.Comment(" " + comment.replace("--", "- -") + " "))
    taken = set(chain.joint_names)
    links = [_unique(BASE_LINK, taken)]
    ET.SubElement(root, "link", name=links[0])
    for i, jname in enumerate(chain.joint_names):
        link = _unique(f"{jname}_link", taken)
        el = ET.SubElement(root, "link", name=link)
        inertial = ET.SubElement(el, "inertial")
        ET.SubElement(inertial, "origin", xyz=_vec(chain.coms[i]), rpy="0 0 0")
        ET.SubElement(inertial, "mass", value=_num(chain.masses[i]))
        inertia = chain.inertias[i]
        ET.SubElement(
            inertial,
            "inertia",
            ixx=_num(inertia[0, 0]),
            ixy=_num(inertia[0, 1]),
            ixz=_num(inertia[0, 2]),
            iyy=_num(inertia[1, 1]),
            iyz=_num(inertia[1, 2]),
            izz=_num(inertia[2, 2]),
        )
        joint = ET.SubElement(root, "joint", name=jname, type="revolute")
        ET.SubElement(joint, "parent", link=links[-1])
        ET.SubElement(joint, "child", link=link)
        _origin(joint, chain.placements[i])
        ET.SubElement(joint, "axis", xyz=_vec(chain.axes[i]))
        ET.SubElement(
            joint,
            "limit",
            lower=_known(chain.lower[i]),
            upper=_known(chain.upper[i]),
            velocity=_known(chain.velocity[i]),
            effort=_known(chain.effort[i]),
        )
        links.append(link)
    tool_link = TOOL_LINK
    if tool_link in taken:
        tool_link = _unique(TOOL_LINK, taken)
    else:
        taken.add(tool_link)
    tool = ET.SubElement(root, "joint", name=_unique(f"{links[-1]}-{tool_link}", taken), type="fixed")
    ET.SubElement(tool, "parent", link=links[-1])
    ET.SubElement(tool, "child", link=tool_link)
    _origin(tool, chain.tool)
    ET.SubElement(root, "link", name=tool_link)
    ET.indent(root)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


__all__ = ["BASE_LINK", "TOOL_LINK", "chain_urdf_string"]
