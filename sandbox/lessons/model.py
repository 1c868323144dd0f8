"""The lesson model: a lesson's front matter and its frozen steps (each field of a step is a
directive of the lesson file, see :mod:`sandbox.lessons`), and the errors naming a lesson
that cannot be used."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from sandbox.errors import SandboxError
from sandbox.lessons.checks import Check

ANY_SCENE = "any"
"""The scene of a lesson that runs on every scene."""


class BadLesson(SandboxError):
    """A lesson file that cannot be used (the message names file and line)."""


class UnknownLesson(SandboxError):
    """No lesson has that name."""


def fail(path: Path, line: int, message: str) -> BadLesson:
    """A :class:`BadLesson` naming ``path:line`` and ``message`` (the fix)."""
    return BadLesson(f"{path}:{line}: {message}")


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
