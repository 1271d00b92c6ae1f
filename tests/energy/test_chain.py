"""The energy chain: invariants, agreement with independent implementations, exact gradients."""

import numpy as np
import pytest

from joulepath.energy import (
    STAGES,
    DriveModel,
    Drivetrain,
    chain_power,
    joint_energy,
    measure_energy,
    measure_power,
    motor_side_torque,
)


def _train(n, *, k=2.0, R=0.0, eta_d=1.0, eta=1.0, bus="bleeder", eta_r=0.0, standby=0.0):
    drives = DriveModel(
        torque_constant=(k,) * n,
        resistance=(R,) * n,
        drive_efficiency=(eta_d,) * n,
        bus=bus,
        regen_efficiency=eta_r,
        standby_W=standby,
    )
    return Drivetrain(gear_efficiency=(eta,) * n, drives=drives)


@pytest.fixture
def motion(rng):
    return rng.normal(size=(60, 4)) * 5.0, rng.normal(size=(60, 4))


def test_stages_run_joint_to_cabinet():
    assert list(STAGES) == ["joint", "gear", "copper", "motor", "drive", "bus", "standby"]
    assert all(s.unit == "W" for s in STAGES.values())


def test_chain_power_ideal_regenerative_bus_is_the_signed_sum(motion):
    tau, qd = motion
    c = chain_power(tau, qd, _train(4, bus="regenerative", eta_r=1.0))
    np.testing.assert_allclose(c.bus, (tau * qd).sum(axis=1), rtol=1e-12)
    e = measure_energy("electrical", tau, qd, 0.01, _train(4, bus="regenerative", eta_r=1.0))
    np.testing.assert_allclose(e.total_J, joint_energy(tau, qd, 0.01, mode="signed").sum(), rtol=1e-12)


def test_chain_power_ideal_per_axis_bus_is_the_positive_part(motion):
    tau, qd = motion
    c = chain_power(tau, qd, _train(4, bus="per-axis"))
    np.testing.assert_allclose(c.bus, joint_energy(tau, qd, 1.0, mode="positive").sum(axis=1), rtol=1e-12)


def test_chain_power_bus_kinds_are_ordered(motion):
    tau, qd = motion
    per_axis, bleeder, regen, signed = (
        chain_power(tau, qd, _train(4, R=0.3, eta_d=0.9, eta=0.8, bus=b, eta_r=r)).bus
        for b, r in (("per-axis", 0.0), ("bleeder", 0.0), ("regenerative", 0.6), ("regenerative", 1.0))
    )
    assert np.all(per_axis >= bleeder - 1e-12)
    assert np.all(bleeder >= regen - 1e-12)
    assert np.all(regen >= signed - 1e-12)


def test_chain_power_losses_are_never_negative(motion):
    tau, qd = motion
    lossy = chain_power(tau, qd, _train(4, R=0.5, eta_d=0.85, eta=0.7))
    ideal = chain_power(tau, qd, _train(4))
    assert np.all(lossy.gear >= lossy.joint - 1e-12)  # gear losses, driving and braking
    assert np.all(lossy.copper >= 0.0)
    assert np.all(lossy.drive >= lossy.motor - 1e-12)  # drive losses, both directions
    assert np.all(lossy.bus >= ideal.bus - 1e-12)  # every loss costs at the cabinet


def test_chain_power_copper_loss_at_rest():
    tau = np.array([[12.0, -3.0, 0.5]])
    rest = np.zeros_like(tau)
    k, R = 4.0, 0.7
    c = chain_power(tau, rest, _train(3, k=k, R=R))
    np.testing.assert_allclose(c.copper, R * (tau / k) ** 2)  # holding costs energy
    np.testing.assert_allclose(c.joint, 0.0)
    # through gears, the motor holds tau * eta at rest (the lab plant's convention)
    c = chain_power(tau, rest, _train(3, k=k, R=R, eta=0.8))
    np.testing.assert_allclose(c.copper, R * (0.8 * tau / k) ** 2)
    e = measure_energy("electrical", tau, rest, 0.5, _train(3, k=k, R=R, standby=0.0))
    np.testing.assert_allclose(e.total_J, 0.5 * (R * (tau / k) ** 2).sum())


def test_chain_power_gear_stage_matches_motor_side_torque(motion):
    tau, qd = motion
    c = chain_power(tau, qd, Drivetrain(gear_efficiency=(0.8,) * 4))
    np.testing.assert_allclose(c.gear, motor_side_torque(tau, qd, 0.8) * qd)
    assert c.copper is None and c.bus is None


def test_chain_power_single_sample_and_batch_agree(motion):
    tau, qd = motion
    train = _train(4, R=0.2, eta_d=0.9, eta=0.85)
    batch = chain_power(tau, qd, train).bus
    one = np.array([chain_power(tau[k], qd[k], train).bus for k in range(3)])
    np.testing.assert_allclose(one, batch[:3])


def test_measure_power_smooth_tends_to_exact(motion):
    tau, qd = motion
    qd = qd.copy()
    qd[:5] = 0.0  # at rest: the gears' switch is exact there too
    train = _train(4, R=0.2, eta_d=0.9, eta=0.85, bus="bleeder")
    exact = measure_power("electrical", tau, qd, train).value
    np.testing.assert_allclose(exact, chain_power(tau, qd, train).bus)
    smooth = [measure_power("electrical", tau, qd, train, eps=e).value for e in (1.0, 0.1, 0.01)]
    errors = [np.abs(v - exact).max() for v in smooth]
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.05


@pytest.mark.parametrize(
    ("name", "bus"),
    [
        ("thesis", "bleeder"),
        ("mechanical", "bleeder"),
        ("electrical", "bleeder"),
        ("electrical", "regenerative"),
        ("electrical", "per-axis"),
    ],
)
def test_measure_power_gradient_matches_finite_differences(rng, name, bus):
    tau = rng.normal(size=(8, 3)) * 4.0
    qd = rng.normal(size=(8, 3))
    qd[0] = 0.0  # at rest: copper losses only
    train = _train(3, k=3.0, R=0.4, eta_d=0.9, eta=0.8, bus=bus, eta_r=0.7)
    eps = 0.3
    p = measure_power(name, tau, qd, train, eps=eps)
    h = 1e-6
    for arg, grad in ((0, p.d_tau), (1, p.d_qd)):
        fd = np.zeros_like(tau)
        for idx in np.ndindex(tau.shape):
            plus = [tau.copy(), qd.copy()]
            minus = [tau.copy(), qd.copy()]
            plus[arg][idx] += h
            minus[arg][idx] -= h
            up = measure_power(name, *plus, train, eps=eps).value.sum()
            down = measure_power(name, *minus, train, eps=eps).value.sum()
            fd[idx] = (up - down) / (2 * h)
        np.testing.assert_allclose(grad, fd, rtol=1e-5, atol=1e-6)
