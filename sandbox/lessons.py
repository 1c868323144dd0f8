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
    success: Well done ...
    hint: Try ...
    solution: @balancing_solution      (or NAME=VALUE, ...: a state where the check passes)

    Free Markdown text, formulas between $...$ (a LaTeX subset rendered as HTML).

Directives are the ``key: value`` lines right under the step's heading. A check is a
Python-like condition on readouts (``and``, ``or``, ``not``, comparisons, + - * /,
``abs``, ``min``, ``max``, and ``initial(name)``: the value when the step began).
Any mistake raises :class:`BadLesson` naming the file and line.
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from sandbox.data import data_dir
from sandbox.errors import SandboxError, choices

ANY_SCENE = "any"
DIRECTIVES = ("preset", "show", "plots", "arrows", "question", "check", "success", "hint")
DIRECTIVES += ("solution",)


class BadLesson(SandboxError):
    """A lesson file that cannot be used (the message names file and line)."""


class UnknownLesson(SandboxError):
    """No lesson has that name."""


@dataclass(frozen=True)
class Check:
    """A live condition on readouts.

    Attributes:
        source: The condition as written.
        names: Readouts it reads.
        initial: Readouts whose value at the step's start it uses.
    """

    source: str
    names: tuple[str, ...]
    initial: tuple[str, ...]

    def evaluate(self, values: Mapping[str, float], initial: Mapping[str, float]) -> bool:
        """True when the condition holds for ``values`` (``initial``: at the step's start)."""
        return bool(_evaluate(_parse(self.source), values, initial))


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
_ALLOWED = (
    ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.UnaryOp, ast.Not, ast.USub, ast.UAdd,
    ast.BinOp, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.Compare, ast.Lt, ast.LtE,
    ast.Gt, ast.GtE, ast.Eq, ast.NotEq, ast.Name, ast.Load, ast.Constant, ast.Call,
)  # fmt: skip
_FUNCTIONS: dict[str, Callable[..., float]] = {"abs": abs, "min": min, "max": max}


@lru_cache(maxsize=256)
def _parse(source: str) -> ast.Expression:
    tree = ast.parse(source, mode="eval")
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED):
            raise ValueError(f"{type(node).__name__} is not allowed in a check")
        if isinstance(node, ast.Constant) and not isinstance(node.value, (int, float)):
            raise ValueError(f"only numbers are allowed, not {node.value!r}")
        if isinstance(node, ast.Call):
            fn = node.func
            if not isinstance(fn, ast.Name) or fn.id not in (*_FUNCTIONS, "initial"):
                raise ValueError("only abs, min, max and initial(name) can be called")
            if fn.id == "initial" and (
                len(node.args) != 1 or not isinstance(node.args[0], ast.Name)
            ):
                raise ValueError("initial() takes one readout name")
    return tree


def _names(tree: ast.Expression) -> tuple[tuple[str, ...], tuple[str, ...]]:
    names, initial = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            if node.func.id == "initial":
                initial.add(node.args[0].id)  # type: ignore[attr-defined]
        elif isinstance(node, ast.Name) and node.id not in (*_FUNCTIONS, "initial"):
            names.add(node.id)
    return tuple(sorted(names)), tuple(sorted(initial))


def _evaluate(node: ast.AST, values: Mapping[str, float], initial: Mapping[str, float]) -> float:
    ev = lambda n: _evaluate(n, values, initial)  # noqa: E731
    if isinstance(node, ast.Expression):
        return ev(node.body)
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.Name):
        return values[node.id]
    if isinstance(node, ast.BoolOp):
        results = [bool(ev(v)) for v in node.values]
        return all(results) if isinstance(node.op, ast.And) else any(results)
    if isinstance(node, ast.UnaryOp):
        x = ev(node.operand)
        return (
            (not x)
            if isinstance(node.op, ast.Not)
            else (-x if isinstance(node.op, ast.USub) else x)
        )
    if isinstance(node, ast.BinOp):
        a, b = ev(node.left), ev(node.right)
        op = type(node.op)
        if op is ast.Div:
            return a / b if b != 0 else math.inf
        return {ast.Add: a + b, ast.Sub: a - b, ast.Mult: a * b, ast.Pow: a**b}[op]
    if isinstance(node, ast.Compare):
        left = ev(node.left)
        for op, comp in zip(node.ops, node.comparators, strict=True):
            right = ev(comp)
            ok = {
                ast.Lt: left < right,
                ast.LtE: left <= right,
                ast.Gt: left > right,
                ast.GtE: left >= right,
                ast.Eq: left == right,
                ast.NotEq: left != right,
            }
            if not ok[type(op)]:
                return False
            left = right
        return True
    if isinstance(node, ast.Call):
        fn = node.func.id  # type: ignore[attr-defined]
        if fn == "initial":
            return initial[node.args[0].id]  # type: ignore[attr-defined]
        return _FUNCTIONS[fn](*(ev(a) for a in node.args))
    raise ValueError(f"cannot evaluate {type(node).__name__}")


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

    Raises:
        ValueError: an unknown command (named).
    """
    s = tex
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
            raise ValueError(f"unknown formula command \\{name}")
        return _SYMBOLS[name]

    s = re.sub(r"\\([A-Za-z]+|[{}|])", symbol, s)
    s = s.replace("{", "").replace("}", "")
    return f"<i>{s}</i>"


def render_text(text: str) -> str:
    """Markdown with every ``$...$`` formula rendered by :func:`formula_html`."""
    return re.sub(r"\$([^$]+)\$", lambda m: formula_html(m.group(1)), text)


# -- loading --------------------------------------------------------------------------------
def _csv(value: str) -> tuple[str, ...]:
    return tuple(v.strip() for v in value.split(",") if v.strip())


def _fail(path: Path, line: int, message: str) -> BadLesson:
    return BadLesson(f"{path}:{line}: {message}")


def parse(path: Path, text: str | None = None) -> Lesson:
    """Read one lesson file (names are checked by :func:`validate`)."""
    text = path.read_text(encoding="utf-8") if text is None else text
    lines = text.splitlines()
    if not lines or lines[0].strip() != "---":
        raise _fail(path, 1, "a lesson starts with a front matter between two '---' lines")
    try:
        end = next(i for i in range(1, len(lines)) if lines[i].strip() == "---")
    except StopIteration:
        raise _fail(path, 1, "the front matter is not closed by a '---' line") from None
    meta: dict[str, str] = {}
    for i in range(1, end):
        key, sep, value = lines[i].partition(":")
        if not sep:
            raise _fail(path, i + 1, f"expected 'key: value' in the front matter, got {lines[i]!r}")
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
        raise _fail(path, 1, f"number: expects an integer, got {meta['number']!r}") from None
    return Lesson(
        path.stem, meta["scene"], meta["title"], meta["level"], tuple(steps), path, number
    )


def _step(path: Path, lines: list[str], start: int, stop: int) -> Step:
    fields: dict[str, object] = {"questions": [], "hints": []}
    i = start + 1
    while i < stop and re.match(r"^[a-z]+:", lines[i]):
        key, _, value = lines[i].partition(":")
        key, value = key.strip(), value.strip()
        where = i + 1
        if key not in DIRECTIVES:
            raise _fail(
                path, where, f"unknown directive {key!r}; use one of: {choices(DIRECTIVES)}"
            )
        try:
            if key == "preset":
                pairs = []
                for item in _csv(value):
                    name, sep, number = item.partition("=")
                    if not sep:
                        raise ValueError(f"preset expects NAME=VALUE, got {item!r}")
                    pairs.append((name.strip(), float(number)))
                fields["preset"] = tuple(pairs)
            elif key in ("show", "plots", "arrows"):
                fields[key] = _csv(value)
            elif key == "question":
                question, _, answer = value.partition("| answer:")
                fields["questions"].append((question.strip(), answer.strip()))  # type: ignore[union-attr]
            elif key == "hint":
                fields["hints"].append(value)  # type: ignore[union-attr]
            elif key == "check":
                names, initial = _names(_parse(value))
                fields["check"] = Check(value, names, initial)
            else:
                fields[key] = value
        except (ValueError, SyntaxError) as exc:
            raise _fail(path, where, f"bad {key}: {exc}") from None
        i += 1
    body = "\n".join(lines[i:stop]).strip()
    try:
        rendered = render_text(body)
        fields["success"] = render_text(str(fields.get("success", "")))
        fields["questions"] = [
            (render_text(q), render_text(a))
            for q, a in fields["questions"]  # type: ignore[attr-defined]
        ]
        fields["hints"] = [render_text(h) for h in fields["hints"]]  # type: ignore[attr-defined]
    except ValueError as exc:
        raise _fail(path, start + 1, f"in this step: {exc}") from None
    fields["questions"] = tuple(fields["questions"])  # type: ignore[arg-type]
    fields["hints"] = tuple(fields["hints"])  # type: ignore[arg-type]
    return Step(title=lines[start][3:].strip(), text=rendered, line=start + 1, **fields)  # type: ignore[arg-type]


def validate(lesson: Lesson) -> None:
    """Check every name against the scene: presets, shown readouts, checks, arrows.

    Raises:
        BadLesson: naming the file, the step's line and the valid names.
    """
    from sandbox.physics.readouts import GENERIC_NAMES
    from sandbox.scenes import SCENES

    if lesson.scene == ANY_SCENE:
        scenes = list(SCENES.values())
        params: set[str] = set()
        readouts = set(GENERIC_NAMES)
    elif lesson.scene in SCENES:
        scene = SCENES[lesson.scene]
        scenes = [scene]
        params = {p.name for p in scene.params}
        readouts = set(GENERIC_NAMES) | {r.name for r in scene.readouts}
    else:
        raise _fail(
            lesson.path, 2, f"unknown scene {lesson.scene!r}; use one of: {choices(SCENES)}, any"
        )
    arrows = {a.name for s in scenes for a in s.arrows}
    for step in lesson.steps:
        bad = [n for n, _ in step.preset if n not in params]
        if bad:
            raise _fail(
                lesson.path,
                step.line,
                f"preset names no parameter {bad[0]!r}; valid: {choices(params)}",
            )
        used = set(step.show) | set(step.plots)
        if step.check is not None:
            used |= set(step.check.names) | set(step.check.initial)
        bad = sorted(used - readouts)
        if bad:
            raise _fail(
                lesson.path, step.line, f"no readout {bad[0]!r}; valid: {choices(sorted(readouts))}"
            )
        bad = [a for a in step.arrows if a not in arrows]
        if bad:
            raise _fail(lesson.path, step.line, f"no arrow {bad[0]!r}; valid: {choices(arrows)}")


@lru_cache(maxsize=1)
def lessons() -> dict[str, Lesson]:
    """Every lesson in ``lessons/`` by name, parsed and validated."""
    try:
        folder = data_dir("lessons")
    except FileNotFoundError:
        return {}
    found = []
    for path in sorted(folder.glob("*.md")):
        lesson = parse(path)
        validate(lesson)
        found.append(lesson)
    return {lesson.name: lesson for lesson in sorted(found, key=lambda x: (x.number, x.name))}


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
            raise BadLesson(f"step {step.title!r}: the scene has no helper {text!r}")
        return {k: float(v) for k, v in helper(values).items()}
    out = {}
    for item in _csv(text):
        name, sep, number = item.partition("=")
        if not sep:
            raise BadLesson(f"step {step.title!r}: solution expects NAME=VALUE, got {item!r}")
        out[name.strip()] = float(number)
    return out


class Progress:
    """Where a student is in a lesson: step, start values, success, hints shown.

    Pure state (no UI): the web panel asks it what to apply and what to show.
    """

    def __init__(self, lesson: Lesson) -> None:
        self.lesson = lesson
        self.index = 0
        self.initial: dict[str, float] | None = None
        self.passed: set[int] = set()
        self.hints_shown = 0

    @property
    def step(self) -> Step:
        return self.lesson.steps[self.index]

    def go(self, index: int) -> Step:
        """Enter step ``index`` (clamped); the caller applies its presets."""
        self.index = min(max(index, 0), len(self.lesson.steps) - 1)
        self.initial = None
        self.hints_shown = 0
        return self.step

    def ready(self, current: Mapping[str, float]) -> bool:
        """True once the step's presets are in force in the parameter values ``current``."""
        return all(current.get(n) == v for n, v in self.step.preset)

    def observe(self, readouts: Mapping[str, float], params: Mapping[str, float]) -> bool | None:
        """Feed the readouts shown now; returns the check's result (None: no check yet)."""
        check = self.step.check
        if self.initial is None:
            if not self.ready(params):
                return None
            self.initial = dict(readouts)
        if check is None:
            return None
        try:
            ok = check.evaluate(readouts, self.initial)
        except (KeyError, ArithmeticError):
            return None
        if ok:
            self.passed.add(self.index)
        return ok

    def next_hint(self) -> str | None:
        """Reveal one more hint (None when all are shown)."""
        if self.hints_shown >= len(self.step.hints):
            return None
        self.hints_shown += 1
        return self.step.hints[self.hints_shown - 1]
