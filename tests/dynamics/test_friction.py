import numpy as np
import pytest

from joulepath.dynamics import CoulombViscousFriction, ElastoPlasticFriction, FrictionSum
from joulepath.errors import InvalidInput


def test_elasto_plastic_listing_form():
    f = ElastoPlasticFriction()
    v = np.array([-2.0, 0.0, 0.302, 2.0])
    expected = 0.504 * np.sign(v) * (1 - np.exp(-(np.abs(v) - 0.302) / 0.504))
    np.testing.assert_allclose(f.torque(v), expected)
    assert f.torque(np.array([0.0]))[0] == 0.0
    assert f.torque(np.array([0.302]))[0] == pytest.approx(0.0, abs=1e-15)  # sign change point


def test_elasto_plastic_text_form_differs():
    v = np.array([1.0])
    listing = ElastoPlasticFriction().torque(v)
    text = ElastoPlasticFriction(form="text").torque(v)
    np.testing.assert_allclose(text, 0.504 * (1 - np.exp(-1.302) / 0.504))
    assert not np.allclose(listing, text)


def test_friction_is_odd_and_per_joint():
    f = CoulombViscousFriction(coulomb=(1, 2, 3, 4, 5, 6), viscous=0.5)
    v = np.linspace(-1, 1, 12).reshape(2, 6)
    np.testing.assert_allclose(f.torque(-v), -f.torque(v))
    np.testing.assert_allclose(f.torque(np.full(6, 2.0)), np.arange(1, 7) + 1.0)


def test_coulomb_smoothing_is_continuous():
    f = CoulombViscousFriction(coulomb=1.0, smoothing=0.01)
    assert abs(f.torque(np.array([1e-6]))[0]) < 1e-3
    assert f.torque(np.array([1.0]))[0] == pytest.approx(1.0)


def test_friction_terms_add():
    a, b = ElastoPlasticFriction(), CoulombViscousFriction(viscous=0.2)
    total = a + b
    assert isinstance(total, FrictionSum)
    v = np.array([0.5, -1.5])
    np.testing.assert_allclose(total.torque(v), a.torque(v) + b.torque(v))
    assert len((total + a).terms) == 3


def test_friction_adds_to_inverse_dynamics(irb120):
    f = CoulombViscousFriction(viscous=0.3)
    qd = np.full(6, 0.5)
    diff = irb120.inverse_dynamics(np.zeros(6), qd, np.zeros(6), friction=f) - irb120.inverse_dynamics(
        np.zeros(6), qd, np.zeros(6)
    )
    np.testing.assert_allclose(diff, 0.15)


@pytest.mark.parametrize(
    "make",
    [
        lambda: ElastoPlasticFriction(form="other"),
        lambda: ElastoPlasticFriction(mu_k=0.0),
        lambda: CoulombViscousFriction(coulomb=-1.0),
        lambda: CoulombViscousFriction(smoothing=-1),
    ],
)
def test_friction_invalid_parameters(make):
    with pytest.raises(InvalidInput):
        make()
