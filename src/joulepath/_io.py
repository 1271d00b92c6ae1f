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
"""

from __future__ import annotations

import json
import math
import os
import stat
import tempfile
import tomllib
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
