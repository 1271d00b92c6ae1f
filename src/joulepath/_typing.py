"""Array aliases used across joulepath (foundation: imports nothing of ours)."""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
import numpy.typing as npt

FloatArray: TypeAlias = npt.NDArray[np.float64]
"""A float64 array; the docstring of each function states its shape."""

ArrayLike: TypeAlias = npt.ArrayLike
