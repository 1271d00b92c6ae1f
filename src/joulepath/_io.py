"""Safe file reading and writing (foundation): bounded reads, and nothing ever left half-written.

Readers (:func:`read_capped`, :func:`load_toml`, :func:`load_json`) accept only a
regular file (a link to one is followed) no larger than a cap, checked before the
file is opened, so a folder, a device such as ``/dev/zero``, a FIFO or a sparse
file of gigabytes is refused by name instead of read until memory runs out or
blocking forever. What TOML and JSON give back is checked by :func:`check_tree`:
nesting at most :data:`MAX_NESTING` deep and integers within 64 bits (TOML's own
range), so a 5,000-digit number or arrays nested thousands deep are one line, not
a traceback. Every reader raises the error class its caller names, with the path.

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
import json
import math
import os
import shutil
import stat
import tempfile
import tomllib
from collections.abc import Iterable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from joulepath.errors import InvalidInput, JoulepathError

MAX_NESTING = 32
"""Deepest nesting of arrays and tables (objects) a TOML or JSON file may have."""
MAX_INTEGER = 2**63 - 1
"""Largest integer magnitude TOML or JSON may hold (TOML's 64-bit range); beyond it, one line."""


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


# --------------------------------------------------------------------------- reading


def check_regular_file(
    path: str | os.PathLike[str],
    *,
    max_bytes: int,
    what: str,
    error: type[JoulepathError] = InvalidInput,
) -> int:
    """Refuse anything but an existing regular file of at most ``max_bytes``; return its size.

    Checked with ``os.stat`` before the file is opened: a folder, a device, a FIFO or a
    socket is refused by name, so nothing blocks on a pipe or reads ``/dev/zero``.

    Parameters
    ----------
    path : path-like
        The file; a symbolic link is followed.
    max_bytes : int
        Largest size accepted.
    what : str
        What the file should be, for the message (e.g. ``"a TOML cell file"``).
    error : type of JoulepathError
        The class raised.

    Raises
    ------
    JoulepathError
        Of class ``error``: missing, not a regular file, unreadable or larger than ``max_bytes``.
    """
    p = Path(path)
    try:
        st = os.stat(p)
    except OSError as err:
        raise error(f"{p}: cannot be read ({err.strerror}); give {what}") from err
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{p}: is a {file_kind(st.st_mode)}, not a regular file; give {what}")
    if st.st_size > max_bytes:
        raise error(
            f"{p}: is {_size_text(st.st_size)}, larger than the {_size_text(max_bytes)} accepted for "
            f"{what}; is it the right file?"
        )
    return int(st.st_size)


def _size_text(n: int) -> str:
    for unit, shift in (("GiB", 30), ("MiB", 20), ("KiB", 10)):
        if n >= 1 << shift:
            return f"{n / (1 << shift):.3g} {unit}"
    return f"{n} bytes"


def read_capped(
    path: str | os.PathLike[str],
    *,
    max_bytes: int,
    what: str,
    error: type[JoulepathError] = InvalidInput,
) -> bytes:
    """The bytes of a regular file of at most ``max_bytes`` (see :func:`check_regular_file`).

    At most ``max_bytes`` are read even if the file grows while it is read.

    Raises
    ------
    JoulepathError
        Of class ``error``, as :func:`check_regular_file`, or when reading fails.
    """
    p = Path(path)
    check_regular_file(p, max_bytes=max_bytes, what=what, error=error)
    try:
        with p.open("rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as err:
        raise error(f"{p}: cannot be read ({err.strerror}); give {what}") from err
    if len(data) > max_bytes:
        raise error(f"{p}: grew past {_size_text(max_bytes)} while it was read; give {what}")
    return data


def check_tree(
    value: Any, where: str, *, error: type[JoulepathError] = InvalidInput, max_depth: int = MAX_NESTING
) -> None:
    """Refuse nesting deeper than ``max_depth`` and integers beyond 64 bits in parsed TOML/JSON.

    Walks the tree with an explicit stack (no recursion), once per value.

    Raises
    ------
    JoulepathError
        Of class ``error``, naming ``where``.
    """
    stack: list[tuple[Any, int]] = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict | list):
            if depth >= max_depth:
                raise error(
                    f"{where}: arrays or tables nested more than {max_depth} deep; "
                    "this file needs only a few levels"
                )
            children = item.values() if isinstance(item, dict) else item
            stack.extend((child, depth + 1) for child in children)
        elif isinstance(item, int) and not isinstance(item, bool) and abs(item) > MAX_INTEGER:
            raise error(
                f"{where}: an integer of {len(str(abs(item)))} digits, beyond 64 bits; "
                "write a number of sane size (a decimal point makes it a float)"
            )


def _decode(data: bytes, p: Path, what: str, error: type[JoulepathError]) -> str:
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as err:
        raise error(f"{p}: not UTF-8 text ({err.reason} at byte {err.start}); give {what}") from err


def load_toml(
    path: str | os.PathLike[str],
    *,
    max_bytes: int,
    what: str,
    error: type[JoulepathError] = InvalidInput,
) -> dict[str, Any]:
    """A TOML file as a dict, read through :func:`read_capped` and checked by :func:`check_tree`.

    Raises
    ------
    JoulepathError
        Of class ``error``: not a regular file, too large, not UTF-8, not valid TOML,
        nested too deep, or an integer beyond 64 bits.
    """
    p = Path(path)
    text = _decode(read_capped(p, max_bytes=max_bytes, what=what, error=error), p, what, error)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise error(f"{p}: not valid TOML ({err}); fix the syntax there") from err
    except RecursionError as err:
        raise error(f"{p}: arrays or tables nested more than {MAX_NESTING} deep; give {what}") from err
    except ValueError as err:  # an integer of more than 4,300 digits
        raise error(f"{p}: a number of more than 4,300 digits; write a number of sane size") from err
    check_tree(data, str(p), error=error)
    return data


def load_json(
    path: str | os.PathLike[str],
    *,
    max_bytes: int,
    what: str,
    error: type[JoulepathError] = InvalidInput,
) -> Any:
    """A JSON file, read through :func:`read_capped` and checked by :func:`check_tree`.

    ``NaN`` and ``Infinity`` (which Python's ``json`` accepts) are refused.

    Raises
    ------
    JoulepathError
        Of class ``error``: as :func:`load_toml`, for JSON.
    """
    p = Path(path)
    text = _decode(read_capped(p, max_bytes=max_bytes, what=what, error=error), p, what, error)

    def _constant(name: str) -> Any:
        raise ValueError(f"{name} is not a JSON number")

    try:
        data = json.loads(text, parse_constant=_constant)
    except json.JSONDecodeError as err:
        raise error(f"{p}: not valid JSON ({err}); give {what}") from err
    except RecursionError as err:
        raise error(f"{p}: arrays or objects nested more than {MAX_NESTING} deep; give {what}") from err
    except ValueError as err:  # NaN/Infinity, or an integer of more than 4,300 digits
        why = "a number of more than 4,300 digits" if "digits" in str(err) else str(err)
        raise error(f"{p}: {why}; write finite numbers of sane size") from err
    check_tree(data, str(p), error=error)
    return data


def finite_number(
    value: Any,
    where: str,
    *,
    lo: float = -1e12,
    hi: float = 1e12,
    error: type[JoulepathError] = InvalidInput,
    unit: str = "",
) -> float:
    """``value`` as a float if it is a number (never a boolean), finite and in ``[lo, hi]``.

    Raises
    ------
    JoulepathError
        Of class ``error``, naming ``where`` and the range.
    """
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    number = float(value) if ok and abs(value) <= 1e300 else math.nan
    if not (ok and math.isfinite(number) and lo <= number <= hi):
        if isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_INTEGER:
            shown = "an integer beyond 64 bits"
        else:
            text = repr(value)
            shown = text if len(text) <= 40 else text[:37] + "..."
        of = f" of {unit}" if unit else ""
        raise error(f"{where}: must be a number{of} in [{lo:g}, {hi:g}], got {shown}")
    return number
