"""The page on phones and tablets: the 3D view on top (or left), the key readouts in a strip
of their own, the controls in a sheet that scrolls without moving any slider.

viser's prebuilt client has a desktop layout (the control panel docked beside the 3D view)
and, below 36 em (576 px), a mobile one: the panel becomes a sheet fixed over the bottom
60 % of the 3D view, 20 em wide. Neither suits a phone or a tablet: the sheet covers the
mechanism, the readout overlay (fixed, sized for a desktop) is squeezed to a word per line
over the controls and folds away with the sheet, a swipe over a slider drags its value,
and slider thumbs are 7×10 px. The client cannot be rebuilt, so :func:`html` adds to the
page's head

- a script that answers viser's "(max-width: 36em)" question with :data:`SHEET_MEDIA`
  (phones and tablets held upright, landscape screens at most :data:`LOW_PX` high, touch
  screens in landscape under :data:`TOUCH_WIDE_PX`), so that viser uses its sheet there;
  that marks the sheet, its row and the 3D view's box with ``data-sandbox`` attributes
  (found from the 3D canvas, not from viser's class names); and that copies the readout
  overlay's lines into a strip of its own placed between the view and the sheet (the
  overlay sits inside the sheet's folding part: the strip stays when the sheet folds);
- a style laying these out by orientation: upright, the view on top (at least
  :data:`VIEW_SHARE` of the height, more when the sheet is folded), the strip, then the
  sheet scrolling in the rest; in landscape, the view left and the strip and sheet in a
  column of :data:`SIDE_SHARE` of the width at most :data:`SIDE_MAX_PX`; in the sheet,
  the lesson panel first, nothing wider than the window, and a slider's label above it
  when the sheet is narrower than :data:`SLIDER_ROW_PX`;
- for touch screens only (``pointer: coarse``): targets of at least :data:`TOUCH_PX`
  (slider thumbs, buttons, folder titles, boxes, check boxes) and a guard that keeps a
  touch starting on a slider's track, off its thumb, from reaching the slider: a vertical
  swipe there scrolls the sheet; a tap still sets the value (the browser follows a tap
  with mouse events, which the slider takes).

Nothing here is used with a mouse on a screen wider than 1279 px: the desktop and
projector layouts stay as viser draws them. When a viser release changes its breakpoint
or the sheet's structure, the page falls back to viser's own layouts; the browser tests
of tests/web/test_browser_layout.py fail.
"""

from __future__ import annotations

import json

from sandbox.web.panels.projector import OVERLAY_ID

VIEWER_MOBILE_QUERY = "(max-width: 36em)"
"""The media query viser's client asks to choose its mobile sheet (Mantine's xs)."""

NARROW_PX = 900
"""Widest upright window [px] laid out as a phone or a tablet (view, strip, sheet)."""

LOW_PX = 500
"""Highest landscape window [px] laid out with a side sheet (a phone on its side)."""

TOUCH_WIDE_PX = 1280
"""Touch screens in landscape narrower than this [px] get the side sheet too (tablets):
viser's docked panel (430 px) would leave less than 60 % of the width to the view."""

SHEET_MEDIA = (
    f"{VIEWER_MOBILE_QUERY}, (max-width: {NARROW_PX}px) and (orientation: portrait), "
    f"(max-height: {LOW_PX}px) and (orientation: landscape), "
    f"(pointer: coarse) and (orientation: landscape) and (max-width: {TOUCH_WIDE_PX - 1}px)"
)
"""Where the page uses viser's sheet, laid out by :func:`html`'s style."""

VIEW_SHARE = 0.42
"""Least share of the window's height given to the 3D view, upright."""

TALLEST = 1.0
"""Greatest height/width ratio of the 3D canvas, upright [1]: the camera keeps its vertical
angle of view, so a taller canvas only zooms in and cuts the mechanism's sides (the scenes
are framed for a desktop view about as wide as high). When the sheet is folded the view's
box grows past it and the canvas stays centred in it."""

SIDE_SHARE = 0.38
"""Share of the window's width given to the side column (strip and sheet) in landscape."""

SIDE_MAX_PX = 430
"""Widest side column [px] (the desktop panel's width)."""

SLIDER_ROW_PX = 600
"""Narrowest sheet [px] where a slider keeps its label beside it; narrower, the label goes
above and the slider gets the row's whole width (a longer track to aim at)."""

TOUCH_PX = 44
"""Least size [px] of a touch target (slider thumbs, buttons, titles, boxes)."""

HANDLE_PX = 48
"""Height [px] of the sheet's handle (its title; a tap folds or unfolds the sheet)."""

STRIP_ID = "sandbox-strip"
"""Id of the readout strip the script adds (its lines copied from the overlay)."""

_STYLE = (
    "<style>"
    "#%(strip)s{display:none}"
    # the sheet found: the strip stands for the overlay (fixed, sized for a desktop)
    "html[data-sandbox-sheet] #%(overlay)s{display:none !important}"
    "[data-sandbox=row]>[data-sandbox=view]{order:1;height:auto !important;min-width:0;"
    "min-height:0}"
    "[data-sandbox=row]>#%(strip)s{order:2;display:flex;flex-wrap:wrap;gap:0 1.2em;"
    "padding:4px 12px;background:var(--mantine-color-gray-0,#f8f9fa);"
    "color:var(--mantine-color-text,#111);"
    "border-top:1px solid var(--mantine-color-default-border,#ccc);"
    "font-size:var(--mantine-font-size-md);line-height:1.35;"
    "font-variant-numeric:tabular-nums;overflow-wrap:anywhere}"
    "[data-mantine-color-scheme=dark] [data-sandbox=row]>#%(strip)s"
    "{background:var(--mantine-color-dark-6)}"
    "[data-sandbox=row]>#%(strip)s:empty{display:none}"
    # viser's sheet leaves its fixed place at the bottom right for the row's flow
    "[data-sandbox=row]>[data-sandbox=sheet]{order:3;position:relative !important;"
    "inset:auto !important;width:auto !important;max-height:none !important;"
    "min-height:0 !important;box-shadow:none;"
    "border-top:1px solid var(--mantine-color-default-border,#ccc)}"
    '[data-sandbox=sheet] [style*="width: 20em"]{width:auto !important}'
    # its content as wide as the window, not as its widest chart (a table there grew)
    "[data-sandbox=sheet] .mantine-ScrollArea-content{display:block !important;"
    "min-width:0 !important}"
    "[data-sandbox=sheet] .mantine-ScrollArea-viewport{overflow-x:hidden !important}"
    # its handle (title, fold on a tap): 48 px instead of 3.5 em
    '[data-sandbox=sheet] [style*="height: 3.5em"]{height:%(handle)dpx !important}'
    "[data-sandbox=sheet] table{display:block;max-width:100%%;overflow-x:auto}"
    # the other panels (the lesson), which viser lists after the controls, come first
    "[data-sandbox=sheet] div:has(>div>.mantine-Tabs-root){display:flex;"
    "flex-direction:column}"
    "[data-sandbox=sheet] div:has(>.mantine-Tabs-root){order:-1}"
    "[data-sandbox=sheet] div:has(>div>.mantine-Tabs-root)>.mantine-Divider-root{order:-2}"
    # a narrow sheet: a slider's label above it, the track across the row
    "[data-sandbox=sheet]{container-type:inline-size}"
    "@container (max-width:%(narrow_row)dpx){"
    '[data-sandbox=sheet] .mantine-Flex-root:has(>div[style*="width: 6.6125em"])'
    ":has(.mantine-Slider-root){flex-wrap:wrap}"
    "[data-sandbox=sheet] .mantine-Flex-root:has(.mantine-Slider-root)"
    '>div[style*="width: 6.6125em"]{width:100%% !important}}'
    # upright: view, strip, sheet from top to bottom; the folded sheet gives its room to
    # the view's box, where the canvas stays centred, at most as high as wide
    "@media (orientation:portrait){"
    "[data-sandbox=row]{flex-direction:column !important}"
    "[data-sandbox=row]>[data-sandbox=view]{flex:1 0 %(view)s !important;display:flex;"
    "flex-direction:column;justify-content:center}"
    "[data-sandbox=view]>*{flex:0 0 auto;height:min(100%%,%(tall)s) !important}"
    "[data-sandbox=row]>#%(strip)s{flex:0 0 auto}"
    "[data-sandbox=row]>[data-sandbox=sheet]{flex:0 1 auto !important}}"
    # landscape: the view left, the strip over the sheet in a column at the right
    "@media (orientation:landscape){"
    "[data-sandbox=row]{display:grid !important;grid-template-rows:auto minmax(0,1fr);"
    "grid-template-columns:minmax(0,1fr) min(%(side)s,%(side_max)dpx)}"
    "[data-sandbox=row]>[data-sandbox=view]{grid-area:1/1/3/2}"
    "[data-sandbox=row]>#%(strip)s{grid-area:1/2/2/3}"
    "[data-sandbox=row]>[data-sandbox=sheet]{grid-area:2/2/3/3}"
    "[data-sandbox=row]>#%(strip)s,[data-sandbox=row]>[data-sandbox=sheet]"
    "{border-left:1px solid var(--mantine-color-default-border,#ccc)}}"
    # touch: 44 px targets (":root" outranks the other additions' one-class rules); a
    # slider's thumb is a transparent square around a 22 px disc; its track lets a
    # vertical swipe scroll the sheet; a check box is a 24 px square in a 44 px one
    "@media (pointer:coarse){"
    ":root .mantine-Slider-root{height:%(touch)dpx !important;"
    "touch-action:pan-y !important;margin-inline:%(inset)dpx}"
    ":root .mantine-Slider-trackContainer{height:%(touch)dpx !important}"
    ":root .mantine-Slider-thumb{width:%(touch)dpx !important;height:%(touch)dpx !important;"
    "border:0 !important;background:transparent !important;box-shadow:none !important}"
    ':root .mantine-Slider-thumb::before{content:"";width:22px;height:22px;'
    "border-radius:50%%;box-sizing:border-box;border:3px solid var(--slider-color);"
    "background:#fff}"
    ":root .mantine-Button-root{height:auto !important;min-height:%(touch)dpx !important}"
    ":root .mantine-ActionIcon-root{min-width:%(touch)dpx !important;"
    "min-height:%(touch)dpx !important}"
    ":root .mantine-Input-input{min-height:%(touch)dpx !important}"
    ":root .mantine-Select-option{min-height:%(touch)dpx}"
    ":root .mantine-Checkbox-inner{width:%(touch)dpx !important;"
    "height:%(touch)dpx !important}"
    ":root .mantine-Checkbox-input{width:%(touch)dpx !important;"
    "height:%(touch)dpx !important;border:10px solid transparent !important;"
    "background-clip:padding-box;box-shadow:inset 0 0 0 1px var(--mantine-color-gray-5)}"
    ":root .mantine-Checkbox-input:checked{box-shadow:none}"
    ":root .mantine-Checkbox-inner>svg{width:14px !important}"
    ":root .mantine-Checkbox-body,:root .mantine-Switch-body{align-items:center;"
    "min-height:%(touch)dpx}"
    ":root .mantine-Tabs-root>[role=button],:root .mantine-Tabs-tab"
    "{min-height:%(touch)dpx !important}"
    # a folder's title, drawn over the frame's top line by viser, becomes its first row
    ":root [data-with-border]>.mantine-Paper-root:first-child{position:relative;"
    "transform:none;left:0;min-height:%(touch)dpx;display:flex;align-items:center}"
    ":root [data-with-border]>div:last-child>div:empty{display:none}}"
    "</style>"
)

_SCRIPT = """<script>(function () {
  var asked = %(asked)s, sheetMedia = %(sheet)s, overlayId = %(overlay)s;
  var media = window.matchMedia && window.matchMedia.bind(window);
  if (media) window.matchMedia = function (q) {
    return media(String(q).trim() === asked ? sheetMedia : q);
  };
  var sheetList = media ? media(sheetMedia) : {matches: false};
  var strip = document.createElement("div"), shown = null, at = null;
  strip.id = %(strip)s;
  function mark(el, name) { if (el.dataset.sandbox !== name) el.dataset.sandbox = name; }
  // viser's sheet: a fixed Paper beside the box holding the 3D canvas, in the same row
  function find() {
    var canvas = document.querySelector("#root canvas");
    for (var el = canvas; el && el.parentElement; el = el.parentElement) {
      var row = el.parentElement;
      if (row.id === "root") break;
      for (var c = row.firstElementChild; c; c = c.nextElementSibling)
        if (c !== el && c.classList.contains("mantine-Paper-root") &&
            c.style.position === "fixed") return {row: row, view: el, sheet: c};
    }
    return null;
  }
  function place() {
    if (!(at && at.sheet.isConnected && at.view.isConnected &&
          at.sheet.parentElement === at.row)) {
      if (at) ["row", "view", "sheet"].forEach(function (k) { delete at[k].dataset.sandbox; });
      at = find();
    }
    if (!at) {
      shown = null;
      document.documentElement.removeAttribute("data-sandbox-sheet");
      if (strip.parentElement) strip.remove();
      return;
    }
    document.documentElement.setAttribute("data-sandbox-sheet", "");
    mark(at.row, "row"); mark(at.view, "view"); mark(at.sheet, "sheet");
    if (strip.parentElement !== at.row) at.row.insertBefore(strip, at.sheet);
  }
  // the overlay's lines (text and <br>) become the strip's lines, as text
  function copy() {
    var overlay = document.getElementById(overlayId);
    var html = overlay ? overlay.innerHTML : "";
    if (html === shown) return;
    shown = html;
    var lines = [], line = "";
    if (overlay) overlay.childNodes.forEach(function (n) {
      if (n.nodeName === "BR") { lines.push(line); line = ""; } else line += n.textContent;
    });
    if (line) lines.push(line);
    strip.replaceChildren.apply(strip, lines.map(function (t) {
      var span = document.createElement("span");
      span.textContent = t;
      return span;
    }));
  }
  // checked at every change of the page (viser remounts the sheet on a reconnection)
  new MutationObserver(function () {
    if (sheetList.matches || at) place();
    if (at) copy();
  }).observe(document.documentElement, {childList: true, subtree: true});
  // a touch on a slider off its thumb never reaches the slider: the sheet scrolls
  function thumbAt(slider, x, y) {
    var thumbs = slider.querySelectorAll(".mantine-Slider-thumb");
    for (var i = 0; i < thumbs.length; i++) {
      var r = thumbs[i].getBoundingClientRect(), h = %(half)d;
      var cx = r.left + r.width / 2, cy = r.top + r.height / 2;
      if (Math.abs(x - cx) <= h && Math.abs(y - cy) <= h) return true;
    }
    return false;
  }
  function guard(e) {
    if (e.type === "pointerdown" && e.pointerType !== "touch") return;
    var slider = e.target && e.target.closest && e.target.closest(".mantine-Slider-root");
    if (!slider) return;
    var p = e.touches ? e.touches[0] : e;
    if (p && !thumbAt(slider, p.clientX, p.clientY)) e.stopPropagation();
  }
  window.addEventListener("touchstart", guard, {capture: true, passive: true});
  window.addEventListener("pointerdown", guard, true);
})();</script>"""


def html() -> str:
    """The ``<style>`` and ``<script>`` added to the head of viser's page (constant)."""
    style = _STYLE % {
        "strip": STRIP_ID,
        "overlay": OVERLAY_ID,
        "view": f"{round(VIEW_SHARE * 100)}%",
        "tall": f"{round(TALLEST * 100)}vw",
        "side": f"{round(SIDE_SHARE * 100)}%",
        "side_max": SIDE_MAX_PX,
        "touch": TOUCH_PX,
        "inset": TOUCH_PX // 2 - 4,  # the thumb's overhang past the track's ends
        "narrow_row": SLIDER_ROW_PX,
        "handle": HANDLE_PX,
    }
    script = _SCRIPT % {
        "asked": json.dumps(VIEWER_MOBILE_QUERY),
        "sheet": json.dumps(SHEET_MEDIA),
        "overlay": json.dumps(OVERLAY_ID),
        "strip": json.dumps(STRIP_ID),
        "half": TOUCH_PX // 2,
    }
    return style + script
