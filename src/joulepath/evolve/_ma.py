"""Memetic algorithm: an evolutionary algorithm plus local search on each generation's best."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from joulepath.errors import InvalidInput
from joulepath.evolve._algorithm import Population
from joulepath.evolve._de import DE
from joulepath.evolve._ga import GA
from joulepath.evolve._local_search import informed_local_search, random_local_search
from joulepath.evolve._problem import Problem
from joulepath.evolve._validate import check_choice, check_int, check_real

LOCAL_SEARCHES = ("informed", "random")


@dataclass(frozen=True, slots=True, kw_only=True)
class MA:
    """Memetic algorithm (thesis §2.3.4): ``base`` then local search on the generation's best.

    Each generation runs one generation of ``base`` (the thesis' GA by default; DE works
    as well), then refines the best individual with the local search and puts the
    result back in its slot when it is better. The local search draws from its own child
    generator, spawned from the run's generator every generation (``rng.spawn``), so the
    evolutionary stream does not depend on how many samples the local search draws.

    Parameters
    ----------
    base : GA or DE
        The evolutionary first stage.
    local_search : {"random", "informed"}
        ``"random"``: ``n_samples`` neighbours with every gene moved by a uniform offset
        in ``{-radius..radius} * grid_step`` (thesis: N = 1000, ±{0, 0.05, …, 0.25}),
        evaluated in batches of ``batch_size``. ``"informed"``: scale the coefficients
        of ``joints`` by ``factor**s``, ``s = 1..steps`` (thesis: 0.9, 20 steps).
    n_samples : int
        Neighbours of the random search (>= 1).
    radius : int
        Largest offset of the random search, in grid steps (>= 1).
    batch_size : int
        Neighbours per ``problem.evaluate`` call (>= 1).
    steps : int
        Steps of the informed search (>= 1).
    factor : float
        Scale per step of the informed search, in (0, 1).
    joints : tuple of int
        Joint indices (0-based) to shrink, most influential first: pass them from the
        feature-importance ranking of the data at hand. Required for ``"informed"``.
    genes_per_joint : int
        Coefficients per joint: the chromosome is a row-major (n_joints,
        genes_per_joint) matrix flattened to ``n_var`` genes.

    Raises
    ------
    InvalidInput
        For a value out of range, an unknown local search, or ``"informed"`` without
        joints (the message lists the allowed values).

    Examples
    --------
    >>> MA(local_search="informed", joints=(1, 0)).base.pop_size
    100
    """

    base: GA | DE = field(default_factory=GA)
    local_search: str = "random"
    n_samples: int = 1000
    radius: int = 5
    batch_size: int = 1000
    steps: int = 20
    factor: float = 0.9
    joints: tuple[int, ...] = ()
    genes_per_joint: int = 6

    def __post_init__(self) -> None:
        if not isinstance(self.base, (GA, DE)):
            raise InvalidInput(f"MA: base must be a GA or DE config, got {type(self.base).__name__}")
        check_choice("MA", "local_search", self.local_search, LOCAL_SEARCHES)
        check_int("MA", "n_samples", self.n_samples, minimum=1)
        check_int("MA", "radius", self.radius, minimum=1)
        check_int("MA", "batch_size", self.batch_size, minimum=1)
        check_int("MA", "steps", self.steps, minimum=1)
        check_real("MA", "factor", self.factor, low=0.0, high=1.0, low_open=True, high_open=True)
        check_int("MA", "genes_per_joint", self.genes_per_joint, minimum=1)
        if not isinstance(self.joints, tuple) or not all(
            isinstance(j, int) and not isinstance(j, bool) and j >= 0 for j in self.joints
        ):
            raise InvalidInput(f"MA: joints must be a tuple of joint indices >= 0, got {self.joints!r}")
        if len(set(self.joints)) != len(self.joints):
            raise InvalidInput(f"MA: joints must not repeat a joint, got {self.joints!r}")
        if self.local_search == "informed" and not self.joints:
            raise InvalidInput(
                "MA: local_search='informed' needs joints, e.g. joints=(0, 1): the most influential "
                "joints from the feature-importance ranking of your data"
            )

    @property
    def pop_size(self) -> int:
        return self.base.pop_size

    @property
    def grid_step(self) -> float:
        return self.base.grid_step

    def check(self, problem: Problem) -> None:
        """The chromosome must split into joints, and ``joints`` must exist."""
        self.base.check(problem)
        if self.local_search != "informed":
            return
        if problem.n_var % self.genes_per_joint:
            raise InvalidInput(
                f"MA: n_var = {problem.n_var} is not a multiple of genes_per_joint = {self.genes_per_joint}"
            )
        n_joints = problem.n_var // self.genes_per_joint
        bad = [j for j in self.joints if j >= n_joints]
        if bad:
            raise InvalidInput(f"MA: joints {bad} do not exist; the problem has joints 0..{n_joints - 1}")

    def advance(self, problem: Problem, pop: Population, *, rng: np.random.Generator) -> Population:
        """One generation of ``base``, then local search on its best individual."""
        pop = self.base.advance(problem, pop, rng=rng)
        i = int(np.argmin(pop.F))
        x, f = pop.X[i], float(pop.F[i])
        if self.local_search == "random":
            (child,) = rng.spawn(1)
            x_new, f_new = random_local_search(
                problem,
                x,
                f,
                n_samples=self.n_samples,
                radius=self.radius,
                batch_size=self.batch_size,
                step=self.grid_step,
                rng=child,
            )
        else:
            x_new, f_new = informed_local_search(
                problem,
                x,
                f,
                joints=self.joints,
                genes_per_joint=self.genes_per_joint,
                factor=self.factor,
                steps=self.steps,
                step=self.grid_step,
            )
        if not f_new < f:
            return pop
        X, F = pop.X.copy(), pop.F.copy()
        X[i], F[i] = x_new, f_new
        return Population(X=X, F=F)
