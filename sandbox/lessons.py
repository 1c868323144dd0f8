"""Guided lessons: Markdown files in ``lessons/`` turned into frozen step lists.

A lesson file::

    ---
    scene: rotor            (a scene name, or "any")
    title: Équilibrage statique puis dynamique
    level: L3
    ---

    ## Step title
    preset: speed_rpm=1500, mass1_g=0
    show: bearing_A, bearing_B
    plots: bearing_A, bearing_B
    arrows: bearing_A, bearing_B
    question: Why ...? | answer: Because ...
    check: bearing_A < 0.01 * initial(bearing_A)
    goal: Divide the force of bearing A by 100
    success: Well done ...
    hint: Try ...
    solution: @balancing_solution      (or NAME=VALUE, ...: a state where the check passes)

    Free Markdown text, formulas between $...$ (a LaTeX subset rendered as HTML).

Directives are the ``key: value`` lines right under the step's heading. A check is a
condition on readouts (``and``, ``or``, ``not``, comparisons, ``+ - * / **``, ``abs(x)``,
``min(a, b, ...)``, ``max(a, b, ...)`` and ``initial(name)``: the value when the step began).
The page states the goal in words from the check (e.g. "Palier A : 54 N → objectif < 0,54 N",
with a progress bar); ``goal:`` replaces that sentence when it reads badly.

Lesson files are untrusted (students and teachers exchange them):

- Loading refuses, as :class:`BadLesson` naming ``file:line`` and the fix, a file above
  :data:`MAX_LESSON_BYTES` or with a line above :data:`MAX_LINE_CHARS`, and every check
  that is malformed, too big (:data:`MAX_CHECK_CHARS`, :data:`MAX_CHECK_NODES`,
  :data:`MAX_CHECK_DEPTH`), not a condition, or whose written numbers already fail
  (``9**9**9``, ``x / 0``, ``(-8)**0.5``, literals above :data:`MAX_LITERAL`).
- A check computes only the operator written, in floats, with ``|exponent| <=``
  :data:`MAX_EXPONENT`; what fails only with live values (overflow, division by zero)
  raises :class:`CheckError`, which :class:`Progress` keeps and the lesson panel shows
  once, in French, with ``file:line``.
- Text is Markdown without raw HTML: ``<`` is shown as text (also inside code spans, where
  it appears as ``&lt;``: write ``$<$`` or ``\\le`` instead), links and images only go
  to ``http(s)://`` addresses, reference definitions are shown as text.
"""

from __future__ import annotations

import ast
import html
import logging
import math
import operator
import re
import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

from sandbox.data import data_dir
from sandbox.errors import BadParameter, SandboxError, choices, shown

ANY_SCENE = "any"
DIRECTIVES = (
    "preset", "show", "plots", "arrows", "question", "check", "goal", "success", "hint",
    "solution",
)  # fmt: skip
REPEATABLE = ("question", "hint")
"""Directives a step may give several times; the others at most once."""
MAX_LESSON_BYTES = 64 * 1024
"""Largest lesson file read [bytes] (the course's longest is under 4 KiB)."""

PARSE_LOCK = threading.Lock()
"""One ``ast.parse`` at a time in this process: Python 3.11 keeps the AST builder's depth
count per interpreter, not per thread, and two sessions reading the lessons at once (a
class arriving) raised "SystemError: AST constructor recursion depth mismatch", which
killed a session: its browser got no frame (found by ``bench --classroom``)."""

MAX_LINE_CHARS = 2000
"""Longest line of a lesson file [characters]."""
MISSING_FRAMES = 5
"""Refreshes a check may wait for a readout it names before this is reported."""

log = logging.getLogger(__name__)


class BadLesson(SandboxError):
    """A lesson file that cannot be used (the message names file and line)."""


class UnknownLesson(SandboxError):
    """No lesson has that name."""


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
        return _truth(tree.body, values, initial)


@lru_cache(maxsize=256)
def _compiled(source: str) -> Check:
    return compile_check(source)


@dataclass(frozen=True)
class Step:
    """One step of a lesson (see the module doc for each field)."""

    title: str
    text: str
    line: int
    preset: tuple[tuple[str, float], ...] = ()
    show: tuple[str, ...] = ()
    plots: tuple[str, ...] = ()
    arrows: tuple[str, ...] = ()
    questions: tuple[tuple[str, str], ...] = ()
    check: Check | None = None
    success: str = ""
    hints: tuple[str, ...] = ()
    solution: str = ""
    goal: str = ""


@dataclass(frozen=True)
class Lesson:
    """A lesson: front matter and steps."""

    name: str
    scene: str
    title: str
    level: str
    steps: tuple[Step, ...]
    path: Path = field(compare=False)
    number: int = 99

    def for_scene(self, scene: str) -> bool:
        """True when the lesson runs on ``scene``."""
        return self.scene in (scene, ANY_SCENE)


# -- checks ---------------------------------------------------------------------------------
MAX_CHECK_CHARS = 300
"""Longest check [characters]."""
MAX_CHECK_NODES = 80
"""Most syntax nodes (numbers, names, operators, calls) in one check."""
MAX_CHECK_DEPTH = 32
"""Deepest nesting of operations and parentheses in one check."""
MAX_LITERAL = 1e15
"""Largest number written in a check (in absolute value)."""
MAX_EXPONENT = 64.0
"""Largest exponent of ``**`` (in absolute value), written or live."""
MAX_ARGUMENTS = 8
"""Most arguments of ``min`` and ``max``."""

_CHECK_CHARS = re.compile(r"[A-Za-z0-9_ .+\-*/()<>=!,]*")
_COMPARE = {
    ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
    ast.Eq: operator.eq, ast.NotEq: operator.ne,
}  # fmt: skip
_ARITHMETIC = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)
_FUNCTIONS = ("abs", "min", "max", "initial")
_NAMED: dict[type, str] = {
    ast.Attribute: "'.' (attribute access)", ast.Starred: "'*' (unpacking)",
    ast.FloorDiv: "'//'", ast.IfExp: "'if ... else'", ast.Invert: "'~'",
    ast.BitAnd: "'&'", ast.BitOr: "'|'", ast.BitXor: "'^'", ast.LShift: "'<<'",
    ast.RShift: "'>>'", ast.Subscript: "indexing",
}  # fmt: skip


class CheckError(ArithmeticError):
    """A check that cannot be computed: refused at load time when the numbers are written in
    the check, caught at run time when they come from live readouts.

    Attributes:
        french: The same problem in French, for the lesson panel.
    """

    def __init__(self, message: str, french: str) -> None:
        super().__init__(message)
        self.french = french


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
        if not all(type(op) in _COMPARE for op in node.ops):
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
                _number(node, {}, {})
            elif isinstance(node, ast.BinOp) and _constant(node.right):
                right = _number(node.right, {}, {})  # x / 0, x ** 1000
                if isinstance(node.op, ast.Div) and right == 0:
                    raise CheckError("division by zero", "division par zéro")
                if isinstance(node.op, ast.Pow):
                    _power(1.0, right)
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


def _finite(result: float, *inputs: float) -> float:
    if not math.isfinite(result) and all(math.isfinite(x) for x in inputs):
        raise CheckError("the result overflows", "résultat trop grand (dépassement)")
    return result


def _power(a: float, b: float) -> float:
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
        return _power(a, b)
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


def _truth(node: ast.AST, values: Mapping[str, float], initial: Mapping[str, float]) -> bool:
    """The value of a validated condition node."""
    if isinstance(node, ast.BoolOp):
        if isinstance(node.op, ast.And):
            return all(_truth(v, values, initial) for v in node.values)
        return any(_truth(v, values, initial) for v in node.values)
    if isinstance(node, ast.UnaryOp):
        return not _truth(node.operand, values, initial)
    if isinstance(node, ast.Compare):
        left = _number(node.left, values, initial)
        for op, comp in zip(node.ops, node.comparators, strict=True):
            right = _number(comp, values, initial)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True
    raise CheckError(f"cannot test {type(node).__name__}", "condition non calculable")


# -- formulas -------------------------------------------------------------------------------
_SYMBOLS = {
    "alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "Delta": "Δ", "theta": "θ",
    "lambda": "λ", "mu": "μ", "pi": "π", "rho": "ρ", "sigma": "σ", "tau": "τ", "phi": "φ",
    "psi": "ψ", "omega": "ω", "Omega": "Ω", "Gamma": "Γ", "wedge": "∧", "times": "×",
    "cdot": "·", "le": "≤", "ge": "≥", "approx": "≈", "neq": "≠", "infty": "∞", "in": "∈",
    "to": "→", "otimes": "⊗", "sum": "Σ", "quad": " ", "{": "{", "}": "}", "|": "‖",
    "partial": "∂", "pm": "±", "ll": "≪", "gg": "≫", "Sigma": "Σ", "Lambda": "Λ",
    "cos": "cos", "sin": "sin", "tan": "tan", "ln": "ln", "exp": "exp", "dot": "˙",
    "nabla": "∇", "cdots": "⋯", "ldots": "…", "Rightarrow": "⇒", "iff": "⇔",
}  # fmt: skip
_GROUP = r"\{([^{}]*)\}"


def formula_html(tex: str) -> str:
    """A LaTeX subset as HTML: Greek letters and operators, ``_{}``/``^{}``, ``\\frac``,
    ``\\sqrt``, ``\\vec``/``\\overrightarrow`` (arrow above), ``\\mathrm``, ``\\text``.

    The formula is text: ``<``, ``>`` and ``&`` are escaped first, so the only tags in the
    result are the ``<i>``, ``<sub>`` and ``<sup>`` made here.

    Raises:
        ValueError: an unknown command (named).
    """
    s = html.escape(tex, quote=False)
    for _ in range(4):  # nested groups, innermost first
        s = re.sub(r"\\frac" + _GROUP + _GROUP, r"(\1)/(\2)", s)
        s = re.sub(r"\\sqrt" + _GROUP, r"√(\1)", s)
        s = re.sub(r"\\(?:vec|overrightarrow)" + _GROUP, lambda m: m.group(1) + "\u20d7", s)
        s = re.sub(r"\\(?:mathrm|text|mathbf|operatorname)" + _GROUP, r"\1", s)
        s = re.sub(r"_" + _GROUP, r"<sub>\1</sub>", s)
        s = re.sub(r"\^" + _GROUP, r"<sup>\1</sup>", s)
    s = re.sub(r"_([A-Za-z0-9])", r"<sub>\1</sub>", s)
    s = re.sub(r"\^([A-Za-z0-9])", r"<sup>\1</sup>", s)

    def symbol(m: re.Match[str]) -> str:
        name = m.group(1)
        if name not in _SYMBOLS:
            raise ValueError(f"unknown formula command \\{name[:40]}")
        return _SYMBOLS[name]

    s = re.sub(r"\\([A-Za-z]+|[{}|])", symbol, s)
    s = s.replace("{", "").replace("}", "")
    return f"<i>{s}</i>"


_FORMULA = re.compile(r"\$([^$]+)\$")
_SLOT = "\ue000"  # stands for a rendered formula while the Markdown around it is cleaned
_SLOT_RE = re.compile(_SLOT + r"(\d+)" + _SLOT)
_DESTINATION = re.compile(r"\]\(")
_SAFE_URL = re.compile(r"[ \t]*\n?[ \t]*https?://", re.IGNORECASE)
_DEFINITION = re.compile(r"\[(?=[^\]\n]*\]:)")


def _unlink(text: str) -> str:
    """Break every Markdown link or image whose address is not ``http(s)://`` (it stays
    as text), and every reference definition (``[x]: url``)."""
    out = []
    pos = 0
    for m in _DESTINATION.finditer(text):
        if not _SAFE_URL.match(text, m.end()):
            out.append(text[pos : m.start()] + "]\\(")
            pos = m.end()
    out.append(text[pos:])
    return _DEFINITION.sub(r"\\[", "".join(out))


def render_text(text: str) -> str:
    """Lesson Markdown for viser's Markdown: every ``$...$`` formula rendered by
    :func:`formula_html`, raw HTML shown as text (``<`` escaped), links and images kept
    only towards ``http(s)://`` addresses.

    Raises:
        ValueError: an unknown formula command (named).
    """
    text = text.replace(_SLOT, "")
    formulas: list[str] = []

    def slot(m: re.Match[str]) -> str:
        formulas.append(formula_html(m.group(1)))
        return f"{_SLOT}{len(formulas) - 1}{_SLOT}"

    text = _FORMULA.sub(slot, text)
    text = _unlink(text.replace("<", "&lt;"))
    return _SLOT_RE.sub(lambda m: formulas[int(m.group(1))], text)


# -- loading --------------------------------------------------------------------------------
def _csv(value: str) -> tuple[str, ...]:
    return tuple(v.strip() for v in value.split(",") if v.strip())


def _fail(path: Path, line: int, message: str) -> BadLesson:
    return BadLesson(f"{path}:{line}: {message}")


def read_lesson(path: Path) -> str:
    """The text of a lesson file, read with a size bound.

    Raises:
        BadLesson: not a regular file, unreadable, above :data:`MAX_LESSON_BYTES`, or not
            UTF-8.
    """
    try:
        if not path.is_file():
            raise _fail(path, 1, "not a regular file; a lesson is a Markdown text file")
        with path.open("rb") as stream:
            data = stream.read(MAX_LESSON_BYTES + 1)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise _fail(
            path, 1, f"cannot read the file ({reason}); check it exists and is readable"
        ) from None
    if len(data) > MAX_LESSON_BYTES:
        raise _fail(
            path, 1, f"the file is larger than {MAX_LESSON_BYTES // 1024} KiB; split the lesson"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise _fail(path, line, "the file is not UTF-8 text; save it as UTF-8") from None


def _lines(path: Path, text: str) -> list[str]:
    if len(text) > MAX_LESSON_BYTES or len(text.encode("utf-8", "replace")) > MAX_LESSON_BYTES:
        raise _fail(
            path, 1, f"the file is larger than {MAX_LESSON_BYTES // 1024} KiB; split the lesson"
        )
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    for number, line in enumerate(lines, start=1):
        if len(line) > MAX_LINE_CHARS:
            raise _fail(
                path,
                number,
                f"the line has {len(line)} characters (at most {MAX_LINE_CHARS}); break it",
            )
        if "\x00" in line:
            raise _fail(path, number, "NUL byte: this is not a text file; save it as UTF-8 text")
        hidden = _hidden_character(line)
        if hidden is not None:
            column, what = hidden
            raise _fail(
                path,
                number,
                f"{what} at column {column}: a lesson is plain text (it would reach the "
                "terminal of 'sandbox list' and the page as it is); delete it",
            )
    return lines


BIDI_CONTROLS = frozenset(
    "\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069"
)
"""Characters that reorder the text around them (Trojan Source): the words a reader sees
are not the words the file holds."""


def _hidden_character(line: str) -> tuple[int, str] | None:
    """(column, description) of the first control character (a tab is allowed) or
    bidirectional control in ``line``, or None. Other invisible characters a French text
    needs (no-break spaces) stay allowed."""
    for column, char in enumerate(line, start=1):
        if char in BIDI_CONTROLS:
            return column, f"bidirectional control U+{ord(char):04X}"
        if char != "\t" and (char < " " or "\x7f" <= char <= "\x9f"):
            return column, f"control character U+{ord(char):04X}"
    return None


def parse(path: Path, text: str | None = None) -> Lesson:
    """Read one lesson file (names are checked by :func:`validate`).

    Raises:
        BadLesson: naming ``file:line`` and the fix.
    """
    lines = _lines(path, read_lesson(path) if text is None else text)
    if lines[0].strip() != "---":
        raise _fail(path, 1, "a lesson starts with a front matter between two '---' lines")
    try:
        end = next(i for i in range(1, len(lines)) if lines[i].strip() == "---")
    except StopIteration:
        raise _fail(path, 1, "the front matter is not closed by a '---' line") from None
    meta: dict[str, str] = {}
    for i in range(1, end):
        key, sep, value = lines[i].partition(":")
        if not sep:
            raise _fail(
                path, i + 1, f"expected 'key: value' in the front matter, got {lines[i][:80]!r}"
            )
        meta[key.strip()] = value.strip()
    for key in ("scene", "title", "level"):
        if not meta.get(key):
            raise _fail(path, 1, f"the front matter needs '{key}:'")
    heads = [i for i in range(end + 1, len(lines)) if lines[i].startswith("## ")]
    if not heads:
        raise _fail(path, end + 2, "a lesson needs at least one step ('## Title')")
    steps = []
    for k, start in enumerate(heads):
        stop = heads[k + 1] if k + 1 < len(heads) else len(lines)
        steps.append(_step(path, lines, start, stop))
    try:
        number = int(meta.get("number", "99"))
    except ValueError:
        raise _fail(path, 1, f"number: expects an integer, got {meta['number'][:40]!r}") from None
    return Lesson(
        path.stem, meta["scene"], meta["title"], meta["level"], tuple(steps), path, number
    )


def _pairs(value: str, what: str) -> tuple[tuple[str, float], ...]:
    pairs = []
    for item in _csv(value):
        name, sep, number = item.partition("=")
        if not sep or not name.strip():
            raise ValueError(f"{what} expects NAME=VALUE, got {item[:40]!r}")
        try:
            x = float(number)
        except ValueError:
            raise ValueError(
                f"{name.strip()[:40]!r} expects a number, got {number[:40]!r}"
            ) from None
        if not math.isfinite(x):
            raise ValueError(f"{name.strip()[:40]!r} expects a finite number, got {number[:40]!r}")
        pairs.append((name.strip(), x))
    return tuple(pairs)


def _step(path: Path, lines: list[str], start: int, stop: int) -> Step:
    title = lines[start][3:].strip()
    if not title:
        raise _fail(path, start + 1, "a step needs a title after '## '")
    preset: tuple[tuple[str, float], ...] = ()
    lists: dict[str, tuple[str, ...]] = {}
    questions: list[tuple[str, str]] = []
    hints: list[str] = []
    check: Check | None = None
    success = solution = goal = ""
    seen: set[str] = set()
    i = start + 1
    while i < stop and re.match(r"^[a-z]+:", lines[i]):
        key, _, value = lines[i].partition(":")
        key, value = key.strip(), value.strip()
        where = i + 1
        if key not in DIRECTIVES:
            raise _fail(
                path, where, f"unknown directive {key!r}; use one of: {choices(DIRECTIVES)}"
            )
        if key in seen and key not in REPEATABLE:
            raise _fail(path, where, f"{key}: is given twice in this step; keep one")
        seen.add(key)
        try:
            if key == "preset":
                preset = _pairs(value, "preset")
            elif key in ("show", "plots", "arrows"):
                lists[key] = _csv(value)
            elif key == "question":
                question, sep, answer = value.partition("| answer:")
                if not sep or not question.strip() or not answer.strip():
                    raise ValueError("expects 'QUESTION | answer: ANSWER'")
                questions.append((render_text(question.strip()), render_text(answer.strip())))
            elif key == "hint":
                hints.append(render_text(value))
            elif key == "check":
                check = compile_check(value, f"{path.name}:{where}")
            elif key == "success":
                success = render_text(value)
            elif key == "goal":
                goal = render_text(value)
            elif key == "solution":
                solution = value
                if value and not value.startswith("@"):
                    _pairs(value, "solution")
        except (ValueError, SyntaxError) as exc:
            raise _fail(path, where, f"bad {key}: {exc}") from None
        i += 1
    body = "\n".join(lines[i:stop]).strip()
    try:
        rendered = render_text(body)
    except ValueError as exc:
        raise _fail(path, start + 1, f"in this step: {exc}") from None
    return Step(
        title=title,
        text=rendered,
        line=start + 1,
        preset=preset,
        show=lists.get("show", ()),
        plots=lists.get("plots", ()),
        arrows=lists.get("arrows", ()),
        questions=tuple(questions),
        check=check,
        success=success,
        hints=tuple(hints),
        solution=solution,
        goal=goal,
    )


def validate(lesson: Lesson) -> None:
    """Check every name against the scene: presets (names and ranges), solutions, shown
    readouts, checks, arrows.

    Raises:
        BadLesson: naming the file, the step's line and the valid names.
    """
    from sandbox.physics.readouts import GENERIC_NAMES
    from sandbox.scenes import SCENES

    if lesson.scene == ANY_SCENE:
        scenes = list(SCENES.values())
        params = {}
        readouts = set(GENERIC_NAMES)
    elif lesson.scene in SCENES:
        scene = SCENES[lesson.scene]
        scenes = [scene]
        params = {p.name: p for p in scene.params}
        readouts = set(GENERIC_NAMES) | {r.name for r in scene.readouts}
    else:
        raise _fail(
            lesson.path,
            2,
            f"unknown scene {lesson.scene[:80]!r}; use one of: {choices(SCENES)}, any",
        )
    arrows = {a.name for s in scenes for a in s.arrows}
    for step in lesson.steps:
        pairs = list(step.preset)
        if step.solution and not step.solution.startswith("@"):
            pairs += _pairs(step.solution, "solution")
        for name, value in pairs:
            if name not in params:
                raise _fail(
                    lesson.path,
                    step.line,
                    f"preset names no parameter {name[:80]!r}; valid: {choices(params)}",
                )
            try:
                params[name].check(value)
            except BadParameter as exc:
                raise _fail(lesson.path, step.line, f"preset {exc}") from None
        used = set(step.show) | set(step.plots)
        if step.check is not None:
            used |= set(step.check.names) | set(step.check.initial)
        bad = sorted(used - readouts)
        if bad:
            raise _fail(
                lesson.path,
                step.line,
                f"no readout {bad[0][:80]!r}; valid: {choices(sorted(readouts))}",
            )
        bad = [a for a in step.arrows if a not in arrows]
        if bad:
            raise _fail(
                lesson.path, step.line, f"no arrow {bad[0][:80]!r}; valid: {choices(arrows)}"
            )


class Catalogue(NamedTuple):
    """The lessons found: those that load, and the refusal of each one that does not."""

    lessons: dict[str, Lesson]
    errors: tuple[BadLesson, ...]


LESSON_SUFFIX = ".md"
"""How the name of a lesson file ends (``sandbox serve FILE.md`` opens a lesson)."""

_opened: dict[str, Lesson] = {}
"""Lesson files opened by path in this process (:func:`open_lesson_file`), by name."""


def is_lesson_file(target: str | Path) -> bool:
    """True when ``target`` names a lesson file (``*.md``), not a scene or an MJCF file."""
    return str(target).lower().endswith(LESSON_SUFFIX)


def open_lesson_file(path: Path) -> Lesson:
    """Parse and validate the lesson file ``path`` (anywhere, named anyhow) and offer it
    with the shipped lessons (:func:`catalogue`) to the pages this process serves, in
    place of a shipped lesson of the same name.

    Raises:
        BadLesson: no such file, or naming ``file:line`` and the fix.
    """
    if not path.exists():
        raise BadLesson(
            f"no lesson file {shown(str(path), 200)}; check the path (or name a shipped "
            "lesson: sandbox list)"
        )
    lesson = parse(path)
    validate(lesson)
    _opened[lesson.name] = lesson
    catalogue.cache_clear()
    return lesson


@lru_cache(maxsize=1)
def catalogue() -> Catalogue:
    """Every lesson in ``lessons/`` parsed and validated, and the files refused (the web
    app opens the good ones and shows the refusals; the CLI refuses them all); with the
    lesson files opened by :func:`open_lesson_file`, which replace the shipped ones of
    their name."""
    found = list(_opened.values())
    errors = []
    try:
        paths = sorted(data_dir("lessons").glob("*.md"))
    except FileNotFoundError:
        paths = []
    for path in paths:
        if path.stem in _opened:
            continue
        try:
            lesson = parse(path)
            validate(lesson)
        except BadLesson as exc:
            errors.append(exc)
            continue
        found.append(lesson)
    ordered = sorted(found, key=lambda x: (x.number, x.name))
    return Catalogue({lesson.name: lesson for lesson in ordered}, tuple(errors))


def lessons() -> dict[str, Lesson]:
    """Every lesson in ``lessons/`` by name, parsed and validated.

    Raises:
        BadLesson: the first file refused (``file:line`` and the fix).
    """
    found, errors = catalogue()
    if errors:
        raise errors[0]
    return found


def get_lesson(name: str) -> Lesson:
    """The lesson called ``name`` (UnknownLesson listing the valid names)."""
    found = lessons()
    if name not in found:
        raise UnknownLesson(f"unknown lesson {name!r}; lessons: {choices(found) or 'none'}")
    return found[name]


def solution_values(step: Step, scene_name: str, values: Mapping[str, float]) -> dict[str, float]:
    """The parameter values of a step's ``solution`` (``@helper`` calls the scene's extra).

    Raises:
        BadLesson: an unknown helper or a malformed pair.
    """
    from sandbox.scenes import get_scene

    text = step.solution.strip()
    if not text:
        return {}
    if text.startswith("@"):
        helper = get_scene(scene_name).extra.get(text[1:])
        if not callable(helper):
            raise BadLesson(f"step {step.title!r}: the scene has no helper {text[:80]!r}")
        return {k: float(v) for k, v in helper(values).items()}
    try:
        return dict(_pairs(text, "solution"))
    except ValueError as exc:
        raise BadLesson(f"step {step.title!r}: {exc}") from None


_REPORTED: set[tuple[str, str]] = set()
"""Check errors already logged by this process (each is logged once)."""
MAX_REPORTED = 1000
"""Most distinct check errors logged by one process."""


class Progress:
    """Where a student is in a lesson: step, start values, success, hints shown.

    Pure state (no UI): the web panel asks it what to apply and what to show.

    Attributes:
        error: Why the step's check cannot be computed (French, ending with ``file:line``),
            None while it can. Set by the first failure of the step and kept until the
            student changes step; a later evaluation that succeeds still counts.
    """

    def __init__(self, lesson: Lesson) -> None:
        self.lesson = lesson
        self.index = 0
        self.initial: dict[str, float] | None = None
        self.passed: set[int] = set()
        self.hints_shown = 0
        self.error: str | None = None
        self._missing = 0

    @property
    def step(self) -> Step:
        return self.lesson.steps[self.index]

    def go(self, index: int) -> Step:
        """Enter step ``index`` (clamped); the caller applies its presets."""
        self.index = min(max(index, 0), len(self.lesson.steps) - 1)
        self.initial = None
        self.hints_shown = 0
        self.error = None
        self._missing = 0
        return self.step

    def ready(self, current: Mapping[str, float]) -> bool:
        """True once the step's presets are in force in the parameter values ``current``."""
        return all(current.get(n) == v for n, v in self.step.preset)

    def observe(self, readouts: Mapping[str, float], params: Mapping[str, float]) -> bool | None:
        """Feed the readouts shown now; returns the check's result (None: no check, not
        ready yet, or the check cannot be computed: see :attr:`error`)."""
        check = self.step.check
        if self.initial is None and not self.ready(params):
            return None
        if check is not None:
            missing = [n for n in (*check.names, *check.initial) if n not in readouts]
            if missing:  # a frame with fewer readouts (the lesson was just opened)
                self._missing += 1
                if self._missing >= MISSING_FRAMES:
                    name = missing[0]
                    self._report(
                        check,
                        CheckError(f"no readout {name!r}", f"grandeur « {name} » absente"),
                    )
                return None
            self._missing = 0
        if self.initial is None:
            self.initial = dict(readouts)
        if check is None:
            return None
        try:
            ok = check.evaluate(readouts, self.initial)
        except CheckError as exc:
            self._report(check, exc)
            return None
        if ok:
            self.passed.add(self.index)
        return ok

    def _report(self, check: Check, exc: CheckError) -> None:
        if self.error is not None:
            return
        where = check.where or f"{self.lesson.path.name}:{self.step.line}"
        self.error = f"{exc.french} ({where})"
        key = (where, str(exc))
        if key not in _REPORTED and len(_REPORTED) < MAX_REPORTED:
            _REPORTED.add(key)
            log.warning("lesson check %s (%s) cannot be computed: %s", where, check.source, exc)

    def next_hint(self) -> str | None:
        """Reveal one more hint (None when all are shown)."""
        if self.hints_shown >= len(self.step.hints):
            return None
        self.hints_shown += 1
        return self.step.hints[self.hints_shown - 1]
