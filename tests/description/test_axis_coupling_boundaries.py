"""The controller's axis values at every boundary of an axis-coupled arm (the IRB 2400: axis 3 = q2 + q3).

RAPID jointtargets, written programs, controller logs and EGM messages hold the controller's axis
values; the models work in serial joints. Each test checks agreement between two independent paths
(the parallelogram's geometry, a RAPID round trip, forward kinematics against a log's TCP, the power
kept by the torque map), never copied numbers. The IRB 120 (no coupling) is the identity throughout.
"""

from __future__ import annotations

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.data import log_in_joints, read_log
from joulepath.errors import LimitViolation
from joulepath.export import path_module
from joulepath.program import RapidError, parse_module, read_cycle_program, resolve_module
from joulepath.program._task import RobotKinematics
from joulepath.rapid import parse_module as parse_rapid
from joulepath.rapid.interpreter import Interpreter
from joulepath.rapid.task import Task
from joulepath.sim import simulate

EXT = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
# two jointtargets with the same axis 3 and different axis 2 (deg), all axes in the IRB 2400's ranges
A = (10.0, 20.0, 30.0, 0.0, 40.0, 0.0)
B = (10.0, -25.0, 30.0, 0.0, 40.0, 0.0)


@pytest.fixture(scope="module")
def irb2400():
    return load_robot("irb2400")


@pytest.fixture(scope="module")
def irb120():
    return load_robot("irb120")


def _jt(axes) -> str:
    return "[[" + ", ".join(f"{v:g}" for v in axes) + f"], {EXT}]"


def _module(body: str, decl: str = "") -> str:
    return (
        f"MODULE T\n    CONST jointtarget jA := {_jt(A)};\n    CONST jointtarget jB := {_jt(B)};\n"
        f"{decl}    PROC main()\n{body}    ENDPROC\nENDMODULE\n"
    )


def _moves(spec):
    return [s for s in spec.steps if s.kind == "move"]


def _run(robot, text: str):
    task = Task((parse_rapid(text, path="t.mod"),), frozenset(), "t.mod")
    return Interpreter(task, kinematics=RobotKinematics(robot)).run()


def _robax(record) -> np.ndarray:
    return np.array([float(v) for v in record.get("robax").values])


def test_the_robot_converts_axes_for_the_irb2400_only(irb2400, irb120):
    axes = np.radians([[5.0, 20.0, 30.0, 1.0, 2.0, 3.0], [-5.0, -40.0, 60.0, 0.0, 0.0, 0.0]])
    q = irb2400.axes_to_joints(axes)
    np.testing.assert_allclose(q[:, 2], axes[:, 2] - axes[:, 1])
    np.testing.assert_allclose(np.delete(q, 2, axis=1), np.delete(axes, 2, axis=1))
    np.testing.assert_allclose(irb2400.joints_to_axes(q), axes)
    # the torque map keeps the power: tau_axes . axes' = tau . q'
    tau = np.array([[3.0, -7.0, 11.0, 1.0, 2.0, 0.5]])
    np.testing.assert_allclose(
        (irb2400.joint_torques_to_axes(tau) * irb2400.joints_to_axes(q[:1])).sum(), (tau * q[:1]).sum()
    )
    assert irb2400.axes_coupled and not irb120.axes_coupled
    for f in (irb120.axes_to_joints, irb120.joints_to_axes, irb120.axis_torques_to_joints):
        np.testing.assert_array_equal(f(axes), axes)
    assert irb120.axis3_range is None
    assert np.degrees(irb2400.axis3_range).round().tolist() == [-60.0, 65.0]


def test_a_jointtarget_is_read_as_axis_values_by_both_readers(irb2400, tmp_path):
    """Two jointtargets with the same axis 3: the parallelogram keeps the forearm's angle, so the tool
    (wrist straight, axis 4 = 0) points the same way whatever axis 2 does; read as serial joints it
    would not. Both the interpreter and the static reader give q3 = axis 3 - axis 2."""
    text = _module("        MoveAbsJ jA, v100, fine, tool0;\n        MoveAbsJ jB, v100, fine, tool0;\n")
    (tmp_path / "t.mod").write_text(text)
    spec, _ = read_cycle_program(tmp_path / "t.mod", irb2400)
    static = resolve_module(parse_module(text, path="t.mod"), irb2400)
    for got in (spec, static):
        qa, qb = (m.q for m in _moves(got)[:2])
        for q, axes in ((qa, A), (qb, B)):
            np.testing.assert_allclose(np.degrees(q[2]), axes[2] - axes[1], atol=1e-9)
            np.testing.assert_allclose(np.degrees(np.delete(q, 2)), np.delete(axes, 2), atol=1e-9)
        ra, rb = irb2400.fk(qa).rotation, irb2400.fk(qb).rotation
        np.testing.assert_allclose(ra, rb, atol=1e-9)  # the forearm's angle is axis 3
        wrong_a, wrong_b = (irb2400.fk(np.radians(axes)).rotation for axes in (A, B))
        assert np.abs(wrong_a - wrong_b).max() > 0.5  # as serial joints the two would differ


def test_calcrobt_and_calcjointt_round_trip_in_axis_values(irb2400):
    """CalcRobT of a jointtarget is where FK of its serial joints puts the TCP; CalcJointT of that
    robtarget gives the same axis values back; CJointT after a move gives the jointtarget moved to."""
    body = (
        "        p := CalcRobT(jA, tool0);\n        j2 := CalcJointT(p, tool0);\n"
        "        MoveAbsJ jA, v100, fine, tool0;\n        j3 := CJointT();\n"
        "        MoveAbsJ j2, v100, fine, tool0;\n        MoveJ p, v100, fine, tool0;\n"
        "        MoveAbsJ j3, v100, fine, tool0;\n"
    )
    decl = "    VAR robtarget p;\n    VAR jointtarget j2;\n    VAR jointtarget j3;\n"
    trace = _run(irb2400, _module(body, decl))
    m_a, m_j2, m_p, m_j3 = trace.motions[:4]
    np.testing.assert_allclose(_robax(m_j2.target), A, atol=1e-6)
    np.testing.assert_allclose(_robax(m_j3.target), A, atol=1e-6)
    np.testing.assert_allclose(m_p.joints, m_a.joints, atol=1e-6)
    trans = m_p.target.get("trans")
    xyz = np.array([float(trans.get(k)) for k in ("x", "y", "z")])
    np.testing.assert_allclose(xyz, irb2400.fk(m_a.joints).position_mm, atol=1e-6)


def test_axis3_outside_the_controllers_range_is_refused_by_both_readers(irb2400, tmp_path):
    """Axis 3 = 70 deg with axis 2 = 20 deg: serial q3 = 50 deg lies in its box, but the controller's
    axis 3 stops at 65 deg."""
    text = (
        f"MODULE T\n    CONST jointtarget jX := {_jt((0, 20, 70, 0, 0, 0))};\n"
        "    PROC main()\n        MoveAbsJ jX, v100, fine, tool0;\n    ENDPROC\nENDMODULE\n"
    )
    (tmp_path / "t.mod").write_text(text)
    with pytest.raises(RapidError, match="axis 3 = 70.00 deg is outside the controller's axis-3 range"):
        read_cycle_program(tmp_path / "t.mod", irb2400)
    with pytest.raises(RapidError, match="axis 3 = 70.00 deg is outside the controller's axis-3 range"):
        resolve_module(parse_module(text, path="t.mod"), irb2400)


def _path(robot, axes_deg_rows):
    q = robot.axes_to_joints(np.radians(axes_deg_rows))
    t = np.linspace(0.0, 2.0, q.shape[0])
    qd = np.gradient(q, t, axis=0)
    return q, qd


@pytest.mark.parametrize("name", ["irb2400", "irb120"])
def test_path_mod_jointtargets_read_back_to_the_same_joints(name, tmp_path):
    """path.mod written from serial joints, read back by the RAPID interpreter: the same joints."""
    robot = load_robot(name)
    q, qd = _path(robot, np.linspace([0, 0, 0, 0, 30, 0], [20, 15, 25, 10, 40, 20], 5))
    (tmp_path / "path.mod").write_text(path_module(robot, q, qd, 2.0, repeats=1))
    spec, _ = read_cycle_program(tmp_path / "path.mod", robot)
    moved = np.array([m.q for m in _moves(spec)])
    for row in q:  # START, every via point and GOAL are moved to
        assert np.abs(moved - row).max(axis=1).min() < 1e-6


def test_path_mod_refuses_a_path_past_the_controllers_axis3_range(irb2400):
    q, qd = _path(irb2400, np.linspace([0, 0, 0, 0, 30, 0], [0, 0, 64, 0, 30, 0], 5))
    q[:, 2] += np.radians([0, 0, 0, 0, 3])  # the last sample: axis 3 at 67 deg, q3 still in its box
    with pytest.raises(LimitViolation, match="axis-3 range"):
        path_module(irb2400, q, np.zeros_like(qd), 2.0)


def test_a_simulated_controller_log_holds_axis_values(tmp_path):
    """The log's TCP columns are FK of the serial joints: the logged positions converted back agree
    with them; read as joints they would not. Power is the same in both coordinates."""
    run = simulate(tmp_path / "log.csv", plant="sim", n_moves=3, seed=1, robot="irb2400")
    robot = load_robot("irb2400")
    raw = read_log(run.log)
    log = log_in_joints(raw, robot)
    tcp = robot.fk(log.q).position_m
    assert np.abs(tcp - raw.tcp_position).max() < 1e-4
    assert np.abs(robot.fk(raw.q).position_m - raw.tcp_position).max() > 0.01
    np.testing.assert_allclose((log.tau * log.qd).sum(axis=1), (raw.tau * raw.qd).sum(axis=1), atol=1e-2)
    np.testing.assert_allclose(log.q[:, 2], raw.q[:, 2] - raw.q[:, 1])


def test_the_irb120_log_is_unchanged(tmp_path):
    run = simulate(tmp_path / "log.csv", plant="sim", n_moves=2, seed=1, robot="irb120")
    raw = read_log(run.log)
    log = log_in_joints(raw, load_robot("irb120"))
    assert log is raw
