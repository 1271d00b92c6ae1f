"""Programs that leave the tool: RAPID modules for the ABB controller, and the moves they run."""

from joulepath.export._excitation import excitation_module
from joulepath.export._moves import Move, draw_moves, random_moves
from joulepath.export._rapid import (
    MODES,
    collection_module,
    collection_programs,
    measurement_module,
    path_module,
)

__all__ = [
    "MODES",
    "Move",
    "collection_module",
    "collection_programs",
    "draw_moves",
    "excitation_module",
    "measurement_module",
    "path_module",
    "random_moves",
]
