"""Constrained gradient-based optimization of one move on the physics model.

The path is the minimum-jerk move plus a rest-to-rest B-spline shape
(:class:`joulepath.trajectory.SplineBasis`); the search variables are the spline's
free coefficients, ``x = C.ravel()`` with ``C`` of shape (n_free, n_joints).

Objective: the path energy on an energy measure (:data:`joulepath.energy.MEASURES`;
by default the thesis' ``Σ_k Σ_i |tau_ki qd_ki| dt``) with every ``|p|`` replaced by
``sqrt(p² + ε²) - ε`` and every ``max(p, 0)`` (a bleeder bus, the gears' and drives'
switch between driving and braking) by its smooth counterpart
(:func:`joulepath.energy.measure_power`), solved for a decreasing sequence of ``ε``
(continuation towards the true objective), each stage warm-started from the last.
Its gradient is exact: the measure's derivatives by torque and speed, Pinocchio's
analytic RNEA derivatives and the friction derivative, chained through the linear
spline basis.

Constraints (not penalties), solved by SLSQP:

* joint ranges, speed, acceleration and jerk limits — linear in ``x`` — as bounds on the
  control points of the path and of its first three derivatives (B-splines of degree 5 to 2;
  the accelerations' and jerks' on knots ``hull_refine`` times finer, whose control points lie
  closer to the curve): a B-spline lies in the convex hull of its control points, so the limits
  hold at every instant, with a few rows per knot (``rate_rows="grid"``: the accelerations and
  jerks instead on a grid ``check_factor`` times finer than the samples, the jerk being the
  difference of consecutive accelerations over the grid step, the quantity
  :func:`joulepath.optimize._verify.path_jerk` checks; a move added to a given ``base`` motion
  always takes these);
* effort limits (where the robot states them) on the same fine grid;
* optionally a corridor: the TCP stays within ``max_deviation_m`` of the default
  move's TCP at every sample;
* optionally waypoints (linear in ``x``): the path passes through given joint
  positions at given interior times with whatever velocity the search finds best —
  a chain of fly-by targets solved as one move; exactly (equalities), or within a
  box of given half-widths per joint (``waypoint_radius``: a zone, inequalities).

Each continuation stage, and each round of it (see below), solves in coordinates in which the
smoothed energy's Hessian at its start is near the identity (``GradientSettings.precondition``):
SLSQP's quasi-Newton model starts from the identity, and on the fine knots' many variables it needs far fewer
iterations so.

Constraints are generated lazily (active-set style): each solve includes
the rows (control points, grid points) whose value is within ``SCREEN_BAND`` of its limit
at the start point; after the solve, every row is checked, the violated or nearly active
ones are added, and the solve is repeated from the last point. A result counts as within
the limits only when every row holds and every point of the fine grid does too.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import Friction, Robot, inverse_dynamics_derivatives
from joulepath.energy import DEFAULT_MEASURE, check_measure
from joulepath.errors import InvalidInput
from joulepath.kinematics import position_and_jacobian
from joulepath.optimize._verify import energy_on_samples
from joulepath.trajectory import DEFAULT_KNOT_SPACING, GridBasis, SplineBasis, Trajectory, minimum_jerk
from joulepath.units import SAMPLE_PERIOD

SCREEN_BAND = 0.25
"""A constraint enters the solve when its value is within this share of its limit (the rest are
checked after each solve, and those it breaks or nears enter the next): the default of
:attr:`GradientSettings.screen_band`."""
EFFORT_BAND = 0.05
"""The single move's :attr:`GradientSettings.effort_band` (:data:`MOVE_SEARCH`): an effort row enters a solve
within this share of its limit."""
THIN_ROWS = 2
"""Rows of one rate kind, per variable, above which only each bump's deepest samples enter a solve."""
RANGE_MARGIN = 1e-6
"""rad kept from each range end inside the solve (solver tolerance)."""
RATE_MARGIN = 1e-6
"""Share of the speed and effort limits kept free inside the solve (solver tolerance)."""
WAYPOINT_TOLERANCE = 1e-6
"""rad a path may miss a waypoint by (solver tolerance)."""
RATE_ROWS = ("hull", "grid")
"""How the acceleration and jerk limits enter a solve (:attr:`GradientSettings.rate_rows`)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class GradientSettings:
    """Settings of the gradient search.

    Coarse to fine: with ``coarse_factor > 1`` the starts are first solved on knots
    ``coarse_factor`` times wider apart (fewer variables, fewer local minima) through the
    continuation stages before the last ``refine_stages`` (at least the first stage; or
    the first ``coarse_stages`` when that is set), and
    the best result is refined on the ``knot_spacing`` knots through the last
    ``refine_stages`` stages.

    ``continuation`` gives the smoothing ``ε`` of ``|p|`` at each stage as a share of
    the default move's mean ``|tau_i qd_i|`` (W); ``n_starts`` counts the starting
    paths (the minimum-jerk move first, then random smooth shapes drawn with the
    seed); ``check_factor`` is how many times finer than the samples the limits are
    enforced; ``energy_every``: the objective is summed on a grid this many times finer
    than the samples (a divisor of ``check_factor``). ``give_up``: a start whose
    continuation stage ends outside a limit is not carried through the later stages, nor
    refined on the fine knots (a probe that may be infeasible costs one stage).
    ``max_knots``: at most this many knot intervals on the fine knots; a longer move gets
    its knots wider apart, and its rate rows thinned (``SplineProblem.thin_rows``): the dense
    solver's work grows with the variables and the rows (a 5.3 s fly-by chain of 8 moves
    took 392 s on 106 knots with every row; on 52 knots 21 s, thinned 11 s, for 1.2 % more
    energy).

    ``rate_rows``: how the acceleration and jerk limits enter a solve. ``"hull"`` (default):
    bounds on the control points of the path's second and third derivative, B-splines of
    degree 3 and 2 that lie in the convex hull of their control points, so the limits hold at
    every instant, with a few rows per knot; ``hull_refine`` inserts that many - 1 knots into
    each interval of those derivative splines first (their control points then lie closer to
    the curve: a bound less conservative, for more rows). ``"grid"``: one row per point of the
    fine grid (``check_factor`` times finer than the samples), the search before the hull rows
    (about ten times the rows). A move added to a given ``base`` motion (not a spline) always
    takes the grid rows.

    ``screen_band``: a row enters a solve when its value is within this share of its limit
    (:data:`SCREEN_BAND`); after each solve every row is checked and those broken or within the band
    enter the next round. ``prune_stages``: a continuation stage after the first that starts within
    every limit starts again from the rows within the band there (and the known ones), not with every
    row the earlier rounds gathered (:func:`_solve_from`).

    ``effort_band``: an effort row (the torque limits, where the robot states them) enters a solve within
    this share of its limit, and the coarse level's effort rows are not carried into the fine level (None:
    ``screen_band``, and carried, as the other rows of the fine grid). An effort row is nonlinear: SLSQP
    evaluates it and its gradient at every step, the dynamics' derivatives at each of its points, where a
    linear row costs a matrix product; and every effort row is checked on the fine grid after each solve, so
    one that breaks enters the next round. The fine level starts on the coarse level's own path (nested
    knots), so the effort rows it screens there are those near their limits at the coarse result; the ones
    the coarse level carried besides were gathered at iterates on its way (a first round without rows runs
    far past the limits). Measured on the Panda's 2 s move (issue 36): of the 74 effort rows the search
    carried, none was within 0.1 of its limit at a round's end after the first; its search 4.4-4.7 ->
    3.3-3.4 s of CPU, 37.821 -> 37.827 % (0.1: the same iterates, 3.6 s). The IRB 120 states no torque
    limits (no effort rows), the UR5's README move carries none: both unchanged. :data:`MOVE_SEARCH` sets
    it for the single move; the cycle and the plan for RAPID via points keep None.

    ``precondition``: each continuation stage's round solves in coordinates ``y`` with ``x = x_at + W y``,
    ``Wᵀ H W`` near the identity for the smoothed energy's Hessian ``H`` at the round's start (its
    eigenvalues' magnitudes held at least this share of the largest; 0: the plain coefficients).
    SLSQP's quasi-Newton model starts from the identity, so it starts near the curvature there.
    Measured on the random tasks of ``benchmarks/optimizer_speed.py`` against the search before
    (``rate_rows="grid"``, ``precondition=0``, ``max_iter=200``, ``ftol=1e-7``): BENCHMARKS.md.
    """

    knot_spacing: float = DEFAULT_KNOT_SPACING
    max_knots: int = 64
    degree: int = 5
    n_starts: int = 1
    continuation: tuple[float, ...] = (0.3, 0.03, 0.003)
    max_iter: int = 80
    ftol: float = 1e-6
    check_factor: int = 10
    max_rounds: int = 6
    start_scale: float = 0.15
    coarse_factor: int = 2
    refine_stages: int = 1
    coarse_stages: int = 0
    give_up: bool = False
    energy_every: int = 1
    rate_rows: str = "hull"
    hull_refine: int = 3
    precondition: float = 1e-3
    screen_band: float = SCREEN_BAND
    prune_stages: bool = False
    effort_band: float | None = None

    def __post_init__(self) -> None:
        if self.rate_rows not in RATE_ROWS:
            raise InvalidInput(f"rate_rows must be one of {', '.join(RATE_ROWS)}, got {self.rate_rows!r}")
        if not 0.0 <= self.precondition < 1.0:
            raise InvalidInput(f"precondition must be in [0, 1) (0: none), got {self.precondition}")
        if not 0.0 < self.screen_band <= 1.0:
            raise InvalidInput(f"screen_band must be in (0, 1] (a share of a limit), got {self.screen_band}")
        if self.effort_band is not None and not 0.0 < self.effort_band <= 1.0:
            raise InvalidInput(
                f"effort_band must be in (0, 1] (a share of a limit) or None (screen_band), "
                f"got {self.effort_band}"
            )
        if not 1 <= self.hull_refine <= 8:
            raise InvalidInput(f"hull_refine must be 1..8, got {self.hull_refine}")
        if self.refine_stages < 1 or self.coarse_stages < 0:
            raise InvalidInput(
                f"refine_stages must be ≥ 1 and coarse_stages ≥ 0 (0: the stages before the refined ones), "
                f"got {self.refine_stages} and {self.coarse_stages}"
            )
        if self.n_starts < 1 or self.max_iter < 1 or self.max_rounds < 1:
            raise InvalidInput("n_starts, max_iter and max_rounds must be ≥ 1")
        if not self.continuation or any(not e > 0 for e in self.continuation):
            raise InvalidInput(f"continuation must be positive shares, got {self.continuation}")
        if self.check_factor < 1:
            raise InvalidInput(f"check_factor must be ≥ 1, got {self.check_factor}")
        if self.max_knots < 4:
            raise InvalidInput(f"max_knots must be ≥ 4, got {self.max_knots}")

    def spacing_for(self, duration: float) -> float:
        """s between the fine knots of a ``duration`` s move (``knot_spacing``, wider past ``max_knots``)."""
        return max(self.knot_spacing, duration / self.max_knots)

    def is_long(self, duration: float) -> bool:
        """A move past ``max_knots`` knots at ``knot_spacing``: wider knots and thinned rows."""
        return duration > self.knot_spacing * self.max_knots + 1e-9


SEARCH_BEFORE_HULL: dict[str, Any] = {"rate_rows": "grid", "precondition": 0.0, "ftol": 1e-7, "max_iter": 200}
""":class:`GradientSettings` of the single move's search before the hull rows (issue 36): a row per point
of the fine grid for the accelerations and jerks, SLSQP in the plain coefficients. The single move's
``gradient-grid``, the yardstick of its speed-up."""

MOVE_SEARCH: dict[str, Any] = {"effort_band": EFFORT_BAND, "prune_stages": True}
""":class:`GradientSettings` overrides of the single move's default search (``gradient``,
``gradient-fast``; not the plan for RAPID via points, :func:`joulepath.optimize._search.via_point_settings`,
nor ``gradient-grid``, the yardstick, nor the cycle's :data:`GRID_SEARCH`), for issue 36's 7-joint arm:

* ``effort_band`` (:data:`EFFORT_BAND`): effort rows only near their limits, none carried from the coarse
  level into the fine one (:attr:`GradientSettings.effort_band`);
* ``prune_stages``: a continuation stage that starts within every limit starts again from the rows near
  their limits there (:func:`_solve_from`). The Panda's 2 s move carried 668 hull rows into its second
  coarse stage, 155 of them near their limits (its first stage's first round, without rows, ran far past
  them): its search 3.4 -> 2.9 s of CPU, 37.827 -> 37.778 %; the IRB 120's 21 tasks of
  ``benchmarks/optimizer_speed.py`` as fast (the median of the per-task CPU ratios 0.95), 97.23 -> 97.20 %
  of the jerk-limited optimum, every result within every limit (BENCHMARKS.md).

The Panda's 2 s move with both, as a user runs it (the whole process, imports and plots included):
4.3-5.1 s of CPU against 6.8-7.5 s before, 37.78 % saved (CMA-ES: 25.82 %)."""

GRID_SEARCH: dict[str, Any] = {**SEARCH_BEFORE_HULL, "ftol": 3e-7, "screen_band": 0.1, "prune_stages": True}
""":class:`GradientSettings` of the cycle (:class:`joulepath.program.CycleSettings`' default): the rows on
the fine grid and the plain coefficients of :data:`SEARCH_BEFORE_HULL` (measured on the bundled
examples, the single move's new settings saved less there, payload_tool 12.0 % against 12.7 %, and took
as long), with three changes for speed (issue 36; one BLAS thread, CPU s of the plan, measured on the
bundled examples one after the other, BENCHMARKS.md):

* ``screen_band`` 0.1 (the single move's default 0.25): pick_and_place 9.5-10.8 -> 7.7-8.1 s at
  12.189 -> 12.181 %, palletizing 12.0-12.5 -> 11.6-12.3 s at 22.373 -> 22.357 %. On the single move
  it is no faster (the 21 tasks of ``benchmarks/optimizer_speed.py``: median 0.84 -> 0.88 s, share
  97.24 -> 97.25 %; the Panda's 2 s move, its many hull rows near their limits: its search 4.5 -> 3.8 s
  at 37.82 -> 37.83 %), and on the short move of ``tests/optimize/test_gradient_hull.py`` it ends in
  a poorer local optimum;
* ``prune_stages`` (:func:`_solve_from`): palletizing 11.5-11.6 -> 10.3-10.7 s at 22.357 -> 22.349 %;
* ``ftol`` 3e-7 (from 1e-7): palletizing 10.8-11.7 -> 9.8-10.2 s at 22.349 -> 22.372 %, the five
  others as fast or faster at the same or a higher saving (1e-6: palletizing 9.8-9.9 s, 22.351 %, but
  payload_tool 12.663 -> 12.649 %)."""


@dataclass(frozen=True, slots=True)
class GradientResult:
    """Best coefficients found, the path, its true (non-smooth) energy and the search's record."""

    coefficients: FloatArray
    path: Trajectory
    energy_J: float
    feasible: bool
    history: FloatArray
    n_evaluations: int
    n_iterations: int
    wall_s: float
    starts: tuple[float, ...]
    active: dict[str, np.ndarray] = field(default_factory=dict)
    """The fine-grid constraints the search ended with (flat indices per kind), to warm-start another."""


@dataclass(eq=False)
class SplineProblem:
    """Energy, limits and corridor of one move as functions of the spline coefficients.

    ``thin_rows``: a long move's rate rows (accelerations, jerks, efforts) enter a solve thinned
    to each bump's deepest samples once they pass :data:`THIN_ROWS` per variable (:func:`_near_limit`).
    """

    robot: Robot
    q_start: FloatArray
    q_end: FloatArray
    duration: float
    friction: Friction | None
    basis: SplineBasis
    check_factor: int = 10
    max_deviation_m: float | None = None
    acceleration_limit: FloatArray | None = None
    waypoints: tuple[tuple[float, FloatArray], ...] = ()
    jerk_limit: FloatArray | None = None
    waypoint_radius: tuple[FloatArray, ...] = ()
    base: Trajectory | None = None
    energy_measure: str = DEFAULT_MEASURE
    energy_every: int = 1
    thin_rows: bool = False
    rate_rows: str = "grid"
    hull_refine: int = 2
    n_evaluations: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        self.drivetrain = self.robot.drivetrain
        # refused in one line saying what data it needs
        self.energy_measure_def = check_measure(self.energy_measure, self.drivetrain)
        self.q_start = np.asarray(self.q_start, dtype=float)
        self.q_end = np.asarray(self.q_end, dtype=float)
        self.n = self.robot.n_joints
        self.m = self.basis.n_free
        self.samples: GridBasis = self.basis.samples
        self.fine: GridBasis = self.basis.grid(self.basis.dt / self.check_factor)
        if self.base is None:
            self.default = minimum_jerk(self.q_start, self.q_end, self.duration, dt=self.basis.dt)
            self.default_fine = minimum_jerk(
                self.q_start, self.q_end, self.duration, dt=self.basis.dt / self.check_factor
            )
        else:  # a given motion (on the fine grid) the shape is added to: its ends are kept
            fine_t = self.fine.t
            b = self.base
            if b.t.shape != fine_t.shape or np.abs(b.t - fine_t).max() > 1e-9:
                raise InvalidInput(
                    f"base must be sampled on the fine grid: {fine_t.size} samples 0..{self.duration:g} s "
                    f"every {self.basis.dt / self.check_factor:g} s"
                )
            self.default_fine = b
            every = self.check_factor
            self.default = Trajectory(t=b.t[::every], q=b.q[::every], qd=b.qd[::every], qdd=b.qdd[::every])
        self.lo, self.hi = self.robot.joint_ranges()
        self.vmax = np.where(
            np.isfinite(self.robot.velocity_limit), np.asarray(self.robot.velocity_limit, dtype=float), 1e9
        )
        amax = self.acceleration_limit
        self.amax = np.full(self.n, 1e9) if amax is None else np.where(np.isfinite(amax), amax, 1e9)
        jmax = self.jerk_limit
        self.has_jerk = jmax is not None and bool(np.any(np.isfinite(jmax)))
        self.jmax = np.full(self.n, 1e12) if jmax is None else np.where(np.isfinite(jmax), jmax, 1e12)
        # jerk on the fine grid: (qdd[k+1] - qdd[k]) / h, linear in x like the acceleration
        h = self.basis.dt / self.check_factor
        self.fine_Bddd: FloatArray = np.diff(self.fine.Bdd, axis=0) / h
        self.default_fine_qddd: FloatArray = np.diff(self.default_fine.qdd, axis=0) / h
        self.emax = np.asarray(self.robot.effort_limit, dtype=float)
        self.has_effort = bool(np.any(np.isfinite(self.emax)))
        self.dt = self.basis.dt
        self._energy_grid()
        self.origin = np.zeros(self.n_var)
        self._waypoint_rows()
        if self.max_deviation_m is not None:
            self.tcp_default = self.robot.fk(self.path(self.origin).q).position_m
        self.hull = self._hull()

    def _energy_grid(self) -> None:
        """The grid the objective is summed on: the samples, or ``energy_every`` times finer (a
        divisor of ``check_factor``; on the samples alone the search can place power peaks between
        them, and a finer grid's energy is what the move spends)."""
        f = self.energy_every
        if f < 1 or self.check_factor % f:
            raise InvalidInput(f"energy_every must divide check_factor ({self.check_factor}), got {f}")
        if f == 1:
            self.egrid, self.edefault, self.edt = self.samples, self.default, self.dt
            return
        every = self.check_factor // f
        fine = self.fine
        self.egrid = GridBasis(
            t=fine.t[::every], B=fine.B[::every], Bd=fine.Bd[::every], Bdd=fine.Bdd[::every]
        )
        d = self.default_fine
        self.edefault = Trajectory(t=d.t[::every], q=d.q[::every], qd=d.qd[::every], qdd=d.qdd[::every])
        self.edt = self.dt / f

    def _waypoint_rows(self) -> None:
        """``A_w x = b_w``: the path through each waypoint; ``origin``: the smoothest such ``x``.

        ``origin`` minimizes the squared acceleration of the shape on the samples among the
        coefficient vectors that meet the waypoints (the minimum-jerk move when there are
        none); the search starts there, and the corridor is measured from its path.
        """
        self.way_A: FloatArray = np.zeros((0, self.n_var))
        self.way_b: FloatArray = np.zeros(0)
        self.way_r: FloatArray = np.zeros(0)
        if not self.waypoints:
            return
        times = np.array([float(t) for t, _ in self.waypoints])
        if np.any(times <= 0.0) or np.any(times >= self.duration) or np.any(np.diff(times) <= 0.0):
            raise InvalidInput(
                f"waypoint times must increase strictly inside (0, {self.duration:g}) s, got {times.tolist()}"
            )
        q_way = np.stack([np.asarray(q, dtype=float) for _, q in self.waypoints])
        if q_way.shape[1] != self.n or not np.all(np.isfinite(q_way)):
            raise InvalidInput(f"waypoints must be finite joint vectors of {self.n} joints")
        Bw = self.basis.free_basis(times)  # (w, m)
        if self.base is None:
            s = times / self.duration  # the minimum-jerk move at the waypoint times
            blend = 10 * s**3 - 15 * s**4 + 6 * s**5
            base_at = self.q_start + blend[:, None] * (self.q_end - self.q_start)
        else:
            b = self.default_fine
            base_at = np.column_stack([np.interp(times, b.t, b.q[:, j]) for j in range(self.n)])
        d = q_way - base_at  # (w, n)
        self.way_A = np.asarray(np.kron(Bw, np.eye(self.n)), dtype=float)  # rows w * n + i
        self.way_b = d.ravel()
        if self.waypoint_radius:
            r = np.stack(
                [np.broadcast_to(np.asarray(v, dtype=float), (self.n,)) for v in self.waypoint_radius]
            )
            if r.shape != q_way.shape or not np.all(np.isfinite(r)) or np.any(r < 0.0):
                raise InvalidInput(
                    f"waypoint_radius must give {len(self.waypoints)} non-negative finite radii of "
                    f"{self.n} joints (rad), one per waypoint"
                )
            self.way_r = r.ravel()
        else:
            self.way_r = np.zeros_like(self.way_b)
        # the smoothest shape through the waypoints: min |Bdd C|² + ridge s.t. Bw C = d
        H = self.samples.Bdd.T @ self.samples.Bdd
        H = H + 1e-9 * np.trace(H) / H.shape[0] * np.eye(self.m)
        K = np.block([[H, Bw.T], [Bw, np.zeros((Bw.shape[0], Bw.shape[0]))]])
        rhs = np.vstack([np.zeros((self.m, self.n)), d])
        sol = np.linalg.solve(K, rhs)
        self.origin = sol[: self.m].ravel()

    def waypoint_error(self, x: FloatArray) -> float:
        """Largest distance (rad) of the path beyond a waypoint's box at its time (0 without waypoints;
        the box of an exact waypoint has no width)."""
        if not self.way_b.size:
            return 0.0
        miss = np.abs(self.way_A @ np.asarray(x, dtype=float) - self.way_b) - self.way_r
        return float(max(miss.max(), 0.0))

    @property
    def n_var(self) -> int:
        return self.m * self.n

    def coefficients(self, x: FloatArray) -> FloatArray:
        return np.asarray(x, dtype=float).reshape(self.m, self.n)

    def path(self, x: FloatArray, *, fine: bool = False) -> Trajectory:
        c = self.coefficients(x)
        grid, base = (self.fine, self.default_fine) if fine else (self.samples, self.default)
        return Trajectory(
            t=grid.t, q=base.q + grid.B @ c, qd=base.qd + grid.Bd @ c, qdd=base.qdd + grid.Bdd @ c
        )

    # ------------------------------------------------------------------ energy
    def true_energy(self, x: FloatArray) -> float:
        """The reported metric, unsmoothed, on the samples (or the energy grid): the measure's motion part."""
        return energy_on_samples(
            self.robot, self._energy_path(x), friction=self.friction, measure=self.energy_measure
        )

    def _energy_path(self, x: FloatArray) -> Trajectory:
        if self.energy_every == 1:
            return self.path(x)
        c = self.coefficients(x)
        g, b = self.egrid, self.edefault
        return Trajectory(t=g.t, q=b.q + g.B @ c, qd=b.qd + g.Bd @ c, qdd=b.qdd + g.Bdd @ c)

    def smooth_energy(self, x: FloatArray, eps: float) -> tuple[float, FloatArray]:
        """Smoothed energy (J) and its exact gradient with respect to ``x``.

        The energy term is the measure's smoothed power (:func:`joulepath.energy.measure_power`
        with ``eps``) summed over the samples; its derivatives by ``tau`` and ``qd`` are chained
        through the inverse dynamics' derivatives and the spline basis.
        """
        self.n_evaluations += 1
        p = self._energy_path(x)
        value, per_state = self._state_gradient(p.q, p.qd, p.qdd, eps)
        g = (
            self.egrid.B.T @ per_state[:, 0]
            + self.egrid.Bd.T @ per_state[:, 1]
            + self.egrid.Bdd.T @ per_state[:, 2]
        )
        return value, g.ravel()

    def _state_gradient(
        self, q: FloatArray, qd: FloatArray, qdd: FloatArray, eps: float
    ) -> tuple[float, FloatArray]:
        """The smoothed energy over the energy grid's states and its gradient by each state,
        ``(N, 3, n)``: by ``q``, ``qd`` and ``qdd`` at each point (the measure's derivatives by torque
        and speed chained through the inverse dynamics' derivatives)."""
        d = inverse_dynamics_derivatives(self.robot, q, qd, qdd, friction=self.friction)
        power = self.energy_measure_def.power(d.tau, qd, self.drivetrain, eps)
        wq = power.d_tau * self.edt  # dE/dtau
        # dE/dq_k = Tq_kᵀ wq_k, dE/dqd_k = Tv_kᵀ wq_k + dE/dqd_k (direct), dE/dqdd_k = Ta_kᵀ wq_k
        out = np.stack(
            [
                np.einsum("kij,ki->kj", d.dq, wq),
                np.einsum("kij,ki->kj", d.dqd, wq) + power.d_qd * self.edt,
                np.einsum("kij,ki->kj", d.dqdd, wq),
            ],
            axis=1,
        )
        return float(power.value.sum() * self.edt), out

    def smooth_energy_value(self, x: FloatArray, eps: float) -> float:
        """The smoothed energy (J) of :meth:`smooth_energy` without its gradient: the torques alone
        (Pinocchio's RNEA, about a fifth of the cost of its derivatives). SLSQP asks for the gradient
        only at the points its line search accepts; its trial steps need the value only."""
        self.n_evaluations += 1
        p = self._energy_path(x)
        tau = self.robot.inverse_dynamics(p.q, p.qd, p.qdd, friction=self.friction)
        power = self.energy_measure_def.power(tau, p.qd, self.drivetrain, eps)
        return float(power.value.sum() * self.edt)

    # ------------------------------------------------------------- constraints
    @property
    def rate_hull(self) -> bool:
        """Whether the acceleration and jerk limits are rows on control points (else on the fine grid)."""
        return self.rate_rows == "hull" and self.base is None

    def _hull(self) -> tuple[FloatArray, FloatArray]:
        """``A x + b ≥ 0``: every control point of q and qd inside its bounds (holds at every instant),
        and with :attr:`rate_hull` those of qdd and qddd (on ``hull_refine`` times finer knots);
        with a given ``base``, q and qd inside their bounds at every sample."""
        span = np.where(np.isfinite(self.hi - self.lo), self.hi - self.lo, 2 * np.pi)
        q_bounds = (self.hi - RANGE_MARGIN, self.lo + RANGE_MARGIN, span)
        v_bounds = (self.vmax * (1 - RATE_MARGIN), -self.vmax * (1 - RATE_MARGIN), self.vmax)
        if self.base is not None:
            # on the samples (the fine grid would hold ten times the rows); the result is verified
            # on the fine grid all the same (check_limits)
            blocks = [(self.samples.B, self.default.q), (self.samples.Bd, self.default.qd)]
        else:  # control point (r, i) = P[r, i] + Σ_j M[r, j] C[j, i];  x[j * n + i] = C[j, i]
            maps = self.basis.control_maps[:2]
            offsets = self.basis.minimum_jerk_control(self.q_start, self.q_end)[:2]
            blocks = list(zip(maps, offsets, strict=True))
        bounds = [q_bounds, v_bounds]
        if self.rate_hull:
            # a joint without a limit (held as a huge number) gets no rows; twice the margin of the
            # fine-grid check (:meth:`violation`): where the hull touches the curve (at the ends), the
            # grid's difference quotient meets the same value up to rounding
            a = np.where(self.amax < 1e9, self.amax * (1 - 2 * RATE_MARGIN), np.inf)
            j = np.where(self.jmax < 1e12, self.jmax * (1 - 2 * RATE_MARGIN), np.inf)
            blocks += _rate_control_blocks(self.basis, self.q_start, self.q_end, self.hull_refine)
            bounds += [(a, -a, self.amax), (j, -j, self.jmax)]
        rows_a, rows_b, rows_s = [], [], []
        eye = np.eye(self.n)
        for (M, P), (hi, lo, sc) in zip(blocks, bounds, strict=True):
            full = np.kron(M, eye)  # rows r * n + i
            for sign, bound in ((-1.0, hi), (1.0, lo)):
                finite = np.isfinite(np.broadcast_to(bound, P.shape)).ravel()
                b = (sign * (P - bound)).ravel()
                rows_a.append(sign * full[finite])
                rows_b.append(b[finite])
                rows_s.append(np.broadcast_to(sc, P.shape).ravel()[finite])
        coupled = self._axis3_rows(*blocks[0])
        if coupled is not None:
            rows_a.append(coupled[0])
            rows_b.append(coupled[1])
            rows_s.append(np.full(coupled[1].size, coupled[2]))
        self.hull_scale = np.concatenate(rows_s)
        return np.concatenate(rows_a), np.concatenate(rows_b)

    def _axis3_rows(self, M: FloatArray, P: FloatArray) -> tuple[FloatArray, FloatArray, float] | None:
        """``A x + b ≥ 0`` rows keeping the controller's coupled axis 3 (a linear map of the joints,
        joint 2 + joint 3 on the IRB 2400) inside its range at each control point (or sample) of q,
        where the robot has one; with the row scale. None for any other arm."""
        rng = self.robot.axis3_range
        if rng is None or self.n < 3:
            return None
        zero = self.robot.joints_to_axes(np.zeros(self.n))[2]
        c = self.robot.joints_to_axes(np.eye(self.n))[:, 2] - zero  # axis 3 = zero + c · q
        full = np.kron(M, c[None, :])  # rows r: c · (control point r's change)
        value = zero + P @ c
        hi, lo = rng[1] - RANGE_MARGIN, rng[0] + RANGE_MARGIN
        A = np.concatenate([-full, full])
        b = np.concatenate([hi - value, value - lo])
        return A, b, float(rng[1] - rng[0])

    def accel_slack(self, x: FloatArray) -> FloatArray:
        """Acceleration slack on the fine grid: ``amax - qdd`` then ``qdd + amax``, shape (2K, n)."""
        qdd = self.default_fine.qdd + self.fine.Bdd @ self.coefficients(x)
        a = self.amax * (1.0 - RATE_MARGIN)
        return np.concatenate([a - qdd, qdd + a])

    def _accel_rows(self, idx: np.ndarray) -> tuple[FloatArray, FloatArray]:
        """``A x + b ≥ 0`` for flat indices into :meth:`accel_slack` (linear in ``x``)."""
        K, n, m = self.fine.t.size, self.n, self.m
        half, i = np.divmod(idx, n)
        upper = half < K
        k = np.where(upper, half, half - K)
        sign = np.where(upper, -1.0, 1.0)
        A = np.zeros((idx.size, m * n))
        cols = np.arange(m)[None, :] * n + i[:, None]
        np.put_along_axis(A, cols, sign[:, None] * self.fine.Bdd[k], axis=1)
        b = self.amax[i] * (1.0 - RATE_MARGIN) + sign * self.default_fine.qdd[k, i]
        return A, b

    def jerk_slack(self, x: FloatArray) -> FloatArray:
        """Jerk slack on the fine grid's steps: ``jmax - qddd`` then ``qddd + jmax``, shape (2(K-1), n)."""
        qddd = self.default_fine_qddd + self.fine_Bddd @ self.coefficients(x)
        j = self.jmax * (1.0 - RATE_MARGIN)
        return np.concatenate([j - qddd, qddd + j])

    def _jerk_rows(self, idx: np.ndarray) -> tuple[FloatArray, FloatArray]:
        """``A x + b ≥ 0`` for flat indices into :meth:`jerk_slack` (linear in ``x``)."""
        K, n, m = self.fine_Bddd.shape[0], self.n, self.m
        half, i = np.divmod(idx, n)
        upper = half < K
        k = np.where(upper, half, half - K)
        sign = np.where(upper, -1.0, 1.0)
        A = np.zeros((idx.size, m * n))
        cols = np.arange(m)[None, :] * n + i[:, None]
        np.put_along_axis(A, cols, sign[:, None] * self.fine_Bddd[k], axis=1)
        b = self.jmax[i] * (1.0 - RATE_MARGIN) + sign * self.default_fine_qddd[k, i]
        return A, b

    def hull_slack(self, x: FloatArray) -> FloatArray:
        A, b = self.hull
        out: FloatArray = A @ x + b
        return out

    def effort_slack(self, x: FloatArray) -> FloatArray:
        """Effort slack (2K, n): ``emax - tau`` then ``tau + emax`` on the fine grid (inf where unlimited)."""
        p = self.path(x, fine=True)
        tau = self.robot.inverse_dynamics(p.q, p.qd, p.qdd, friction=self.friction)
        e = np.where(np.isfinite(self.emax), self.emax * (1.0 - RATE_MARGIN), np.inf)
        return np.concatenate([e - tau, tau + e])

    def deviation(self, x: FloatArray) -> FloatArray:
        """TCP distance (m) from the default move's TCP at each sample."""
        p = self.path(x)
        tcp = self.robot.fk(p.q).position_m
        out: FloatArray = np.linalg.norm(tcp - self.tcp_default, axis=-1)
        return out

    def constraints(
        self, active: dict[str, np.ndarray], change: tuple[FloatArray, FloatArray] | None = None
    ) -> list[dict[str, Any]]:
        """SLSQP constraint dicts for the active fine-grid points ``active[kind]`` (flat indices).

        ``change = (x0, W)``: the dicts take ``y`` with ``x = x0 + W y`` (a preconditioned solve);
        the linear rows are mapped once.
        """
        cons: list[dict[str, Any]] = []

        def linear(kind: str, A: FloatArray, b: FloatArray) -> None:
            if change is not None:
                x0, W = change
                A, b = A @ W, A @ x0 + b
            cons.append({"type": kind, "fun": lambda y: A @ y + b, "jac": lambda y: A})

        def nonlinear(rows: Callable[[FloatArray], tuple[FloatArray, FloatArray]]) -> None:
            # SLSQP asks for the rows' values and their gradient at the same point one after the
            # other: both come from one evaluation (the same numbers, half the dynamics' derivatives)
            rows = _last_point(rows)
            if change is None:
                cons.append({"type": "ineq", "fun": lambda x: rows(x)[0], "jac": lambda x: rows(x)[1]})
                return
            x0, W = change
            cons.append(
                {
                    "type": "ineq",
                    "fun": lambda y: rows(x0 + W @ y)[0],
                    "jac": lambda y: rows(x0 + W @ y)[1] @ W,
                }
            )

        if self.way_b.size:
            exact = self.way_r <= 0.0
            if exact.any():
                linear("eq", self.way_A[exact], -self.way_b[exact])
            if (~exact).any():  # a zone: -r <= A x - b <= r
                Az = np.vstack([-self.way_A[~exact], self.way_A[~exact]])
                bz = np.concatenate(
                    [self.way_r[~exact] + self.way_b[~exact], self.way_r[~exact] - self.way_b[~exact]]
                )
                linear("ineq", Az, bz)
        rows = active.get("hull")
        if rows is not None and rows.size:
            linear("ineq", self.hull[0][rows], self.hull[1][rows])
        acc = active.get("qdd")
        if acc is not None and acc.size:
            linear("ineq", *self._accel_rows(acc))
        jer = active.get("qddd")
        if jer is not None and jer.size:
            linear("ineq", *self._jerk_rows(jer))
        eff = active.get("tau")
        if eff is not None and eff.size:
            nonlinear(partial(self._effort_rows, idx=eff))
        dev = active.get("tcp")
        if dev is not None and dev.size and self.max_deviation_m is not None:
            nonlinear(partial(self._corridor_rows, idx=dev))
        return cons

    def _effort_rows(self, x: FloatArray, idx: np.ndarray) -> tuple[FloatArray, FloatArray]:
        """Effort slack and its gradient at flat indices into the (2K, n) effort-slack array."""
        K, n, m = self.fine.t.size, self.n, self.m
        half, i = np.divmod(idx, n)
        upper = half < K
        k = np.where(upper, half, half - K)
        uk, inv = np.unique(k, return_inverse=True)
        c = self.coefficients(x)
        B, Bd, Bdd = self.fine.B[uk], self.fine.Bd[uk], self.fine.Bdd[uk]
        q = self.default_fine.q[uk] + B @ c
        qd = self.default_fine.qd[uk] + Bd @ c
        qdd = self.default_fine.qdd[uk] + Bdd @ c
        d = inverse_dynamics_derivatives(self.robot, q, qd, qdd, friction=self.friction)
        e = self.emax[i] * (1.0 - RATE_MARGIN)
        tau = d.tau[inv, i]
        sign = np.where(upper, -1.0, 1.0)
        val = e + sign * tau
        # d tau_i(k) / d C[j, l] = dq[k,i,l] B[k,j] + dqd[k,i,l] Bd[k,j] + dqdd[k,i,l] Bdd[k,j]
        grad = (
            d.dq[inv, i][:, None, :] * B[inv][:, :, None]
            + d.dqd[inv, i][:, None, :] * Bd[inv][:, :, None]
            + d.dqdd[inv, i][:, None, :] * Bdd[inv][:, :, None]
        ).reshape(idx.size, m * n)
        return val, sign[:, None] * grad

    def _corridor_rows(self, x: FloatArray, idx: np.ndarray) -> tuple[FloatArray, FloatArray]:
        """``d² - |tcp - tcp_default|²`` (m²) at sample indices ``idx`` and its gradient."""
        assert self.max_deviation_m is not None
        c = self.coefficients(x)
        q = self.default.q[idx] + self.samples.B[idx] @ c
        tcp, jac6 = position_and_jacobian(self.robot.chain, q)  # one pass over the chain for both
        delta = tcp - self.tcp_default[idx]
        jac = jac6[:, :3, :]  # (k, 3, n)
        dd = 2.0 * np.einsum("ka,kal->kl", delta, jac)  # d|delta|²/dq (k, n)
        grad = -(self.samples.B[idx][:, :, None] * dd[:, None, :]).reshape(idx.size, self.m * self.n)
        bound = self.max_deviation_m * (1.0 - RATE_MARGIN)  # solver tolerance, as for the rates
        return bound**2 - (delta * delta).sum(axis=1), grad

    def screen(self, x: FloatArray, band: float, effort_band: float | None = None) -> dict[str, np.ndarray]:
        """Indices of the constraints within ``band`` of their limits, or violated (the effort rows within
        ``effort_band`` where it is narrower: :attr:`GradientSettings.effort_band`)."""
        cap = THIN_ROWS * self.m * self.n if self.thin_rows else np.iinfo(np.int64).max
        out = {"hull": np.flatnonzero(self.hull_slack(x) < band * self.hull_scale)}
        if not self.rate_hull:
            out["qdd"] = _near_limit(self.accel_slack(x), band * self.amax, cap)
        if self.has_jerk and not self.rate_hull:
            out["qddd"] = _near_limit(self.jerk_slack(x), band * self.jmax, cap)
        if self.has_effort:
            lim = np.where(np.isfinite(self.emax), self.emax, np.inf)
            tau_band = band if effort_band is None else min(band, effort_band)
            out["tau"] = _near_limit(self.effort_slack(x), tau_band * lim, cap)
        if self.max_deviation_m is not None:
            out["tcp"] = np.flatnonzero(self.deviation(x) > (1.0 - band) * self.max_deviation_m)
        return out

    def violation(self, x: FloatArray) -> float:
        """Largest constraint violation on the fine grid (rad, rad/s, N·m or m; 0 when feasible)."""
        worst = max(0.0, float(-self.hull_slack(x).min()) - 1e-9, float(-self.accel_slack(x).min()) - 1e-9)
        if self.has_jerk:
            worst = max(worst, float(-self.jerk_slack(x).min()) - 1e-9)
        if self.has_effort:
            worst = max(worst, float(-self.effort_slack(x).min()))
        if self.max_deviation_m is not None:
            worst = max(worst, float(self.deviation(x).max() - self.max_deviation_m) - 1e-9)
        worst = max(worst, self.waypoint_error(x) - WAYPOINT_TOLERANCE)
        return max(worst, 0.0)


def _last_point(
    rows: Callable[[FloatArray], tuple[FloatArray, FloatArray]],
) -> Callable[[FloatArray], tuple[FloatArray, FloatArray]]:
    """``rows`` that keeps its last point's result: a second call at an equal point returns it."""
    last: list[tuple[FloatArray, tuple[FloatArray, FloatArray]]] = []

    def cached(x: FloatArray) -> tuple[FloatArray, FloatArray]:
        if last and np.array_equal(last[0][0], x):
            return last[0][1]
        out = rows(x)
        last[:] = [(np.array(x, dtype=float, copy=True), out)]
        return out

    return cached


def _derivative_controls(
    knots: FloatArray, degree: int, P: FloatArray, order: int
) -> tuple[FloatArray, int, FloatArray]:
    """Control points, degree and knots of the ``order``-th derivative of the B-spline (``knots``,
    ``degree``) with control points ``P`` (rows; any trailing shape): differences of ``P``."""
    cur, deg, t = P, degree, knots
    for _ in range(order):
        rows = t.size - deg - 2
        span = t[deg + 1 : deg + 1 + rows] - t[1 : 1 + rows]
        cur = deg * np.diff(cur, axis=0) / span.reshape((-1,) + (1,) * (cur.ndim - 1))
        deg, t = deg - 1, t[1:-1]
    return cur, deg, t


def _refinement(knots: FloatArray, degree: int, factor: int) -> FloatArray:
    """``R``: the control points of a B-spline on ``knots`` after ``factor - 1`` knots are inserted
    evenly into each interval are ``R @`` its control points (the same curve: nested spaces)."""
    from scipy.interpolate import BSpline

    n_ctrl = knots.size - degree - 1
    if factor <= 1:
        return np.eye(n_ctrl)
    inner = np.unique(knots)
    fine_inner = np.concatenate(
        [np.linspace(a, b, factor + 1)[:-1] for a, b in zip(inner[:-1], inner[1:], strict=True)]
        + [inner[-1:]]
    )
    fine = np.concatenate([np.full(degree, inner[0]), fine_inner, np.full(degree, inner[-1])])
    x = np.linspace(inner[0], inner[-1], 4 * (fine.size + degree))
    N = BSpline.design_matrix(x, knots, degree).toarray()
    Nf = BSpline.design_matrix(x, fine, degree).toarray()
    R: FloatArray = np.asarray(np.linalg.lstsq(Nf, N, rcond=None)[0], dtype=float)
    R[np.abs(R) < 1e-12] = 0.0
    return R


def _rate_control_blocks(
    basis: SplineBasis, q_start: FloatArray, q_end: FloatArray, refine: int
) -> list[tuple[FloatArray, FloatArray]]:
    """``(M, P)`` of the second and third derivative: control point ``(r, i) = P[r, i] + Σ_j M[r, j] C[j, i]``
    of the minimum-jerk move plus the shape, on knots ``refine`` times finer than ``basis``'s."""
    pad = basis.control_maps[0]  # (n_ctrl, n_free): the free coefficients among the control points
    P0 = basis.minimum_jerk_control(q_start, q_end)[0]
    out = []
    for order in (2, 3):
        M, deg, t = _derivative_controls(basis.knots, basis.degree, pad, order)
        P, _, _ = _derivative_controls(basis.knots, basis.degree, P0, order)
        R = _refinement(t, deg, refine)
        out.append((R @ M, R @ P))
    return out


def smooth_energy_hessian(problem: SplineProblem, x: FloatArray, eps: float) -> FloatArray:
    """The smoothed energy's Hessian (J) at ``x``, symmetrized.

    The energy is a sum over the grid's points of a function of each point's state
    ``(q, qd, qdd)``, each linear in ``x`` through the spline basis; so the Hessian is
    ``Σ_k J_kᵀ H_k J_k`` with ``H_k`` the ``3n × 3n`` Hessian of point ``k``'s term by its state:
    forward differences of the exact per-state gradient, ``3n`` evaluations on all points at
    once (against one per variable, ``n_free · n``, when differencing the gradient by ``x``).
    """
    x = np.asarray(x, dtype=float)
    problem.n_evaluations += 1
    p = problem._energy_path(x)
    states = np.stack([p.q, p.qd, p.qdd], axis=1)  # (N, 3, n)
    g0 = problem._state_gradient(p.q, p.qd, p.qdd, eps)[1]
    N, _, n = states.shape
    Hk = np.empty((N, 3, n, 3, n))
    for b in range(3):
        h = 1e-6 * max(1.0, float(np.abs(states[:, b]).max(initial=0.0)))
        for j in range(n):
            problem.n_evaluations += 1
            moved = states.copy()
            moved[:, b, j] += h
            Hk[:, :, :, b, j] = (
                problem._state_gradient(moved[:, 0], moved[:, 1], moved[:, 2], eps)[1] - g0
            ) / h
    Hk = 0.5 * (Hk + Hk.transpose(0, 3, 4, 1, 2))
    g = problem.egrid
    D = np.stack([g.B, g.Bd, g.Bdd], axis=1)  # (N, 3, m): d state / d coefficient
    m = D.shape[2]
    Y = np.einsum("kaibc,kbl->kailc", Hk, D)  # (N, 3, n, m, n)
    H = (D.reshape(N * 3, m).T @ Y.reshape(N * 3, n * m * n)).reshape(m * n, m * n)
    out: FloatArray = 0.5 * (H + H.T)
    return out


def _preconditioner(
    problem: SplineProblem, x: FloatArray, eps: float, scale: float, floor: float
) -> FloatArray | None:
    """``W`` with ``Wᵀ H W`` near the identity, ``H`` the objective's Hessian at ``x`` with each
    eigenvalue's magnitude held at least ``floor`` times the largest (None: ``floor`` 0, no change).

    SLSQP's quasi-Newton model starts from the identity; in ``y`` (``x = x_at + W y``) that start is
    already close to the curvature, so it needs far fewer iterations on the many variables of the
    fine knots (the objective and the feasible set are the same, only their coordinates change).
    """
    if floor <= 0.0:
        return None
    H = smooth_energy_hessian(problem, x, eps) / scale
    w, V = np.linalg.eigh(H)
    big = float(np.abs(w).max(initial=0.0))
    if not np.isfinite(big) or big <= 0.0:
        return None
    w = np.maximum(np.abs(w), floor * big)
    out: FloatArray = V / np.sqrt(w)
    return out


def _near_limit(slack: FloatArray, within: FloatArray, cap: int) -> np.ndarray:
    """Flat indices of the fine-grid rate constraints (``slack`` (R, n)) within ``within`` of their
    limits; over ``cap`` of them (a long move that runs along its limits), only each bump's deepest
    sample and its two neighbours: neighbouring samples of the fine grid
    carry nearly the same row, and a dense solver's work grows with the rows it carries. A bump
    missed this way is violated after the solve, and :func:`_solve_from` adds it then."""
    near = slack < within
    if np.count_nonzero(near) <= cap:
        return np.flatnonzero(near.ravel())
    pad = np.pad(slack, ((1, 1), (0, 0)), constant_values=np.inf)
    deepest = (slack <= pad[:-2]) & (slack <= pad[2:])
    keep = deepest.copy()
    keep[1:] |= deepest[:-1]
    keep[:-1] |= deepest[1:]
    return np.flatnonzero((near & keep).ravel())


def _past(deadline: float | None) -> bool:
    """Whether ``deadline`` (``time.perf_counter()``, None: none) has passed."""
    return deadline is not None and time.perf_counter() > deadline


def _merge(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {
        k: np.union1d(a.get(k, np.empty(0, int)), b.get(k, np.empty(0, int))) for k in a.keys() | b.keys()
    }


def _solve_from(
    problem: SplineProblem,
    x0: FloatArray,
    settings: GradientSettings,
    scale: float,
    eps_unit: float,
    history: list[float],
    known: dict[str, np.ndarray] | None = None,
    deadline: float | None = None,
) -> tuple[FloatArray, int, dict[str, np.ndarray]]:
    """Continuation stages from ``x0``; each stage regenerates constraints until none is violated.

    With :attr:`GradientSettings.prune_stages`, a stage after the first that starts within every
    limit starts with the rows near their limits there and ``known``, the rows an earlier stage
    gathered dropped (on the way, a round's iterate can run far past limits whose rows it did not
    have yet, and every row it came near stayed in every later solve). Measured (issue 36, one BLAS
    thread): the cycle's palletizing 11.5-11.6 -> 10.3-10.7 s of CPU, 22.357 -> 22.349 %,
    pick_and_place the same (7.6-8.2 s, 12.181 -> 12.184 %); the single move's 21 tasks of
    ``benchmarks/optimizer_speed.py`` no faster (the median of the per-task CPU ratios 1.00), share
    97.23 -> 97.20 %: on for the cycle (:data:`GRID_SEARCH`) only.

    ``known`` adds constraints found active by an earlier search on the same fine grid.
    ``deadline`` (``time.perf_counter()``): past it the solver stops at its current iterate.
    """
    from scipy.optimize import minimize

    def stop_when_late(_: Any) -> None:
        if _past(deadline):
            raise StopIteration

    x = x0.copy()
    n_iter = 0
    active = problem.screen(x, settings.screen_band, settings.effort_band)
    if known:
        active = _merge(active, known)
    for stage, share in enumerate(settings.continuation):
        eps = share * eps_unit
        if stage and settings.prune_stages and problem.violation(x) == 0.0:
            # a later stage starts from a point within every limit: only the rows near their limits
            # there (and the known ones), not every row an earlier round's iterate came near on its
            # way (the dense QP's work grows with its rows; those it breaks enter again after the solve)
            active = problem.screen(x, settings.screen_band, settings.effort_band)
            if known:
                active = _merge(active, known)

        def fun(z: FloatArray, eps: float = eps) -> float:
            return problem.smooth_energy_value(z, eps) / scale

        def jac(z: FloatArray, eps: float = eps) -> FloatArray:
            return problem.smooth_energy(z, eps)[1] / scale

        for _ in range(settings.max_rounds):
            W = _preconditioner(problem, x, eps, scale, settings.precondition)
            if W is None:
                res = minimize(
                    fun,
                    x,
                    jac=jac,
                    method="SLSQP",
                    constraints=problem.constraints(active),
                    options={"maxiter": settings.max_iter, "ftol": settings.ftol},
                    callback=None if deadline is None else stop_when_late,
                )
                cand = np.asarray(res.x, dtype=float)
            else:  # the same problem in y, x = x + W y: its Hessian near the identity at y = 0
                x_at, Wm = x, W

                def fun_y(y: FloatArray, x_at: FloatArray = x_at, Wm: FloatArray = Wm) -> float:
                    return fun(x_at + Wm @ y)

                def jac_y(y: FloatArray, x_at: FloatArray = x_at, Wm: FloatArray = Wm) -> FloatArray:
                    out: FloatArray = Wm.T @ jac(x_at + Wm @ y)
                    return out

                res = minimize(
                    fun_y,
                    np.zeros(x.size),
                    jac=jac_y,
                    method="SLSQP",
                    constraints=problem.constraints(active, (x_at, Wm)),
                    options={"maxiter": settings.max_iter, "ftol": settings.ftol},
                    callback=None if deadline is None else stop_when_late,
                )
                cand = x_at + Wm @ np.asarray(res.x, dtype=float)
            n_iter += int(res.nit)
            if np.all(np.isfinite(cand)):
                x = cand
            history.append(problem.true_energy(x))
            active = _merge(active, problem.screen(x, settings.screen_band, settings.effort_band))
            if problem.violation(x) == 0.0 or _past(deadline):
                break
        if (settings.give_up and problem.violation(x) > 0.0) or _past(deadline):
            break
    return x, n_iter, active


def optimize_spline(
    problem: SplineProblem,
    settings: GradientSettings,
    *,
    rng: np.random.Generator,
    progress: Callable[[int, int], None] | None = None,
    initial: FloatArray | None = None,
    known: dict[str, np.ndarray] | None = None,
    deadline: float | None = None,
) -> GradientResult:
    """Multi-start continuation SLSQP on ``problem``; returns the best feasible start.

    The first start is the minimum-jerk move (all-zero coefficients); further starts
    add random smooth shapes of about ``start_scale`` times each joint's travel
    (at least 0.05 rad), drawn from ``rng``. A start's result counts only if it
    satisfies every constraint on the fine grid; the minimum-jerk move itself is
    the fall-back when none does and it is feasible. ``deadline`` (``time.perf_counter()``):
    past it the search stops where it is (no further iteration, round or start).
    """
    from threadpoolctl import threadpool_limits

    # the solver's small dense linear algebra runs many times faster on one BLAS
    # thread than on a pool that competes with other work for the same cores
    with threadpool_limits(limits=1, user_api="blas"):
        return _optimize_spline(
            problem, settings, rng=rng, progress=progress, initial=initial, known=known, deadline=deadline
        )


def _optimize_spline(
    problem: SplineProblem,
    settings: GradientSettings,
    *,
    rng: np.random.Generator,
    progress: Callable[[int, int], None] | None,
    initial: FloatArray | None,
    known: dict[str, np.ndarray] | None = None,
    deadline: float | None = None,
) -> GradientResult:
    t0 = time.perf_counter()
    zero = problem.origin.copy()  # the minimum-jerk move, or the smoothest path through the waypoints
    e_default = problem.true_energy(zero)
    p0 = problem.path(zero)
    tau0 = problem.robot.inverse_dynamics(p0.q, p0.qd, p0.qdd, friction=problem.friction)
    eps_unit = float(np.mean(np.abs(tau0 * p0.qd))) or 1.0
    scale = max(e_default, 1e-9)
    travel = np.maximum(np.abs(problem.q_end - problem.q_start), 0.05 / max(settings.start_scale, 1e-9))
    starts = [zero] if initial is None else [np.asarray(initial, dtype=float).ravel()]
    for _ in range(settings.n_starts - 1):
        bump = rng.standard_normal((problem.m, problem.n)) * settings.start_scale * travel
        starts.append(zero + bump.ravel())
    history: list[float] = [e_default]
    best_x, best_e, best_ok = zero, e_default, problem.violation(zero) == 0.0
    best_active: dict[str, np.ndarray] = {}
    finals: list[float] = []
    n_iter = 0
    for s, x0 in enumerate(starts):
        if s and _past(deadline):
            break
        x, it, active = _solve_from(problem, x0, settings, scale, eps_unit, history, known, deadline)
        n_iter += it
        e = problem.true_energy(x)
        ok = problem.violation(x) == 0.0
        finals.append(e if ok else float("inf"))
        if ok and (not best_ok or e < best_e):
            best_x, best_e, best_ok, best_active = x, e, True, active
        if progress is not None:
            progress(s + 1, len(starts))
    return GradientResult(
        coefficients=problem.coefficients(best_x),
        path=problem.path(best_x),
        energy_J=best_e,
        feasible=best_ok,
        history=np.minimum.accumulate(np.asarray(history)),
        n_evaluations=problem.n_evaluations,
        n_iterations=n_iter,
        wall_s=time.perf_counter() - t0,
        starts=tuple(finals),
        active=best_active,
    )


def solve_move(
    robot: Robot,
    q_start: FloatArray,
    q_end: FloatArray,
    duration: float,
    *,
    friction: Friction | None,
    settings: GradientSettings,
    rng: np.random.Generator,
    acceleration_limit: FloatArray | None = None,
    max_deviation_m: float | None = None,
    dt: float = SAMPLE_PERIOD,
    waypoints: tuple[tuple[float, FloatArray], ...] = (),
    jerk_limit: FloatArray | None = None,
    waypoint_radius: tuple[FloatArray, ...] = (),
    base: Trajectory | None = None,
    energy_measure: str = DEFAULT_MEASURE,
    deadline: float | None = None,
    initial: FloatArray | None = None,
) -> tuple[GradientResult, SplineProblem]:
    """Coarse-to-fine gradient search of one move; the result and the problem it lives in.

    ``waypoints``: (time s, joint vector) pairs inside the move that the path passes
    through exactly, at any speed (a chain of fly-by targets solved as one move), or
    within ``waypoint_radius`` (rad per joint, one per waypoint) of each: a zone.
    ``base``: the motion (on the fine grid) the shape is added to instead of the
    minimum-jerk move; its start and end states (q, qd, qdd) are kept.
    ``energy_measure``: the energy minimized (:data:`joulepath.energy.MEASURES`), its data
    from :attr:`Robot.drivetrain`. ``deadline`` (``time.perf_counter()``): past it the search
    stops where it is (:func:`optimize_spline`). ``initial``: the start (coefficients on the fine
    knots, flat) in place of the smoothest path, for a search on one level of knots only
    (``coarse_factor`` 1 or a move too short for two levels); refused otherwise. A path on other
    knots (a search its deadline stopped at its coarse level) is not used: the search starts as without.
    """

    def make(spacing: float) -> SplineProblem:
        basis = SplineBasis(duration, knot_spacing=spacing, degree=settings.degree, dt=dt)
        return SplineProblem(
            robot,
            q_start,
            q_end,
            duration,
            friction,
            basis,
            check_factor=settings.check_factor,
            max_deviation_m=max_deviation_m,
            acceleration_limit=acceleration_limit,
            waypoints=waypoints,
            jerk_limit=jerk_limit,
            waypoint_radius=waypoint_radius,
            base=base,
            energy_measure=energy_measure,
            energy_every=settings.energy_every,
            thin_rows=settings.is_long(duration),
            rate_rows=settings.rate_rows,
            hull_refine=settings.hull_refine,
        )

    spacing = settings.spacing_for(duration)
    fine = make(spacing)
    if initial is not None and np.asarray(initial).size != fine.m * fine.n:
        initial = None  # a path on other knots (a search its deadline stopped on its coarse level)
    coarse_spacing = spacing * settings.coarse_factor
    if settings.coarse_factor <= 1 or round(duration / coarse_spacing) < 2:
        return optimize_spline(fine, settings, rng=rng, initial=initial, deadline=deadline), fine
    if initial is not None:
        raise InvalidInput("an initial path needs a search on one level of knots (coarse_factor 1)")
    coarse = make(coarse_spacing)
    # the continuation runs coarse to fine: the wide knots take the stages before the last
    # `refine_stages`, the fine knots those (measured against every stage on the wide knots
    # first, coarse_stages=3: the same shares, CPU time within noise; BENCHMARKS.md)
    head = (
        settings.continuation[: settings.coarse_stages]
        if settings.coarse_stages
        else settings.continuation[: -settings.refine_stages] or settings.continuation[:1]
    )
    first = optimize_spline(coarse, replace(settings, continuation=head), rng=rng, deadline=deadline)
    if (settings.give_up and not first.feasible) or _past(deadline):
        return first, coarse
    # the coarse path in the fine basis: least squares on the fine grid (exact for nested knots)
    target = coarse.fine.B @ first.coefficients
    start: FloatArray = np.asarray(np.linalg.lstsq(fine.fine.B, target, rcond=None)[0], dtype=float)
    refine = replace(settings, n_starts=1, continuation=settings.continuation[-settings.refine_stages :])
    # the limit grids (accelerations, jerks, efforts, corridor) are the same in both bases;
    # the control-point (hull) rows are not; with an effort band, the fine level screens the effort
    # rows at its start (the coarse level's path) and takes none of those the coarse level gathered
    known = {
        kind: rows
        for kind, rows in first.active.items()
        if kind != "hull" and not (kind == "tau" and settings.effort_band is not None)
    }
    second = optimize_spline(fine, refine, rng=rng, initial=start, known=known, deadline=deadline)
    merged_history = np.minimum.accumulate(np.concatenate([first.history, second.history]))
    best, problem = (
        (second, fine) if second.feasible and second.energy_J <= first.energy_J else (first, coarse)
    )
    result = replace(
        best,
        history=merged_history,
        n_evaluations=first.n_evaluations + second.n_evaluations,
        n_iterations=first.n_iterations + second.n_iterations,
        wall_s=first.wall_s + second.wall_s,
        starts=first.starts,
    )
    return result, problem
