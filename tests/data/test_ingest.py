"""Ingestion into the energy table: schema, energies against the dynamics model, real KUKA logs."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import joulepath
from joulepath.data import (
    FEATURES_FULL,
    FEATURES_JOINT,
    ingest,
    load_table,
    read_log,
    save_table,
    segment_moves,
    table_columns,
)
from joulepath.errors import InvalidLog
from joulepath.export import draw_moves
from joulepath.sim import measure, simulate

KUKA = Path(__file__).parents[3] / "shared" / "datasets" / "kuka-kr300-weigand"


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("plants")
    return {p: simulate(d / f"{p}.csv", plant=p, n_moves=40, seed=5) for p in ("sim", "lab")}


def test_feature_order_is_appendix_f():
    assert len(FEATURES_FULL) == 40
    assert FEATURES_FULL[:4] == ("q1", "dq1", "q2", "dq2")
    assert FEATURES_FULL[12:22] == ("x", "y", "z", "qx", "qy", "qz", "qw", "yaw", "pitch", "roll")
    assert FEATURES_FULL[-3:] == ("ddphi", "ddtheta", "ddpsi")
    assert len(FEATURES_JOINT) == 18


@pytest.mark.parametrize("plant", ["sim", "lab"])
def test_ingest_plants_full40(logs, plant, irb120, tmp_path):
    table = ingest([logs[plant].log], robot=irb120)
    assert table.feature_set == "full40"
    assert list(table.frame.columns) == list(table_columns("full40"))
    assert np.isfinite(table.frame.to_numpy(dtype=float)).all()
    out = save_table(table, tmp_path / "t.parquet")
    again = load_table(out)
    pd.testing.assert_frame_equal(again.frame, table.frame)
    assert again.fingerprint() == table.fingerprint() and again.robot == "IRB 120"


def test_sim_log_energy_agrees_with_dynamics_model(irb120):
    """The sim plant's logged energy = the dynamics model (plus its friction) on the logged motion."""
    rng = np.random.default_rng(3)
    moves = draw_moves(irb120, 15, rng=rng)
    from joulepath.sim import log_text, make_plant

    plan, measured = measure(irb120, "sim", moves, rng=rng)
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "sim.csv"
        p.write_text(log_text(irb120, measured))
        table = ingest([p], robot=irb120)
    plant = make_plant("sim", irb120)
    kept = np.isin(measured.t, table.frame["t"].to_numpy()) | np.isclose(
        measured.t[:, None], table.frame["t"].to_numpy()[None, :], atol=1e-5
    ).any(axis=1)
    tau = irb120.inverse_dynamics(measured.q, measured.qd, measured.qdd) + plant.friction.torque(measured.qd)
    dt = np.r_[np.diff(measured.t), np.diff(measured.t)[-1]]
    model = (np.abs(tau * measured.qd) * dt[:, None])[kept].sum()
    logged = table.frame["E"].sum()
    assert logged == pytest.approx(model, rel=2e-3)  # only the 5-decimal printing differs


def test_lab_log_differs_from_the_nominal_model(logs, irb120):
    """The lab plant is not the twin: its torques (and energies) sit off the nominal model's."""
    log = read_log(logs["lab"].log)
    table = ingest([logs["lab"].log], robot=irb120)
    qdd = np.gradient(log.qd, log.t, axis=0)
    nominal = irb120.inverse_dynamics(log.q, log.qd, qdd)
    gap = np.abs(log.tau - nominal).mean(axis=0)
    assert gap[1] > 0.3  # shoulder: perturbed masses, flange adapter, friction, gear losses
    assert table.frame["E"].sum() > 0


def test_move_segmentation_recovers_programmed_moves(logs, irb120):
    truth = pd.read_csv(logs["sim"].moves)
    log = read_log(logs["sim"].log)
    labels = segment_moves(log.t, log.qd, speed_scale=irb120.velocity_limit)
    starts = log.t[np.r_[True, labels[1:] != labels[:-1]] & (labels >= 0)]
    ts, te = truth.t_start.to_numpy(), truth.t_end.to_numpy()
    expected = np.r_[ts[0], np.where(ts[1:] < te[:-1], 0.5 * (ts[1:] + te[:-1]), ts[1:])]
    dist = np.abs(starts[:, None] - expected[None, :])
    found = (dist.min(axis=0) < 0.25).mean()
    spurious = (dist.min(axis=1) >= 0.25).mean()
    assert found >= 0.85 and spurious <= 0.1, (found, spurious)


def test_segment_moves_fine_stops_exact():
    t = np.arange(300) * 0.025
    qd = np.zeros((300, 6))
    for a, b in ((10, 60), (80, 150), (170, 260)):
        qd[a:b, 0] = np.sin(np.linspace(0, np.pi, b - a))
    labels = segment_moves(t, qd)  # sin(0) = 0: each move sets off one sample after a
    assert labels[:11].tolist() == [-1] * 11
    assert [int(np.argmax(labels == k)) for k in range(3)] == [11, 81, 171]
    assert labels[-1] == 2  # the last move keeps its trailing rest


def test_ingest_robot_mismatch_is_refused(logs):
    from dataclasses import replace

    from joulepath.description import chain_from_description, preset_description

    desc = preset_description("irb120")
    bigger = replace(desc, joints=tuple(replace(j, d=j.d * 1.5) for j in desc.joints))
    robot = joulepath.Robot(chain_from_description(bigger), description=bigger)
    with pytest.raises(InvalidLog, match=r"TCP columns x, y, z are [\d.]+ mm \(median\) away from"):
        ingest([logs["sim"].log], robot=robot)


def test_ingest_bad_log_writes_nothing(tmp_path, logs, capsys):
    from joulepath.cli import main

    bad = tmp_path / "bad.csv"
    bad.write_text(logs["sim"].log.read_text()[:-30])  # truncated last line
    out = tmp_path / "table.parquet"
    assert main(["ingest", str(logs["sim"].log), str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.csv: line" in err[0] and "truncated" in err[0]
    assert not out.exists() and list(tmp_path.iterdir()) == [bad]


def test_load_table_refuses_wrong_columns(tmp_path, logs, irb120):
    table = ingest([logs["sim"].log], robot=irb120)
    frame = table.frame.drop(columns=["ddq3"]).assign(extra=1.0)
    from joulepath.data import EnergyTable

    p = save_table(EnergyTable(frame=frame, feature_set="full40"), tmp_path / "x.parquet")
    with pytest.raises(InvalidLog, match=r"missing column\(s\) ddq3; unexpected column\(s\) extra"):
        load_table(p)


def _kuka_to_generic_csv(mat: Path, out: Path) -> Path:
    """Convert one Weigand KR300 .mat recording to the documented generic CSV (SI, joint side)."""
    from scipy.io import loadmat

    data = loadmat(mat, squeeze_me=True, struct_as_record=False)
    rec, para = data["rec"], data["para"]
    t = np.asarray(rec.time_cont, float)
    q = np.radians(np.asarray(rec.act_pos_mot_deg, float)).T
    qd = np.radians(np.asarray(rec.act_vel_mot_deg_per_s, float)).T
    gear = np.asarray(para.u, float).ravel()[:6]
    tau = np.asarray(rec.act_torque_abs_nm, float).T * gear  # motor side -> joint side
    keep = np.r_[True, np.diff(t) > 0]
    header = "t," + ",".join(f"q{i},dq{i},tau{i}" for i in range(1, 7))
    rows = np.column_stack([t] + [c for j in range(6) for c in (q[:, j], qd[:, j], tau[:, j])])[keep]
    np.savetxt(out, rows, delimiter=",", header=header, comments="", fmt="%.9g")
    return out


@pytest.mark.skipif(not KUKA.exists(), reason="../shared/datasets not present")
def test_ingest_real_kuka_kr300_logs(tmp_path):
    paths = [_kuka_to_generic_csv(m, tmp_path / f"{m.stem}.csv") for m in sorted(KUKA.glob("*.mat"))]
    table = ingest(paths)
    assert table.feature_set == "joint"
    assert list(table.frame.columns) == list(table_columns("joint"))
    values = table.frame.to_numpy(dtype=float)
    assert np.isfinite(values).all()
    assert table.frame["E"].sum() > 0 and len(table.frame) > 7000
    assert [s["kind"] for s in table.sources] == ["generic"] * 3
