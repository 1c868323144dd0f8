"""The lesson-file parser: Markdown files turned into frozen step lists.

Lesson files are untrusted (students and teachers exchange them): loading refuses, as
:class:`~sandbox.lessons.model.BadLesson` naming ``file:line`` and the fix, a file above
:data:`MAX_LESSON_BYTES` or with a line above :data:`MAX_LINE_CHARS`, hidden characters,
unknown or repeated directives and every check :func:`~sandbox.lessons.checks.compile_check`
refuses.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from sandbox.errors import choices
from sandbox.lessons.checks import Check, compile_check
from sandbox.lessons.markup import render_text
from sandbox.lessons.model import Lesson, Step, fail

DIRECTIVES = (
    "preset", "show", "plots", "arrows", "question", "check", "goal", "success", "hint",
    "solution",
)  # fmt: skip
REPEATABLE = ("question", "hint")
"""Directives a step may give several times; the others at most once."""
MAX_LESSON_BYTES = 64 * 1024
"""Largest lesson file read [bytes] (the course's longest is under 4 KiB)."""
MAX_LINE_CHARS = 2000
"""Longest line of a lesson file [characters]."""


def _csv(value: str) -> tuple[str, ...]:
    return tuple(v.strip() for v in value.split(",") if v.strip())


def read_lesson(path: Path) -> str:
    """The text of a lesson file, read with a size bound.

    Raises:
        BadLesson: not a regular file, unreadable, above :data:`MAX_LESSON_BYTES`, or not
            UTF-8.
    """
    try:
        if not path.is_file():
            raise fail(path, 1, "not a regular file; a lesson is a Markdown text file")
        with path.open("rb") as stream:
            data = stream.read(MAX_LESSON_BYTES + 1)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise fail(
            path, 1, f"cannot read the file ({reason}); check it exists and is readable"
        ) from None
    if len(data) > MAX_LESSON_BYTES:
        raise fail(
            path, 1, f"the file is larger than {MAX_LESSON_BYTES // 1024} KiB; split the lesson"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise fail(path, line, "the file is not UTF-8 text; save it as UTF-8") from None


def _lines(path: Path, text: str) -> list[str]:
    if len(text) > MAX_LESSON_BYTES or len(text.encode("utf-8", "replace")) > MAX_LESSON_BYTES:
        raise fail(
            path, 1, f"the file is larger than {MAX_LESSON_BYTES // 1024} KiB; split the lesson"
        )
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    for number, line in enumerate(lines, start=1):
        if len(line) > MAX_LINE_CHARS:
            raise fail(
                path,
                number,
                f"the line has {len(line)} characters (at most {MAX_LINE_CHARS}); break it",
            )
        if "\x00" in line:
            raise fail(path, number, "NUL byte: this is not a text file; save it as UTF-8 text")
        hidden = _hidden_character(line)
        if hidden is not None:
            column, what = hidden
            raise fail(
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
        raise fail(path, 1, "a lesson starts with a front matter between two '---' lines")
    try:
        end = next(i for i in range(1, len(lines)) if lines[i].strip() == "---")
    except StopIteration:
        raise fail(path, 1, "the front matter is not closed by a '---' line") from None
    meta: dict[str, str] = {}
    for i in range(1, end):
        key, sep, value = lines[i].partition(":")
        if not sep:
            raise fail(
                path, i + 1, f"expected 'key: value' in the front matter, got {lines[i][:80]!r}"
            )
        meta[key.strip()] = value.strip()
    for key in ("scene", "title", "level"):
        if not meta.get(key):
            raise fail(path, 1, f"the front matter needs '{key}:'")
    heads = [i for i in range(end + 1, len(lines)) if lines[i].startswith("## ")]
    if not heads:
        raise fail(path, end + 2, "a lesson needs at least one step ('## Title')")
    steps = []
    for k, start in enumerate(heads):
        stop = heads[k + 1] if k + 1 < len(heads) else len(lines)
        steps.append(_step(path, lines, start, stop))
    try:
        number = int(meta.get("number", "99"))
    except ValueError:
        raise fail(path, 1, f"number: expects an integer, got {meta['number'][:40]!r}") from None
    return Lesson(
        path.stem, meta["scene"], meta["title"], meta["level"], tuple(steps), path, number
    )


def parse_pairs(value: str, what: str) -> tuple[tuple[str, float], ...]:
    """The ``NAME=VALUE, ...`` pairs of a ``preset:`` or ``solution:`` line (``what``).

    Raises:
        ValueError: a malformed pair or a value that is not a finite number.
    """
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
        raise fail(path, start + 1, "a step needs a title after '## '")
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
            raise fail(path, where, f"unknown directive {key!r}; use one of: {choices(DIRECTIVES)}")
        if key in seen and key not in REPEATABLE:
            raise fail(path, where, f"{key}: is given twice in this step; keep one")
        seen.add(key)
        try:
            if key == "preset":
                preset = parse_pairs(value, "preset")
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
                    parse_pairs(value, "solution")
        except (ValueError, SyntaxError) as exc:
            raise fail(path, where, f"bad {key}: {exc}") from None
        i += 1
    body = "\n".join(lines[i:stop]).strip()
    try:
        rendered = render_text(body)
    except ValueError as exc:
        raise fail(path, start + 1, f"in this step: {exc}") from None
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
