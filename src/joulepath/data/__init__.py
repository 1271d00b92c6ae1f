"""Data: joint logs (controller and generic), the energy-table schema, ingestion."""

from joulepath.data._features import REST_SPEED, find_gaps, segment_moves, tcp_columns
from joulepath.data._logs import (
    JointLog,
    controller_log_text,
    generic_log_text,
    is_moves_sidecar,
    moves_sidecar_path,
    read_log,
    write_controller_log,
)
from joulepath.data._schema import (
    FEATURE_SETS,
    FEATURES_FULL,
    FEATURES_JOINT,
    GENERIC_REQUIRED,
    LOG_COLUMNS,
    MAX_JOINTS,
    MOVES_SIDECAR_COLUMNS,
    TARGETS,
    card_joints,
    feature_columns,
    generic_required,
    joints_in,
    table_columns,
    target_columns,
)
from joulepath.data._table import EnergyTable, check_columns, ingest, load_table, save_table
from joulepath.data._table import _check_limits as check_limits

__all__ = [
    "EnergyTable",
    "FEATURES_FULL",
    "FEATURES_JOINT",
    "FEATURE_SETS",
    "GENERIC_REQUIRED",
    "JointLog",
    "LOG_COLUMNS",
    "MAX_JOINTS",
    "MOVES_SIDECAR_COLUMNS",
    "REST_SPEED",
    "TARGETS",
    "card_joints",
    "check_columns",
    "check_limits",
    "controller_log_text",
    "feature_columns",
    "find_gaps",
    "generic_log_text",
    "generic_required",
    "ingest",
    "is_moves_sidecar",
    "joints_in",
    "load_table",
    "moves_sidecar_path",
    "read_log",
    "save_table",
    "segment_moves",
    "table_columns",
    "target_columns",
    "tcp_columns",
    "write_controller_log",
]
