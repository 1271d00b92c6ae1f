"""Validation helpers for the algorithm configs (messages: received, expected, fix)."""

from __future__ import annotations

import math
from collections.abc import Collection

from joulepath.errors import InvalidInput


def check_int(owner: str, name: str, value: object, *, minimum: int) -> None:
    if not isinstance(value, int) or isinstance(value, bool) or value < minimum:
        raise InvalidInput(f"{owner}: {name} must be an integer >= {minimum}, got {value!r}")


def check_real(
    owner: str,
    name: str,
    value: object,
    *,
    low: float,
    high: float,
    low_open: bool = False,
    high_open: bool = False,
    hint: str = "",
) -> None:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok:
        v = float(value)  # type: ignore[arg-type]
        ok = (v > low if low_open else v >= low) and (v < high if high_open else v <= high)
    if not ok:
        interval = f"{'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
        raise InvalidInput(f"{owner}: {name} must be a number in {interval}, got {value!r}{hint}")


def check_choice(owner: str, name: str, value: object, allowed: Collection[str]) -> None:
    if value not in allowed:
        options = ", ".join(repr(a) for a in sorted(allowed))
        raise InvalidInput(f"{owner}: {name} must be one of {options}; got {value!r}")
