"""Evolutionary search over a gene grid: GA, DE and memetic algorithms (thesis §2.3).

Four roles kept apart (STYLE.md §9): a :class:`Problem` evaluates a whole population,
an algorithm config (:class:`GA`, :class:`DE`, :class:`MA`) advances it one generation,
a :class:`Termination` says when to stop, and the operators are pure array functions.
:func:`minimize` is the front door. This stage knows only its own ``Problem`` protocol.
"""

from joulepath.evolve._algorithm import Algorithm, Population
from joulepath.evolve._de import DE, de_rand_1_bin
from joulepath.evolve._ga import GA
from joulepath.evolve._local_search import (
    informed_local_search,
    joint_genes,
    random_local_search,
    random_neighbours,
    shrink_candidates,
)
from joulepath.evolve._ma import MA
from joulepath.evolve._minimize import Result, minimize
from joulepath.evolve._operators import (
    mutate,
    recombine_average,
    recombine_differential,
    recombine_random,
    reproduce,
    roulette_weights,
    sample_grid,
    select_roulette,
    snap_to_grid,
)
from joulepath.evolve._problem import FunctionProblem, Problem
from joulepath.evolve._termination import Termination

__all__ = [
    "Algorithm",
    "DE",
    "FunctionProblem",
    "GA",
    "MA",
    "Population",
    "Problem",
    "Result",
    "Termination",
    "de_rand_1_bin",
    "informed_local_search",
    "joint_genes",
    "minimize",
    "mutate",
    "random_local_search",
    "random_neighbours",
    "recombine_average",
    "recombine_differential",
    "recombine_random",
    "reproduce",
    "roulette_weights",
    "sample_grid",
    "select_roulette",
    "shrink_candidates",
    "snap_to_grid",
]
