"""Lessons: every file loads, names real things, and every check passes when solved."""

from __future__ import annotations

import colorsys
import contextlib
import re
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from sandbox.errors import BadOption
from sandbox.lessons import (
    BadLesson,
    Progress,
    compile_check,
    formula_html,
    get_lesson,
    lessons,
    parse,
    solution_values,
    validate,
)
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene, resolve
from sandbox.web.loop.requests import SetValue

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
    _solve(Simulation(resolve(lesson.scene), values=values), lesson, index)


def _solve(sim: Simulation, lesson, index: int) -> None:
    """Step ``index`` of ``lesson`` is not solved at its start, and is once the step's
    solution is set (the motion given up to 5 s to reach the goal)."""
    step = lesson.steps[index]
    sim.advance(0.1)
    progress = Progress(lesson)
    progress.go(index)
    assert progress.observe(sim.readouts(), sim.values) is False  # not solved yet
    for key, value in solution_values(step, lesson.scene, sim.values).items():
        sim.set_value(key, value)
    for _ in range(20):
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


def test_french_spacing_and_tabs_are_plain_text(tmp_path):
    text = GOOD.replace("Text", "«\u00a0Texte\u202f»\t!")
    assert parse(tmp_path / "ok.md", text).steps


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
        # issue 22: a title that clears the teacher's terminal, text that reads backwards
        (lambda s: s.replace("title: T", "title: T\x1b[2J"), 3, "control character U\\+001B"),
        (lambda s: s.replace("Text", "Te\u202ext"), 12, "bidirectional control U\\+202E"),
        (lambda s: s.replace("Text", "Te\x85xt"), 12, "control character U\\+0085"),
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


# -- fakes of viser's GuiApi and of a session's controller, for the panel -------------------
class Handle:
    """A viser handle: content, value, visibility, callbacks; counts content changes."""

    def __init__(self, content: str = "", value: str = "") -> None:
        self._content = content
        self.changes = 0
        self.value = value
        self.visible = True
        self.removed = False
        self.callbacks: list[Callable[[Any], None]] = []

    @property
    def content(self) -> str:
        return self._content

    @content.setter
    def content(self, text: str) -> None:
        self._content = text
        self.changes += 1

    def on_click(self, fn: Callable[[Any], None]) -> Callable[[Any], None]:
        self.callbacks.append(fn)
        return fn

    on_update = on_click

    def remove(self) -> None:
        self.removed = True


class Gui:
    """Just enough of viser's GuiApi for the lesson panel."""

    def __init__(self) -> None:
        self.markdowns: list[Handle] = []
        self.htmls: list[Handle] = []

    def add_folder(self, label: str, **_: object) -> contextlib.nullcontext[None]:
        return contextlib.nullcontext()

    def add_markdown(self, content: str) -> Handle:
        handle = Handle(content)
        self.markdowns.append(handle)
        return handle

    def add_html(self, content: str) -> Handle:
        handle = Handle(content)
        self.htmls.append(handle)
        return handle

    def add_dropdown(self, label: str, options: tuple[str, ...], **kw: Any) -> Handle:
        return Handle(value=kw.get("initial_value", options[0]))

    def add_button_group(self, label: str, options: tuple[str, ...], **_: object) -> Handle:
        return Handle()

    def add_button(self, label: str, **_: object) -> Handle:
        return Handle()


class FakeController:
    def __init__(self, values: dict[str, float]) -> None:
        self.sim = SimpleNamespace(
            scene=SimpleNamespace(name="rotor"), values=values, readout_infos=lambda: []
        )
        self.submitted: list[Any] = []
        self.lesson: str | None = None
        self.recorder = None

    def submit(self, request: Any) -> None:
        self.submitted.append(request)


# -- the evaluator ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("x + y == 5", True),  # 2 + 3
        ("x - y == -1", True),
        ("x * y == 6", True),
        ("x / y > 0.66 and x / y < 0.67", True),  # 2/3 = 0.667
        ("x ** y == 8", True),
        ("y ** 0.5 > 1.73 and y ** 0.5 < 1.74", True),  # √3 = 1.732
        ("-x < -y", False),  # -2 < -3 is false
        ("x < y < 4", True),
        ("x < y < 3", False),
        ("abs(x - y) == 1", True),
        ("min(x, y, 7) == 2 and max(x, y, 7) == 7", True),
        ("not x > y", True),
        ("x > y or y == 3", True),
        ("x == 2 and y != 3", False),
        ("2 * x + y ** 2 / 3 == 7", True),  # precedence: 4 + 9/3
        ("y < 1.5 * initial(y)", True),  # initial y = 2.5: 3 < 3.75
        ("y < initial(y)", False),
    ],
)
def test_a_check_computes_what_is_written(source, expected):
    assert compile_check(source).evaluate({"x": 2.0, "y": 3.0}, {"y": 2.5}) is expected


def test_a_check_lists_live_and_initial_readouts_apart():
    check = compile_check(
        "pilon_h1 < 0.6 * initial(pilon_h1) and abs(pilon_h2) > initial(speed)", "p.md:3"
    )
    assert check.names == ("pilon_h1", "pilon_h2")
    assert check.initial == ("pilon_h1", "speed")
    assert check.where == "p.md:3"


def test_the_start_values_wait_for_a_frame_with_every_readout_the_check_needs():
    """The first frame after a lesson opens may carry only the shown folder's readouts."""
    lesson = parse(Path("t.md"), GOOD)
    progress = Progress(lesson)
    params = {"mass1_g": 10.0}
    assert progress.observe({"time": 0.1}, params) is None and progress.initial is None
    assert progress.observe({"bearing_A": 1.0}, params) is True  # 1 < 2 * 1
    assert progress.initial == {"bearing_A": 1.0}
    assert progress.error is None


def test_a_passing_check_is_remembered_and_the_error_cleared_on_a_new_step():
    lesson = parse(Path("t.md"), GOOD.replace("< 2 *", "< 0.5 *"))
    progress = Progress(lesson)
    params = {"mass1_g": 10.0}
    assert progress.observe({"bearing_A": 1.0}, params) is False
    assert progress.observe({"bearing_A": 0.4}, params) is True and progress.passed == {0}
    progress.error = "x"
    progress.go(0)
    assert progress.error is None and progress.initial is None


def test_the_course_lessons_have_no_raw_html_beyond_formulas():
    import re

    for name in ALL:
        for step in get_lesson(name).steps:
            for text in (step.text, step.success, *step.hints, *sum(step.questions, ())):
                tags = set(re.findall(r"</?([a-zA-Z]+)", text))
                assert tags <= {"i", "sub", "sup"}, (name, step.title, tags)


def test_the_panel_walks_a_lesson_with_presets_questions_and_success(monkeypatch, tmp_path):
    from sandbox.lessons import Catalogue
    from sandbox.web.panels import lesson as lesson_panel
    from sandbox.web.panels.lesson import LessonPanel

    text = GOOD.replace("show:", "question: Pourquoi ? | answer: Parce que $\\omega$.\nshow:")
    lesson = parse(tmp_path / "good.md", text)
    monkeypatch.setattr(lesson_panel, "catalogue", lambda: Catalogue({"good": lesson}, ()))
    gui = Gui()
    controller = FakeController({"mass1_g": 0.0})
    panel = LessonPanel(gui, controller, lesson="good")  # type: ignore[arg-type]
    panel.refresh({"bearing_A": 1.0})
    assert controller.submitted == [SetValue("mass1_g", 10.0)]
    assert controller.lesson == "good" and "étape 1/1" in panel.header.content
    assert panel.status.content == ""  # the goal block says where the student is
    assert "Objectif — En cours" in panel.goal.content
    assert "bearing_A : 1 → objectif &lt; …" in panel.goal.content  # start not known yet
    assert panel.progress is not None and panel.progress.initial is None  # preset not in force
    controller.sim.values["mass1_g"] = 10.0
    panel.refresh({"bearing_A": 1.0})  # start value: 1
    assert "bearing_A : 1 → objectif &lt; 2" in panel.goal.content
    panel.refresh({"bearing_A": 1.5})
    assert panel.status.content.startswith("**Réussi.**")
    assert "Objectif — Réussi" in panel.goal.content and 'aria-valuenow="100"' in panel.goal.content
    question, button, reply = panel._step_handles
    assert question.content == "**Question :** Pourquoi ?"
    button.callbacks[0](None)
    assert reply.content == "**Réponse :** Parce que <i>ω</i>."


# -- the lesson texts agree with their own physics ------------------------------------------
EMOJI = re.compile("[\u2300-\u23ff\u2600-\u27bf\u2b00-\u2bff\U0001f000-\U0001faff\ufe0f]")
COLOURS = {
    "rouge": "rouge", "rouges": "rouge", "orange": "orange", "oranges": "orange",
    "jaune": "jaune", "jaunes": "jaune", "vert": "vert", "verte": "vert", "verts": "vert",
    "vertes": "vert", "bleu": "bleu", "bleue": "bleu", "bleus": "bleu", "bleues": "bleu",
    "violet": "violet", "violette": "violet", "violets": "violet", "violettes": "violet",
}  # fmt: skip


def colour_name(rgb: tuple[int, int, int]) -> str:
    """The French word a reader uses for an arrow's colour (hue in HSV)."""
    h, s, _ = colorsys.rgb_to_hsv(*(c / 255 for c in rgb))
    hue = 360 * h
    if s < 0.25:
        return "gris"
    for name, upper in (("rouge", 10), ("orange", 45), ("jaune", 70), ("vert", 170)):
        if hue < upper:
            return name
    return "bleu" if hue < 250 else "violet" if hue < 335 else "rouge"


def _words(text: str) -> str:
    return re.sub(r"<[^>]+>", "", text)


def _texts(step) -> list[str]:
    return [step.text, step.success, step.goal, *step.hints, *sum(step.questions, ())]


def test_colour_names_of_the_known_arrows():
    assert colour_name((40, 110, 230)) == "bleu"  # bearing A
    assert colour_name((230, 80, 40)) == "orange"  # bearing B
    assert colour_name((220, 60, 60)) == "rouge" and colour_name((120, 60, 160)) == "violet"


@pytest.mark.parametrize("name", ALL)
def test_the_colours_named_in_a_step_are_those_of_its_arrows(name):
    lesson = get_lesson(name)
    scenes = list(SCENES.values()) if lesson.scene == "any" else [SCENES[lesson.scene]]
    arrows = {a.name: a.color for s in scenes for a in s.page.arrows}
    labels = {a.label.lower(): colour_name(a.color) for s in scenes for a in s.page.arrows}
    for step in lesson.steps:
        shown = {colour_name(arrows[a]) for a in (step.arrows or arrows)}
        named: set[str] = set()
        for text in _texts(step):
            for sentence in re.split(r"[.;:!?]", _words(text)):
                if "flèche" not in sentence:
                    continue
                colours = {COLOURS[w] for w in re.findall(r"\w+", sentence) if w in COLOURS}
                assert colours <= shown, (name, step.title, sentence, shown)
                named |= colours
                for clause in sentence.split(","):  # "la flèche orange ... palier B"
                    words = [COLOURS[w] for w in re.findall(r"\w+", clause) if w in COLOURS]
                    said = [
                        c
                        for label, c in labels.items()
                        if re.search(rf"\b{re.escape(label)}\b", clause.lower())
                    ]
                    if len(words) == 1 and len(said) == 1:
                        assert words == said, (name, step.title, clause)
        # a step that names arrows by colour names every colour it shows ("flèches bleues"
        # for a blue and an orange arrow is refused)
        assert not named or named == shown, (name, step.title, named, shown)


@pytest.mark.parametrize("name", ALL)
def test_lesson_texts_have_no_emoji_and_no_code_names(name):
    lesson = get_lesson(name)
    scenes = list(SCENES.values()) if lesson.scene == "any" else [SCENES[lesson.scene]]
    code = {p.name for s in scenes for p in s.params} | {r.name for s in scenes for r in s.readouts}
    code = {c for c in code if "_" in c}
    for step in lesson.steps:
        for text in (step.title, *_texts(step)):
            assert not EMOJI.search(text), (name, step.title, text)
            assert "`" not in text and "<code>" not in text, (name, step.title, text)
            words = set(re.findall(r"[A-Za-z0-9_]+", _words(text)))
            assert not words & code, (name, step.title, words & code)


def test_the_balancing_hints_give_the_solution_that_passes_the_check():
    """Step 3: 32 g at 180°; step 4: the last hint's two masses are the course's solution
    (rounded to 0,1 g) and, typed as written, bring both bearings under 1 %."""
    from sandbox.scenes.rotor import balancing_solution

    lesson = get_lesson("equilibrage")
    static, dynamic = lesson.steps[2], lesson.steps[3]
    assert "<i>m<sub>1</sub> = 32</i> g" in static.hints[-1]
    assert dict(_pairs_of(static.solution)) == {"mass1_g": 32.0, "angle1_deg": 180.0}
    values: dict[str, float] = {}
    for step in lesson.steps[:4]:
        values.update(dict(step.preset))
    found = re.findall(r"([\d,]+) g à (\d+)°", _words(dynamic.hints[-1]))
    typed = {
        "mass1_g": float(found[0][0].replace(",", ".")),
        "angle1_deg": float(found[0][1]),
        "mass2_g": float(found[1][0].replace(",", ".")),
        "angle2_deg": float(found[1][1]),
    }
    exact = balancing_solution(values)
    assert typed["mass1_g"] == pytest.approx(exact["mass1_g"], abs=0.05)
    assert typed["mass2_g"] == pytest.approx(exact["mass2_g"], abs=0.05)
    assert abs(exact["angle1_deg"]) == pytest.approx(typed["angle1_deg"])  # -180 is 180
    assert exact["angle2_deg"] == pytest.approx(typed["angle2_deg"], abs=1e-9)
    sim = Simulation(get_scene("rotor"), values=values)
    sim.advance(0.1)
    progress = Progress(lesson)
    progress.go(3)
    assert progress.observe(sim.readouts(), sim.values) is False
    for key, value in typed.items():
        sim.set_value(key, value)
    sim.advance(0.25)
    assert progress.observe(sim.readouts(), sim.values) is True


def _pairs_of(text: str) -> list[tuple[str, float]]:
    return [(k.strip(), float(v)) for k, v in (p.split("=") for p in text.split(","))]


def test_a_goal_directive_replaces_the_sentence_and_is_shown_as_text(monkeypatch, tmp_path):
    from sandbox.lessons import Catalogue
    from sandbox.web.panels import lesson as lesson_panel
    from sandbox.web.panels.lesson import LessonPanel

    text = GOOD.replace("check:", "goal: Diviser <img src=x> par $\\omega$\ncheck:")
    lesson = parse(tmp_path / "good.md", text)
    monkeypatch.setattr(lesson_panel, "catalogue", lambda: Catalogue({"good": lesson}, ()))
    gui = Gui()
    controller = FakeController({"mass1_g": 10.0})
    panel = LessonPanel(gui, controller, lesson="good")  # type: ignore[arg-type]
    panel.refresh({"bearing_A": 4.0})
    panel.refresh({"bearing_A": 3.0})
    goal = panel.goal.content
    assert "<img" not in goal and "Diviser &lt;img src=x> par <i>ω</i>" in goal
    assert "bearing_A : 3" in goal and "objectif" not in goal.split("</div>", 2)[-1]
    shown = [h.content for h in gui.markdowns + gui.htmls]
    assert not any(EMOJI.search(c) for c in shown)


def test_checks_are_parsed_one_at_a_time(monkeypatch):
    """Python 3.11's AST builder counts its depth per interpreter: two sessions parsing
    lessons at once raised SystemError (a session lost, its browser without frames)."""
    import ast
    import threading
    import time

    from sandbox.lessons import checks

    inside, most = [0], [0]
    real = ast.parse

    def slow_parse(*args, **kwargs):
        inside[0] += 1
        most[0] = max(most[0], inside[0])
        time.sleep(0.002)
        inside[0] -= 1
        return real(*args, **kwargs)

    monkeypatch.setattr(checks.ast, "parse", slow_parse)
    threads = [
        threading.Thread(target=lambda: [compile_check("x < 2 * y", "t") for _ in range(20)])
        for _ in range(4)
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert most[0] == 1


def _imposed_checks():
    for name in ALL:
        lesson = get_lesson(name)
        scene = SCENES.get(lesson.scene)
        if scene is None or scene.imposed is None:
            continue
        for index, step in enumerate(lesson.steps):
            if step.check is not None:
                yield pytest.param(name, index, id=f"{name}-{index + 1}")


@pytest.mark.parametrize(("name", "index"), list(_imposed_checks()))
@pytest.mark.parametrize("motion", ["imposed", "free"])
def test_a_check_passes_in_the_solved_state_whichever_way_the_motion_is_computed(
    name, index, motion
):
    """Issue 35: a lesson's checks hold for the imposed motion and the free simulation
    alike (where the scene's values let the motion be imposed)."""
    lesson = get_lesson(name)
    values: dict[str, float] = {}
    for earlier in lesson.steps[: index + 1]:
        values.update(dict(earlier.preset))
    sim = Simulation(resolve(lesson.scene), values=values)
    if motion not in sim.motions:
        pytest.skip("this scene has no imposed motion")
    try:
        sim.set_motion(motion)
    except BadOption:
        pytest.skip("these values call for the free simulation")
    _solve(sim, lesson, index)
