"""Where a cycle's energy goes, and the power-saving modes' saving: invariants."""

from __future__ import annotations

import numpy as np
import pytest

from joulepath.plant import Pause, mode_saving, split_energy


def _cycle(rng):
    n = 200
    t = np.cumsum(rng.uniform(0.001, 0.01, n)) - 0.001
    t[120] += 2.0  # a wait: a gap after sample 119
    t[121:] += 2.0
    qd = rng.normal(size=(n, 6))
    qd[100:140] = 0.0  # standing still around the wait
    qd[180:] = 0.0
    power = rng.uniform(0.0, 50.0, n)
    return t - t[0], power, qd


def test_split_energy_adds_up_to_the_cycle():
    t, power, qd = _cycle(np.random.default_rng(3))
    cycle_time = float(t[-1]) + 0.7
    s = split_energy(t, power, qd, cycle_time=cycle_time, standby_W=100.0)
    w = np.append(np.diff(t), 0.7)
    assert s.motion_J + s.holding_J == pytest.approx(float(power @ w))
    assert s.standby_J == pytest.approx(100.0 * cycle_time)
    moving_time = float(w[np.any(qd != 0, axis=1)].sum())
    assert s.standstill_s + moving_time == pytest.approx(cycle_time)
    assert len(s.pauses) == 2  # samples 100-139 (with the wait) and 180 to the end
    assert sum(p.duration_s for p in s.pauses) == pytest.approx(s.standstill_s)
    assert sum(p.holding_J for p in s.pauses) == pytest.approx(s.holding_J)
    assert s.pauses[0].duration_s > 2.0


def test_mode_saving_takes_each_pause_at_its_best_mode():
    modes = {"brakes": (38.0, 0.5), "bus_off": (27.0, 5.0)}
    pauses = [Pause(0.4, 0.8), Pause(3.0, 6.0), Pause(20.0, 40.0)]
    m = mode_saving(pauses, standby_W=100.0, modes=modes)
    by_hand = (100 + 2 - 38) * 2.5 + max((100 + 2 - 38) * 19.5, (100 + 2 - 27) * 15.0)
    assert m.saving_J == pytest.approx(by_hand)
    assert m.pauses_used == {"brakes": 2}
    long = mode_saving([Pause(200.0, 400.0)], standby_W=100.0, modes=modes)
    assert long.pauses_used == {"bus_off": 1}  # long enough for the deeper mode to win


def test_mode_saving_grows_with_the_pause_and_is_zero_without_modes():
    modes = {"brakes": (38.0, 0.5), "bus_off": (27.0, 5.0)}
    savings = [
        mode_saving([Pause(d, d)], standby_W=100.0, modes=modes).saving_J for d in np.linspace(0.1, 60, 40)
    ]
    assert np.all(np.diff(savings) >= 0) and savings[0] == 0.0
    assert mode_saving([Pause(10.0, 5.0)], standby_W=100.0, modes={}).saving_J == 0.0
