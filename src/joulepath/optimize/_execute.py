"""How the controller will run what is written: the executed move, measured before it leaves the tool.

An exporter that writes samples the controller follows one by one (URScript ``servoj``, a
ROS 2 ``JointTrajectory``, a stream) runs the planned path. RAPID does not: the optimized
move is written as ``MoveAbsJ`` via points with ``\\T`` and the controller plans its own
motion through them (:mod:`joulepath.sim._timing`). For RAPID the via points are laid out
where the emulated controller follows them most closely (:func:`joulepath.sim.follow_path`),
the default move is the controller's own ``MoveAbsJ \\T:=duration`` (:func:`joulepath.sim.timed_move`),
and both are run by the controller emulation and measured on physics and the lab robot: the
*executed* duration, energies and saving are those of the written program.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from joulepath.dynamics import Robot
from joulepath.energy import DEFAULT_MEASURE, MEASURES
from joulepath.optimize._verify import energy_on_samples, measured_energy, plant_energy
from joulepath.trajectory import Trajectory

EXECUTION_TOLERANCES = {"duration_pct": 2.0, "tcp_mm": 5.0}
"""How far the written program, run by the controller emulation, may depart from the plan: its
optimized move at most ``duration_pct`` longer (faster is allowed: the robot then waits at the
goal), its TCP path at most ``tcp_mm`` from the planned one. Its energy is not held to the
plan's: the saving stated is the executed one, and it must be a saving."""


@dataclass(frozen=True, slots=True)
class Execution:
    """The written RAPID program as the controller emulation runs it (``result.json`` keys).

    Durations in s, energies in J on the same measure as the plan (``Σ |tau qd| dt`` on the
    physics model, and the lab robot's drive torque), on a 2.5 ms grid. The default is the
    controller's own ``MoveAbsJ \\T``, so ``executed_saved_pct`` is what the robot saves by
    running the written optimized move instead of its own move at the same cycle time.
    ``executed_tcp_deviation_mm`` is the largest TCP distance between the planned and the
    executed TCP paths (each point of one to the nearest of the other, both ways);
    ``executed_tcp_lag_mm`` the largest distance at the same time.
    ``executed_lab_*_J``: the emulated motions as the lab robot's servo tracks them (:func:`tracked`),
    on the plan's measure
    (None where the lab robot has no data for it); ``executed_energy_*_lab_J`` and
    ``executed_saved_lab_pct`` are the lab's on its logged (``mechanical``) measure,
    deprecated (:data:`joulepath.optimize._figures.RESULT_DEPRECATED`).
    """

    executed_via_points: int
    executed_via_spacing_s: float
    executed_duration_s: float
    executed_default_duration_s: float
    executed_energy_default_J: float
    executed_energy_optimized_J: float
    executed_saved_pct: float
    executed_energy_default_lab_J: float
    executed_energy_optimized_lab_J: float
    executed_saved_lab_pct: float
    executed_tcp_deviation_mm: float
    executed_tcp_lag_mm: float
    executed_energy_vs_plan_pct: float
    executed_duration_vs_plan_pct: float
    executed_matches_plan: bool
    executed_model: str
    executed_lab_default_J: float | None = None
    executed_lab_optimized_J: float | None = None

    def to_json(self) -> dict[str, Any]:
        from dataclasses import asdict

        return asdict(self)

    def refusal(self) -> str | None:
        """Why the module is not written (one line), or None when it runs as planned."""
        if self.executed_matches_plan:
            return None
        tol = EXECUTION_TOLERANCES
        return (
            "the controller emulation does not run the via points as planned: the optimized move takes "
            f"{self.executed_duration_s:.3f} s ({self.executed_duration_vs_plan_pct:+.1f} %, at most "
            f"+{tol['duration_pct']:g} %), leaves the planned TCP path by "
            f"{self.executed_tcp_deviation_mm:.1f} mm (at most {tol['tcp_mm']:g} mm) and takes "
            f"{self.executed_energy_optimized_J:.2f} J against the controller's own move's "
            f"{self.executed_energy_default_J:.2f} J; "
            "path.mod is not written. --export egm streams the planned path to an ABB controller "
            "(Externally Guided Motion); a longer --duration or a larger --accel-time gives a plan the "
            "controller follows"
        )


def rapid_execution(
    robot: Robot, planned: Trajectory, planned_fine_J: float, *, measure: str = DEFAULT_MEASURE
) -> tuple[Execution, Trajectory]:
    """Lay out the via points of ``planned`` and measure the written program on the emulation.

    ``planned_fine_J``: the plan's physics energy on the fine grid on ``measure`` (what the
    executed energy is compared with; with a measure that counts standby, over the plan's
    duration). The executed physics energies are on the same measure (standby over each
    move's own duration), the lab's on its logged (``mechanical``) one. Returns the
    measurement and the via points as a (non-uniform) trajectory: its samples are what the
    RAPID exporter writes, the first the start.
    """
    from joulepath.sim import follow_path, make_plant, timed_move

    duration = float(planned.t[-1])
    followed = follow_path(robot, planned)
    d_end, default = timed_move(robot, planned.q[0], planned.q[-1], duration)
    lab = make_plant("lab", robot)
    if measure == DEFAULT_MEASURE:
        e_opt = energy_on_samples(robot, followed.executed, friction=robot.friction)
        e_def = energy_on_samples(robot, default, friction=robot.friction)
    else:
        e_opt, e_def = (
            measured_energy(robot, path, friction=robot.friction, measure=measure).total_J
            for path in (followed.executed, default)
        )
    # the lab robot runs the commanded motion through its servo (its tracking lag), as a log of it shows
    lab_opt, lab_def = tracked(lab, followed.executed), tracked(lab, default)
    l_opt, l_def = plant_energy(lab, lab_opt), plant_energy(lab, lab_def)
    lab_ok = MEASURES[measure].missing(lab.drivetrain) is None
    m_opt, m_def = (
        (plant_energy(lab, p, measure=measure) for p in (lab_opt, lab_def)) if lab_ok else (None, None)
    )
    from scipy.spatial import cKDTree

    pos_plan = robot.fk(_at(planned, np.minimum(followed.executed.t, duration))).position_mm
    pos_exec = robot.fk(followed.executed.q).position_mm
    lag = float(np.linalg.norm(pos_plan - pos_exec, axis=1).max())
    dense = robot.fk(_at(planned, np.linspace(0.0, duration, pos_exec.shape[0]))).position_mm
    dev = float(max(cKDTree(dense).query(pos_exec)[0].max(), cKDTree(pos_exec).query(dense)[0].max()))
    dur_pct = 100.0 * (followed.executed_duration_s / duration - 1.0)
    e_pct = 100.0 * (e_opt / planned_fine_J - 1.0) if planned_fine_J > 0 else 0.0
    tol = EXECUTION_TOLERANCES
    ok = dur_pct <= tol["duration_pct"] and dev <= tol["tcp_mm"] and e_opt < e_def
    execution = Execution(
        executed_via_points=len(followed.indices),
        executed_via_spacing_s=followed.spacing,
        executed_duration_s=followed.executed_duration_s,
        executed_default_duration_s=float(d_end),
        executed_energy_default_J=e_def,
        executed_energy_optimized_J=e_opt,
        executed_saved_pct=100.0 * (e_def - e_opt) / e_def if e_def > 0 else 0.0,
        executed_energy_default_lab_J=l_def,
        executed_energy_optimized_lab_J=l_opt,
        executed_saved_lab_pct=100.0 * (l_def - l_opt) / l_def if l_def > 0 else 0.0,
        executed_tcp_deviation_mm=dev,
        executed_tcp_lag_mm=lag,
        executed_energy_vs_plan_pct=e_pct,
        executed_duration_vs_plan_pct=dur_pct,
        executed_matches_plan=bool(ok),
        executed_lab_default_J=m_def,
        executed_lab_optimized_J=m_opt,
        executed_model=(
            "joulepath's ABB controller emulation (joulepath.sim): the default is MoveAbsJ \\T:=duration "
            "(jerk-limited sin² profile), the optimized move the written MoveAbsJ via points (\\T, z200, the "
            "last fine) run as a timed fly-by chain; energies on the physics model and the emulated lab "
            "robot on a 2.5 ms grid"
        ),
    )
    idx = [0, *followed.indices]
    vias = Trajectory(t=planned.t[idx], q=planned.q[idx], qd=planned.qd[idx], qdd=planned.qdd[idx])
    return execution, vias


@dataclass(frozen=True, slots=True)
class _Commanded:
    """A sampled motion as a plant's command (:class:`joulepath.sim._plants.Commanded`): held at its end."""

    path: Trajectory

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        p = self.path
        tt = np.clip(t, p.t[0], p.t[-1])
        q, qd, qdd = (
            np.column_stack([np.interp(tt, p.t, x[:, j]) for j in range(x.shape[1])])
            for x in (p.q, p.qd, p.qdd)
        )
        return q, qd, qdd


def tracked(plant: Any, path: Trajectory) -> Trajectory:
    """The motion ``plant`` runs when commanded ``path``, at its samples: through its servo's tracking
    lag (:func:`joulepath.sim.run_plant`, without its sensor noise); ``path`` itself for a plant
    without one.

    The controller emulation's timed via-point chains step their accelerations at the corners; the
    servo smooths those steps, and so does the energy a log of the robot shows (measured on the fixed
    task: the lab rehearsal of ``tests/measure`` gave 10.0-10.3 % against 8.9 % predicted from the
    commanded motion, 9.8 % from the tracked one).
    """
    from joulepath.sim import run_plant

    if plant.tracking_hz is None:
        return path
    quiet = replace(plant, torque_noise=(), speed_noise_deg_s=0.0)
    m = run_plant(quiet, _Commanded(path), path.t, rng=np.random.default_rng(0))
    return Trajectory(t=path.t, q=m.q, qd=m.qd, qdd=m.qdd)


def _at(path: Trajectory, t: np.ndarray) -> np.ndarray:
    from joulepath.sim import interpolate_via as _interpolate

    return _interpolate(path, t)
