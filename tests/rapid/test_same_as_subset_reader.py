"""Programs the earlier subset reader accepted give the same cycle through the interpreter: the same
steps, the same joint targets (to 1e-9 rad), speeds, zones, waits and motion settings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.program import parse_module, read_cycle_program, read_module, resolve_module
from joulepath.rapid import RapidError

ROOT = Path(__file__).parents[2]
PROGRAMS = sorted((ROOT / "examples").glob("*.mod")) + sorted(
    (ROOT / "tests" / "program" / "corpus").glob("*.mod")
)


@pytest.fixture(scope="module")
def robot():
    return joulepath.load_robot("irb120")


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_the_interpreter_reads_the_same_cycle(path, robot):
    try:
        old = resolve_module(read_module(path), robot)
    except RapidError:
        pytest.skip("the subset reader refuses it")
    new, _ = read_cycle_program(path, robot)
    assert [s.kind for s in new.steps] == [s.kind for s in old.steps]
    for a, b in zip(old.steps, new.steps, strict=True):
        assert a.line == b.line
        if a.kind == "move":
            assert np.abs(a.q - b.q).max() <= 1e-9
            assert (a.speed, a.time_s, a.zone_mm, a.linear, a.repeated) == (
                b.speed,
                b.time_s,
                b.zone_mm,
                b.linear,
                b.repeated,
            )
            assert (a.acc_pct, a.ramp_pct, a.vel_override_pct) == (b.acc_pct, b.ramp_pct, b.vel_override_pct)
            assert np.allclose(a.tcp, b.tcp)
            q, z = a.q[None, :], np.zeros((1, a.q.size))  # the same load: the same gravity torques
            assert np.allclose(a.robot.inverse_dynamics(q, z, z), b.robot.inverse_dynamics(q, z, z))
        elif a.kind == "wait":
            assert (a.seconds, a.idle) == (b.seconds, b.idle)
    # the via-point writer works on the same statements
    assert new.module is not None and new.module.source == parse_module("\n".join(new.module.source)).source


def test_most_of_them_are_compared():
    compared = 0
    robot = joulepath.load_robot("irb120")
    for path in PROGRAMS:
        try:
            resolve_module(read_module(path), robot)
            compared += 1
        except RapidError:
            pass
    assert compared >= 12
