"""Small energy tables and fitted synthesizers shared by the synth tests (built once per session)."""

from __future__ import annotations

import pytest

import joulepath
from joulepath.data import EnergyTable, ingest, table_columns
from joulepath.sim import simulate
from joulepath.synth import SynthConfig, Synthesizer

TINY = {"epochs": 1, "batch_size": 100}
"""Neural methods: one epoch of 100-row batches (the tests check plumbing, not quality)."""


@pytest.fixture(scope="session")
def energy_table(tmp_path_factory) -> EnergyTable:
    """About 660 rows of 10 lab moves, all 40 features."""
    log = simulate(tmp_path_factory.mktemp("synth") / "x.csv", plant="lab", n_moves=10, seed=1)
    return ingest([log.log], robot=joulepath.load_robot("irb120"))


@pytest.fixture(scope="session")
def joint_table(energy_table) -> EnergyTable:
    """The first 300 rows as a joint-only table (25 modelled columns: quick to fit)."""
    frame = energy_table.frame.iloc[:300][list(table_columns("joint"))].reset_index(drop=True)
    return EnergyTable(frame=frame, feature_set="joint", robot=energy_table.robot)


class _Fitted:
    """Lazily fitted synthesizers, one per method, and their first sample of 300 rows."""

    def __init__(self, table: EnergyTable) -> None:
        self.table = table
        self._cache: dict[str, tuple[Synthesizer, EnergyTable]] = {}

    def __call__(self, method: str) -> tuple[Synthesizer, EnergyTable]:
        if method not in self._cache:
            synth = Synthesizer(SynthConfig(method=method, seed=7, **TINY)).fit(self.table)
            self._cache[method] = (synth, synth.sample(300))
        return self._cache[method]


@pytest.fixture(scope="session")
def fitted(energy_table) -> _Fitted:
    return _Fitted(energy_table)
