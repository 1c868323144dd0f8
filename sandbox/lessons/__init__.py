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

The package, one concept per module (each imports only those above it in this list):

- :mod:`~sandbox.lessons.evaluation`: how a check is computed (:class:`CheckError`);
- :mod:`~sandbox.lessons.checks`: the safe expression language (:func:`compile_check`);
- :mod:`~sandbox.lessons.markup`: Markdown and formulas (:func:`render_text`);
- :mod:`~sandbox.lessons.model`: :class:`Lesson`, :class:`Step`, :class:`BadLesson`;
- :mod:`~sandbox.lessons.reader`: the lesson-file parser (:func:`parse`);
- :mod:`~sandbox.lessons.validation`: names checked against the scene (:func:`validate`);
- :mod:`~sandbox.lessons.registry`: the catalogue of lessons (:func:`catalogue`);
- :mod:`~sandbox.lessons.progress`: a student's progress (:class:`Progress`).
"""

from __future__ import annotations

from sandbox.lessons.checks import (
    MAX_CHECK_CHARS,
    MAX_CHECK_DEPTH,
    MAX_CHECK_NODES,
    MAX_LITERAL,
    Check,
    compile_check,
)
from sandbox.lessons.evaluation import MAX_EXPONENT, CheckError, number_of
from sandbox.lessons.markup import formula_html, render_text
from sandbox.lessons.model import ANY_SCENE, BadLesson, Lesson, Step, UnknownLesson
from sandbox.lessons.progress import Progress
from sandbox.lessons.reader import MAX_LESSON_BYTES, MAX_LINE_CHARS, parse, read_lesson
from sandbox.lessons.registry import (
    Catalogue,
    catalogue,
    get_lesson,
    is_lesson_file,
    lessons,
    open_lesson_file,
)
from sandbox.lessons.validation import solution_values, validate

__all__ = [
    "ANY_SCENE",
    "MAX_CHECK_CHARS",
    "MAX_CHECK_DEPTH",
    "MAX_CHECK_NODES",
    "MAX_EXPONENT",
    "MAX_LESSON_BYTES",
    "MAX_LINE_CHARS",
    "MAX_LITERAL",
    "BadLesson",
    "Catalogue",
    "Check",
    "CheckError",
    "Lesson",
    "Progress",
    "Step",
    "UnknownLesson",
    "catalogue",
    "compile_check",
    "formula_html",
    "get_lesson",
    "is_lesson_file",
    "lessons",
    "number_of",
    "open_lesson_file",
    "parse",
    "read_lesson",
    "render_text",
    "solution_values",
    "validate",
]
