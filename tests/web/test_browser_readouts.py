"""Readout panels as a student sees them, in headless Chromium: plots that keep drawing
while their range grows, tables in French with a decimal comma and no raw HTML."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest
from conftest import choose, free_port, wait_for

from sandbox.web.loop.requests import Reset

pytestmark = [pytest.mark.browser, pytest.mark.slow]  # Chromium pages: 10-20 s each

CHARTS = """() => Object.values((window.__viserTestpoints || {}).uplots || {}).map((entry) => {
  const chart = entry.chart, t = chart.data[0];
  const canvas = chart.ctx.canvas, ctx = chart.ctx;
  const box = chart.bbox;  // plotting area, canvas pixels
  const image = ctx.getImageData(box.left, box.top, box.width, box.height).data;
  const third = Math.floor(box.width / 3);
  let coloured = 0, right = 0;
  for (let i = 0; i < image.length; i += 4) {
    const r = image[i], g = image[i + 1], b = image[i + 2];
    if (Math.max(r, g, b) - Math.min(r, g, b) > 80) {
      coloured += 1;
      if ((i / 4) % box.width >= 2 * third) right += 1;
    }
  }
  return {last: t.length ? t[t.length - 1] : null, xmax: chart.scales.x.max,
          ymin: chart.scales.y.min, ymax: chart.scales.y.max,
          coloured, right, width: canvas.width};
})"""
"""Per chart: last sample time, x and y ranges, and how many saturated (line) pixels its
plotting area holds, in all and in its right third (the latest samples)."""


@pytest.fixture
def served_cylinder() -> Iterator[object]:
    from sandbox.web.serving.app import start

    # a plane long enough for 9 s of descent (the default one ends the run at 3 s, and
    # the page then starts it again)
    app = start(
        "rolling_cylinder", port=free_port(), open_message=False, values={"plane_length": 200.0}
    )
    try:
        yield app
    finally:
        app.stop()


def test_plots_keep_drawing_while_their_range_grows(open_page, served_cylinder):
    """Issue 14: the cylinder's speed grows from 0 to 40 m/s; each new range rebuilt the
    chart, which drew nothing, then one second of data lagging 8 s behind."""
    page = open_page(served_cylinder.url)
    page.get_by_text("Panneau affiché", exact=True).first.wait_for(timeout=30_000)
    choose(page, "Panneau affiché", "Courbes")
    (session,) = served_cylinder.sessions.values()
    assert session.controller.playing  # the cylinder rolls from the start
    session.controller.submit(Reset())  # the descent from 0, with the plots shown
    assert wait_for(lambda: session.controller.sim.data.time < 1.0, timeout=10)
    ranges = set()
    checked = 0
    deadline_time = 9.0
    while session.controller.sim.data.time < deadline_time:
        at = session.controller.sim.data.time  # the next look: half a simulated second on
        assert wait_for(lambda at=at: session.controller.sim.data.time > at + 0.5, timeout=10)
        charts = page.evaluate(CHARTS)
        assert charts, "no chart in the page"
        for chart in charts:
            if chart["last"] is None or chart["last"] < 1.0:
                continue
            ranges.add((chart["ymin"], chart["ymax"]))
            # Drawn up to the latest sample (one refresh late at most: 0.1 s at 10 Hz,
            # and the time the page takes to draw it).
            assert chart["xmax"] == pytest.approx(chart["last"], abs=0.5), chart
            assert chart["coloured"] > 50 and chart["right"] > 10, f"blank chart: {chart}"
            checked += 1
    assert checked >= 10
    assert len(ranges) >= 4, f"the vertical range never changed: {ranges}"


def test_scene_table_is_french_with_a_decimal_comma(open_page, served_cylinder):
    page = open_page(served_cylinder.url)
    table = page.locator("table").first
    table.wait_for(timeout=30_000)
    text = page.locator("body").inner_text()
    assert "<span" not in text and "title=" not in text
    shown = table.inner_text()
    for code in ("slip_velocity", "mu_required", "P_contact", "delta_A", "on_plane"):
        assert code not in shown, code
    assert "Vitesse du centre v [m/s]" in shown and "|Tt|" not in shown
    cells = page.locator("[data-readout]").all_inner_texts()
    numbers = [c for c in cells if re.search(r"\d", c)]
    assert numbers and not any(re.search(r"\d\.\d", c) for c in numbers), numbers


def test_plot_ticks_use_a_decimal_comma_in_a_french_browser(browser, served_cylinder):
    """uPlot writes tick labels in the browser's language: a lab PC set to French reads
    "0,05" (viser cannot send a JavaScript formatter)."""
    context = browser.new_context(viewport={"width": 1280, "height": 720}, locale="fr-FR")
    try:
        page = context.new_page()
        page.goto(served_cylinder.url)
        page.get_by_text("Panneau affiché", exact=True).first.wait_for(timeout=30_000)
        choose(page, "Panneau affiché", "Courbes")
        (session,) = served_cylinder.sessions.values()
        session.controller.playing = True
        read = (
            "() => Object.values((window.__viserTestpoints || {}).uplots || {}).flatMap("
            "(e) => e.chart.axes.flatMap((a) => (a._values || []).map(String)))"
        )
        found: list[list[str]] = []

        def fractions_shown() -> bool:  # the charts have data with decimal ticks
            found.append(page.evaluate(read))
            return any(re.search(r"\d[.,]\d", t) for t in found[-1])

        wait_for(fractions_shown, timeout=20)
        ticks = found[-1]
    finally:
        context.close()
    fractions = [t for t in ticks if re.search(r"\d[.,]\d", t)]
    assert fractions, ticks
    assert all("," in t and "." not in t for t in fractions), fractions
