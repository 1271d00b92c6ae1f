"""Where a cycle's energy goes, and what a power-saving mode in its pauses would save (pure functions).

A cycle's samples are split into those where the arm moves and those where it stands
still (every joint slower than :data:`AT_REST_RAD_S`); each run of standing samples is a
*pause*. The energy of the moving samples is *motion*, that of the standing ones
*holding at rest* (the drives hold the arm against gravity), and the cabinet's standby
power over the cycle time is *standby*.

A power-saving mode (:data:`joulepath.energy._drives.IDLE_MODES`: brakes engaged, bus
power off) draws ``P_mode`` in all instead of ``standby_W`` plus the holding power. A
pause of ``T`` s longer than the mode's entry time ``T_e`` (entering and leaving it)
saves ``(standby_W + P_hold - P_mode) * (T - T_e)``; each pause takes its best mode.
That is a recommendation under the drives file's assumed mode powers, never a saving
of a written program.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from joulepath._typing import FloatArray

AT_REST_RAD_S = 1e-4
"""rad/s: a sample whose joints all move slower than this stands still."""


@dataclass(frozen=True, slots=True)
class Pause:
    """A run of standing samples: its length (s) and the energy holding the arm drew in it (J)."""

    duration_s: float
    holding_J: float


@dataclass(frozen=True, slots=True)
class EnergySplit:
    """Where one cycle's energy goes (J) and how long the arm stands still (s)."""

    motion_J: float
    holding_J: float
    standby_J: float
    standstill_s: float
    pauses: tuple[Pause, ...]

    @property
    def total_J(self) -> float:
        return self.motion_J + self.holding_J + self.standby_J


@dataclass(frozen=True, slots=True)
class ModeSaving:
    """What power-saving modes in a cycle's pauses would save (J per cycle), and in how many pauses."""

    saving_J: float
    pauses_used: dict[str, int]
    time_in_mode_s: float


def split_energy(
    t: FloatArray, power: FloatArray, qd: FloatArray, *, cycle_time: float, standby_W: float
) -> EnergySplit:
    """Split a cycle's energy into motion, holding at rest and standby.

    Parameters
    ----------
    t : ndarray of shape (n_steps,)
        s, strictly increasing, from 0; a gap between samples (a wait) counts at the
        sample before it, as the cycle's energy does.
    power : ndarray of shape (n_steps,)
        W per sample, standby excluded.
    qd : ndarray of shape (n_steps, n_joints)
        rad/s.
    cycle_time : float
        s; the time after the last sample, up to the cycle time, counts at the last sample.
    standby_W : float
        W the cabinet draws whatever the arm does (0: not counted).

    Returns
    -------
    EnergySplit

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0])
    >>> qd = np.array([[0.0], [1.0], [0.0]])
    >>> s = split_energy(t, np.array([5.0, 20.0, 5.0]), qd, cycle_time=4.0, standby_W=10.0)
    >>> s.motion_J, s.holding_J, s.standby_J, s.standstill_s
    (20.0, 15.0, 40.0, 3.0)
    """
    w = np.append(np.diff(t), max(cycle_time - float(t[-1]), 0.0))
    rest = np.all(np.abs(qd) < AT_REST_RAD_S, axis=1)
    e = power * w
    pauses: list[Pause] = []
    if rest.any():
        edges = np.flatnonzero(np.diff(np.concatenate(([0], rest.astype(np.int8), [0]))))
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            pauses.append(Pause(float(w[a:b].sum()), float(e[a:b].sum())))
    return EnergySplit(
        motion_J=float(e[~rest].sum()),
        holding_J=float(e[rest].sum()),
        standby_J=float(standby_W * cycle_time),
        standstill_s=float(w[rest].sum()),
        pauses=tuple(p for p in pauses if p.duration_s > 0),
    )


def mode_saving(
    pauses: Sequence[Pause], *, standby_W: float, modes: Mapping[str, tuple[float, float]]
) -> ModeSaving:
    """J per cycle a power-saving mode in each pause would save (each pause its best mode).

    ``modes`` maps a mode's name to ``(P_mode W, entry s)`` (see the module docstring).

    Examples
    --------
    >>> m = mode_saving([Pause(3.0, 6.0), Pause(0.2, 0.4)], standby_W=100.0, modes={"brakes": (40.0, 0.5)})
    >>> round(m.saving_J, 6), m.pauses_used
    (155.0, {'brakes': 1})
    """
    total = 0.0
    used: dict[str, int] = {}
    in_mode = 0.0
    for pause in pauses:
        hold_W = pause.holding_J / pause.duration_s
        best, best_name, best_time = 0.0, "", 0.0
        for name, (p_mode, entry) in modes.items():
            span = pause.duration_s - entry
            gain = (standby_W + hold_W - p_mode) * span
            if span > 0 and gain > best:
                best, best_name, best_time = gain, name, span
        if best_name:
            total += best
            used[best_name] = used.get(best_name, 0) + 1
            in_mode += best_time
    return ModeSaving(saving_J=total, pauses_used=used, time_in_mode_s=in_mode)
