"""Output safety (issue 15, item 3 and defect 2): --out never replaces anything but a file.

Refused with exit 2, one line on stderr and nothing written: device nodes, FIFOs,
sockets, folders where a file goes, the command's own inputs, programs already in
``rapid collect``'s folder (without --force), and folders that cannot be written.
"""

from __future__ import annotations

import os
import socket
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from joulepath._io import atomic_write_bytes, atomic_write_text, check_replaceable
from joulepath.cli import main
from joulepath.errors import InvalidInput
from joulepath.sim import simulate

ROOT = os.geteuid() == 0 if hasattr(os, "geteuid") else False


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    return simulate(tmp_path_factory.mktemp("lab") / "lab.csv", plant="lab", n_moves=3, seed=4)


@pytest.fixture
def null_device(tmp_path) -> Path:
    """A character device like /dev/null that a regression may destroy without harm.

    As root (where the defect replaced the real /dev/null), a private node made
    with mknod; otherwise the real /dev/null, which a non-root process cannot replace.
    """
    if not ROOT:
        return Path("/dev/null")
    node = tmp_path / "null"
    os.mknod(node, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    return node


def _one_line(capsys, args, fragment):
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert fragment in err, err
    return err


def _mtime_and_bytes(p: Path) -> tuple[int, bytes]:
    return p.stat().st_mtime_ns, p.read_bytes()


# --------------------------------------------------------------------------- the writers


def test_atomic_write_refuses_a_fifo_and_leaves_it(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(InvalidInput, match=r"pipe: is a FIFO \(named pipe\), not a regular file"):
        atomic_write_text(fifo, "x")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert [p.name for p in tmp_path.iterdir()] == ["pipe"]  # no temporary file left


def test_atomic_write_refuses_a_socket(tmp_path):
    path = tmp_path / "s.sock"
    with socket.socket(socket.AF_UNIX) as s:
        s.bind(str(path))
        with pytest.raises(InvalidInput, match="is a socket"):
            atomic_write_bytes(path, b"x")
    assert stat.S_ISSOCK(os.lstat(path).st_mode)


def test_check_replaceable_refuses_a_character_device_and_a_link_to_it(tmp_path):
    with pytest.raises(InvalidInput, match=r"/dev/null: is a character device"):
        check_replaceable("/dev/null")
    link = tmp_path / "null.parquet"
    link.symlink_to("/dev/null")
    with pytest.raises(InvalidInput, match="is a character device"):
        atomic_write_text(link, "x")
    assert link.is_symlink()


def test_atomic_write_refuses_a_folder(tmp_path):
    with pytest.raises(InvalidInput, match="is a folder, not a regular file"):
        atomic_write_text(tmp_path, "x")


def test_atomic_write_replaces_a_regular_file(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    atomic_write_text(p, "new")
    assert p.read_text() == "new"


def test_atomic_write_permission_denied_is_one_error(tmp_path, monkeypatch):
    import joulepath._io as io_

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(io_.tempfile, "mkstemp", denied)
    with pytest.raises(InvalidInput, match=r"x\.txt: cannot be written \(Permission denied\)"):
        atomic_write_text(tmp_path / "x.txt", "x")


def test_cli_permission_denied_is_one_line(tmp_path, lab, capsys, monkeypatch):
    import joulepath._io as io_

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(io_.tempfile, "mkstemp", denied)
    out = tmp_path / "t.parquet"
    _one_line(capsys, ["ingest", str(lab.log), "--out", str(out)], "cannot be written (Permission denied)")
    assert not out.exists()


@pytest.mark.skipif(ROOT, reason="root may write anywhere; the monkeypatched test covers it")
def test_cli_unwritable_folder_is_one_line(tmp_path, lab, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        _one_line(capsys, ["ingest", str(lab.log), "--out", str(locked / "t.parquet")], "not writable")
        assert not list(locked.iterdir())
    finally:
        locked.chmod(0o700)


# --------------------------------------------------------------------------- ingest


def test_cli_ingest_out_dev_null_refused(lab, capsys, null_device):
    before = os.stat(null_device)
    _one_line(
        capsys, ["ingest", str(lab.log), "--out", str(null_device)], f"{null_device}: is a character device"
    )
    after = os.stat(null_device)
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev


def test_cli_ingest_out_fifo_refused(tmp_path, lab, capsys):
    fifo = tmp_path / "t.parquet"
    os.mkfifo(fifo)
    _one_line(capsys, ["ingest", str(lab.log), "--out", str(fifo)], "is a FIFO (named pipe)")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_cli_ingest_out_is_its_own_input_refused(tmp_path, lab, capsys):
    log = tmp_path / "log.csv"
    log.write_bytes(lab.log.read_bytes())
    before = _mtime_and_bytes(log)
    _one_line(capsys, ["ingest", str(log), "--out", str(log)], "is also an input of this command")
    assert _mtime_and_bytes(log) == before


def test_cli_ingest_out_is_an_input_by_another_name_refused(tmp_path, lab, capsys, monkeypatch):
    log = tmp_path / "log.csv"
    log.write_bytes(lab.log.read_bytes())
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path / "sub")
    hard = tmp_path / "hard.parquet"
    os.link(log, hard)  # the same file under a second name
    _one_line(capsys, ["ingest", "../log.csv", "--out", str(hard)], "is also an input of this command")
    _one_line(
        capsys, ["ingest", "../log.csv", "--out", str(tmp_path / "sub" / ".." / "log.csv")], "also an input"
    )
    assert log.read_bytes() == lab.log.read_bytes()


# --------------------------------------------------------------------------- simulate, rapid, synth, compare


def test_cli_simulate_refuses_dev_null_and_its_sidecar_fifo(tmp_path, capsys, null_device):
    _one_line(
        capsys, ["simulate", "--moves", "2", "--out", f"{null_device}/x.csv"], "is a file, not a folder"
    )
    os.mkfifo(tmp_path / "lab.moves.csv")
    _one_line(
        capsys, ["simulate", "--moves", "2", "--out", str(tmp_path / "lab.csv")], "lab.moves.csv: is a FIFO"
    )
    assert not (tmp_path / "lab.csv").exists()


def test_cli_simulate_folder_refuses_a_fifo_where_the_log_goes(tmp_path, capsys):
    os.mkfifo(tmp_path / "lab-0.csv")
    _one_line(capsys, ["simulate", "--moves", "2", "--out", str(tmp_path)], "lab-0.csv: is a FIFO")
    assert not (tmp_path / "lab-0.moves.csv").exists()


def test_cli_simulate_says_simulated_robot_time(tmp_path, capsys):
    assert main(["simulate", "--moves", "2", "--seed", "1", "--out", str(tmp_path / "l.csv")]) == 0
    out = capsys.readouterr().out
    assert "s of robot motion" in out and "simulated" in out


def test_cli_rapid_collect_does_not_overwrite_without_force(tmp_path, capsys):
    args = ["rapid", "collect", "--out", str(tmp_path), "--moves", "5", "--mode", "table"]
    assert main(args) == 0
    capsys.readouterr()
    collect = tmp_path / "JPCollect.mod"
    collect.write_text("! my edited program\n")
    before = _mtime_and_bytes(collect)
    err = _one_line(capsys, [*args, "--seed", "9"], "already holds JPCollect.mod and JPMeasure.mod")
    assert "--force" in err
    assert _mtime_and_bytes(collect) == before
    assert main([*args, "--seed", "9", "--force"]) == 0
    assert collect.read_text().startswith("MODULE JPCollect")


def test_cli_rapid_collect_refuses_a_fifo_program(tmp_path, capsys):
    os.mkfifo(tmp_path / "JPMeasure.mod")
    args = ["rapid", "collect", "--out", str(tmp_path), "--moves", "5", "--mode", "table", "--force"]
    _one_line(capsys, args, "JPMeasure.mod: is a FIFO")
    assert not (tmp_path / "JPCollect.mod").exists()


def test_cli_synth_out_is_its_source_refused(tmp_path, lab, capsys, null_device):
    from joulepath.data import ingest, save_table

    table = save_table(ingest([lab.log]), tmp_path / "real.parquet")
    before = _mtime_and_bytes(table)
    args = ["synth", "--method", "copula", "--from", str(table), "--rows", "10", "--out", str(table)]
    _one_line(capsys, args, "is also an input of this command")
    args = [
        "synth",
        "--method",
        "copula",
        "--from",
        str(table),
        "--rows",
        "10",
        "--out",
        str(tmp_path / "s.parquet"),
    ]
    _one_line(capsys, [*args, "--save-model", str(table)], "is also an input of this command")
    _one_line(capsys, [*args[:-2], "--out", str(null_device)], "is a character device")
    assert _mtime_and_bytes(table) == before and not (tmp_path / "s.parquet").exists()


def test_cli_compare_refuses_a_fifo_where_the_statistics_go(tmp_path, lab, capsys):
    from joulepath.data import ingest, save_table

    table = save_table(ingest([lab.log]), tmp_path / "real.parquet")
    out = tmp_path / "cmp"
    out.mkdir()
    os.mkfifo(out / "statistics.csv")
    _one_line(capsys, ["compare", str(table), "--out", str(out)], "statistics.csv: is a FIFO")
    assert [p.name for p in out.iterdir()] == ["statistics.csv"]


# --------------------------------------------------------------------------- a real process


def test_subprocess_ingest_dev_null_exit_code_and_one_line(lab, null_device):
    """The installed entry point, as a user runs it: rc 2, one line, the device untouched."""
    proc = subprocess.run(
        [sys.executable, "-m", "joulepath", "ingest", str(lab.log), "--out", str(null_device)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"error: {null_device}: is a character device, not a regular file; joulepath only replaces files: "
        "choose another output path (--out)"
    ]
    assert stat.S_ISCHR(os.stat(null_device).st_mode)


# --------------------------------------------------------------------------- joint arguments (cli/_common.py)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_cli_joint_values_must_be_finite(capsys, value):
    _one_line(capsys, ["robot", "fk", "irb120", "--q", f"{value},0,0,0,0,0"], f"{value} in ")
