"""The RAPID language: grammar, typed tree, interpreter and writer (ABB's robot programs)."""

from joulepath.errors import RapidError
from joulepath.rapid._parse import decode, parse_module, read_module_file
from joulepath.rapid.task import MotionConfig, find_moc, read_moc

__all__ = [
    "MotionConfig",
    "RapidError",
    "decode",
    "find_moc",
    "parse_module",
    "read_moc",
    "read_module_file",
]
