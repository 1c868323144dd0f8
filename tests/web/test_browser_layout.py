"""The page on phones and tablets (sandbox.web.page.layout), in headless Chromium with
touch emulation: the 3D view, the readout strip and the control sheet side by side or
stacked without overlap, the mechanism whole in the view, a swipe over the sliders that
scrolls and changes nothing, touch targets of 44 px, and the desktop layout untouched."""

from __future__ import annotations

import io
import time
from collections.abc import Callable, Iterator

import numpy as np
import pytest
from conftest import choose, free_port, settled, wait_for
from PIL import Image

from sandbox.web.page.layout import STRIP_ID, TOUCH_PX
from sandbox.web.panels.projector import OVERLAY_ID, OVERLAY_LABEL

pytestmark = [pytest.mark.browser, pytest.mark.slow]  # Chromium pages: 10-20 s each

SCENES = ("rotor", "wheel_balancer", "compressor", "engine")

GEOMETRY = """([overlayId, stripId]) => {
  const box = e => { if (!e) return null; const r = e.getBoundingClientRect();
    return {x: r.x, y: r.y, w: r.width, h: r.height, right: r.right, bottom: r.bottom}; };
  const overlay = document.getElementById(overlayId);
  const strip = document.getElementById(stripId);
  const lines = [];
  if (overlay) { let line = "";
    overlay.childNodes.forEach(n => { if (n.nodeName === "BR") { lines.push(line); line = ""; }
      else line += n.textContent; });
    if (line) lines.push(line); }
  return {
    view: box(document.querySelector("[data-sandbox=view]")),
    strip: box(strip), sheet: box(document.querySelector("[data-sandbox=sheet]")),
    canvas: box(document.querySelector("#root canvas")),
    overlayShown: !!overlay && getComputedStyle(overlay).display !== "none",
    overlay: box(overlay), overlayLines: lines,
    stripLines: strip ? [...strip.children].map(s => s.textContent) : [],
    stripShown: !!strip && getComputedStyle(strip).display !== "none",
    marked: document.querySelectorAll("[data-sandbox]").length,
    width: innerWidth, height: innerHeight, scrollY: scrollY,
  };
}"""

OVERFLOW = """() => {
  // elements past the window's sides that are not in a box of their own scrolling sideways
  // (a wide table); the sheet's own scrolling area and boxes that cut their content off
  // do not count: what they hide cannot be read
  const W = innerWidth, bad = [];
  for (const e of document.querySelectorAll("body *")) {
    const r = e.getBoundingClientRect();
    if (r.width === 0 || r.height === 0 || (r.left >= -1 && r.right <= W + 1)) continue;
    let scrolls = false;
    for (let a = e.parentElement; a && a !== document.body; a = a.parentElement) {
      const ox = getComputedStyle(a).overflowX;
      if ((ox !== "auto" && ox !== "scroll") || a.matches(".mantine-ScrollArea-viewport"))
        continue;
      const ar = a.getBoundingClientRect();
      if (ar.left >= -1 && ar.right <= W + 1) { scrolls = true; break; }
    }
    if (!scrolls) bad.push(e.tagName + "." + e.className + " " + Math.round(r.left) + ".." +
      Math.round(r.right));
  }
  return {scrollWidth: document.documentElement.scrollWidth, bad: bad.slice(0, 5)};
}"""

TARGETS = """(touch) => {
  // the sheet's touch targets on show: how many of each kind, and those under `touch` px
  const sheet = document.querySelector("[data-sandbox=sheet]"), small = [], seen = {};
  const kinds = {"slider thumb": ".mantine-Slider-thumb", "button": ".mantine-Button-root",
    "folder title": "[data-with-border] > .mantine-Paper-root:first-child",
    "check box": ".mantine-Checkbox-input", "box": ".mantine-Input-input",
    "icon": ".mantine-ActionIcon-root", "panel title": ".mantine-Tabs-root > [role=button]"};
  for (const [what, css] of Object.entries(kinds))
    for (const e of sheet.querySelectorAll(css)) {
      const r = e.getBoundingClientRect();
      if (r.width === 0) continue;
      seen[what] = (seen[what] || 0) + 1;
      const square = what === "slider thumb" || what === "icon" || what === "check box";
      if (r.height < touch - 0.5 || (square && r.width < touch - 0.5))
        small.push([what, e.textContent.slice(0, 30), Math.round(r.width), Math.round(r.height)]);
    }
  return {seen: seen, small: small};
}"""

SLIDERS = """() => [...document.querySelectorAll("[data-sandbox=sheet] .mantine-Slider-root")]
  .map(s => { const t = s.querySelector(".mantine-Slider-track").getBoundingClientRect();
    const th = s.querySelector(".mantine-Slider-thumb");
    const h = th.getBoundingClientRect();
    return {label: th.getAttribute("aria-label"), value: th.getAttribute("aria-valuenow"),
      x: t.x, y: t.y + t.height / 2, w: t.width, thumbX: h.x + h.width / 2,
      thumbY: h.y + h.height / 2}; })"""

SCROLLED = """() => { const v = document.querySelector(
  "[data-sandbox=sheet] .mantine-ScrollArea-viewport"); return v ? v.scrollTop : -1; }"""


@pytest.fixture(scope="module")
def served() -> Iterator[Callable[..., object]]:
    """Apps started on demand, one per scene and lesson, stopped after the module."""
    from sandbox.web.serving.app import start

    apps: dict[tuple[str, str | None], object] = {}

    def get(scene: str, lesson: str | None = None):
        if (scene, lesson) not in apps:
            apps[scene, lesson] = start(scene, port=free_port(), open_message=False, lesson=lesson)
        return apps[scene, lesson]

    try:
        yield get
    finally:
        for app in apps.values():
            app.stop()  # type: ignore[attr-defined]


@pytest.fixture
def device(browser) -> Iterator[Callable[..., object]]:
    """Opens a page in a fresh context of the given size (touch: a phone or a tablet)."""
    contexts = []

    def open_(url: str, width: int, height: int, *, touch: bool = True):
        context = browser.new_context(
            viewport={"width": width, "height": height},
            has_touch=touch,
            is_mobile=touch,
            device_scale_factor=2 if touch else 1,
        )
        contexts.append(context)
        page = context.new_page()
        page.goto(url)
        page.locator(".mantine-Slider-thumb").first.wait_for(state="attached", timeout=60_000)
        # headless Chromium draws without a GPU: viser's notice of it would cover the view
        page.add_style_tag(content=".mantine-Notifications-root{display:none !important}")
        if touch:
            page.locator(f"#{STRIP_ID} span").first.wait_for(timeout=30_000)
        _settled(page)  # the canvas takes its size
        return page

    try:
        yield open_
    finally:
        for context in contexts:
            context.close()


CANVAS = """() => { const c = document.querySelector("canvas"); if (!c) return null;
  const r = c.getBoundingClientRect(); return [c.width, c.height, r.width, r.height]; }"""
CHART = """() => { const u = document.querySelector("[data-sandbox=sheet] .uplot");
  return u ? u.getBoundingClientRect().width : null; }"""


def _settled(page, script: str = CANVAS) -> None:
    """Wait until ``script`` reads the same value three times, 0,1 s apart (the canvas
    or a chart has taken its size)."""
    assert settled(lambda: page.evaluate(script)), page.evaluate(script)


def _geometry(page) -> dict:
    return page.evaluate(GEOMETRY, [OVERLAY_ID, STRIP_ID])


def _ink(page, box: dict) -> np.ndarray:
    """Where something is drawn in ``box`` of the page: pixels darker than the white
    background (True), the axes gizmo's corner left out."""
    png = page.screenshot(
        clip={"x": box["x"], "y": box["y"], "width": box["w"], "height": box["h"]}, scale="css"
    )
    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
    ink = pixels.min(axis=2) < 225
    ink[-100:, :100] = False  # the axes gizmo, bottom left
    assert ink.sum() > 500, "nothing drawn in the 3D view"
    return ink


EDGE = 3
"""Width [px] of the band along each side of the view where the mechanism must not be."""

EDGE_RUN = 16
"""Longest stretch [px] of a side that may be drawn on: an arrow's tip or a label's end
(an arrow's length follows a force); a machine cut by the side covers much more."""


def _assert_framed(page, box: dict) -> None:
    """The mechanism is whole in ``box`` (at most an arrow's tip or a label's end on its
    sides) and not tiny."""
    ink = _ink(page, box)
    sides = {
        "left": ink[:, :EDGE].any(axis=1),
        "right": ink[:, -EDGE:].any(axis=1),
        "top": ink[:EDGE, :].any(axis=0),
        "bottom": ink[-EDGE:, :].any(axis=0),
    }
    cut = {side: int(run.sum()) for side, run in sides.items() if run.sum() > EDGE_RUN}
    assert not cut, f"mechanism cut by the view's sides (px drawn along them): {cut}"
    ys, xs = np.nonzero(ink)
    w, h = ink.shape[1], ink.shape[0]
    span_x, span_y = int(xs.max() - xs.min()), int(ys.max() - ys.min())
    assert span_x > 0.35 * w or span_y > 0.35 * h, f"mechanism tiny: {span_x}×{span_y}"


def _assert_no_overlap(*boxes: dict) -> None:
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            apart = (
                a["right"] <= b["x"] + 0.5
                or b["right"] <= a["x"] + 0.5
                or a["bottom"] <= b["y"] + 0.5
                or b["bottom"] <= a["y"] + 0.5
            )
            assert apart, f"{a} overlaps {b}"


def _assert_inside_window(g: dict, *boxes: dict) -> None:
    for b in boxes:
        assert b["x"] >= -0.5 and b["y"] >= -0.5, b
        assert b["right"] <= g["width"] + 0.5 and b["bottom"] <= g["height"] + 0.5, b


def _assert_no_horizontal_scroll(page) -> None:
    over = page.evaluate(OVERFLOW)
    assert over["scrollWidth"] <= page.viewport_size["width"], over
    assert over["bad"] == [], over


def _assert_strip_shows_the_readouts(g: dict) -> None:
    assert not g["overlayShown"], "the overlay inside the sheet should give way to the strip"
    assert g["stripShown"] and g["overlayLines"], g
    assert g["stripLines"] == g["overlayLines"]
    assert all("=" in line for line in g["stripLines"]), g["stripLines"]


@pytest.mark.parametrize("size", [(390, 844), (360, 640)])
def test_upright_phone_stacks_view_strip_and_sheet(served, device, size):
    width, height = size
    page = device(served("rotor").url, width, height)
    g = _geometry(page)
    view, strip, sheet = g["view"], g["strip"], g["sheet"]
    assert view is not None and strip is not None and sheet is not None, g
    assert view["y"] == 0 and view["h"] >= 0.4 * height, view
    assert view["bottom"] <= strip["y"] + 0.5 and strip["bottom"] <= sheet["y"] + 0.5, g
    assert g["canvas"]["h"] == pytest.approx(view["h"], abs=1)  # the 3D drawn in the view
    for box in (view, strip, sheet):
        assert box["w"] == pytest.approx(width, abs=1), box
    _assert_inside_window(g, view, strip, sheet)
    _assert_no_overlap(view, strip, sheet)
    _assert_strip_shows_the_readouts(g)
    _assert_no_horizontal_scroll(page)
    _assert_framed(page, view)
    if size == (390, 844):  # a slider in reach: whole in the sheet's visible part
        first = page.evaluate(SLIDERS)[0]
        assert sheet["y"] + 22 <= first["thumbY"] <= min(sheet["bottom"], height) - 22, first
        assert g["scrollY"] == 0
        choose(page, "Panneau affiché", "Projecteur")  # a check box on show
        page.get_by_text(OVERLAY_LABEL, exact=True).wait_for(timeout=10_000)
        targets = page.evaluate(TARGETS, TOUCH_PX)
        assert len(targets["seen"]) == 7 and targets["small"] == [], targets


@pytest.mark.parametrize("scene", [s for s in SCENES if s != "rotor"])  # rotor: above
def test_each_machine_is_whole_in_the_upright_phone_view(served, device, scene):
    page = device(served(scene).url, 390, 844)
    g = _geometry(page)
    _assert_framed(page, g["view"])
    _assert_no_overlap(g["view"], g["strip"], g["sheet"])
    _assert_strip_shows_the_readouts(g)


def _touch(cdp, kind: str, x: float = 0.0, y: float = 0.0) -> None:
    points = [] if kind == "touchEnd" else [{"x": x, "y": y}]
    cdp.send("Input.dispatchTouchEvent", {"type": kind, "touchPoints": points})


def _drag(cdp, x0: float, y0: float, x1: float, y1: float, steps: int = 12) -> None:
    _touch(cdp, "touchStart", x0, y0)
    for i in range(1, steps + 1):
        _touch(cdp, "touchMove", x0 + (x1 - x0) * i / steps, y0 + (y1 - y0) * i / steps)
        time.sleep(0.02)
    _touch(cdp, "touchEnd")


def _off_thumb(slider: dict) -> float:
    """A point of the slider's track [px] far from its thumb: 85 % or 15 % of the way."""
    far = 0.85 if slider["thumbX"] < slider["x"] + slider["w"] / 2 else 0.15
    return slider["x"] + far * slider["w"]


def test_vertical_swipe_over_sliders_scrolls_and_changes_no_value(served, device):
    app = served("rotor")
    page = device(app.url, 390, 844)
    cdp = page.context.new_cdp_session(page)
    sheet = _geometry(page)["sheet"]
    session = next(iter(app.sessions.values()))  # type: ignore[attr-defined]
    sim_values = dict(session.controller.sim.values)
    before = {s["label"]: s["value"] for s in page.evaluate(SLIDERS)}
    swiped = 0
    for _ in range(3):  # up the sheet, over every slider in sight, off their thumbs
        for s in page.evaluate(SLIDERS):
            if not sheet["y"] + 30 < s["y"] < sheet["bottom"] - 30:
                continue
            x = _off_thumb(s)
            start = page.evaluate(SCROLLED)
            _drag(cdp, x, s["y"], x, s["y"] - 120)
            swiped += 1
            assert wait_for(lambda start=start: page.evaluate(SCROLLED) > start + 30), (
                f"swiping over {s['label']} did not scroll the sheet"
            )
            break
    assert swiped == 3
    _settled(page, SLIDERS)  # whatever the swipes did has landed
    assert {s["label"]: s["value"] for s in page.evaluate(SLIDERS)} == before
    assert session.controller.sim.values == sim_values
    # the sliders still answer: a tap on a track sets its value, a thumb drags
    target = next(
        s for s in page.evaluate(SLIDERS) if sheet["y"] + 30 < s["y"] < sheet["bottom"] - 30
    )
    page.touchscreen.tap(_off_thumb(target), target["y"])

    def value(label: str) -> str:
        return next(s["value"] for s in page.evaluate(SLIDERS) if s["label"] == label)

    assert wait_for(lambda: value(target["label"]) != before[target["label"]])
    tapped = value(target["label"])
    moved = next(s for s in page.evaluate(SLIDERS) if s["label"] == target["label"])
    _drag(cdp, moved["thumbX"], moved["thumbY"], target["x"] + target["w"] / 2, moved["thumbY"])
    assert wait_for(lambda: value(target["label"]) != tapped)


def test_folding_the_sheet_keeps_the_readouts_and_the_mechanism_whole(served, device):
    page = device(served("rotor").url, 360, 640)
    before = _geometry(page)
    page.locator("[data-sandbox=sheet]").get_by_text("Dynamique des solides", exact=True).tap()
    assert wait_for(lambda: _geometry(page)["sheet"]["h"] < 100)
    _settled(page)  # the canvas takes its new size
    g = _geometry(page)
    _assert_strip_shows_the_readouts(g)
    assert g["view"]["h"] > before["view"]["h"] + 150
    _assert_no_overlap(g["view"], g["strip"], g["sheet"])
    _assert_inside_window(g, g["view"], g["strip"], g["sheet"])
    assert g["canvas"]["h"] <= g["canvas"]["w"] + 1  # not taller than wide: sides kept
    _assert_framed(page, g["canvas"])


def test_the_lesson_comes_first_in_the_sheet_and_fits_the_phone(served, device):
    page = device(served("wheel_balancer", "equilibreuse").url, 390, 844)
    sheet = page.locator("[data-sandbox=sheet]")
    header = sheet.locator(".mantine-Tabs-root > [role=button]").first
    folder = sheet.locator("[data-with-border] > .mantine-Paper-root:first-child").first
    above, below = header.bounding_box(), folder.bounding_box()
    assert above is not None and below is not None
    assert above["y"] + above["height"] <= below["y"] and above["height"] >= TOUCH_PX
    header.tap()
    sheet.locator(".uplot").first.wait_for(timeout=30_000)  # the step's goal, a chart
    _settled(page, CHART)  # the chart takes its width
    _assert_no_horizontal_scroll(page)


def test_landscape_phone_has_a_side_panel(served, device):
    page = device(served("wheel_balancer", "equilibreuse").url, 844, 390)
    g = _geometry(page)
    view, strip, sheet = g["view"], g["strip"], g["sheet"]
    assert view["x"] == 0 and view["w"] >= 0.6 * 844 and view["h"] == pytest.approx(390, abs=1)
    assert strip["x"] >= view["right"] - 0.5 and sheet["x"] >= view["right"] - 0.5, g
    assert strip["bottom"] <= sheet["y"] + 0.5 and sheet["bottom"] <= 390.5, g
    _assert_no_overlap(view, strip, sheet)
    _assert_strip_shows_the_readouts(g)
    _assert_no_horizontal_scroll(page)
    _assert_framed(page, view)
    targets = page.evaluate(TARGETS, TOUCH_PX)
    assert len(targets["seen"]) >= 4 and targets["small"] == [], targets


def test_upright_tablet_stacks_and_keeps_the_bearings_in_view(served, device):
    page = device(served("rotor").url, 820, 1180)
    g = _geometry(page)
    view, strip, sheet = g["view"], g["strip"], g["sheet"]
    assert view["y"] == 0 and view["h"] >= 0.4 * 1180 and view["w"] == pytest.approx(820, abs=1)
    assert view["bottom"] <= strip["y"] + 0.5 and strip["bottom"] <= sheet["y"] + 0.5, g
    _assert_strip_shows_the_readouts(g)
    _assert_no_horizontal_scroll(page)
    _assert_framed(page, view)


def test_desktop_with_a_mouse_keeps_the_docked_panel_and_the_overlay(served, device):
    page = device(served("rotor").url, 1280, 720, touch=False)
    page.locator(f"#{OVERLAY_ID}").wait_for(timeout=30_000)
    g = _geometry(page)
    assert g["marked"] == 0 and g["view"] is None and not g["stripShown"], g
    assert page.evaluate("document.documentElement.hasAttribute('data-sandbox-sheet')") is False
    # viser's docked panel, 430 px at the right edge, as the server sets it
    panel = page.evaluate(
        """() => { const t = [...document.querySelectorAll("#root *")].find(e =>
          e.childElementCount === 0 && e.textContent === "Dynamique des solides");
          const r = t.closest(".mantine-Paper-root").getBoundingClientRect();
          return {x: r.x, w: r.width, right: r.right}; }"""
    )
    assert panel["w"] == pytest.approx(430, abs=3) and panel["right"] >= 1275, panel
    canvas, overlay = g["canvas"], g["overlay"]
    assert canvas["right"] <= panel["x"] + 3 and canvas["h"] == pytest.approx(720, abs=1)
    # the overlay in large print over the 3D view, bottom left, as projector.style_html says
    assert g["overlayShown"] and g["overlayLines"], g
    assert canvas["x"] <= overlay["x"] and overlay["right"] <= canvas["right"], g
    assert overlay["bottom"] == pytest.approx(720 - 12, abs=1)
    thumb = page.locator(".mantine-Slider-thumb").first.bounding_box()
    assert thumb is not None and thumb["width"] < 20 and thumb["height"] < 20, thumb
