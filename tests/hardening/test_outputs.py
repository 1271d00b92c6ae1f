"""Output folders under hostile and careless input (issue 25, item 4), through the real CLI.

Every case ends with exit 2, exactly one line on stderr and nothing of the command's own
left behind (no file, no temporary file, no hidden copy, no folder it created), or with a
valid run. Names inside ``--out`` are checked before any work; a failure midway (a full
disk while a plot is saved) undoes what was already written.
"""

from __future__ import annotations

import errno
import shutil
from pathlib import Path

import pytest

import joulepath._io as io_
from joulepath.cli import main
from joulepath.sim import simulate

MOVE = ["--start", "0,0,0,0,0,0", "--end", "0.5,0,0,0,0,0", "--duration", "1"]


@pytest.fixture(scope="module")
def lab_log(tmp_path_factory):
    return simulate(tmp_path_factory.mktemp("lab") / "lab.csv", plant="lab", n_moves=30, seed=3).log


@pytest.fixture(scope="module")
def twin(lab_log, tmp_path_factory):
    out = tmp_path_factory.mktemp("twin") / "twin"
    assert main(["identify", str(lab_log), "--out", str(out)]) == 0
    return out


def _tree(folder: Path) -> dict[str, bytes | None]:
    """Every path under ``folder`` (hidden ones and links included) with the bytes of its files."""
    if not folder.exists():
        return {}
    return {
        str(p.relative_to(folder)): (p.read_bytes() if p.is_file() and not p.is_symlink() else None)
        for p in sorted(folder.rglob("*"))
    }


def _refused(capsys, args, fragment):
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert fragment in err, err
    return err


# --------------------------------------------------------------------------- names inside --out


@pytest.mark.parametrize("name", ["power.png", "result.json", "path.mod", "convergence.csv"])
def test_optimize_refuses_a_folder_where_a_file_goes_before_any_work(tmp_path, capsys, name):
    out = tmp_path / "run"
    (out / name).mkdir(parents=True)
    _refused(capsys, ["optimize", *MOVE, "--out", str(out)], f"{name}: is a folder where a file must be")
    assert _tree(out) == {name: None}


def test_cycle_refuses_a_folder_where_a_file_goes(tmp_path, capsys):
    out = tmp_path / "run"
    (out / "cycle.json").mkdir(parents=True)
    program = tmp_path / "c.toml"
    program.write_text("[[step]]\njoints_deg = [10, 0, 0, 0, 30, 0]\nduration_s = 1\n")
    _refused(capsys, ["cycle", str(program), "--out", str(out)], "cycle.json: is a folder where a file")
    assert _tree(out) == {"cycle.json": None}


def test_run_refuses_a_file_where_a_stage_folder_goes(tmp_path, capsys):
    out = tmp_path / "run"
    out.mkdir()
    (out / "models").write_text("mine")
    _refused(capsys, ["run", "demo", "--out", str(out)], "models: is not a folder")
    assert _tree(out) == {"models": b"mine"}


# --------------------------------------------------------------------------- dangling links


def _commands(tmp_path: Path, out: Path, lab_log: Path) -> dict[str, list[str]]:
    program = tmp_path / "c.toml"
    program.write_text("[[step]]\njoints_deg = [10, 0, 0, 0, 30, 0]\nduration_s = 1\n")
    return {
        "optimize": ["optimize", *MOVE, "--out", str(out)],
        "cycle": ["cycle", str(program), "--out", str(out)],
        "identify": ["identify", str(lab_log), "--out", str(out)],
        "measure": ["measure", str(lab_log), "--plan", str(tmp_path), "--out", str(out)],
        "simulate": ["simulate", "--moves", "2", "--out", str(out)],
        "run": ["run", "demo", "--out", str(out)],
    }


@pytest.mark.parametrize("command", ["optimize", "cycle", "identify", "measure", "simulate", "run"])
def test_a_dangling_link_as_out_is_refused(tmp_path, capsys, lab_log, command):
    out = tmp_path / "out"
    out.symlink_to(tmp_path / "nowhere")
    _refused(capsys, _commands(tmp_path, out, lab_log)[command], "which does not exist")
    assert out.is_symlink() and not (tmp_path / "nowhere").exists()


@pytest.mark.parametrize("command", ["optimize", "cycle", "identify", "measure"])
def test_a_dangling_link_inside_out_is_refused(tmp_path, capsys, lab_log, command):
    names = {"optimize": "result.json", "cycle": "cycle.json", "identify": "friction.json"}
    out = tmp_path / "out"
    out.mkdir()
    name = names.get(command, "measure.json")
    (out / name).symlink_to(tmp_path / "nowhere")
    _refused(capsys, _commands(tmp_path, out, lab_log)[command], f"{name}: is a symbolic link to")
    assert [p.name for p in out.iterdir()] == [name] and not (tmp_path / "nowhere").exists()


def test_a_dangling_link_above_out_is_refused(tmp_path, capsys):
    (tmp_path / "runs").symlink_to(tmp_path / "nowhere")
    _refused(capsys, ["optimize", *MOVE, "--out", str(tmp_path / "runs" / "a")], "which does not exist")


# --------------------------------------------------------------------------- a full disk midway


def _full_disk_at(monkeypatch, name: str) -> None:
    """The disk fills up when ``name`` is written (its temporary file cannot be created)."""
    real = io_.tempfile.mkstemp

    def mkstemp(*args, **kwargs):
        if kwargs.get("prefix", "").startswith(f".{name}.") and kwargs.get("suffix") == ".tmp":
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(*args, **kwargs)

    monkeypatch.setattr(io_.tempfile, "mkstemp", mkstemp)


def test_optimize_full_disk_at_a_plot_leaves_nothing_of_its_own(tmp_path, capsys, monkeypatch):
    """result.json, path.csv, default_path.csv, convergence.csv, path.mod and joints.png are
    written before power.png; the disk is full at power.png: all of them go again."""
    _full_disk_at(monkeypatch, "power.png")
    out = tmp_path / "new" / "run"
    err = _refused(capsys, ["optimize", *MOVE, "--out", str(out)], "power.png: cannot be written (No space")
    assert "nothing of this run was kept (the 6 file(s)" in err
    assert not (tmp_path / "new").exists()


def test_optimize_full_disk_puts_back_an_earlier_run(tmp_path, capsys, monkeypatch):
    out = tmp_path / "run"
    assert main(["optimize", *MOVE, "--out", str(out)]) == 0
    (out / "notes.txt").write_text("mine")
    before = _tree(out)
    capsys.readouterr()
    _full_disk_at(monkeypatch, "convergence.png")
    _refused(capsys, ["optimize", *MOVE, "--end", "0.4,0,0,0,0,0", "--out", str(out)], "No space left")
    assert _tree(out) == before  # the earlier run byte for byte, and no hidden copy or temporary file


def test_simulate_full_disk_at_the_second_file_leaves_nothing(tmp_path, capsys, monkeypatch):
    _full_disk_at(monkeypatch, "lab.moves.csv")
    _refused(capsys, ["simulate", "--moves", "2", "--out", str(tmp_path / "lab.csv")], "No space left")
    assert _tree(tmp_path) == {}


def test_a_full_disk_outside_our_writers_is_one_line(tmp_path, capsys, monkeypatch):
    """A writer that meets a full disk outside the journal's own writers (the table writer stands in)."""
    import joulepath.data._table as table

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "t.parquet"))

    monkeypatch.setattr(table, "atomic_write_bytes", full)
    log = simulate(tmp_path / "l.csv", plant="sim", n_moves=2, seed=1).log
    err = _refused(capsys, ["ingest", str(log), "--out", str(tmp_path / "t.parquet")], "No space left")
    assert "t.parquet" in err and not (tmp_path / "t.parquet").exists()


# --------------------------------------------------------------------------- identify and its input twin


def test_identify_never_rewrites_the_twin_it_reads(twin, lab_log, tmp_path, capsys):
    before = _tree(twin)
    for out in (twin, Path(str(twin) + "/"), twin / ".." / twin.name):
        args = ["identify", str(lab_log), "--robot", str(twin), "--out", str(out), "--force"]
        _refused(capsys, args, "is also an input of this command")
    assert _tree(twin) == before


def test_identify_from_a_twin_into_another_folder_works(twin, lab_log, tmp_path, capsys):
    copy = tmp_path / "copy"
    shutil.copytree(twin, copy)
    assert main(["identify", str(lab_log), "--robot", str(copy), "--out", str(tmp_path / "again")]) == 0
    assert sorted(p.name for p in (tmp_path / "again").iterdir()) == sorted(p.name for p in twin.iterdir())
