"""The ABB range's drive and idle figures: one bundled drives file per size class, every value assumed
with its basis, and electrical energies that an independent computation from the file reproduces."""

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.description import ABB_DRIVE_CLASSES, ABB_RANGE, abb_drive_class, abb_drives_path, preset_path
from joulepath.energy import measure_energy

BUKATA = "Bukata et al."
CLASS_MASS_KG = {"compact": 75.0, "medium": 265.0, "large": 425.0}
"""The manipulator mass each class's standby is stated at (its file's standby_W source)."""


def _file(cls: str) -> dict:
    return tomllib.loads(
        (preset_path("irb120").parent / f"abb-{cls}.drives.toml").read_text(encoding="utf-8")
    )


def test_every_variant_of_the_range_has_one_class():
    listed = [arm for arms in ABB_DRIVE_CLASSES.values() for arm in arms]
    assert sorted(listed) == sorted(ABB_RANGE)
    assert abb_drive_class("irb120") is None and abb_drives_path("irb120") is None
    assert abb_drive_class("irb6700") == "heavy"  # a family's name is its default variant


@pytest.mark.parametrize(
    ("name", "cls"), [("irb6700", "heavy"), ("irb4600-60-2.05", "large"), ("irb2600", "medium")]
)
def test_a_large_arm_gets_its_class_figures(name, cls):
    robot = joulepath.load_robot(name)
    drives = robot.drives
    assert drives is not None
    assert Path(drives.origin).name == f"abb-{cls}.drives.toml"
    assert f"the {cls} class of the ABB range" in robot.drives_note
    data = _file(cls)
    assert drives.standby_W == data["standby_W"]
    assert (drives.brakes_W, drives.bus_off_W) == (data["brakes_W"], data["bus_off_W"])
    assert drives.torque_constant == tuple(data["torque_constant"])
    assert robot.drivetrain.gear_efficiency == (data["gear_efficiency"],) * 6


def test_the_idle_draw_grows_with_the_class():
    standby = [
        joulepath.load_robot(n).drives.standby_W
        for n in ("irb120", "irb1200", "irb1600", "irb4600", "irb6700")
    ]
    assert standby == sorted(standby) and len(set(standby)) == len(standby)


@pytest.mark.parametrize("cls", list(ABB_DRIVE_CLASSES))
def test_every_value_is_assumed_and_the_idle_draws_cite_their_source(cls):
    drives = joulepath.load_robot(ABB_DRIVE_CLASSES[cls][0]).drives
    assert drives is not None
    assert drives.describe().endswith("(every value assumed)")
    for key in ("torque_constant", "resistance", "drive_efficiency", "gear_efficiency", "bus", "standby_W"):
        assert drives.source(key).startswith("assumed ("), key  # assumed, with its basis
    for key in ("standby_W", "brakes_W"):
        assert BUKATA in drives.source(key) and "IEEE Trans. Industrial Informatics" in drives.source(key)
    for mode in ("brakes", "bus_off"):
        assert 0 < getattr(drives, f"{mode}_W") < drives.standby_W


def test_the_figures_follow_their_stated_basis():
    # heavy: the middle of the measured per-robot ranges (motors on, brakes engaged, bus power off)
    heavy = _file("heavy")
    assert heavy["standby_W"] == pytest.approx((567 + 751) / 2, abs=0.5)
    assert heavy["brakes_W"] == pytest.approx((218 + 278) / 2, abs=0.5)
    assert heavy["bus_off_W"] == pytest.approx((153 + 195) / 2, abs=0.5)
    # the others: the power law through (25 kg, 100 W) and (1,170 kg, heavy), rounded to 5 W;
    # the modes 38 % and 27 % of it
    exponent = math.log(heavy["standby_W"] / 100.0) / math.log(1170.0 / 25.0)
    assert f"^{exponent:.3f}" in _file("large")["sources"]["standby_W"]
    for cls, mass in CLASS_MASS_KG.items():
        data = _file(cls)
        assert data["standby_W"] == pytest.approx(100.0 * (mass / 25.0) ** exponent, abs=2.5), cls
        assert f"at {mass:.0f} kg" in data["sources"]["standby_W"]
        assert data["brakes_W"] == pytest.approx(0.38 * data["standby_W"], abs=0.5)
        assert data["bus_off_W"] == pytest.approx(0.27 * data["standby_W"], abs=0.5)


def _independent_electrical_J(tau, qd, dt, duration, data):
    """The cabinet's energy from the drives file's numbers, sample by sample, joint by joint (plain loops)."""
    eta, eta_d = data["gear_efficiency"], data["drive_efficiency"]
    total = 0.0
    for tau_k, qd_k in zip(tau.tolist(), qd.tolist(), strict=True):
        bus = 0.0
        for t, v, k, r in zip(tau_k, qd_k, data["torque_constant"], data["resistance"], strict=True):
            t_m = t / eta if t * v > 0 else t * eta  # the gears lose while driving and while braking
            motor = t_m * v + r * (t_m / k) ** 2  # shaft power plus copper losses
            bus += motor / eta_d if motor > 0 else motor * eta_d
        total += max(bus, 0.0) * dt  # bleeder: a braking surplus is burnt
    return total + data["standby_W"] * duration


def test_electrical_energy_of_a_heavy_arm_agrees_with_an_independent_computation():
    robot = joulepath.load_robot("irb6700")
    data = _file("heavy")
    assert data["bus"] == "bleeder"
    n, dt = 201, 0.01
    s = np.linspace(0.0, 1.0, n)
    blend = (10 * s**3 - 15 * s**4 + 6 * s**5)[:, None]
    dblend = ((30 * s**2 - 60 * s**3 + 30 * s**4) / (dt * (n - 1)))[:, None]
    ddblend = ((60 * s - 180 * s**2 + 120 * s**3) / (dt * (n - 1)) ** 2)[:, None]
    q0, q1 = np.radians([0.0, 30.0, 20.0, 0.0, 0.0, 0.0]), np.radians([60.0, -10.0, -20.0, 30.0, 40.0, 50.0])
    q, qd, qdd = q0 + blend * (q1 - q0), dblend * (q1 - q0), ddblend * (q1 - q0)
    tau = robot.inverse_dynamics(q, qd, qdd)
    duration = dt * (n - 1)
    e = measure_energy("electrical", tau, qd, dt, robot.drivetrain, duration=duration)
    expected = _independent_electrical_J(tau, qd, dt, duration, data)
    assert e.standby_J == pytest.approx(659.0 * duration)
    assert e.total_J == pytest.approx(expected, rel=1e-9)
    assert e.motion_J > 0.25 * e.standby_J  # a lift: the motion is a real share, not lost in the standby


def test_robot_show_names_the_class_drives_and_its_standby(capsys):
    from joulepath.cli import main

    assert main(["robot", "show", "irb6700"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("drive data:"))
    assert "abb-heavy.drives.toml (the heavy class of the ABB range)" in line
    assert "standby 659 W (assumed (from a measurement of arms of this size" in line


def test_a_copy_of_the_description_elsewhere_has_only_its_own_drives_file(tmp_path):
    import shutil

    copy = tmp_path / "irb4600-40-2.55.irml"
    shutil.copy(preset_path("irb4600-40-2.55"), copy)
    assert joulepath.load_robot(str(copy)).drives is None  # the user's arm: no bundled figures guessed
    shutil.copy(abb_drives_path("irb4600"), tmp_path / "irb4600-40-2.55.drives.toml")
    assert joulepath.load_robot(str(copy)).drives.standby_W == 400.0  # its own file, beside it
