"""Robot descriptions as immutable values.

Two levels:

* :class:`RobotDescription` mirrors an IRML file: general information, one
  :class:`JointDescription` per joint with its Denavit–Hartenberg parameters
  (standard DH, ``T_i = Rz(theta_i) Tz(d_i) Tx(r_i) Rx(alpha_i)``, ``theta_i =
  sign_i * q_i + offset_i``), the link's :class:`Inertial` and its limits, named
  joint-range sets and an optional payload.
* :class:`Chain` is the generic serial chain every robot (IRML or URDF) is turned
  into: per joint a fixed placement relative to the previous joint frame, a unit
  rotation axis, and the link's inertial parameters in the joint frame. Kinematics
  and dynamics work on a Chain only.

IRML frame convention (ours; the thesis' Appendix C used world coordinates at the
zero pose, see :func:`joulepath.description.check_physical`): ``<center>`` is the
link's centre of mass in the link's DH frame ``i`` (the frame at the end of link
``i``), in m; ``<inertia>`` is the 3x3 inertia tensor about that centre of mass,
axes parallel to DH frame ``i``, in kg·m², written entry by entry (``xy`` is row x,
column y, i.e. ``-∫xy dm``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from joulepath._typing import FloatArray

Vec3 = tuple[float, float, float]
Mat3 = tuple[Vec3, Vec3, Vec3]

JOINT_TYPES = {"T": "torsion (revolute)", "R": "rotational (revolute)", "L": "linear (prismatic)"}


@dataclass(frozen=True, slots=True, kw_only=True)
class Inertial:
    """Mass properties of one rigid body.

    Parameters
    ----------
    mass : float
        kg.
    com : tuple of 3 float
        Centre of mass in the body frame, m.
    inertia : 3x3 tuple
        Inertia tensor about the centre of mass, axes of the body frame, kg·m².
    """

    mass: float
    com: Vec3 = (0.0, 0.0, 0.0)
    inertia: Mat3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))

    @property
    def com_array(self) -> FloatArray:
        return np.array(self.com, dtype=float)

    @property
    def inertia_array(self) -> FloatArray:
        return np.array(self.inertia, dtype=float)

    @classmethod
    def from_arrays(cls, mass: float, com: object, inertia: object) -> Inertial:
        c = np.asarray(com, dtype=float).reshape(3)
        i = np.asarray(inertia, dtype=float).reshape(3, 3)
        return cls(
            mass=float(mass),
            com=(float(c[0]), float(c[1]), float(c[2])),
            inertia=tuple(tuple(float(x) for x in row) for row in i),  # type: ignore[arg-type]
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class JointDescription:
    """One joint of an IRML robot and the link it moves.

    ``theta = sign * q + offset`` for a revolute joint; ``r`` is the DH link
    length (IRML writes it ``r``) and ``alpha`` the DH twist (IRML ``a``).
    Limits are in rad, rad/s and N·m; None when the file does not give them.
    """

    id: int
    type: str
    xi: int
    variable: str
    sign: float = 1.0
    offset: float = 0.0
    d: float = 0.0
    r: float = 0.0
    alpha: float = 0.0
    inertial: Inertial
    lower: float | None = None
    upper: float | None = None
    velocity: float | None = None
    effort: float | None = None

    @property
    def is_revolute(self) -> bool:
        return self.type in ("T", "R")


@dataclass(frozen=True, slots=True, kw_only=True)
class RangeSet:
    """A named set of joint ranges (rad), e.g. the lab cell's ranges of thesis Table 3.1."""

    name: str
    lower: tuple[float, ...]
    upper: tuple[float, ...]


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotDescription:
    """Everything an IRML file says about a robot."""

    name: str
    manufacturer: str = ""
    info: tuple[tuple[str, str], ...] = ()
    joints: tuple[JointDescription, ...]
    base: Inertial | None = None
    payload: Inertial | None = None
    range_sets: tuple[RangeSet, ...] = ()
    source: str | None = field(default=None, compare=False)

    def info_value(self, key: str) -> str | None:
        """Text of a general-information entry (``"reach"``, ``"ambient/maximal-humidity"``)."""
        for k, v in self.info:
            if k == key:
                return v
        return None

    def info_float(self, key: str) -> float | None:
        text = self.info_value(key)
        if text is None:
            return None
        try:
            return float(text)
        except ValueError:
            return None

    @property
    def spec_mass_kg(self) -> float | None:
        """The manipulator mass the data sheet gives (``<manipulator-mass>``)."""
        return self.info_float("manipulator-mass")

    @property
    def reach_m(self) -> float | None:
        return self.info_float("reach")

    def range_set(self, name: str) -> RangeSet:
        for rs in self.range_sets:
            if rs.name == name:
                return rs
        known = ", ".join(["nominal", *(rs.name for rs in self.range_sets)])
        from joulepath.errors import InvalidInput

        raise InvalidInput(f"robot {self.name!r} has no range set {name!r}; known: {known}")


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Chain:
    """A serial chain of revolute joints, ready for kinematics and dynamics.

    Joint frame ``i`` at configuration ``q`` is
    ``F_i = F_{i-1} @ placements[i] @ Rot(axes[i], q[i])`` with ``F_0 = I``; link
    ``i``'s mass properties are given in ``F_i``; the tool frame (ABB ``tool0``) is
    ``F_n @ tool``.

    Attributes
    ----------
    placements : ndarray of shape (n, 4, 4)
    axes : ndarray of shape (n, 3)
        Unit rotation axes in the joint frames.
    masses : ndarray of shape (n,)
    coms : ndarray of shape (n, 3)
    inertias : ndarray of shape (n, 3, 3)
        About the centre of mass, joint-frame axes.
    tool : ndarray of shape (4, 4)
    lower, upper, velocity, effort : ndarray of shape (n,)
        rad, rad/s, N·m; NaN where unknown.
    armature : ndarray of shape (n,) or None
        kg·m², per joint: the drive's rotating inertia reflected to the joint, ``J_rotor *
        ratio²`` (motor rotor and gear input side), which adds ``armature[i] * qdd[i]`` to the
        torque of joint ``i`` and ``armature[i]`` to the mass matrix's diagonal (Pinocchio's
        ``model.armature``). It is the one definition of the quantity: every dynamics of the chain
        (RNEA, Lagrange–Euler, mass matrix, forward dynamics) and identification use it. None: no
        armature (zero), as for a description that gives none (URDF and IRML do not).
    """

    name: str
    joint_names: tuple[str, ...]
    placements: FloatArray
    axes: FloatArray
    masses: FloatArray
    coms: FloatArray
    inertias: FloatArray
    tool: FloatArray
    lower: FloatArray
    upper: FloatArray
    velocity: FloatArray
    effort: FloatArray
    gravity: FloatArray = field(default_factory=lambda: np.array([0.0, 0.0, -9.80665]))
    notes: tuple[tuple[str, str], ...] = ()
    """``(where, message)`` warnings from reading the description (e.g. a joint named like a gripper)."""
    armature: FloatArray | None = None

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    @property
    def joint_armature(self) -> FloatArray:
        """:attr:`armature` as an array of ``n`` values (zeros where none is given), kg·m²."""
        if self.armature is None:
            return np.zeros(self.n_joints)
        return np.asarray(self.armature, dtype=float).copy()
