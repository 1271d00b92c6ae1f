"""A RAPID task: its modules (program and system modules), found across files and folders.

``load_task(paths)`` takes module files (``.mod``, ``.modx``, ``.sys``, ``.prg``), folders
(a task's modules, as a controller backup stores them under ``RAPID/TASK*/PROGMOD`` and
``SYSMOD``; searched recursively) and the controller's I/O configuration (``EIO.cfg``,
whose signal names become known signals). Data, tools, work objects and routines are
then found across all the modules, as the controller finds them in one task.
"""

from __future__ import annotations

import math
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
class MotionConfig:
    """What a backup's ``MOC.cfg`` says of the robot (its ``ROBOT:`` section): the robot type as ABB
    names it (``ROB1_4600_2.55_40``: an IRB 4600 of 2.55 m reach and 40 kg payload), the base frame
    in the world (position m, quaternion w x y z) and ``gravity_beta`` (rad: 0 floor, pi/2 wall, pi
    ceiling)."""

    path: str
    robot_type: str | None = None
    base_pos_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    base_quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    gravity_beta: float = 0.0
    robot: str | None = None
    """The ``ROBOT`` instance read (``ROB_2``), where the file names one."""
    robots: tuple[str, ...] = ()
    """Every ``ROBOT`` instance the file configures (a cell of several arms: ``ROB_1``, ``ROB_2``)."""

    @property
    def family(self) -> tuple[str, float | None, float | None] | None:
        """``(IRB family, reach m, payload kg)`` read from :attr:`robot_type`, or None."""
        if self.robot_type is None:
            return None
        m = re.match(r"ROB\d*_([0-9]+[A-Za-z]*)_([0-9.]+)_([0-9.]+)", self.robot_type)
        if m is None:
            return None
        return m.group(1), float(m.group(2)), float(m.group(3))

    @property
    def moves_the_base(self) -> bool:
        """Whether the base frame is other than the world's (targets go by it)."""
        return self.base_pos_m != (0.0, 0.0, 0.0) or self.base_quat != (1.0, 0.0, 0.0, 0.0)

    @property
    def mounting(self) -> str:
        beta = abs(self.gravity_beta) % (2 * math.pi)
        if beta < 0.1 or beta > 2 * math.pi - 0.1:
            return "floor"
        return "ceiling" if abs(beta - math.pi) < 0.1 else f"tilted ({math.degrees(beta):.0f} deg)"

    def lines(self) -> list[str]:
        """What was read, a line each, for the run's notes."""
        out = []
        fam = self.family
        if len(self.robots) > 1:
            out.append(
                f"{self.path}: {len(self.robots)} robots ({', '.join(self.robots)}): {self.robot}'s data "
                "read (the task's number names it; else the first)"
            )
        if self.robot_type is not None:
            what = (
                f" (an IRB {fam[0]}, {fam[1]:g} m reach, {fam[2]:g} kg)" if fam and fam[1] and fam[2] else ""
            )
            out.append(f"{self.path}: the robot type is {self.robot_type}{what}")
        if self.moves_the_base:
            pos = ", ".join(f"{1000 * v:.0f}" for v in self.base_pos_m)
            quat = ", ".join(f"{v:.4g}" for v in self.base_quat)
            out.append(
                f"{self.path}: the base frame is at [{pos}] mm, [{quat}] in the world (targets go by it)"
            )
        if self.mounting != "floor":
            out.append(
                f"{self.path}: the arm is {self.mounting}-mounted (gravity_beta {self.gravity_beta:g} rad); "
                "joulepath's dynamics take it floor-mounted, so the energies are those of a floor-mounted arm"
            )
        return out


def task_number(paths: Sequence[str | Path]) -> int | None:
    """The task's number that its modules' paths name (a backup's ``RAPID/TASK2``, a ``T_ROB2``
    folder), where they all name the same one; else None."""
    found = set()
    for raw in paths:
        for part in Path(raw).parts:
            m = re.fullmatch(r"(?:TASK|T_ROB)(\d{1,2})", part, re.I)
            if m:
                found.add(int(m.group(1)))
    return found.pop() if len(found) == 1 else None


def read_moc(path: Path, task: int | None = None) -> MotionConfig:
    """The robot's type, base frame and mounting from a ``MOC.cfg`` (other sections are ignored).

    A cell of several arms configures several ``ROBOT`` instances (``-name "ROB_1"``, ``"ROB_2"``),
    each with its own type and base frame: the one of task number ``task`` (``ROB_2`` for TASK2)
    is read where the file has it, else the first; each instance's data alone."""
    data = read_capped(path, max_bytes=MAX_BYTES, what="a motion configuration (MOC.cfg)", error=RapidError)
    text, _, _ = decode(data)
    text = text.replace("\\\n", " ")
    section = re.search(r"^ROBOT:\s*$(.*?)(?=^[A-Z_]+:\s*$|\Z)", text, re.M | re.S)
    whole = section.group(1) if section else ""
    starts = [m.start() for m in re.finditer(r"-name\s+\"", whole)]
    instances = [whole[a:b] for a, b in zip(starts, [*starts[1:], len(whole)], strict=True)] or [whole]
    names = [m.group(1) if m else "" for m in (re.search(r'-name\s+"([^"]{1,40})"', i) for i in instances)]
    chosen = 0
    if task is not None:
        chosen = next((k for k, name in enumerate(names) if re.fullmatch(rf"ROB_?{task}", name, re.I)), 0)
    body = instances[chosen]

    def num(key: str, default: float) -> float:
        m = re.search(rf"-{key}\s+(-?[0-9.]+(?:[eE][-+]?[0-9]+)?)", body)
        try:
            value = float(m.group(1)) if m else default
        except ValueError:
            value = default
        return value if math.isfinite(value) else default

    kind = re.search(r'-use_robot_type\s+"([^"]{1,80})"', body)
    quat = tuple(num(f"base_frame_orient_u{k}", 1.0 if k == 0 else 0.0) for k in range(4))
    norm = math.sqrt(sum(v * v for v in quat))
    return MotionConfig(
        str(path),
        kind.group(1) if kind else None,
        (num("base_frame_pos_x", 0.0), num("base_frame_pos_y", 0.0), num("base_frame_pos_z", 0.0)),
        tuple(v / norm for v in quat) if norm > 0.5 else (1.0, 0.0, 0.0, 0.0),  # type: ignore[arg-type]
        num("gravity_beta", 0.0),
        names[chosen] or None,
        tuple(n for n in names if n),
    )


def find_moc(paths: Sequence[str | Path]) -> MotionConfig | None:
    """The ``MOC.cfg`` given among ``paths`` or found in a folder of them, read (for the task whose
    number the modules' paths name: :func:`task_number`); None where there is none."""
    modules: list[Path] = []
    moc: Path | None = None
    for raw in paths:
        p = Path(raw)
        if p.is_file() and p.name.lower() == "moc.cfg":
            moc = moc or p
        elif p.is_dir():
            found = sorted(f for f in p.rglob("*") if f.is_file() and f.name.lower() == "moc.cfg")
            moc = moc or (found[0] if found else None)
            modules.extend(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in MODULE_SUFFIXES)
        else:
            modules.append(p)
    return None if moc is None else read_moc(moc, task_number(modules))


@dataclass(frozen=True, slots=True)
class Task:
    """The modules of one task, the signals the I/O configuration declares, and where they came from."""

    modules: tuple[n.Module, ...]
    signals: frozenset[str]
    source: str
    eio: str | None = None
    moc: MotionConfig | None = None
    notes: tuple[str, ...] = ()

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
    moc: list[Path] = []
    found_in_folders: set[Path] = set()
    if not paths:
        raise RapidError("no program given: name a module file (.mod, .sys) or a task's folder")
    for raw in paths:
        p = Path(raw)
        if p.is_dir():
            found = sorted(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in MODULE_SUFFIXES)
            eio.extend(sorted(f for f in p.rglob("*") if f.is_file() and f.name.lower() == "eio.cfg"))
            moc.extend(sorted(f for f in p.rglob("*") if f.is_file() and f.name.lower() == "moc.cfg"))
            if not found:
                raise RapidError(f"{p}: the folder holds no RAPID module (.mod, .sys); give a task's folder")
            files.extend(found)
            found_in_folders.update(found)
        elif p.suffix.lower() == ".cfg" and p.is_file():
            (moc if p.name.lower() == "moc.cfg" else eio).append(p)
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
    modules = []
    notes = []
    for f in unique:
        try:
            modules.append(read_module_file(f))
        except RapidError as err:  # an encrypted module in a backup's folder: the task runs without it
            if f in found_in_folders and "a binary file" in str(err):
                notes.append(
                    f"{f}: an encrypted or binary module, left out (its routines are declared nowhere)"
                )
                continue
            raise
    if not modules:
        raise RapidError(f"{', '.join(map(str, paths))}: no module could be read (binary files only)")
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
    return Task(
        tuple(modules),
        signals,
        source,
        str(eio[0]) if eio else None,
        read_moc(moc[0], task_number(unique)) if moc else None,
        tuple(notes),
    )
