"""Reading and validating joint logs: every malformed case gives one clear error."""

import numpy as np
import pytest

from joulepath.data import LOG_COLUMNS, read_log
from joulepath.errors import InvalidLog
from joulepath.sim import simulate


@pytest.fixture(scope="module")
def sim_log(tmp_path_factory):
    out = tmp_path_factory.mktemp("logs") / "sim.csv"
    return simulate(out, plant="sim", n_moves=6, seed=11).log


def _lines(path):
    return path.read_text().splitlines()


def _write(tmp_path, lines, name="bad.csv"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


def test_read_log_controller_units(sim_log):
    log = read_log(sim_log)
    assert log.kind == "controller" and log.n_rows > 100
    raw = np.loadtxt(sim_log, delimiter=",", skiprows=1)
    np.testing.assert_allclose(log.q[:, 0], np.radians(raw[:, 1]))
    np.testing.assert_allclose(log.tcp_position[:, 0], raw[:, 19] / 1000)
    np.testing.assert_allclose(log.tcp_euler[:, 0], np.radians(raw[:, 28]))  # phi: about Z
    assert np.all(np.diff(log.t) > 0)


def test_read_log_empty(tmp_path):
    p = tmp_path / "empty.csv"
    p.write_text("")
    with pytest.raises(InvalidLog, match=r"empty\.csv: is empty; a log starts with a header"):
        read_log(p)


def test_read_log_header_only(tmp_path):
    with pytest.raises(InvalidLog, match="has a header but no data lines"):
        read_log(_write(tmp_path, [",".join(LOG_COLUMNS)]))


def test_read_log_wrong_header(tmp_path, sim_log):
    lines = _lines(sim_log)
    lines[0] = lines[0].replace("tau3", "torque3")
    with pytest.raises(
        InvalidLog,
        match=r"line 1: not the controller log header \(field 10 is 'torque3', expected 'tau3'\)",
    ):
        read_log(_write(tmp_path, lines))


def test_read_log_generic_header_missing_columns(tmp_path):
    with pytest.raises(InvalidLog, match=r"line 1: header lacks column\(s\) tau1"):
        read_log(_write(tmp_path, ["t,q1,dq1", "0,0,0"]))


def test_read_log_truncated_last_line(tmp_path, sim_log):
    lines = _lines(sim_log)[:40]
    lines[-1] = ",".join(lines[-1].split(",")[:17])
    with pytest.raises(InvalidLog, match=r"line 40: 17 fields instead of 29 \(the file is truncated"):
        read_log(_write(tmp_path, lines))


def test_read_log_not_a_number(tmp_path, sim_log):
    lines = _lines(sim_log)[:30]
    fields = lines[12].split(",")
    fields[4] = "12.3a"
    lines[12] = ",".join(fields)
    with pytest.raises(InvalidLog, match=r"bad\.csv: line 13, field q2: '12\.3a' is not a number"):
        read_log(_write(tmp_path, lines))


def test_read_log_nan(tmp_path, sim_log):
    lines = _lines(sim_log)[:30]
    fields = lines[7].split(",")
    fields[3] = "nan"
    lines[7] = ",".join(fields)
    with pytest.raises(InvalidLog, match=r"line 8, field tau1: nan is not a finite number"):
        read_log(_write(tmp_path, lines))


def test_read_log_non_monotonic_time(tmp_path, sim_log):
    lines = _lines(sim_log)[:30]
    lines[10], lines[11] = lines[11], lines[10]
    with pytest.raises(InvalidLog, match=r"line 12: t = [\d.]+ s does not increase \(line 11"):
        read_log(_write(tmp_path, lines))


def test_read_log_duplicated_rows(tmp_path, sim_log):
    lines = _lines(sim_log)[:30]
    lines.insert(9, lines[8])
    with pytest.raises(InvalidLog, match=r"line 10 duplicates line 9.*delete the duplicated lines"):
        read_log(_write(tmp_path, lines))


def test_read_log_radians_in_a_degree_log(tmp_path, sim_log):
    raw = np.loadtxt(sim_log, delimiter=",", skiprows=1)
    raw[:, 7] = np.radians(raw[:, 7])  # q3 written in rad
    lines = [",".join(LOG_COLUMNS)] + [",".join(f"{v:.5f}" for v in row) for row in raw]
    with pytest.raises(InvalidLog, match=r"column q3 looks like radians next to dq3 in degrees/s"):
        read_log(_write(tmp_path, lines))


def test_read_log_generic_degrees_in_a_radian_log(tmp_path):
    t = np.arange(200) * 0.01
    q = np.sin(t)[:, None] * np.ones(6)
    qd = np.cos(t)[:, None] * np.ones(6)
    q[:, 1] = np.degrees(q[:, 1])
    header = "t," + ",".join(f"q{i},dq{i},tau{i}" for i in range(1, 7))
    rows = [f"{t[k]}," + ",".join(f"{q[k, j]},{qd[k, j]},1.0" for j in range(6)) for k in range(200)]
    with pytest.raises(InvalidLog, match=r"column q2 looks like degrees next to dq2 in rad/s"):
        read_log(_write(tmp_path, [header, *rows], "generic.csv"))


def test_read_log_generic_any_column_order(tmp_path):
    t = np.arange(50) * 0.004
    cols = {"t": t}
    for i in range(1, 7):
        cols[f"tau{i}"] = np.full(50, float(i))
        cols[f"dq{i}"] = np.full(50, 0.5)
        cols[f"q{i}"] = 0.5 * t
    cols["move"] = np.repeat([3, 7], 25)
    names = list(cols)[::-1]
    rows = [",".join(str(cols[n][k]) for n in names) for k in range(50)]
    log = read_log(_write(tmp_path, [",".join(names), *rows], "g.csv"))
    assert log.kind == "generic" and log.qdd is None
    np.testing.assert_allclose(log.tau[0], np.arange(1, 7))
    np.testing.assert_array_equal(np.unique(log.move), [3, 7])


# --------------------------------------------------------------------------- motor currents


@pytest.fixture(scope="module")
def current_signals(sim_log):
    log = read_log(sim_log)
    current = log.tau / np.array([1.2, 1.5, 0.8, 0.3, 0.3, 0.2])  # any joint-side torque constants
    return log.t, log.q, log.qd, log.tau, current


def test_read_log_currents_only(tmp_path, current_signals):
    from joulepath.data import generic_log_text

    t, q, qd, _, current = current_signals
    p = tmp_path / "i.csv"
    p.write_text(generic_log_text(t, q, qd, None, current=current))
    log = read_log(p)
    assert log.kind == "generic" and log.tau is None
    np.testing.assert_allclose(log.current, current, rtol=1e-9, atol=1e-12)
    with pytest.raises(InvalidLog, match=r"i\.csv: logs motor currents \(i1\.\.i6\) but no joint torques"):
        log.torques("ingestion")


def test_read_log_torques_and_currents(tmp_path, current_signals):
    from joulepath.data import generic_log_text

    t, q, qd, tau, current = current_signals
    p = tmp_path / "both.csv"
    p.write_text(generic_log_text(t, q, qd, tau, current=current))
    log = read_log(p)
    np.testing.assert_allclose(log.torques("a test"), tau, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(log.current, current, rtol=1e-9, atol=1e-12)


def test_ingest_refuses_a_log_of_currents_only(tmp_path, current_signals):
    from joulepath.data import generic_log_text, ingest

    t, q, qd, _, current = current_signals
    p = tmp_path / "i.csv"
    p.write_text(generic_log_text(t, q, qd, None, current=current))
    with pytest.raises(InvalidLog, match="ingestion .* needs the torques tau1..tau6"):
        ingest([p])


@pytest.mark.parametrize(
    ("edit", "pattern"),
    [
        (lambda h: h.replace(",i6", ",x6"), r"lacks column\(s\) i6 of a 6-joint log"),
        (lambda h: h.replace(",tau3", ",torque3"), r"lacks column\(s\) tau3 of a 6-joint log"),
        (lambda h: h + ",i8", r"column\(s\) i8 name joint\(s\) 8"),
    ],
)
def test_read_log_current_columns_come_for_every_joint(tmp_path, current_signals, edit, pattern):
    from joulepath.data import generic_log_text

    t, q, qd, tau, current = current_signals
    lines = generic_log_text(t[:50], q[:50], qd[:50], tau[:50], current=current[:50]).splitlines()
    extra = lines[0] != edit(lines[0]) and edit(lines[0]).endswith(",i8")
    lines[0] = edit(lines[0])
    if extra:
        lines[1:] = [line + ",0" for line in lines[1:]]
    with pytest.raises(InvalidLog, match=pattern):
        read_log(_write(tmp_path, lines))


def test_read_log_currents_in_milliamperes_refused(tmp_path, current_signals):
    from joulepath.data import generic_log_text

    t, q, qd, _, current = current_signals
    p = tmp_path / "ma.csv"
    p.write_text(generic_log_text(t, q, qd, None, current=current * 1000 + 2000))
    with pytest.raises(InvalidLog, match=r"column i1 reaches .*, more than 1000 A.*in mA"):
        read_log(p)
