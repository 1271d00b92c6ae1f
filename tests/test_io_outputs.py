"""The output journal (``joulepath._io``): a command's writes are undone as a whole, or kept as a whole."""

from __future__ import annotations

import errno
import os

import pytest

import joulepath._io as io_
from joulepath._io import (
    OutputJournal,
    atomic_write_text,
    expect_outputs,
    make_folder,
    output_journal,
    outside_journal,
    remove_output,
    save_figure,
)
from joulepath.errors import InvalidInput


def _tree(folder):
    """Every path under ``folder`` (hidden ones included) with the bytes of its files."""
    return {
        str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
        for p in sorted(folder.rglob("*"))
    }


def test_undo_puts_back_what_was_there(tmp_path):
    (tmp_path / "kept.txt").write_text("old")
    (tmp_path / "gone.txt").write_text("removed by the command")
    before = _tree(tmp_path)
    journal = OutputJournal()
    with pytest.raises(RuntimeError), output_journal(journal):
        atomic_write_text(tmp_path / "kept.txt", "new")
        atomic_write_text(tmp_path / "kept.txt", "newer")  # twice: the first copy is what comes back
        atomic_write_text(make_folder(tmp_path / "a" / "b") / "new.txt", "x")
        remove_output(tmp_path / "gone.txt")
        assert (tmp_path / "kept.txt").read_text() == "newer" and not (tmp_path / "gone.txt").exists()
        raise RuntimeError("the command fails midway")
    assert _tree(tmp_path) == before  # no hidden copy, temporary file or created folder left
    assert journal.undone == 3


def test_commit_keeps_the_writes_and_drops_the_copies(tmp_path):
    (tmp_path / "kept.txt").write_text("old")
    (tmp_path / "gone.txt").write_text("x")
    with output_journal():
        atomic_write_text(tmp_path / "kept.txt", "new")
        remove_output(tmp_path / "gone.txt")
    assert _tree(tmp_path) == {"kept.txt": b"new"}


def test_undo_keeps_a_folder_someone_else_filled(tmp_path):
    with pytest.raises(RuntimeError), output_journal():
        folder = make_folder(tmp_path / "out")
        atomic_write_text(folder / "ours.txt", "x")
        (folder / "theirs.txt").write_text("not ours")
        raise RuntimeError
    assert _tree(tmp_path) == {"out": None, "out/theirs.txt": b"not ours"}


def test_a_removed_folder_comes_back(tmp_path):
    old = tmp_path / "models" / "svr"
    old.mkdir(parents=True)
    (old / "card.json").write_text("{}")
    before = _tree(tmp_path)
    with pytest.raises(RuntimeError), output_journal():
        remove_output(old)
        assert not old.exists()
        raise RuntimeError
    assert _tree(tmp_path) == before


def test_caches_outside_the_journal_outlive_a_failure(tmp_path):
    with pytest.raises(RuntimeError), output_journal():
        with outside_journal():
            atomic_write_text(tmp_path / "cache.json", "{}")
        atomic_write_text(tmp_path / "result.json", "{}")
        raise RuntimeError
    assert _tree(tmp_path) == {"cache.json": b"{}"}


def test_a_full_disk_midway_leaves_nothing(tmp_path, monkeypatch):
    real = io_.tempfile.mkstemp

    def full(*args, **kwargs):
        if kwargs.get("prefix", "").startswith(".c.txt"):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(*args, **kwargs)

    monkeypatch.setattr(io_.tempfile, "mkstemp", full)
    out = tmp_path / "run"
    with pytest.raises(InvalidInput, match=r"c\.txt: cannot be written \(No space left on device\)"):
        with output_journal():
            for name in "ab":
                atomic_write_text(make_folder(out) / f"{name}.txt", name)
            atomic_write_text(out / "c.txt", "c")
    assert not out.exists()


def test_save_figure_writes_a_png_and_no_temporary_file(tmp_path):
    from matplotlib.figure import Figure

    fig = Figure()
    fig.subplots().plot([0, 1], [1, 0])
    path = save_figure(fig, tmp_path / "p.png")
    assert path.read_bytes().startswith(b"\x89PNG")
    os.mkdir(tmp_path / "d.png")
    with pytest.raises(InvalidInput, match="is a folder"):
        save_figure(fig, tmp_path / "d.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.png", "p.png"]


def test_make_folder_refuses_a_dangling_link(tmp_path):
    (tmp_path / "out").symlink_to(tmp_path / "nowhere")
    with pytest.raises(InvalidInput, match="which does not exist"):
        make_folder(tmp_path / "out")


def test_files_other_processes_write_are_undone_too(tmp_path):
    (tmp_path / "old.csv").write_text("earlier run")
    before = _tree(tmp_path)
    with pytest.raises(RuntimeError), output_journal():
        expect_outputs([tmp_path / "old.csv", tmp_path / "logs" / "new.csv"])
        (tmp_path / "logs").mkdir()  # as a worker process does, outside the journal
        (tmp_path / "logs" / "new.csv").write_text("x")
        (tmp_path / "old.csv").write_text("overwritten")
        raise RuntimeError
    assert _tree(tmp_path) == before
