import math

import pytest

from joulepath.description._expr import (
    ExpressionError,
    evaluate,
    evaluate_affine,
    format_angle,
    format_number,
)


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("0.29", 0.29),
        ("-pi/2", -math.pi / 2),
        ("165*pi/180", 165 * math.pi / 180),
        ("2**3", 8.0),
        ("(1+2)*3", 9.0),
        ("-0.00615871", -0.00615871),
        ("1e-3", 1e-3),
    ],
)
def test_evaluate_happy(text, value):
    assert evaluate(text) == pytest.approx(value, rel=1e-15)


@pytest.mark.parametrize(
    "text",
    [
        "__import__('os').system('true')",
        "abs(-1)",
        "x",
        "1/0",
        "",
        "9**9**9",
        "[1]",
        "'a'",
        "True",
        "pi.real",
        "lambda: 1",
        "1 if 1 else 2",
        "2**100000",
    ],
)
def test_evaluate_rejects_anything_but_arithmetic(text):
    with pytest.raises(ExpressionError):
        evaluate(text)


def test_evaluate_affine_joint_variable():
    aff = evaluate_affine("q2 - pi/2", frozenset({"q2"}))
    assert (aff.var, aff.coef, aff.const) == ("q2", 1.0, -math.pi / 2)
    aff = evaluate_affine("-q6 + pi", frozenset({"q6"}))
    assert (aff.var, aff.coef, aff.const) == ("q6", -1.0, math.pi)


@pytest.mark.parametrize("text", ["q1*q1", "1/q1", "q1**2", "q1 + q2"])
def test_evaluate_affine_rejects_nonlinear(text):
    with pytest.raises(ExpressionError):
        evaluate_affine(text, frozenset({"q1", "q2"}))


@pytest.mark.parametrize("value", [math.pi, -math.pi / 2, 165 * math.pi / 180, 0.25, 1e-7, -2.87979, 0.0])
def test_format_angle_round_trips_exactly(value):
    assert evaluate(format_angle(value)) == value


def test_format_number_round_trips_exactly():
    for v in (0.29, 1.0, -8.0784e-05, 3.06700626, 1e300):
        assert float(format_number(v)) == v


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ("(-1)**0.5", r"is not a real number \(\(-1\) \*\* 0.5 is complex\)"),
        ("(-8)**(1/3)", "is complex"),
        ("1" + "0" * 190 + "**2", "not finite|larger|cannot be evaluated"),
        ("1\x00", "not a valid arithmetic expression"),
    ],
)
def test_evaluate_refuses_complex_and_hostile_values_with_expression_error(text, pattern):
    with pytest.raises(ExpressionError, match=pattern):
        evaluate(text)


def test_evaluate_affine_complex_offset_is_expression_error():
    with pytest.raises(ExpressionError, match="complex"):
        evaluate_affine("q1 + (-2)**0.5", frozenset({"q1"}))


def test_evaluate_deepest_nesting_within_the_length_limit():
    assert evaluate("(" * 99 + "1" + ")" * 99) == 1.0
    assert evaluate("-" * 199 + "1") == -1.0
