"""Robot programs: read a RAPID module (or a plain cycle file), run its cycle as the
controller does, optimize it."""

from joulepath.program._cell import Cell, read_cell
from joulepath.program._cycle import CycleOptimizer, check_cycle, optimize_cycle, pareto
from joulepath.program._cycle_model import (
    FAST_CYCLE,
    Breakdown,
    CycleResult,
    CycleSettings,
    MoveOutcome,
    ParetoPoint,
)
from joulepath.program._levers import LeverResult, MoveLever, levers_module
from joulepath.program._model import Module, RapidError
from joulepath.program._output import CYCLE_FILES, optimized_module, write_cycle_run
from joulepath.program._parse import parse_module, read_module
from joulepath.program._pipeline import (
    LEVER_PLANS,
    ProgramResult,
    ProgramSettings,
    optimize_program,
)
from joulepath.program._resolve import (
    CycleSpec,
    read_cycle_program,
    read_cycle_toml,
    read_rapid_cycle,
    resolve_module,
)
from joulepath.program._scenario import Scenario, read_scenario, scenario_from_dict
from joulepath.program._simulate import ProgramMotion, ProgramRun, program_motion, simulate_program
from joulepath.program._via_levers import ViaLevers, via_levers
from joulepath.program._write import format_move, write_module
from joulepath.sim import plan_cycle

__all__ = [
    "Breakdown",
    "CYCLE_FILES",
    "Cell",
    "CycleOptimizer",
    "CycleResult",
    "CycleSettings",
    "CycleSpec",
    "FAST_CYCLE",
    "LEVER_PLANS",
    "LeverResult",
    "Module",
    "MoveLever",
    "MoveOutcome",
    "ParetoPoint",
    "ProgramMotion",
    "ProgramResult",
    "ProgramRun",
    "ProgramSettings",
    "RapidError",
    "Scenario",
    "ViaLevers",
    "check_cycle",
    "format_move",
    "levers_module",
    "optimize_cycle",
    "optimize_program",
    "optimized_module",
    "pareto",
    "parse_module",
    "plan_cycle",
    "program_motion",
    "read_cell",
    "read_cycle_program",
    "read_cycle_toml",
    "read_module",
    "read_rapid_cycle",
    "read_scenario",
    "resolve_module",
    "scenario_from_dict",
    "simulate_program",
    "via_levers",
    "write_cycle_run",
    "write_module",
]
