"""Exporters: each one's files read back and compared with path.csv within the exported precision.

The path is a real optimized move (CMA-ES, few evaluations) written by ``write_run``;
the robots are the bundled IRB 120 and a 6-joint URDF arm named like a UR (a
"Universal Robots" arm for the registry) and a 7-joint one, so no extra is needed.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import CubicHermiteSpline

import joulepath
from joulepath.cli import main
from joulepath.errors import InvalidInput, LimitViolation
from joulepath.export import (
    EXPORTERS,
    declared_controller,
    get_exporter,
    refuse_foreign,
    render_rapid,
    render_ros2,
    render_urscript,
    select_exporter,
)
from joulepath.export._urscript import CB3_PERIOD, E_SERIES_PERIOD
from joulepath.optimize import OptimizeConfig, optimize_move, write_run
from joulepath.trajectory import minimum_jerk

LINK = (
    '<link name="l{i}"><inertial><mass value="{m}"/><origin xyz="0 0 0.1"/>'
    '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>'
)
JOINT = (
    '<joint name="{name}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>'
    '<origin xyz="0 0 0.15" rpy="{rpy}"/><axis xyz="0 0 1"/>'
    '<limit lower="-3" upper="3" effort="150" velocity="3"/></joint>'
)


def arm_urdf(path, name, n):
    """An n-joint serial arm; joints alternate their axes so that gravity loads them."""
    body = LINK.format(i=0, m=4.0)
    for i in range(1, n + 1):
        rpy = "1.5708 0 0" if i % 2 == 0 else "0 0 0"
        body += LINK.format(i=i, m=3.0 - 0.3 * i) + JOINT.format(name=f"joint_{i}", i=i, p=i - 1, rpy=rpy)
    path.write_text(f'<?xml version="1.0"?><robot name="{name}">{body}</robot>')
    return path


@pytest.fixture(scope="module")
def ur_like(tmp_path_factory):
    return joulepath.load_robot(arm_urdf(tmp_path_factory.mktemp("ur") / "ur5e.urdf", "ur5e", 6))


@pytest.fixture(scope="module")
def seven(tmp_path_factory):
    return joulepath.load_robot(arm_urdf(tmp_path_factory.mktemp("s") / "arm7.urdf", "arm7", 7))


def optimized_run(robot, folder, export):
    q0 = np.linspace(-0.4, 0.4, robot.n_joints)
    qf = -0.5 * q0 + 0.3
    config = OptimizeConfig(algorithm="cmaes", evaluations=120, accel_time=0.0, seed=1)
    result = optimize_move(robot, q0, qf, 1.5, config)
    assert result.summary.limits_ok
    files = write_run(result, robot, folder, export=export)
    path = pd.read_csv(folder / "path.csv")
    return result, files, path


def columns(path, prefix, n):
    return path[[f"{prefix}{i}" for i in range(1, n + 1)]].to_numpy()


# --------------------------------------------------------------------------- registry


def test_registry_names_files_and_declared_controllers(irb120, ur_like, seven):
    assert set(EXPORTERS) >= {"rapid", "urscript", "urscript-cb3", "ros2"}
    assert get_exporter("ros2").files == ("trajectory.yaml", "trajectory.csv")
    with pytest.raises(InvalidInput, match="unknown exporter 'kuka'; use one of"):
        get_exporter("kuka")
    assert declared_controller(irb120) == "rapid"
    assert declared_controller(ur_like) == "urscript"
    assert declared_controller(seven) == "ros2"


def test_foreign_controller_needs_explicit_name_and_warns(irb120, ur_like):
    exporter, warning = select_exporter(ur_like, "rapid")
    assert exporter.name == "rapid" and "writes programs for ABB controllers" in warning
    assert "--export urscript" in warning
    assert select_exporter(irb120, None) == (get_exporter("rapid"), None)
    assert select_exporter(ur_like, "ros2")[1] is None  # vendor-neutral
    with pytest.raises(InvalidInput, match="pass --export rapid to write rapid programs for it anyway"):
        refuse_foreign(ur_like, "rapid", explicit=False)
    assert "ABB" in refuse_foreign(ur_like, "rapid", explicit=True)


# --------------------------------------------------------------------------- read back


def test_rapid_path_mod_reads_back_to_path_csv(irb120, tmp_path):
    result, files, path = optimized_run(irb120, tmp_path, None)
    assert "path.mod" in files
    summary = json.loads((tmp_path / "result.json").read_text())
    assert (
        summary["export"] == "rapid" and summary["program"] == ["path.mod"] and summary["rapid"] == "path.mod"
    )
    text = (tmp_path / "path.mod").read_text()
    q_deg = np.degrees(columns(path, "q", 6))
    targets = re.findall(r"\[\[([-\d., ]+)\], \[[^\]]+\]\]", text.split("CONST jointtarget OPT")[1])
    opt = np.array([[float(v) for v in t.split(",")] for t in targets])
    times = re.search(r"OPT_T\{\d+\} := \[(.*?)\];", text, re.S).group(1)
    seg = np.array([float(v) for v in times.replace("\n", " ").split(",")])
    assert seg.sum() == pytest.approx(1.5, abs=1e-3)
    assert len(seg) == len(opt) == summary["executed_via_points"]
    # every via point is the planned path's sample at the via point's time (laid out by sim.follow_path)
    idx = np.round(np.cumsum(seg) / 0.025).astype(int)
    assert np.all(np.diff(idx) > 0) and idx[-1] == len(path) - 1
    np.testing.assert_allclose(opt, q_deg[idx], atol=5e-5 + 1e-9)  # 4 decimals of a degree
    start = re.search(r"CONST jointtarget START := \[\[([-\d., ]+)\]", text).group(1)
    np.testing.assert_allclose([float(v) for v in start.split(",")], q_deg[0], atol=5e-5 + 1e-9)


@pytest.mark.parametrize(("name", "period"), [("urscript", E_SERIES_PERIOD), ("urscript-cb3", CB3_PERIOD)])
def test_urscript_reads_back_to_path_csv(ur_like, tmp_path, name, period):
    result, files, path = optimized_run(ur_like, tmp_path, name)
    assert "path.script" in files and "path.mod" not in files
    text = (tmp_path / "path.script").read_text()
    rows = re.findall(r"servoj\(\[([^\]]+)\], 0, 0, ([\d.]+), 0\.1, 300\)", text)
    targets = np.array([[float(v) for v in r[0].split(",")] for r in rows])
    assert {float(r[1]) for r in rows} == {period}
    t = path["t"].to_numpy()
    q, qd = columns(path, "q", 6), columns(path, "qd", 6)
    times = np.minimum(np.arange(1, len(rows) + 1) * period, t[-1])
    assert len(rows) == int(np.ceil(t[-1] / period - 1e-9))
    expected = CubicHermiteSpline(t, q, qd, axis=0)(times)
    np.testing.assert_allclose(targets, expected, atol=5e-7 + 1e-8)  # 6 decimals of a radian
    on_sample = np.isclose(times / 0.025, np.round(times / 0.025), atol=1e-9)
    k = np.round(times[on_sample] / 0.025).astype(int)
    np.testing.assert_allclose(targets[on_sample], q[k], atol=5e-7 + 1e-8)  # exact at the 40 Hz samples
    start = re.search(r"start_q = \[([^\]]+)\]", text).group(1)
    np.testing.assert_allclose([float(v) for v in start.split(",")], q[0], atol=5e-7)
    assert text.index("movej(start_q") < text.index("servoj(")


def test_ros2_yaml_and_csv_read_back_to_path_csv(seven, tmp_path):
    yaml = pytest.importorskip("yaml")
    result, files, path = optimized_run(seven, tmp_path, None)  # a 7-joint arm declares ROS 2
    assert {"trajectory.yaml", "trajectory.csv"} <= set(files)
    goal = yaml.safe_load((tmp_path / "trajectory.yaml").read_text())
    traj = goal["trajectory"]
    assert traj["joint_names"] == list(seven.joint_names)
    points = traj["points"]
    assert len(points) == len(path)
    for key, prefix in (("positions", "q"), ("velocities", "qd"), ("accelerations", "qdd")):
        got = np.array([p[key] for p in points])
        np.testing.assert_allclose(got, columns(path, prefix, 7), rtol=1e-9, atol=1e-9)
    t = np.array([p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"] for p in points])
    np.testing.assert_allclose(t, path["t"].to_numpy(), atol=1e-9)
    assert all(0 <= p["time_from_start"]["nanosec"] < 10**9 for p in points)
    table = pd.read_csv(tmp_path / "trajectory.csv")
    names = [f"{n}_position" for n in seven.joint_names]
    np.testing.assert_allclose(table[names].to_numpy(), columns(path, "q", 7), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(table["time_from_start_s"], path["t"], atol=1e-9)


# --------------------------------------------------------------------------- refusals


def test_every_exporter_refuses_a_path_outside_the_limits(irb120, ur_like, seven):
    for robot, render in ((irb120, render_rapid), (ur_like, render_urscript), (seven, render_ros2)):
        hi = robot.upper
        q0 = np.zeros(robot.n_joints)
        bad = minimum_jerk(q0, hi + 0.2, 2.0)
        with pytest.raises(LimitViolation, match="is not written"):
            render(robot, bad, 2.0)
        fast = minimum_jerk(q0, np.full(robot.n_joints, 0.5), 0.05)
        with pytest.raises(LimitViolation, match="exceeds its limit"):
            render(robot, fast, 0.05)


def test_controller_programs_refuse_arms_of_other_joint_counts(seven):
    path = minimum_jerk(np.zeros(7), np.full(7, 0.2), 1.0)
    with pytest.raises(InvalidInput, match="RAPID jointtargets drive 6-axis arms"):
        render_rapid(seven, path, 1.0)
    with pytest.raises(InvalidInput, match="URScript drives 6-joint"):
        render_urscript(seven, path, 1.0)


def test_refused_program_leaves_no_program_of_any_exporter(ur_like, tmp_path):
    from dataclasses import replace

    result, files, _ = optimized_run(ur_like, tmp_path, "ros2")
    assert (tmp_path / "trajectory.yaml").exists()
    (tmp_path / "path.script").write_text("old")
    broken = replace(
        result, summary=replace(result.summary, limits_ok=False, limit_excess=("joint 1 range",))
    )
    write_run(broken, ur_like, tmp_path, export="ros2")
    assert not any((tmp_path / f).exists() for f in ("trajectory.yaml", "trajectory.csv", "path.script"))
    summary = json.loads((tmp_path / "result.json").read_text())
    assert summary["program"] is None and "violates a limit" in summary["program_refused"]


# --------------------------------------------------------------------------- CLI


def test_cli_rapid_collect_for_a_ur_needs_export_rapid(ur_like, tmp_path, capsys):
    urdf = ur_like.source
    out = tmp_path / "collect"
    assert (
        main(["rapid", "collect", "--robot", urdf, "--out", str(out), "--moves", "3", "--mode", "table"]) == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pass --export rapid" in err[0] and not out.exists()
    args = ["rapid", "collect", "--robot", urdf, "--out", str(out), "--moves", "3", "--mode", "table"]
    assert main([*args, "--export", "rapid"]) == 0
    captured = capsys.readouterr()
    assert "warning: rapid writes programs for ABB controllers" in captured.err
    assert "has no 'collection' range set; the moves use its nominal ranges" in captured.out
    assert (out / "JPCollect.mod").is_file()


def test_cli_optimize_writes_the_declared_controller_or_the_one_asked(ur_like, tmp_path, capsys):
    base = [
        "optimize",
        "--robot",
        ur_like.source,
        "--start",
        "0,0.2,-0.2,0.3,0,0",
        "--end",
        "0.5,-0.3,0.4,0,0.3,0.2",
    ]
    base += ["--duration", "1.5", "--algo", "cmaes"]
    assert main([*base, "--out", str(tmp_path / "a")]) == 0
    assert (tmp_path / "a" / "path.script").is_file() and not (tmp_path / "a" / "path.mod").exists()
    assert "no friction modelled for ur5e" in capsys.readouterr().out
    assert main([*base, "--export", "rapid", "--out", str(tmp_path / "b")]) == 0
    assert "writes programs for ABB controllers" in capsys.readouterr().err
    summary = json.loads((tmp_path / "b" / "result.json").read_text())
    assert summary["export"] == "rapid" and "ABB" in summary["export_warning"]
    assert (tmp_path / "b" / "path.mod").is_file()
    assert main([*base, "--export", "fanuc", "--out", str(tmp_path / "c")]) == 2
    assert "unknown exporter 'fanuc'" in capsys.readouterr().err
