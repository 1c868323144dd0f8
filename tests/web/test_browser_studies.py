"""« Tracé X–Y » and « Étude paramétrique » as a student sees them in headless Chromium:
in French, drawn (not blank charts), a study's dots arriving, a refusal in French, and a
cancelled study that leaves no process behind."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest
from conftest import choose, free_port, wait_for

from sandbox.web.loop.study_queue import StudyQueue
from tests.web.test_study_queue import _children

pytestmark = [pytest.mark.browser, pytest.mark.slow]

CHARTS = """() => Object.values((window.__viserTestpoints || {}).uplots || {}).map((entry) => {
  const chart = entry.chart, box = chart.bbox;
  const image = chart.ctx.getImageData(box.left, box.top, box.width, box.height).data;
  let coloured = 0;
  for (let i = 0; i < image.length; i += 4) {
    const r = image[i], g = image[i + 1], b = image[i + 2];
    if (Math.max(r, g, b) - Math.min(r, g, b) > 80) coloured += 1;
  }
  const title = chart.root.querySelector('.u-title');
  return {title: title ? title.textContent : '', coloured, xmin: chart.scales.x.min,
          xmax: chart.scales.x.max, ymin: chart.scales.y.min, ymax: chart.scales.y.max,
          visible: chart.root.offsetParent !== null};
})"""
"""Per chart: its title, how many saturated pixels its plotting area holds (lines and
dots), its ranges, and whether it is shown."""


def _served(scene: str) -> Iterator[object]:
    from sandbox.web.serving.app import start

    app = start(scene, port=free_port(), open_message=False)
    try:
        yield app
    finally:
        app.stop()


@pytest.fixture
def served_compressor() -> Iterator[object]:
    yield from _served("compressor")


def _chart(page, title: str) -> dict:
    charts = [c for c in page.evaluate(CHARTS) if c["title"] == title and c["visible"]]
    return charts[0] if charts else {}


def _shown(page, words: str) -> bool:
    """Some element showing exactly ``words`` is visible (hidden folders hold others)."""
    return any(e.is_visible() for e in page.get_by_text(words, exact=True).all())


def _no_english(text: str) -> None:
    for word in ("Value", "Loading", "undefined", "NaN", "null", "True", "False"):
        assert not re.search(rf"\b{word}\b", text), f"{word!r} on the page"


def test_the_xy_plot_draws_the_pilon_over_a_revolution_in_french(open_page, served_compressor):
    page = open_page(served_compressor.url)
    page.get_by_text("Panneau affiché", exact=True).first.wait_for(timeout=30_000)
    choose(page, "Panneau affiché", "Tracé X–Y")
    title = ""  # no title on the chart: the preset's name is above it (a phone cut it)
    preset = "Pilon et tamis sur un tour du vilebrequin"
    assert wait_for(  # the panel switched (a loaded machine takes a moment)
        lambda: (
            _shown(page, preset)
            or preset in page.locator("input").evaluate_all("(es) => es.map((e) => e.value)")
        )
    )
    assert wait_for(lambda: _chart(page, title).get("coloured", 0) > 500, timeout=20)
    chart = _chart(page, title)
    assert 0 <= chart["xmin"] < 40 and 320 < chart["xmax"] <= 360  # degrees, one turn
    assert chart["ymin"] < -100 < 100 < chart["ymax"]  # N: the pilon's ±300 N swing
    values = page.locator("input").evaluate_all(
        "(es) => es.filter((e) => e.offsetParent !== null).map((e) => e.value)"
    )
    assert {"Angle du vilebrequin θ [°]", "Effet de pilon [N]", "Effet de tamis [N]"} <= set(values)
    for words in (
        "Tracé proposé",
        "Axe horizontal X",
        "Courbe 1 (axe vertical Y)",
        "Curseur sur X [%]",
        "Figer le tracé",
        "Télécharger le tracé (CSV)",
        "Effet de pilon, cours",
    ):
        assert _shown(page, words), words
    reading = page.get_by_text(re.compile("pente")).first.inner_text()
    assert re.search(r"\d,\d", reading) and not re.search(r"\d\.\d", reading), reading
    assert "N/°" in reading
    _no_english(page.inner_text("body"))


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_a_study_runs_refuses_in_french_and_cancels_without_leftovers(open_page, served_rotor):
    page = open_page(served_rotor.url)
    page.get_by_text("Panneau affiché", exact=True).first.wait_for(timeout=30_000)
    choose(page, "Panneau affiché", "Étude paramétrique")
    assert wait_for(lambda: len(served_rotor.sessions) == 1)  # this page's alone
    (session,) = served_rotor.sessions.values()
    study = session.view.study
    assert study is not None
    page.get_by_role("button", name="Lancer l'étude").click()
    page.get_by_text(re.compile("Étude terminée : 13 simulations")).wait_for(timeout=60_000)
    title = "Effort du palier A [N]"
    assert wait_for(lambda: _chart(page, title).get("coloured", 0) > 150, timeout=10)
    chart = _chart(page, title)
    assert chart["xmin"] == 0 and chart["xmax"] == 6000 and chart["ymax"] >= 870  # 868 N
    for words in (
        "Étude proposée",
        "Paramètre varié",
        "Grandeur mesurée",
        "Ce qu'on en retient",
        "Durée de chaque simulation [s]",
        "Télécharger l'étude (CSV)",
    ):
        assert _shown(page, words), words
    _no_english(page.inner_text("body"))

    # a bound past the slider's range: one French refusal, nothing runs
    row = page.locator("div.mantine-Flex-root", has=page.get_by_text("À", exact=True)).last
    row.locator("input").first.fill("7000")
    row.locator("input").first.press("Tab")
    assert wait_for(lambda: study.stop.value == 7000)  # the server has the bound
    page.get_by_role("button", name="Lancer l'étude").click()
    page.get_by_text(re.compile("refusé, choisissez entre 0 et 6")).wait_for(timeout=10_000)

    # a long study (50 speeds × 3 defect masses × 20 s), cancelled: no process is left
    row.locator("input").first.fill("6000")
    choose(page, "Famille de courbes (second paramètre)", "Masselotte de défaut [g]")
    count = (
        page.locator("div.mantine-Flex-root", has=page.get_by_text("Nombre de points", exact=True))
        .last.locator("input")
        .first
    )
    count.fill("50")
    duration = (
        page.locator(
            "div.mantine-Flex-root",
            has=page.get_by_text("Durée de chaque simulation [s]", exact=True),
        )
        .last.locator("input")
        .first
    )
    duration.fill("20")
    duration.press("Tab")
    assert wait_for(lambda: study.duration.value == 20 and study.count.value == 50)
    before = _children()
    page.get_by_role("button", name="Lancer l'étude").click()
    page.get_by_role("button", name="Annuler l'étude").wait_for(timeout=10_000)
    assert wait_for(lambda: StudyQueue.shared().processes > 0, timeout=20)
    page.get_by_role("button", name="Annuler l'étude").click()
    page.get_by_text(re.compile("Étude annulée")).wait_for(timeout=10_000)
    assert wait_for(lambda: StudyQueue.shared().processes == 0, timeout=60)
    assert wait_for(lambda: _children() <= before, timeout=30)
