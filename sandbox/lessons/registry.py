"""The catalogue of lessons: the shipped files in ``lessons/`` and the lesson files opened
by path (``sandbox serve FILE.md``), parsed and validated once, by name."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

from sandbox.data import data_dir
from sandbox.errors import choices, shown
from sandbox.lessons.model import BadLesson, Lesson, UnknownLesson
from sandbox.lessons.reader import parse
from sandbox.lessons.validation import validate


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
