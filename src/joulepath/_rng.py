"""The one place where seeds become random generators (foundation)."""

from __future__ import annotations

import numpy as np


def check_rng(seed: int | np.random.Generator | None) -> np.random.Generator:
    """Turn a seed or a Generator into a ``numpy.random.Generator``.

    Parameters
    ----------
    seed : int, Generator or None
        An integer seed, an existing Generator (returned unchanged) or None
        (fresh entropy from the operating system).

    Returns
    -------
    Generator

    Raises
    ------
    TypeError
        For anything else (a float, a legacy ``RandomState``, ...).

    Examples
    --------
    >>> bool(check_rng(3).integers(10) == check_rng(3).integers(10))
    True
    """
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is None or (isinstance(seed, (int, np.integer)) and not isinstance(seed, bool)):
        return np.random.default_rng(seed)
    raise TypeError(f"seed must be an int, a numpy.random.Generator or None, got {type(seed).__name__}")


def integer_seed(rng: np.random.Generator) -> int:
    """Draw a plain integer seed for a library that wants one (scikit-learn, XGBoost)."""
    return int(rng.integers(2**31 - 1))
