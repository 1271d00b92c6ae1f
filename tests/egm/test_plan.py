"""The plan: quintic Hermite interpolation, plan files, limits, the run folder's robot."""

import numpy as np
import pytest

from joulepath.egm import Plan, check_plan, hermite5, plan_file, read_plan, run_robot
from joulepath.errors import InvalidInput, LimitViolation


def quintic_plan(n_steps=9, duration=0.2):
    """Samples of a known quintic per joint (exactly representable by the interpolant)."""
    t = np.linspace(0.0, duration, n_steps)
    c = np.array(
        [
            [0.1, -0.2, 0.3, 0.05, -0.1, 0.2],
            [0.5, 1.0, -0.5, 0.2, 0.1, -0.3],
            [2.0, -1.0, 0.5, 1.5, -2.0, 0.7],
        ]
    )
    q = 0.2 + c[0] * t[:, None] + c[1] * t[:, None] ** 3 + c[2] * t[:, None] ** 5
    qd = c[0] + 3 * c[1] * t[:, None] ** 2 + 5 * c[2] * t[:, None] ** 4
    qdd = 6 * c[1] * t[:, None] + 20 * c[2] * t[:, None] ** 3
    return Plan(t=t, q=q, qd=qd, qdd=qdd), c


def test_hermite5_reproduces_a_quintic_between_samples():
    plan, c = quintic_plan()
    s = np.linspace(0.0, plan.duration, 101)
    q, qd = plan.at(s)
    q_true = 0.2 + c[0] * s[:, None] + c[1] * s[:, None] ** 3 + c[2] * s[:, None] ** 5
    qd_true = c[0] + 3 * c[1] * s[:, None] ** 2 + 5 * c[2] * s[:, None] ** 4
    np.testing.assert_allclose(q, q_true, atol=1e-12)
    np.testing.assert_allclose(qd, qd_true, atol=1e-10)


def test_hermite5_matches_the_samples_and_clamps():
    plan, _ = quintic_plan()
    q, qd = hermite5(plan.t, plan.q, plan.qd, plan.qdd, plan.t)
    np.testing.assert_allclose(q, plan.q, atol=1e-12)
    np.testing.assert_allclose(qd, plan.qd, atol=1e-10)
    before, _ = plan.at(-1.0)
    after, _ = plan.at(plan.duration + 1.0)
    np.testing.assert_allclose(before, plan.start)
    np.testing.assert_allclose(after, plan.end)


def test_hermite5_scalar_and_batch_shapes():
    plan, _ = quintic_plan()
    q1, qd1 = plan.at(0.05)
    qm, qdm = plan.at(np.array([0.05, 0.1]))
    assert q1.shape == qd1.shape == (6,)
    assert qm.shape == qdm.shape == (2, 6)
    np.testing.assert_allclose(qm[0], q1)


def test_plan_reversed_swaps_ends_and_negates_speed():
    plan, _ = quintic_plan()
    back = plan.reversed()
    np.testing.assert_allclose(back.start, plan.end)
    np.testing.assert_allclose(back.end, plan.start)
    q, qd = back.at(0.07)
    qf, qdf = plan.at(plan.duration - 0.07)
    np.testing.assert_allclose(q, qf, atol=1e-12)
    np.testing.assert_allclose(qd, -qdf, atol=1e-10)
    assert not plan.closed


def test_read_plan_reads_an_optimize_run(egm_run):
    plan = read_plan(plan_file(egm_run))
    assert plan.n_joints == 6
    assert plan.duration == pytest.approx(1.6)
    np.testing.assert_allclose(plan.start, [0.3, 0.2, -0.4, 0.5, -0.6, 1.0], atol=1e-9)
    np.testing.assert_allclose(plan.end, [-0.9, 0.6, 0.3, -1.2, 0.8, -1.5], atol=1e-9)


def test_plan_file_finds_cycle_path_csv(tmp_path):
    (tmp_path / "cycle_path.csv").write_text("t,q1,qd1,qdd1\n0,0,0,0\n0.025,0.1,0,0\n")
    assert plan_file(tmp_path).name == "cycle_path.csv"
    assert read_plan(plan_file(tmp_path)).n_joints == 1


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("t,q1,qd1\n0,0,0\n", "header"),
        ("t,q1,qd1,qdd1\n0,0,0,0\n", "at least 2 rows"),
        ("t,q1,qd1,qdd1\n0,0,0,0\n0,0,0,0\n", "increase"),
        ("t,q1,qd1,qdd1\n0,0,0,0\n0.1,nan,0,0\n", "finite"),
        ("t,q1,qd1,qdd1\n0,0,0,0\n0.1,x,0,0\n", "not a number"),
    ],
)
def test_read_plan_refuses_bad_files(tmp_path, text, match):
    p = tmp_path / "path.csv"
    p.write_text(text)
    with pytest.raises(InvalidInput, match=match):
        read_plan(p)


def test_plan_file_refuses_a_folder_without_plan(tmp_path):
    with pytest.raises(InvalidInput, match="neither path.csv nor cycle_path.csv"):
        plan_file(tmp_path)


def test_check_plan_accepts_the_optimized_path(egm_run, irb120):
    check_plan(read_plan(plan_file(egm_run)), irb120)


def test_check_plan_refuses_range_and_speed(irb120):
    plan, _ = quintic_plan()
    hi = irb120.joint_ranges()[1]
    shift = (hi[0] - plan.q[:, 0].min() + 0.01) * np.eye(6)[0]
    far = Plan(t=plan.t, q=plan.q + shift, qd=plan.qd, qdd=plan.qdd)
    with pytest.raises(LimitViolation, match="outside its range"):
        check_plan(far, irb120)
    fast = Plan(t=plan.t, q=plan.q, qd=plan.qd * 0 + 2 * irb120.velocity_limit, qdd=plan.qdd)
    with pytest.raises(LimitViolation, match="over its limit"):
        check_plan(fast, irb120)


def test_check_plan_refuses_another_joint_count(irb120):
    t = np.array([0.0, 0.025])
    z = np.zeros((2, 5))
    with pytest.raises(InvalidInput, match="5 joints"):
        check_plan(Plan(t=t, q=z, qd=z, qdd=z), irb120)


def test_run_robot_resolves_the_display_name_and_checks_the_given_one():
    assert run_robot("IRB 120", None).n_joints == 6
    assert run_robot(None, "irb120").name == "IRB 120"
    with pytest.raises(InvalidInput, match="names no robot"):
        run_robot(None, None)
    with pytest.raises(InvalidInput, match="is for robot"):
        run_robot("UR5", "irb120")
    with pytest.raises(InvalidInput, match="--robot"):
        run_robot("no such robot", None)
