"""A whole plant: every cell program optimized as one task on Dask, resumable, with a plant report.

:func:`read_plant` reads and checks the plant file, :func:`run_cell` is one cell's pure
task, :func:`run_plant` runs the tasks on a local Dask cluster or an existing
scheduler and stores each result as it finishes, keyed by its input hash, and
:func:`write_plant_report` writes ``plant.json``, ``cells.csv`` and ``report.html``.
"""

from joulepath.plant._config import CELL_SETTINGS, CellConfig, PlantConfig, PlantFileError, read_plant
from joulepath.plant._idle import EnergySplit, ModeSaving, Pause, mode_saving, split_energy
from joulepath.plant._report import PLANT_FILES, plant_summary, write_plant_report
from joulepath.plant._run import PlantProgress, PlantRun, cell_key, run_plant
from joulepath.plant._task import CellTask, run_cell

__all__ = [
    "CELL_SETTINGS",
    "CellConfig",
    "CellTask",
    "EnergySplit",
    "ModeSaving",
    "PLANT_FILES",
    "Pause",
    "PlantConfig",
    "PlantFileError",
    "PlantProgress",
    "PlantRun",
    "cell_key",
    "mode_saving",
    "plant_summary",
    "read_plant",
    "run_cell",
    "run_plant",
    "split_energy",
    "write_plant_report",
]
