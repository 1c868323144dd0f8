"""How a compiled check is computed: only the operator written, in floats, with
``|exponent| <=`` :data:`MAX_EXPONENT`; what fails only with live values (overflow, division
by zero, a readout missing) raises :class:`CheckError`.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Mapping

MAX_EXPONENT = 64.0
"""Largest exponent of ``**`` (in absolute value), written or live."""

COMPARE = {
    ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
    ast.Eq: operator.eq, ast.NotEq: operator.ne,
}  # fmt: skip
"""The comparison operators a check may use, and what each computes."""


class CheckError(ArithmeticError):
    """A check that cannot be computed: refused at load time when the numbers are written in
    the check, caught at run time when they come from live readouts.

    Attributes:
        french: The same problem in French, for the lesson panel.
    """

    def __init__(self, message: str, french: str) -> None:
        super().__init__(message)
        self.french = french


def _finite(result: float, *inputs: float) -> float:
    if not math.isfinite(result) and all(math.isfinite(x) for x in inputs):
        raise CheckError("the result overflows", "résultat trop grand (dépassement)")
    return result


def power_of(a: float, b: float) -> float:
    """``a ** b`` in floats, refused when the exponent is above :data:`MAX_EXPONENT`, the
    result is not a real number or overflows.

    Raises:
        CheckError: naming the problem (in English and in French).
    """
    if abs(b) > MAX_EXPONENT:
        raise CheckError(
            f"exponent {b:g} is too large (at most ±{MAX_EXPONENT:g})",
            f"exposant {b:g} trop grand (au plus ±{MAX_EXPONENT:g})",
        )
    if a == 0 and b < 0:
        raise CheckError("division by zero (0 to a negative power)", "division par zéro")
    if a < 0 and b != int(b):
        raise CheckError(
            f"({a:g}) ** {b:g} is not a real number (negative base, fractional exponent)",
            f"({a:g}) ** {b:g} n'est pas un nombre réel",
        )
    try:
        return _finite(math.pow(a, b), a, b)
    except OverflowError:
        raise CheckError("the result overflows", "résultat trop grand (dépassement)") from None


def _number(node: ast.AST, values: Mapping[str, float], initial: Mapping[str, float]) -> float:
    """The value of a validated numeric node."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        return float(node.value)
    if isinstance(node, ast.Name):
        return _read(values, node.id, "")
    if isinstance(node, ast.UnaryOp):
        x = _number(node.operand, values, initial)
        return -x if isinstance(node.op, ast.USub) else x
    if isinstance(node, ast.BinOp):
        a = _number(node.left, values, initial)
        b = _number(node.right, values, initial)
        op = node.op
        if isinstance(op, ast.Add):
            return _finite(a + b, a, b)
        if isinstance(op, ast.Sub):
            return _finite(a - b, a, b)
        if isinstance(op, ast.Mult):
            return _finite(a * b, a, b)
        if isinstance(op, ast.Div):
            if b == 0:
                raise CheckError("division by zero", "division par zéro")
            return _finite(a / b, a, b)
        return power_of(a, b)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        fn = node.func.id
        if fn == "initial":
            arg = node.args[0]
            assert isinstance(arg, ast.Name)
            return _read(initial, arg.id, "initial")
        args = [_number(a, values, initial) for a in node.args]
        if fn == "abs":
            return abs(args[0])
        return min(args) if fn == "min" else max(args)
    raise CheckError(f"cannot compute {type(node).__name__}", "expression non calculable")


def number_of(node: ast.AST, values: Mapping[str, float], initial: Mapping[str, float]) -> float:
    """The value of a numeric part of a compiled check's tree (e.g. the bound of a
    comparison, for the lesson panel's goal), with the live values and those at the step's
    start.

    Raises:
        CheckError: it cannot be computed with these values.
    """
    return _number(node, values, initial)


def _read(values: Mapping[str, float], name: str, kind: str) -> float:
    try:
        return float(values[name])
    except KeyError:
        where = "at the step's start" if kind else "now"
        quand = "au début de l'étape" if kind else "maintenant"
        raise CheckError(
            f"no readout {name!r} {where}", f"grandeur « {name} » absente {quand}"
        ) from None
    except (TypeError, ValueError):
        raise CheckError(
            f"readout {name!r} is not a number", f"grandeur « {name} » non numérique"
        ) from None


def truth_of(node: ast.AST, values: Mapping[str, float], initial: Mapping[str, float]) -> bool:
    """The value of a validated condition node (``values``: live, ``initial``: at the step's
    start).

    Raises:
        CheckError: it cannot be computed with these values.
    """
    if isinstance(node, ast.BoolOp):
        if isinstance(node.op, ast.And):
            return all(truth_of(v, values, initial) for v in node.values)
        return any(truth_of(v, values, initial) for v in node.values)
    if isinstance(node, ast.UnaryOp):
        return not truth_of(node.operand, values, initial)
    if isinstance(node, ast.Compare):
        left = _number(node.left, values, initial)
        for op, comp in zip(node.ops, node.comparators, strict=True):
            right = _number(comp, values, initial)
            if not COMPARE[type(op)](left, right):
                return False
            left = right
        return True
    raise CheckError(f"cannot test {type(node).__name__}", "condition non calculable")
