"""Boundary conditions of the polynomial trajectories for any start, end and grid chromosome."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from joulepath.trajectory import GRID_HIGH, GRID_LOW, GRID_STEP, rest_to_rest, thesis_quintic

K_LOW, K_HIGH = round(GRID_LOW / GRID_STEP), round(GRID_HIGH / GRID_STEP)
angles = st.floats(-7.0, 7.0, allow_nan=False, allow_subnormal=False)
configurations = hnp.arrays(np.float64, (6,), elements=angles)
chromosomes = (
    st.integers(1, 4)
    .flatmap(lambda n: hnp.arrays(np.int64, (n, 6, 6), elements=st.integers(K_LOW, K_HIGH)))
    .map(lambda k: k * GRID_STEP)
)
durations = st.integers(4, 120).map(lambda n: n * 0.025)


@given(c=chromosomes, q0=configurations, qf=configurations, duration=durations)
def test_rest_to_rest_starts_and_ends_at_rest(c, q0, qf, duration):
    tr = rest_to_rest(c, q0, qf, duration)
    assert tr.q.shape == (c.shape[0], tr.t.size, 6)
    assert np.array_equal(tr.q[:, 0], np.broadcast_to(q0, (c.shape[0], 6)))
    assert np.array_equal(tr.q[:, -1], np.broadcast_to(qf, (c.shape[0], 6)))
    assert np.all(tr.qd[:, [0, -1]] == 0) and np.all(tr.qdd[:, [0, -1]] == 0)


@given(c=chromosomes, q0=configurations, qf=configurations, duration=durations)
def test_thesis_quintic_hits_start_and_end(c, q0, qf, duration):
    tr = thesis_quintic(c, q0, qf, duration)
    assert np.array_equal(tr.q[:, 0], np.broadcast_to(q0, (c.shape[0], 6)))
    assert np.array_equal(tr.q[:, -1], np.broadcast_to(qf, (c.shape[0], 6)))
    for a in (tr.q, tr.qd, tr.qdd):
        assert np.all(np.isfinite(a))
