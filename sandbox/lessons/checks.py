"""The safe expression language of a lesson's ``check:``: a condition on readouts
(``and``, ``or``, ``not``, comparisons, ``+ - * / **``, ``abs(x)``, ``min(a, b, ...)``,
``max(a, b, ...)`` and ``initial(name)``: the value when the step began).

Lesson files are untrusted: :func:`compile_check` refuses every check that is malformed, too
big (:data:`MAX_CHECK_CHARS`, :data:`MAX_CHECK_NODES`, :data:`MAX_CHECK_DEPTH`), not a
condition, or whose written numbers already fail (``9**9**9``, ``x / 0``, ``(-8)**0.5``,
literals above :data:`MAX_LITERAL`).
"""

from __future__ import annotations

import ast
import math
import re
import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache

from sandbox.lessons.evaluation import COMPARE, CheckError, number_of, power_of, truth_of

PARSE_LOCK = threading.Lock()
"""One ``ast.parse`` at a time in this process: Python 3.11 keeps the AST builder's depth
count per interpreter, not per thread, and two sessions reading the lessons at once (a
class arriving) raised "SystemError: AST constructor recursion depth mismatch", which
killed a session: its browser got no frame (found by ``bench --classroom``)."""

MAX_CHECK_CHARS = 300
"""Longest check [characters]."""
MAX_CHECK_NODES = 80
"""Most syntax nodes (numbers, names, operators, calls) in one check."""
MAX_CHECK_DEPTH = 32
"""Deepest nesting of operations and parentheses in one check."""
MAX_LITERAL = 1e15
"""Largest number written in a check (in absolute value)."""
MAX_ARGUMENTS = 8
"""Most arguments of ``min`` and ``max``."""

_CHECK_CHARS = re.compile(r"[A-Za-z0-9_ .+\-*/()<>=!,]*")
_ARITHMETIC = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)
_FUNCTIONS = ("abs", "min", "max", "initial")
_NAMED: dict[type, str] = {
    ast.Attribute: "'.' (attribute access)", ast.Starred: "'*' (unpacking)",
    ast.FloorDiv: "'//'", ast.IfExp: "'if ... else'", ast.Invert: "'~'",
    ast.BitAnd: "'&'", ast.BitOr: "'|'", ast.BitXor: "'^'", ast.LShift: "'<<'",
    ast.RShift: "'>>'", ast.Subscript: "indexing",
}  # fmt: skip


@dataclass(frozen=True)
class Check:
    """A live condition on readouts (build it with :func:`compile_check`).

    Attributes:
        source: The condition as written.
        names: Readouts it reads live.
        initial: Readouts whose value at the step's start it uses.
        where: ``file:line`` of the check, named by the errors shown during the lesson.
    """

    source: str
    names: tuple[str, ...]
    initial: tuple[str, ...]
    where: str = field(default="", compare=False)
    tree: ast.Expression | None = field(default=None, compare=False, repr=False)

    def evaluate(self, values: Mapping[str, float], initial: Mapping[str, float]) -> bool:
        """True when the condition holds for ``values`` (``initial``: at the step's start).

        Raises:
            CheckError: the live values make it impossible to compute (overflow, division
                by zero, a readout missing...).
        """
        tree = self.tree if self.tree is not None else _compiled(self.source).tree
        assert tree is not None
        return truth_of(tree.body, values, initial)


@lru_cache(maxsize=256)
def _compiled(source: str) -> Check:
    return compile_check(source)


def _refuse(message: str) -> ValueError:
    return ValueError(message)


def _arity(node: ast.Call, name: str) -> None:
    n = len(node.args)
    if node.keywords:
        raise _refuse(f"{name}() takes no keyword arguments; write {name}(a, b)")
    if name == "initial":
        if n != 1 or not isinstance(node.args[0], ast.Name):
            raise _refuse("initial() takes one readout name; write e.g. initial(bearing_A)")
    elif name == "abs":
        if n != 1:
            raise _refuse(f"abs() takes one number, got {n}; write abs(x)")
    elif not 2 <= n <= MAX_ARGUMENTS:
        raise _refuse(f"{name}() takes 2 to {MAX_ARGUMENTS} numbers, got {n}; write {name}(a, b)")


def _typed(node: ast.AST, depth: int, count: list[int]) -> bool:
    """Validate ``node``; True when it is a condition, False when it is a number."""
    count[0] += 1
    if count[0] > MAX_CHECK_NODES:
        raise _refuse(f"more than {MAX_CHECK_NODES} terms; split the condition or simplify it")
    if depth > MAX_CHECK_DEPTH:
        raise _refuse(
            f"more than {MAX_CHECK_DEPTH} operations inside one another; simplify the condition"
        )

    def number(child: ast.AST, what: str) -> None:
        if _typed(child, depth + 1, count):
            raise _refuse(f"{what} needs a number, not a condition; compare numbers, e.g. x < 1")

    def condition(child: ast.AST, what: str) -> None:
        if not _typed(child, depth + 1, count):
            raise _refuse(
                f"{what} combines conditions, not numbers; compare the numbers first, e.g. x < 1"
            )

    if isinstance(node, ast.Constant):
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise _refuse(f"only numbers are allowed, not {value!r}; write a number such as 0.5")
        if abs(value) > MAX_LITERAL or not math.isfinite(value):
            raise _refuse(
                f"the number {float(value):.6g} is too large; write numbers within ±{MAX_LITERAL:g}"
            )
        return False
    if isinstance(node, ast.Name):
        if node.id in _FUNCTIONS:
            raise _refuse(f"{node.id} is a function; call it, e.g. {node.id}(x)")
        return False
    if isinstance(node, ast.BoolOp):
        for part in node.values:
            condition(part, "'and'/'or'")
        return True
    if isinstance(node, ast.UnaryOp):
        if isinstance(node.op, ast.Not):
            condition(node.operand, "'not'")
            return True
        if isinstance(node.op, (ast.USub, ast.UAdd)):
            number(node.operand, "a sign")
            return False
    elif isinstance(node, ast.BinOp) and isinstance(node.op, _ARITHMETIC):
        number(node.left, "an operation")
        number(node.right, "an operation")
        return False
    elif isinstance(node, ast.Compare):
        if not all(type(op) in COMPARE for op in node.ops):
            raise _refuse("use <, <=, >, >=, == or != to compare numbers")
        for part in (node.left, *node.comparators):
            number(part, "a comparison")
        return True
    elif isinstance(node, ast.Call):
        fn = node.func
        if not isinstance(fn, ast.Name) or fn.id not in _FUNCTIONS:
            raise _refuse("only abs, min, max and initial(name) can be called; use one of them")
        _arity(node, fn.id)
        if fn.id != "initial":
            for arg in node.args:
                number(arg, f"{fn.id}()")
        return False
    kind = type(node.op) if isinstance(node, (ast.BinOp, ast.UnaryOp)) else type(node)
    what = _NAMED.get(kind, kind.__name__)
    raise _refuse(
        f"{what} is not allowed in a check; use numbers, readout names, + - * / **, "
        "comparisons, and/or/not, abs, min, max, initial(name)"
    )


def _reads(node: ast.AST, live: set[str], start: set[str]) -> None:
    """Collect the readouts ``node`` reads now (``live``) and at the step's start."""
    if isinstance(node, ast.Name):
        live.add(node.id)
    elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        if node.func.id == "initial":
            arg = node.args[0]
            if isinstance(arg, ast.Name):
                start.add(arg.id)
        else:
            for arg in node.args:
                _reads(arg, live, start)
    else:
        for child in ast.iter_child_nodes(node):
            _reads(child, live, start)


def _constant(node: ast.AST) -> bool:
    """True when ``node`` reads no readout (its value is known when the lesson loads)."""
    live: set[str] = set()
    start: set[str] = set()
    _reads(node, live, start)
    return not live and not start


def compile_check(source: str, where: str = "") -> Check:
    """A check from its source, validated: syntax, size, types (a condition made of numbers),
    and every part made only of written numbers computed once (``9**9**9``, ``1/0`` and
    ``(-8)**0.5`` are refused here, not when the student runs the step).

    Args:
        source: The condition, e.g. ``bearing_A < 0.01 * initial(bearing_A)``.
        where: ``file:line`` named by the errors shown during the lesson.

    Raises:
        ValueError: what is wrong and how to write it (SyntaxError for bad syntax).
    """
    if len(source) > MAX_CHECK_CHARS:
        raise _refuse(
            f"{len(source)} characters; a check has at most {MAX_CHECK_CHARS}: shorten it"
        )
    if not source.strip():
        raise _refuse("empty condition; write e.g. 'x < 0.5 * initial(x)'")
    bad = _CHECK_CHARS.sub("", source)
    if bad:
        raise _refuse(
            f"character {bad[0]!r} is not allowed; use names, numbers, + - * / ( ) , < > = !"
        )
    try:
        with PARSE_LOCK:
            tree = ast.parse(source.strip(), mode="eval")
    except (RecursionError, MemoryError):
        raise _refuse(f"nested too deeply; at most {MAX_CHECK_DEPTH} levels") from None
    except SyntaxError as exc:
        raise _refuse(f"invalid syntax ({exc.msg}); write e.g. 'x < 0.5 * initial(x)'") from None
    if not _typed(tree.body, 0, [0]):
        raise _refuse("a check is a condition, not a number; write e.g. 'x < 0.5 * initial(x)'")
    for node in ast.walk(tree.body):
        try:
            if isinstance(node, (ast.BinOp, ast.UnaryOp, ast.Call)) and _constant(node):
                number_of(node, {}, {})
            elif isinstance(node, ast.BinOp) and _constant(node.right):
                right = number_of(node.right, {}, {})  # x / 0, x ** 1000
                if isinstance(node.op, ast.Div) and right == 0:
                    raise CheckError("division by zero", "division par zéro")
                if isinstance(node.op, ast.Pow):
                    power_of(1.0, right)
        except CheckError as exc:
            raise _refuse(
                f"{ast.unparse(node)!r} cannot be computed: {exc}; change the numbers written"
            ) from None
    names: set[str] = set()
    initial: set[str] = set()
    _reads(tree.body, names, initial)
    if not names and not initial:
        raise _refuse("the condition reads no readout (always true or always false); name one")
    return Check(source.strip(), tuple(sorted(names)), tuple(sorted(initial)), where, tree)
