"""The :class:`Robot`: a chain with its kinematics, dynamics, limits and checks."""

from __future__ import annotations

import os
import re
from dataclasses import replace
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from joulepath import energy as _energy
from joulepath._typing import ArrayLike, FloatArray
from joulepath.description import (
    DEFAULT_ROBOT,
    HOME,
    NAMED_ARMS,
    PRESETS,
    Chain,
    Finding,
    Inertial,
    RobotDescription,
    abb_drive_class,
    abb_drives_path,
    axes_to_joints,
    axis3_range,
    axis_torques_to_joints,
    chain_from_description,
    chain_from_urdf,
    check_chain,
    check_inertial,
    check_physical,
    has_axis3_coupling,
    joint_torques_to_axes,
    joints_to_axes,
    named_arm_path,
    pinocchio_model,
    preset_path,
    read_irml,
)
from joulepath.dynamics._calibration import Calibration, read_calibration, twin_paths
from joulepath.dynamics._friction import FRICTION_SUFFIX, NOMINAL_FRICTION, Friction, read_friction_file
from joulepath.dynamics._lagrange_euler import lagrange_euler, mass_matrix_le
from joulepath.dynamics._rnea import PinocchioRnea
from joulepath.errors import InvalidInput, InvalidRobotDescription
from joulepath.kinematics import Pose, check_q, forward_kinematics, geometric_jacobian

METHODS = ("pinocchio", "lagrange-euler")
FRICTION_BOUND = 10.0
"""A joint friction torque (N·m) is refused above this many times the torque of the arm's whole moving
weight held at its reach (the IRB 120: about 840 N·m, some 500 times its identified friction)."""
TWIN_KINEMATICS_TOLERANCE_MM = 1.0
"""How far tool0 of a twin and of the robot its ``twin_of`` names may lie apart at the same configuration."""
_IRB120 = re.compile(r"irb[ _-]?120", re.I)


def _bundled_abb_drives(source: Path) -> Path | None:
    """The class drives file of a bundled ABB arm's description (``presets/irb6700-*.irml``), or None."""
    cls_file = abb_drives_path(source.stem)
    if cls_file is None or source.stem not in PRESETS:
        return None
    if source.resolve().parent != preset_path("irb120").resolve().parent:
        return None  # a copy elsewhere is the user's robot: its own drives file, if any, beside it
    return cls_file if cls_file.is_file() else None


_FROM_FILES = object()
FALLBACK_RANGE_SETS = ("lab", "collection")
"""Range sets whose absence falls back to the nominal ranges (:meth:`Robot.ranges_for`)."""


OVERLOAD_FACTOR = 2.0
"""A program's load above the rated payload is run (with a line that says so) up to this many times
it: a controller runs a ``loaddata`` over the rating (at reduced performance, within its load
diagram); beyond it, the program is taken to be for a larger arm and refused with that hint."""


class Robot:
    """A six-axis (or any n-axis serial revolute) arm.

    Build one with :func:`load_robot`. Joint arrays have shape ``(..., n)`` with
    any batch shape, in SI units (rad, rad/s, rad/s², N·m).

    Examples
    --------
    >>> robot = load_robot("irb120")
    >>> robot.fk([0, 0, 0, 0, 0, 0]).position_mm.round(3)
    array([374.,   0., 630.])
    """

    def __init__(
        self,
        chain: Chain,
        *,
        description: RobotDescription | None = None,
        source: str | None = None,
        payload: Inertial | None = None,
        calibration: Calibration | None = None,
        friction: Friction | None | object = _FROM_FILES,
        friction_note: str = "",
    ) -> None:
        self.chain = chain
        self.description = description
        self.source = source
        self.payload = payload
        self.calibration = calibration
        self._given_friction = friction
        self._given_friction_note = friction_note

    # ------------------------------------------------------------------ facts
    @property
    def name(self) -> str:
        return self.chain.name

    @property
    def n_joints(self) -> int:
        return self.chain.n_joints

    @property
    def joint_names(self) -> tuple[str, ...]:
        return self.chain.joint_names

    @property
    def lower(self) -> FloatArray:
        """Nominal lower joint limits, rad (NaN where unknown)."""
        return self.chain.lower.copy()

    @property
    def upper(self) -> FloatArray:
        return self.chain.upper.copy()

    @property
    def velocity_limit(self) -> FloatArray:
        """Maximum joint speeds, rad/s (NaN where unknown)."""
        return self.chain.velocity.copy()

    @property
    def effort_limit(self) -> FloatArray:
        """Maximum joint torques, N·m (NaN where unknown)."""
        return self.chain.effort.copy()

    @property
    def home(self) -> FloatArray:
        """Home configuration (rad): q = 0 (ABB), or mid-range for a joint whose range excludes 0."""
        lo, hi = self.chain.lower, self.chain.upper
        outside = np.isfinite(lo) & np.isfinite(hi) & ((lo > 0) | (hi < 0))
        return np.where(outside, (lo + hi) / 2, 0.0)

    def joint_ranges(self, name: str = "nominal") -> tuple[FloatArray, FloatArray]:
        """``(lower, upper)`` of a named range set (``"nominal"``, or e.g. ``"lab"``)."""
        if name == "nominal":
            return self.lower, self.upper
        if self.description is None:
            raise InvalidInput(
                f"robot {self.name!r} has only the 'nominal' range set (asked for {name!r}); "
                "use --range-set nominal"
            )
        rs = self.description.range_set(name)
        return np.array(rs.lower), np.array(rs.upper)

    def ranges_for(self, name: str) -> tuple[str, FloatArray, FloatArray]:
        """``(name used, lower, upper)`` of a range set, the nominal ranges standing in for a missing default.

        The default sets :data:`FALLBACK_RANGE_SETS` (``"lab"``, ``"collection"``) exist
        for robots with a lab description (the IRB 120); for any other robot the
        nominal ranges are used, and the name returned is ``"nominal"`` so that the
        caller can say so. Any other missing name is refused.
        """
        if name in FALLBACK_RANGE_SETS and name not in self.range_set_names:
            lower, upper = self.joint_ranges()
            return "nominal", lower, upper
        lower, upper = self.joint_ranges(name)
        return name, lower, upper

    @property
    def range_set_names(self) -> tuple[str, ...]:
        extra = tuple(rs.name for rs in self.description.range_sets) if self.description else ()
        return ("nominal", *extra)

    @cached_property
    def _friction(self) -> tuple[Friction | None, str]:
        if self._given_friction is not _FROM_FILES:
            given: Friction | None = self._given_friction  # type: ignore[assignment]
            return given, self._given_friction_note or ("given" if given is not None else "none")
        beside = None
        if self.source and Path(self.source).is_file():
            src = Path(self.source)
            beside = src.with_name(src.stem + FRICTION_SUFFIX)
            if beside.is_file():
                from_file = read_friction_file(beside, self.n_joints)
                n = self.n_joints
                check_friction(
                    self,
                    str(beside),
                    coulomb=np.broadcast_to(np.asarray(from_file.coulomb, dtype=float), (n,)),
                    viscous=np.broadcast_to(np.asarray(from_file.viscous, dtype=float), (n,)),
                )
                return from_file, f"friction file {beside}"
        if _IRB120.search(self.name) and self.n_joints == 6:
            return (
                NOMINAL_FRICTION,
                "NOMINAL_FRICTION (assumed for the IRB 120; no identified friction is public)",
            )
        where = f"no {beside.name} beside the description" if beside else "no friction file"
        return None, f"none ({where}): the physics is rigid body only"

    @property
    def friction(self) -> Friction | None:
        """The robot's joint friction, or None: rigid body only.

        From, in order: a twin's identified friction (:attr:`calibration`); the
        ``friction`` given to the constructor; a friction file
        beside the description (``ur5.urdf`` -> ``ur5.friction.toml``, see
        :func:`~joulepath.dynamics.read_friction_file`); for the IRB 120,
        :data:`~joulepath.dynamics.NOMINAL_FRICTION`. :attr:`friction_note` says which.
        """
        if self.calibration is not None:
            return self.calibration.friction
        return self._friction[0]

    @property
    def friction_note(self) -> str:
        """Where :attr:`friction` comes from, in words (shown in outputs)."""
        if self.calibration is not None:
            return f"identified (twin {self.source})"
        return self._friction[1]

    @cached_property
    def _drives(self) -> tuple[_energy.DriveModel | None, str]:
        cal = self.calibration
        if cal is not None:
            if cal.folder is not None:
                own = Path(cal.folder) / _energy.TWIN_DRIVES_FILE
                if own.is_file():
                    return _energy.read_drives_file(own, self.n_joints), f"drives file {own}"
            if cal.twin_of is not None:
                drives, note = load_robot(cal.twin_of)._drives
                return drives, f"{note}, of {cal.twin_of} (the robot this twin twins)"
            return None, "none (the twin has no drives.toml and names no robot it twins)"
        beside = None
        if self.source and Path(self.source).is_file():
            src = Path(self.source)
            beside = src.with_name(src.stem + _energy.DRIVES_SUFFIX)
            if beside.is_file():
                return _energy.read_drives_file(beside, self.n_joints), f"drives file {beside}"
            cls_file = _bundled_abb_drives(src)
            if cls_file is not None:
                cls = abb_drive_class(src.stem)
                return (
                    _energy.read_drives_file(cls_file, self.n_joints),
                    f"bundled drives file {cls_file} (the {cls} class of the ABB range)",
                )
        if self.name in NAMED_ARMS:
            bundled = preset_path("irb120").with_name(self.name + _energy.DRIVES_SUFFIX)
            if bundled.is_file():
                return _energy.read_drives_file(bundled, self.n_joints), f"bundled drives file {bundled}"
        where = f"no {beside.name} beside the description" if beside else "no drives file"
        return None, f"none ({where})"

    @property
    def drives(self) -> _energy.DriveModel | None:
        """The robot's drive data, or None (:attr:`drives_note` says where they come from, or why not).

        From, in order: a twin folder's ``drives.toml`` (else the drives of the robot it
        twins); a drives file beside the description (``ur5.urdf`` -> ``ur5.drives.toml``,
        see :func:`~joulepath.energy.read_drives_file`); for a named arm, the bundled one.
        """
        return self._drives[0]

    @property
    def drives_note(self) -> str:
        """Where :attr:`drives` come from, in words (shown with every electrical figure)."""
        return self._drives[1]

    @property
    def drivetrain(self) -> _energy.Drivetrain:
        """Gear efficiency and drives for the energy measures beyond the joint (:mod:`joulepath.energy`).

        The gear efficiency is a twin's identified one, else its drives file's, else unknown.
        """
        drives, note = self._drives
        cal = self.calibration
        if cal is not None:
            gear: tuple[float, ...] | None = (cal.gear_efficiency,) * self.n_joints
            gear_source = f"identified (twin {cal.folder or self.source})"
        elif drives is not None and drives.gear_efficiency is not None:
            gear = drives.gear_efficiency
            gear_source = f"{drives.source('gear_efficiency')} ({note})"
        else:
            gear = None
            gear_source = f"none known (drives: {note})" if drives is None else f"not in {drives.origin}"
        return _energy.Drivetrain(
            gear_efficiency=gear,
            gear_source=gear_source,
            drives=drives,
            drives_source=note if drives is None else f"{drives.describe()}",
        )

    # ------------------------------------------------------------- controller axes
    def axes_to_joints(self, axes: ArrayLike) -> FloatArray:
        """The model's serial joints (rad) for the controller's axis values (rad), shape ``(..., n)``.

        What a controller reads and writes (RAPID ``jointtarget``, its logs, EGM joint messages) are
        axis values; for an arm whose axis 3 is coupled to axis 2 (the IRB 2400's parallel
        linkage, :func:`~joulepath.description.axes_to_joints`) they differ from the joints every
        model here works in. The identity for any other arm. Convert at the boundary, only there.

        >>> load_robot("irb2400").axes_to_joints([0, 0.2, 0.3, 0, 0, 0]).round(3).tolist()
        [0.0, 0.2, 0.1, 0.0, 0.0, 0.0]
        """
        if self.description is None:
            return np.array(axes, dtype=float)
        return axes_to_joints(self.description, axes)

    def joints_to_axes(self, q: ArrayLike) -> FloatArray:
        """The controller's axis values (rad) for serial joints ``q`` (rad), the inverse map."""
        if self.description is None:
            return np.array(q, dtype=float)
        return joints_to_axes(self.description, q)

    @property
    def axes_coupled(self) -> bool:
        """Whether the controller's axis values differ from the joints (axis 3 = joint 2 + joint 3)."""
        return self.description is not None and has_axis3_coupling(self.description)

    def axis_torques_to_joints(self, tau_axes: ArrayLike) -> FloatArray:
        """The model's joint torques (N·m) for the controller's axis torques (a log's), shape ``(..., n)``.

        The transpose of :meth:`axes_to_joints`' map, so power is kept; the identity for an uncoupled arm.
        """
        if self.description is None:
            return np.array(tau_axes, dtype=float)
        return axis_torques_to_joints(self.description, tau_axes)

    def joint_torques_to_axes(self, tau: ArrayLike) -> FloatArray:
        """The controller's axis torques (N·m) for the model's joint torques (the inverse map)."""
        if self.description is None:
            return np.array(tau, dtype=float)
        return joint_torques_to_axes(self.description, tau)

    @property
    def axis3_range(self) -> tuple[float, float] | None:
        """The controller's axis-3 range (rad) of an axis-coupled arm (no joint box states it), or None."""
        return None if self.description is None else axis3_range(self.description)

    def axes_outside(self, axes: ArrayLike) -> str | None:
        """Why controller axis values ``axes`` (rad, shape ``(n,)``) are refused by a range that only
        the controller's axes have (the coupled axis 3), or None. The joints' own ranges are checked
        on :meth:`axes_to_joints` of them."""
        rng = self.axis3_range
        a = np.asarray(axes, dtype=float)
        if rng is None or a.shape[-1] < 3 or rng[0] - 1e-9 <= a[2] <= rng[1] + 1e-9:
            return None
        lo, hi = np.degrees(rng)
        return (
            f"axis 3 = {np.degrees(a[2]):.2f} deg is outside the controller's axis-3 range "
            f"[{lo:.1f}, {hi:.1f}] deg (axis 3 = joint 2 + joint 3: a parallel linkage)"
        )

    # ------------------------------------------------------------- kinematics
    def fk(self, q: ArrayLike) -> Pose:
        """Tool0 pose for ``q`` of shape ``(..., n)`` (rad)."""
        return forward_kinematics(self.chain, q)

    def jacobian(self, q: ArrayLike) -> FloatArray:
        """Geometric Jacobian at tool0 in the base frame, shape ``(..., 6, n)``."""
        return geometric_jacobian(self.chain, q)

    # --------------------------------------------------------------- dynamics
    @cached_property
    def pinocchio_model(self) -> Any:
        """The ``pinocchio.Model`` of this robot (with a ``tool0`` frame)."""
        return pinocchio_model(self.chain)

    @cached_property
    def _rnea(self) -> PinocchioRnea:
        return PinocchioRnea(self.pinocchio_model)

    def _broadcast(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray, tuple[int, ...]]:
        n = self.n_joints
        arrays = [check_q(x, n, name) for x, name in ((q, "q"), (qd, "qd"), (qdd, "qdd"))]
        try:
            shape = np.broadcast_shapes(*(a.shape for a in arrays))
        except ValueError as err:
            raise InvalidInput(
                f"q, qd and qdd have shapes {[a.shape for a in arrays]} that do not broadcast"
            ) from err
        flat = [np.broadcast_to(a, shape).reshape(-1, n) for a in arrays]
        return flat[0], flat[1], flat[2], shape

    def inverse_dynamics(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        *,
        friction: Friction | None = None,
        method: str = "pinocchio",
    ) -> FloatArray:
        """Joint torques τ(q, qd, qdd) in N·m, same batch shape as the inputs.

        Parameters
        ----------
        q, qd, qdd : array_like of shape (..., n)
            rad, rad/s, rad/s²; broadcast against each other.
        friction : Friction, optional
            Added to the rigid-body torque (see :mod:`joulepath.dynamics`).
        method : {"pinocchio", "lagrange-euler"}
            Pinocchio's RNEA (fast) or the thesis' Lagrange–Euler formulation
            (independent cross-check, slower).
        """
        qf, qdf, qddf, shape = self._broadcast(q, qd, qdd)
        if method == "pinocchio":
            tau = self._rnea(qf, qdf, qddf)
        elif method == "lagrange-euler":
            tau = lagrange_euler(self.chain, qf, qdf, qddf)
        else:
            raise InvalidInput(f"method must be one of {METHODS}, got {method!r}")
        if friction is not None:
            tau = tau + friction.torque(qdf)
        return tau.reshape(shape)

    def mass_matrix(self, q: ArrayLike) -> FloatArray:
        """Joint-space inertia matrix D(q), shape ``(..., n, n)`` (Lagrange–Euler eq. 2.20)."""
        qa = check_q(q, self.n_joints)
        flat = qa.reshape(-1, self.n_joints)
        return mass_matrix_le(self.chain, flat).reshape(qa.shape + (self.n_joints,))

    def gravity_torque(self, q: ArrayLike) -> FloatArray:
        """Static holding torques at rest, N·m, shape ``(..., n)``."""
        qa = check_q(q, self.n_joints)
        zero = np.zeros_like(qa)
        return self.inverse_dynamics(qa, zero, zero)

    def joint_energy(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        dt: float | ArrayLike,
        *,
        friction: Friction | None = None,
        mode: str = "absolute",
        copper_loss: float | ArrayLike | None = None,
    ) -> FloatArray:
        """Per-sample, per-joint energy (J) of sampled motion: see :func:`joulepath.energy.joint_energy`."""
        tau = self.inverse_dynamics(q, qd, qdd, friction=friction)
        return _energy.joint_energy(tau, np.asarray(qd, float), dt, mode=mode, copper_loss=copper_loss)

    def path_energy(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        dt: float | ArrayLike,
        *,
        friction: Friction | None = None,
        mode: str = "absolute",
        copper_loss: float | ArrayLike | None = None,
    ) -> _energy.PathEnergy:
        """Energy of sampled paths ``(..., n_steps, n)``: per joint and total, summed over time."""
        tau = self.inverse_dynamics(q, qd, qdd, friction=friction)
        return _energy.path_energy(tau, np.asarray(qd, float), dt, mode=mode, copper_loss=copper_loss)

    # ---------------------------------------------------------------- payload
    @property
    def rated_payload_kg(self) -> float | None:
        """The heaviest load the maker rates the arm for (kg), if known.

        From the IRML ``<carrying-capacity>``, else a named arm's data sheet
        (:data:`~joulepath.description.NAMED_ARMS`); None when neither says.
        """
        if self.description is not None:
            rated = self.description.info_float("carrying-capacity")
            if rated is not None and rated > 0:
                return float(rated)
        arm = NAMED_ARMS.get(self.name)
        if arm is not None and arm.payload_kg is not None and (self.source or "").endswith(arm.urdf):
            return arm.payload_kg
        return None

    def check_payload(self, mass: float, *, what: str = "payload", over_rated: bool = False) -> None:
        """Refuse a load the arm cannot carry: above its :attr:`rated_payload_kg` (with
        ``over_rated``, as a controller runs a program's load: above :data:`OVERLOAD_FACTOR` times
        it), or, when no rating is known, heavier than the arm's own moving links.

        Raises
        ------
        InvalidInput
            ``mass`` is not a finite number ≥ 0, or is above the bound; the message names it.
        """
        if not (np.isfinite(mass) and mass >= 0):
            raise InvalidInput(f"{what}: mass {mass!r} kg is not a finite number ≥ 0")
        rated = self.rated_payload_kg
        if rated is not None and over_rated and mass > OVERLOAD_FACTOR * rated:
            raise InvalidInput(
                f"{what}: {mass:g} kg is more than {OVERLOAD_FACTOR:g} times the {self.name}'s rated "
                f"payload of {rated:g} kg: probably a program for a larger arm; give it with --robot"
            )
        if rated is not None and not over_rated and mass > rated:
            raise InvalidInput(
                f"{what}: {mass:g} kg is more than the {self.name}'s rated payload of {rated:g} kg; "
                "check the mass (kg), or use an arm rated for it"
            )
        own = float(np.sum(self.chain.masses))
        if rated is None and mass > own:
            raise InvalidInput(
                f"{what}: {mass:g} kg is heavier than the {self.name}'s own moving links ({own:.3g} kg) and "
                "no rated payload is known for it; check the mass (kg), or give the robot's "
                "<carrying-capacity> in its IRML"
            )

    def over_rated_note(self, mass: float, what: str = "payload") -> str | None:
        """The line a result carries when ``mass`` (kg) is above the rated payload (None: it is not)."""
        rated = self.rated_payload_kg
        if rated is None or mass <= rated:
            return None
        return (
            f"{what}: {mass:g} kg, above the {self.name}'s rated payload of {rated:g} kg: run as the "
            "controller runs it (its load diagram and motion supervision may slow or stop it); the "
            "saving is stated on this load"
        )

    def with_payload(
        self,
        mass: float,
        com: ArrayLike = (0.0, 0.0, 0.0),
        inertia: ArrayLike | None = None,
        *,
        what: str = "payload",
        over_rated: bool = False,
    ) -> Robot:
        """A copy of this robot carrying a payload at tool0.

        Parameters
        ----------
        mass : float
            kg (ABB ``loaddata.mass``).
        com : array_like of shape (3,)
            Centre of mass in the tool0 frame, m (ABB ``loaddata.cog``, in mm there).
        inertia : array_like of shape (3, 3) or (3,), optional
            About the centre of mass, tool0 axes, kg·m²; a 3-vector is the diagonal
            (ABB ``ix, iy, iz``). Default: a point mass.
        what : str
            How a refusal names the load (e.g. ``"tool tGripper"``).
        over_rated : bool
            Carry a load above the rated payload, up to :data:`OVERLOAD_FACTOR` times it, as a
            controller runs a program's ``loaddata`` (:meth:`over_rated_note` says so).

        Raises
        ------
        InvalidInput
            A negative or non-finite mass, a mass above the arm's rating (:meth:`check_payload`),
            or an inertia that is not physical.
        """
        self.check_payload(float(mass), what=what, over_rated=over_rated)
        inertia_arr = np.zeros((3, 3)) if inertia is None else np.asarray(inertia, dtype=float)
        if inertia_arr.shape == (3,):
            inertia_arr = np.diag(inertia_arr)
        load = Inertial.from_arrays(mass, com, inertia_arr)
        problems = [f for f in check_inertial("payload", load) if f.severity == "error"]
        if mass < 0 or (mass > 0 and inertia is not None and problems):
            raise InvalidInput("; ".join(str(p) for p in problems) or "payload mass must be ≥ 0")
        if self.description is not None:
            chain = replace(
                chain_from_description(self.description, payload=load), armature=self.chain.armature
            )
        else:
            from joulepath.description import combine_inertials, transform_inertial

            base = Inertial.from_arrays(self.chain.masses[-1], self.chain.coms[-1], self.chain.inertias[-1])
            last = combine_inertials(base, transform_inertial(load, self.chain.tool))
            masses = self.chain.masses.copy()
            coms = self.chain.coms.copy()
            inertias = self.chain.inertias.copy()
            masses[-1], coms[-1], inertias[-1] = last.mass, last.com_array, last.inertia_array
            chain = replace(self.chain, masses=masses, coms=coms, inertias=inertias)
        return Robot(
            chain,
            description=self.description,
            source=self.source,
            payload=load,
            calibration=self.calibration,
            friction=self._given_friction,
            friction_note=self._given_friction_note,
        )

    # ----------------------------------------------------------------- checks
    def check_physical(self) -> list[Finding]:
        """Everything not physical about this robot's description (errors first).

        IRML robots are checked on their description (:func:`~joulepath.description.check_physical`),
        other robots on their chain (mass properties, joint axes, limits).
        """
        if self.description is not None:
            return check_physical(self.description)
        return check_chain(self.chain)

    def summary(self) -> str:
        """A few lines describing the robot (used by ``joulepath robot show``)."""
        lines = [f"{self.name}  ({self.n_joints} revolute joints, source: {self.source})"]
        if self.description is not None and self.description.manufacturer:
            lines[0] = f"{self.description.manufacturer} " + lines[0]
        lines.append("joint        lower°    upper°   speed°/s  torque N·m   mass kg")
        for i, name in enumerate(self.joint_names):
            lo, hi, v = np.degrees([self.chain.lower[i], self.chain.upper[i], self.chain.velocity[i]])
            e = self.chain.effort[i]
            torque = f"{e:10.1f}" if np.isfinite(e) else f"{'not given':>10}"
            lines.append(f"{name:<10} {lo:8.1f}  {hi:8.1f}  {v:8.1f}  {torque}  {self.chain.masses[i]:8.3f}")
        lines.append(f"moving mass {self.chain.masses.sum():.3f} kg")
        if self.payload is not None:
            lines.append(f"payload {self.payload.mass:.3f} kg at {self.payload.com} m (tool0)")
        if self.rated_payload_kg is not None:
            lines.append(f"rated payload {self.rated_payload_kg:g} kg")
        if len(self.range_set_names) > 1:
            lines.append("range sets: " + ", ".join(self.range_set_names))
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"Robot(name={self.name!r}, n_joints={self.n_joints}, source={self.source!r})"


def load_robot(
    name_or_path: str | os.PathLike[str],
    *,
    tool_frame: str | None = None,
    checked: bool = True,
    lock: dict[str, float] | None = None,
) -> Robot:
    """Load a bundled robot (``"irb120"``), a named arm, a robot file (``.irml``, ``.urdf``) or a twin folder.

    Named arms (``"ur3"``, ``"ur5"``, ``"ur10"``, ``"panda"``, ``"xarm7"``, ...,
    :data:`~joulepath.description.NAMED_ARMS`) are URDFs of the ``example-robot-data``
    package (``pip install 'joulepath[robots]'``), with their grippers locked.
    A twin folder (written by ``joulepath identify``) gives its identified robot with
    its identified friction and drive losses (:attr:`Robot.calibration`).

    The robot is checked on load (:meth:`Robot.check_physical`): a description with
    an error (a non-positive mass, an inertia that is not positive definite or breaks
    the triangle inequality, a zero joint axis, a joint without a range or a speed
    limit, ...) is refused. Warnings (e.g. no torque limits) are not.

    Parameters
    ----------
    name_or_path : str or path
        A bundled robot's name or a robot file.
    tool_frame : str, optional
        URDF only: the frame used as tool0.
    lock : dict of str to float, optional
        URDF only: joints fixed at these values (rad; m for a prismatic joint) before
        the arm is read, e.g. a gripper's fingers (added to a named arm's own locks).
    checked : bool, default True
        For experts: ``False`` loads a robot that fails the physical check (to
        inspect it, as ``joulepath robot show`` does); its dynamics may be
        meaningless or fail inside Pinocchio.

    Raises
    ------
    InvalidRobotDescription
        Unknown name, unreadable or invalid file, unsupported extension, or (when
        ``checked``) a description that fails the physical check; the message
        names the first error found.

    Examples
    --------
    >>> load_robot("irb120").n_joints
    6
    """
    text = os.fspath(name_or_path)
    if text in NAMED_ARMS:
        arm = NAMED_ARMS[text]
        path = named_arm_path(text)
        chain = chain_from_urdf(path, tool_frame=tool_frame, lock={**arm.lock, **(lock or {})}, name=text)
        robot = Robot(chain, source=str(path))
        if checked:
            _refuse_unphysical(robot, text)
        return robot
    if text not in PRESETS and Path(text).is_dir():
        return _load_twin(Path(text), checked=checked)
    if text in PRESETS:
        path = preset_path(text)
    else:
        path = Path(text)
        if not path.exists():
            raise InvalidRobotDescription(
                f"{text}: no such file and not a bundled robot (bundled: {', '.join(PRESETS)}; "
                f"named arms with the [robots] extra: {', '.join(NAMED_ARMS)})"
            )
    suffix = path.suffix.lower()
    if lock and suffix != ".urdf":
        raise InvalidRobotDescription(f"{path}: joints can be locked in a URDF only; remove the lock")
    if suffix in (".irml", ".xml"):
        desc = read_irml(path)
        robot = Robot(chain_from_description(desc), description=desc, source=str(path))
    elif suffix == ".urdf":
        robot = Robot(chain_from_urdf(path, tool_frame=tool_frame, lock=lock), source=str(path))
    else:
        raise InvalidRobotDescription(f"{path}: unknown robot file type {suffix!r}; use .irml or .urdf")
    if checked:
        _refuse_unphysical(robot, text)
        _ = robot.friction  # a friction file beside the description is read (and checked) now
    return robot


def _load_twin(folder: Path, *, checked: bool) -> Robot:
    """A twin folder (``joulepath identify --out``): its robot with its identified friction, drive
    losses and armature (:attr:`Calibration.armature`, set as the chain's :attr:`Chain.armature`)."""
    robot_file, friction_file = twin_paths(folder)
    robot = load_robot(robot_file, checked=checked)
    calibration = read_calibration(friction_file, robot.n_joints)
    f = calibration.friction
    check_friction(
        robot,
        str(friction_file),
        coulomb=np.array(f.coulomb),
        viscous=np.array(f.viscous),
        offset=np.array(f.offset),
        stribeck=np.array(f.stribeck),
    )
    _check_twin_of(robot, calibration.twin_of, str(friction_file))
    if calibration.armature:
        # the drives' identified armature (friction file) joins the chain: every dynamics uses it
        twin = Robot(
            replace(robot.chain, armature=np.array(calibration.armature)),
            description=robot.description,
            source=robot.source,
            calibration=calibration,
        )  # read_calibration refused a negative armature
        return twin
    robot.calibration = calibration
    return robot


def friction_bound(robot: Robot) -> float:
    """The largest plausible friction torque of a joint of ``robot`` (N·m), see :data:`FRICTION_BOUND`.

    The reach is the IRML ``<reach>`` or tool0's distance from the base at home,
    whichever is larger (at least 0.1 m).
    """
    reach = float(np.linalg.norm(robot.fk(robot.home).position_m))
    if robot.description is not None:
        reach = max(reach, robot.description.info_float("reach") or 0.0)
    weight = float(np.sum(robot.chain.masses)) * float(np.linalg.norm(robot.chain.gravity))
    return FRICTION_BOUND * max(weight, 1.0) * max(reach, 0.1)


def check_friction(
    robot: Robot,
    where: str,
    *,
    coulomb: FloatArray,
    viscous: FloatArray,
    offset: FloatArray | None = None,
    stribeck: FloatArray | None = None,
) -> None:
    """Refuse friction that no drive has: a negative Coulomb, viscous or Stribeck level (friction
    opposes motion), or a torque over :func:`friction_bound` (the break-away level, or the viscous
    torque at the joint's speed limit, 10 rad/s where none is given). ``offset`` may be negative
    (a direction asymmetry) but counts in the break-away level.

    Raises
    ------
    InvalidRobotDescription
        The first joint and term that fail, and the bound.
    """
    n = robot.n_joints
    zero = np.zeros(n)
    terms = {"coulomb": coulomb, "viscous": viscous, "stribeck": zero if stribeck is None else stribeck}
    for name, values in terms.items():
        bad = np.nonzero(~(np.asarray(values, dtype=float) >= 0))[0]
        if bad.size:
            j = int(bad[0])
            raise InvalidRobotDescription(
                f"{where}: {name} friction of joint {j + 1} is {float(values[j]):g}; friction opposes "
                "motion, so it must be ≥ 0: identify the friction again"
            )
    bound = friction_bound(robot)
    offsets = zero if offset is None else np.abs(np.asarray(offset, dtype=float))
    breakaway = np.asarray(coulomb, float) + offsets + np.asarray(terms["stribeck"], float)
    speed = np.where(np.isfinite(robot.velocity_limit), robot.velocity_limit, 10.0)
    viscous_torque = np.asarray(viscous, float) * speed
    for label, torque in (
        ("break-away (coulomb + |offset| + stribeck)", breakaway),
        ("viscous", viscous_torque),
    ):
        over = np.nonzero(~(torque <= bound))[0]
        if over.size:
            j = int(over[0])
            raise InvalidRobotDescription(
                f"{where}: the {label} friction torque of joint {j + 1} is {float(torque[j]):.3g} N·m, over "
                f"{bound:.3g} N·m ({FRICTION_BOUND:g} times the arm's whole weight at its reach): not a "
                "plausible friction; identify the friction again"
            )


def _probe_configurations(robot: Robot) -> FloatArray:
    """Home and three spread configurations within the joint ranges (±1 rad where a range is open)."""
    lo = np.where(np.isfinite(robot.lower), robot.lower, -1.0)
    hi = np.where(np.isfinite(robot.upper), robot.upper, 1.0)
    j = np.arange(robot.n_joints)
    fractions = [0.2 + 0.6 * (((3 * j + 7 * k) % 10) / 9.0) for k in range(3)]
    return np.vstack([robot.home, *(lo + (hi - lo) * f for f in fractions)])


def _check_twin_of(robot: Robot, twin_of: str | None, where: str) -> None:
    """Refuse a twin whose ``twin_of`` names a robot of other kinematics (or one that cannot be loaded)."""
    if twin_of is None:
        return
    fix = "set twin_of to the robot the twin was identified on, or identify the twin again"
    if twin_of not in PRESETS and twin_of not in NAMED_ARMS and Path(twin_of).is_dir():
        raise InvalidRobotDescription(
            f"{where}: twin_of = {twin_of!r} is a folder; a twin is the twin of a robot (a bundled name or "
            f"a robot file), never of another twin folder: {fix}"
        )
    from joulepath.errors import JoulepathError

    try:
        nominal = load_robot(twin_of, checked=False)
    except JoulepathError as err:
        raise InvalidRobotDescription(
            f"{where}: twin_of = {twin_of!r} cannot be loaded ({err}); {fix}"
        ) from err
    if nominal.n_joints != robot.n_joints:
        raise InvalidRobotDescription(
            f"{where}: twin_of = {twin_of!r} has {nominal.n_joints} joints, the twin {robot.n_joints}: {fix}"
        )
    qs = _probe_configurations(robot)
    gap_mm = 1000.0 * np.linalg.norm(nominal.fk(qs).position_m - robot.fk(qs).position_m, axis=-1)
    if not np.all(gap_mm <= TWIN_KINEMATICS_TOLERANCE_MM):
        k = int(np.argmax(np.where(np.isfinite(gap_mm), gap_mm, np.inf)))
        raise InvalidRobotDescription(
            f"{where}: twin_of = {twin_of!r}, but the twin's kinematics are not that robot's: tool0 lies "
            f"{gap_mm[k]:.0f} mm apart at q = [{', '.join(f'{v:.2f}' for v in qs[k])}] rad: {fix}"
        )


def _refuse_unphysical(robot: Robot, given: str) -> None:
    """Raise InvalidRobotDescription naming the first error of the physical check, if any."""
    errors = [f for f in robot.check_physical() if f.severity == "error"]
    if not errors:
        return
    more = f" (and {len(errors) - 1} more error(s))" if len(errors) > 1 else ""
    raise InvalidRobotDescription(
        f"{robot.source}: fails the physical check: {errors[0].where}: {errors[0].message}{more}; "
        f"fix the description (`joulepath robot show {given}` lists every finding) or, for experts "
        "only, use it unchecked (load_robot(..., checked=False), --unchecked on the command line)"
    )


__all__ = ["DEFAULT_ROBOT", "HOME", "METHODS", "Robot", "load_robot"]
