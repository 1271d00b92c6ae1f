"""The policy as a pure function: wait, ramp-in, run on the controller's clock, hold, repeat, faults."""

import math

import numpy as np
import pytest

from joulepath.egm import Phase, Plan, PolicyState, RobotState, StreamSettings, step
from joulepath.errors import InvalidInput

START = np.array([0.3, 0.2, -0.4, 0.5, -0.6, 1.0])
END = np.array([-0.9, 0.6, 0.3, -1.2, 0.8, -1.5])
T = 1.0
DT = 0.004


def rest_to_rest(start=START, end=END, duration=T):
    """A minimum-jerk move sampled at 25 ms (q, qd, qdd exact)."""
    t = np.linspace(0.0, duration, round(duration / 0.025) + 1)
    tau = (t / duration)[:, None]
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    sd = (30 * tau**2 - 60 * tau**3 + 30 * tau**4) / duration
    sdd = (60 * tau - 180 * tau**2 + 120 * tau**3) / duration**2
    d = end - start
    return Plan(t=t, q=start + s * d, qd=sd * d, qdd=sdd * d)


def closed_plan():
    """Out and back: ends where it starts."""
    t = np.linspace(0.0, T, 41)
    w = 2 * math.pi / T
    c, s = np.cos(w * t)[:, None], np.sin(w * t)[:, None]
    a = np.array([0.2, -0.1, 0.1, 0.3, -0.2, 0.4])
    return Plan(
        t=t,
        q=START + a * (1 - c) ** 2 / 4,
        qd=a * (1 - c) * s * w / 2,
        qdd=a * w**2 / 2 * (s**2 + (1 - c) * c),
    )


def drive(plan, settings, *, follow=True, q0=None, t0=100.0, running_after=0.02, n=2000, until=Phase.DONE):
    """Run the policy against an ideal robot (feedback = last reference) for at most n messages."""
    state = PolicyState()
    q = (plan.start if q0 is None else q0).copy()
    rows = []
    for k in range(n):
        t = t0 + k * DT
        robot = RobotState(t=t, q=q, running=k * DT >= running_after)
        ref, state = step(plan, settings, state, robot)
        rows.append((t, ref, state))
        if follow:
            q = ref.q.copy()
        if state.phase in (until, Phase.FAULT):
            break
    return rows


def test_step_waits_at_the_start_until_running_and_ramped_in():
    plan = rest_to_rest()
    settings = StreamSettings(ramp_in_s=0.1)
    rows = drive(plan, settings, running_after=0.04, until=Phase.RUN)
    t_run, ref, state = rows[-1]
    assert state.phase is Phase.RUN
    assert t_run - 100.0 >= 0.04 + 0.1 - 1e-9  # running, then the ramp-in held
    for _, r, s in rows[:-1]:
        assert s.phase is Phase.WAIT
        np.testing.assert_allclose(r.q, plan.start)
        np.testing.assert_allclose(r.qd, 0.0)
    np.testing.assert_allclose(ref.q, plan.start)
    assert state.t0 == t_run


def test_step_reference_is_the_interpolated_plan_at_controller_time():
    plan = rest_to_rest()
    rows = drive(plan, StreamSettings(), until=Phase.HOLD)
    run = [(t, r, s) for t, r, s in rows if s.phase is Phase.RUN]
    assert len(run) > 100
    t0 = run[0][2].t0
    for t, ref, _ in run:
        q, qd = plan.at(t - t0)
        np.testing.assert_allclose(ref.q, q)
        np.testing.assert_allclose(ref.qd, qd)
        assert ref.plan_time == pytest.approx(t - t0)


def test_step_follows_the_controller_clock_not_the_message_count():
    plan = rest_to_rest()
    state = PolicyState()
    settings = StreamSettings(ramp_in_s=0.0)
    _, state = step(plan, settings, state, RobotState(t=5.0, q=plan.start, running=True))
    ref, state = step(plan, settings, state, RobotState(t=5.5, q=plan.at(0.5)[0], running=True))
    np.testing.assert_allclose(ref.q, plan.at(0.5)[0])  # one message later, half the plan: its time counts


def test_step_holds_the_end_and_finishes_once_settled():
    plan = rest_to_rest()
    settings = StreamSettings(settle_messages=5)
    rows = drive(plan, settings)
    phases = [s.phase for _, _, s in rows]
    assert phases[-1] is Phase.DONE
    hold = [(t, r) for t, r, s in rows if s.phase in (Phase.HOLD, Phase.DONE)]
    for _, r in hold:
        np.testing.assert_allclose(r.q, plan.end)
        np.testing.assert_allclose(r.qd, 0.0)
    assert 1 <= phases.count(Phase.HOLD) <= 5


def test_step_is_pure():
    plan = rest_to_rest()
    settings = StreamSettings()
    state = PolicyState(phase=Phase.RUN, t0=10.0)
    robot = RobotState(t=10.3, q=plan.at(0.3)[0], running=True)
    a = step(plan, settings, state, robot)
    b = step(plan, settings, state, robot)
    np.testing.assert_array_equal(a[0].q, b[0].q)
    assert a[1] == b[1]
    assert state == PolicyState(phase=Phase.RUN, t0=10.0)


def test_step_refuses_ramp_in_from_away_from_the_start():
    plan = rest_to_rest()
    q0 = plan.start + np.radians([0, 0, 2.0, 0, 0, 0])
    rows = drive(plan, StreamSettings(), q0=q0)
    _, ref, state = rows[-1]
    assert state.phase is Phase.FAULT
    assert "joint 3" in state.fault and "from the path's start" in state.fault
    np.testing.assert_allclose(ref.q, q0)  # holds the robot where it is
    np.testing.assert_allclose(ref.qd, 0.0)
    for _, r, _ in rows:  # never a reference away from the robot
        assert np.max(np.abs(r.q - q0)) <= 1e-12


def test_step_waits_without_fault_while_not_running_away_from_start():
    plan = rest_to_rest()
    q0 = plan.start + np.radians([5.0, 0, 0, 0, 0, 0])
    ref, state = step(plan, StreamSettings(), PolicyState(), RobotState(t=1.0, q=q0, running=False))
    assert state.phase is Phase.WAIT
    np.testing.assert_allclose(ref.q, q0)


def test_step_never_commands_far_from_the_feedback():
    plan = rest_to_rest()
    settings = StreamSettings(max_step_deg=2.0)
    state = PolicyState(phase=Phase.RUN, t0=0.0)
    stuck = RobotState(t=0.5, q=plan.start, running=True)  # the robot did not follow
    ref, state = step(plan, settings, state, stuck)
    assert state.phase is Phase.FAULT and "more than 2 deg" in state.fault
    np.testing.assert_allclose(ref.q, plan.start)
    ref2, state2 = step(plan, settings, state, RobotState(t=0.504, q=plan.start, running=True))
    assert state2.phase is Phase.FAULT
    np.testing.assert_allclose(ref2.q, plan.start)


def test_step_run_cut_short_waits_and_counts_it():
    plan = rest_to_rest()
    state = PolicyState(phase=Phase.RUN, t0=0.0)
    q = plan.at(0.3)[0]
    ref, state = step(plan, StreamSettings(), state, RobotState(t=0.3, q=q, running=False))
    assert state.phase is Phase.WAIT and state.interrupted == 1
    np.testing.assert_allclose(ref.q, q)


def test_step_repeats_with_a_return_move_when_the_end_differs():
    plan = rest_to_rest()
    rows = drive(plan, StreamSettings(repeats=2), n=5000)
    phases = [s.phase for _, _, s in rows]
    assert phases[-1] is Phase.DONE and rows[-1][2].done == 2
    assert Phase.RETURN in phases
    ret = [(t, r, s) for t, r, s in rows if s.phase is Phase.RETURN and r.plan_time is None]
    t0 = ret[0][2].t0
    back = plan.reversed()
    for t, r, _ in ret:
        if t - t0 < back.duration:
            np.testing.assert_allclose(r.q, back.at(t - t0)[0])
    runs = [k for k in range(1, len(phases)) if phases[k] is Phase.RUN and phases[k - 1] is not Phase.RUN]
    assert len(runs) == 2


def test_step_repeats_a_closed_plan_without_return():
    plan = closed_plan()
    assert plan.closed
    rows = drive(plan, StreamSettings(repeats=3), n=5000)
    phases = [s.phase for _, _, s in rows]
    assert phases[-1] is Phase.DONE and rows[-1][2].done == 3
    assert Phase.RETURN not in phases


def test_step_hold_that_never_settles_is_a_fault():
    plan = rest_to_rest()
    settings = StreamSettings(max_hold_s=0.1)
    state = PolicyState(phase=Phase.HOLD, t0=1.0)
    short = plan.end + np.radians([0.5, 0, 0, 0, 0, 0])
    ref, state = step(plan, settings, state, RobotState(t=1.05, q=short, running=True))
    assert state.phase is Phase.HOLD
    ref, state = step(plan, settings, state, RobotState(t=1.2, q=short, running=True))
    assert state.phase is Phase.FAULT and "did not settle" in state.fault


@pytest.mark.parametrize(
    "kw",
    [
        {"repeats": 0},
        {"start_tolerance_deg": 0},
        {"end_tolerance_deg": 1.0, "start_tolerance_deg": 0.5},
        {"max_step_deg": 0.4},
        {"settle_messages": 0},
        {"ramp_in_s": -1},
        {"max_hold_s": math.nan},
    ],
)
def test_stream_settings_refuse_bad_values(kw):
    with pytest.raises(InvalidInput):
        StreamSettings(**kw)
