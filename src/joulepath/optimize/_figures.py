"""Energy figures paired with their measure: every figure is one stage on one named measure.

A run reports the energy of the default and the optimized move at three stages
(:data:`FIGURE_STAGES`):

* ``planned``: on the model the optimizer planned with (the nominal robot or a twin);
* ``lab``: the same planned motion on the lab robot (the emulated lab plant; for a
  twin, the lab robot it twins);
* ``executed``: the written program as the controller emulation runs it, on the model
  (and, beside it, on the lab robot).

Each stage's pair (default, optimized) is on one measure, the run's ``--energy`` measure
(:data:`joulepath.energy.MEASURES`), so two figures of the same block, or the same key
of two blocks, are always the same quantity. The per-measure blocks (``energies``) hold
the planned and lab figures of every other measure. Keys of earlier releases that paired
figures of two measures stay for one release (:data:`RESULT_DEPRECATED`,
:data:`CYCLE_DEPRECATED`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from joulepath.errors import InvalidInput

FIGURE_STAGES = ("planned", "lab", "executed")
"""Where a pair of energies is taken (see the module docstring)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class EnergyPair:
    """The default and the optimized move's energy (J) at one stage, on one measure.

    Attributes
    ----------
    stage : {"planned", "lab", "executed"}
    measure : str
        A name of :data:`joulepath.energy.MEASURES`.
    on : str
        What the figures are taken on, in words (the model, the lab plant, the emulation).
    default_J, optimized_J : float or None
        None where the stage cannot take the measure (``note`` says why).
    lab_default_J, lab_optimized_J : float or None
        The executed stage only: the emulated motion on the lab robot, same measure.
    note : str
    """

    stage: str
    measure: str
    on: str
    default_J: float | None
    optimized_J: float | None
    lab_default_J: float | None = None
    lab_optimized_J: float | None = None
    note: str = ""

    def __post_init__(self) -> None:
        if self.stage not in FIGURE_STAGES:
            raise InvalidInput(f"stage must be one of {', '.join(FIGURE_STAGES)}, got {self.stage!r}")

    @property
    def saved_pct(self) -> float | None:
        """The optimized move's saving against the default, %, on this stage's measure."""
        return _saved(self.default_J, self.optimized_J)

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "measure": self.measure,
            "on": self.on,
            "default_J": self.default_J,
            "optimized_J": self.optimized_J,
            "saved_pct": self.saved_pct,
        }
        if self.stage == "executed":
            out.update(
                lab_default_J=self.lab_default_J,
                lab_optimized_J=self.lab_optimized_J,
                lab_saved_pct=_saved(self.lab_default_J, self.lab_optimized_J),
            )
        if self.note:
            out["note"] = self.note
        return out


def _saved(before: float | None, after: float | None) -> float | None:
    if before is None or after is None or not before > 0:
        return None
    return 100.0 * (before - after) / before


def _off(value: float, reference: float) -> float | None:
    return 100.0 * (value / reference - 1.0) if reference > 0 else None


def planned_vs_lab(planned: EnergyPair, lab: EnergyPair) -> dict[str, Any] | None:
    """How far the plan's energies are from the lab robot's, on their one measure.

    ``default_pct`` and ``optimized_pct``: ``100 (planned / lab - 1)``; ``saved_points``:
    the planned saving minus the lab's, percentage points. None when the lab has no figure.

    Raises
    ------
    InvalidInput
        The two pairs are on different measures (they would not compare).
    """
    if planned.measure != lab.measure:
        raise InvalidInput(
            f"the planned figures are on {planned.measure!r}, the lab's on {lab.measure!r}: "
            "only figures on one measure compare"
        )
    if None in (planned.default_J, planned.optimized_J, lab.default_J, lab.optimized_J):
        return None
    assert planned.default_J is not None and lab.default_J is not None
    assert planned.optimized_J is not None and lab.optimized_J is not None
    ps, ls = planned.saved_pct, lab.saved_pct
    return {
        "measure": planned.measure,
        "default_pct": 100.0 * (planned.default_J / lab.default_J - 1.0) if lab.default_J > 0 else None,
        "optimized_pct": 100.0 * (planned.optimized_J / lab.optimized_J - 1.0)
        if lab.optimized_J > 0
        else None,
        "saved_points": None if ps is None or ls is None else ps - ls,
    }


def figures_json(measure: str, pairs: Iterable[EnergyPair]) -> dict[str, Any]:
    """The ``energy_figures`` block: the measure, one entry per stage, and the plan against the lab.

    Raises
    ------
    InvalidInput
        A pair on another measure than ``measure``, or a stage given twice.
    """
    out: dict[str, Any] = {"measure": measure}
    by_stage: dict[str, EnergyPair] = {}
    for p in pairs:
        if p.measure != measure:
            raise InvalidInput(f"the {p.stage} figures are on {p.measure!r}, the run's on {measure!r}")
        if p.stage in by_stage:
            raise InvalidInput(f"two {p.stage} pairs")
        by_stage[p.stage] = p
    for stage in FIGURE_STAGES:
        out[stage] = by_stage[stage].to_json() if stage in by_stage else None
    planned, lab = by_stage.get("planned"), by_stage.get("lab")
    out["planned_vs_lab"] = None if planned is None or lab is None else planned_vs_lab(planned, lab)
    return out


def headline_keys(pairs: Iterable[EnergyPair]) -> dict[str, float | None]:
    """The flat headline keys: ``<stage>_default_J``, ``<stage>_optimized_J``, ``<stage>_saved_pct``."""
    out: dict[str, float | None] = {}
    for p in pairs:
        out[f"{p.stage}_default_J"] = p.default_J
        out[f"{p.stage}_optimized_J"] = p.optimized_J
        out[f"{p.stage}_saved_pct"] = p.saved_pct
    return out


def lab_pair(measure: str, energies: Iterable[Any], *, on: str, standby: bool = True) -> EnergyPair:
    """The lab stage on ``measure`` from the per-measure summaries (:class:`MeasureSummary`).

    ``standby=False`` takes the standby energy out (the motion alone, as a cycle's headline).
    """
    m = next((e for e in energies if e.measure == measure), None)
    if m is None or m.lab_default_J is None or m.lab_optimized_J is None:
        why = "the lab robot has no data for this measure" if m is None else m.lab_source
        return EnergyPair(stage="lab", measure=measure, on=on, default_J=None, optimized_J=None, note=why)
    drop = 0.0 if standby else m.standby_J
    return EnergyPair(
        stage="lab",
        measure=measure,
        on=on,
        default_J=m.lab_default_J - drop,
        optimized_J=m.lab_optimized_J - drop,
        note="standby included" if standby and m.standby_J else "",
    )


_SAME = "{} (same value)"
_MECHANICAL = "{} (on energy_measure); this key is on energy_lab_measure (mechanical)"
_LAB_MEASURE = "energy_figures.lab.measure (the lab figures are now on energy_measure)"

RESULT_DEPRECATED = {
    "energy_default_J": _SAME.format("planned_default_J"),
    "energy_optimized_J": _SAME.format("planned_optimized_J"),
    "saved_pct": _SAME.format("planned_saved_pct"),
    "energy_default_lab_J": _MECHANICAL.format("lab_default_J"),
    "energy_optimized_lab_J": _MECHANICAL.format("lab_optimized_J"),
    "saved_lab_pct": _MECHANICAL.format("lab_saved_pct"),
    "energy_lab_measure": _LAB_MEASURE,
    "executed_energy_default_J": _SAME.format("executed_default_J"),
    "executed_energy_optimized_J": _SAME.format("executed_optimized_J"),
    "executed_energy_default_lab_J": _MECHANICAL.format("executed_lab_default_J"),
    "executed_energy_optimized_lab_J": _MECHANICAL.format("executed_lab_optimized_J"),
    "executed_saved_lab_pct": _MECHANICAL.format("energy_figures.executed.lab_saved_pct"),
}
"""``result.json`` keys kept for one release: the key, and what replaces it."""

CYCLE_DEPRECATED = {
    "energy_default_J": _SAME.format("planned_default_J"),
    "energy_optimized_J": _SAME.format("planned_optimized_J"),
    "saved_pct": _SAME.format("planned_saved_pct"),
    "energy_default_lab_J": _MECHANICAL.format("lab_default_J"),
    "energy_optimized_lab_J": _MECHANICAL.format("lab_optimized_J"),
    "saved_lab_pct": _MECHANICAL.format("lab_saved_pct"),
    "energy_lab_measure": _LAB_MEASURE,
    "executed_energy_J": _SAME.format("executed_optimized_J"),
    "executed_energy_lab_J": _MECHANICAL.format("energy_figures.executed.lab_optimized_J"),
    "executed_saved_lab_pct": _MECHANICAL.format("energy_figures.executed.lab_saved_pct"),
}
"""``cycle.json`` keys kept for one release: the key, and what replaces it."""

__all__ = [
    "CYCLE_DEPRECATED",
    "EnergyPair",
    "FIGURE_STAGES",
    "RESULT_DEPRECATED",
    "figures_json",
    "headline_keys",
    "lab_pair",
    "planned_vs_lab",
]
