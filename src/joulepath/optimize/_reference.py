"""The reference optimum: a direct transcription of one move, solved by IPOPT (CasADi).

Independent of the default optimizer on every count that matters:

* its own inverse dynamics — the recursive Newton–Euler algorithm written in CasADi
  from the Pinocchio model's joint placements, axes and inertias (``casadi_rnea``,
  checked against Pinocchio in the tests);
* its own representation — the joint positions, speeds and accelerations at every
  25 ms sample are the unknowns, tied by a piecewise-constant jerk (an exact triple
  integrator), so the path between samples is a cubic;
* its own solver — IPOPT with the exact Hessian from CasADi's automatic
  differentiation.

Same problem: start and end at rest, joint ranges, speed limits and effort limits
at every sample, the acceleration limits and the jerk limits when given (the jerk of
each interval is one unknown, so its limit is a bound on it: the same mean jerk over
each step that the limit check measures on any grid finer than the samples), the
energy ``Σ |tau qd| dt`` on the samples with friction. ``|p|``
is smoothed as ``sqrt(p² + ε²) - ε`` with ``ε`` driven towards zero; the reported
energy is the true metric of the final samples. Used by the benchmarks and the tests
to state "% of the optimum reached"; it needs the ``reference`` extra (``casadi``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.dynamics import CoulombViscousFriction, Friction, FrictionSum, Robot
from joulepath.energy import path_energy
from joulepath.errors import InvalidInput, MissingDependency
from joulepath.trajectory import Trajectory, minimum_jerk
from joulepath.units import SAMPLE_PERIOD


def _casadi() -> Any:
    try:
        import casadi
    except ImportError as err:  # pragma: no cover - depends on the environment
        raise MissingDependency(
            "the reference solver needs CasADi; install it with pip install 'joulepath[reference]'"
        ) from err
    return casadi


_AXES = {"RX": (1.0, 0.0, 0.0), "RY": (0.0, 1.0, 0.0), "RZ": (0.0, 0.0, 1.0)}


def _joint_axis(joint: Any) -> FloatArray:
    name = joint.shortname().removeprefix("JointModel")
    for key in ("RUB", "R"):
        if name.startswith(key) and name[len(key) :] in ("X", "Y", "Z"):
            return np.array(_AXES["R" + name[len(key) :]])
    if name == "RevoluteUnaligned":
        axis: FloatArray = np.asarray(joint.axis, dtype=float)
        return axis
    raise InvalidInput(f"the reference solver handles revolute joints only, got {name}")


def _rotation(cs: Any, axis: FloatArray, angle: Any) -> Any:
    """Rodrigues' rotation about a unit axis, as a CasADi 3x3 expression."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = cs.DM([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return cs.DM.eye(3) + cs.sin(angle) * K + (1.0 - cs.cos(angle)) * (K @ K)


def casadi_rnea(robot: Robot) -> Any:
    """``tau = f(q, qd, qdd)`` (rigid body, no friction) as a CasADi Function of three n-vectors.

    Recursive Newton–Euler in each link's frame, from the Pinocchio model's data
    (joint placements, axes, masses, centres of mass, inertias about the centre of
    mass) and its gravity vector.
    """
    cs = _casadi()
    model = robot.pinocchio_model
    n = robot.n_joints
    if model.nq != n or model.nv != n or any(model.parents[i] != i - 1 for i in range(1, n + 1)):
        raise InvalidInput("the reference solver handles serial chains of revolute joints only")
    q = cs.SX.sym("q", n)
    qd = cs.SX.sym("qd", n)
    qdd = cs.SX.sym("qdd", n)
    omega = cs.SX.zeros(3)
    domega = cs.SX.zeros(3)
    acc = cs.DM(-np.asarray(model.gravity.linear, dtype=float))  # base accelerates against gravity
    rot, pos, forces, moments = [], [], [], []
    for i in range(1, n + 1):
        placement = model.jointPlacements[i]
        axis = cs.DM(_joint_axis(model.joints[i]))
        R = cs.DM(np.asarray(placement.rotation)) @ _rotation(cs, _joint_axis(model.joints[i]), q[i - 1])
        p = cs.DM(np.asarray(placement.translation))
        Rt = R.T
        acc = Rt @ (acc + cs.cross(domega, p) + cs.cross(omega, cs.cross(omega, p)))
        w_parent = Rt @ omega
        omega = w_parent + axis * qd[i - 1]
        domega = Rt @ domega + cs.cross(w_parent, axis * qd[i - 1]) + axis * qdd[i - 1]
        inertia = model.inertias[i]
        m = float(inertia.mass)
        com = cs.DM(np.asarray(inertia.lever))
        Ic = cs.DM(np.asarray(inertia.inertia))
        a_com = acc + cs.cross(domega, com) + cs.cross(omega, cs.cross(omega, com))
        F = m * a_com
        N = Ic @ domega + cs.cross(omega, Ic @ omega)
        rot.append(R)
        pos.append(p)
        forces.append(F)
        moments.append(N + cs.cross(com, F))
    tau = [cs.SX(0)] * n
    f_child = cs.SX.zeros(3)
    n_child = cs.SX.zeros(3)
    for i in range(n, 0, -1):
        f = forces[i - 1]
        nm = moments[i - 1]
        if i < n:
            Rc, pc = rot[i], pos[i]
            fc = Rc @ f_child
            f = f + fc
            nm = nm + Rc @ n_child + cs.cross(pc, fc)
        tau[i - 1] = cs.dot(cs.DM(_joint_axis(model.joints[i])), nm)
        f_child, n_child = f, nm
    return cs.Function("rnea", [q, qd, qdd], [cs.vertcat(*tau)])


def _casadi_friction(cs: Any, friction: Friction | None, qd: Any, n: int) -> Any:
    if friction is None:
        return cs.SX.zeros(n)
    terms = friction.terms if isinstance(friction, FrictionSum) else (friction,)
    total = cs.SX.zeros(n)
    for term in terms:
        if not isinstance(term, CoulombViscousFriction):
            raise InvalidInput(
                f"the reference solver handles Coulomb–viscous friction only, got {type(term).__name__}"
            )
        fc = np.broadcast_to(np.asarray(term.coulomb, dtype=float), (n,))
        fv = np.broadcast_to(np.asarray(term.viscous, dtype=float), (n,))
        sgn = cs.tanh(qd / term.smoothing) if term.smoothing > 0 else cs.sign(qd)
        total = total + cs.DM(fc) * sgn + cs.DM(fv) * qd
    return total


def _between_samples(
    q: FloatArray, v: FloatArray, a: FloatArray, h: float, substeps: int
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The piecewise-cubic path at ``substeps`` points per interval (and the last sample)."""
    u = np.diff(a, axis=0) / h
    s = (np.arange(substeps) * h / substeps)[None, :, None]
    qf = q[:-1, None] + s * v[:-1, None] + s**2 / 2 * a[:-1, None] + s**3 / 6 * u[:, None]
    vf = v[:-1, None] + s * a[:-1, None] + s**2 / 2 * u[:, None]
    af = a[:-1, None] + s * u[:, None]
    n = q.shape[1]
    return (
        np.vstack([qf.reshape(-1, n), q[-1:]]),
        np.vstack([vf.reshape(-1, n), v[-1:]]),
        np.vstack([af.reshape(-1, n), a[-1:]]),
    )


@dataclass(frozen=True, slots=True)
class ReferenceResult:
    """The transcription's optimum: its sampled path, true energy, largest violation and cost.

    ``max_violation``: the largest excess over a limit at the samples, in SI units (rad,
    rad/s, rad/s², N·m), the jerk's as a share of its limit.
    """

    path: Trajectory
    energy_J: float
    energy_fine_J: float
    max_violation: float
    status: str
    wall_s: float


def reference_optimum(
    robot: Robot,
    q_start: FloatArray,
    q_end: FloatArray,
    duration: float,
    *,
    friction: Friction | None,
    initial: Trajectory | None = None,
    continuation: tuple[float, ...] = (0.1, 0.003),
    dt: float = SAMPLE_PERIOD,
    acceleration_limit: FloatArray | None = None,
    jerk_limit: FloatArray | None = None,
    substeps: int = 4,
    tol: float = 1e-9,
    max_iter: int = 3000,
) -> ReferenceResult:
    """Solve the move by direct transcription and IPOPT, from ``initial`` (default: minimum jerk).

    Energy and limits are evaluated on ``substeps`` points per sample interval (the
    exact cubic between samples), so the optimum cannot hide motion between samples.
    Returns the path at the samples with its true (non-smooth) energy on the
    samples and on the fine grid. The continuation shares scale ``ε`` with the
    initial path's mean ``|tau qd|``.
    """
    cs = _casadi()
    n = robot.n_joints
    q0 = np.asarray(q_start, dtype=float)
    qf = np.asarray(q_end, dtype=float)
    start = initial if initial is not None else minimum_jerk(q0, qf, duration, dt=dt)
    K = start.t.size
    h = float(dt)
    rnea = casadi_rnea(robot)
    lo, hi = robot.joint_ranges()
    vmax = np.asarray(robot.velocity_limit, dtype=float)
    emax = np.asarray(robot.effort_limit, dtype=float)
    amax = None if acceleration_limit is None else np.asarray(acceleration_limit, dtype=float)
    jmax = None if jerk_limit is None else np.asarray(jerk_limit, dtype=float)

    opti = cs.Opti()
    Q = opti.variable(n, K)
    V = opti.variable(n, K)
    A = opti.variable(n, K)
    U = opti.variable(n, K - 1)
    eps = opti.parameter()
    opti.subject_to(Q[:, 0] == q0)
    opti.subject_to(Q[:, -1] == qf)
    for M in (V, A):
        opti.subject_to(M[:, 0] == 0)
        opti.subject_to(M[:, -1] == 0)
    opti.subject_to(Q[:, 1:] == Q[:, :-1] + h * V[:, :-1] + h**2 / 2 * A[:, :-1] + h**3 / 6 * U)
    opti.subject_to(V[:, 1:] == V[:, :-1] + h * A[:, :-1] + h**2 / 2 * U)
    opti.subject_to(A[:, 1:] == A[:, :-1] + h * U)
    # the path between samples is the exact cubic of each interval's jerk: evaluate it
    # at `substeps` points per interval, so that energy and limits see the whole path
    # (an energy summed on the samples alone can be gamed by moving between them)
    parts_q, parts_v, parts_a = [], [], []
    for j in range(substeps):
        s_ = j * h / substeps
        parts_q.append(Q[:, :-1] + s_ * V[:, :-1] + s_**2 / 2 * A[:, :-1] + s_**3 / 6 * U)
        parts_v.append(V[:, :-1] + s_ * A[:, :-1] + s_**2 / 2 * U)
        parts_a.append(A[:, :-1] + s_ * U)
    Qf = cs.horzcat(*parts_q, Q[:, -1])
    Vf = cs.horzcat(*parts_v, V[:, -1])
    Af = cs.horzcat(*parts_a, A[:, -1])
    Kf = substeps * (K - 1) + 1
    for i in range(n):
        if np.isfinite(lo[i]):
            opti.subject_to(Qf[i, :] >= lo[i])
        if np.isfinite(hi[i]):
            opti.subject_to(Qf[i, :] <= hi[i])
        if np.isfinite(vmax[i]):
            opti.subject_to(opti.bounded(-vmax[i], Vf[i, :], vmax[i]))
        if amax is not None and np.isfinite(amax[i]):
            opti.subject_to(opti.bounded(-amax[i], Af[i, :], amax[i]))
        if jmax is not None and np.isfinite(jmax[i]):
            opti.subject_to(opti.bounded(-jmax[i], U[i, :], jmax[i]))
    tau = rnea.map(Kf)(Qf, Vf, Af)
    if friction is not None:
        v_sym = cs.SX.sym("v", n)
        fr = cs.Function("friction", [v_sym], [_casadi_friction(cs, friction, v_sym, n)])
        tau = tau + fr.map(Kf)(Vf)
    for i in range(n):
        if np.isfinite(emax[i]):
            opti.subject_to(opti.bounded(-emax[i], tau[i, :], emax[i]))
    power = tau * Vf
    energy = cs.sum1(cs.sum2(cs.sqrt(power**2 + eps**2) - eps)) * (h / substeps)
    tau0 = robot.inverse_dynamics(start.q, start.qd, start.qdd, friction=friction)
    unit = float(np.mean(np.abs(tau0 * start.qd))) or 1.0
    scale = max(float(path_energy(tau0, start.qd, h).total), 1e-9)
    opti.minimize(energy / scale)
    opti.set_initial(Q, start.q.T)
    opti.set_initial(V, start.qd.T)
    opti.set_initial(A, start.qdd.T)
    jerk = np.diff(start.qdd, axis=0).T / h
    opti.set_initial(U, jerk)
    opti.solver(
        "ipopt",
        {"print_time": False},
        {"print_level": 0, "tol": tol, "max_iter": max_iter, "sb": "yes", "mu_strategy": "adaptive"},
    )
    t0 = time.perf_counter()
    status = "not run"
    sol_q, sol_v, sol_a = start.q, start.qd, start.qdd
    for share in continuation:
        opti.set_value(eps, share * unit)
        try:
            sol = opti.solve()
            status = str(sol.stats()["return_status"])
            sol_q, sol_v, sol_a = (np.asarray(sol.value(M)).T.reshape(K, n) for M in (Q, V, A))
        except RuntimeError:
            status = str(opti.stats()["return_status"])
            sol_q, sol_v, sol_a = (np.asarray(opti.debug.value(M)).T.reshape(K, n) for M in (Q, V, A))
        opti.set_initial(Q, sol_q.T)
        opti.set_initial(V, sol_v.T)
        opti.set_initial(A, sol_a.T)
        opti.set_initial(U, np.diff(sol_a, axis=0).T / h)
    wall = time.perf_counter() - t0
    path = Trajectory(t=start.t, q=sol_q, qd=sol_v, qdd=sol_a)
    tau_s = robot.inverse_dynamics(sol_q, sol_v, sol_a, friction=friction)
    e = float(path_energy(tau_s, sol_v, h).total)
    fq, fv, fa = _between_samples(sol_q, sol_v, sol_a, h, substeps)
    viol = max(
        0.0,
        float(np.max(np.where(np.isfinite(hi), sol_q - hi, 0.0))),
        float(np.max(np.where(np.isfinite(lo), lo - sol_q, 0.0))),
        float(np.max(np.where(np.isfinite(vmax), np.abs(sol_v) - vmax, 0.0))),
        float(np.max(np.abs(sol_a) - amax)) if amax is not None else 0.0,
        # relative: IPOPT relaxes each bound by 1e-8 of its size, and jerk limits are ~100 rad/s³
        float(np.max(np.abs(np.diff(sol_a, axis=0)) / h / jmax - 1.0)) if jmax is not None else 0.0,
        float(np.max(np.where(np.isfinite(emax), np.abs(tau_s) - np.nan_to_num(emax, nan=0.0), 0.0))),
    )
    tau_f = robot.inverse_dynamics(fq, fv, fa, friction=friction)
    e_fine = float(path_energy(tau_f, fv, h / substeps).total)
    return ReferenceResult(
        path=path, energy_J=e, energy_fine_J=e_fine, max_violation=viol, status=status, wall_s=wall
    )
