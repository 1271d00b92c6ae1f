"""The bundled ABB range: names, physical consistency, provenance, IRML against URDF, IK in every branch."""

from __future__ import annotations

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.description import (
    ABB_RANGE,
    FAMILY_DEFAULTS,
    KINDS,
    Chain,
    chain_from_urdf,
    preset_description,
    preset_path,
    provenance_beside,
    read_provenance,
)
from joulepath.dynamics import Robot
from joulepath.errors import InvalidRobotDescription
from joulepath.kinematics import check_layout, confdata, forward_kinematics, ik_branches, solve_ik

QUADRANT = np.pi / 2


@pytest.fixture(scope="module", params=ABB_RANGE)
def arm(request: pytest.FixtureRequest) -> Robot:
    return load_robot(request.param)


# --------------------------------------------------------------------------- names


def test_load_robot_every_variant_passes_the_physical_check(arm: Robot) -> None:
    errors = [f for f in arm.check_physical() if f.severity == "error"]
    assert errors == []
    assert arm.n_joints == 6
    assert arm.rated_payload_kg is not None and arm.rated_payload_kg > 0


@pytest.mark.parametrize("family", sorted(FAMILY_DEFAULTS))
def test_load_robot_family_name_is_its_default_variant_and_says_so(family: str) -> None:
    variant = FAMILY_DEFAULTS[family]
    by_family, by_variant = load_robot(family), load_robot(variant)
    assert by_family.name == by_variant.name
    assert preset_path(family) == preset_path(variant)
    assert any(family in message for _, message in by_family.chain.notes)
    assert preset_description(variant).info_value("family-default") == family
    assert read_provenance(preset_path(variant, fmt="provenance.toml")).family_default


def test_variant_names_follow_abb_payload_and_reach() -> None:
    """``irb4600-40-2.55`` is the IRB 4600-40/2.55: its payload and reach as its name says."""
    for name in ABB_RANGE:
        desc = preset_description(name)
        family, payload, reach = name.split("-")
        assert desc.name == f"IRB {family[3:]}-{payload}/{reach}"
        assert desc.info_float("carrying-capacity") == pytest.approx(float(payload))
        assert desc.reach_m == pytest.approx(float(reach), rel=0.02)  # ABB rounds: 0.81 m is "0.8"


def test_preset_path_unknown_name_is_refused_with_the_known_ones() -> None:
    with pytest.raises(InvalidRobotDescription, match="irb4600-40-2.55"):
        preset_path("irb9999")


# --------------------------------------------------------------------------- physics


def test_every_model_is_physically_consistent(arm: Robot) -> None:
    desc = arm.description
    assert desc is not None and desc.base is not None
    bodies = [desc.base, *(j.inertial for j in desc.joints)]
    for body in bodies:
        assert body.mass > 0
        inertia = body.inertia_array
        assert np.allclose(inertia, inertia.T)
        principal = np.linalg.eigvalsh(inertia)
        assert principal.min() > 0
        # triangle inequality of the principal moments: each at most the sum of the other two
        assert np.all(principal <= principal.sum() - principal + 1e-12 * principal.sum())
    prov = provenance_beside(arm.source)
    assert prov is not None
    total = sum(b.mass for b in bodies)
    catalogue = desc.spec_mass_kg
    assert catalogue is not None
    assert abs(total - catalogue) <= prov.uncertainty.catalogue_mass_rel * catalogue


def test_irml_and_urdf_twin_agree_in_kinematics_and_dynamics(arm: Robot) -> None:
    """Two descriptions of one arm (DH IRML, URDF joint origins) through two code paths agree."""
    name = next(n for n in ABB_RANGE if preset_description(n).name == arm.name)
    twin = Robot(chain_from_urdf(preset_path(name, fmt="urdf")))
    rng = np.random.default_rng(7)
    lo, hi = arm.joint_ranges()
    q = rng.uniform(lo, hi, size=(50, 6))
    qd = rng.uniform(-1, 1, size=(50, 6))
    qdd = rng.uniform(-3, 3, size=(50, 6))
    a, b = arm.fk(q), twin.fk(q)
    np.testing.assert_allclose(a.position_m, b.position_m, atol=1e-9)
    np.testing.assert_allclose(a.rotation, b.rotation, atol=1e-9)
    tau_a = arm.inverse_dynamics(q, qd, qdd)
    tau_b = twin.inverse_dynamics(q, qd, qdd)
    np.testing.assert_allclose(tau_a, tau_b, atol=1e-6 * np.abs(tau_b).max())


# --------------------------------------------------------------------------- provenance


def test_provenance_every_parameter_has_a_kind_a_source_and_a_bound(arm: Robot) -> None:
    prov = provenance_beside(arm.source)
    assert prov is not None
    assert prov.status == "estimated" and prov.is_estimate
    names = {p.name for p in prov.parameters}
    assert {"kinematics", "axis ranges", "axis speeds", "link masses", "inertias"} <= names
    for p in prov.parameters:
        assert p.kind in KINDS and p.source and p.how and p.bound
    kinds = {p.name: p.kind for p in prov.parameters}
    assert kinds["inertias"] == "estimated"
    # the IRB 2400's link masses are published (Obal & Gierlak 2025); every other arm's estimated
    assert kinds["link masses"] == ("published" if prov.family == "irb2400" else "estimated")
    assert 0 < prov.uncertainty.link_mass_rel < 1 and prov.uncertainty.link_com_m > 0
    # the licence of a public source is named with it
    assert all("Apache-2.0" in p.source for p in prov.parameters if "ROS-Industrial" in p.source)
    assert all("doi:" in p.source for p in prov.parameters if "Obal" in p.source)
    # every command's output says the model is an estimate (the CLI prints the chain's notes)
    assert any(where == "model" and "estimated" in message for where, message in arm.chain.notes)


def test_estimate_note_goes_when_the_masses_are_not_the_estimate_any_more() -> None:
    """A twin (identified) or an edited copy keeps the IRML's general information but not its
    masses: it is not called an estimate (the ``<model-fingerprint>`` no longer matches)."""
    from dataclasses import replace

    from joulepath.description import Inertial, chain_from_description, irml_string, parse_irml

    desc = preset_description("irb2600")
    assert any(where == "model" for where, _ in chain_from_description(desc).notes)
    again = parse_irml(irml_string(desc))  # written and read back: still the estimate
    assert any(where == "model" for where, _ in chain_from_description(again).notes)
    joints = list(desc.joints)
    b = joints[1].inertial
    joints[1] = replace(joints[1], inertial=Inertial.from_arrays(b.mass * 1.2, b.com, b.inertia))
    identified = replace(desc, joints=tuple(joints))
    assert all(where != "model" for where, _ in chain_from_description(identified).notes)


def test_irb120_has_no_estimate_note() -> None:
    assert load_robot("irb120").chain.notes == ()


def test_read_provenance_refuses_an_unknown_kind(tmp_path) -> None:
    path = tmp_path / "x.provenance.toml"
    path.write_text('robot = "x"\nname = "X"\nstatus = "guessed"\n')
    with pytest.raises(InvalidRobotDescription, match="status 'guessed' is not one of"):
        read_provenance(path)
    path.write_text('robot = "x"\nname = "X"\nstatus = "assumed"\n[uncertainty]\nlink_mass_rel = 1.5\n')
    with pytest.raises(InvalidRobotDescription, match="link_mass_rel"):
        read_provenance(path)


# --------------------------------------------------------------------------- inverse kinematics


def _branch_in_quadrants(qs: np.ndarray, cfx: np.ndarray, conf: np.ndarray, chain: Chain) -> np.ndarray:
    """From the 8 branches of each pose, the one ``confdata`` names, joints 1, 4, 6 turned into
    its quadrants (what the controller does with ConfJ/ConfL on), vectorised."""
    pick = np.argmax(cfx == conf[:, 3:4], axis=1)
    assert np.all(np.take_along_axis(cfx, pick[:, None], axis=1)[:, 0] == conf[:, 3])
    q = qs[np.arange(len(qs)), pick].copy()
    for col, j in ((0, 0), (1, 3), (2, 5)):
        low = conf[:, col] * QUADRANT
        turns = np.ceil((low - 1e-9 - q[:, j]) / (2 * np.pi))
        q[:, j] += 2 * np.pi * turns
    for j in (
        1,
        2,
        4,
    ):  # a range wider than a half turn (IRB 140 axis 3: -230..50 deg): the one turn within it
        q[:, j] += (
            2 * np.pi * ((q[:, j] < chain.lower[j] - 1e-9).astype(float) - (q[:, j] > chain.upper[j] + 1e-9))
        )
    return q


def test_ik_round_trip_10000_configurations_every_branch(arm: Robot) -> None:
    chain = arm.chain
    lay = check_layout(chain)
    rng = np.random.default_rng(2026)
    q = rng.uniform(chain.lower, chain.upper, size=(10_000, 6))
    q = q[np.abs(q[:, 4]) > 1e-3]  # away from the wrist singularity, where q4 and q6 are not unique
    pose = forward_kinematics(chain, q).homogeneous
    conf = confdata(chain, q)
    assert set(conf[:, 3]) == set(range(8))  # every branch is exercised
    qs, valid = ik_branches(chain, pose)
    from joulepath.kinematics._ik import branch_cfx

    cfx = np.where(valid, branch_cfx(chain, qs), -1)
    back = _branch_in_quadrants(qs, cfx, conf, chain)
    np.testing.assert_allclose(back, q, atol=1e-7)
    np.testing.assert_array_equal(confdata(chain, back), conf)
    if preset_description(next(n for n in ABB_RANGE if preset_description(n).name == arm.name)).joints[0].r:
        assert lay.a1 > 0  # a shoulder offset, read from the chain


def test_solve_ik_with_confdata_returns_the_same_joints(arm: Robot) -> None:
    chain = arm.chain
    rng = np.random.default_rng(11)
    q = rng.uniform(chain.lower, chain.upper, size=(60, 6))
    conf = confdata(chain, q)
    pose = forward_kinematics(chain, q).homogeneous
    for k in range(len(q)):
        got = solve_ik(chain, pose[k], tuple(int(c) for c in conf[k]), lower=chain.lower, upper=chain.upper)
        assert got is not None
        np.testing.assert_allclose(got, q[k], atol=1e-7)


# --------------------------------------------------------------------------- command line


def test_robot_show_prints_provenance_and_the_variant_a_family_name_takes(capsys) -> None:
    from joulepath.cli import main

    assert main(["robot", "show", "irb4600"]) == 0
    out = capsys.readouterr().out
    assert "IRB 4600-40/2.55" in out
    assert "family name 'irb4600'" in out
    assert "is ESTIMATED" in out
    assert "link masses: estimated" in out
    assert "kinematics: published" in out and "Apache-2.0" in out


def test_robot_show_unknown_abb_variant_is_one_line_and_exit_2(capsys) -> None:
    from joulepath.cli import main

    assert main(["robot", "show", "irb4600-99-9.99"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "irb4600-40-2.55" in err[0]
