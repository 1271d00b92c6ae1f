import numpy as np
import pytest

from joulepath.description import (
    Inertial,
    chain_from_urdf,
    check_inertial,
    check_physical,
    preset_description,
    preset_path,
    read_irml,
)


def test_check_physical_bundled_irb120_has_no_errors():
    findings = check_physical(preset_description("irb120"))
    assert [f.severity for f in findings] == ["warning", "warning"]
    torque, mass = findings
    assert "no torque (effort) limit" in torque.message and torque.where == "every joint <limits>"
    assert "18.146 kg" in mass.message and "25 kg" in mass.message


def test_check_physical_appendix_c_lists_what_is_wrong(appendix_c_path):
    findings = check_physical(read_irml(appendix_c_path))
    text = [str(f) for f in findings]
    for jid in range(1, 7):
        assert any(f"joint {jid} <dynamics> <inertia>: is a rotation matrix" in t for t in text)
    not_pd = {t.split()[2] for t in text if "not positive definite" in t}
    assert not_pd == {"1", "2", "4", "5", "6"}
    assert any("joint 6 <dynamics>: repeats joint 5" in t for t in text)
    mass = [t for t in text if "<manipulator-mass>" in t]
    assert len(mass) == 1 and "11.394 kg" in mass[0] and "25 kg" in mass[0]
    for jid in (3, 4, 5, 6):
        assert any(f"joint {jid} <dynamics> <center>" in t and "world coordinates" in t for t in text)
    assert findings[0].severity == "error" and findings[-1].severity == "warning"


def test_check_inertial_triangle_inequality_violation():
    bad = Inertial.from_arrays(1.0, (0, 0, 0), np.diag([0.1, 0.1, 0.5]))
    (finding,) = check_inertial("body", bad)
    assert "triangle inequality" in finding.message and finding.severity == "error"


def test_check_inertial_non_positive_mass():
    bad = Inertial.from_arrays(-1.0, (0, 0, 0), np.eye(3) * 0.01)
    assert any("mass -1.0 kg is not positive" in f.message for f in check_inertial("b", bad))


@pytest.mark.parametrize("diag", [(0.01, 0.02, 0.025), (0.03, 0.03, 0.001)])
def test_check_inertial_valid_body(diag):
    assert check_inertial("b", Inertial.from_arrays(2.0, (0, 0, 0.1), np.diag(diag)), reach=0.6) == []


def test_check_limits_missing_range_and_speed_are_errors_missing_torque_a_warning():
    from joulepath.description._check import check_limits

    nan = float("nan")
    findings = check_limits(
        ["joint 1", "joint 2"],
        np.array([nan, -1.0]),
        np.array([1.0, 1.0]),
        np.array([2.0, nan]),
        np.array([nan, 5.0]),
    )
    text = [str(f) for f in findings]
    assert text[0].startswith("error: joint 1 <limits>: no lower range limit")
    assert text[1].startswith("error: joint 2 <limits>: no speed limit")
    assert text[2].startswith("warning: joint 1 <limits>: no torque (effort) limit")
    assert len(text) == 3


@pytest.mark.parametrize(
    ("velocity", "effort", "fragment"), [(-1.0, 5.0, "velocity -1"), (2.0, 0.0, "effort 0")]
)
def test_check_limits_non_positive_speed_or_torque(velocity, effort, fragment):
    from joulepath.description._check import check_limits

    (finding,) = check_limits(
        ["j"], np.array([-1.0]), np.array([1.0]), np.array([velocity]), np.array([effort])
    )
    assert finding.severity == "error" and fragment in finding.message


@pytest.mark.parametrize("axis", [(0.0, 0.0, 0.0), (float("nan"), 0.0, 1.0)])
def test_check_axes_zero_or_not_finite_axis_is_an_error(axis):
    from joulepath.description._check import check_axes

    axes = np.array([[0.0, 0.0, 1.0], axis])
    (finding,) = check_axes(["joint 1", "joint 2"], axes)
    assert finding.severity == "error" and finding.where == "joint 2 <axis>"


def test_check_chain_bundled_urdf_has_only_the_torque_warning():
    from joulepath.description._check import check_chain

    chain = chain_from_urdf(preset_path("irb120", fmt="urdf"))
    findings = check_chain(chain)
    assert [f.severity for f in findings] == ["warning"] and "torque" in findings[0].message
