"""Twins of URDF arms: a named arm (UR5) with perturbed inertials and friction as the plant.

The identifiable parameters (the base set, friction) are recovered from exact signals; a
parameter the motion leaves unexcited keeps its prior, with a warning; the twin folder
(``robot.urdf``) loads back as the identified robot and is taken by ``evaluate`` and
``optimize``.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.dynamics import TWIN_CARD_FILE, TWIN_FRICTION_FILE, TWIN_URDF_FILE, IdentifiedFriction
from joulepath.errors import MissingDependency
from joulepath.identify import (
    FourierExcitation,
    IdentificationData,
    IdentifyOptions,
    UnexcitedParameterWarning,
    base_parameters,
    identify,
    true_parameters,
    twin_robot,
    write_twin,
)
from joulepath.identify._urdf import chain_urdf_string
from joulepath.sim import Plant
from joulepath.sim._plants import perturbed_robot

DT = 0.01
EXACT = 1e-8
"""Relative tolerance of parameters recovered from exact (noise-free) signals: the least-squares
solution is exact up to rounding (measured ~1e-14); the consistent refinement keeps it (~1e-10)."""


@pytest.fixture(scope="module")
def ur5():
    try:
        return joulepath.load_robot("ur5")
    except MissingDependency:
        pytest.skip("example-robot-data (the [robots] extra) is not installed")


@pytest.fixture(scope="module")
def plant(ur5):
    """The 'real' UR5: perturbed links, per-joint Coulomb and viscous friction (no offset), no gear loss."""
    rng = np.random.default_rng(1)
    real = perturbed_robot(ur5, rng)
    n = ur5.n_joints
    friction = IdentifiedFriction(
        coulomb=tuple(rng.uniform(1.0, 4.0, n)),
        viscous=tuple(rng.uniform(0.5, 3.0, n)),
        offset=(0.0,) * n,
        stribeck=(0.0,) * n,
    )
    return Plant(name="ur5-real", robot=real, friction=friction)


def _motion(n, seed, *, seconds=5.0):
    """A random 4-harmonic Fourier motion of every joint (q, qd, qdd exact), sampled at DT."""
    rng = np.random.default_rng(seed)
    shape = (n, 4)
    ex = FourierExcitation(
        q_mid=rng.uniform(-1.0, 1.0, n),
        a=rng.normal(0.0, 0.5, shape),
        b=rng.normal(0.0, 0.5, shape),
        base_hz=1.0 / seconds,
    )
    tr = ex.sample(DT)
    return tr.q, tr.qd, tr.qdd


def _data(plant, q, qd, qdd):
    return IdentificationData.from_arrays(q, qd, qdd, plant.drive_torque(q, qd, qdd), DT)


def _relative(a, b):
    return float(np.linalg.norm(np.asarray(a) - b) / np.linalg.norm(b))


OPTIONS = IdentifyOptions(gear_efficiency=1.0, rest_speed=0.0)


@pytest.fixture(scope="module")
def identified(ur5, plant):
    return identify(_data(plant, *_motion(6, seed=2)), ur5, OPTIONS)


def test_chain_urdf_string_reads_back_as_the_same_chain(ur5, tmp_path):
    """The twin's robot file: the chain written as URDF and read by Pinocchio's parser is the chain."""
    path = tmp_path / "robot.urdf"
    path.write_text(chain_urdf_string(ur5.chain, comment="a -- comment"))
    back = joulepath.load_robot(path)
    for name in ("placements", "axes", "masses", "coms", "inertias", "tool", "lower", "upper", "velocity"):
        np.testing.assert_allclose(getattr(back.chain, name), getattr(ur5.chain, name), atol=1e-12)
    assert back.chain.joint_names == ur5.chain.joint_names and back.name == ur5.name
    q, qd, qdd = _motion(6, seed=9, seconds=1.0)
    np.testing.assert_allclose(back.inverse_dynamics(q, qd, qdd), ur5.inverse_dynamics(q, qd, qdd), atol=1e-9)


def test_identify_recovers_the_base_parameters_and_friction_of_a_urdf_arm(ur5, plant, identified):
    truth = base_parameters(ur5, armature=True).project(true_parameters(plant.robot, armature=True))
    assert identified.kept == ()
    assert _relative(identified.beta_ls, truth) < EXACT
    assert _relative(identified.beta, truth) < EXACT
    np.testing.assert_allclose(identified.friction.coulomb, plant.friction.coulomb, rtol=EXACT)
    np.testing.assert_allclose(identified.friction.viscous, plant.friction.viscous, rtol=EXACT)
    np.testing.assert_allclose(identified.friction.offset, 0.0, atol=EXACT)
    assert identified.consistent


def test_the_twin_of_a_urdf_arm_predicts_the_plant_on_another_motion(ur5, plant, identified):
    """Agreement of two implementations: the twin's RNEA + friction against the plant's own."""
    twin = twin_robot(ur5, identified)
    assert twin.description is None and twin.calibration is not None
    assert twin.calibration.twin_of == "ur5"
    q, qd, qdd = _motion(6, seed=31)
    predicted = twin.inverse_dynamics(q, qd, qdd, friction=twin.friction)
    np.testing.assert_allclose(predicted, plant.joint_torque(q, qd, qdd), rtol=1e-6, atol=1e-6)
    # the kinematics are the nominal arm's, exactly
    np.testing.assert_array_equal(twin.chain.placements, ur5.chain.placements)
    np.testing.assert_array_equal(twin.fk(q[:5]).position_m, ur5.fk(q[:5]).position_m)


def test_write_twin_of_a_urdf_arm_writes_robot_urdf_that_loads_back(ur5, plant, identified, tmp_path):
    folder = tmp_path / "twin"
    paths = write_twin(identified, ur5, folder)
    assert sorted(p.name for p in paths) == sorted([TWIN_URDF_FILE, TWIN_FRICTION_FILE, TWIN_CARD_FILE])
    card = json.loads((folder / TWIN_CARD_FILE).read_text())
    assert card["twin_of"] == "ur5" and card["robot_file"] == TWIN_URDF_FILE
    assert card["kept_at_prior"] == []
    assert {row["coulomb"]["status"] for row in card["parameters"]} == {"identified"}
    robot = joulepath.load_robot(folder)
    assert robot.calibration is not None and robot.calibration.twin_of == "ur5"
    q, qd, qdd = _motion(6, seed=32, seconds=2.0)
    np.testing.assert_allclose(
        robot.inverse_dynamics(q, qd, qdd, friction=robot.friction),
        plant.joint_torque(q, qd, qdd),
        rtol=1e-6,
        atol=1e-6,
    )
    # the drives of a twin without drives.toml are those of the arm it twins (the bundled ur5's)
    assert robot.drives is not None and "ur5" in robot.drives_note


def test_a_parameter_the_motion_does_not_excite_keeps_its_prior_with_a_warning(ur5, plant):
    """Joint 6 turning one way only: its Coulomb level and offset act alike (sign(qd) = |sign(qd)|);
    the offset keeps its prior (0: no friction known for the nominal ur5), the rest is identified."""
    q, qd, qdd = _motion(6, seed=2)
    t = np.arange(q.shape[0]) * DT
    q[:, 5] = 0.5 * t + 0.05 * np.sin(2 * t)
    qd[:, 5] = 0.5 + 0.1 * np.cos(2 * t)
    qdd[:, 5] = -0.2 * np.sin(2 * t)
    match = r"joint6\.offset is not excited .* kept at its prior 0"
    with pytest.warns(UnexcitedParameterWarning, match=match):
        result = identify(_data(plant, q, qd, qdd), ur5, OPTIONS)
    assert [k.name for k in result.kept] == ["joint6.offset"]
    assert result.friction.offset[5] == 0.0
    truth = base_parameters(ur5, armature=True).project(true_parameters(plant.robot, armature=True))
    assert _relative(result.beta_ls, truth) < EXACT
    np.testing.assert_allclose(result.friction.coulomb, plant.friction.coulomb, rtol=EXACT)
    # the card says which parameter was assumed, from where and why
    from joulepath.identify import parameter_report

    row = parameter_report(result)[5]
    assert row["offset"]["status"] == "assumed" and "condition number" in row["offset"]["reason"]
    assert "no friction known" in row["offset"]["prior"]
    assert all(r["offset"]["status"] == "identified" for r in parameter_report(result)[:5])


def test_an_unexcited_inertial_parameter_keeps_the_nominal_value(ur5, plant):
    """Joint 1 (vertical axis) coasting to rest, qdd1 = -qd1 / T: the inertia about axis 1 (a base
    parameter that regroups it) acts on joint 1 exactly as viscous friction does, so the logs cannot
    tell them apart. The inertia keeps the nominal description's value (a known prior), the viscous
    level is identified. With torque noise (0.05 N·m) as a real log has: exact signals leave the
    weighted refinement too stiff to finish in its step budget."""
    q, qd, qdd = _motion(6, seed=2)
    t = np.arange(q.shape[0]) * DT
    v0, T = 0.6, 2.0
    q[:, 0] = v0 * T * (1.0 - np.exp(-t / T))
    qd[:, 0] = v0 * np.exp(-t / T)
    qdd[:, 0] = -qd[:, 0] / T
    data = _data(plant, q, qd, qdd)
    noisy = replace(data, tau=data.tau + 0.05 * np.random.default_rng(3).standard_normal(data.tau.shape))
    with pytest.warns(UnexcitedParameterWarning) as record:
        result = identify(noisy, ur5, OPTIONS)
    names = [k.name for k in result.kept]
    assert len(record) == len(names)
    base = base_parameters(ur5, armature=True)
    index = {name: i for i, name in enumerate(base.names)}
    inertial = [name for name in names if name in index]
    assert len(inertial) == 1, names
    prior = base.project(true_parameters(ur5, armature=True))
    kept = index[inertial[0]]
    assert result.beta[kept] == pytest.approx(prior[kept], rel=1e-6)
    assert result.beta_ls[kept] == pytest.approx(prior[kept], rel=1e-12)
    # joint 1 turns one way only: its offset is kept (0) too; the other joints' friction is identified
    assert set(names) == {inertial[0], "joint1.offset"}
    assert result.friction.offset[0] == 0.0
    np.testing.assert_allclose(result.friction.viscous[1:], plant.friction.viscous[1:], rtol=0.03)
    np.testing.assert_allclose(result.friction.coulomb, plant.friction.coulomb, rtol=0.03)


def test_identify_and_evaluate_a_named_arm_on_the_command_line(ur5, plant, tmp_path, capsys):
    """``identify LOG --robot ur5`` writes robot.urdf; ``evaluate --robot TWIN`` scores a held-out log;
    ``optimize --robot TWIN --energy electrical`` plans on the twin with the UR5's drive data."""
    logs = []
    for seed in (2, 41):
        q, qd, qdd = _motion(6, seed=seed)
        tau = plant.drive_torque(q, qd, qdd)
        cols = {"t": np.arange(q.shape[0]) * DT}
        for i in range(6):
            for name, arr in (("q", q), ("dq", qd), ("ddq", qdd), ("tau", tau)):
                cols[f"{name}{i + 1}"] = arr[:, i]
        path = tmp_path / f"ur5-{seed}.csv"
        rows = np.column_stack(list(cols.values()))
        path.write_text(
            ",".join(cols) + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n"
        )
        logs.append(path)
    twin = tmp_path / "twin"
    args = ["identify", str(logs[0]), "--robot", "ur5", "--out", str(twin), "--gear-efficiency", "1"]
    assert main(args) == 0
    assert (twin / TWIN_URDF_FILE).is_file() and not (twin / "robot.irml").exists()
    capsys.readouterr()
    assert main(["evaluate", str(logs[1]), "--robot", str(twin), "--out", str(tmp_path / "ev")]) == 0
    out = capsys.readouterr().out
    r2 = json.loads((tmp_path / "ev" / "evaluate.json").read_text())["torque"]["r2"]
    assert min(r2) > 0.999, out
    task = ["--start", "0,-60,60,0,40,0", "--end", "60,-80,40,20,60,30", "--degrees", "--duration", "2"]
    quick = ["--knot-spacing", "0.1", "--energy", "electrical"]
    assert main(["optimize", *task, *quick, "--robot", str(twin), "--out", str(tmp_path / "opt")]) == 0
    result = json.loads((tmp_path / "opt" / "result.json").read_text())
    assert result["energy_measure"] == "electrical" and "identified twin of ur5" in result["physics_model"]
    assert result["limits_ok"] and result["energy_optimized_J"] <= result["energy_default_J"]
