"""The served page as a student sees it, in headless Chromium (Playwright)."""

from __future__ import annotations

import re

import pytest
from conftest import choose, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow]  # Chromium pages: 10-19 s each


def _readout(page, name: str) -> float:
    """The number shown in a readout cell (``data-readout`` span)."""
    # the cell shows "54,42"; its data-value attribute keeps the exact number for scripts
    value = page.locator(f'[data-readout="{name}"]').first.get_attribute("data-value")
    return float(value or "nan")


def _label(name: str) -> str:
    """A rotor parameter's label on the page ("Masse de correction m₁ [g]")."""
    from sandbox.scenes import SCENES
    from sandbox.web.client.fields import param_label

    return param_label(SCENES["rotor"].param(name))


def _slider_input(page, label: str):
    """The number box next to the slider labelled ``label``."""
    row = page.locator("div.mantine-Flex-root", has=page.get_by_text(label, exact=True)).last
    return row.locator("input.mantine-NumberInput-input").first


def _open(open_page, app):
    page = open_page(app.url)
    page.locator('[data-readout="bearing_A"]').first.wait_for(timeout=30_000)
    return page


def test_page_shows_canvas_one_folder_at_a_time_and_bearing_forces(open_page, served_rotor):
    page = _open(open_page, served_rotor)
    assert page.title() == "Dynamique des solides"  # the tab, not "Viser"
    assert page.locator("canvas").first.is_visible()
    assert page.get_by_text("Grandeurs de la scène", exact=True).first.is_visible()
    assert _readout(page, "bearing_A") > 1.0
    for title in ("Torseurs", "Hypothèses de modélisation", "Courbes"):
        assert not page.get_by_text(title, exact=True).first.is_visible(), title
    (session,) = served_rotor.sessions.values()
    assert session.view.shown == "Grandeurs de la scène"
    choose(page, "Panneau affiché", "Hypothèses de modélisation")
    page.get_by_text("Poids négligé").first.wait_for(timeout=10_000)
    assert not page.get_by_text("Grandeurs de la scène", exact=True).first.is_visible()
    choose(page, "Panneau affiché", "Tous les panneaux")
    for title in ("Grandeurs de la scène", "Torseurs", "Hypothèses de modélisation", "Courbes"):
        page.get_by_text(title, exact=True).first.wait_for(timeout=10_000)


def test_moving_mass1_changes_the_bearing_force(open_page, served_rotor):
    page = _open(open_page, served_rotor)
    before = _readout(page, "bearing_A")
    box = _slider_input(page, _label("mass1_g"))
    box.fill("60")
    box.press("Enter")
    assert wait_for(lambda: abs(_readout(page, "bearing_A") - before) > 0.05 * before), (
        f"bearing_A stayed at {before} N after mass1_g = 60 g"
    )
    session = next(iter(served_rotor.sessions.values()))
    assert session.controller.sim.values["mass1_g"] == pytest.approx(60.0)


def test_bad_timestep_is_refused_and_the_server_keeps_running(open_page, served_rotor):
    from sandbox.web.panels.controls import NUMERICS_FOLDER, TIMESTEP_LABEL

    page = _open(open_page, served_rotor)
    page.get_by_text(NUMERICS_FOLDER, exact=True).first.click()  # folded by default
    label = page.get_by_text(TIMESTEP_LABEL, exact=True)
    label.first.wait_for(timeout=10_000)
    box = page.locator("div.mantine-Flex-root", has=label)
    field = box.last.locator("input").first
    field.fill("0")
    field.press("Enter")
    page.get_by_text(re.compile("Valeur refusée")).first.wait_for(timeout=10_000)
    session = next(iter(served_rotor.sessions.values()))
    assert session.controller.sim.timestep == pytest.approx(session.controller.sim.scene.timestep)
    t0 = session.controller.sim.data.time
    assert wait_for(lambda: session.controller.sim.data.time > t0 + 0.2)


def test_each_browser_has_its_own_simulation(open_page, served_rotor):
    first = _open(open_page, served_rotor)
    second = _open(open_page, served_rotor)
    assert wait_for(lambda: len(served_rotor.sessions) == 2)
    sims = [s.controller.sim for s in served_rotor.sessions.values()]
    assert sims[0] is not sims[1]
    _slider_input(first, _label("mass1_g")).fill("80")
    _slider_input(first, _label("mass1_g")).press("Enter")
    assert wait_for(lambda: sorted(s.values["mass1_g"] for s in sims) == [0.0, 80.0])
    second.close()
    assert wait_for(lambda: len(served_rotor.sessions) == 1)


def test_replay_server_shows_the_timeline_to_several_browsers(open_page, tmp_path):
    from conftest import free_port

    from sandbox.cli import main
    from sandbox.recording import load
    from sandbox.web.replay.player import start_replay

    path = tmp_path / "r.sbx"
    assert main(["run", "rotor", "--duration", "1", "--record", str(path)]) == 0
    app = start_replay(load(path), port=free_port(), open_message=False)
    try:
        pages = [_open(open_page, app) for _ in range(2)]
        assert wait_for(lambda: len(app.sessions) == 2)
        for page in pages:
            assert page.get_by_text("Relecture", exact=True).first.is_visible()
            assert _readout(page, "bearing_A") > 1.0
        ctl = next(iter(app.sessions.values())).controller
        assert wait_for(lambda: not ctl.playing)  # a 1 s recording plays to its end
        assert ctl.index == len(ctl.rec.times) - 1
    finally:
        app.stop()


def test_a_student_walks_the_balancing_lesson_to_success(open_page):
    """Lesson 3: go to the dynamic-balancing step, type the two correction masses
    computed from the course's conditions, and see the check succeed."""
    from conftest import free_port

    from sandbox.scenes.rotor import balancing_solution
    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), lesson="equilibrage", open_message=False)
    try:
        page = _open(open_page, app)
        page.get_by_text("Équilibrage statique puis dynamique", exact=False).first.wait_for()
        for step in (2, 3, 4):
            page.get_by_text("Suivant ▶").click()
            page.get_by_text(f"étape {step}/4", exact=False).first.wait_for(timeout=10_000)
        session = next(iter(app.sessions.values()))
        assert wait_for(lambda: session.controller.sim.values["mass1_g"] == 0.0)
        lesson = session.view.lesson
        assert lesson is not None  # the step records the unbalanced forces as its start values
        assert wait_for(lambda: lesson.progress is not None and lesson.progress.initial is not None)
        solution = balancing_solution(session.controller.sim.values)
        values = session.controller.sim.values
        for name in ("mass1_g", "angle1_deg", "mass2_g", "angle2_deg"):
            box = _slider_input(page, _label(name))
            box.fill(f"{solution[name]:.3f}")
            box.press("Enter")
            # applied, on the slider's step (0,1)
            close = lambda n=name: abs(values[n] - solution[n]) <= 0.051  # noqa: E731
            assert wait_for(close, timeout=10), (name, values[name], solution[name])
        page.get_by_text("Réussi", exact=False).first.wait_for(timeout=20_000)
    finally:
        app.stop()
