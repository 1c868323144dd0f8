"""The page for a keyboard and a screen reader: names, folders, keys, contrast.

viser's client is a prebuilt React/Mantine bundle that leaves its controls half reachable:
its sliders have an empty name (``aria-label=""``), its number boxes and icon buttons
none, its folder headers are ``<div>`` elements that the Tab key skips, and its control
labels are grey on white at 3,3:1 (WCAG asks 4,5:1). The bundle cannot be rebuilt here,
so :func:`html` adds to the page's head a style and a script that mend the page as it is
drawn:

- every control of a row takes the row's label as its name, the unit written after a
  comma ("Vitesse de rotation ω, tr/min"), and a slider reads its value with a decimal
  comma and its unit; icon buttons are named in French (:data:`ICON_NAMES`), and viser's
  English names built from a panel's title are put in French (:data:`PATTERNS`);
- every folder header is a button in the Tab order, opened and closed by Enter or Space,
  that says whether it is open (``aria-expanded``);
- Space pauses or plays the simulation (it clicks the time bar's button, whose words are
  :data:`PLAY_PAUSE`) unless the focus is in a box, on a button or on a folder header,
  where Space keeps its own meaning; the arrow keys move a focused slider by its step
  (Mantine's own keys: the script only keeps them from moving the 3D view as well, which
  viser does for any key not typed in a box);
- the style draws a visible focus ring on everything focusable, darkens the grey and blue
  texts to at least 4,5:1 on their background, writes a slider's end marks as large as the
  labels (its first and last marks inside the track's ends, "0,25" rather than viser's
  "0.25"), lets a button's words wrap and a box grow with its text instead of being cut at
  the larger text sizes of the "Projecteur" folder.

The script works over the page at most :data:`PASS_HZ` times a second, after the page
changed: nothing per drawn frame. When a viser release renames the classes this relies on
(``mantine-Slider-thumb``, ``tabler-icon-chevron-*``...), the page stays as viser draws it
and the browser tests of this module fail.
"""

from __future__ import annotations

import json

from sandbox.web.loop.requests import Pause, Play
from sandbox.web.panels.controls import COMMAND_KINDS

REPLAY_TOGGLE = "Lecture/Pause"
"""The replay's play/pause button (sandbox.web.replay.player.ReplayPanel.COMMANDS[0])."""

PLAY_PAUSE: tuple[str, ...] = (
    *(label for label, cmd in COMMAND_KINDS.items() if isinstance(cmd, (Pause, Play))),
    REPLAY_TOGGLE,
)
"""Words of the buttons Space clicks: the live time bar's "Pause"/"Lecture", the replay's
"Lecture/Pause" (a visible one rather than one in a closed folder)."""

SPACE_NEWS = {"Pause": "Simulation en pause", "Lecture": "Simulation en cours"}
"""What a screen reader says after Space clicked a button (by the button's words)."""

ICON_NAMES: dict[str, str] = {
    "tabler-icon-adjustments": "Configuration et diagnostic",
    "tabler-icon-x": "Fermer",
    "tabler-icon-copy": "Copier",
    "tabler-icon-check": "Copié",
    "tabler-icon-share": "Partager",
    "tabler-icon-arrows-maximize": "Agrandir",
    "tabler-icon-maximize": "Agrandir",
    "tabler-icon-minimize": "Réduire",
    "tabler-icon-chevron-left": "Replier",
    "tabler-icon-chevron-right": "Déplier",
    "tabler-icon-chevron-up": "Replier",
    "tabler-icon-chevron-down": "Déplier",
    "tabler-icon-player-play": "Lecture",
    "tabler-icon-player-pause": "Pause",
    "tabler-icon-search": "Chercher une commande",
    "tabler-icon-binary-tree": "Arbre de la scène",
    "tabler-icon-list-tree": "Arbre de la scène",
    "tabler-icon-eye": "Afficher",
    "tabler-icon-eye-off": "Masquer",
    "tabler-icon-pencil": "Modifier",
    "tabler-icon-dots": "Plus de choix",
}
"""French names of viser's icon buttons that have none, by their Tabler icon's class."""

CLOSE_NAME = "Fermer"
"""Name of Mantine's close buttons (notifications, dialogs), drawn without an icon class."""

SERVER_NAME = "Adresse du serveur"
"""Name of the settings' box holding the server's address (``ws://…``)."""

PATTERNS: tuple[tuple[str, str], ...] = (
    (r"^Collapse panel (.+)$", "Replier le panneau $1"),
    (r"^Expand panel (.+)$", "Déplier le panneau $1"),
    (r"^Minimize panel (.+)$", "Réduire le panneau $1"),
    (r"^Edit props for (.+)$", "Propriétés de $1"),
)
"""viser's English names built around a title (JavaScript regular expression ->
replacement); its fixed sentences are in sandbox.web.page.locale.FRENCH."""

STYLE_ID = "sandbox-access"
"""``id`` of the style element (a test removes it to compare the page without it)."""

PASS_HZ = 4.0
"""Most passes over the page per second (one pass follows a change of the page)."""

FOCUS_LIGHT = "#1864ab"
"""Focus ring on a light page (6,1:1 on white)."""

FOCUS_DARK = "#74c0fc"
"""Focus ring on a dark page."""

INK: dict[str, str] = {
    # Mantine's light-scheme colours under 4,5:1 on white, darkened: grey labels
    # (#868e96, 3,3:1) to 8,2:1, blue buttons and links (#228be6, 3,6:1) to 6,1:1...
    "--mantine-color-dimmed": "#495057",
    "--mantine-color-placeholder": "#6c757d",
    "--mantine-color-anchor": "#1864ab",
    "--mantine-primary-color-filled": "#1864ab",
    "--mantine-primary-color-filled-hover": "#145591",
    "--mantine-primary-color-light-color": "#1864ab",
    "--mantine-color-blue-filled": "#1864ab",
    "--mantine-color-blue-filled-hover": "#145591",
    "--mantine-color-blue-outline": "#1864ab",
    "--mantine-color-blue-light-color": "#1864ab",
    "--mantine-color-red-filled": "#c92a2a",
    "--mantine-color-red-filled-hover": "#a51d1d",
    "--mantine-color-red-outline": "#c92a2a",
    "--mantine-color-red-light-color": "#c92a2a",
    "--mantine-color-gray-filled": "#495057",
    "--mantine-color-gray-filled-hover": "#343a40",
    "--mantine-color-gray-outline": "#495057",
    "--mantine-color-gray-light-color": "#495057",
    "--mantine-color-error": "#c92a2a",
}
"""Mantine colour variables set on a light page (texts of at least 4,5:1 on white)."""


def style() -> str:
    """The ``<style>`` element: focus ring, darker inks, readable slider marks, buttons
    whose words wrap. Sizes are in ``em`` or follow Mantine's size variables, which the
    "Taille du texte" setting changes: the same rules hold at every text size."""
    ink = "".join(f"{name}:{value} !important;" for name, value in INK.items())
    return (
        f"<style id='{STYLE_ID}'>"
        f":root[data-mantine-color-scheme=light]{{{ink}}}"
        # a ring on whatever the keyboard reaches (Mantine draws one on some elements
        # only, 2 px of #228be6)
        ":focus-visible,.mantine-focus-auto:focus-visible,[data-sandbox-folder]:focus-visible"
        f"{{outline:3px solid {FOCUS_LIGHT} !important;outline-offset:2px !important}}"
        "[data-mantine-color-scheme=dark] :focus-visible,"
        "[data-mantine-color-scheme=dark] [data-sandbox-folder]:focus-visible"
        f"{{outline-color:{FOCUS_DARK} !important}}"
        ".mantine-Slider-thumb:focus-visible{outline-offset:3px !important}"
        # a slider's end marks: as dark as the labels, 7/8 of their size (not 12 px),
        # the first and last ones inside the track's ends (they overran the number box)
        ".mantine-Slider-root .mantine-Slider-markLabel{"
        "font-size:max(14px,calc(var(--mantine-font-size-sm) * .875)) !important;"
        "color:var(--mantine-color-dimmed) !important;white-space:nowrap}"
        ".mantine-Slider-root .mantine-Slider-markWrapper:first-child .mantine-Slider-markLabel"
        "{transform:translate(0,.05rem) !important}"
        ".mantine-Slider-root .mantine-Slider-markWrapper:last-child .mantine-Slider-markLabel"
        "{transform:translate(-100%,.05rem) !important}"
        # a button grows with its words instead of cutting them
        ".mantine-Button-root{height:auto !important;min-height:var(--button-height,2em)}"
        ".mantine-Button-inner{height:auto !important}"
        ".mantine-Button-label{white-space:normal !important;overflow:visible !important;"
        "text-align:center;line-height:1.15 !important;overflow-wrap:anywhere}"
        # a box or a list as tall as its words (viser fixes 1,625 rem: 24 px text in 24 px)
        ".mantine-Input-input{min-height:max(1.625rem,1.5em) !important}"
        # words a screen reader says, not shown
        ".sandbox-unseen{position:absolute !important;width:1px;height:1px;overflow:hidden;"
        "clip:rect(0 0 0 0);white-space:nowrap}"
        "</style>"
    )


_SCRIPT = r"""<script>(function () {
  var ICONS = %(icons)s, PATTERNS = %(patterns)s, PLAY = %(play)s, NEWS = %(news)s;
  var CLOSE = %(close)s, SERVER = %(server)s, EVERY = %(every_ms)d;
  var patterns = PATTERNS.map(function (p) { return [new RegExp(p[0]), p[1]]; });
  var CAMERA = {ArrowUp: 1, ArrowDown: 1, ArrowLeft: 1, ArrowRight: 1, KeyW: 1, KeyA: 1,
    KeyS: 1, KeyD: 1, KeyQ: 1, KeyE: 1};
  function set(el, name, value) {
    if (el.getAttribute(name) !== value) el.setAttribute(name, value);
  }
  // "Vitesse de rotation ω [tr/min]" -> "Vitesse de rotation ω, tr/min"
  function spoken(text) {
    text = text.replace(/\s+/g, " ").trim();
    return text.replace(/\s*\[([^\]]+)\]$/, ", $1");
  }
  function unitOf(text) {
    var m = /\[([^\]]+)\]\s*$/.exec(text.replace(/\s+/g, " ").trim());
    return m ? m[1] : "";
  }
  function french(v) {
    var n = Number(v);
    if (!isFinite(n)) return String(v);
    return n.toLocaleString("fr-FR", {maximumFractionDigits: 6});
  }
  function valueText(thumb) {
    var v = thumb.getAttribute("aria-valuenow");
    if (v === null) return;
    var unit = thumb.dataset.sandboxUnit || "";
    set(thumb, "aria-valuetext", french(v) + (unit ? " " + unit : ""));
    // the value Mantine shows over a thumb being moved, with a decimal comma too
    var shown = thumb.querySelector(".mantine-Slider-label");
    var text = shown && shown.firstChild;
    if (text && text.nodeType === 3 && /^[-\u2212]?\d+\.\d+$/.test(text.nodeValue)) {
      text.nodeValue = text.nodeValue.replace(".", ",");
    }
  }
  // Every control of a viser row named after the row's label.
  function rows() {
    document.querySelectorAll("label[for]").forEach(function (label) {
      var row = label.closest(".mantine-Flex-root");
      var text = label.textContent || "";
      if (!row || !text.trim()) return;
      var name = spoken(text), unit = unitOf(text);
      row.querySelectorAll(".mantine-Slider-thumb").forEach(function (thumb) {
        set(thumb, "aria-label", name);
        if (unit) thumb.dataset.sandboxUnit = unit;
        valueText(thumb);
      });
      row.querySelectorAll("input:not([type=hidden]),textarea").forEach(function (input) {
        set(input, "aria-label", name);
      });
    });
  }
  // Folder headers: a button in the Tab order that says whether it is open.
  function folders() {
    document.querySelectorAll(".mantine-Paper-root > .mantine-Paper-root:first-child")
      .forEach(function (head) {
        var chevron = head.querySelector(":scope > svg[class*='tabler-icon-chevron']");
        if (!chevron) return;
        var body = head.nextElementSibling;
        var open = body ? body.getAttribute("aria-hidden") !== "true"
          : /chevron-up/.test(chevron.getAttribute("class"));
        set(head, "data-sandbox-folder", "");
        set(head, "role", "button");
        set(head, "tabindex", "0");
        set(head, "aria-expanded", open ? "true" : "false");
        set(chevron, "aria-hidden", "true");
      });
  }
  function hasName(el) {
    if ((el.getAttribute("aria-label") || "").trim()) return true;
    if (el.getAttribute("aria-labelledby")) return true;
    if ((el.getAttribute("title") || "").trim()) return true;
    return (el.textContent || "").trim() !== "";
  }
  function iconName(el) {
    if (el.classList.contains("mantine-CloseButton-root")) return CLOSE;
    var icons = el.querySelectorAll("svg[class*='tabler-icon-']");
    for (var i = 0; i < icons.length; i++) {
      var classes = (icons[i].getAttribute("class") || "").split(/\s+/);
      for (var j = 0; j < classes.length; j++) {
        if (Object.prototype.hasOwnProperty.call(ICONS, classes[j])) return ICONS[classes[j]];
      }
    }
    return "";
  }
  // Boxes outside a labelled row: viser's server address (named by a tooltip only).
  function boxes() {
    document.querySelectorAll("input:not([type=hidden]):not([aria-label])").forEach(function (i) {
      if (i.labels && i.labels.length) return;
      var name = (i.getAttribute("placeholder") || "").trim();
      if (!name && /^wss?:\/\//.test(i.value)) name = SERVER;
      if (name) set(i, "aria-label", name);
    });
  }
  function buttons() {
    document.querySelectorAll("button,[role=button],[role=tab],a[href]").forEach(function (el) {
      var label = el.getAttribute("aria-label");
      if (label) {
        for (var i = 0; i < patterns.length; i++) {
          if (patterns[i][0].test(label)) {
            set(el, "aria-label", label.replace(patterns[i][0], patterns[i][1]).trim());
            return;
          }
        }
      }
      if (el.getAttribute("aria-hidden") === "true" || hasName(el)) return;
      var name = iconName(el);
      if (name) set(el, "aria-label", name);
    });
  }
  // A slider's end marks viser writes itself ("0.25"): with a decimal comma.
  function marks() {
    document.querySelectorAll(".mantine-Slider-markLabel").forEach(function (m) {
      var t = m.firstChild;
      if (t && t.nodeType === 3 && /^[-\u2212]?\d+\.\d+$/.test(t.nodeValue)) {
        t.nodeValue = t.nodeValue.replace(".", ",");
      }
    });
  }
  function pass() {
    timer = 0;
    rows();
    boxes();
    folders();
    buttons();
    marks();
  }
  var timer = 0;
  function soon(ms) {
    if (!timer) timer = setTimeout(pass, ms === undefined ? EVERY : ms);
  }
  // Space: the time bar's play/pause button, unless Space means something where it is.
  var TYPED = /^(INPUT|TEXTAREA|SELECT)$/;
  var PRESSED = new RegExp("^(button|checkbox|switch|radio|tab|option|menuitem|" +
    "menuitemcheckbox|link|combobox|textbox|searchbox|spinbutton|listbox)$");
  function ownSpace(el) {
    if (!el || el === document.body || el === document.documentElement) return false;
    if (TYPED.test(el.tagName) || el.isContentEditable) return true;
    if (el.tagName === "BUTTON" || (el.tagName === "A" && el.hasAttribute("href"))) return true;
    return PRESSED.test(el.getAttribute("role") || "");
  }
  function playPause() {
    var found = null;
    document.querySelectorAll("button").forEach(function (b) {
      var words = (b.textContent || "").trim();
      if (PLAY.indexOf(words) < 0) return;
      if (!found || (found.offsetParent === null && b.offsetParent !== null)) found = b;
    });
    return found;
  }
  var news = null;
  function say(text) {
    if (!news) {
      news = document.createElement("div");
      news.className = "sandbox-unseen";
      news.setAttribute("aria-live", "polite");
      document.body.appendChild(news);
    }
    news.textContent = text;
  }
  window.addEventListener("keydown", function (e) {
    if (e.ctrlKey || e.altKey || e.metaKey) return;
    var el = e.target;
    var folder = el && el.hasAttribute && el.hasAttribute("data-sandbox-folder");
    if (folder && (e.key === "Enter" || e.key === " ")) {
      e.preventDefault();
      e.stopPropagation();
      if (!e.repeat) el.click();
      setTimeout(folders, 50);
      return;
    }
    if (e.key !== " " || e.shiftKey || ownSpace(el) || ownSpace(document.activeElement)) return;
    e.preventDefault();
    e.stopPropagation();
    if (e.repeat) return;
    var button = playPause();
    if (!button) return;
    var words = (button.textContent || "").trim();
    button.click();
    if (NEWS[words]) say(NEWS[words]);
  }, true);
  // viser moves the 3D view on arrows and W A S D Q E typed anywhere but in a box: not
  // while the focus is on a control (a slider's arrows move the slider only).
  document.addEventListener("DOMContentLoaded", function () {
    document.body.addEventListener("keydown", function (e) {
      var el = e.target;
      if (!CAMERA[e.code] || !el || el === document.body || el.tagName === "CANVAS") return;
      if (el.closest && el.closest("canvas")) return;
      e.stopPropagation();
    });
    new MutationObserver(function (changes) {
      for (var i = 0; i < changes.length; i++) {
        var c = changes[i];
        if (c.type === "attributes" && c.attributeName === "aria-valuenow") {
          valueText(c.target);
        } else {
          soon();
        }
      }
    }).observe(document.body, {
      subtree: true, childList: true, attributes: true,
      attributeFilter: ["aria-hidden", "aria-label", "aria-valuenow"],
    });
    soon(0);
  });
})();</script>"""


def script() -> str:
    """The ``<script>`` element (its JSON escaped so that no text can close it)."""

    def js(value: object) -> str:
        return json.dumps(value, ensure_ascii=True).replace("<", "\\u003c")

    return _SCRIPT % {
        "icons": js(ICON_NAMES),
        "patterns": js([list(p) for p in PATTERNS]),
        "play": js(list(PLAY_PAUSE)),
        "news": js(SPACE_NEWS),
        "close": js(CLOSE_NAME),
        "server": js(SERVER_NAME),
        "every_ms": round(1000 / PASS_HZ),
    }


def html() -> str:
    """The elements added to the head of viser's page: :func:`style` and :func:`script`."""
    return style() + script()
