"""The page's side of a shared setup: its address reaches the server, its folders open, the
link is copied.

A setup travels in the fragment of the page's address (after ``#``, see
:mod:`sandbox.web.panels.setup_link`), which a browser never sends to a server, and viser's client
opens its websocket at the page's path without it. So the script that :func:`html` adds to
the page's head wraps the browser's ``WebSocket``: a websocket opened to the page's own host
carries two query parameters, :data:`LINK_KEY` (the fragment, cut one character past
:data:`~sandbox.web.panels.setup_link.MAX_CHARS` so that the server sees it was too long) and
:data:`PAGE_KEY` (the page's origin and path: the address the student reached, which the
server's own address is not behind a proxy). The server reads them from the websocket's
handshake (:func:`request_query`, :func:`from_query`), with any other connection, in
every worker process alike (a worker is handed the connection whole). The script also:

- reloads the page when only its fragment changes (a link pasted into the same tab: the
  browser would not reload by itself, and the setup is read once, when the page connects);
- opens, once, the folders named by the fragment's ``open`` that are among
  :data:`FOLDABLE` (folded by default; folders of the "Panneau affiché" list are chosen by
  the server), by clicking their header as a user would;
- disables the number box of a disabled slider (a locked one: viser disables its track
  only; the server ignores the box's messages anyway);
- makes the link's field read-only, and copies the link when "Copier le lien de cette
  configuration" is clicked: the server writes the new link into the field, the script
  waits for it (at most :data:`COPY_WAIT_S`), then writes it to the clipboard
  (``navigator.clipboard`` on HTTPS or localhost, else ``document.execCommand``, both
  allowed for a few seconds after the click), or, failing both, selects it for Ctrl+C; a
  line under the field says which.

The script works on the page after it changed, at most :data:`PASS_HZ` times a second, and
stops watching the folders once they are open: nothing per drawn frame.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from typing import TYPE_CHECKING
from urllib.parse import parse_qsl

from sandbox.web.client import viser_internals
from sandbox.web.panels.board import NAME_LABEL
from sandbox.web.panels.board_rows import MAX_NAME, clean_name
from sandbox.web.panels.controls import ADVANCED_FOLDER, NUMERICS_FOLDER
from sandbox.web.panels.display import FOLDER as DISPLAY_FOLDER
from sandbox.web.panels.setup_link import MAX_CHARS, slug

if TYPE_CHECKING:
    import viser

SHARE_FOLDER = "Partager"
"""The folder holding the button (:mod:`sandbox.web.views.share`)."""

BUTTON = "Copier le lien de cette configuration"
"""The button's words (the script finds it by them)."""

LINK_LABEL = "Lien à donner"
"""The label of the read-only field showing the link."""

FOLDABLE = (NUMERICS_FOLDER, ADVANCED_FOLDER, DISPLAY_FOLDER)
"""Folders folded by default that a link may open (the script clicks their header)."""

LINK_KEY = "sandbox_link"
"""Query parameter of the websocket carrying the page's fragment."""

PAGE_KEY = "sandbox_page"
"""Query parameter of the websocket carrying the page's origin and path."""

WHO_KEY = "sandbox_who"
"""Query parameter of the websocket carrying the tab's own key (kept across reloads)."""

NAME_KEY = "sandbox_name"
"""Query parameter of the websocket carrying the name last typed in « Votre prénom »."""

_WHO = re.compile(r"[0-9a-f]{24}")

MAX_PAGE = 512
"""Longest page address kept [characters]."""

COPY_WAIT_S = 2.0
"""Seconds the script waits for the server's new link after the click (a browser lets a
page write to the clipboard for about 5 s after a click)."""

PASS_HZ = 4.0
"""Most passes of the script over the page per second."""

COPIED = "Lien copié : collez-le (Ctrl+V) dans un message aux élèves."
NOT_COPIED = "Le navigateur refuse la copie : le lien est sélectionné, copiez-le avec Ctrl+C."

_PAGE = re.compile(
    r"https?://(?:[A-Za-z0-9](?:[A-Za-z0-9.-]{0,252})|\[[0-9A-Fa-f:.]{2,45}\])(?::\d{1,5})?"
    r"(?:/[A-Za-z0-9._~!$'()*+,;=:@%/-]{0,400})?"
)
_HOST = re.compile(r"(?:[A-Za-z0-9][A-Za-z0-9.-]{0,252}|\[[0-9A-Fa-f:.]{2,45}\])(?::\d{1,5})?")

_SCRIPT = """<script>(function () {
  var LINK = %(link_key)s, PAGE = %(page_key)s, MAX = %(max)d, FOLDABLE = %(foldable)s;
  var BUTTON = %(button)s, FIELD = %(field)s, COPIED = %(copied)s, REFUSED = %(refused)s;
  var WAIT = %(wait_ms)d, EVERY = %(every_ms)d;
  var WHO = %(who_key)s, NAMED = %(name_key)s, NAME_LABEL = %(name_label)s;
  var NAME_MAX = %(name_max)d;
  // Who this tab is, kept across reloads (the session's storage: a second tab is another
  // student), and the name last typed in « Votre prénom » (this browser's storage): the
  // board keeps a student's row and name when the page reloads or its server restarts.
  function kept(area, key, make) {
    try {
      var value = window[area].getItem(key);
      if (!value && make) { value = make(); window[area].setItem(key, value); }
      return value || "";
    } catch (e) {
      return make ? make() : "";  // storage refused: a new student at each load
    }
  }
  var who = kept("sessionStorage", "sandbox-who", function () {
    var bytes = new Uint8Array(12);
    if (window.crypto && window.crypto.getRandomValues) window.crypto.getRandomValues(bytes);
    else for (var i = 0; bytes.length > i; i++) bytes[i] = Math.floor(Math.random() * 256);
    return Array.prototype.map.call(bytes, function (b) {
      return ("0" + b.toString(16)).slice(-2);
    }).join("");
  });
  document.addEventListener("input", function (e) {
    var t = e.target;
    if (!t || t.tagName !== "INPUT") return;
    // named by the row's label (the page's access script names the box later, and
    // viser's label may point elsewhere than the box)
    var row = t.closest && t.closest(".mantine-Flex-root");
    var label = row && row.querySelector("label");
    var named = t.getAttribute("aria-label") === NAME_LABEL ||
      (label && (label.textContent || "").trim() === NAME_LABEL);
    if (!named) return;
    try { localStorage.setItem("sandbox-name", t.value.slice(0, NAME_MAX)); } catch (err) {}
  }, true);
  // The websocket to this page's server carries the fragment and the page's address
  // instead of the fragment itself (viser's client opens it at the page's whole address,
  // fragment included, which a websocket's address may not have). viser opens it in a
  // worker, told the address by a "set_server" message; in the page itself otherwise.
  function linked(url) {
    try {
      var u = new URL(url, location.href);
      u.hash = "";
      if (u.host === location.host) {
        u.searchParams.set(LINK, location.hash.slice(1, MAX + 2));
        u.searchParams.set(PAGE, (location.origin + location.pathname).slice(0, 600));
        u.searchParams.set(WHO, who);
        var name = kept("localStorage", "sandbox-name");
        if (name) u.searchParams.set(NAMED, name.slice(0, NAME_MAX));
      }
      return u.toString();
    } catch (e) {
      return url;
    }
  }
  if (window.Worker) {
    var post = Worker.prototype.postMessage;
    Worker.prototype.postMessage = function (message) {
      if (message && message.type === "set_server" && typeof message.server === "string") {
        var copy = {};
        for (var k in message) copy[k] = message[k];
        copy.server = linked(message.server);
        arguments[0] = copy;
      }
      return post.apply(this, arguments);
    };
  }
  var Native = window.WebSocket;
  if (Native) {
    var Linked = function (url, protocols) {
      url = linked(url);
      return protocols === undefined ? new Native(url) : new Native(url, protocols);
    };
    Linked.prototype = Native.prototype;
    ["CONNECTING", "OPEN", "CLOSING", "CLOSED"].forEach(function (k) { Linked[k] = Native[k]; });
    window.WebSocket = Linked;
  }
  var loaded = location.hash;
  window.addEventListener("hashchange", function () {
    if (location.hash !== loaded) location.reload();
  });
  function slug(text) {
    return text.normalize("NFD").replace(/[\\u0300-\\u036f]/g, "").toLowerCase()
      .replace(/[^a-z0-9]+/g, "-").replace(/^-+|-+$/g, "");
  }
  // The folders the fragment opens: its first "open", among the foldable ones.
  var wanted = [];
  (function () {
    var parts = location.hash.slice(1, MAX + 1).split("&");
    for (var i = 0; parts.length > i; i++) {
      var at = parts[i].indexOf("=");
      if (at === -1 || parts[i].slice(0, at) !== "open") continue;
      try {
        decodeURIComponent(parts[i].slice(at + 1)).split(",").forEach(function (s) {
          if (FOLDABLE.indexOf(slug(s)) >= 0) wanted.push(slug(s));
        });
      } catch (e) {}
      return;
    }
  })();
  var opened = {};
  function folders() {
    if (!wanted.length) return;
    document.querySelectorAll(".mantine-Paper-root > .mantine-Paper-root:first-child")
      .forEach(function (head) {
        var chevron = head.querySelector(":scope > svg[class*='tabler-icon-chevron']");
        if (!chevron) return;
        var name = slug(head.textContent || "");
        if (wanted.indexOf(name) === -1 || opened[name]) return;
        opened[name] = true;
        var body = head.nextElementSibling;
        var open = body ? body.getAttribute("aria-hidden") !== "true"
          : /chevron-up/.test(chevron.getAttribute("class"));
        if (!open) head.click();
      });
    wanted = wanted.filter(function (s) { return !opened[s]; });
  }
  function field() {
    var labels = document.querySelectorAll("label[for]");
    for (var i = 0; labels.length > i; i++) {
      if ((labels[i].textContent || "").trim() !== FIELD) continue;
      var row = labels[i].closest(".mantine-Flex-root");
      var input = row && row.querySelector("input:not([type=hidden]),textarea");
      if (input) return input;
    }
    return null;
  }
  function readOnly() {
    var input = field();
    if (input && !input.readOnly) input.readOnly = true;
  }
  function say(input, text) {
    var wrap = input.closest(".mantine-InputWrapper-root") || input.parentElement;
    var line = wrap.parentElement.querySelector(".sandbox-link-status");
    if (!line) {
      line = document.createElement("div");
      line.className = "sandbox-link-status";
      line.setAttribute("role", "status");
      line.style.cssText = "font-size:0.85em;margin-top:0.25em;";
      wrap.insertAdjacentElement("afterend", line);
    }
    line.textContent = text;
  }
  function select(input) {
    input.focus();
    input.select();
    input.setSelectionRange(0, input.value.length);
  }
  function copy(input) {
    var text = input.value;
    function fallback() {
      select(input);
      var done = false;
      try { done = document.execCommand("copy"); } catch (e) {}
      say(input, done ? COPIED : REFUSED);
    }
    if (navigator.clipboard && window.isSecureContext) {
      navigator.clipboard.writeText(text).then(function () {
        select(input);
        say(input, COPIED);
      }, fallback);
    } else {
      fallback();
    }
  }
  document.addEventListener("click", function (e) {
    var button = e.target && e.target.closest && e.target.closest("button");
    if (!button || (button.textContent || "").trim() !== BUTTON) return;
    var input = field();
    if (!input) return;
    var before = input.value, start = Date.now();
    (function wait() {
      var now = field() || input;
      if (now.value && (now.value !== before || Date.now() - start > WAIT)) return copy(now);
      if (Date.now() - start > WAIT) return;
      setTimeout(wait, 50);
    })();
  }, true);
  // viser disables a locked slider's track but not the number box beside it.
  function boxes() {
    document.querySelectorAll(".mantine-Slider-thumb").forEach(function (thumb) {
      var row = thumb.closest(".mantine-Flex-root");
      var box = row && row.querySelector("input.mantine-NumberInput-input");
      var off = thumb.getAttribute("aria-disabled") === "true";
      if (box && box.disabled !== off) box.disabled = off;
    });
  }
  var pending = false;
  function pass() {
    pending = false;
    folders();
    readOnly();
    boxes();
  }
  function soon() {
    if (!pending) { pending = true; setTimeout(pass, EVERY); }
  }
  document.addEventListener("DOMContentLoaded", function () {
    new MutationObserver(soon).observe(document.body, {
      subtree: true, childList: true, attributes: true, attributeFilter: ["aria-disabled"],
    });
    soon();
  });
})();</script>"""


def html() -> str:
    """The ``<script>`` added to the head of viser's page (its JSON escaped, and no ``<``
    but its own tags: no text can close it)."""

    def js(value: object) -> str:
        return json.dumps(value, ensure_ascii=True).replace("<", "\\u003c")

    return _SCRIPT % {
        "link_key": js(LINK_KEY),
        "page_key": js(PAGE_KEY),
        "max": MAX_CHARS,
        "foldable": js([slug(f) for f in FOLDABLE]),
        "button": js(BUTTON),
        "field": js(LINK_LABEL),
        "copied": js(COPIED),
        "refused": js(NOT_COPIED),
        "wait_ms": round(COPY_WAIT_S * 1000),
        "every_ms": round(1000 / PASS_HZ),
        "who_key": js(WHO_KEY),
        "name_key": js(NAME_KEY),
        "name_label": js(NAME_LABEL),
        "name_max": MAX_NAME,
    }


def request_query(server: viser.ViserServer, client_id: int) -> tuple[str, str, str]:
    """The query of the browser's websocket handshake, its ``Host`` header and its path
    ("" when unknown). viser keeps each live connection's handshake; its attributes are
    private: a later viser may rename them (the link is then ignored, never trusted)."""
    request = viser_internals.handshake(server, client_id)
    if request is None:
        return "", "", ""
    host = request.headers.get("Host", "")
    path, _, query = request.path.partition("?")
    return query, host if isinstance(host, str) else "", path


def _fields(query: str) -> dict[str, str]:
    """The first value of each key of a websocket's query ({} when unreadable)."""
    try:
        pairs = parse_qsl(query[: 4 * MAX_CHARS], keep_blank_values=True, max_num_fields=16)
    except ValueError:
        return {}
    found: dict[str, str] = {}
    for key, value in pairs:
        found.setdefault(key, value)
    return found


def identity(query: str) -> tuple[str, str]:
    """(the tab's key, the name its browser kept) a websocket's query carries: "" for
    what is absent or malformed (a key is 24 hexadecimal digits; a name is cleaned as a
    typed one is)."""
    found = _fields(query)
    key = found.get(WHO_KEY, "")
    return (key if _WHO.fullmatch(key) else ""), clean_name(found.get(NAME_KEY, ""))


def arrival(server: viser.ViserServer, client_id: int) -> tuple[str, str]:
    """:func:`identity` of the browser ``client_id`` (("", "") when its handshake is
    unknown)."""
    return identity(request_query(server, client_id)[0])


def from_query(query: str) -> tuple[str, str]:
    """The fragment and the page address a websocket's query carries ("" when absent or
    unreadable); the fragment is cut one character past the longest one read."""
    found = _fields(query)
    return found.get(LINK_KEY, "")[: MAX_CHARS + 1], found.get(PAGE_KEY, "")[: MAX_PAGE + 1]


LOOPBACK = re.compile(r"https?://(?:localhost|127(?:\.\d{1,3}){3}|\[::1\])(?::\d{1,5})?(?:/.*)?")
"""An address only this computer opens."""


def link_base(join_urls: Sequence[str], page: str) -> tuple[str, str]:
    """(the address links start with, the sentence saying whose it is, ending with that
    address when it names it).

    The first address students type when there is one (``--host 0.0.0.0``: this machine's
    network address; ``--public-url``: the proxy's), whatever address the teacher's page
    was opened at; else the page's own, said to be this computer's only when it is.

    Args:
        join_urls: Addresses students type (:func:`~sandbox.web.serving.startup.join_urls`).
        page: The page's own address (:func:`page_address`).
    """
    if join_urls:
        base = join_urls[0] if join_urls[0].endswith("/") else join_urls[0] + "/"
        return base, f"Le lien part de l'adresse des élèves : {base}"
    if LOOPBACK.fullmatch(page):
        return page, (
            "Ce serveur n'écoute que cet ordinateur : les élèves ne pourront pas ouvrir ce "
            "lien. Relancez-le avec --host 0.0.0.0 pour qu'ils le puissent."
        )
    return page, (f"Le lien part de l'adresse de cette page : {page}" if page else "")


def page_address(page: str, host: str, path: str = "") -> str:
    """The address links start with: the page's own (origin and path) when well formed,
    else ``http://HOST/`` from the handshake's ``Host`` header, else ``""``.

    Args:
        page: The page's origin and path, as its script sent them.
        host: The handshake's ``Host`` header.
        path: The path the websocket reached (the page's, less a proxy's prefix). A page
            served at a path of its own (the teacher's secret ``/prof/<token>``) gives the
            students' page instead: a link never carries that path.
    """
    if len(page) <= MAX_PAGE and _PAGE.fullmatch(page):
        own = path.rstrip("/")
        if own and page.rstrip("/").endswith(own):
            return page.rstrip("/")[: -len(own)] + "/"
        return page
    if _HOST.fullmatch(host):
        return f"http://{host}/"
    return ""
