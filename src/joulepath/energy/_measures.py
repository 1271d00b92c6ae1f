"""Energy measures: a registry of what "the energy of a path" can mean, each taken at one stage of the chain.

* ``thesis`` — ``Σ_i ∫ |tau_i qd_i| dt`` at the joints (stage ``joint``): the thesis'
  metric, the default while nothing else is known, and always reported. Braking
  costs as much as driving, holding costs nothing.
* ``mechanical`` — ``Σ_i ∫ |tau_m,i qd_i| dt`` at the motor side of the gears (stage
  ``gear``): what a drive's torque signal times speed integrates to; needs a gear
  efficiency (a twin's identified one, or a drives file's).
* ``electrical`` — the energy the cabinet draws (stage ``bus`` plus ``standby``):
  copper losses (holding costs energy), drive losses, the DC bus's sharing between
  axes and its bleeder or regeneration, and the standby power over the whole time;
  needs drive data (:func:`joulepath.energy.read_drives_file`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from joulepath._typing import ArrayLike, FloatArray
from joulepath.energy._chain import (
    STAGES,
    Drivetrain,
    SmoothPower,
    electrical_power,
    mechanical_power,
    thesis_power,
)
from joulepath.errors import InvalidInput

PowerFunction = Callable[[FloatArray, FloatArray, Drivetrain, float], SmoothPower]


@dataclass(frozen=True, slots=True)
class EnergyMeasure:
    """A registered measure: its name, the stage it is taken at, what it needs, and its power."""

    name: str
    stage: str
    description: str
    needs: tuple[str, ...]
    """``"gear"`` (a gear efficiency) and/or ``"drives"`` (drive data)."""
    power: PowerFunction
    """``(tau, qd, drivetrain, eps) -> SmoothPower``: per-sample power (W) without standby."""
    standby: bool = False
    """Whether the cabinet's standby power counts (over the whole time)."""

    def missing(self, drivetrain: Drivetrain) -> str | None:
        """Why this measure cannot be computed with ``drivetrain`` (None: it can), in one line."""
        if "drives" in self.needs and drivetrain.drives is None:
            return (
                f"the {self.name} energy needs drive data (torque constants, winding resistances, drive "
                f"efficiencies, bus kind, standby power): {drivetrain.drives_source}; provide a "
                "<robot>.drives.toml beside the robot description, or drives.toml in a twin folder "
                "(format: docs/reference/formats.md, 'Drives files')"
            )
        if "gear" in self.needs and drivetrain.gear_efficiency is None:
            return (
                f"the {self.name} energy needs the gears' efficiency: {drivetrain.gear_source}; give "
                "gear_efficiency in the robot's drives file, or use a twin (`joulepath identify`)"
            )
        return None

    def source(self, drivetrain: Drivetrain) -> str:
        """Where this measure's data come from, in words (shown with its figures)."""
        parts = []
        if "gear" in self.needs:
            parts.append(f"gear efficiency: {drivetrain.gear_source}")
        if "drives" in self.needs:
            parts.append(f"drives: {drivetrain.drives_source}")
        return "; ".join(parts) or "the robot's dynamics model only"


MEASURES: dict[str, EnergyMeasure] = {}
"""The measure registry; adding a measure is :func:`register_measure` and its power function."""


def register_measure(measure: EnergyMeasure) -> EnergyMeasure:
    if measure.stage not in STAGES:
        raise InvalidInput(f"measure {measure.name!r}: unknown stage {measure.stage!r}")
    MEASURES[measure.name] = measure
    return measure


def _thesis(tau: FloatArray, qd: FloatArray, drivetrain: Drivetrain, eps: float) -> SmoothPower:
    return thesis_power(tau, qd, eps)


def _mechanical(tau: FloatArray, qd: FloatArray, drivetrain: Drivetrain, eps: float) -> SmoothPower:
    assert drivetrain.gear_efficiency is not None  # checked by EnergyMeasure.missing
    return mechanical_power(tau, qd, drivetrain.gear_efficiency, eps)


def _electrical(tau: FloatArray, qd: FloatArray, drivetrain: Drivetrain, eps: float) -> SmoothPower:
    return electrical_power(tau, qd, drivetrain, eps)


register_measure(
    EnergyMeasure(
        "thesis",
        "joint",
        "Σ|tau·qd| at the joints, friction included (the thesis' metric; braking costs, holding is free)",
        (),
        _thesis,
    )
)
register_measure(
    EnergyMeasure(
        "mechanical",
        "gear",
        "Σ|tau_m·qd| at the motor side of the gears (gear losses driving and braking)",
        ("gear",),
        _mechanical,
    )
)
register_measure(
    EnergyMeasure(
        "electrical",
        "bus",
        "what the cabinet draws: gear, copper and drive losses, the DC bus (bleeder or regeneration) "
        "and the standby power",
        ("gear", "drives"),
        _electrical,
        standby=True,
    )
)
DEFAULT_MEASURE = "thesis"


def energy_measure(name: str) -> EnergyMeasure:
    """The registered measure ``name``; InvalidInput naming the choices otherwise."""
    try:
        return MEASURES[name]
    except KeyError:
        raise InvalidInput(f"energy measure must be one of {', '.join(MEASURES)}, got {name!r}") from None


def check_measure(name: str, drivetrain: Drivetrain) -> EnergyMeasure:
    """The measure ``name`` if ``drivetrain`` has what it needs; else InvalidInput saying what to provide."""
    measure = energy_measure(name)
    why = measure.missing(drivetrain)
    if why is not None:
        raise InvalidInput(why)
    return measure


@dataclass(frozen=True, slots=True)
class MeasuredEnergy:
    """A path's energy on one measure, J: motion and standby, and where it was taken."""

    measure: str
    stage: str
    motion_J: float
    standby_J: float
    source: str

    @property
    def total_J(self) -> float:
        return self.motion_J + self.standby_J


def measure_power(
    name: str, tau: ArrayLike, qd: ArrayLike, drivetrain: Drivetrain | None = None, *, eps: float = 0.0
) -> SmoothPower:
    """Per-sample power (W, standby excluded) of measure ``name`` and its derivatives by ``tau`` and ``qd``.

    ``eps`` (W) > 0 smooths every ``|x|`` and ``max(x, 0)`` (see :mod:`joulepath.energy`);
    0 is exact.

    Examples
    --------
    >>> float(measure_power("thesis", [[2.0, -3.0]], [[1.0, 1.0]]).value[0])
    5.0
    """
    measure = check_measure(name, drivetrain or Drivetrain())
    t = np.asarray(tau, dtype=float)
    v = np.asarray(qd, dtype=float)
    if t.shape != v.shape:
        raise InvalidInput(f"tau has shape {t.shape} but qd has shape {v.shape}; they must match")
    return measure.power(t, v, drivetrain or Drivetrain(), eps)


def measure_energy(
    name: str,
    tau: ArrayLike,
    qd: ArrayLike,
    dt: float | ArrayLike,
    drivetrain: Drivetrain | None = None,
    *,
    duration: float | None = None,
) -> MeasuredEnergy:
    """Energy (J) of a sampled path ``(n_steps, n)`` on measure ``name``: ``Σ_k P_k dt_k`` (+ standby).

    Parameters
    ----------
    tau, qd : array_like of shape (n_steps, n)
    dt : float or array_like of shape (n_steps,)
        Each sample's weight, s (the thesis: one sample period per sample).
    drivetrain : Drivetrain, optional
        The robot's gear efficiency and drives (:attr:`joulepath.Robot.drivetrain`).
    duration : float, optional
        s over which the standby power counts (default: ``(n_steps - 1) * dt``, or the
        sum of the weights).

    Raises
    ------
    InvalidInput
        An unknown measure, or one whose data ``drivetrain`` lacks (the message says what to provide).

    Examples
    --------
    >>> e = measure_energy("thesis", [[1.0], [1.0]], [[2.0], [2.0]], 0.5)
    >>> e.total_J, e.stage
    (2.0, 'joint')
    """
    train = drivetrain or Drivetrain()
    measure = check_measure(name, train)
    power = measure_power(name, tau, qd, train).value
    if power.ndim != 1:
        raise InvalidInput(f"expected one path of shape (n_steps, n), got tau of shape {np.shape(tau)}")
    w = np.asarray(dt, dtype=float)
    if np.any(w < 0) or not np.all(np.isfinite(w)):
        raise InvalidInput("dt must be finite and ≥ 0 s")
    motion = float((power * w).sum())
    standby = 0.0
    if measure.standby and train.drives is not None:
        if duration is None:
            duration = float(w.sum()) if w.ndim else float(w) * max(power.shape[-1] - 1, 0)
        standby = train.drives.standby_W * float(duration)
    return MeasuredEnergy(name, measure.stage, motion, standby, measure.source(train))


def available_measures(drivetrain: Drivetrain) -> tuple[str, ...]:
    """The registered measures ``drivetrain`` has the data for, in registry order."""
    return tuple(name for name, m in MEASURES.items() if m.missing(drivetrain) is None)
