"""The single move's search on an arm with torque limits (issue 36, the Panda): effort rows enter a solve
only near their limits (``GradientSettings.effort_band``), and the settings the default search adds
(``MOVE_SEARCH``) stay out of the search before and the cycle.

The Panda is a named arm of example-robot-data (the [robots] extra): skipped when it is not installed.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import joulepath
from joulepath.errors import InvalidInput, MissingDependency
from joulepath.optimize import (
    ACCEL_TIME,
    GRID_SEARCH,
    JERK_TIME,
    MOVE_SEARCH,
    SEARCH_BEFORE_HULL,
    GradientSettings,
    OptimizeConfig,
    SplineProblem,
    acceleration_limit,
    check_limits,
    jerk_limit,
    solve_move,
)

Q0 = np.array([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0])
QF = np.array([1.0, 0.5, 0.5, -1.0, 0.5, 2.0, 0.5])


@pytest.fixture(scope="module")
def panda() -> joulepath.Robot:
    from joulepath.description import named_arm_path

    try:
        named_arm_path("panda")
    except MissingDependency:
        pytest.skip("example-robot-data (the [robots] extra) is not installed")
    return joulepath.load_robot("panda")


@pytest.fixture(scope="module")
def weak_panda(panda) -> joulepath.Robot:
    """The Panda with its second joint's torque limit 60 N·m (87): its default 2 s move peaks at 41 N·m
    there, its least-energy move with the limit of 87 N·m at 69 (the limit of 60 binds)."""
    from dataclasses import replace

    from joulepath.dynamics import Robot

    effort = panda.effort_limit
    effort[1] = 60.0
    return Robot(replace(panda.chain, effort=effort), description=panda.description, friction=panda.friction)


def _solve(panda, effort_band, monkeypatch):
    """The 2 s move on knots 0.1 s apart, and the effort rows each solve carried."""
    seen: list[int] = []
    original = SplineProblem.constraints

    def counting(self, active, change=None):
        seen.append(int(active.get("tau", np.empty(0)).size))
        return original(self, active, change)

    monkeypatch.setattr(SplineProblem, "constraints", counting)
    amax = acceleration_limit(panda, ACCEL_TIME)
    jmax = jerk_limit(panda, ACCEL_TIME, JERK_TIME)
    res, problem = solve_move(
        panda,
        Q0,
        QF,
        2.0,
        friction=panda.friction,
        settings=GradientSettings(knot_spacing=0.1, continuation=(0.3, 0.03), effort_band=effort_band),
        rng=np.random.default_rng(0),
        acceleration_limit=amax,
        jerk_limit=jmax,
    )
    monkeypatch.setattr(SplineProblem, "constraints", original)
    report = check_limits(
        panda,
        problem.path(res.coefficients.ravel(), fine=True),
        friction=panda.friction,
        acceleration_limit=amax,
        jerk_limit=jmax,
    )
    return res, problem, report, seen


def test_effort_rows_enter_only_near_their_limits_and_the_search_still_holds_every_limit(
    weak_panda, monkeypatch
):
    """A torque limit that binds: with an effort band the solves carry fewer effort rows (nonlinear: the
    dynamics' derivatives at each of their points at every step), and the result still holds every limit
    on the 10x grid (a row that breaks enters the next round), the torques included, saving as much as
    the search without the band (or more: here that one ends outside a limit in its rounds and keeps the
    default move)."""
    wide, _, wide_report, wide_rows = _solve(weak_panda, None, monkeypatch)
    narrow, problem, narrow_report, narrow_rows = _solve(weak_panda, 0.05, monkeypatch)
    x = narrow.coefficients.ravel()
    assert narrow.feasible and narrow_report.ok and wide_report.ok
    assert problem.violation(x) == 0.0  # the torques on the fine grid included
    assert problem.effort_slack(x).min() < 0.01 * 60.0  # the limit binds
    assert 0 < sum(narrow_rows) < sum(wide_rows)
    default = problem.true_energy(problem.origin)
    assert narrow.energy_J < 0.8 * default
    assert narrow.energy_J <= wide.energy_J + 0.005 * default


def test_the_effort_band_screens_torques_alone(panda):
    """``screen`` with an effort band: the same rows of every other kind, and of the effort rows those
    within the narrower band only (a subset of the rows the plain band takes)."""
    res, problem = solve_move(
        panda,
        Q0,
        QF,
        2.0,
        friction=panda.friction,
        settings=GradientSettings(knot_spacing=0.1, continuation=(0.3,), coarse_factor=1),
        rng=np.random.default_rng(0),
        acceleration_limit=acceleration_limit(panda, ACCEL_TIME),
        jerk_limit=jerk_limit(panda, ACCEL_TIME, JERK_TIME),
    )
    x = res.coefficients.ravel()
    plain = problem.screen(x, 0.25)
    banded = problem.screen(x, 0.25, 0.05)
    assert plain.keys() == banded.keys()
    for kind in plain.keys() - {"tau"}:
        np.testing.assert_array_equal(plain[kind], banded[kind])
    assert set(banded["tau"]) <= set(plain["tau"])
    slack = problem.effort_slack(x).ravel()
    limit = np.broadcast_to(problem.emax, problem.effort_slack(x).shape).ravel()
    np.testing.assert_array_equal(banded["tau"], np.flatnonzero(slack < 0.05 * limit))
    np.testing.assert_array_equal(plain["tau"], np.flatnonzero(slack < 0.25 * limit))
    np.testing.assert_array_equal(problem.screen(x, 0.03, 0.05)["tau"], np.flatnonzero(slack < 0.03 * limit))


@pytest.mark.parametrize("band", [0.0, -0.1, 1.5])
def test_an_effort_band_outside_0_1_is_refused(band):
    with pytest.raises(InvalidInput, match="effort_band"):
        GradientSettings(effort_band=band)


def test_the_default_search_adds_its_settings_and_the_yardstick_and_the_cycle_do_not(monkeypatch):
    """``gradient`` and ``gradient-fast`` run with ``MOVE_SEARCH``; ``gradient-grid`` (the search before),
    the plan for RAPID via points and the cycle's ``GRID_SEARCH`` keep the defaults (their plans stay as
    they were)."""
    import joulepath.optimize._search as search
    from joulepath.program import CycleSettings

    seen: dict[str, GradientSettings] = {}

    def capture(*args, settings, **kwargs):
        seen["settings"] = settings
        raise StopIteration

    monkeypatch.setattr(search, "solve_move", capture)
    task = search.SearchTask(
        robot=joulepath.load_robot("irb120"),
        q_start=np.zeros(6),
        q_end=np.full(6, 0.3),
        duration=1.0,
        acceleration_limit=np.full(6, np.inf),
        models=(),
        joints=(1, 2),
        dt=0.025,
    )
    runs = (
        ("gradient", OptimizeConfig(), MOVE_SEARCH),
        ("gradient-fast", OptimizeConfig(), MOVE_SEARCH),
        ("gradient-grid", OptimizeConfig(), {}),
        ("gradient", OptimizeConfig(follow="via-points"), {}),
    )
    for name, config, wanted in runs:
        with pytest.raises(StopIteration):
            search.ALGORITHMS[name].run(task, config, np.random.default_rng(0))
        defaults = GradientSettings()
        for key in MOVE_SEARCH:
            assert getattr(seen["settings"], key) == wanted.get(key, getattr(defaults, key)), (name, key)
    assert "effort_band" not in GRID_SEARCH and "effort_band" not in SEARCH_BEFORE_HULL
    cycle = CycleSettings().gradient
    assert cycle.effort_band is None and cycle == GradientSettings(**GRID_SEARCH)


def test_optimize_imports_neither_scikit_learn_nor_scipy_signal():
    """``joulepath optimize`` on the physics fitness: the learned models (scikit-learn) and SciPy's signal
    package (the lab plant's tracking filter, a log's corners) are imported where they are used, not
    with the command (1.2 s of the Panda's 2 s move's process)."""
    code = (
        "import sys\n"
        "from joulepath.cli._optimize import _models\n"
        "import joulepath.optimize, joulepath.export, joulepath.sim, joulepath.data\n"
        "assert _models(None, 'physics', '', 'panda', 7) == ((), None)\n"
        "heavy = ('sklearn', 'scipy.signal', 'scipy.stats', 'joulepath.learn')\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr
