"""How the motion is derived from a log: raw differences or speeds low-passed before differentiation.

The plant: a perturbed IRB 120 turning through sums of sines, logged as a fast real logger
logs (the Franka Panda log of ``benchmarks/identify_real.py``): about 1 kHz with timestamps
0.56 to 1.44 ms apart, 6 % of the rows a stale copy of the row before, speed sensor noise.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from joulepath.cli import main
from joulepath.dynamics import NOMINAL_FRICTION, TWIN_CARD_FILE
from joulepath.errors import InvalidInput
from joulepath.identify import (
    AUTO_SPEED_CUTOFF_HZ,
    EvaluateConfig,
    IdentifyOptions,
    UnexcitedParameterWarning,
    base_parameters,
    data_from_logs,
    evaluate_model,
    filtered_motion,
    identify,
    true_parameters,
    twin_speed_cutoff,
)
from joulepath.identify._data import repeated_rows, resolve_speed_cutoff
from joulepath.sim import Plant
from joulepath.sim._plants import perturbed_robot

HEADER = ",".join(["t", *(f"{p}{i}" for i in range(1, 7) for p in ("q", "dq", "tau"))])


def _sines(t: np.ndarray):
    n = 6
    freq = 0.3 + 0.17 * np.arange(n)
    amp = 0.6 / (1 + 0.2 * np.arange(n))
    w = 2 * np.pi * freq
    q = amp * (np.sin(w * t[:, None]) + 0.5 * np.sin(2.3 * w * t[:, None] + 1.0))
    qd = amp * w * (np.cos(w * t[:, None]) + 1.15 * np.cos(2.3 * w * t[:, None] + 1.0))
    qdd = -amp * w**2 * (np.sin(w * t[:, None]) + 2.645 * np.sin(2.3 * w * t[:, None] + 1.0))
    return q, qd, qdd


def _write_log(path, real, *, seconds, seed, speed_noise=0.005, repeat=0.06, torque_ripple=0.0):
    """A jittered, partly repeated, noisy-speed log of ``real``'s exact torques (plus ``torque_ripple``
    N·m at 150 Hz on every joint, a signal only the torque holds)."""
    rng = np.random.default_rng(seed)
    n = int(seconds * 1000)
    t = np.cumsum(rng.uniform(0.56, 1.44, n) * 1e-3)
    t -= t[0]
    q, qd, qdd = _sines(t)
    plant = Plant(name="jittered", robot=real, friction=NOMINAL_FRICTION)
    tau = plant.drive_torque(q, qd, qdd) + torque_ripple * np.sin(2 * np.pi * 150.0 * t)[:, None]
    rows = np.concatenate([q, qd + speed_noise * rng.standard_normal(qd.shape), tau], axis=1)
    stale = np.nonzero(rng.random(n) < repeat)[0]
    for k in stale[stale > 0]:
        rows[k] = rows[k - 1]
    cols = [t]
    for j in range(6):
        cols += [rows[:, j], rows[:, 6 + j], rows[:, 12 + j]]
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=HEADER, comments="", fmt="%.10g")
    return path


@pytest.fixture(scope="module")
def plant_robot(irb120):
    return perturbed_robot(irb120, np.random.default_rng(5))


@pytest.fixture(scope="module")
def jittered_log(plant_robot, tmp_path_factory):
    return _write_log(tmp_path_factory.mktemp("logs") / "jittered.csv", plant_robot, seconds=10, seed=1)


def _base_error(data, robot, real):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnexcitedParameterWarning)
        result = identify(data, robot, IdentifyOptions(gear_efficiency=1.0, consistent=False))
    truth = base_parameters(robot, armature=True).project(true_parameters(real, armature=True))
    return float(np.linalg.norm(result.beta_ls - truth) / np.linalg.norm(truth))


def test_the_filter_recovers_the_parameters_the_raw_difference_misses(irb120, plant_robot, jittered_log):
    """Measured on this plant (seed 1): acceleration RMS error 5.2 rad/s² raw, 0.47 at 20 Hz; base-parameter
    error 25.6 % raw, 0.05 % at 20 Hz. Asserted with margins."""
    raw = data_from_logs([jittered_log], irb120)
    low = data_from_logs([jittered_log], irb120, speed_cutoff_hz=20.0)
    assert raw.motion is not None and not raw.motion.filtered
    assert low.motion is not None and low.motion.cutoff_hz == (20.0,)
    assert low.motion.repeated_rows[0] > 0.04 * low.motion.n_rows[0]
    assert 900 < low.motion.sample_rate_hz[0] < 1100
    # the same rows either way, the accelerations much closer to the plant's
    np.testing.assert_array_equal(low.dt, raw.dt)
    t = np.loadtxt(jittered_log, delimiter=",", skiprows=1)[1:-1, 0]
    exact = _sines(t)[2]
    raw_err = np.sqrt(np.mean((raw.qdd - exact) ** 2))
    low_err = np.sqrt(np.mean((low.qdd - exact) ** 2))
    assert low_err < 0.2 * raw_err
    err_raw = _base_error(raw, irb120, plant_robot)
    err_low = _base_error(low, irb120, plant_robot)
    assert err_low < 0.01 < 0.1 < err_raw


def test_the_filter_never_touches_the_logged_torque(irb120, plant_robot, tmp_path):
    """A 150 Hz torque ripple (far above the cutoff) stays in the data and in the scored target."""
    log = _write_log(tmp_path / "ripple.csv", plant_robot, seconds=3, seed=2, torque_ripple=5.0)
    logged = np.loadtxt(log, delimiter=",", skiprows=1)[1:-1, 3::3]
    raw = data_from_logs([log], irb120)
    low = data_from_logs([log], irb120, speed_cutoff_hz=10.0)
    np.testing.assert_array_equal(low.tau, logged)
    np.testing.assert_array_equal(low.tau, raw.tau)
    assert not np.allclose(low.qdd, raw.qdd)  # while the motion is filtered
    config = EvaluateConfig(speed_cutoff_hz=10.0)
    ev = evaluate_model(log, plant_robot, robot_source="plant", config=config)
    ev_raw = evaluate_model(log, plant_robot, robot_source="plant")
    np.testing.assert_array_equal(ev.tau_measured, logged)
    np.testing.assert_array_equal(ev_raw.tau_measured, logged)
    assert not np.allclose(ev.tau_predicted, ev_raw.tau_predicted)
    # the measured per-move energy is the logged torque times the logged speed, filter or not
    assert [m["energy_measured_J"] for m in ev.moves] == [m["energy_measured_J"] for m in ev_raw.moves]
    assert ev.summary()["motion"]["speed_cutoff_hz"] == [10.0]


def test_filtered_motion_of_a_clean_uniform_log_is_the_motion(rng):
    """No noise, no jitter: the low-passed speed and its derivative stay on the exact ones."""
    t = np.arange(0.0, 6.0, 1e-3)
    q, qd, qdd = _sines(t)
    pos, speed, accel = filtered_motion(t, q, qd, 20.0)
    inner = slice(200, -200)  # away from the ends, where the filter starts up
    np.testing.assert_array_equal(pos, q)
    assert np.max(np.abs(speed - qd)[inner]) < 1e-3 * np.max(np.abs(qd))
    assert np.max(np.abs(accel - qdd)[inner]) < 1e-2 * np.max(np.abs(qdd))
    # repeated rows are left out of the fit, their positions interpolated
    stale = q.copy(), qd.copy()
    stale[0][500], stale[1][500] = q[499], qd[499]
    assert repeated_rows(*stale).nonzero()[0].tolist() == [500]
    pos, speed, _ = filtered_motion(t, *stale, 20.0)
    assert abs(pos[500, 0] - q[500, 0]) < 1e-6 and abs(speed[500, 0] - qd[500, 0]) < 1e-3


def test_auto_and_refused_cutoffs(irb120, jittered_log):
    assert resolve_speed_cutoff("auto", 1000.0) == AUTO_SPEED_CUTOFF_HZ
    assert resolve_speed_cutoff("auto", 38.0) is None
    assert resolve_speed_cutoff("auto", 1000.0, has_qdd=True) is None
    assert resolve_speed_cutoff(None, 1000.0) is None
    assert data_from_logs([jittered_log], irb120, speed_cutoff_hz="auto").motion.cutoff_hz == (20.0,)
    with pytest.raises(InvalidInput, match="half the log's sample rate"):
        data_from_logs([jittered_log], irb120, speed_cutoff_hz=600.0)
    for bad in (0.0, -5.0, float("nan"), "fast", True):
        with pytest.raises(InvalidInput, match="speed cutoff"):
            data_from_logs([jittered_log], irb120, speed_cutoff_hz=bad)
        with pytest.raises(InvalidInput, match="speed cutoff"):
            EvaluateConfig(speed_cutoff_hz=bad)


def test_cli_round_trip_of_the_cutoff(irb120, plant_robot, tmp_path, capsys):
    """identify --speed-cutoff HZ records it on the card; evaluate applies it unless told otherwise."""
    log = _write_log(tmp_path / "log.csv", plant_robot, seconds=6, seed=3)
    valid = _write_log(tmp_path / "valid.csv", plant_robot, seconds=3, seed=4)
    twin = tmp_path / "twin"
    argv = ["identify", str(log), "--robot", "irb120", "--gear-efficiency", "1", "--out", str(twin)]
    assert main([*argv, "--speed-cutoff", "25"]) == 0
    out = capsys.readouterr().out
    assert "motion: logged speeds low-passed at 25 Hz (as given" in out
    card = json.loads((twin / TWIN_CARD_FILE).read_text())
    assert card["motion"]["requested"] == 25.0 and card["motion"]["speed_cutoff_hz"] == [25.0]
    assert twin_speed_cutoff(twin) == (True, 25.0)

    assert main(["evaluate", str(valid), "--robot", str(twin), "--out", str(tmp_path / "e1")]) == 0
    out = capsys.readouterr().out
    assert "low-passed at 25 Hz" in out and "[as the twin's card says it was identified]" in out
    filtered = json.loads((tmp_path / "e1" / "evaluate.json").read_text())
    assert filtered["motion"]["speed_cutoff_hz"] == [25.0]

    off = ["--speed-cutoff", "off"]
    assert main(["evaluate", str(valid), "--robot", str(twin), *off, "--out", str(tmp_path / "e2")]) == 0
    assert "motion: raw logged speeds" in capsys.readouterr().out
    raw = json.loads((tmp_path / "e2" / "evaluate.json").read_text())
    assert raw["motion"]["speed_cutoff_hz"] == [None]
    assert filtered["torque"]["r2_mean"] > raw["torque"]["r2_mean"]

    # the default: auto, 20 Hz on this 1 kHz log, said in one line; the card keeps "auto"
    assert main([*argv, "--force"]) == 0
    assert "low-passed at 20 Hz (auto, from the sample rate" in capsys.readouterr().out
    assert twin_speed_cutoff(twin) == (True, "auto")
    # a model that is no twin: auto
    assert main(["evaluate", str(valid), "--robot", "irb120", "--out", str(tmp_path / "e3")]) == 0
    assert "low-passed at 20 Hz (auto, from the sample rate" in capsys.readouterr().out

    assert main([*argv, "--force", "--speed-cutoff", "fast"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --speed-cutoff 'fast'") and err.count("\n") == 1
