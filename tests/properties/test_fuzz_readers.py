"""Fuzzing the readers: any byte string gives a valid result or a JoulepathError, never another exception.

Issue 15 item 1. Each reader gets raw bytes and mutations of a valid file (a byte
range replaced, a value swapped for hostile text, a tail cut off), so that most
examples get past the first check. The examples are bounded (``max_examples``), so
the whole file stays under a minute on two cores.
"""

from __future__ import annotations

import math
import string
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from joulepath.description import chain_from_urdf, parse_irml, preset_path
from joulepath.description._expr import ExpressionError, evaluate, evaluate_affine
from joulepath.errors import JoulepathError

# derandomize: the same examples on every run, so `make test` never flakes; run with more
# examples and random seeds by hand to search further (that found a lone CR in a log line
# raising csv.Error, since fixed in data/).
FUZZ = settings(
    max_examples=200, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)
FEW = settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])

IRML = preset_path("irb120").read_bytes()
URDF = preset_path("irb120", fmt="urdf").read_bytes()


def _generic_log() -> bytes:
    t = np.arange(60) * 0.025
    cols = {"t": t}
    for i in range(1, 7):
        cols |= {f"q{i}": 0.3 * np.sin(t * i), f"dq{i}": 0.3 * i * np.cos(t * i), f"tau{i}": t + i}
    lines = [",".join(cols)]
    lines += [",".join(f"{cols[k][r]:.6f}" for k in cols) for r in range(t.size)]
    return ("\n".join(lines) + "\n").encode()


LOG = _generic_log()
TOML = b"""name = "fuzz"
seed = 1

[data]
train_moves = 3
test_moves = 2

[train]
families = ["par"]
cv = 2

[optimize]
tasks = 1
generations = 2
population = 4
"""

HOSTILE = [
    "",
    "nan",
    "inf",
    "-1e999",
    "1e308",
    "(-1)**0.5",
    "q1**q1",
    "\x00",
    "\ufeff",
    "\udcff",
    "1_0",
    "0x10",
    "9" * 400,
    "(" * 300 + "1" + ")" * 300,
    "-" * 199 + "1",
    "]]>",
    "<!ENTITY a 'b'>",
    "&amp;&lt;",
    '"',
    "'",
    "\\",
    ",",
    "\n",
    "\r\n",
    "[a]",
    "{b=1}",
    "true",
    "1979-05-27",
]


@st.composite
def mutated(draw: Any, base: bytes) -> bytes:
    """``base`` with one to three edits: a slice replaced by bytes or hostile text, or cut short."""
    data = bytearray(base)
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["replace", "insert", "cut", "hostile"]))
        i = draw(st.integers(0, len(data)))
        j = draw(st.integers(i, min(len(data), i + 40)))
        if kind == "replace":
            data[i:j] = draw(st.binary(max_size=20))
        elif kind == "insert":
            data[i:i] = draw(st.binary(min_size=1, max_size=20))
        elif kind == "cut":
            del data[i:]
        else:
            text = draw(st.sampled_from(HOSTILE) | st.text(max_size=20))
            data[i:j] = text.encode("utf-8", "surrogatepass")
    return bytes(data)


@st.composite
def value_swapped(draw: Any, base: bytes, opening: bytes, closing: bytes) -> bytes:
    """Replace the text between one ``opening``/``closing`` pair of ``base`` (an XML value, an attribute)."""
    starts = [k for k in range(len(base)) if base.startswith(opening, k)]
    k = draw(st.sampled_from(starts)) + len(opening)
    end = base.index(closing, k)
    text = draw(
        st.sampled_from(HOSTILE)
        | st.text(alphabet="0123456789.eE+-*/()pi q_j ", max_size=30)
        | st.text(max_size=30)
    )
    return base[:k] + text.encode("utf-8", "surrogatepass") + base[end:]


def _valid_or_joulepath_error(call: Callable[[], object]) -> object:
    try:
        return call()
    except JoulepathError:
        return None


def _write(data: bytes, name: str) -> tuple[tempfile.TemporaryDirectory[str], Path]:
    folder = tempfile.TemporaryDirectory()
    path = Path(folder.name) / name
    path.write_bytes(data)
    return folder, path


# --------------------------------------------------------------------------- expressions


@FUZZ
@given(
    st.text(alphabet="0123456789.eE+-*/()% pi q1 jx_,<>=~&|^@[]{}:'\"", max_size=60) | st.text(max_size=60)
)
def test_evaluate_affine_any_text_gives_finite_affine_or_expression_error(text):
    try:
        result = evaluate_affine(text, frozenset({"q1"}))
    except ExpressionError:
        return
    assert math.isfinite(result.const) and math.isfinite(result.coef)
    assert isinstance(result.const, float) and isinstance(result.coef, float)
    assert result.var in (None, "q1")


@FUZZ
@given(
    st.recursive(
        st.sampled_from(["1", "2.5", "pi", "0", "-1", "1e300", "0.5", "q1"]),
        lambda inner: st.tuples(inner, st.sampled_from(["+", "-", "*", "/", "**"]), inner).map(
            lambda t: f"({t[0]}{t[1]}{t[2]})"
        ),
        max_leaves=12,
    )
)
def test_evaluate_any_arithmetic_gives_a_finite_float_or_expression_error(text):
    try:
        value = evaluate(text)
    except ExpressionError:
        return
    assert isinstance(value, float) and math.isfinite(value)


# --------------------------------------------------------------------------- IRML


@FUZZ
@given(st.binary(max_size=300) | mutated(IRML))
def test_parse_irml_any_bytes_gives_a_description_or_joulepath_error(data):
    _valid_or_joulepath_error(lambda: parse_irml(data, source="fuzz.irml"))


@FUZZ
@given(
    value_swapped(IRML, b"<d>", b"</d>")
    | value_swapped(IRML, b"<q>", b"</q>")
    | value_swapped(IRML, b"<link-mass>", b"</link-mass>")
    | value_swapped(IRML, b'id="', b'"')
    | value_swapped(IRML, b"<lower>", b"</lower>")
)
def test_parse_irml_any_value_gives_a_description_or_joulepath_error(data):
    desc = _valid_or_joulepath_error(lambda: parse_irml(data, source="fuzz.irml"))
    if desc is not None:
        for j in desc.joints:  # type: ignore[attr-defined]
            assert all(math.isfinite(v) for v in (j.d, j.r, j.alpha, j.offset, j.inertial.mass))


@FEW
@given(st.integers(1, 3000), st.sampled_from(["<a>", "<joint>", "<range-set>", "<x/>"]))
def test_parse_irml_deep_or_wide_nesting_gives_joulepath_error_or_a_description(depth, tag):
    if tag == "<x/>":
        inner = tag * depth
    else:
        inner = tag * depth + tag.replace("<", "</") * depth
    data = IRML.replace(b"<name>", inner.encode() + b"<name>", 1)
    _valid_or_joulepath_error(lambda: parse_irml(data, source="deep.irml"))


# --------------------------------------------------------------------------- URDF


@FUZZ
@given(
    st.binary(max_size=200)
    | mutated(URDF)
    | value_swapped(URDF, b'xyz="', b'"')
    | value_swapped(URDF, b'value="', b'"')
    | value_swapped(URDF, b'link="', b'"')
    | value_swapped(URDF, b'type="', b'"')
    | value_swapped(URDF, b'lower="', b'"')
    | value_swapped(URDF, b'ixx="', b'"')
)
def test_chain_from_urdf_any_bytes_gives_a_chain_or_joulepath_error(data):
    folder, path = _write(data, "fuzz.urdf")
    with folder:
        chain = _valid_or_joulepath_error(lambda: chain_from_urdf(path))
    if chain is not None:
        assert chain.n_joints == 6  # type: ignore[attr-defined]
        assert np.all(np.isfinite(chain.placements))  # type: ignore[attr-defined]


# --------------------------------------------------------------------------- experiment TOML

KEYS = [
    "name", "robot", "seed", "jobs", "scheduler", "plant", "train_moves", "test_moves", "micro_moves",
    "sim_moves", "train_logs", "test_logs", "methods", "rows", "epochs", "batch_size", "source",
    "repair", "families", "targets", "grid", "cv", "inputs", "max_rows", "tasks", "algorithm",
    "fitness", "generations", "population", "range_set", "configurations", "unknown",
]  # fmt: skip
SECTION_NAMES = ["", "data", "synth", "train", "importance", "optimize", "bench", "other"]


def _toml_value(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return (
            "nan"
            if math.isnan(value)
            else ("inf" if value > 0 else "-inf")
            if math.isinf(value)
            else repr(value)
        )
    if isinstance(value, int):
        return str(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    text = str(value)
    escaped = "".join(
        c if c in string.printable and c not in '"\\\n\r\t\x0b\x0c' else f"\\u{ord(c):04x}"
        for c in text
        if ord(c) < 0x10000 and not 0xD800 <= ord(c) < 0xE000
    )
    return f'"{escaped}"'


VALUES = (
    st.integers(min_value=-(2**70), max_value=2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.booleans()
    | st.text(max_size=20)
    | st.sampled_from(["irb120", "lab", "par", "E", "quick", "ga", "physics", "..", "", "demo.toml"])
    | st.lists(st.sampled_from(["par", "xgb", "E", "E1", "copula", "knn", "", "x.csv"]), max_size=4)
)


@st.composite
def experiment_text(draw: Any) -> bytes:
    lines = ['name = "fuzz"'] if draw(st.booleans()) else []
    for section in draw(st.lists(st.sampled_from(SECTION_NAMES), max_size=4, unique=True)):
        if section:
            lines.append(f"[{section}]")
        for key in draw(st.lists(st.sampled_from(KEYS), max_size=4, unique=True)):
            lines.append(f"{key} = {_toml_value(draw(VALUES))}")
    return ("\n".join(lines) + "\n").encode()


@FUZZ
@given(st.binary(max_size=200) | mutated(TOML) | experiment_text())
def test_load_experiment_any_bytes_gives_an_experiment_or_joulepath_error(data):
    from joulepath.experiment import load_experiment

    folder, path = _write(data, "fuzz.toml")
    with folder:
        exp = _valid_or_joulepath_error(lambda: load_experiment(path))
    if exp is not None:
        assert 0 <= exp.seed < 2**32 and 1 <= exp.jobs <= 256  # type: ignore[attr-defined]
        assert exp.data.train_moves <= 20_000 and exp.optimize.tasks <= 1000  # type: ignore[attr-defined]


# --------------------------------------------------------------------------- joint logs


@FUZZ
@given(st.binary(max_size=300) | mutated(LOG))
def test_read_log_any_bytes_gives_a_log_or_joulepath_error(data):
    from joulepath.data import read_log

    folder, path = _write(data, "fuzz.csv")
    with folder:
        log = _valid_or_joulepath_error(lambda: read_log(path))
    if log is not None:
        assert np.all(np.isfinite(log.q)) and np.all(np.diff(log.t) > 0)  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    "data",
    [
        b"",
        b"\xff\xfe\x00",
        LOG[:200],
        LOG.replace(b"\n", b"\r"),
        LOG * 2,
        LOG.replace(b"\n", b"\r\n"),
        LOG.replace(b"\n0.000000,", b"\n0\r.000000,", 1),  # a lone CR in a data line (was csv.Error)
    ],
)
def test_read_log_examples_give_a_log_or_joulepath_error(data, tmp_path):
    from joulepath.data import read_log

    path = tmp_path / "log.csv"
    path.write_bytes(data)
    _valid_or_joulepath_error(lambda: read_log(path))
