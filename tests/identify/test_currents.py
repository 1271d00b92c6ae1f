"""Identification from motor currents: drive gains of a UR10e-class plant with a known drive model.

The plant: a UR10e-class arm (UR10e DH and link masses), its links perturbed from the
nominal description (the "real" robot), Coulomb and viscous friction, gears of efficiency
``ETA``, drives of joint-side torque constants ``K`` (N·m/A), current noise, speed noise,
and at rest a holding torque anywhere within a static friction band. Logs at 100 Hz:
an exciting trajectory to identify on, the same robot carrying a known payload (the
reference), a point-to-point log and static poses to validate on.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import joulepath
from joulepath.cli import main
from joulepath.data import generic_log_text
from joulepath.description import Inertial, JointDescription, RobotDescription, irml_string
from joulepath.dynamics import IdentifiedFriction, motor_torque
from joulepath.energy import read_drives_file
from joulepath.errors import InvalidInput, InvalidLog
from joulepath.identify import (
    MAX_GAIN_ERROR,
    DriveGainFit,
    IdentificationData,
    PayloadReference,
    data_from_logs,
    design_excitation,
    evaluate_model,
    fit_drive_gains,
    gear_side_speed,
    identified_drives,
    identify,
    logged_signal,
    read_drive_gains,
)
from joulepath.sim._plants import perturbed_robot

RATE = 100.0
DH = (  # d, r (DH a), alpha: UR10e
    (0.1807, 0.0, np.pi / 2),
    (0.0, -0.6127, 0.0),
    (0.0, -0.57155, 0.0),
    (0.17415, 0.0, np.pi / 2),
    (0.11985, 0.0, -np.pi / 2),
    (0.11655, 0.0, 0.0),
)
MASS = (7.369, 13.051, 3.989, 2.1, 1.98, 0.615)
COM = ((0.021, 0.0, 0.027), (0.38, 0.0, 0.158), (0.24, 0.0, 0.068), (0.0, 0.007, 0.018), (0.0, 0.007, 0.018))
INERTIA = (
    (0.034, 0.034, 0.021),
    (0.04, 0.43, 0.43),
    (0.01, 0.11, 0.11),
    (0.004, 0.004, 0.003),
    (0.004, 0.004, 0.003),
)
WRIST3 = ((0.0, 0.0, -0.026), (0.0005, 0.0005, 0.0008))
TOOL = (2.6, (0.03, 0.01, 0.06), (0.01, 0.01, 0.005))
"""Link 6 with a gripper mounted (mass, centre of mass, inertia diagonal): torque on every joint."""
SPEED = np.radians((120, 120, 180, 180, 180, 180))
EFFORT = (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)

K = np.array([14.9, 14.9, 10.6, 7.6, 7.6, 7.6])
"""The plant's joint-side torque constants, N·m/A."""
R = (0.3, 0.3, 0.5, 1.0, 1.0, 1.0)
ETA = 0.9
FRICTION = IdentifiedFriction(
    coulomb=(6.0, 6.0, 4.0, 1.5, 1.5, 1.5),
    viscous=(8.0, 8.0, 5.0, 1.0, 1.0, 1.0),
    offset=(0.0,) * 6,
    stribeck=(0.0,) * 6,
)
STATIC = np.array([3.0, 3.0, 2.0, 0.8, 0.8, 0.8])
"""N·m: a joint at rest holds anywhere within this band around its model torque."""
NOISE_A = 0.03
NOISE_SPEED = 0.001
PAYLOAD = (5.0, (0.05, 0.02, 0.08))
K_TOLERANCE = 0.03
"""The recovered k must be within 3 % of the plant's (typical errors measured: ≤ 2 %)."""


def ur10e(*, tool: bool = False, mass_scale: float = 1.0) -> RobotDescription:
    """A UR10e-class description (DH, masses and centres of mass of UR's published UR10e data)."""
    wrist3 = (TOOL[0], TOOL[1], TOOL[2]) if tool else (MASS[5], *WRIST3)
    links = [(MASS[j], COM[j], INERTIA[j]) for j in range(5)] + [wrist3]
    joints = tuple(
        JointDescription(
            id=j + 1,
            type="R",
            xi=1,
            variable=f"q{j + 1}",
            d=d,
            r=r,
            alpha=a,
            inertial=Inertial.from_arrays(mass_scale * m, c, mass_scale * np.diag(i)),
            lower=-2 * np.pi,
            upper=2 * np.pi,
            velocity=float(SPEED[j]),
            effort=EFFORT[j],
        )
        for j, ((d, r, a), (m, c, i)) in enumerate(zip(DH, links, strict=True))
    )
    return RobotDescription(
        name="UR10e-class", manufacturer="test", info=(("carrying-capacity", "12.5"),), joints=joints
    )


def _currents(real, q, qd, qdd, rng, payload=None, *, noise=True):
    """The plant's motor currents (A) of a motion (exact signals in; measurement noise added)."""
    robot = real if payload is None else real.with_payload(*payload)
    tau = robot.inverse_dynamics(q, qd, qdd) + FRICTION.torque(qd)
    if noise:
        rest = np.all(qd == 0.0, axis=1)
        run = np.cumsum(np.r_[True, rest[1:] != rest[:-1]])
        held = rng.uniform(-1, 1, (run.max() + 1, q.shape[1])) * STATIC  # one draw per rest
        tau = tau + np.where(rest[:, None], held[run], 0.0)
    i = motor_torque(tau, qd, ETA) / K
    return i + NOISE_A * rng.standard_normal(i.shape) if noise else i


def _point_to_point(poses, *, move_s, rest_s):
    """Quintic moves between poses with rests before, between and after (exact q, qd, qdd)."""
    s = np.arange(int(move_s * RATE)) / (move_s * RATE)
    shape = (
        10 * s**3 - 15 * s**4 + 6 * s**5,
        (30 * s**2 - 60 * s**3 + 30 * s**4) / move_s,
        (60 * s - 180 * s**2 + 120 * s**3) / move_s**2,
    )
    n_rest = int(rest_s * RATE)
    zero = np.zeros((n_rest, poses.shape[1]))
    parts: list[list[np.ndarray]] = [[], [], []]
    for a, b in zip(poses[:-1], poses[1:], strict=True):
        parts[0] += [np.repeat(a[None], n_rest, 0), a + np.outer(shape[0], b - a)]
        parts[1] += [zero, np.outer(shape[1], b - a)]
        parts[2] += [zero, np.outer(shape[2], b - a)]
    parts[0].append(np.repeat(poses[-1][None], n_rest, 0))
    parts[1].append(zero)
    parts[2].append(zero)
    q, qd, qdd = (np.concatenate(p) for p in parts)
    return np.arange(q.shape[0]) / RATE, q, qd, qdd


def _poses(rng, n):
    out = rng.uniform(-1, 1, (n, 6)) * np.array([2.0, 1.0, 1.5, 1.5, 1.5, 2.0])
    out[:, 1] -= 1.2  # the upper arm mostly above the horizontal
    return out


def _exciting(robot, seed):
    design = design_excitation(
        robot, harmonics=4, base_hz=0.1, range_set="nominal", iterations=0, margin=0.6, seed=seed
    )
    t = np.arange(0.0, 10.0, 1.0 / RATE)
    return (t, *design.trajectory.evaluate(t))


@pytest.fixture(scope="module")
def plant(tmp_path_factory):
    """Logs of the plant, the nominal description with a drives file beside it (assumed k)."""
    folder = tmp_path_factory.mktemp("ur10e")
    nominal_file = folder / "ur10e.irml"
    nominal_file.write_text(irml_string(ur10e()))
    (folder / "ur10e.drives.toml").write_text(
        "torque_constant = [10.0, 10.0, 10.0, 5.0, 5.0, 5.0]\n"
        f'resistance = {list(R)}\ndrive_efficiency = 0.95\nbus = "bleeder"\nstandby_W = 90.0\n'
        '[sources]\nresistance = "the test plant"\ntorque_constant = "assumed: a guess"\n'
    )
    nominal = joulepath.load_robot(nominal_file)
    rng = np.random.default_rng(0)
    real = perturbed_robot(nominal, rng)

    def write(name, t, q, qd, qdd, payload=None):
        current = _currents(real, q, qd, qdd, rng, payload)
        path = folder / f"{name}.csv"
        path.write_text(
            generic_log_text(t, q, qd + NOISE_SPEED * rng.standard_normal(qd.shape), None, current=current)
        )
        return path

    logs = {
        "excite": write("excite", *_exciting(nominal, 1)),
        "payload": write("payload", *_exciting(nominal, 2), payload=PAYLOAD),
        "p2p": write("p2p", *_point_to_point(_poses(rng, 7), move_s=1.5, rest_s=0.6)),
        "static": write("static", *_point_to_point(_poses(rng, 10), move_s=2.5, rest_s=1.0)),
    }
    return {"folder": folder, "nominal": nominal_file, "robot": nominal, "real": real, **logs}


def _identify_cli(plant, out, *extra):
    return main(
        ["identify", str(plant["excite"]), "--robot", str(plant["nominal"]), "--out", str(out), *extra]
    )


def test_done_when_ur10e_class_drive_model_from_a_payload_reference(plant, tmp_path, capsys):
    """identify (payload reference) gives k; evaluate reaches current R² ≥ 0.9 and holds 9 of 10 poses."""
    twin = tmp_path / "twin"
    payload = [
        "--payload-log",
        str(plant["payload"]),
        "--payload-mass",
        "5",
        "--payload-com",
        "0.05,0.02,0.08",
    ]
    assert _identify_cli(plant, twin, *payload) == 0
    out = capsys.readouterr().out
    assert "scale reference: payload (payload of 5 kg at (0.05, 0.02, 0.08) m" in out
    drives = read_drives_file(twin / "drives.toml", 6)
    k = np.array(drives.torque_constant)
    np.testing.assert_allclose(k, K, rtol=K_TOLERANCE)
    assert drives.source("torque_constant").startswith("identified from excite.csv, payload.csv")
    assert drives.resistance == R and drives.source("resistance") == "the test plant"  # kept
    assert drives.source("drive_efficiency") == "assumed"
    card = json.loads((twin / "card.json").read_text())
    assert card["drive_gains"]["reference"] == "payload" and card["signal"] == "current"
    assert max(card["drive_gains"]["relative_error"]) <= MAX_GAIN_ERROR
    # the twin is a robot whose drives are the identified ones (what optimize --energy electrical uses)
    loaded = joulepath.load_robot(twin)
    assert loaded.drives is not None and loaded.drives.torque_constant == drives.torque_constant
    gains = read_drive_gains(twin / "drives.toml", 6)
    p2p = evaluate_model(plant["p2p"], loaded, robot_source=str(twin), drives=gains)
    assert np.mean(p2p.current_r2) >= 0.9
    static = evaluate_model(plant["static"], loaded, robot_source=str(twin), drives=gains)
    assert len(static.poses) == 10  # each pose held 1 s, 2.5 s moves between
    hits = static.holding_summary("i")["share_of_poses_predicted"]
    assert hits[1] >= 0.9 and hits[2] >= 0.9  # shoulder and elbow: 15 % or 0.3 A


def test_exact_currents_give_the_plant_k_exactly(plant):
    """Noise-free currents (no rest in the samples): the payload reference recovers k and eta."""
    robot, real = plant["robot"], plant["real"]
    rng = np.random.default_rng(3)

    def data(seed, payload=None):
        t, q, qd, qdd = _exciting(robot, seed)
        keep = np.abs(qd).max(axis=1) > np.radians(1.0)  # the trajectory's ends at rest left out
        current = _currents(real, q, qd, qdd, rng, payload, noise=False)
        return IdentificationData.from_arrays(
            q[keep], qd[keep], qdd[keep], current[keep], 1 / RATE, signal="current"
        )

    reference = PayloadReference(data=data(2, PAYLOAD), mass=PAYLOAD[0], com=PAYLOAD[1])
    gains = fit_drive_gains(data(1), robot, payload=reference)
    np.testing.assert_allclose(gains.torque_constant, K, rtol=1e-6)
    assert gains.gear_efficiency == pytest.approx(ETA, abs=1e-5)
    assert gains.reference == "payload" and "5 kg" in gains.reference_note


def test_nominal_reference_scales_k_with_the_nominal_masses(tmp_path):
    """With the nominal masses as reference, k follows them: masses 10 % heavier, k 10 % larger."""
    true = joulepath.load_robot(_write(tmp_path / "true.irml", ur10e(tool=True)))
    heavy = joulepath.load_robot(_write(tmp_path / "heavy.irml", ur10e(tool=True, mass_scale=1.1)))
    t, q, qd, qdd = _exciting(true, 1)
    keep = np.abs(qd).max(axis=1) > np.radians(1.0)
    current = _currents(true, q, qd, qdd, np.random.default_rng(0), noise=False)
    data = IdentificationData.from_arrays(
        q[keep], qd[keep], qdd[keep], current[keep], 1 / RATE, signal="current"
    )
    exact = fit_drive_gains(data, true)
    assert exact.reference == "nominal" and "nominal masses" in exact.reference_note
    np.testing.assert_allclose(exact.torque_constant, K, rtol=1e-3)
    scaled = fit_drive_gains(data, heavy)
    np.testing.assert_allclose(np.array(scaled.torque_constant) / exact.torque_constant, 1.1, rtol=1e-3)


def _write(path, description):
    path.write_text(irml_string(description))
    return path


def test_refusals(plant, tmp_path, capsys):
    """What cannot be identified is refused in one line (exit 2), and nothing is written."""
    cases = [
        (["--payload-log", str(plant["payload"])], "needs the payload's --payload-mass KG and --payload-com"),
        (["--payload-mass", "5"], "describe the payload of --payload-log; give the log"),
        (
            ["--payload-log", str(plant["payload"]), "--payload-mass", "5", "--payload-com", "0.05,0"],
            "--payload-com '0.05,0': give three numbers",
        ),
        (  # 20 g: the payload's effect is below the noise
            ["--payload-log", str(plant["payload"]), "--payload-mass", "0.02", "--payload-com", "0,0,0.01"],
            "below the noise",
        ),
    ]
    for k, (extra, message) in enumerate(cases):
        out = tmp_path / f"twin{k}"
        assert _identify_cli(plant, out, *extra) == 2
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err
        assert not out.exists()


def test_done_when_a_weak_wrist_keeps_a_stated_prior_without_a_payload_log(plant, tmp_path, capsys):
    """No payload log, a bare wrist 3 (its torque is friction and noise): the twin is written,
    wrist 3's k is stated as assumed (shared with wrist 1, the same motor) in one warning line
    and on the card, and evaluate on a second log of the arm gives a mean current R² >= 0.9."""
    twin = tmp_path / "twin"
    assert _identify_cli(plant, twin) == 0
    captured = capsys.readouterr()
    warnings = [line for line in captured.err.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 1 and warnings[0].startswith("warning: joint 6: the log does not fix its torque")
    assert "joint 4 (same motor" in warnings[0]
    said = next(line for line in captured.out.splitlines() if line.startswith("assumed, not identified:"))
    assert "joint 6: torque_constant" in said and "joint 5: torque_constant" not in said
    card = json.loads((twin / "card.json").read_text())
    rows = {row["joint"]: row for row in card["parameters"]}
    assert [rows[j]["torque_constant"]["status"] for j in range(1, 7)] == ["identified"] * 5 + ["assumed"]
    assert rows[6]["torque_constant"]["prior"].startswith("joint 4 (same motor")
    assert all(rows[j]["coulomb"]["status"] == "identified" for j in rows)
    assert rows[1]["resistance"] == {"status": "given", "value": R[0], "source": "the test plant"}
    assert rows[1]["drive_efficiency"]["status"] == "assumed"  # the drives file gives no source
    assert card["drive_gains"]["assumed"][0]["joint"] == 6
    k = np.array(read_drives_file(twin / "drives.toml", 6).torque_constant)
    assert k[5] == k[3]  # one motor, one k
    np.testing.assert_allclose(k, K, rtol=0.05)  # the nominal masses' error (the plant is perturbed)
    ev = tmp_path / "ev"
    assert main(["evaluate", str(plant["p2p"]), "--robot", str(twin), "--out", str(ev)]) == 0
    summary = json.loads((ev / "evaluate.json").read_text())
    assert len(summary["current"]["r2"]) == 6 and summary["current"]["r2_mean"] >= 0.9
    assert "current R² per joint:" in capsys.readouterr().out


def test_a_weak_joint_takes_the_data_sheet_k_or_is_refused_without_a_prior(plant, tmp_path):
    """The drives file's k (a data sheet) is the prior where it is given; without it and without a
    joint of the same motor, the weak joint is refused, naming both ways out."""
    from dataclasses import replace as swap

    data = data_from_logs([plant["excite"]], plant["robot"], signal="current")
    data = data.subset(np.arange(data.n_samples) % 2 == 0)  # every other sample: half the time
    sheet = tmp_path / "sheet"
    sheet.mkdir()
    (sheet / "ur.irml").write_text(irml_string(ur10e()))
    (sheet / "ur.drives.toml").write_text(
        f"torque_constant = {[float(v) for v in K * 1.02]}\nresistance = {list(R)}\n"
        'drive_efficiency = 0.95\nbus = "bleeder"\n'
        '[sources]\ntorque_constant = "data sheet of the test drives"\n'
    )
    gains = fit_drive_gains(data, joulepath.load_robot(sheet / "ur.irml"))
    assert [a.joint for a in gains.assumed] == [6] and gains.status(6) == "assumed"
    assert gains.torque_constant[5] == pytest.approx(K[5] * 1.02)
    assert gains.assumed[0].prior == "the data sheet (data sheet of the test drives)"
    assert gains.assumed[0].tied_to is None and np.isnan(gains.relative_error[5])
    desc = ur10e()
    own = swap(desc, joints=(*desc.joints[:5], swap(desc.joints[5], effort=28.0)))  # a motor of its own
    with pytest.raises(InvalidInput, match=r"joint 6 .*no prior for it.*give a payload log.*data sheet"):
        fit_drive_gains(data, joulepath.load_robot(_write(tmp_path / "own.irml", own)))


def test_same_motor_pairs_joints_of_equal_ratings_and_drive_data(plant):
    from joulepath.identify import same_motor

    assert same_motor(plant["robot"]) == ((1,), (0,), (), (4, 5), (3, 5), (3, 4))  # R of joint 3 differs


def test_current_data_refused_where_torques_are_needed(plant):
    data = data_from_logs([plant["excite"]], plant["robot"], signal="current")
    assert data.signal == "current" and data.unit == "A"
    with pytest.raises(InvalidInput, match="hold motor currents"):
        identify(data, plant["robot"])
    with pytest.raises(InvalidLog, match="no joint torques"):
        data_from_logs([plant["excite"]], plant["robot"])
    scaled = data.scaled(K)
    assert scaled.signal == "torque"
    np.testing.assert_allclose(scaled.tau, data.tau * K)
    with pytest.raises(InvalidInput, match="only motor currents are scaled"):
        scaled.scaled(K)


def test_logged_signal_of_mixed_logs(plant, tmp_path):
    assert logged_signal([plant["excite"]]) == "current"
    t = np.arange(5) / RATE
    torques = tmp_path / "torques.csv"
    torques.write_text(generic_log_text(t, np.zeros((5, 6)), np.zeros((5, 6)), np.ones((5, 6))))
    assert logged_signal([torques]) == "torque"
    with pytest.raises(InvalidLog, match="identify from one kind of log"):
        logged_signal([plant["excite"], torques])


def test_gear_side_speed_counts_only_the_whole_arm_at_rest():
    qd = np.array([[0.001, -0.001, 0.0], [0.001, 0.5, 0.0], [-0.3, 0.0, 0.2]])
    np.testing.assert_array_equal(gear_side_speed(qd), [[0.0, 0.0, 0.0], [0.001, 0.5, 0.0], [-0.3, 0.0, 0.2]])


def test_identified_drives_keep_or_assume_the_rest(plant):
    gains = _dummy_gains()
    nominal = joulepath.load_robot(plant["nominal"]).drives
    kept = identified_drives(gains, nominal, 6)
    assert kept.torque_constant == gains.torque_constant and kept.resistance == R
    assert kept.source("resistance") == "the test plant" and kept.source("torque_constant").startswith(
        "identified"
    )
    bare = identified_drives(gains, None, 6)
    assert bare.resistance == (0.0,) * 6 and bare.source("resistance").startswith("assumed: unknown")
    assert "assumed" in bare.describe()


def _dummy_gains():
    return DriveGainFit(
        torque_constant=tuple(K),
        relative_error=(0.01,) * 6,
        gear_efficiency=ETA,
        reference="payload",
        reference_note="a test payload",
        sources=("a.csv",),
    )
