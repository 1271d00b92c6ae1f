"""``joulepath stream`` against the emulated controller on 127.0.0.1; faults exit 2 with one line."""

import json
import shutil
import socket
import threading

import numpy as np
import pytest

pytest.importorskip("abb_robot_client._egm_protobuf.egm_pb2")

from joulepath.cli import main  # noqa: E402
from joulepath.egm import EmulatorConfig, read_plan, run_emulator  # noqa: E402


def free_port():
    """An ephemeral UDP port of 127.0.0.1 that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return str(s.getsockname()[1])


def run_cli(args, emulator=None):
    """``main(args)`` in a thread; the emulated controller (if any) plays against its port."""
    out = {}
    thread = threading.Thread(target=lambda: out.update(rc=main(args)), daemon=True)
    thread.start()
    log = None
    if emulator is not None:
        port = int(args[args.index("--port") + 1])
        log = run_emulator(("127.0.0.1", port), emulator)
    thread.join(60)
    assert not thread.is_alive()
    return out["rc"], log


@pytest.fixture
def folder(egm_run, tmp_path):
    out = tmp_path / "run"
    shutil.copytree(egm_run, out)
    return out


def emulator_for(folder, **kw):
    start = np.degrees(read_plan(folder / "path.csv").start)
    return EmulatorConfig(q_start_deg=tuple(start + kw.pop("offset", 0.0)), wall_period_s=0.001, **kw)


def test_cli_stream_streams_and_reports(folder, capsys):
    port = free_port()
    rc, log = run_cli(["stream", str(folder), "--port", port, "--timeout", "5"], emulator_for(folder))
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    assert "1/1 runs streamed" in cap.out and "listening on udp 127.0.0.1:" in cap.out
    summary = json.loads((folder / "stream.json").read_text())
    assert summary["outcome"] == "done" and summary["datagrams"]["parsed"] == log.answered
    assert cap.err == ""


def one_error_line(err):
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ")
    return lines[0]


def test_cli_stream_refuses_a_robot_away_from_the_start(folder, capsys):
    port = free_port()
    offset = np.array([2.0, 0, 0, 0, 0, 0])
    rc, _ = run_cli(["stream", str(folder), "--port", port], emulator_for(folder, offset=offset))
    assert rc == 2
    line = one_error_line(capsys.readouterr().err)
    assert "from the path's start" in line
    assert json.loads((folder / "stream.json").read_text())["outcome"] == "fault"


def test_cli_stream_silence_exits_2_with_the_log_written(folder, capsys):
    port = free_port()
    emulator = emulator_for(folder, silent_after_s=0.5, silence_s=0.8)
    rc, _ = run_cli(["stream", str(folder), "--port", port, "--timeout", "0.3"], emulator)
    assert rc == 2
    assert "no datagram from the controller for 0.3 s" in one_error_line(capsys.readouterr().err)
    assert (folder / "stream.csv").is_file()


def test_cli_stream_refuses_a_plan_over_a_speed_limit(tmp_path, capsys):
    folder = tmp_path / "fast"
    folder.mkdir()
    rows = [f"{k * 0.025},{0.1 + 10 * k * 0.025}" + ",0" * 5 + ",10" + ",0" * 11 for k in range(5)]
    head = "t," + ",".join(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, 7))
    (folder / "path.csv").write_text(head + "\n" + "\n".join(rows) + "\n")
    rc = main(["stream", str(folder), "--port", free_port(), "--robot", "irb120"])
    assert rc == 2
    assert "over its limit" in one_error_line(capsys.readouterr().err)


def test_cli_stream_refuses_a_folder_without_a_plan(tmp_path, capsys):
    rc = main(["stream", str(tmp_path), "--port", free_port()])
    assert rc == 2
    assert "neither path.csv nor cycle_path.csv" in one_error_line(capsys.readouterr().err)
