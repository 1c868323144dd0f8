"""Controls that never lie, and a page readable on a 1280×720 projector (headless
Chromium): every slider reads the value in force after presets, steps, refusals and
resets; the simulation controls and the lesson step fit without scrolling; 16 px text;
no code name, English word or emoji in the control folders."""

from __future__ import annotations

import re

import pytest
from conftest import free_port, pause, settled, wait_for

from sandbox.lessons import catalogue
from sandbox.scenes import SCENES
from sandbox.web.client.fields import param_label
from sandbox.web.panels.controls import NUMERICS_FOLDER, TIMESTEP_LABEL

pytestmark = [pytest.mark.browser, pytest.mark.slow]  # Chromium pages: 10-30 s each

VIEWPORT = {"width": 1280, "height": 720}


@pytest.fixture
def projector_page(projector_context):
    return projector_context


@pytest.fixture
def balancing():
    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), lesson="equilibrage", open_message=False)
    try:
        yield app
    finally:
        app.stop()


def _box(page, label: str):
    """The number box of the control labelled ``label``."""
    row = page.locator("div.mantine-Flex-root", has=page.get_by_text(label, exact=True)).last
    return row.locator("input").last


def _shown(page, label: str) -> float:
    text = _box(page, label).input_value()
    return float(text.replace("\u202f", "").replace(",", ".").replace("−", "-"))


def _params():
    return {p.name: p for p in SCENES["rotor"].params}


def _reads(page, expected: dict[str, float]) -> dict[str, tuple[float, float]]:
    """Sliders whose box does not read the expected value: name -> (shown, expected)."""
    wrong = {}
    params = _params()
    for name, value in expected.items():
        p = params[name]
        if p.choices:  # a dropdown reads the option's name
            text = _box(page, param_label(p)).input_value()
            if text != p.choices[int(round(value))]:
                wrong[name] = (text, value)  # type: ignore[assignment]
            continue
        shown = _shown(page, param_label(p))
        if shown != pytest.approx(value, abs=1e-6):
            wrong[name] = (shown, value)
    return wrong


def _type(page, name: str, value: float) -> None:
    box = _box(page, param_label(_params()[name]))
    box.fill(f"{value:g}")
    box.press("Enter")


def test_every_slider_reads_the_lesson_values_step_by_step(projector_page, balancing):
    lesson = catalogue()[0]["equilibrage"]
    page = projector_page.new_page()
    page.goto(balancing.url)
    page.get_by_text("étape 1/4", exact=False).first.wait_for(timeout=30_000)
    session = next(iter(balancing.sessions.values()))
    sim = session.controller.sim
    expected = SCENES["rotor"].defaults()
    for index, step in enumerate(lesson.steps):
        if index:
            page.get_by_text("Suivant", exact=False).first.click()
            page.get_by_text(f"étape {index + 1}/4", exact=False).first.wait_for(timeout=10_000)
        expected.update(dict(step.preset))
        assert wait_for(lambda: sim.values == pytest.approx(expected), timeout=10)
        assert wait_for(lambda: not _reads(page, expected), timeout=5), (
            f"step {index + 1}: {_reads(page, expected)}"
        )
        if index == 2:
            # The case: the solution typed, then at once the next step, whose
            # preset puts the masses back to 0 before any panel refresh.
            for name, value in (("mass1_g", 32.0), ("angle1_deg", 180.0)):
                _type(page, name, value)
            expected.update({"mass1_g": 32.0, "angle1_deg": 180.0})
    # step 4 reset the masses: the sliders read 0, and typing 32 again is sent
    assert wait_for(lambda: not _reads(page, expected), timeout=5), _reads(page, expected)
    # the box the server replaced is hidden for one refresh and built anew: type into the
    # new one (a box typed into while it was being rebuilt kept nothing, as a user's would)
    mirror = session.view.controls.mirrors["mass1_g"]
    assert wait_for(lambda: not mirror._hidden and mirror.handle.visible, timeout=5)
    for _ in range(3):  # were the box not rebuilt, typing the same 32 again sends nothing
        _type(page, "mass1_g", 32.0)
        if wait_for(lambda: sim.values["mass1_g"] == 32.0, timeout=5):
            break
    assert sim.values["mass1_g"] == 32.0
    assert wait_for(lambda: _shown(page, param_label(_params()["mass1_g"])) == 32.0)


def test_a_refused_value_and_a_reset_leave_the_controls_on_the_values_in_force(
    projector_page, balancing
):
    page = projector_page.new_page()
    page.goto(balancing.url)
    page.get_by_text("étape 1/4", exact=False).first.wait_for(timeout=30_000)
    sim = next(iter(balancing.sessions.values())).controller.sim
    page.get_by_text(NUMERICS_FOLDER, exact=True).first.click()
    dt = _box(page, TIMESTEP_LABEL)
    dt.wait_for(timeout=10_000)
    before = sim.timestep
    dt.fill("0")
    dt.press("Enter")
    page.get_by_text(re.compile("Valeur refusée")).first.wait_for(timeout=10_000)
    assert wait_for(lambda: _shown(page, TIMESTEP_LABEL) == pytest.approx(before), timeout=5)
    _type(page, "mass1_g", 50.0)
    assert wait_for(lambda: sim.values["mass1_g"] == 50.0, timeout=10)
    ctl = next(iter(balancing.sessions.values())).controller
    reset = ctl.generation
    page.get_by_role("button", name="Réinitialiser").first.click()
    assert wait_for(lambda: ctl.generation > reset, timeout=10)  # the reset is applied
    assert wait_for(lambda: not _reads(page, dict(sim.values)), timeout=5)


def _inside(page, locator) -> bool:
    box = locator.bounding_box()
    return box is not None and box["y"] >= 0 and box["y"] + box["height"] <= VIEWPORT["height"]


def test_projector_layout_fits_1280x720_with_16px_text(projector_page, balancing):
    page = projector_page.new_page()
    page.goto(balancing.url)
    page.get_by_text("étape 1/4", exact=False).first.wait_for(timeout=30_000)
    # the panel is laid out: its controls stop moving
    boxes = (
        "() => [...document.querySelectorAll('button, input')]"
        ".map(e => e.getBoundingClientRect().y)"
    )
    assert settled(lambda: page.evaluate(boxes))
    # the simulation controls: time buttons, speed, recording, every parameter
    must_see = [
        page.get_by_role("button", name="Pause").first,
        page.get_by_role("button", name="Enregistrer").first,
    ]
    # every parameter but the advanced ones, folded on purpose (the rotor's start time)
    must_see += [_box(page, param_label(p)) for p in _params().values() if not p.advanced]
    # the lesson step: title, navigation, and the first and last lines of its text
    must_see += [
        page.get_by_text("étape 1/4", exact=False).first,
        page.get_by_text("Suivant", exact=False).first,
        page.get_by_text("Le rotor tourne", exact=False).first,
        page.get_by_text("regardez-les", exact=False).first,
    ]
    hidden = [str(loc) for loc in must_see if not _inside(page, loc)]
    assert not hidden, hidden
    sizes = page.evaluate(
        """() => [...document.querySelectorAll('label, input, button, p')]
            .filter(e => e.offsetParent !== null && e.textContent.trim())
            .map(e => parseFloat(getComputedStyle(e).fontSize))"""
    )
    assert sizes and min(sizes) >= 16, sorted(sizes)[:5]
    overlay = page.locator("#sandbox-overlay")
    assert wait_for(lambda: "N" in overlay.inner_text(), timeout=10)
    assert _inside(page, overlay)


EMOJI = re.compile("[\U0001f000-\U0001faff\u2600-\u27bf\u2b00-\u2bff\u231a-\u23ff\ufe0f]")
ENGLISH = (
    "speed", "bearing", "unbalance", "timestep", "integrator", "omega", "theta", "lambda",
    "length", "slope", "spin", "drift", "true", "false", "None", "nan",
)  # fmt: skip


def _code_names() -> set[str]:
    """Contract names of the registry that no French reader would write (with "_")."""
    names: set[str] = set()
    for scene in SCENES.values():
        names.update(p.name for p in scene.params)
        names.update(r.name for r in scene.readouts)
    return {n for n in names if "_" in n}


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_control_folders_speak_french_without_code_names_or_emoji(projector_page, scene):
    from sandbox.web.serving.app import start

    app = start(scene, port=free_port(), open_message=False)
    try:
        page = projector_page.new_page()
        page.goto(app.url)
        page.get_by_text("Simulation", exact=True).first.wait_for(timeout=30_000)
        pause(page)  # words, not motion
        folders = page.locator(".mantine-ScrollArea-viewport")  # the control panels

        def panels_text() -> str:
            return "\n".join(folders.nth(i).inner_text() for i in range(folders.count()))

        # every folder built and filled: its elements stop coming (the numbers run on)
        parts = "() => document.querySelectorAll('label, button, p, td, th, h1, h2').length"
        assert settled(lambda: page.evaluate(parts))
        text = panels_text()
        words = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", text))
        assert not words & _code_names(), sorted(words & _code_names())
        assert not words & set(ENGLISH), sorted(words & set(ENGLISH))
        assert not EMOJI.findall(text), EMOJI.findall(text)
    finally:
        app.stop()
