"""A lesson step's goal in words, with a progress bar: "Palier A : 54,4 N → objectif < 0,544 N".

The goal is read from the step's compiled check, so it works for every lesson file: each
comparison of a readout with a bound that reads no live value (``bearing_A < 0.01 *
initial(bearing_A)``, ``slip_velocity > 0.05``), joined by ``and``, becomes one line and
one bar. A check of another shape (``or``, two live readouts compared...) is written in
words (readout labels, "et", "ou", "au départ") without a bar. A ``goal:`` line in the
lesson file replaces the sentence; the bars stay.

The bar measures the way from the value at the step's start to the bound: linearly, or on
a logarithmic scale when the bound is 10 times or more away from the start (dividing a
force by 100: a tenth of the force is half the way).
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from sandbox.lessons import Check, CheckError, number_of
from sandbox.web.client.text import html_text, number
from sandbox.written import written

SYMBOLS: dict[type, str] = {
    ast.Lt: "<", ast.LtE: "≤", ast.Gt: ">", ast.GtE: "≥", ast.Eq: "=", ast.NotEq: "≠",
}  # fmt: skip
_FLIPPED: dict[type, type] = {
    ast.Lt: ast.Gt, ast.LtE: ast.GtE, ast.Gt: ast.Lt, ast.GtE: ast.LtE, ast.Eq: ast.Eq,
    ast.NotEq: ast.NotEq,
}  # fmt: skip
_REACHED: dict[type, Callable[[float, float], bool]] = {
    ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
}  # fmt: skip
_ARITHMETIC = {ast.Add: "+", ast.Sub: "−", ast.Mult: "×", ast.Div: "/", ast.Pow: "^"}
LOG_RATIO = 10.0
"""A bar uses a logarithmic scale when the bound and the start differ by this factor."""
BAR_COLOURS = ("#1f6fd1", "#2e8b3e")
"""Bar fill while in progress, and once the part is reached."""


@dataclass(frozen=True)
class Part:
    """One comparison of a goal: ``readout op bound`` (``absolute``: ``abs(readout)``)."""

    readout: str
    op: type
    bound: ast.expr
    absolute: bool = False

    def value(self, values: Mapping[str, float]) -> float:
        """The readout's value now (absolute when the check takes ``abs``)."""
        x = float(values.get(self.readout, math.nan))
        return abs(x) if self.absolute else x


def _live(node: ast.AST) -> bool:
    """True when ``node`` reads a live readout (``initial(x)`` is not live)."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        if node.func.id == "initial":
            return False
        return any(_live(a) for a in node.args)
    if isinstance(node, ast.Name):
        return True
    return any(_live(c) for c in ast.iter_child_nodes(node))


def _readout(node: ast.AST) -> tuple[str, bool] | None:
    """(name, absolute) when ``node`` is ``name`` or ``abs(name)``."""
    if isinstance(node, ast.Name):
        return node.id, False
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id == "abs"
        and len(node.args) == 1
        and isinstance(node.args[0], ast.Name)
    ):
        return node.args[0].id, True
    return None


def parts(check: Check) -> tuple[Part, ...] | None:
    """The comparisons of ``check`` as :class:`Part` (None: the check has another shape)."""
    tree = check.tree
    if tree is None:
        return None
    body = tree.body
    terms = body.values if isinstance(body, ast.BoolOp) and isinstance(body.op, ast.And) else [body]
    out = []
    for term in terms:
        if not isinstance(term, ast.Compare) or len(term.ops) != 1:
            return None
        left, op, right = term.left, type(term.ops[0]), term.comparators[0]
        found = _readout(left)
        if found is None or _live(right):
            found, left, right = _readout(right), right, left
            op = _FLIPPED[op]
            if found is None or _live(right):
                return None
        out.append(Part(found[0], op, right, found[1]))
    return tuple(out)


def fraction(part: Part, now: float, start: float, bound: float) -> float | None:
    """How far ``now`` has gone from ``start`` towards ``bound``, in [0, 1] (1 only when
    reached);
    None for ``=`` and ``≠`` goals or values that are not numbers."""
    if not all(math.isfinite(x) for x in (now, start, bound)):
        return None
    if part.op in (ast.Eq, ast.NotEq):
        return None
    below = part.op in (ast.Lt, ast.LtE)
    if _REACHED[part.op](now, bound):
        return 1.0
    if (start <= bound) if below else (start >= bound):
        return 0.0  # the start already met the bound: the value went the wrong way since
    lo, hi = sorted((start, bound))
    if lo > 0 and hi / lo >= LOG_RATIO and now > 0:
        done = math.log(start / now) / math.log(start / bound)
    else:
        done = (start - now) / (start - bound)
    return min(max(done, 0.0), 0.99)  # 100 % only once reached


@dataclass(frozen=True)
class Line:
    """One part of a goal as shown: the sentence and the bar's fill (None: no bar)."""

    text: str
    done: float | None


class Words:
    """How readouts are written: French label (else the name), and the value as every
    view writes it (:func:`sandbox.written.written`) from its contract unit and the
    scene's round-off by readout in that unit (values at or under it are written 0)."""

    def __init__(
        self,
        labels: Mapping[str, str],
        units: Mapping[str, str],
        zeros: Mapping[str, float] | None = None,
    ) -> None:
        self.labels = labels
        self.units = units  # contract units
        self.zeros = zeros or {}

    def label(self, name: str) -> str:
        return self.labels.get(name) or name

    def quantity(self, value: float, name: str) -> str:
        unit = self.units.get(name, "")
        return str(written(name, value, unit, zero=self.zeros.get(name, 0.0)))


def lines(
    check: Check,
    words: Words,
    values: Mapping[str, float],
    initial: Mapping[str, float] | None,
    *,
    brief: bool = False,
) -> tuple[Line, ...]:
    """The goal of ``check`` as sentences (plain text) with the progress of each part.

    Args:
        check: The step's check.
        words: Labels and units of the readouts.
        values: The readouts now.
        initial: The readouts at the step's start (None until the step's presets are in
            force: the bounds that need them are then not written yet).
        brief: Only "label : value" before each bar (the lesson writes its own goal).
    """
    found = parts(check)
    if found is None:
        return () if brief else (Line(describe(check, words), None),)
    out = []
    for part in found:
        name = words.label(part.readout)
        if part.absolute:
            name = f"|{name}|"
        now = part.value(values)
        try:
            bound = number_of(part.bound, values, initial) if initial is not None else math.nan
        except CheckError:
            bound = math.nan
        target = words.quantity(bound, part.readout) if math.isfinite(bound) else "…"
        text = f"{name} : {words.quantity(now, part.readout)}"
        if not brief:
            text += f" → objectif {SYMBOLS[part.op]} {target}"
        start = part.value(initial) if initial is not None else math.nan
        out.append(Line(text, fraction(part, now, start, bound)))
    return tuple(out)


def describe(check: Check, words: Words) -> str:
    """A check written in words: labels for names, "et"/"ou"/"non", "au départ"."""
    tree = check.tree
    return _words(tree.body, words) if tree is not None else check.source


def _words(node: ast.AST, words: Words) -> str:
    if isinstance(node, ast.BoolOp):
        joint = " et " if isinstance(node.op, ast.And) else " ou "
        return joint.join(_words(v, words) for v in node.values)
    if isinstance(node, ast.UnaryOp):
        inner = _words(node.operand, words)
        if isinstance(node.op, ast.Not):
            return f"non ({inner})"
        return f"−{inner}" if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.Compare):
        items = [_words(node.left, words)]
        for op, right in zip(node.ops, node.comparators, strict=True):
            items += [SYMBOLS[type(op)], _words(right, words)]
        return " ".join(items)
    if isinstance(node, ast.BinOp):
        symbol = _ARITHMETIC.get(type(node.op), "?")
        return f"({_words(node.left, words)} {symbol} {_words(node.right, words)})"
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        return number(float(node.value), 6)
    if isinstance(node, ast.Name):
        return words.label(node.id)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        args = [_words(a, words) for a in node.args]
        if node.func.id == "initial":
            return f"{args[0]} au départ"
        if node.func.id == "abs":
            return f"|{args[0]}|"
        return f"{node.func.id}({' ; '.join(args)})"
    return "?"


def goal_html(
    shown: tuple[Line, ...],
    *,
    state: str,
    sentence: str = "",
) -> str:
    """The goal block: "Objectif" and the step's state, each line and its bar.

    Args:
        shown: From :func:`lines` (plain text: escaped here).
        state: "En cours", "Réussi"... (plain text).
        sentence: The lesson's own ``goal:`` (already safe HTML from ``render_text``), shown
            instead of the sentences; the bars stay, labelled by their readout.
    """
    rows = [f'<div style="font-weight:600;margin-bottom:0.3em">Objectif — {html_text(state)}</div>']
    if sentence:
        rows.append(f'<div style="margin-bottom:0.3em">{sentence}</div>')
    for line in shown:
        rows.append(f'<div style="margin-top:0.35em">{html_text(line.text, 400)}</div>')
        if line.done is not None:
            rows.append(_bar(line.done))
    style = "line-height:1.35;padding:0 0.75em"
    return f'<div class="sandbox-goal" style="{style}">' + "".join(rows) + "</div>"


def _bar(done: float) -> str:
    percent = round(100 * min(max(done, 0.0), 1.0))
    colour = BAR_COLOURS[1] if percent >= 100 else BAR_COLOURS[0]
    return (
        '<div style="display:flex;align-items:center;gap:0.5em">'
        '<div role="progressbar" aria-valuemin="0" aria-valuemax="100" '
        f'aria-valuenow="{percent}" style="flex:1;height:0.8em;border:1px solid #888;'
        'border-radius:0.4em;background:#e8e8e8;overflow:hidden">'
        f'<div style="width:{percent}%;height:100%;background:{colour}"></div></div>'
        f'<span style="min-width:3.2em;text-align:right">{percent} %</span></div>'
    )
