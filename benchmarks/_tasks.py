"""The named single moves the benchmarks share: the fixed task and the README's move (radians, s)."""

from __future__ import annotations

import numpy as np

NAMED_TASKS = [
    (
        "fixed task",
        np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0]),
        np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5]),
        1.6,
    ),
    ("README move", np.radians([-60, 10, -30, 40, 20, 0]), np.radians([70, 30, 10, -50, -40, 90]), 1.5),
]
