"""The calibrated twin: an identification turned into a robot and written as a twin folder.

The folder's files are declared once in :mod:`joulepath.dynamics` (``TWIN_*_FILE``)
and read back by :func:`joulepath.load_robot`:

* ``robot.irml`` — the nominal description (kinematics, limits, range sets) with
  each link's identified mass, centre of mass and inertia (a payload logged with the
  robot is part of the last link; the description has no separate payload);
* ``robot.urdf`` instead, for an arm read from a URDF (a named arm such as ``ur5``, a
  ``.urdf`` file): the arm's chain as joulepath reads it (kinematics and limits of the
  nominal URDF, locked joints fixed, fixed links merged) with the identified inertials,
  written as a serial URDF (:func:`joulepath.identify._urdf.chain_urdf_string`); the
  nominal URDF (with its meshes) is the one ``twin_of`` names;
* ``friction.json`` — identified friction, gear efficiency and armature (the drives' reflected
  rotor inertia per joint, :attr:`joulepath.description.Chain.armature`: neither URDF nor IRML
  has a place for it, so it lives with the other drive terms; ``load_robot`` sets it on the
  twin's chain, and every dynamics of the twin uses it);
* ``card.json`` — data hash, fit and held-out scores, condition number, base parameters,
  ``robot_file`` (which of the two robot files the folder holds), ``kept_at_prior`` (the
  parameters the logs left unexcited, each with its prior, where the prior comes from and
  why: :attr:`~joulepath.identify.Identification.kept`), and ``parameters``: per joint and
  per parameter what the logs identified and what was assumed or taken as given, with why
  and from where (:func:`parameter_report`);
* ``drives.toml`` — only for a twin identified from motor currents: the identified
  joint-side torque constants and gear efficiency, the other drive data as the nominal
  robot's drives file gives them (:func:`joulepath.identify.identified_drives`), in
  :mod:`joulepath.energy`'s format, so the energy measures use the identified ``k``.
"""

from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._io import atomic_write_text, check_replaceable, finite_json, make_folder, remove_output
from joulepath.description import (
    NAMED_ARMS,
    PRESETS,
    Chain,
    Inertial,
    RobotDescription,
    chain_from_description,
    dh_link,
    named_arm_path,
    preset_path,
    transform_inertial,
)
from joulepath.dynamics import (
    TWIN_CARD_FILE,
    TWIN_FRICTION_FILE,
    TWIN_ROBOT_FILE,
    TWIN_URDF_FILE,
    Calibration,
    Robot,
)
from joulepath.energy import TWIN_DRIVES_FILE, DriveModel, drives_toml
from joulepath.errors import InvalidInput
from joulepath.identify._currents import DriveGainFit
from joulepath.identify._fit import Identification
from joulepath.identify._urdf import chain_urdf_string

CARD_FORMAT = "joulepath-twin-card/1"


def link_inertials(phi: np.ndarray) -> list[Inertial]:
    """Per link: mass, centre of mass and inertia about it (joint frame) of parameters ``phi``."""
    out = []
    for p in np.asarray(phi, dtype=float).reshape(-1, 10):
        m = float(p[0])
        c = p[1:4] / m
        i_o = np.array([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]])
        i_c = i_o - m * (c @ c * np.eye(3) - np.outer(c, c))
        out.append(Inertial.from_arrays(m, c, 0.5 * (i_c + i_c.T)))
    return out


def twin_description(nominal: RobotDescription, ident: Identification) -> RobotDescription:
    """``nominal`` with every link's mass properties replaced by the identified ones (no payload)."""
    if len(nominal.joints) * 10 != ident.phi.size:
        raise InvalidInput(
            f"the identification has {ident.phi.size // 10} links but robot {nominal.name!r} has "
            f"{len(nominal.joints)}"
        )
    joints = []
    for j, body in zip(nominal.joints, link_inertials(ident.phi), strict=True):
        # chain_from_description moves DH-frame mass properties into the joint frame by dh_link
        back = np.asarray(np.linalg.inv(dh_link(j.d, j.r, j.alpha)), dtype=np.float64)
        joints.append(replace(j, inertial=transform_inertial(body, back)))
    return replace(nominal, joints=tuple(joints), payload=None, source=None)


def load_name(robot: Robot) -> str | None:
    """What :func:`joulepath.load_robot` loads ``robot`` by: a bundled or named arm, else its file."""
    if robot.calibration is not None:
        return robot.calibration.twin_of
    if robot.source is None:
        return None
    for name in PRESETS:
        if Path(robot.source).resolve() == preset_path(name).resolve():
            return name
    if robot.name in NAMED_ARMS and Path(robot.source).resolve() == named_arm_path(robot.name).resolve():
        return robot.name
    return str(Path(robot.source).resolve())


def twin_chain(nominal: Robot, ident: Identification) -> Chain:
    """The nominal robot's chain with every link's mass properties replaced by the identified ones."""
    if nominal.n_joints * 10 != ident.phi.size:
        raise InvalidInput(
            f"the identification has {ident.phi.size // 10} links but robot {nominal.name!r} has "
            f"{nominal.n_joints}"
        )
    bodies = link_inertials(ident.phi)
    return replace(
        nominal.chain,
        masses=np.array([b.mass for b in bodies]),
        coms=np.array([b.com_array for b in bodies]),
        inertias=np.array([b.inertia_array for b in bodies]),
        armature=None if ident.armature is None else np.array(ident.armature, dtype=float),
    )


def twin_robot(nominal: Robot, ident: Identification) -> Robot:
    """The identified robot, usable wherever a robot is (its friction is :attr:`Robot.friction`).

    An IRML robot's twin keeps its description (range sets, info) with the identified
    inertials; a URDF robot's twin is its chain with the identified inertials
    (written as ``robot.urdf`` by :func:`write_twin`).
    """
    calibration = Calibration(
        friction=ident.friction,
        gear_efficiency=ident.gear_efficiency,
        twin_of=load_name(nominal),
        armature=() if ident.armature is None else tuple(float(a) for a in ident.armature),
    )
    if nominal.description is None:
        return Robot(twin_chain(nominal, ident), source=f"twin of {nominal.name}", calibration=calibration)
    desc = twin_description(nominal.description, ident)
    return Robot(
        replace(
            chain_from_description(desc),
            armature=None if ident.armature is None else np.array(ident.armature, dtype=float),
        ),
        description=desc,
        source=f"twin of {nominal.name}",
        calibration=calibration,
    )


def parameter_report(
    ident: Identification, *, gains: DriveGainFit | None = None, drives: DriveModel | None = None
) -> list[dict[str, Any]]:
    """Per joint and per parameter: what the logs identified, what was assumed, what was given.

    Each parameter is a dict with ``status``: ``"identified"`` (from these logs),
    ``"assumed"`` (the logs do not fix it, e.g. a parameter they leave unexcited, kept at
    its prior (:attr:`Identification.kept`); ``reason`` says why, ``prior`` where the value
    comes from), ``"given"`` (not identifiable from positions and currents: taken from
    ``source``, the drives file or an option) or ``"not modelled"``.

    Parameters
    ----------
    ident : Identification
    gains : DriveGainFit, optional
        The drive gains of an identification from currents.
    drives : DriveModel, optional
        The twin's drive data (its sources say what is assumed).

    Returns
    -------
    list of dict
        One per joint: ``joint`` (1-based) and one entry per parameter.
    """
    f = ident.friction
    n = f.n_joints
    options = ident.options
    eta_status = "given" if options.gear_efficiency is not None else "identified"
    out: list[dict[str, Any]] = []
    kept = {k.name: k for k in ident.kept}

    def term(j: int, name: str, value: float, **more: Any) -> dict[str, Any]:
        k = kept.get(f"joint{j + 1}.{name}")
        if k is not None:
            return {"status": "assumed", "value": value, "prior": k.prior_source, "reason": k.reason}
        return {"status": "identified", "value": value, **more}

    for j in range(n):
        names = [b for b in ident.base.names if b.startswith(f"link{j + 1}.")]
        held = [b for b in names if b in kept]
        found = [b for b in names if b not in kept]
        inertia: dict[str, Any] = {
            "status": "identified" if found else "assumed" if held else "not identifiable",
            "base_parameters": found,
            "note": "the logs fix these base parameters of the link (combinations with the links "
            "after it); what they leave open follows the nominal description",
        }
        if held:
            inertia["kept_at_prior"] = held
            inertia["prior"] = kept[held[0]].prior_source
            inertia["reason"] = "not excited by the logs: " + kept[held[0]].reason
        row: dict[str, Any] = {
            "joint": j + 1,
            "inertia": inertia,
            "coulomb": term(j, "coulomb", f.coulomb[j]),
            "viscous": term(j, "viscous", f.viscous[j]),
            "offset": (
                term(j, "offset", f.offset[j]) if options.offset else {"status": "not modelled", "value": 0.0}
            ),
            "stribeck": (
                term(j, "stribeck", f.stribeck[j], speed=f.stribeck_speed)
                if options.stribeck_speed
                else {"status": "not modelled", "value": 0.0}
            ),
            "viscous_offset": (
                term(j, "viscous_offset", f.viscous_offset[j])
                if options.viscous_offset
                else {"status": "not modelled", "value": 0.0}
            ),
            "gear_efficiency": {"status": eta_status, "value": ident.gear_efficiency},
            "armature": (
                {"status": "not modelled", "value": 0.0}
                if ident.armature is None
                else _armature_entry(ident, j, kept)
            ),
        }
        if gains is not None:
            k = {"value": gains.torque_constant[j], "relative_error": gains.relative_error[j]}
            assumed = next((a for a in gains.assumed if a.joint == j + 1), None)
            row["torque_constant"] = (
                {"status": "identified", **k}
                if assumed is None
                else {"status": "assumed", **k, "reason": assumed.reason, "prior": assumed.prior}
            )
        if drives is not None:
            for key in ("resistance", "drive_efficiency"):
                source = drives.source(key)
                row[key] = {
                    "status": "assumed" if source.lower().startswith("assumed") else "given",
                    "value": float(getattr(drives, key)[j]),
                    "source": source,
                }
        out.append(row)
    return out


def _armature_entry(ident: Identification, j: int, kept: dict[str, Any]) -> dict[str, Any]:
    """The armature of joint ``j``: kept at its prior, identified alone, or only in a sum with link
    inertias (a dependent column, regrouped into a base parameter)."""
    assert ident.armature is not None
    name = f"joint{j + 1}.armature"
    value = float(ident.armature[j])
    if name in kept:
        return {
            "status": "assumed",
            "value": value,
            "prior": kept[name].prior_source,
            "reason": kept[name].reason,
        }
    if name in ident.base.names:
        return {"status": "identified", "value": value}
    return {
        "status": "identified in a sum",
        "value": value,
        "note": "the logs fix it only together with the inertia of the link about the joint's axis "
        "(a base parameter regroups them); the split follows the prior",
    }


def write_twin(
    ident: Identification,
    nominal: Robot,
    out: str | os.PathLike[str],
    *,
    extra: dict[str, Any] | None = None,
    drives: DriveModel | None = None,
    gains: DriveGainFit | None = None,
) -> list[Path]:
    """Write the twin folder; refuses (before writing anything) files it may not replace.

    Returns the paths written. ``extra`` adds entries to the card; ``drives`` (identified
    drive data) is written as the folder's ``drives.toml``; the card's ``parameters``
    (:func:`parameter_report`) say per joint what was identified and what assumed,
    the torque constants' included when ``gains`` (of an identification from currents)
    are given.
    """
    from joulepath.description import irml_string

    robot = twin_robot(nominal, ident)
    folder = Path(out)
    robot_file = TWIN_ROBOT_FILE if robot.description is not None else TWIN_URDF_FILE
    names = (robot_file, TWIN_FRICTION_FILE, TWIN_CARD_FILE, *((TWIN_DRIVES_FILE,) if drives else ()))
    paths = [folder / name for name in names]
    if drives is not None and drives.n_joints != nominal.n_joints:
        raise InvalidInput(
            f"drive data of {drives.n_joints} joints for the {nominal.n_joints} of {nominal.name!r}"
        )
    other = folder / (TWIN_URDF_FILE if robot_file == TWIN_ROBOT_FILE else TWIN_ROBOT_FILE)
    for p in (*paths, other):
        check_replaceable(p)
    make_folder(folder)
    remove_output(other)  # a twin written before of the other kind: one robot file per folder
    assert robot.calibration is not None
    card = {
        "format": CARD_FORMAT,
        "twin_of": robot.calibration.twin_of,
        "robot_file": robot_file,
        **ident.card(),
        **(extra or {}),
    }
    card["parameters"] = parameter_report(ident, gains=gains, drives=drives)
    if robot.description is not None:
        atomic_write_text(paths[0], irml_string(robot.description))
    else:
        note = (
            f"twin of {robot.calibration.twin_of or nominal.name} written by joulepath identify: the "
            "nominal kinematics and limits with identified inertials; friction and drives beside it"
        )
        atomic_write_text(paths[0], chain_urdf_string(robot.chain, comment=note))
    atomic_write_text(paths[1], json.dumps(robot.calibration.to_json(), indent=2) + "\n")
    atomic_write_text(paths[2], json.dumps(finite_json(card), indent=2, default=_jsonable) + "\n")
    if drives is not None:
        comment = (
            f"drives.toml of the twin of {robot.calibration.twin_of or nominal.name}: joint side.\n"
            f"{drives.describe()}"
        )
        atomic_write_text(paths[3], drives_toml(drives, comment=comment))
    return paths


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serializable: {type(value).__name__}")


__all__ = [
    "CARD_FORMAT",
    "link_inertials",
    "load_name",
    "parameter_report",
    "twin_chain",
    "twin_description",
    "twin_robot",
    "write_twin",
]
