"""Bounded reading (joulepath._io) and work limits (joulepath._work)."""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

from joulepath._io import MAX_NESTING, check_tree, finite_number, load_json, load_toml, read_capped
from joulepath._work import WORK_LIMITS, check_work, work_limit
from joulepath.errors import InvalidInput, InvalidRobotDescription
from joulepath.sim._profile import Profile, evaluate_profile, plan_profile


def test_read_capped_reads_a_small_regular_file(tmp_path):
    p = tmp_path / "a.txt"
    p.write_bytes(b"abc")
    assert read_capped(p, max_bytes=3, what="a file") == b"abc"


@pytest.mark.parametrize(
    ("make", "needle"),
    [
        (lambda p: p.mkdir(), "is a folder, not a regular file"),
        (lambda p: os.mkfifo(p), "is a FIFO (named pipe), not a regular file"),
        (lambda p: None, "cannot be read (No such file or directory)"),
        (lambda p: p.write_bytes(b"abcd"), "is 4 bytes, larger than the 3 bytes accepted for a file"),
    ],
)
def test_read_capped_refuses_by_name_before_opening(tmp_path, make, needle):
    p = tmp_path / "x"
    make(p)
    with pytest.raises(InvalidInput, match=re.escape(needle)):
        read_capped(p, max_bytes=3, what="a file")


def test_read_capped_refuses_a_device_and_a_sparse_file_without_reading_them(tmp_path):
    with pytest.raises(InvalidInput, match="character device"):
        read_capped("/dev/zero", max_bytes=10, what="a file")
    p = tmp_path / "sparse"
    with p.open("wb") as fh:
        fh.truncate(3 << 30)
    with pytest.raises(InvalidRobotDescription, match="is 3 GiB, larger than the 1 MiB"):
        read_capped(p, max_bytes=1 << 20, what="a file", error=InvalidRobotDescription)


def test_read_capped_link_to_a_device_is_refused_like_the_device(tmp_path):
    link = tmp_path / "link"
    link.symlink_to("/dev/zero")
    with pytest.raises(InvalidInput, match="character device"):
        read_capped(link, max_bytes=10, what="a file")


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("a = " + "[" * 3000 + "]" * 3000, "nested more than 32 deep"),
        ("a = " + "[" * (MAX_NESTING + 1) + "]" * (MAX_NESTING + 1), "nested more than 32 deep"),
        ("a = " + "{b = " * 3000 + "1" + "}" * 3000, "nested more than 32 deep"),
        ("a = 1" + "0" * 400, "an integer of 401 digits, beyond 64 bits"),
        ("a = " + "9" * 5000, "more than 4,300 digits"),
        ("a = [", "not valid TOML"),
        ("a = '\udcff'", "not UTF-8"),
    ],
)
def test_load_toml_refuses_in_one_line(tmp_path, text, needle):
    p = tmp_path / "a.toml"
    p.write_bytes(text.encode("utf-8", "surrogateescape"))
    with pytest.raises(InvalidInput, match=needle) as info:
        load_toml(p, max_bytes=1 << 20, what="a TOML file")
    assert "\n" not in str(info.value)


def test_load_toml_keeps_32_levels_and_64_bit_integers(tmp_path):
    p = tmp_path / "a.toml"
    p.write_text("a = " + "[" * (MAX_NESTING - 1) + "9223372036854775807" + "]" * (MAX_NESTING - 1) + "\n")
    data = load_toml(p, max_bytes=1 << 20, what="a TOML file")
    inner = data["a"]
    for _ in range(MAX_NESTING - 2):
        inner = inner[0]
    assert inner == [2**63 - 1]


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("[" * 5000 + "]" * 5000, "nested more than 32 deep"),
        ('{"a": NaN}', "NaN is not a JSON number"),
        ('{"a": -Infinity}', "-Infinity is not a JSON number"),
        ('{"a": ' + "9" * 5000 + "}", "more than 4,300 digits"),
        ('{"a": 1' + "0" * 30 + "}", "beyond 64 bits"),
        ('{"a": ', "not valid JSON"),
    ],
)
def test_load_json_refuses_in_one_line(tmp_path, text, needle):
    p = tmp_path / "a.json"
    p.write_text(text)
    with pytest.raises(InvalidInput, match=needle):
        load_json(p, max_bytes=1 << 20, what="a JSON file")


def test_check_tree_walks_without_recursion():
    deep: list[object] = []
    node = deep
    for _ in range(100_000):  # far beyond Python's recursion limit
        node.append([])
        node = node[0]  # type: ignore[assignment]
    with pytest.raises(InvalidInput, match="nested more than 32 deep"):
        check_tree(deep, "x")


@pytest.mark.parametrize("value", [True, False, float("nan"), float("inf"), 10**400, "1", None, 2.0])
def test_finite_number_refuses_booleans_non_finite_and_out_of_range(value):
    with pytest.raises(InvalidInput, match="x: must be a number of s in"):
        finite_number(value, "x", lo=0.0, hi=1.0, unit="s")


def test_finite_number_accepts_ints_and_floats_in_range():
    assert finite_number(1, "x", lo=0, hi=1) == 1.0 and isinstance(finite_number(1, "x"), float)
    assert finite_number(0.5, "x", lo=0, hi=1) == 0.5


def test_work_limit_default_and_environment(monkeypatch):
    for name, spec in WORK_LIMITS.items():
        monkeypatch.delenv(f"JOULEPATH_MAX_{name.upper()}", raising=False)
        assert work_limit(name) == spec.default
    monkeypatch.setenv("JOULEPATH_MAX_MOVES", "3")
    assert work_limit("moves") == 3
    check_work("moves", 3, "p.mod", "split it")
    with pytest.raises(
        InvalidInput, match=r"p.mod: 4 moves in one cycle, over the limit of 3 \(set JOULEPATH_MAX_MOVES"
    ):
        check_work("moves", 4, "p.mod", "split it")
    for bad in ("0", "-1", "nan", "x"):
        monkeypatch.setenv("JOULEPATH_MAX_MOVES", bad)
        with pytest.raises(InvalidInput, match="give a positive number"):
            work_limit("moves")


def test_check_work_refuses_nan_and_infinity():
    for value in (float("nan"), float("inf")):
        with pytest.raises(InvalidInput, match="over the limit"):
            check_work("motion_s", value, "p.mod", "speed it up")


def test_evaluate_profile_of_a_zero_length_move_is_done_at_once():
    """Two identical consecutive targets: the profile has no duration (was a ZeroDivisionError)."""
    tau = np.array([0.0, 0.5, 1.0])
    s, sd, sdd = evaluate_profile(Profile(ta=0.0, tc=0.0, v=0.0), tau)
    assert np.all(s == 1.0) and np.all(sd == 0.0) and np.all(sdd == 0.0)
    p = plan_profile(2.0, 10.0, 100.0)
    s, _, _ = evaluate_profile(p, np.array([p.duration]))
    assert s[0] == pytest.approx(1.0)
