"""A lesson against its scene: every name a lesson uses checked against the scene
(:func:`validate`), and a step's ``solution:`` turned into parameter values
(:func:`solution_values`)."""

from __future__ import annotations

from collections.abc import Mapping

from sandbox.errors import BadParameter, choices
from sandbox.lessons.model import ANY_SCENE, BadLesson, Lesson, Step, fail
from sandbox.lessons.reader import parse_pairs
from sandbox.physics.readouts import GENERIC_NAMES
from sandbox.scenes import SCENES, get_scene


def validate(lesson: Lesson) -> None:
    """Check every name against the scene: presets (names and ranges), solutions, shown
    readouts, checks, arrows.

    Raises:
        BadLesson: naming the file, the step's line and the valid names.
    """
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
        raise fail(
            lesson.path,
            2,
            f"unknown scene {lesson.scene[:80]!r}; use one of: {choices(SCENES)}, any",
        )
    arrows = {a.name for s in scenes for a in s.page.arrows}
    for step in lesson.steps:
        pairs = list(step.preset)
        if step.solution and not step.solution.startswith("@"):
            pairs += parse_pairs(step.solution, "solution")
        for name, value in pairs:
            if name not in params:
                raise fail(
                    lesson.path,
                    step.line,
                    f"preset names no parameter {name[:80]!r}; valid: {choices(params)}",
                )
            try:
                params[name].check(value)
            except BadParameter as exc:
                raise fail(lesson.path, step.line, f"preset {exc}") from None
        used = set(step.show) | set(step.plots)
        if step.check is not None:
            used |= set(step.check.names) | set(step.check.initial)
        bad = sorted(used - readouts)
        if bad:
            raise fail(
                lesson.path,
                step.line,
                f"no readout {bad[0][:80]!r}; valid: {choices(sorted(readouts))}",
            )
        bad = [a for a in step.arrows if a not in arrows]
        if bad:
            raise fail(
                lesson.path, step.line, f"no arrow {bad[0][:80]!r}; valid: {choices(arrows)}"
            )


def solution_values(step: Step, scene_name: str, values: Mapping[str, float]) -> dict[str, float]:
    """The parameter values of a step's ``solution`` (``@name``: the scene's solution of
    that name, called with ``values``).

    Raises:
        BadLesson: an unknown helper or a malformed pair.
    """
    text = step.solution.strip()
    if not text:
        return {}
    if text.startswith("@"):
        helper = get_scene(scene_name).solutions.get(text[1:])
        if not callable(helper):
            raise BadLesson(f"step {step.title!r}: the scene has no helper {text[:80]!r}")
        return {k: float(v) for k, v in helper(values).items()}
    try:
        return dict(parse_pairs(text, "solution"))
    except ValueError as exc:
        raise BadLesson(f"step {step.title!r}: {exc}") from None
