"""A planned saving stated over the model's uncertainty: a seeded Monte Carlo on plausible models.

A robot model made of estimates (:class:`joulepath.description.ModelProvenance`) plans a
saving on its nominal parameters. The real arm is one of many models within the stated
bounds. :func:`saving_over_uncertainty` evaluates the default and the planned path on
``n_samples`` models drawn within those bounds (:func:`joulepath.description.sample_chains`)
and states the saving's median and 5th percentile. A zero-width uncertainty gives the
nominal saving on every sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from joulepath._rng import check_rng
from joulepath._typing import FloatArray
from joulepath.description import Uncertainty, sample_chains
from joulepath.dynamics import Robot
from joulepath.energy import DEFAULT_MEASURE, measure_energy, measure_power
from joulepath.errors import InvalidInput
from joulepath.trajectory import Trajectory

MC_SAMPLES = 64
"""Models sampled by default (the 5th percentile of 64 draws: between the 3rd and 4th lowest)."""
ROBUST_SAMPLES = 16
"""Models the robust objective averages over (:class:`ExpectedEnergy`)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class SavingStatement:
    """A planned saving on the nominal model and over the model's uncertainty (% of the default's energy).

    ``holds`` is False when the 5th percentile is below zero: the saving is then not headlined.
    """

    nominal_pct: float
    median_pct: float
    p5_pct: float
    n_samples: int
    seed: int | None
    measure: str
    uncertainty: Uncertainty

    @property
    def holds(self) -> bool:
        return self.p5_pct >= 0.0

    def line(self) -> str:
        u = self.uncertainty
        over = (
            f"over the model's uncertainty (masses ±{u.link_mass_rel:.0%}, centres of mass "
            f"±{u.link_com_m * 1000:.0f} mm, inertias ±{u.link_inertia_rel:.0%}; "
            f"{self.n_samples} sampled models, "
            f"seed {self.seed}, {self.measure} energy): median {self.median_pct:.1f} %, 5th percentile "
            f"{self.p5_pct:.1f} % (nominal {self.nominal_pct:.1f} %)"
        )
        if self.holds:
            return f"planned saving {over}"
        return f"planned saving NOT headlined: its 5th percentile is below zero {over}"


def _energies(robot: Robot, chain_robot: Robot, paths: tuple[Trajectory, ...], measure: str) -> list[float]:
    out = []
    for path in paths:
        tau = chain_robot.inverse_dynamics(path.q, path.qd, path.qdd, friction=robot.friction)
        e = measure_energy(
            measure, tau, path.qd, path.dt, robot.drivetrain, duration=float(path.t[-1] - path.t[0])
        )
        out.append(float(e.total_J))
    return out


def _pct(e_def: float, e_opt: float) -> float:
    return 100.0 * (e_def - e_opt) / e_def if e_def > 0 else 0.0


def saving_over_uncertainty(
    robot: Robot,
    default: Trajectory,
    optimized: Trajectory,
    uncertainty: Uncertainty,
    *,
    n_samples: int = MC_SAMPLES,
    seed: int | None = 0,
    measure: str = DEFAULT_MEASURE,
) -> SavingStatement:
    """The saving of ``optimized`` over ``default`` on models sampled within ``uncertainty``.

    Each sample is the robot with its link masses, centres of mass and inertias drawn
    uniformly within the bounds (kinematics, friction and drive data as the robot's); both
    paths are evaluated on it with the energy ``measure`` (:func:`joulepath.energy.measure_energy`).

    Parameters
    ----------
    robot : Robot
        The nominal model (the one the path was planned on).
    default, optimized : Trajectory
        Single paths of the same duration, shape (n_steps, n_joints).
    uncertainty : Uncertainty
        The bounds, e.g. :attr:`ModelProvenance.uncertainty`.
    n_samples : int, default 64
    seed : int or None, default 0
    measure : str
        A name of :data:`joulepath.energy.MEASURES`.

    Raises
    ------
    InvalidInput
        ``n_samples`` below 1; paths of another shape than the robot's joints.
    """
    if not (isinstance(n_samples, int) and n_samples >= 1):
        raise InvalidInput(f"n_samples must be an integer ≥ 1, got {n_samples!r}")
    for name, path in (("default", default), ("optimized", optimized)):
        if path.q.ndim != 2 or path.q.shape[1] != robot.n_joints:
            raise InvalidInput(
                f"{name} path has shape {path.q.shape}; "
                f"expected one path of shape (n_steps, {robot.n_joints})"
            )
    rng = check_rng(seed)
    paths = (default, optimized)
    nominal = _pct(*_energies(robot, robot, paths, measure))
    saved = np.array(
        [
            _pct(*_energies(robot, Robot(chain, payload=robot.payload), paths, measure))
            for chain in sample_chains(robot.chain, uncertainty, n_samples, rng=rng)
        ]
    )
    return SavingStatement(
        nominal_pct=nominal,
        median_pct=float(np.median(saved)),
        p5_pct=float(np.percentile(saved, 5)),
        n_samples=n_samples,
        seed=seed,
        measure=measure,
        uncertainty=uncertainty,
    )


class ExpectedEnergy:
    """The robust objective: a path's energy averaged over models sampled within an uncertainty.

    It plugs into the optimizer as a model of the path energy (``fitness="surrogate"``, the
    ``models`` of :func:`joulepath.optimize.optimize_move`): per sample (row) of a path it returns the
    power of ``measure`` times the sample period, averaged over ``n_samples`` robots whose link
    dynamics are drawn within ``uncertainty`` (:func:`joulepath.description.sample_chains`); the rows
    of a path sum to its expected energy. Its samples are drawn once, from ``rng``: state the result
    with :func:`saving_over_uncertainty` on another stream, so that the statement is not made on the
    models the path was fitted to.

    Parameters
    ----------
    robot : Robot
    uncertainty : Uncertainty
    n_samples : int, default 16
    rng : int or numpy.random.Generator
        Seed or generator of the sampled models.
    measure : str
    """

    target = "E"
    family = "expected-physics"

    def __init__(
        self,
        robot: Robot,
        uncertainty: Uncertainty,
        *,
        rng: int | np.random.Generator,
        n_samples: int = ROBUST_SAMPLES,
        measure: str = DEFAULT_MEASURE,
    ) -> None:
        if not (isinstance(n_samples, int) and n_samples >= 1):
            raise InvalidInput(f"n_samples must be an integer ≥ 1, got {n_samples!r}")
        self.robot = robot
        self.measure = measure
        self.n_samples = n_samples
        chains = sample_chains(robot.chain, uncertainty, n_samples, rng=check_rng(rng))
        self._robots = [Robot(c, payload=robot.payload) for c in chains]
        n = robot.n_joints
        self.input_columns = (
            *(f"q{i + 1}" for i in range(n)),
            *(f"dq{i + 1}" for i in range(n)),
            *(f"ddq{i + 1}" for i in range(n)),
            "dt",
        )

    def predict_rows(self, rows: FloatArray) -> FloatArray:
        """Expected energy (J) of each row ``(q, qd, qdd, dt)``: shape (n_rows,)."""
        n = self.robot.n_joints
        q, qd, qdd, dt = rows[:, :n], rows[:, n : 2 * n], rows[:, 2 * n : 3 * n], rows[:, 3 * n]
        total = np.zeros(rows.shape[0])
        for r in self._robots:
            tau = r.inverse_dynamics(q, qd, qdd, friction=self.robot.friction)
            total += measure_power(self.measure, tau, qd, self.robot.drivetrain).value
        out: FloatArray = total / self.n_samples * dt
        return out
