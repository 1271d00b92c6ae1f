"""A RAPID task: its modules (program and system modules), found across files and folders.

``load_task(paths)`` takes module files (``.mod``, ``.modx``, ``.sys``, ``.prg``), folders
(a task's modules, as a controller backup stores them under ``RAPID/TASK*/PROGMOD`` and
``SYSMOD``; searched recursively) and the controller's I/O configuration (``EIO.cfg``,
whose signal names become known signals). Data, tools, work objects and routines are
then found across all the modules, as the controller finds them in one task.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from joulepath._io import read_capped
from joulepath.errors import RapidError
from joulepath.rapid import nodes as n
from joulepath.rapid._parse import MAX_BYTES, decode, read_module_file

MODULE_SUFFIXES = (".mod", ".modx", ".sys", ".sysx", ".prg")
"""File suffixes read as RAPID modules."""

MAX_MODULES = 200
"""Most module files one task may hold."""


@dataclass(frozen=True, slots=True)
class Task:
    """The modules of one task, the signals the I/O configuration declares, and where they came from."""

    modules: tuple[n.Module, ...]
    signals: frozenset[str]
    source: str
    eio: str | None = None

    def module_of(self, path: str) -> n.Module | None:
        return next((m for m in self.modules if m.path == path), None)


def _signals_of_eio(path: Path) -> frozenset[str]:
    data = read_capped(path, max_bytes=MAX_BYTES, what="an I/O configuration (EIO.cfg)", error=RapidError)
    text, _, _ = decode(data)
    names = re.findall(r"-Name\s+\"?([A-Za-z][A-Za-z0-9_]*)\"?", text)
    return frozenset(name.lower() for name in names)


def load_task(paths: Sequence[str | Path]) -> Task:
    """Parse a task's modules from files and folders; :class:`RapidError` with one line otherwise."""
    files: list[Path] = []
    eio: list[Path] = []
    if not paths:
        raise RapidError("no program given: name a module file (.mod, .sys) or a task's folder")
    for raw in paths:
        p = Path(raw)
        if p.is_dir():
            found = sorted(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in MODULE_SUFFIXES)
            eio.extend(sorted(f for f in p.rglob("*") if f.is_file() and f.name.lower() == "eio.cfg"))
            if not found:
                raise RapidError(f"{p}: the folder holds no RAPID module (.mod, .sys); give a task's folder")
            files.extend(found)
        elif p.suffix.lower() == ".cfg" and p.is_file():
            eio.append(p)
        elif p.exists() or p.is_symlink():
            files.append(p)  # a regular file, or refused by name when read (a device, a FIFO ...)
        else:
            raise RapidError(
                f"{p}: no such file or folder; give a module file (.mod, .sys) or a task's folder"
            )
    if len(files) > MAX_MODULES:
        raise RapidError(
            f"{len(files)} module files: a task holds at most {MAX_MODULES}; give one task's modules"
        )
    if not files:
        raise RapidError("only an I/O configuration was given: add the task's modules (.mod, .sys)")
    unique: list[Path] = []
    resolved: set[Path] = set()
    for f in files:
        where = f.resolve() if f.is_file() else f
        if where not in resolved:
            resolved.add(where)
            unique.append(f)
    modules = [read_module_file(f) for f in unique]
    names: dict[str, n.Module] = {}
    for m in modules:
        key = m.name.lower()
        if key in names:
            raise RapidError(
                f"{m.path}:{m.pos.line}: module {m.name} is also in {names[key].path}; a task holds each "
                "module once: give one of them"
            )
        names[key] = m
    signals: frozenset[str] = frozenset()
    for f in eio:
        signals |= _signals_of_eio(f)
    source = ", ".join(str(Path(p)) for p in paths)
    return Task(tuple(modules), signals, source, str(eio[0]) if eio else None)
