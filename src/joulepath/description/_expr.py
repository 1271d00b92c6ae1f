"""Safe evaluation of the arithmetic expressions IRML allows (``-pi/2``, ``q2 - pi/2``).

Expressions are parsed with :mod:`ast` and walked over a short whitelist of node
types; nothing is ever passed to ``eval``. A value is kept as an affine form
``coef * variable + const`` so that a joint-angle expression such as
``q2 - pi/2`` yields its variable, sign and offset.
"""

from __future__ import annotations

import ast
import math
from dataclasses import dataclass

_MAX_LEN = 200
_MAX_EXPONENT = 16.0
_CONSTANTS = {"pi": math.pi}


class ExpressionError(ValueError):
    """The text is not an allowed expression; the message says why."""


@dataclass(frozen=True, slots=True)
class Affine:
    """``coef * var + const`` (``var`` is None for a plain number)."""

    coef: float
    const: float
    var: str | None


def _combine_var(a: Affine, b: Affine) -> str | None:
    if a.var and b.var and a.var != b.var:
        raise ExpressionError(f"uses two variables, {a.var!r} and {b.var!r}; only one is allowed")
    return a.var or b.var


def _walk(node: ast.AST, variables: frozenset[str]) -> Affine:
    if isinstance(node, ast.Expression):
        return _walk(node.body, variables)
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ExpressionError(f"{str(node.value)[:20]!r} is not a number")
        try:
            return Affine(0.0, float(node.value), None)
        except OverflowError as err:  # an integer literal beyond the float range
            raise ExpressionError("has a number too large for a float") from err
    if isinstance(node, ast.Name):
        if node.id in _CONSTANTS:
            return Affine(0.0, _CONSTANTS[node.id], None)
        if node.id in variables:
            return Affine(1.0, 0.0, node.id)
        allowed = ", ".join(sorted({*_CONSTANTS, *variables}))
        raise ExpressionError(f"unknown name {node.id!r} (allowed: {allowed})")
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
        v = _walk(node.operand, variables)
        s = -1.0 if isinstance(node.op, ast.USub) else 1.0
        return Affine(s * v.coef, s * v.const, v.var)
    if isinstance(node, ast.BinOp):
        a = _walk(node.left, variables)
        b = _walk(node.right, variables)
        if isinstance(node.op, ast.Add):
            return Affine(a.coef + b.coef, a.const + b.const, _combine_var(a, b))
        if isinstance(node.op, ast.Sub):
            return Affine(a.coef - b.coef, a.const - b.const, _combine_var(a, b))
        if isinstance(node.op, ast.Mult):
            if a.var and b.var:
                raise ExpressionError("multiplies the joint variable by itself")
            if b.var:
                a, b = b, a
            return Affine(a.coef * b.const, a.const * b.const, a.var)
        if isinstance(node.op, ast.Div):
            if b.var:
                raise ExpressionError("divides by the joint variable")
            if b.const == 0.0:
                raise ExpressionError("divides by zero")
            return Affine(a.coef / b.const, a.const / b.const, a.var)
        if isinstance(node.op, ast.Pow):
            if a.var or b.var:
                raise ExpressionError("raises the joint variable to a power")
            if abs(b.const) > _MAX_EXPONENT:
                raise ExpressionError(f"exponent {b.const} is larger than {_MAX_EXPONENT:g}")
            try:
                value = a.const**b.const
            except (OverflowError, ZeroDivisionError) as err:
                raise ExpressionError(f"cannot be evaluated ({err})") from err
            if not isinstance(value, float):  # a negative base to a fractional power
                raise ExpressionError(f"is not a real number (({a.const:g}) ** {b.const:g} is complex)")
            return Affine(0.0, value, None)
    raise ExpressionError(
        f"contains {type(node).__name__}; allowed are numbers, pi, + - * / ** and parentheses"
    )


def evaluate_affine(text: str, variables: frozenset[str] = frozenset()) -> Affine:
    """Evaluate ``text`` to an affine form in at most one of ``variables``.

    Raises
    ------
    ExpressionError
        Empty, too long, not parseable, or using anything outside the whitelist.

    Examples
    --------
    >>> evaluate_affine("q2 - pi/2", frozenset({"q2"}))
    Affine(coef=1.0, const=-1.5707963267948966, var='q2')
    """
    text = text.strip()
    if not text:
        raise ExpressionError("is empty")
    if len(text) > _MAX_LEN:
        raise ExpressionError(f"is longer than {_MAX_LEN} characters")
    try:
        tree = ast.parse(text, mode="eval")
    except (SyntaxError, ValueError, MemoryError, RecursionError) as err:
        raise ExpressionError("is not a valid arithmetic expression") from err
    try:
        result = _walk(tree, variables)
    except RecursionError as err:  # unreachable within _MAX_LEN characters; kept as a guard
        raise ExpressionError("is nested too deeply") from err
    if not (math.isfinite(result.const) and math.isfinite(result.coef)):
        raise ExpressionError("is not finite")
    return result


def evaluate(text: str) -> float:
    """Evaluate a constant expression such as ``-pi/2`` or ``0.29``.

    Examples
    --------
    >>> evaluate("-pi/2") == -math.pi / 2
    True
    """
    return evaluate_affine(text).const


_DENOMINATORS = (1, 2, 3, 4, 6, 12, 180)


def format_angle(value: float) -> str:
    """Write an angle in rad, as a multiple of pi when that reads back exactly.

    Examples
    --------
    >>> format_angle(-math.pi / 2)
    '-pi/2'
    >>> format_angle(0.25)
    '0.25'
    """
    if value == 0.0:
        return "0"
    for n in _DENOMINATORS:
        k = round(value * n / math.pi)
        if k == 0 or abs(k) > 4 * n:
            continue
        num = "pi" if abs(k) == 1 else f"{abs(k)}*pi"
        text = ("-" if k < 0 else "") + (num if n == 1 else f"{num}/{n}")
        if evaluate(text) == value:
            return text
    return repr(float(value))


def format_number(value: float) -> str:
    """Shortest text that reads back to exactly ``value``."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text
