"""The RAPID language: grammar, typed tree, interpreter and writer (ABB's robot programs)."""

from joulepath.rapid._parse import RapidError, parse_module, read_module_file

__all__ = ["RapidError", "parse_module", "read_module_file"]
