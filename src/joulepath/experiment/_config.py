"""Experiment files: one TOML file describes a whole study, validated before anything runs.

Example (``joulepath/experiment/presets/demo.toml``, abridged)::

    name = "demo"
    robot = "irb120"
    seed = 0
    scheduler = ""        # a Dask scheduler address ("tcp://host:8786") for grid search and benchmark

    [data]                # simulate on a plant, or ingest logs (train_logs / test_logs)
    plant = "lab"
    train_moves = 30
    test_moves = 10
    micro_moves = 10      # the thesis' small real sample that synthesis grows (0: none)
    sim_moves = 20        # the thesis' simulated dataset, on the nominal "sim" plant (0: none)

    [synth]               # optional: grow synthetic rows from a small real sample
    methods = ["copula"]  # or "tvae", "ctgan", "copulagan"
    rows = 2000

    [train]
    families = ["mlp", "svr", "par", "xgb"]
    targets = ["E"]
    grid = "quick"

    [importance]
    targets = ["E", "E1", "E2", "E3", "E4", "E5", "E6"]

    [optimize]
    tasks = 1
    algorithm = "auto"     # gradient on physics, cmaes on a learned model; or ga, de, ma-*
    fitness = "physics"
    energy = "thesis"      # or "mechanical", "electrical" (needs the robot's drive data)
    reference = true       # also solve each task to the optimum (needs the `reference` extra)

    [bench]               # optional: every GA/DE/MA configuration on the same random tasks
    tasks = 2
    generations = 15

    [identify]            # optional: a calibrated twin from the training logs (joulepath identify)
    enabled = true
    loop_tasks = 1        # tasks optimized on the twin: predicted against realized saving

    [cycle]               # optional: a robot program's whole cycle (joulepath cycle)
    program = "pick_and_place.mod"   # RAPID module or plain cycle TOML, relative to this file
    cell = ""             # cell file (obstacles) the moves must clear; "" for the TCP corridor
    cycle_time = 0.0      # s; 0: the default program's cycle time
    pareto_points = 0     # ≥ 3: also energy against cycle time
    fly_by = true         # false: optimize only moves that run rest to rest on their own
    write_anyway = false  # true: write optimized.mod even if the controller would not run it as planned

Sections left out take their defaults; ``[synth]``, ``[bench]``, ``[identify]`` and ``[cycle]``
are skipped unless they are given (``methods`` non-empty, ``tasks`` ≥ 1, ``enabled = true``,
``program`` non-empty).
A wrong key or value stops the run at once with the file, the section and key, and the
allowed keys or values. Every
count, ``jobs`` and ``seed`` has a range (:data:`BOUNDS`), checked before anything runs.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from joulepath.description import DEFAULT_ROBOT
from joulepath.energy import DEFAULT_MEASURE, MEASURES, energy_measure
from joulepath.errors import InvalidInput
from joulepath.export import EXPORTERS
from joulepath.optimize import ALGORITHMS, AUTO, FITNESS, fitness_kind, resolve_algorithm

ALL_TARGETS = ("E", "E1", "E2", "E3", "E4", "E5", "E6")


@dataclass(frozen=True, slots=True, kw_only=True)
class DataStage:
    """Where the data comes from: a simulated plant, or controller/generic logs.

    ``train`` plays the thesis' real 1000-move dataset, ``test`` its 100 other moves,
    ``micro`` its small real sample (the synthesizers' source) and ``sim`` its
    simulated dataset (nominal model, no plant error).
    """

    plant: str = "lab"
    range_set: str = "collection"
    train_moves: int = 40
    test_moves: int = 15
    micro_moves: int = 0
    sim_moves: int = 0
    train_logs: tuple[str, ...] = ()
    test_logs: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class SynthStage:
    """Synthetic rows grown from ``source`` by each method, scored against real data."""

    methods: tuple[str, ...] = ()
    rows: int = 5000
    epochs: int = 100
    batch_size: int = 500
    source: str = "micro"
    repair: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class TrainStage:
    families: tuple[str, ...] = ("mlp", "svr", "par", "xgb")
    targets: tuple[str, ...] = ("E",)
    grid: str = "quick"
    cv: int = 3
    inputs: str = "physics"


@dataclass(frozen=True, slots=True, kw_only=True)
class ImportanceStage:
    """Feature importance by five methods for each target (thesis Figs 4.1–4.2)."""

    targets: tuple[str, ...] = ALL_TARGETS
    max_rows: int = 3000


@dataclass(frozen=True, slots=True, kw_only=True)
class OptimizeStage:
    """Random feasible tasks optimized and verified (thesis Table 4.7).

    ``algorithm`` is ``auto`` or a name of :data:`joulepath.optimize.ALGORITHMS`;
    ``generations`` and ``population`` set the evolutionary searches; ``reference``
    also solves every task with the reference solver (CasADi + IPOPT, slow) so the
    report can state the share of the optimum's saving reached. ``export`` names the
    program each task folder gets (:data:`joulepath.export.EXPORTERS`; empty: the
    controller the robot declares, RAPID for the IRB 120). ``energy`` is the measure
    minimized (:data:`joulepath.energy.MEASURES`; ``electrical`` needs the robot's drive data).
    """

    tasks: int = 3
    algorithm: str = "auto"
    fitness: str = "physics"
    generations: int = 100
    population: int = 100
    range_set: str = "lab"
    reference: bool = False
    export: str = ""
    energy: str = DEFAULT_MEASURE


@dataclass(frozen=True, slots=True, kw_only=True)
class BenchStage:
    """Optimizer benchmark (thesis Tables 4.5–4.6, Fig 4.19); off while ``tasks`` is 0."""

    tasks: int = 0
    generations: int = 250
    population: int = 100
    fitness: str = "physics"
    configurations: str = "thesis"


@dataclass(frozen=True, slots=True, kw_only=True)
class IdentifyStage:
    """A calibrated twin identified from the training logs (off unless ``enabled``).

    Scores the twin and the nominal physics on the test logs, then optimizes
    ``loop_tasks`` random tasks of ``range_set`` on the twin and compares the saving it
    predicts with the one realized on the lab plant.
    """

    enabled: bool = False
    loop_tasks: int = 3
    range_set: str = "lab"


@dataclass(frozen=True, slots=True, kw_only=True)
class CycleStage:
    """A robot program's whole cycle optimized at the same or a given cycle time (off while program is "").

    The stage runs what ``joulepath cycle`` runs: ``program`` (a RAPID module, or a plain
    cycle TOML for arms without RAPID) and ``cell`` (a cell TOML; "" keeps the TCP within
    ``corridor_mm`` of the taught path instead, 0: no corridor) are paths relative to the
    experiment file; ``cycle_time`` 0 keeps the default program's; ``use_waits`` spends
    the waits declared idle (``! joulepath: idle``) on the moves; ``pareto_points`` ≥ 3 also
    computes energy against cycle time; ``fly_by`` false optimizes only the moves that run from
    rest to rest on their own (chains through fly-by targets stay as taught); ``write_anyway``
    writes the RAPID module even when the controller emulation does not run it as planned.
    """

    program: str = ""
    cell: str = ""
    cycle_time: float = 0.0
    use_waits: bool = False
    pareto_points: int = 0
    corridor_mm: float = 100.0
    fly_by: bool = True
    write_anyway: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class Experiment:
    """A whole study: data -> synthetic data -> models -> importance -> optimized moves -> benchmark."""

    name: str
    robot: str = DEFAULT_ROBOT
    seed: int = 0
    jobs: int = 1
    scheduler: str = ""
    data: DataStage = field(default_factory=DataStage)
    synth: SynthStage = field(default_factory=SynthStage)
    train: TrainStage = field(default_factory=TrainStage)
    importance: ImportanceStage = field(default_factory=ImportanceStage)
    optimize: OptimizeStage = field(default_factory=OptimizeStage)
    bench: BenchStage = field(default_factory=BenchStage)
    identify: IdentifyStage = field(default_factory=IdentifyStage)
    cycle: CycleStage = field(default_factory=CycleStage)
    source: str = ""


SECTIONS: dict[str, type] = {
    "data": DataStage,
    "synth": SynthStage,
    "train": TrainStage,
    "importance": ImportanceStage,
    "optimize": OptimizeStage,
    "bench": BenchStage,
    "identify": IdentifyStage,
    "cycle": CycleStage,
}

_ALLOWED: dict[str, tuple[str, ...]] = {
    "plant": ("sim", "lab"),
    "grid": ("quick", "thesis"),
    "inputs": ("physics", "thesis"),
    "algorithm": (AUTO, *ALGORITHMS),
    "fitness": FITNESS,
    "source": ("micro", "train"),
    "configurations": ("thesis", "compact"),
    "methods": ("copula", "copulagan", "ctgan", "tvae"),
    "families": ("mlp", "svr", "par", "xgb"),
    "targets": ALL_TARGETS,
    "export": ("", *EXPORTERS),
    "energy": tuple(MEASURES),
}
BOUNDS: dict[str, dict[str, tuple[int, int]]] = {
    "": {"seed": (0, 2**32 - 1), "jobs": (1, 256)},
    "data": {
        "train_moves": (1, 20_000),
        "test_moves": (1, 20_000),
        "micro_moves": (0, 20_000),
        "sim_moves": (0, 20_000),
    },
    "synth": {"rows": (1, 1_000_000), "epochs": (1, 10_000), "batch_size": (2, 100_000)},
    "train": {"cv": (2, 20)},
    "importance": {"max_rows": (1, 1_000_000)},
    "optimize": {"tasks": (0, 1_000), "generations": (1, 10_000), "population": (4, 10_000)},
    "bench": {"tasks": (0, 10_000), "generations": (1, 10_000), "population": (4, 10_000)},
    "identify": {"loop_tasks": (0, 1_000)},
    "cycle": {"pareto_points": (0, 30)},
}
"""Allowed range (inclusive) of every integer setting, by section (``""``: top level).

The upper bounds are about 10× (data, synthesis) to 500× (bench tasks) the thesis plan,
so that a typo such as ``train_moves = 1_000_000_000_000`` is refused at once instead of
running out of memory or running for years.
"""
_TYPE_NAMES = {int: "an integer", str: "a string", bool: "true or false", float: "a number"}
_MAX_FILE_BYTES = 1 << 20
_MAX_TEXT = 200
_MAX_LIST = 64


def _show(value: object) -> str:
    """``repr`` of a value, cut short for a one-line message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _has_control(text: str) -> bool:
    return any(ord(c) < 32 or ord(c) == 127 for c in text)


def _section(cls: Any, raw: dict[str, Any], where: str, source: str) -> Any:
    hidden = {*SECTIONS, "source"} if cls is Experiment else set()
    names = {f.name: f for f in fields(cls) if f.name not in hidden}
    bounds = BOUNDS[where.strip().strip("[]")]
    kwargs: dict[str, Any] = {}
    for key, value in raw.items():
        if key not in names:
            raise InvalidInput(
                f"{source}: {where}unknown key {_show(key)}; allowed: {', '.join(sorted(names))}"
            )
        default = names[key].default
        if key == "name":
            default = ""
        allowed = _ALLOWED.get(key)
        if isinstance(default, tuple):
            if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
                raise InvalidInput(
                    f"{source}: {where}{key} must be a list of strings, got {_show(value)}; "
                    f'write it as {key} = ["…", "…"]'
                )
            bad = [v for v in value if allowed and v not in allowed]
            if bad:
                raise InvalidInput(
                    f"{source}: {where}{key} has {_show(bad[0])}, which is not allowed; "
                    f"use some of {', '.join(allowed or ())}"
                )
            if len(value) > _MAX_LIST:
                raise InvalidInput(f"{source}: {where}{key} has {len(value)} items; at most {_MAX_LIST}")
            twice = sorted({v for v in value if value.count(v) > 1})
            if twice:
                raise InvalidInput(
                    f"{source}: {where}{key} names {_show(twice[0])} more than once; list each once"
                )
            if any(not v or len(v) > 4096 or "\x00" in v for v in value):
                raise InvalidInput(
                    f"{source}: {where}{key} has an empty, over-long or NUL-containing item; "
                    "give plain names or paths"
                )
            value = tuple(value)
        elif isinstance(default, float) and type(value) is int:
            value = float(value)
            kwargs[key] = value
            continue
        elif type(value) is not type(default):
            raise InvalidInput(
                f"{source}: {where}{key} must be {_TYPE_NAMES.get(type(default), type(default).__name__)}, "
                f"got {_show(value)}"
            )
        elif allowed and value not in allowed:
            raise InvalidInput(
                f"{source}: {where}{key} = {_show(value)} is not allowed; use one of {', '.join(allowed)}"
            )
        elif isinstance(value, int) and not isinstance(value, bool):
            low, high = bounds[key]
            if not low <= value <= high:
                side = f"must be ≥ {low}" if value < low else f"must be ≤ {high:_}"
                raise InvalidInput(
                    f"{source}: {where or '[top level] '}{key} {side}, got {value:_}; "
                    f"the allowed range is {low}..{high:_}"
                )
        elif isinstance(value, str) and key != "name" and (len(value) > _MAX_TEXT or _has_control(value)):
            raise InvalidInput(
                f"{source}: {where}{key} = {_show(value)} is over {_MAX_TEXT} characters "
                "or holds control characters; give a plain value"
            )
        kwargs[key] = value
    return cls(**kwargs)


def _check_together(exp: Experiment, source: str) -> None:
    """Settings that are valid alone but not together."""
    d, s, t, o = exp.data, exp.synth, exp.train, exp.optimize
    if bool(d.train_logs) != bool(d.test_logs):
        raise InvalidInput(
            f"{source}: [data] give both train_logs and test_logs (other moves), or neither to simulate"
        )
    if s.methods and s.source == "micro" and d.micro_moves == 0:
        raise InvalidInput(
            f"{source}: [synth] source = 'micro' needs [data] micro_moves ≥ 1; "
            "set micro_moves, or source = 'train'"
        )
    if s.methods and s.source == "micro" and d.train_logs:
        raise InvalidInput(f"{source}: [synth] source = 'micro' simulates its sample; with logs use 'train'")
    if s.methods and s.rows < 20:
        raise InvalidInput(f"{source}: [synth] rows must be ≥ 20 to score the rows, got {s.rows}")
    c = exp.cycle
    if not (0.0 <= c.cycle_time < 3600.0):
        raise InvalidInput(
            f"{source}: [cycle] cycle_time must be 0 (the program's own) or seconds below 3600, "
            f"got {c.cycle_time}"
        )
    if not (0.0 <= c.corridor_mm <= 10_000.0):
        raise InvalidInput(f"{source}: [cycle] corridor_mm must be 0..10000 mm, got {c.corridor_mm}")
    if c.pareto_points in (1, 2):
        raise InvalidInput(f"{source}: [cycle] pareto_points must be 0 (off) or ≥ 3, got {c.pareto_points}")
    if c.cell and not c.program:
        raise InvalidInput(f'{source}: [cycle] cell is given but program is not; add program = "….mod"')
    if c.program and Path(c.program).suffix.lower() not in (".mod", ".toml"):
        raise InvalidInput(
            f"{source}: [cycle] program {c.program!r} must be a RAPID module (.mod) or a cycle file (.toml)"
        )
    try:
        resolve_algorithm(o.algorithm, o.fitness)
    except InvalidInput as err:
        raise InvalidInput(f"{source}: [optimize] {err}") from None
    if o.energy != DEFAULT_MEASURE and o.fitness != "physics":
        raise InvalidInput(
            f"{source}: [optimize] energy = {o.energy!r} needs fitness = 'physics' (the learned models "
            "predict the thesis' energy)"
        )
    if o.reference and o.fitness != "physics":
        raise InvalidInput(
            f"{source}: [optimize] reference = true needs fitness = 'physics' (a physics optimum)"
        )
    for where, fitness in (("[optimize]", o.fitness), ("[bench]", exp.bench.fitness)):
        if where == "[bench]" and exp.bench.tasks == 0:
            continue
        needs = fitness_kind(fitness).model_targets(len(ALL_TARGETS) - 1)  # the study's arm: E1..E6
        missing = [x for x in needs if x not in t.targets]
        if missing or (needs and not t.families):
            raise InvalidInput(
                f"{source}: {where} fitness = {fitness!r} needs models of "
                f"{', '.join(needs)}; add them to [train] targets (and a family), "
                "or use fitness = 'physics'"
            )


def load_experiment(path: str | os.PathLike[str]) -> Experiment:
    """Read and validate an experiment file (see the module docstring).

    Raises
    ------
    InvalidInput
        Unreadable TOML, an unknown section or key, a value of the wrong type or
        outside its allowed values, or settings that contradict each other.
    """
    p = Path(path)
    source = str(p)
    try:
        if p.exists() and not p.is_file():
            what = "is a folder" if p.is_dir() else "is not a regular file"
            raise InvalidInput(f"{source}: {what}; give a path to a TOML file, or 'demo'")
        if p.exists() and p.stat().st_size > _MAX_FILE_BYTES:
            raise InvalidInput(
                f"{source}: is larger than {_MAX_FILE_BYTES >> 20} MiB; an experiment file is a few kB"
            )
        raw = tomllib.loads(p.read_text(encoding="utf-8"))
    except InvalidInput:
        raise
    except FileNotFoundError as err:
        raise InvalidInput(
            f"{source}: no such experiment file; give a path to a TOML file, or 'demo'"
        ) from err
    except OSError as err:
        raise InvalidInput(f"{source}: cannot be read ({err.strerror})") from err
    except UnicodeDecodeError as err:
        raise InvalidInput(f"{source}: not UTF-8 text ({err.reason}); save it as UTF-8") from err
    except tomllib.TOMLDecodeError as err:
        raise InvalidInput(f"{source}: not valid TOML ({err}); fix the syntax there") from err
    except (ValueError, RecursionError, MemoryError) as err:  # e.g. arrays nested thousands deep
        raise InvalidInput(f"{source}: not valid TOML ({type(err).__name__}); fix the syntax there") from err
    top = {k: v for k, v in raw.items() if not isinstance(v, dict)}
    sections = {k: v for k, v in raw.items() if isinstance(v, dict)}
    unknown = sorted(set(sections) - set(SECTIONS))
    if unknown:
        raise InvalidInput(
            f"{source}: unknown section [{_show(unknown[0])[1:-1]}]; "
            f"allowed: {', '.join(f'[{s}]' for s in SECTIONS)}"
        )
    if "name" not in top:
        raise InvalidInput(f"{source}: missing key 'name' at the top of the file; add name = \"my-study\"")
    exp = _section(Experiment, top, "", source)
    name = exp.name
    if (
        not name.strip()
        or name in (".", "..")
        or len(name) > 100
        or _has_control(name)
        or any(c in name for c in '/\\:*?"<>|')
    ):
        raise InvalidInput(
            f"{source}: name {_show(name)} must be a folder name of 1 to 100 characters, not . or .., "
            "without / \\ : * ? or control characters"
        )
    parts = {
        name: _section(cls, sections.get(name, {}), f"[{name}] ", source) for name, cls in SECTIONS.items()
    }
    exp = Experiment(
        name=exp.name,
        robot=exp.robot,
        seed=exp.seed,
        jobs=exp.jobs,
        scheduler=exp.scheduler,
        source=source,
        **parts,
    )
    base = p.resolve().parent
    data = exp.data
    named = (
        ("[cycle]", "program", (exp.cycle.program,)),
        ("[cycle]", "cell", (exp.cycle.cell,)),
        ("[data]", "train_logs", data.train_logs),
        ("[data]", "test_logs", data.test_logs),
    )
    for section, key, given in named:
        for item in filter(None, given):
            item_path = Path(item) if Path(item).is_absolute() else base / item
            if not item_path.is_file():
                raise InvalidInput(
                    f"{source}: {section} {key} names {item!r}, which does not exist "
                    f"(paths are relative to the experiment file's folder)"
                )
    _check_together(exp, source)
    robot = _check_robot(exp, source)
    _check_stages(exp, robot, source)
    return exp


def _check_stages(exp: Experiment, robot: Any, source: str) -> None:
    """Every stage's settings and files that can be checked before the first stage starts.

    The ``[optimize]`` program exporter for the robot; ``[identify]``: an IRML robot (a twin
    is written as IRML) and its range set; ``[cycle]``: the program read and resolved for the
    robot, the cell file with its meshes read, the settings built and the default cycle planned.
    """
    from joulepath.errors import JoulepathError
    from joulepath.export import select_exporter

    _check_extras(exp, source)
    o = exp.optimize
    if o.tasks:
        try:
            select_exporter(robot, o.export or None)
        except JoulepathError as err:
            raise InvalidInput(f"{source}: [optimize] export = {o.export!r}: {err}") from err
    st = exp.identify
    if st.enabled:
        if robot.description is None:
            raise InvalidInput(
                f"{source}: [identify] needs a robot described in IRML (the twin is written as IRML); "
                f"robot = {exp.robot!r} comes from a URDF: use an .irml robot, or drop [identify]"
            )
        from joulepath.dynamics import FALLBACK_RANGE_SETS

        if st.range_set not in (*robot.range_set_names, *FALLBACK_RANGE_SETS):
            raise InvalidInput(
                f"{source}: [identify] range_set = {st.range_set!r} is not a range set of {robot.name}; "
                f"use one of {', '.join(robot.range_set_names)}"
            )
    c = exp.cycle
    if c.program:
        from joulepath.program import CycleSettings, check_cycle, read_cell, read_cycle_program

        program, cell = (
            resolve_logs(exp, (c.program,))[0],
            (resolve_logs(exp, (c.cell,))[0] if c.cell else None),
        )
        try:
            spec, _ = read_cycle_program(program, robot)
            settings = CycleSettings(
                cell=read_cell(cell) if cell is not None else None,
                cycle_time=c.cycle_time or None,
                use_waits=c.use_waits,
                fly_by=c.fly_by,
                corridor_mm=c.corridor_mm or None,
                seed=exp.seed,
            )
            check_cycle(spec, settings)
        except JoulepathError as err:
            raise InvalidInput(f"{source}: [cycle] {err}") from err


_EXTRAS: tuple[tuple[str, str, str], ...] = (
    ("synth.methods", "sdv", "synth"),
    ("train.families", "skops", "ml"),
    ("xgb", "xgboost", "ml"),
    ("optimize.reference", "casadi", "reference"),
    ("scheduler", "distributed", "dask"),
)
"""(setting, the module it needs, the extra that installs it), checked before the first stage."""


def _check_extras(exp: Experiment, source: str) -> None:
    """Refuse, before any stage runs, settings whose optional packages are not installed."""
    import importlib.util

    used = {
        "synth.methods": bool(exp.synth.methods),
        "train.families": bool(exp.train.families),
        "xgb": "xgb" in exp.train.families,
        "optimize.reference": exp.optimize.reference and exp.optimize.tasks > 0,
        "scheduler": bool(exp.scheduler),
    }
    for setting, module, extra in _EXTRAS:
        if used[setting] and importlib.util.find_spec(module) is None:
            what = "[train] families = 'xgb'" if setting == "xgb" else setting
            raise InvalidInput(
                f"{source}: {what} needs the optional package {module!r}, which is not installed; "
                f"pip install 'joulepath[{extra}]', or change the setting"
            )


def _check_robot(exp: Experiment, source: str) -> Any:
    from joulepath.dynamics import FALLBACK_RANGE_SETS, load_robot
    from joulepath.errors import JoulepathError

    try:
        robot = load_robot(exp.robot)
    except JoulepathError as err:
        raise InvalidInput(f"{source}: robot = {exp.robot!r}: {err}") from err
    why = energy_measure(exp.optimize.energy).missing(robot.drivetrain)
    if why is not None:
        raise InvalidInput(f"{source}: [optimize] energy = {exp.optimize.energy!r}: {why}")
    names = robot.range_set_names
    if exp.optimize.range_set not in (*names, *FALLBACK_RANGE_SETS):
        raise InvalidInput(
            f"{source}: [optimize] range_set = {exp.optimize.range_set!r} is not a range set of "
            f"{robot.name}; use one of {', '.join(names)}"
        )
    return robot


def resolve_logs(exp: Experiment, logs: tuple[str, ...]) -> list[str]:
    """Log paths of ``exp`` made absolute, relative to the experiment file's folder."""
    base = Path(exp.source).resolve().parent if exp.source else Path.cwd()
    return [str(Path(p) if Path(p).is_absolute() else base / p) for p in logs]
