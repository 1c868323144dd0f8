"""Lessons: every file loads, names real things, and every check passes when solved."""

from __future__ import annotations

import pytest

from sandbox.lessons import (
    BadLesson,
    Progress,
    formula_html,
    get_lesson,
    lessons,
    parse,
    solution_values,
    validate,
)
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES

ALL = sorted(lessons())


def test_the_course_lessons_exist():
    assert {"equilibrage", "precision"} <= set(ALL)


@pytest.mark.parametrize("name", ALL)
def test_lesson_loads_and_names_real_things(name):
    lesson = get_lesson(name)
    validate(lesson)  # presets, readouts, arrows exist (raises otherwise)
    assert lesson.steps and all(step.text for step in lesson.steps)
    assert lesson.scene == "any" or lesson.scene in SCENES


def _checked_steps():
    for name in ALL:
        lesson = get_lesson(name)
        for index, step in enumerate(lesson.steps):
            if step.check is not None:
                yield pytest.param(name, index, id=f"{name}-{index + 1}")


@pytest.mark.parametrize(("name", "index"), list(_checked_steps()))
def test_every_check_fails_at_the_start_and_passes_in_the_solved_state(name, index):
    lesson = get_lesson(name)
    step = lesson.steps[index]
    assert step.solution, f"{name} step {index + 1} has a check but no solution"
    values: dict[str, float] = {}
    for earlier in lesson.steps[: index + 1]:
        values.update(dict(earlier.preset))
    sim = Simulation(lesson.scene, values=values)
    sim.advance(0.1)
    progress = Progress(lesson)
    progress.go(index)
    assert progress.observe(sim.readouts(), sim.values) is False  # not solved yet
    for key, value in solution_values(step, lesson.scene, sim.values).items():
        sim.set_value(key, value)
    for _ in range(20):  # give the motion up to 5 s to reach the goal
        sim.advance(0.25)
        if progress.observe(sim.readouts(), sim.values):
            break
    assert index in progress.passed


def test_progress_waits_for_presets_and_reveals_hints():
    lesson = get_lesson("equilibrage")
    progress = Progress(lesson)
    progress.go(1)  # preset speed_rpm=3000
    assert progress.observe({"bearing_A": 1.0}, {"speed_rpm": 1500.0}) is None
    assert progress.initial is None
    progress.go(3)
    hints = [progress.next_hint() for _ in range(len(progress.step.hints) + 1)]
    assert hints[-1] is None and all(hints[:-1])
    assert progress.go(99) is lesson.steps[-1]


def test_formulas_are_rendered():
    html = formula_html(r"\vec{\Omega} \wedge m \omega^2 Y_{G} \le \frac{a}{b} \sqrt{E^2+F^2}")
    assert "Ω\u20d7" in html and "∧" in html and "ω<sup>2</sup>" in html
    assert "<sub>G</sub>" in html and "(a)/(b)" in html and "√(E<sup>2</sup>+F<sup>2</sup>)" in html
    with pytest.raises(ValueError, match=r"\\foo"):
        formula_html(r"\foo")


GOOD = """---
scene: rotor
title: T
level: L1
---

## Step
preset: mass1_g=10
show: bearing_A
check: bearing_A < 2 * initial(bearing_A)

Text $\\omega$.
"""


@pytest.mark.parametrize(
    ("edit", "line", "needle"),
    [
        (lambda s: s.replace("---\nscene", "scene", 1), 1, "front matter"),
        (lambda s: s.replace("title: T\n", ""), 1, "title"),
        (lambda s: s.replace("## Step", "Step"), 6, "at least one step"),
        (lambda s: s.replace("show:", "shwo:"), 9, "unknown directive 'shwo'"),
        (lambda s: s.replace("mass1_g=10", "mass1_g"), 8, "NAME=VALUE"),
        (lambda s: s.replace("< 2 *", "< os.system(1) or"), 10, "can be called"),
        (lambda s: s.replace("< 2 *", "< bearing_A.real or"), 10, "not allowed"),
        (lambda s: s.replace("$\\omega$", "$\\omegaa$"), 7, "omegaa"),
    ],
)
def test_bad_lesson_files_name_file_and_line(tmp_path, edit, line, needle):
    path = tmp_path / "bad.md"
    text = edit(GOOD)
    with pytest.raises(BadLesson, match=needle) as info:
        parse(path, text)
    assert str(info.value).startswith(f"{path}:{line}:")


@pytest.mark.parametrize(
    ("edit", "needle"),
    [
        (lambda s: s.replace("mass1_g=10", "mass9_g=10"), "no parameter 'mass9_g'"),
        (lambda s: s.replace("show: bearing_A", "show: bearing_C"), "no readout 'bearing_C'"),
        (lambda s: s.replace("scene: rotor", "scene: nope"), "unknown scene 'nope'"),
    ],
)
def test_lessons_naming_unknown_things_are_refused(tmp_path, edit, needle):
    path = tmp_path / "bad.md"
    with pytest.raises(BadLesson, match=needle):
        validate(parse(path, edit(GOOD)))


def test_unknown_lesson_lists_the_valid_ones():
    from sandbox.lessons import UnknownLesson

    with pytest.raises(UnknownLesson, match="equilibrage"):
        get_lesson("nope")
