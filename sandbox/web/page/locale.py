"""French words for the few sentences viser's own client writes, and a French locale for
the numbers it formats.

viser's browser client is a prebuilt bundle: its browser warnings ("Software WebGL rendering
detected" on a lab PC without a graphics driver), a few tooltips and the ticks of its uPlot
charts (formatted for ``navigator.language``) would otherwise reach the page in English.
:func:`install` makes every viser server of this process serve that same bundle with a
short script added at the top of the page, which

- declares the page French (``<html lang="fr">``) and gives ``navigator.language`` as
  ``fr-FR``, so that chart ticks are written with a decimal comma;
- draws over every number box that is not being edited (viser's boxes write "0.25" and
  accept only the point) the same value with a decimal comma, "0,25";
- replaces, as soon as it appears, any text or tooltip that is exactly one of the English
  sentences of :data:`FRENCH` by its French version, and closes the software-rendering
  warning after a few seconds (:data:`CLOSING`).

The bundle itself is not changed (it is copied as is); when a viser release moves the
things this relies on, :func:`install` leaves viser's page untouched and the browser tests
that read the page in French fail.
"""

from __future__ import annotations

import atexit
import json
import re
import shutil
import tempfile
import threading
from pathlib import Path
from typing import Any

import viser.infra as infra

from sandbox.web.page import access as client_access
from sandbox.web.page import layout as client_layout
from sandbox.web.page import link as client_link

FRENCH: dict[str, str] = {
    "Software WebGL rendering detected": "Rendu 3D sans carte graphique",
    "WebGL is running in software mode, not on your GPU. Performance may be degraded. "
    "If this is unexpected, check that hardware acceleration is enabled in your browser "
    "settings.": "Le processeur dessine la 3D à la place de la carte graphique : "
    "l'animation peut être moins fluide. Si ce n'est pas voulu, activez l'accélération "
    "matérielle dans les réglages du navigateur.",
    "WebGL unavailable": "3D indisponible",
    "WebGL is unavailable. This may be caused by hardware acceleration being disabled — "
    "check your browser settings.": "Le navigateur ne peut pas dessiner la 3D : "
    "l'accélération matérielle est peut-être désactivée dans ses réglages.",
    "Could not detect browser version": "Version du navigateur inconnue",
    "Your browser version could not be detected. It may not be supported.": "La version "
    "du navigateur n'a pas pu être lue : il se peut que la page y fonctionne mal.",
    "Unsupported browser": "Navigateur trop ancien",
    "Connection rejected": "Connexion refusée",
    "Connecting...": "Connexion au serveur…",  # the page before its first connection
    "Version mismatch": "Versions incompatibles",
    "Open navigation": "Ouvrir le menu",
    "Close navigation": "Fermer le menu",
    "Control panel": "Panneau de commande",
    "Scene tree": "Arbre de la scène",
    "Playback speed": "Vitesse de lecture",
    "Search commands...": "Chercher une commande…",
    "No matching commands...": "Aucune commande trouvée…",
    # the panel behind the control panel's settings button
    "Configuration & diagnostics": "Configuration et diagnostic",
    "Return to GUI": "Retour aux commandes",
    "Server URL": "Adresse du serveur",
    "Save Canvas": "Enregistrer l'image",
    "Reset View": "Vue initiale",
    "Orbit Origin Tool": "Centre de la vue",
    "Show tool for setting the look-at point and": "Outil pour placer le point visé et",
    "up direction of the camera.": "la verticale de la caméra.",
    "This can be used to set the origin of the": "Il fixe le point autour duquel",
    "camera's orbit controls.": "la caméra tourne.",
    "Dev Settings": "Réglages de l'affichage",
    "Hierarchical view of all objects in the 3D scene.": "Les objets de la scène 3D, en arbre.",
    "Use to override visibility and properties.": "On peut y changer leur visibilité.",
    "Dark Mode": "Mode sombre",
    "WebGL Stats": "Statistiques du rendu 3D",
    "Show Viser Logo": "Logo de viser",
    "Log Camera to Console": "Caméra dans la console",
    "Log camera position and orientation to the": "Écrit la position et l'orientation de la caméra",
    "Javascript console.": "dans la console Javascript.",
    "Show Orbit Crosshair": "Croix au point visé",
    "Show crosshair at look-at point": "Montre une croix au point visé",
    "when moving camera.": "quand la caméra bouge.",
    "Device Pixel Ratio": "Résolution du rendu",
    "Device pixel ratio for rendering.": "Pixels calculés par pixel d'écran.",
    "Default (adaptive) behavior dynamically": "Adaptative : elle baisse d'elle-même",
    "reduces resolution to maintain framerates.": "pour garder une animation fluide.",
    "Adaptive": "Adaptative",
    "Discard any panel rearrangement and restore the layout the server set.": "Oublie les "
    "panneaux déplacés et revient à la disposition d'origine.",
    "Reset Panel Layout": "Disposition d'origine",
    "Share": "Partager",
    "Server": "Serveur",
    "Disconnect": "Déconnecter",
    "Copy URL": "Copier l'adresse",
    "Copied!": "Copié !",
    "Toggle visibility override": "Forcer la visibilité",
    "Clear visibility override": "Rendre la visibilité d'origine",
    "Close props": "Fermer les propriétés",
    # names and tooltips of the panels' dock (keyboard and screen-reader users hear them)
    "Expand column": "Déplier la colonne",
    "Collapse column": "Replier la colonne",
    "Collapse panel area": "Replier la zone des panneaux",
    "Expand panels": "Déplier les panneaux",
    "Minimize panels": "Réduire les panneaux",
    "Expand panel": "Déplier le panneau",
    "Minimize panel": "Réduire le panneau",
    "Expand": "Déplier",
    "Minimize": "Réduire",
    "Collapse": "Replier",
    "Expand plot": "Agrandir le graphique",
    "Expand image": "Agrandir l'image",
    "Show scene tree": "Afficher l'arbre de la scène",
    "Hide scene tree": "Masquer l'arbre de la scène",
    "About Viser": "À propos de viser",
}
"""viser's English sentences (exactly as its client writes them) -> the page's French."""

CLOSING = ("Software WebGL rendering detected",)
"""Warnings (by their English title) that close themselves after :data:`CLOSE_AFTER_S`:
viser keeps them until clicked, over the 3D view of a projected page, though nothing is
wrong with the page (a PC without a graphics driver draws the 3D more slowly)."""

CLOSE_AFTER_S = 8.0
"""Seconds a :data:`CLOSING` warning stays: time to read its two sentences."""

LOST = (
    "Le serveur ne répond plus : la simulation est arrêtée. La page se reconnectera "
    "d'elle-même dès qu'il répondra (sinon, relancez-le et rechargez la page)."
)
"""What a page says once its server stops answering (stopped by the teacher, the
laptop asleep, the network cut): viser only greys the panel and turns a small icon into
a red spinner, and the status line went on reading « en cours »."""
RUNNING, STOPPED = "en cours", "arrêtée (serveur injoignable)"
"""The status line's state while the simulation runs, and what it reads once the server
stopped answering."""
LOST_AFTER_S = 3.0
"""Seconds without a connection before :data:`LOST` shows (a worker's restart takes
less)."""
HIDDEN_SECTION = "Scene tree"
"""viser's settings panel lists the scene's nodes by their code names (``/WorldAxes``,
``/arrows``, ``/model``): a developer's tool, hidden from the page (its section, by its
title)."""
CONNECTED_ICON = "tabler-icon-cloud-check"
"""The class of the icon viser's panel shows while its websocket is connected."""

COMMA_EVERY_S = 0.2
"""Seconds between two readings of the number boxes (a box's value changes without any
event the page can watch when the server moves its slider)."""

LOCALE = "fr-FR"
"""The locale the page's own number formatting follows (uPlot's chart ticks)."""

_SCRIPT = """<script>(function () {
  var fr = %(french)s, locale = %(locale)s, closing = %(closing)s;
  var attrs = ["title", "aria-label", "placeholder"];
  document.documentElement.lang = "fr";
  try {
    Object.defineProperty(navigator, "language", {get: function () { return locale; }});
    Object.defineProperty(navigator, "languages", {get: function () { return [locale]; }});
  } catch (e) {}
  function text(node) {
    var t = node.nodeValue.trim();
    if (!Object.prototype.hasOwnProperty.call(fr, t)) return;
    node.nodeValue = fr[t];
    var title = node.parentElement;
    if (t === %(hidden)s && title && title.tagName === "P" && title.parentElement) {
      title.parentElement.style.display = "none";  // the scene tree: code names, not words
    }
    if (closing.indexOf(t) >= 0) {  // a warning that needs no answer leaves the 3D view
      var box = node.parentElement && node.parentElement.closest("[role=alert]");
      var close = box && box.querySelector("button");
      if (close) setTimeout(function () { close.click(); }, %(close_ms)d);
    }
  }
  function element(node) {
    attrs.forEach(function (a) {
      var v = node.getAttribute(a);
      if (v && Object.prototype.hasOwnProperty.call(fr, v)) node.setAttribute(a, fr[v]);
    });
  }
  function visit(node) {
    if (node.nodeType === 3) return text(node);
    if (node.nodeType !== 1) return;
    element(node);
    var walk = document.createTreeWalker(node, 5);  // elements and texts
    for (var n = walk.nextNode(); n; n = walk.nextNode()) n.nodeType === 3 ? text(n) : element(n);
  }
  // viser's number boxes (Mantine NumberInput) write their value with a decimal point
  // and take no other option: while a box is not being edited, a label drawn over it
  // shows the same value with a decimal comma (the box, its value and typing unchanged).
  function comma(input) {
    var wrap = input.parentElement, shown = input.nextElementSibling;
    var mine = shown && shown.className === "sandbox-comma";
    var v = input.value;
    if (!wrap || document.activeElement === input || v.indexOf(".") === -1) {
      if (mine) { shown.remove(); input.style.color = input.dataset.sandboxColor || ""; }
      return;
    }
    if (!mine) {
      input.dataset.sandboxColor = input.style.color;
      input.dataset.sandboxInk = getComputedStyle(input).color;
      shown = document.createElement("span");
      shown.className = "sandbox-comma";
      shown.setAttribute("aria-hidden", "true");
      input.insertAdjacentElement("afterend", shown);
      input.style.color = "transparent";
    }
    // placed again at every reading: the text size setting and the panels' layout move it
    var cs = getComputedStyle(input);
    var css = "position:absolute;pointer-events:none;white-space:nowrap;" +
      "overflow:hidden;box-sizing:border-box;left:" + input.offsetLeft + "px;top:" +
      input.offsetTop + "px;width:" + input.offsetWidth + "px;height:" +
      input.offsetHeight + "px;line-height:" + input.offsetHeight + "px;padding-left:" +
      cs.paddingLeft + ";font-family:" + cs.fontFamily + ";font-size:" + cs.fontSize +
      ";font-weight:" + cs.fontWeight + ";color:" + input.dataset.sandboxInk + ";";
    if (shown.dataset.css !== css) { shown.style.cssText = css; shown.dataset.css = css; }
    var text = v.replace(".", ",");
    if (shown.textContent !== text) shown.textContent = text;
  }
  function commas() {
    document.querySelectorAll("input.mantine-NumberInput-input").forEach(comma);
    // a list's chosen option is an input's value, which no text node carries
    document.querySelectorAll("input[readonly]").forEach(function (input) {
      if (Object.prototype.hasOwnProperty.call(fr, input.value)) input.value = fr[input.value];
    });
  }
  // the server lost: a French line over the page until the connection comes back
  var connected = false, lostSince = 0;
  function watch() {
    var on = !!document.querySelector("." + %(icon)s);
    var notice = document.getElementById("sandbox-lost");
    if (on) {
      connected = true; lostSince = 0;
      if (notice) notice.remove();
      return;
    }
    if (!connected) return;
    lostSince = lostSince || Date.now();
    if (notice || %(lost_ms)d > Date.now() - lostSince) return;  // no less-than sign: see the tests
    notice = document.createElement("div");
    notice.id = "sandbox-lost";
    notice.setAttribute("role", "alert");
    notice.style.cssText = "position:fixed;top:12px;left:50%%;transform:translateX(-50%%);" +
      "z-index:10000;max-width:min(92vw,640px);padding:10px 16px;border-radius:6px;" +
      "background:#b3261e;color:#fff;font:600 17px/1.4 sans-serif;text-align:center;" +
      "box-shadow:0 2px 8px rgba(0,0,0,.3)";
    notice.textContent = %(lost)s;
    document.body.appendChild(notice);
    // the status line said « en cours »: nothing runs now (a new connection rewrites it)
    var walk = document.createTreeWalker(document.body, 4);
    for (var n = walk.nextNode(); n; n = walk.nextNode()) {
      if (n.nodeValue.trim() === %(running)s) n.nodeValue = %(stopped)s;
    }
  }
  setInterval(function () { commas(); watch(); }, %(comma_ms)d);
  document.addEventListener("focusin", commas, true);
  document.addEventListener("focusout", function () { setTimeout(commas, 0); }, true);
  new MutationObserver(function (changes) {
    changes.forEach(function (c) {
      if (c.type === "childList") c.addedNodes.forEach(visit); else visit(c.target);
    });
  }).observe(document.documentElement, {
    subtree: true, childList: true, characterData: true, attributes: true,
    attributeFilter: attrs,
  });
})();</script>"""

_lock = threading.Lock()
_root: Path | None = None
_installed = False


def page_script() -> str:
    """The ``<script>`` added at the top of viser's page (the JSON is escaped so that no
    sentence can close the script element), followed by the page's other additions
    (:func:`page_additions`)."""
    french = json.dumps(FRENCH, ensure_ascii=True).replace("<", "\\u003c")
    return _french_script(french) + page_additions()


def page_additions() -> str:
    """The other elements added to viser's page, one module each: the layout for phones
    and tablets, keyboard and screen-reader help, setups read from the page's address."""
    return client_layout.html() + client_access.html() + client_link.html()


def _french_script(french: str) -> str:
    return _SCRIPT % {
        "french": french,
        "locale": json.dumps(LOCALE),
        "closing": json.dumps(list(CLOSING)),
        "close_ms": round(CLOSE_AFTER_S * 1000),
        "comma_ms": round(COMMA_EVERY_S * 1000),
        "icon": json.dumps(CONNECTED_ICON),
        "hidden": json.dumps(HIDDEN_SECTION),
        "lost": json.dumps(LOST, ensure_ascii=True),
        "lost_ms": round(LOST_AFTER_S * 1000),
        "running": json.dumps(RUNNING, ensure_ascii=True),
        "stopped": json.dumps(STOPPED, ensure_ascii=True),
    }


PAGE_TITLE = "Dynamique des solides"
"""The browser tab's title (viser's page says "Viser")."""


def french_page(html: str) -> str | None:
    """viser's ``index.html`` with :func:`page_script` first in its head and the tab
    titled :data:`PAGE_TITLE` (None when the page has no ``<head>`` to put it in)."""
    head = html.find("<head>")
    if head < 0:
        return None
    at = head + len("<head>")
    html = html[:at] + page_script() + html[at:]
    return re.sub(r"<title>[^<]*</title>", f"<title>{PAGE_TITLE}</title>", html, count=1)


def french_root(build: Path) -> Path | None:
    """A folder holding viser's client ``build`` with the French page (made once per
    process, removed at exit); None when the build has no page this module can amend."""
    global _root
    with _lock:
        if _root is not None:
            return _root
        try:
            page = french_page((build / "index.html").read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError):
            return None
        if page is None:
            return None
        root = Path(tempfile.mkdtemp(prefix="sandbox-client-"))
        atexit.register(shutil.rmtree, root, ignore_errors=True)
        shutil.copytree(build, root, dirs_exist_ok=True)
        (root / "index.html").write_text(page, encoding="utf-8")
        _root = root
        return root


def install() -> bool:
    """Make every viser server created from now on serve the French page (idempotent).

    Returns:
        True when the page will be French; False when this viser release does not build
        its web server the way this relies on (its page is then served unchanged).
    """
    global _installed

    with _lock:
        if _installed:
            return True
    base = infra.WebsockServer
    build = Path(infra.__file__).resolve().parent.parent / "client" / "build"

    class FrenchClientServer(base):  # type: ignore[misc,valid-type]
        """viser's websocket server, serving the French page instead of its own."""

        def __init__(self, *args: Any, **kwargs: Any) -> None:
            root = kwargs.get("http_server_root")
            if root is not None and Path(root).resolve() == build:
                kwargs["http_server_root"] = french_root(build) or root
            super().__init__(*args, **kwargs)

    if not (build / "index.html").is_file():
        return False
    with _lock:
        if not _installed:
            infra.WebsockServer = FrenchClientServer  # type: ignore[misc]
            _installed = True
    return True
