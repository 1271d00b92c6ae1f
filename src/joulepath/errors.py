"""Errors raised by joulepath.

Every error a user can cause derives from :class:`JoulepathError`; each leaf also
derives from the matching built-in so that ``except ValueError`` keeps working::

    JoulepathError
    ├── InvalidRobotDescription (ValueError)   a robot file that cannot be used
    ├── InvalidInput (ValueError)              arrays or arguments of the wrong shape or range
    │   └── RapidError                         a RAPID program that cannot be read or run
    ├── InvalidLog (ValueError)                a joint log or energy table that cannot be used
    ├── LimitViolation (ValueError)            a result that would drive a joint past a limit
    ├── InvalidModel (ValueError)              a model file refused, or a table it cannot read
    ├── InvalidMessage (ValueError)            a controller datagram that is not a valid message
    ├── StreamAborted (RuntimeError)           a controller connection stopped on a fault
    └── MissingDependency (ImportError)        an optional extra is not installed

Messages say what was received, what was expected and how to fix it.
"""

from __future__ import annotations


class JoulepathError(Exception):
    """Base class of every error joulepath raises on bad input."""


class InvalidRobotDescription(JoulepathError, ValueError):
    """A robot description (IRML, URDF) is missing a field or holds an invalid value."""


class InvalidInput(JoulepathError, ValueError):
    """An argument has the wrong shape, type or range."""


class RapidError(InvalidInput):
    """A RAPID program joulepath cannot read or run: the message starts with ``file:line:``."""


class InvalidLog(JoulepathError, ValueError):
    """A joint log (or energy table) is malformed; the message names file, line and field."""


class LimitViolation(JoulepathError, ValueError):
    """A trajectory or program would drive a joint past its range, speed or torque."""


class InvalidModel(JoulepathError, ValueError):
    """A model file is refused (unknown types, bad card) or does not fit the table given."""


class InvalidMessage(JoulepathError, ValueError):
    """A datagram from a robot controller does not parse or misses a field (``reason`` says which)."""

    def __init__(self, reason: str, detail: str = "") -> None:
        super().__init__(f"{reason}: {detail}" if detail else reason)
        self.reason = reason


class StreamAborted(JoulepathError, RuntimeError):
    """A streaming session to a controller stopped on a fault (silence, robot away from the plan)."""


class MissingDependency(JoulepathError, ImportError):
    """An optional dependency is not installed; the message names the extra to install."""
