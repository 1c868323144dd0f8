"""Motion a student can follow, in headless Chromium: a 6000 rpm rotor at ×0.01 is seen
turning on every frame; "Pas" of an angle; the typed point P drawn."""

from __future__ import annotations

import io

import numpy as np
import pytest
from conftest import choose, free_port, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow]  # a Chromium page: ~15 s


@pytest.fixture
def fast_rotor():
    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), open_message=False, values={"speed_rpm": 6000.0})
    try:
        yield app
    finally:
        app.stop()


def _canvas(page) -> np.ndarray:
    from PIL import Image

    png = page.locator("canvas").first.screenshot()
    return np.asarray(Image.open(io.BytesIO(png)).convert("L"), dtype=float)


def _session(app):
    assert wait_for(lambda: len(app.sessions) == 1)
    (session,) = app.sessions.values()
    if getattr(session.view, "display", None) is None:
        pytest.skip("the view does not build the display panel yet (view.py wiring)")
    return session


def test_a_6000_rpm_rotor_at_one_hundredth_is_seen_turning(open_page, fast_rotor):
    page = open_page(fast_rotor.url)
    page.locator("canvas").first.wait_for(timeout=30_000)
    session = _session(fast_rotor)
    page.get_by_text("Affichage", exact=True).first.click()
    choose(page, "Ralenti", "×0,01")
    assert wait_for(lambda: session.controller.speed == 0.01)
    ctl = session.controller
    start = ctl.display_time
    assert wait_for(lambda: ctl.display_time > start)  # drawn at the new speed
    shots = []
    for _ in range(3):  # a screenshot takes 1-3 s with software WebGL
        shown = ctl.display_time
        assert wait_for(lambda shown=shown: ctl.display_time > shown)  # a new instant drawn
        shots.append(_canvas(page))
    # At ×0.01 the physics (dt = 10 ms, a whole turn a step at 6000 rpm) steps once a
    # second: without the display state, most of these pairs would be identical.
    changes = [float(np.abs(b - a).mean()) for a, b in zip(shots, shots[1:], strict=False)]
    assert min(changes) > 0.05, changes
    assert ctl.display_time > ctl.sim.data.time or ctl.display_time == ctl.sim.data.time


def test_a_step_of_ten_degrees_turns_the_drawn_rotor(open_page, served_rotor):
    page = open_page(served_rotor.url)
    page.locator("canvas").first.wait_for(timeout=30_000)
    session = _session(served_rotor)
    ctl = session.controller
    page.get_by_text("Affichage", exact=True).first.click()
    page.get_by_role("button", name="Avancer d'un pas").click()
    assert wait_for(lambda: not ctl.playing)
    first = ctl.display_time
    before = _canvas(page)
    page.get_by_role("button", name="Avancer d'un pas").click()
    w = 1500 * 2 * np.pi / 60
    assert wait_for(lambda: ctl.display_time == pytest.approx(first + np.radians(10) / w))
    assert wait_for(lambda: float(np.abs(_canvas(page) - before).mean()) > 0.01)
