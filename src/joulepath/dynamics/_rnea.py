"""Inverse dynamics by Pinocchio's recursive Newton–Euler algorithm, batched.

The batch is handed to ``pinocchio.rneaInParallel`` in one call (one thread by
default), so a population of paths costs one C++ loop, not a Python loop.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from joulepath._typing import FloatArray


class PinocchioRnea:
    """Batched RNEA over one Pinocchio model; a pool of model/data per thread."""

    def __init__(self, model: Any) -> None:
        self.model = model
        self._local = threading.local()

    def _pool(self) -> Any:
        pool = getattr(self._local, "pool", None)
        if pool is None:
            import pinocchio as pin

            pool = pin.ModelPool(self.model, 1)
            self._local.pool = pool
        return pool

    def __call__(self, q: FloatArray, qd: FloatArray, qdd: FloatArray, *, n_threads: int = 1) -> FloatArray:
        """Torques for ``q, qd, qdd`` of shape (N, n); returns (N, n)."""
        import pinocchio as pin

        if q.shape[0] == 0:
            return np.zeros_like(q)
        # (N, n) C-ordered transposes to an (n, N) Fortran-ordered view: no copy
        tau = np.empty(q.shape[::-1], order="F")
        pool = self._pool()
        if n_threads > 1 and pool.size() < n_threads:
            pool.resize(n_threads)
        pin.rneaInParallel(
            n_threads,
            pool,
            np.ascontiguousarray(q).T,
            np.ascontiguousarray(qd).T,
            np.ascontiguousarray(qdd).T,
            tau,
        )
        return tau.T
