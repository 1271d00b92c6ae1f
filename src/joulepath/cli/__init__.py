"""The ``joulepath`` command line: thin over the library (see ``joulepath --help``)."""

from joulepath.cli._main import main

__all__ = ["main"]
