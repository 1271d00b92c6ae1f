"""The energy table: one schema that every later stage imports.

A table has one row per log sample. Columns, in this order:

* ``move_id`` (int64) — the move the row belongs to (unique within the table);
* ``t`` (float64, s) — time since the start of the log;
* the model inputs of the feature set (float64, SI units):

  - ``full40`` — the 40 inputs of thesis Appendix F, in its order:
    ``q1, dq1, ..., q6, dq6`` (rad, rad/s); ``x, y, z`` (TCP, m);
    ``qx, qy, qz, qw`` (TCP orientation quaternion); ``yaw, pitch, roll``
    (RAPID EulerZYX about Z, Y, X, rad); ``ddq1..ddq6`` (rad/s²);
    ``dx, dy, dz`` (m/s); ``dphi, dtheta, dpsi`` (rates of yaw, pitch, roll, rad/s);
    ``ddx, ddy, ddz`` (m/s²); ``ddphi, ddtheta, ddpsi`` (rad/s²);
  - ``joint`` — for logs of arms whose kinematics is unknown: ``q1, dq1, ..., q6,
    dq6, ddq1..ddq6`` (18 inputs);

* the targets (float64, J): ``E1 .. E6`` with ``E_i = |tau_i * dq_i| * dt`` and
  their sum ``E``; ``dt`` is the row's sample length (s).

That is a 6-joint arm's table. An arm of ``n`` joints (5 to 7) has the same columns
with ``i = 1..n`` (:func:`feature_columns`, :func:`target_columns`,
:func:`table_columns`): ``full40`` then holds ``3 n + 22`` inputs; the name stays
the thesis' ("the full feature set of Appendix F"). The table's metadata stores
``n_joints``.

Derivatives are finite differences of the logged signals within each move, as the
thesis computed them. The feature set, robot and units are stored in the Parquet
file's metadata (:data:`METADATA_KEY`).
"""

from __future__ import annotations

N_JOINTS = 6

LOG_COLUMNS: tuple[str, ...] = (
    "t",
    *(f"{p}{i}" for i in range(1, N_JOINTS + 1) for p in ("q", "dq", "tau")),
    "x",
    "y",
    "z",
    "e1",
    "e2",
    "e3",
    "e4",
    "psi",
    "theta",
    "phi",
)
"""Columns of the controller log of thesis Appendix D.2 (deg, deg/s, N·m, mm, quaternion, deg)."""

GENERIC_REQUIRED: tuple[str, ...] = (
    "t",
    *(f"{p}{i}" for i in range(1, N_JOINTS + 1) for p in ("q", "dq", "tau")),
)
"""Required columns of the generic joint log (s, rad, rad/s, N·m); optional ``ddq{i}`` and ``move``."""

MOVES_SIDECAR_COLUMNS: tuple[str, ...] = ("move", "t_start", "t_end", "speed", "zone")
"""First columns of the ``<log>.moves.csv`` sidecar with the programmed moves that
``joulepath simulate`` writes beside each log (then ``j1_deg``, ``j2_deg``, ...): not a log."""

MOVES_SIDECAR_SUFFIX = ".moves.csv"
"""Name ending of that sidecar: ``lab.csv`` -> ``lab.moves.csv``."""

JOINT_STATE = tuple(f"{p}{i}" for i in range(1, N_JOINTS + 1) for p in ("q", "dq"))
JOINT_ACC = tuple(f"ddq{i}" for i in range(1, N_JOINTS + 1))

FEATURES_FULL: tuple[str, ...] = (
    *JOINT_STATE,
    "x",
    "y",
    "z",
    "qx",
    "qy",
    "qz",
    "qw",
    "yaw",
    "pitch",
    "roll",
    *JOINT_ACC,
    "dx",
    "dy",
    "dz",
    "dphi",
    "dtheta",
    "dpsi",
    "ddx",
    "ddy",
    "ddz",
    "ddphi",
    "ddtheta",
    "ddpsi",
)
"""The 40 model inputs of thesis Appendix F, in its order."""

FEATURES_JOINT: tuple[str, ...] = (*JOINT_STATE, *JOINT_ACC)
"""The joint-only feature set (18 inputs)."""

FEATURE_SETS = {"full40": FEATURES_FULL, "joint": FEATURES_JOINT}

TARGETS: tuple[str, ...] = (*(f"E{i}" for i in range(1, N_JOINTS + 1)), "E")
"""Per-joint energies and their sum, J."""

META: tuple[str, ...] = ("move_id", "t")

METADATA_KEY = b"joulepath"
"""Key of the JSON metadata in the Parquet schema (feature_set, robot, units, sources)."""

SCHEMA_VERSION = 1


MIN_JOINTS, MAX_JOINTS = 5, 7
"""Joint counts of the arms an energy table may hold."""


def feature_columns(feature_set: str, n_joints: int = N_JOINTS) -> tuple[str, ...]:
    """The model inputs of ``feature_set`` for an arm of ``n_joints`` joints, in order."""
    state = tuple(f"{p}{i}" for i in range(1, n_joints + 1) for p in ("q", "dq"))
    acc = tuple(f"ddq{i}" for i in range(1, n_joints + 1))
    if feature_set == "joint":
        return (*state, *acc)
    tcp = FEATURES_FULL[len(JOINT_STATE) : FEATURES_FULL.index(JOINT_ACC[0])]
    rates = FEATURES_FULL[FEATURES_FULL.index(JOINT_ACC[-1]) + 1 :]
    return (*state, *tcp, *acc, *rates)


def target_columns(n_joints: int = N_JOINTS) -> tuple[str, ...]:
    """``E1 .. En`` and ``E`` (J)."""
    return (*(f"E{i}" for i in range(1, n_joints + 1)), "E")


def table_columns(feature_set: str, n_joints: int = N_JOINTS) -> tuple[str, ...]:
    """All columns of a table holding ``feature_set`` for an arm of ``n_joints`` joints, in order."""
    return (*META, *feature_columns(feature_set, n_joints), *target_columns(n_joints), "dt")


def generic_required(n_joints: int = N_JOINTS) -> tuple[str, ...]:
    """Required columns of a generic joint log of ``n_joints`` joints."""
    return ("t", *(f"{p}{i}" for i in range(1, n_joints + 1) for p in ("q", "dq", "tau")))


def card_joints(columns: object) -> int:
    """Joints of a list of model input columns: :func:`joints_in`, or 6 when that is not 5..7."""
    n = joints_in(columns)
    return n if MIN_JOINTS <= n <= MAX_JOINTS else N_JOINTS


def joints_in(columns: object) -> int:
    """Number of joints whose ``q{i}`` columns are among ``columns`` (1, 2, ... without a hole)."""
    names = set(map(str, columns))  # type: ignore[call-overload]
    n = 0
    while f"q{n + 1}" in names:
        n += 1
    return n
