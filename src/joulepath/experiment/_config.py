"""Experiment files: one TOML file describes a whole study, validated before anything runs.

Example (``joulepath/experiment/presets/demo.toml``)::

    name = "demo"
    robot = "irb120"
    seed = 0

    [data]            # simulate (plant, moves) or ingest logs
    plant = "lab"
    train_moves = 40
    test_moves = 15

    [train]
    families = ["mlp", "svr", "par", "xgb"]
    targets = ["E"]
    grid = "quick"
    cv = 3
    inputs = "physics"

    [optimize]
    tasks = 3
    algorithm = "ma-informed"
    fitness = "surrogate"
    generations = 100
    population = 100

A wrong key or value stops the run at once with the key, the allowed keys or values,
and the file.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from joulepath.errors import InvalidInput


@dataclass(frozen=True, slots=True, kw_only=True)
class DataStage:
    """Where the data comes from: a simulated plant, or controller/generic logs."""

    plant: str = "lab"
    train_moves: int = 40
    test_moves: int = 15
    train_logs: tuple[str, ...] = ()
    test_logs: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class TrainStage:
    families: tuple[str, ...] = ("mlp", "svr", "par", "xgb")
    targets: tuple[str, ...] = ("E",)
    grid: str = "quick"
    cv: int = 3
    inputs: str = "physics"
    jobs: int = 1
    scheduler: str = ""


@dataclass(frozen=True, slots=True, kw_only=True)
class OptimizeStage:
    tasks: int = 3
    algorithm: str = "ma-informed"
    fitness: str = "surrogate"
    generations: int = 100
    population: int = 100
    range_set: str = "lab"


@dataclass(frozen=True, slots=True, kw_only=True)
class Experiment:
    """A whole study: data -> models -> optimized moves."""

    name: str
    robot: str = "irb120"
    seed: int = 0
    data: DataStage = field(default_factory=DataStage)
    train: TrainStage = field(default_factory=TrainStage)
    optimize: OptimizeStage = field(default_factory=OptimizeStage)
    source: str = ""


_ALLOWED = {
    "plant": ("sim", "lab"),
    "grid": ("quick", "thesis"),
    "inputs": ("physics", "thesis"),
    "algorithm": ("ga", "de", "ma-random", "ma-informed"),
    "fitness": ("surrogate", "surrogate-joints", "physics"),
}


def _section(cls: Any, raw: dict[str, Any], where: str, source: str) -> Any:
    names = {f.name: f for f in fields(cls) if f.name not in ("data", "train", "optimize", "source")}
    kwargs: dict[str, Any] = {}
    for key, value in raw.items():
        if key not in names:
            raise InvalidInput(f"{source}: {where}unknown key {key!r}; allowed: {', '.join(sorted(names))}")
        default = names[key].default
        if key == "name":
            default = ""
        if isinstance(default, tuple):
            if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
                raise InvalidInput(f"{source}: {where}{key} must be a list of strings, got {value!r}")
            value = tuple(value)
        elif isinstance(default, bool) or not isinstance(value, type(default)):
            raise InvalidInput(f"{source}: {where}{key} must be a {type(default).__name__}, got {value!r}")
        if key in _ALLOWED and value not in _ALLOWED[key]:
            raise InvalidInput(
                f"{source}: {where}{key} = {value!r} is not allowed; use one of {', '.join(_ALLOWED[key])}"
            )
        if isinstance(value, int) and value < (0 if key == "seed" else 1) and key not in ("seed",):
            raise InvalidInput(f"{source}: {where}{key} must be ≥ 1, got {value}")
        kwargs[key] = value
    return cls(**kwargs)


def load_experiment(path: str | os.PathLike[str]) -> Experiment:
    """Read and validate an experiment file (see the module docstring).

    Raises
    ------
    InvalidInput
        Unreadable TOML, an unknown section or key, a value of the wrong type or
        outside its allowed values.
    """
    p = Path(path)
    source = str(p)
    try:
        raw = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as err:
        raise InvalidInput(f"{source}: cannot be read ({err.strerror})") from err
    except tomllib.TOMLDecodeError as err:
        raise InvalidInput(f"{source}: not valid TOML ({err})") from err
    top = {k: v for k, v in raw.items() if not isinstance(v, dict)}
    sections = {k: v for k, v in raw.items() if isinstance(v, dict)}
    unknown = sorted(set(sections) - {"data", "train", "optimize"})
    if unknown:
        raise InvalidInput(f"{source}: unknown section [{unknown[0]}]; allowed: [data], [train], [optimize]")
    if "name" not in top:
        raise InvalidInput(f"{source}: missing key 'name' at the top of the file")
    exp = _section(Experiment, top, "", source)
    return Experiment(
        name=exp.name,
        robot=exp.robot,
        seed=exp.seed,
        source=source,
        data=_section(DataStage, sections.get("data", {}), "[data] ", source),
        train=_section(TrainStage, sections.get("train", {}), "[train] ", source),
        optimize=_section(OptimizeStage, sections.get("optimize", {}), "[optimize] ", source),
    )
