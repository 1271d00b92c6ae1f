"""Safe file writing (foundation): nothing is ever left half-written, and nothing but a file is replaced.

Every writer here refuses, with :class:`~joulepath.errors.InvalidInput`, a target that
exists and is not a regular file (a folder, a device node such as ``/dev/null``, a
FIFO, a socket), and turns an operating-system failure (permission denied, read-only
file system, disk full) into one :class:`~joulepath.errors.InvalidInput` naming the
path, so the command line prints one line instead of a traceback.

Each file is written atomically (a temporary file beside it, then a rename). A whole
command is made atomic by an :class:`OutputJournal` (:func:`output_journal`): while one
is active, every file written or removed through this module is recorded (a replaced
or removed file is kept under a hidden name beside it), and so is every folder
:func:`make_folder` creates. :meth:`OutputJournal.undo` then puts everything back as
it was before the command (a command that fails midway, e.g. on a full disk, leaves
nothing of its own), and :meth:`OutputJournal.commit` drops the kept copies. The
command line runs every command but ``run`` (whose stages have their own recovery)
inside one.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
from collections.abc import Iterable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from joulepath.errors import InvalidInput


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def file_kind(mode: int) -> str:
    """A short name of what a ``st_mode`` describes ("folder", "character device", ...)."""
    kinds = (
        (stat.S_ISDIR, "folder"),
        (stat.S_ISCHR, "character device"),
        (stat.S_ISBLK, "block device"),
        (stat.S_ISFIFO, "FIFO (named pipe)"),
        (stat.S_ISSOCK, "socket"),
        (stat.S_ISLNK, "symbolic link"),
    )
    for test, name in kinds:
        if test(mode):
            return name
    return "regular file" if stat.S_ISREG(mode) else "special file"


def check_replaceable(path: str | os.PathLike[str]) -> None:
    """Refuse an output path that exists and is not a regular file (or a link to one).

    Raises
    ------
    InvalidInput
        ``path`` is a folder, device, FIFO, socket or a link to one of them.
    """
    p = Path(path)
    try:
        st = os.stat(p)  # follows links: a link to /dev/null is refused like /dev/null
    except FileNotFoundError:
        return
    except OSError as err:
        raise InvalidInput(f"{p}: cannot be checked ({err.strerror}); choose another output path") from err
    if not stat.S_ISREG(st.st_mode):
        raise InvalidInput(
            f"{p}: is a {file_kind(st.st_mode)}, not a regular file; joulepath only replaces files: "
            "choose another output path"
        )


def _missing_folders(p: Path) -> list[Path]:
    """``p`` and the folders above it that do not exist yet, outermost first."""
    missing = []
    for folder in (p, *p.parents):
        if os.path.lexists(folder):
            break
        missing.append(folder)
    return missing[::-1]


@dataclass(eq=False)
class OutputJournal:
    """What one command has written, replaced, removed and created so far (see the module docstring).

    ``changed`` maps each path written or removed to the hidden copy of what was
    there before (None: nothing was); ``created`` lists the folders created, outermost
    first.
    """

    changed: dict[Path, Path | None] = field(default_factory=dict)
    created: list[Path] = field(default_factory=list)
    undone: int = 0
    """How many paths the last :meth:`undo` put back."""

    @property
    def n_changed(self) -> int:
        """How many paths this command has written or removed so far."""
        return len(self.changed)

    def _keep(self, p: Path, *, move: bool, link: bool = True) -> None:
        """Record ``p`` before its first change, keeping what is there under a hidden name beside it.

        ``move``: what is there goes aside (a removal); else it is kept as a second name
        (``link``: a hard link, right for writers that rename a new file into place) or a copy.
        """
        if p in self.changed:
            return
        if not os.path.lexists(p):
            self.changed[p] = None
            return
        if move and p.is_dir() and not p.is_symlink():
            kept = Path(tempfile.mkdtemp(prefix=f".{p.name}.", suffix=".undo", dir=p.parent))
        else:
            fd, name = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".undo", dir=p.parent)
            os.close(fd)
            kept = Path(name)
        try:
            if move:
                os.replace(p, kept)  # over the empty placeholder: atomic, no disk space
            else:
                kept.unlink()
                try:
                    if not link:
                        raise OSError
                    os.link(p, kept, follow_symlinks=False)  # a second name: no copy, no disk space
                except OSError:
                    shutil.copy2(p, kept, follow_symlinks=False)
        except BaseException:
            with contextlib.suppress(OSError):
                _remove_path(kept)
            raise
        self.changed[p] = kept

    def folders(self, p: Path) -> None:
        """Record the folders of ``p`` that do not exist yet (call before creating them)."""
        self.created.extend(f for f in _missing_folders(p) if f not in self.created)

    def undo(self) -> int:
        """Put back what was there before; returns how many paths were written or removed.

        Best effort: a path that cannot be put back is left as it is (never raises).
        """
        n = len(self.changed)
        for p, kept in reversed(list(self.changed.items())):
            with contextlib.suppress(OSError):
                if kept is None:
                    _remove_path(p)
                else:
                    if os.path.lexists(p):
                        _remove_path(p)
                    os.replace(kept, p)
        for folder in reversed(self.created):
            with contextlib.suppress(OSError):
                folder.rmdir()  # only when empty: never what another program put there meanwhile
        self.changed.clear()
        self.created.clear()
        self.undone = n
        return n

    def commit(self) -> None:
        """Keep what was written: drop the hidden copies (never raises)."""
        for kept in self.changed.values():
            if kept is not None:
                with contextlib.suppress(OSError):
                    _remove_path(kept)
        self.changed.clear()
        self.created.clear()


_JOURNAL: ContextVar[OutputJournal | None] = ContextVar("joulepath_output_journal", default=None)


@contextlib.contextmanager
def output_journal(journal: OutputJournal | None = None) -> Iterator[OutputJournal | None]:
    """Record every write of this module in ``journal`` (a new one when None) while the block runs.

    Leaving the block normally commits the journal; an exception undoes it, then
    propagates. A journal opened inside another one keeps what it committed whatever
    the outer one does later (e.g. a session log that is the record of a failure).
    """
    active = journal if journal is not None else OutputJournal()
    token = _JOURNAL.set(active)
    try:
        yield active
    except BaseException:
        _JOURNAL.reset(token)
        active.undo()
        raise
    _JOURNAL.reset(token)
    active.commit()


@contextlib.contextmanager
def outside_journal() -> Iterator[None]:
    """Writes in this block are not recorded: content-keyed caches, meant to outlive a failed run."""
    token = _JOURNAL.set(None)
    try:
        yield
    finally:
        _JOURNAL.reset(token)


def _remove_path(p: Path) -> None:
    if p.is_dir() and not p.is_symlink():
        shutil.rmtree(p)
    else:
        p.unlink(missing_ok=True)


def expect_outputs(paths: Iterable[str | os.PathLike[str]]) -> None:
    """Record, before other processes write them, the files they will write for this command.

    Worker processes do not share the command's journal: what each path holds now is kept
    (and its folders noted), so that a failure of the command undoes their writes too.
    """
    journal = _JOURNAL.get()
    if journal is None:
        return
    for path in paths:
        p = Path(path)
        journal.folders(p.parent)
        if os.path.lexists(p.parent):
            try:
                journal._keep(p, move=False, link=False)  # a worker may write in place
            except OSError as err:
                raise InvalidInput(f"{p}: cannot be written ({err.strerror or err})") from err
        else:
            journal.changed.setdefault(p, None)


def make_folder(path: str | os.PathLike[str]) -> Path:
    """``mkdir -p path``, with one :class:`InvalidInput` line when that fails."""
    p = Path(path)
    if p.is_symlink() and not p.exists():
        raise InvalidInput(
            f"{p}: is a symbolic link to {os.readlink(p)}, which does not exist; "
            "remove the link or choose another folder"
        )
    journal = _JOURNAL.get()
    if journal is not None:
        journal.folders(p)
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InvalidInput(
            f"{p}: cannot create the folder ({err.strerror}); choose a place you can write to"
        ) from err
    return p


def remove_output(path: str | os.PathLike[str]) -> None:
    """Remove a file (or folder) a command replaces by nothing, e.g. a program a refused run must not leave.

    Inside an :class:`OutputJournal` the file is only moved aside, and put back if the
    command fails. A path that does not exist is left alone.
    """
    p = Path(path)
    if not os.path.lexists(p):
        return
    journal = _JOURNAL.get()
    try:
        if journal is None:
            _remove_path(p)
            return
        was_ours = p in journal.changed
        journal._keep(p, move=True)
        if was_ours and os.path.lexists(p):  # written earlier by this command: nothing to keep
            _remove_path(p)
    except OSError as err:
        raise InvalidInput(f"{p}: cannot be removed ({err.strerror or err})") from err


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to a temporary file beside ``path``, then rename it into place.

    Inside an :class:`OutputJournal` the write is recorded (and what it replaces kept)
    so that the whole command can be undone.

    Raises
    ------
    InvalidInput
        ``path`` exists and is not a regular file, or the operating system refuses
        the write (permission denied, read-only file system, disk full).
    """
    p = Path(path)
    check_replaceable(p)
    parent = p.parent if str(p.parent) else Path(".")
    journal = _JOURNAL.get()
    tmp = ""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
        if journal is not None:
            journal._keep(p, move=False)
        os.replace(tmp, p)
    except OSError as err:
        if tmp:
            Path(tmp).unlink(missing_ok=True)
        raise InvalidInput(
            f"{p}: cannot be written ({err.strerror or err}); choose a place you can write to"
        ) from err
    except BaseException:
        if tmp:
            Path(tmp).unlink(missing_ok=True)
        raise
    return p


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Text version of :func:`atomic_write_bytes` (UTF-8)."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def save_figure(fig: Any, path: str | os.PathLike[str], *, dpi: int = 100) -> Path:
    """Render a Matplotlib figure as PNG in memory, then :func:`atomic_write_bytes` it."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return atomic_write_bytes(path, buf.getvalue())


def finite_json(value: Any) -> Any:
    """``value`` with NumPy scalars and arrays as plain JSON types and NaN/infinities as ``None``.

    For strict JSON (``json.dumps(..., allow_nan=False)``): results never carry ``NaN``.
    """
    if isinstance(value, dict):
        return {k: finite_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [finite_json(v) for v in value]
    if isinstance(value, np.ndarray):
        return finite_json(value.tolist())
    if isinstance(value, float | np.floating):
        return float(value) if np.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value
