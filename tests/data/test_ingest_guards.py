"""Ingest guards (issue 15, item 5): logs that would corrupt the energies are refused or split.

Each case is written as a user would make it (a simulated controller log turned into a
generic CSV, then spoiled one way); the CLI cases check exit code 2, one line on
stderr naming the file (and line where there is one), and that no table is written.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from joulepath.cli import main
from joulepath.data import find_gaps, ingest, is_moves_sidecar, moves_sidecar_path, read_log
from joulepath.errors import InvalidInput, InvalidLog
from joulepath.sim import simulate


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A 4-move lab log (controller CSV) and its sidecar."""
    return simulate(tmp_path_factory.mktemp("lab") / "lab.csv", plant="lab", n_moves=4, seed=1)


@pytest.fixture(scope="module")
def signals(lab):
    log = read_log(lab.log)
    return log.t, log.q, log.qd, log.tau


def _generic(path: Path, t, q, qd, tau, **extra) -> Path:
    cols = ["t"] + [f"{p}{i}" for i in range(1, 7) for p in ("q", "dq", "tau")]
    data = [t] + [a[:, i] for i in range(6) for a in (q, qd, tau)]
    for name, values in extra.items():
        cols.append(name)
        data.append(values)
    np.savetxt(path, np.column_stack(data), delimiter=",", header=",".join(cols), comments="", fmt="%.9g")
    return path


def _refused(capsys, args, fragment, out):
    """Run the CLI; expect exit 2, one stderr line holding ``fragment``, and no ``out``."""
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err and fragment in err, err
    assert not out.exists()
    return err


# --------------------------------------------------------------------------- sample period


def test_find_gaps_marks_steps_over_twice_the_median():
    t = np.array([0.0, 0.025, 0.05, 0.075, 3600.0, 3600.025, 3600.05, 3600.101])
    assert find_gaps(t).tolist() == [4, 7]  # 0.051 s > 2 x 0.025 s is a gap too
    assert find_gaps(np.arange(10) * 0.025).size == 0
    assert find_gaps(np.array([0.0, 1.0])).size == 0


def test_ingest_one_hour_gap_splits_the_move_and_keeps_the_energy(tmp_path, signals, irb120):
    t, q, qd, tau = signals
    plain = ingest([_generic(tmp_path / "plain.csv", t, q, qd, tau)], robot=irb120)
    cut = len(t) // 2
    assert np.abs(qd[cut]).max() > 0.1  # the gap falls inside a move
    t_gap = t.copy()
    t_gap[cut:] += 3600.0
    notes: list[str] = []
    gap = ingest([_generic(tmp_path / "gap.csv", t_gap, q, qd, tau)], robot=irb120, progress=notes.append)
    # before the guard: one row with dt = 3600 s and E ~ 50x too large
    assert gap.frame["dt"].max() < 0.05
    assert gap.frame["E"].sum() == pytest.approx(plain.frame["E"].sum(), rel=0.01)
    assert gap.n_moves == plain.n_moves + 1
    assert any(f"line {cut + 2}" in n and "gap" in n for n in notes), notes
    assert gap.sources[0]["gaps"] == 1


def test_ingest_gap_splits_a_labelled_generic_move(tmp_path, signals):
    t, q, qd, tau = signals
    t_gap = t.copy()
    t_gap[20:] += 60.0
    table = ingest([_generic(tmp_path / "m.csv", t_gap, q, qd, tau, move=np.zeros(t.size))])
    assert table.n_moves == 2 and table.frame["dt"].max() < 0.05


# --------------------------------------------------------------------------- units


def test_read_log_time_in_milliseconds(tmp_path, signals):
    t, q, qd, tau = signals
    p = _generic(tmp_path / "ms.csv", t * 1000, q, qd, tau)
    with pytest.raises(InvalidLog, match=r"ms\.csv: column t advances 2\d\.\d+ per sample.*milliseconds"):
        read_log(p)


def test_read_log_fast_log_in_milliseconds_caught_by_speeds(tmp_path, signals):
    """A 2 kHz log in ms has a median 'period' of 0.5: the speeds give it away (x1000)."""
    t, q, qd, tau = signals
    fast = t / 50.0  # the same motion 50x faster: speeds x50, period about 0.5 ms
    p = _generic(tmp_path / "ms2k.csv", fast * 1000, q, qd * 50.0, tau)
    with pytest.raises(InvalidLog, match=r"about (999|1000|1001) times the rate.*milliseconds"):
        read_log(p)


def test_ingest_small_motion_in_degrees_refused_with_robot(tmp_path, signals, irb120, capsys):
    """q and dq both in degrees on a small motion: consistent with each other, below 4 pi,
    so only the robot's range and speed limits reveal them (q3 outside its range)."""
    t, q, qd, tau = signals
    q_small, qd_small = q * 0.02, qd * 0.02
    q_small[:, 2] += np.radians(1.0)  # keep q3 away from 0 so its degree value leaves the range
    p = _generic(tmp_path / "deg.csv", t, np.degrees(q_small), np.degrees(qd_small), tau)
    assert np.abs(np.degrees(q_small)).max() < 4 * np.pi  # the log-only check cannot see it
    read_log(p)  # accepted without a robot
    with pytest.raises(InvalidLog, match=r"deg\.csv: line \d+: q\d = .* is outside IRB 120's range"):
        ingest([p], robot=irb120)
    out = tmp_path / "deg.parquet"
    err = _refused(
        capsys, ["ingest", str(p), "--out", str(out), "--robot", "irb120"], "degrees in q and dq", out
    )
    assert "deg.csv: line " in err


def test_ingest_speed_far_over_the_limit_refused(tmp_path, signals, irb120):
    t, q, qd, tau = signals
    fast = qd.copy()
    fast[:, 5] *= 3.0  # consistent speeds are not checked against q here: the limit is
    p = _generic(tmp_path / "fast.csv", t, q, fast, tau)
    with pytest.raises(InvalidLog, match=r"dq6 = .* times IRB 120's speed limit"):
        ingest([p], robot=irb120)


def test_ingest_refuses_a_robot_of_another_joint_count(tmp_path, signals):
    class Seven:
        name = "seven"
        n_joints = 7

    t, q, qd, tau = signals
    p = _generic(tmp_path / "g.csv", t, q, qd, tau)
    with pytest.raises(InvalidInput, match="logs 6 joints, but robot 'seven' has 7"):
        ingest([p], robot=Seven())  # type: ignore[arg-type]


# --------------------------------------------------------------------------- joint count


@pytest.mark.parametrize("extra", [("q8", "dq8", "tau8"), ("q0",), ("ddq9",)])
def test_read_log_unexpected_joint_columns_refused(tmp_path, signals, extra):
    t, q, qd, tau = signals
    p = _generic(tmp_path / "j.csv", t, q, qd, tau, **{c: q[:, 0] for c in extra})
    with pytest.raises(InvalidLog, match=rf"j\.csv: line 1: column\(s\) {', '.join(extra)} name joint"):
        read_log(p)


def test_cli_eight_joint_log_refused(tmp_path, signals, capsys):
    t, q, qd, tau = signals
    extra = {f"{p}{i}": s[:, 0] for i in (7, 8) for p, s in (("q", q), ("dq", qd), ("tau", tau))}
    p = _generic(tmp_path / "j8.csv", t, q, qd, tau, **extra)
    out = tmp_path / "j8.parquet"
    _refused(capsys, ["ingest", str(p), "--out", str(out)], "arms of 5 to 7 joints", out)


def test_seven_joint_log_missing_a_column_refused(tmp_path, signals):
    t, q, qd, tau = signals
    p = _generic(tmp_path / "j7.csv", t, q, qd, tau, q7=q[:, 0], dq7=qd[:, 0])
    with pytest.raises(InvalidLog, match=r"header lacks column\(s\) tau7 of a 7-joint log"):
        read_log(p)


# --------------------------------------------------------------------------- empty results


@pytest.mark.parametrize("n_rows", [1, 2])
def test_cli_one_and_two_row_logs_refused(tmp_path, signals, capsys, n_rows):
    t, q, qd, tau = signals
    p = _generic(tmp_path / "short.csv", t[:n_rows], q[:n_rows], qd[:n_rows], tau[:n_rows])
    out = tmp_path / "short.parquet"
    _refused(capsys, ["ingest", str(p), "--out", str(out)], f"has only {n_rows} data line(s)", out)


def test_cli_controller_log_of_two_rows_refused(tmp_path, lab, capsys):
    lines = lab.log.read_text().splitlines()
    p = tmp_path / "two.csv"
    p.write_text("\n".join(lines[:3]) + "\n")
    out = tmp_path / "two.parquet"
    _refused(
        capsys, ["ingest", str(p), "--out", str(out), "--robot", "irb120"], "has only 2 data line(s)", out
    )


def test_cli_motionless_log_refused(tmp_path, signals, capsys):
    t, _, _, tau = signals
    n = 50
    p = _generic(tmp_path / "still.csv", t[:n], np.full((n, 6), 0.1), np.zeros((n, 6)), tau[:n])
    out = tmp_path / "still.parquet"
    _refused(capsys, ["ingest", str(p), "--out", str(out)], "still.csv: no motion", out)


def test_ingest_motionless_file_among_others_is_named(tmp_path, signals, lab):
    t, _, _, tau = signals
    still = _generic(tmp_path / "still.csv", t[:30], np.zeros((30, 6)), np.zeros((30, 6)), tau[:30])
    with pytest.raises(InvalidLog, match=r"still\.csv: no motion"):
        ingest([lab.log, still])


# --------------------------------------------------------------------------- bytes


def test_cli_non_utf8_bytes_named_with_line_and_offset(tmp_path, signals, capsys):
    t, q, qd, tau = signals
    good = _generic(tmp_path / "g.csv", t, q, qd, tau).read_bytes().split(b"\n")
    offset = sum(len(line) + 1 for line in good[:5]) + 10
    good[5] = good[5][:10] + b"\xff" + good[5][10:]
    p = tmp_path / "latin.csv"
    p.write_bytes(b"\n".join(good))
    out = tmp_path / "latin.parquet"
    _refused(
        capsys,
        ["ingest", str(p), "--out", str(out)],
        f"latin.csv: line 6 (byte offset {offset}): byte 0xff",
        out,
    )


def test_read_log_non_utf8_header(tmp_path):
    p = tmp_path / "h.csv"
    p.write_bytes(b"t,q1\xe9\n0,1\n")
    with pytest.raises(InvalidLog, match=r"h\.csv: line 1 \(byte offset 4\): byte 0xe9 is not UTF-8"):
        read_log(p)


def test_read_log_non_utf8_after_the_header_is_not_blamed_on_line_1(tmp_path, lab):
    data = lab.log.read_bytes().split(b"\n")
    data[3] = b"\x80" + data[3]
    p = tmp_path / "l3.csv"
    p.write_bytes(b"\n".join(data))
    with pytest.raises(InvalidLog, match=r"line 4 \(byte offset \d+\): byte 0x80"):
        read_log(p)


# --------------------------------------------------------------------------- simulate's sidecar


def test_moves_sidecar_recognized(lab):
    assert lab.moves == moves_sidecar_path(lab.log) and lab.moves.name == "lab.moves.csv"
    assert is_moves_sidecar(lab.moves) and not is_moves_sidecar(lab.log)
    with pytest.raises(InvalidLog, match="programmed moves that `joulepath simulate` writes"):
        read_log(lab.moves)


def test_cli_ingest_glob_after_simulate_skips_the_sidecar(tmp_path, capsys):
    logs = tmp_path / "logs"
    assert main(["simulate", "--moves", "3", "--seed", "2", "--out", str(logs)]) == 0
    files = sorted(str(p) for p in logs.glob("*.csv"))
    assert len(files) == 2  # lab-2.csv and lab-2.moves.csv
    capsys.readouterr()
    out = tmp_path / "t.parquet"
    assert main(["ingest", *files, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "skipped" in printed and "lab-2.moves.csv" in printed
    assert out.exists()


def test_cli_ingest_only_sidecars_refused(tmp_path, lab, capsys):
    out = tmp_path / "t.parquet"
    _refused(capsys, ["ingest", str(lab.moves), "--out", str(out)], "no joint logs among the 1 file(s)", out)


# --------------------------------------------------------------------------- inputs that are not files


def test_read_log_refuses_a_fifo_without_blocking(tmp_path):
    import os

    fifo = tmp_path / "live.csv"
    os.mkfifo(fifo)  # opening it for reading would wait for a writer forever
    assert not is_moves_sidecar(fifo)
    with pytest.raises(InvalidLog, match=r"live\.csv: is a FIFO \(named pipe\), not a regular file"):
        read_log(fifo)


def test_read_log_refuses_a_folder(tmp_path):
    with pytest.raises(InvalidLog, match=r"is a folder, not a log; give the log files in it"):
        read_log(tmp_path)


def test_read_log_stray_carriage_return_is_one_error(tmp_path, lab):
    """Found by fuzzing: a lone \\r inside a line made the line-by-line pass raise csv.Error."""
    data = lab.log.read_bytes().split(b"\n")
    data[4] = data[4][:12] + b"\r" + data[4][12:]
    p = tmp_path / "cr.csv"
    p.write_bytes(b"\n".join(data))
    with pytest.raises(InvalidLog, match=r"cr\.csv: line 5: not a CSV line"):
        read_log(p)


# --------------------------------------------------------------------------- damaged energy tables


@pytest.fixture(scope="module")
def table_file(lab, tmp_path_factory):
    from joulepath.data import save_table

    return save_table(ingest([lab.log]), tmp_path_factory.mktemp("table") / "t.parquet")


@pytest.mark.parametrize(
    ("meta", "fragment"),
    [
        (b"not json", "metadata is not valid JSON"),
        (b"\xff", "metadata is not valid JSON"),
        (b"[1, 2]", "metadata is a JSON list, not an object"),
        (b'{"feature_set": ["joint"]}', "unknown feature set ['joint']"),
        (b'{"feature_set": "joint", "sources": 5}', "sources are not a list of objects"),
        (b'{"feature_set": "joint", "robot": 7}', "names the robot as 7"),
    ],
)
def test_load_table_damaged_metadata_is_one_error(tmp_path, table_file, meta, fragment):
    import pyarrow.parquet as pq

    from joulepath.data import load_table

    arrow = pq.read_table(table_file)
    p = tmp_path / "bad.parquet"
    pq.write_table(arrow.replace_schema_metadata({**arrow.schema.metadata, b"joulepath": meta}), p)
    with pytest.raises(InvalidLog, match=re.escape(fragment)):
        load_table(p)


def test_load_table_nan_and_text_columns_refused(tmp_path, table_file):
    import pyarrow as pa
    import pyarrow.parquet as pq

    from joulepath.data import load_table

    arrow = pq.read_table(table_file)
    frame = arrow.to_pandas()
    for name, change, fragment in (
        (
            "nan",
            lambda f: f.assign(E=np.where(np.arange(len(f)) < 3, np.nan, f["E"])),
            "column(s) E (3 rows)",
        ),
        ("text", lambda f: f.assign(q1="abc"), "column(s) q1 do not hold numbers"),
    ):
        p = tmp_path / f"{name}.parquet"
        spoiled = pa.Table.from_pandas(change(frame), preserve_index=False)
        pq.write_table(spoiled.replace_schema_metadata(arrow.schema.metadata), p)
        with pytest.raises(InvalidLog, match=re.escape(fragment)):
            load_table(p)


def test_load_table_flipped_bytes_never_escape_as_other_errors(tmp_path, table_file):
    """Damaged files (one byte changed anywhere) load or raise InvalidLog, nothing else."""
    from joulepath.data import load_table
    from joulepath.errors import JoulepathError

    data = table_file.read_bytes()
    rng = np.random.default_rng(0)
    for k in range(200):  # the unguarded reader let 3 of these 200 escape as other errors
        b = bytearray(data)
        b[int(rng.integers(len(b)))] = int(rng.integers(256))
        p = tmp_path / f"f{k}.parquet"
        p.write_bytes(bytes(b))
        try:
            load_table(p)
        except JoulepathError:
            pass


# --------------------------------------------------------------------------- the same, as a user runs them


def test_cli_time_in_milliseconds_refused(tmp_path, signals, capsys):
    t, q, qd, tau = signals
    p = _generic(tmp_path / "ms.csv", t * 1000, q, qd, tau)
    out = tmp_path / "ms.parquet"
    _refused(capsys, ["ingest", str(p), "--out", str(out)], "is t in milliseconds? t must be in seconds", out)


def test_cli_gap_is_noted_and_no_row_spans_it(tmp_path, signals, capsys):
    import pandas as pd

    t, q, qd, tau = signals
    t_gap = t.copy()
    t_gap[len(t) // 2 :] += 3600.0
    p = _generic(tmp_path / "gap.csv", t_gap, q, qd, tau)
    out = tmp_path / "gap.parquet"
    assert main(["ingest", str(p), "--out", str(out), "--robot", "irb120"]) == 0
    assert "1 gap(s) in t" in capsys.readouterr().out
    assert pd.read_parquet(out)["dt"].max() < 0.05


def test_simulated_lab_log_ingests_with_its_robot(tmp_path, irb120):
    """The tutorials' step: a log that `simulate` writes is accepted by `ingest --robot irb120`.

    The emulated controller's zone blends pass joint 6's nominal speed limit by up to about
    1.7 times (seed 0, 1000 moves); the unit check must not take that for degrees.
    """
    log = simulate(tmp_path / "real.csv", plant="lab", n_moves=1000, seed=0).log
    table = ingest([log], robot=irb120)
    assert len(table.frame) > 60_000
