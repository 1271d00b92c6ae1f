"""The measure registry: names, stages, refusals, standby."""

import numpy as np
import pytest

from joulepath.energy import (
    MEASURES,
    DriveModel,
    Drivetrain,
    available_measures,
    check_measure,
    energy_measure,
    measure_energy,
    path_energy,
    total_energy,
)
from joulepath.errors import InvalidInput


def test_registry_lists_the_three_measures_with_their_stages():
    assert {name: m.stage for name, m in MEASURES.items()} == {
        "thesis": "joint",
        "mechanical": "gear",
        "electrical": "bus",
    }
    assert next(iter(MEASURES)) == "thesis"


def test_energy_measure_unknown_name_names_the_choices():
    with pytest.raises(InvalidInput, match="thesis, mechanical, electrical"):
        energy_measure("meter")


def test_check_measure_refuses_electrical_without_drive_data():
    why = "none (no arm.drives.toml beside the description)"
    train = Drivetrain(gear_efficiency=(0.9,), drives_source=why)
    with pytest.raises(InvalidInput, match=r"needs drive data .*arm\.drives\.toml.*drives\.toml in a twin"):
        check_measure("electrical", train)
    assert available_measures(train) == ("thesis", "mechanical")


def test_check_measure_refuses_mechanical_without_gear_efficiency():
    with pytest.raises(InvalidInput, match="gear_efficiency"):
        check_measure("mechanical", Drivetrain())
    assert available_measures(Drivetrain()) == ("thesis",)


def test_measure_energy_thesis_is_the_joint_energy(rng):
    tau, qd = rng.normal(size=(30, 6)), rng.normal(size=(30, 6))
    e = measure_energy("thesis", tau, qd, 0.025)
    np.testing.assert_allclose(e.total_J, path_energy(tau, qd, 0.025).total)
    np.testing.assert_allclose(e.total_J, total_energy(tau, qd, 0.025).sum())
    assert (e.stage, e.standby_J) == ("joint", 0.0)


def test_measure_energy_mechanical_with_ideal_gears_is_the_thesis(rng):
    tau, qd = rng.normal(size=(30, 2)), rng.normal(size=(30, 2))
    ideal = Drivetrain(gear_efficiency=(1.0, 1.0))
    assert measure_energy("mechanical", tau, qd, 0.1, ideal).total_J == pytest.approx(
        measure_energy("thesis", tau, qd, 0.1).total_J, rel=1e-12
    )


def test_measure_energy_electrical_counts_standby_over_the_duration():
    drives = DriveModel(torque_constant=(1.0,), resistance=(0.0,), drive_efficiency=(1.0,), standby_W=80.0)
    train = Drivetrain(gear_efficiency=(1.0,), drives=drives)
    still = np.zeros((41, 1))
    e = measure_energy("electrical", still, still, 0.025, train)
    assert e.motion_J == 0.0
    assert e.standby_J == pytest.approx(80.0 * 1.0)  # 40 steps of 25 ms
    longer = measure_energy("electrical", still, still, 0.025, train, duration=3.0)
    assert longer.standby_J == pytest.approx(240)


def test_measure_energy_refuses_a_batch():
    with pytest.raises(InvalidInput, match="one path"):
        measure_energy("thesis", np.ones((2, 3, 1)), np.ones((2, 3, 1)), 0.1)
