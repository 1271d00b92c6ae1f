"""End to end on 127.0.0.1: the server (thread) and the emulated controller on the fixed task; faults."""

import json
import math
import shutil
import threading

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import CubicHermiteSpline

pytest.importorskip("abb_robot_client._egm_protobuf.egm_pb2")

from joulepath.egm import (  # noqa: E402
    STREAM_CSV,
    STREAM_JSON,
    EmulatorConfig,
    RobotMessage,
    ServeConfig,
    StreamSettings,
    UdpEndpoint,
    decode_sensor,
    encode_robot,
    executed_energy,
    read_plan,
    run_emulator,
    serve,
    stream_run,
)
from joulepath.errors import LimitViolation, StreamAborted  # noqa: E402

PERIOD = 0.004


def run_stream(folder, background, *, emulator=None, settings=None, timeout_s=2.0, robot=None):
    """Serve ``folder`` in a thread and play the controller against it: (server, emulator log, summary)."""
    plan = read_plan(folder / ("path.csv" if (folder / "path.csv").exists() else "cycle_path.csv"))
    config = ServeConfig(host="127.0.0.1", port=0, timeout_s=timeout_s, settings=settings or StreamSettings())
    server = background(lambda listening: stream_run(folder, config, robot=robot, on_listening=listening))
    address = server.wait_listening()
    options = {"q_start_deg": tuple(np.degrees(plan.start)), "wall_period_s": 0.001, **(emulator or {})}
    log = run_emulator(address, EmulatorConfig(**options))
    server.join()
    summary = json.loads((folder / STREAM_JSON).read_text())
    return server, log, summary


@pytest.fixture
def run_folder(egm_run, tmp_path):
    out = tmp_path / "run"
    shutil.copytree(egm_run, out)
    return out


def test_stream_fixed_task_matches_the_plan_on_the_controller_clock(run_folder, background):
    server, log, s = run_stream(run_folder, background)
    assert server.error is None and s["outcome"] == "done"
    plan_csv = pd.read_csv(run_folder / "path.csv")
    n = 6
    t = plan_csv["t"].to_numpy()
    q = plan_csv[[f"q{i}" for i in range(1, n + 1)]].to_numpy()
    qd = plan_csv[[f"qd{i}" for i in range(1, n + 1)]].to_numpy()
    rows = pd.read_csv(run_folder / STREAM_CSV)
    run = rows[rows["phase"] == "run"]
    assert len(run) >= round(1.6 / PERIOD) - 1
    ref = run[[f"q_ref{i}" for i in range(1, n + 1)]].to_numpy()
    t_run = run["t"].to_numpy() - run["t"].to_numpy()[0]  # controller time since the run began
    # at the controller times that fall on path.csv's samples, the reference is the sample
    on_sample = np.isclose(t_run[:, None], t[None, :], atol=1e-6)
    k_ref, k_plan = np.nonzero(on_sample)
    assert k_ref.size >= 15
    assert np.degrees(np.abs(ref[k_ref] - q[k_plan])).max() < 0.05
    # and in between it is the smooth interpolant of path.csv (an independent spline of q, qd)
    spline = CubicHermiteSpline(t, q, qd, axis=0)
    assert np.degrees(np.abs(ref - spline(t_run))).max() < 0.05
    # what the controller received is what the server logged
    got = {round(tt, 6): r for tt, r in zip(log.t, log.ref_deg, strict=True)}
    for tt, r in zip(run["t"], ref, strict=True):
        np.testing.assert_allclose(got[round(tt, 6)], np.degrees(r), atol=1e-9)
    # executed duration: within two control periods of the plan
    hold = rows[rows["phase"].isin(["hold", "done"])]
    measured = hold["t"].iloc[0] - run["t"].iloc[0]
    assert abs(measured - 1.6) <= 2 * PERIOD
    assert abs(s["executed_duration_s"] - 1.6) <= 2 * PERIOD
    assert s["executed_duration_s"] == pytest.approx(measured)
    # executed saving against the default within half a point of the planned one
    result = json.loads((run_folder / "result.json").read_text())
    assert s["saved_planned_pct"] == result["saved_pct"]
    assert abs(s["saved_executed_pct"] - result["saved_pct"]) <= 0.5
    # the server states what it saw
    d = s["datagrams"]
    assert d["received"] == d["parsed"] == d["answered"] == log.answered
    assert d["ignored"] == d["late"] == d["foreign"] == 0
    assert s["repetitions_executed"] == 1 and s["executed_tracking_error_max_deg"] > 0
    assert s["end"]["phase"] == "done"
    assert max(abs(a - b) for a, b in zip(s["end"]["feedback_deg"], np.degrees(q[-1]), strict=True)) <= 0.1


def test_stream_replies_echo_the_controller_stamp_and_count_up(run_folder, background):
    _, log, _ = run_stream(run_folder, background)
    assert list(log.reply_seqnos) == list(range(1, log.answered + 1))
    assert set(log.reply_tms) <= {round(t * 1000) for t in log.t}


def test_executed_energy_of_the_plan_is_its_planned_energy(egm_run, irb120):
    plan = read_plan(egm_run / "path.csv")
    result = json.loads((egm_run / "result.json").read_text())
    s = np.arange(0.0, plan.duration + 1e-9, PERIOD)
    e = executed_energy(irb120, s, plan.at(s)[0])
    assert e == pytest.approx(result["energy_optimized_fine_J"], rel=0.01)


def test_stream_repeats_with_return_moves(run_folder, background):
    _, _, s = run_stream(run_folder, background, settings=StreamSettings(repeats=2))
    assert s["outcome"] == "done" and s["repetitions_executed"] == 2
    phases = set(pd.read_csv(run_folder / STREAM_CSV)["phase"])
    assert "return" in phases
    for rep in s["repetitions"]:
        assert abs(rep["executed_duration_s"] - 1.6) <= 2 * PERIOD
        assert abs(rep["saved_executed_pct"] - s["saved_planned_pct"]) <= 0.5


def write_cycle_path(folder, duration=1.0):
    """A closed path (out and back, rest to rest) as cycle_path.csv, 25 ms samples."""
    folder.mkdir()
    t = np.arange(0.0, duration + 1e-9, 0.025)
    w = 2 * math.pi / duration
    c, s = np.cos(w * t)[:, None], np.sin(w * t)[:, None]
    start = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
    a = np.array([0.4, -0.3, 0.3, 0.5, -0.4, 0.6])
    q = start + a * (1 - c) ** 2 / 4
    qd = a * (1 - c) * s * w / 2
    qdd = a * w**2 / 2 * (s**2 + (1 - c) * c)
    head = "t," + ",".join(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, 7))
    body = "\n".join(",".join(f"{v:.10g}" for v in row) for row in np.column_stack([t, q, qd, qdd]))
    (folder / "cycle_path.csv").write_text(head + "\n" + body + "\n")
    return folder


def test_stream_cycle_folder_repeats_without_return(tmp_path, background):
    folder = write_cycle_path(tmp_path / "cycle")
    _, _, s = run_stream(folder, background, settings=StreamSettings(repeats=3), robot="irb120")
    assert s["outcome"] == "done" and s["repetitions_executed"] == 3
    assert "return" not in set(pd.read_csv(folder / STREAM_CSV)["phase"])
    energies = [r["energy_executed_J"] for r in s["repetitions"]]
    assert all(e > 0 for e in energies)
    assert max(energies) - min(energies) <= 0.01 * max(energies)  # the same motion each time
    assert s["saved_executed_pct"] is None  # no result.json: nothing to compare with
    for rep in s["repetitions"]:
        assert abs(rep["executed_duration_s"] - 1.0) <= 2 * PERIOD


def last_answered_tick(log):
    return int(np.nonzero(~np.isnan(log.ref_deg[:, 0]))[0][-1])


def test_stream_ignores_garbage_and_counts_it(run_folder, background):
    _, log, s = run_stream(run_folder, background, emulator={"garbage_every": 7})
    assert s["outcome"] == "done"
    served = last_answered_tick(log) // 7 + 1  # garbage sent while the server listened
    assert log.garbage_sent >= served > 10
    assert s["datagrams"]["ignored"] == served
    assert s["datagrams"]["ignored_why"] == {"not an EgmRobot": served}
    assert s["datagrams"]["received"] == s["datagrams"]["parsed"] + served
    assert abs(s["saved_executed_pct"] - s["saved_planned_pct"]) <= 0.5


def test_stream_ignores_a_second_sender(run_folder, background):
    _, log, s = run_stream(run_folder, background, emulator={"foreign_every": 5})
    assert s["outcome"] == "done"
    served = last_answered_tick(log) // 5  # sent from the second socket while the server listened
    assert log.foreign_sent >= served > 10
    assert s["datagrams"]["foreign"] == served
    assert log.foreign_answered == 0
    assert abs(s["executed_duration_s"] - 1.6) <= 2 * PERIOD


def test_stream_refuses_a_robot_away_from_the_start(run_folder, background):
    plan = read_plan(run_folder / "path.csv")
    away = np.degrees(plan.start) + np.array([0.0, 1.5, 0.0, 0.0, 0.0, 0.0])
    server, log, s = run_stream(run_folder, background, emulator={"q_start_deg": tuple(away)})
    assert isinstance(server.error, StreamAborted)
    assert "joint 2" in str(server.error) and "from the path's start" in str(server.error)
    assert s["outcome"] == "fault" and "from the path's start" in s["fault"]
    sent = ~np.isnan(log.ref_deg[:, 0])
    step = np.abs(log.ref_deg[sent] - log.q_deg[sent]).max()
    assert step <= StreamSettings().max_step_deg  # never farther than a small step from the robot
    assert np.abs(log.ref_deg[sent][-1] - log.q_deg[sent][-1]).max() < 1e-9  # holds it where it is


def test_stream_silence_holds_writes_the_log_and_stops(run_folder, background):
    server, log, s = run_stream(
        run_folder, background, emulator={"silent_after_s": 0.6, "silence_s": 0.8}, timeout_s=0.3
    )
    assert isinstance(server.error, StreamAborted) and "no datagram" in str(server.error)
    assert s["outcome"] == "fault" and s["repetitions_executed"] == 0
    rows = pd.read_csv(run_folder / STREAM_CSV)
    assert len(rows) == s["datagrams"]["answered"] > 100
    assert rows["t"].iloc[-1] < 1000.6 + 1e-6


def test_stream_refuses_a_plan_outside_the_limits_before_listening(tmp_path, irb120):
    folder = tmp_path / "fast"
    folder.mkdir()
    v = 1.5 * irb120.velocity_limit[0]
    rows = [f"{k * 0.025},{0.1 + v * k * 0.025},0,0,0,0,0,{v},0,0,0,0,0" + ",0" * 6 for k in range(5)]
    head = "t," + ",".join(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, 7))
    (folder / "path.csv").write_text(head + "\n" + "\n".join(rows) + "\n")
    heard = []
    with pytest.raises(LimitViolation, match="over its limit"):
        stream_run(folder, ServeConfig(port=0), robot="irb120", on_listening=heard.append)
    assert heard == []
    assert not (folder / STREAM_JSON).exists()


def test_serve_counts_late_messages_and_answers_the_others(egm_run):
    plan = read_plan(egm_run / "path.csv")
    start = tuple(float(v) for v in np.degrees(plan.start))
    got = {}
    with UdpEndpoint("127.0.0.1", 0) as endpoint, UdpEndpoint("127.0.0.1", 0) as robot:
        config = ServeConfig(port=0, timeout_s=0.5)
        thread = threading.Thread(target=lambda: got.update(s=serve(plan, endpoint, config)), daemon=True)
        thread.start()
        replies = []
        for k, t in enumerate((1000.0, 1000.008, 1000.004, 1000.012)):  # the third is older than the second
            msg = RobotMessage(
                seqno=k,
                tm_ms=round(t * 1000),
                time_s=t,
                joints_deg=start,
                motors_on=True,
                egm_running=False,
                rapid_running=True,
            )
            robot.send(encode_robot(msg), endpoint.address)
            reply = robot.receive(
                0.1 if k == 2 else 1.0
            )  # no answer to the late one: wait less than the timeout
            replies.append(None if reply is None else decode_sensor(reply.data, 6))
        thread.join(10)
    session = got["s"]
    assert session.late == 1 and session.parsed == 3 and session.received == 4
    assert [r is None for r in replies] == [False, False, True, False]
    assert [r.tm_ms for r in replies if r is not None] == [1000000, 1000008, 1000012]
    assert session.fault is not None and "no datagram" in session.fault
