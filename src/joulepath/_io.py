"""Safe file writing (foundation): nothing is ever left half-written, and nothing but a file is replaced.

Every writer here refuses, with :class:`~joulepath.errors.InvalidInput`, a target that
exists and is not a regular file (a folder, a device node such as ``/dev/null``, a
FIFO, a socket), and turns an operating-system failure (permission denied, read-only
file system, disk full) into one :class:`~joulepath.errors.InvalidInput` naming the
path, so the command line prints one line instead of a traceback.
"""

from __future__ import annotations

import os
import stat
import tempfile
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


def make_folder(path: str | os.PathLike[str]) -> Path:
    """``mkdir -p path``, with one :class:`InvalidInput` line when that fails."""
    p = Path(path)
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InvalidInput(
            f"{p}: cannot create the folder ({err.strerror}); choose a place you can write to"
        ) from err
    return p


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to a temporary file beside ``path``, then rename it into place.

    Raises
    ------
    InvalidInput
        ``path`` exists and is not a regular file, or the operating system refuses
        the write (permission denied, read-only file system, disk full).
    """
    p = Path(path)
    check_replaceable(p)
    parent = p.parent if str(p.parent) else Path(".")
    tmp = ""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
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
