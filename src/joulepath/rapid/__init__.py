"""The RAPID language: grammar, typed tree, interpreter and writer (ABB's robot programs)."""

from joulepath.errors import RapidError
from joulepath.rapid._parse import decode, parse_module, read_module_file

__all__ = [
    "RapidError",
    "decode",
    "parse_module",
    "read_module_file",
]
