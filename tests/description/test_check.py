import numpy as np
import pytest

from joulepath.description import (
    Inertial,
    check_inertial,
    check_physical,
    preset_description,
    read_irml,
)


def test_check_physical_bundled_irb120_has_no_errors():
    findings = check_physical(preset_description("irb120"))
    assert [f.severity for f in findings] == ["warning"]
    assert "18.146 kg" in findings[0].message and "25 kg" in findings[0].message


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
