"""The page for a keyboard and a screen reader (headless Chromium, 1280×720): every
control has a French name, every folder opens from the keyboard, Space pauses, the arrows
move a slider (and the value the server holds), texts reach 4,5:1 and no button's words
are cut at any text size of the "Projecteur" folder."""

from __future__ import annotations

import re

import pytest
from conftest import free_port, pause, settled, wait_for

from sandbox.web.loop.requests import Pause, Play
from sandbox.web.page.access import PLAY_PAUSE, REPLAY_TOGGLE, STYLE_ID, html
from sandbox.web.panels.controls import COMMAND_KINDS
from sandbox.web.panels.projector import FONT_LABEL, FONT_SIZES, font_option
from sandbox.web.views.browser import ALL_FOLDERS

pytestmark = [pytest.mark.browser, pytest.mark.slow]  # Chromium pages: 10-30 s each


INTERACTIVE = {
    "button",
    "checkbox",
    "combobox",
    "link",
    "listbox",
    "menuitem",
    "option",
    "radio",
    "searchbox",
    "slider",
    "spinbutton",
    "switch",
    "tab",
    "textbox",
}
"""Roles of the accessibility tree a keyboard or a screen reader acts on."""

ENGLISH = re.compile(
    r"\b(expand|collapse|minimi[sz]e|panels?|column|show|hide|edit|props|tree|settings|"
    r"close|open|reset|play|step|speed|record|toggle|search|copy|share|server|disconnect|"
    r"view|canvas|save|scene|button|slider|input|value|dark|light|stats)\b",
    re.IGNORECASE,
)
"""English words no control's name may hold (French ones such as "Pause" or "Mode" are
not in the list)."""

PANEL = "[data-dock-region]"
"""The page's panel areas (controls on the right, lesson on the left)."""

ROTOR_SPEED = "Vitesse de rotation ω, tr/min"
"""The rotor's speed slider as a screen reader names it (label "… [tr/min]")."""


@pytest.fixture
def context(projector_context):
    return projector_context


@pytest.fixture(params=["rotor", "compressor"])
def served(request):
    """The rotor, and the compressor whose "Réglages avancés" folder starts closed."""
    from sandbox.web.serving.app import start

    app = start(request.param, port=free_port(), open_message=False)
    try:
        yield app
    finally:
        app.stop()


def _open(context, app, *, paused: bool = False):
    """The page of ``app``; ``paused``: the scene paused first, for a check of words and
    boxes that motion does not change (a playing page redraws its 3D at every frame)."""
    page = context.new_page()
    page.goto(app.url)
    page.locator("[data-sandbox-folder]").first.wait_for(timeout=30_000)
    assert wait_for(lambda: page.get_by_role("slider").count() > 0)
    if paused:
        pause(page)
    return page


def _pick(page, label: str, option: str) -> None:
    """Pick ``option`` in the dropdown named ``label``, from the keyboard (the pointer's
    checks wait for animation frames, which a loaded machine's software 3D delays)."""
    box = page.get_by_role("combobox", name=label, exact=True)
    box.focus()
    page.keyboard.press("ArrowDown")  # opens the list
    page.get_by_role("option", name=option, exact=True).evaluate("e => e.click()")
    assert wait_for(lambda: box.input_value() == option, timeout=10)


def _show_every_folder(page) -> None:
    """Every readout panel shown, and every folder of the page opened."""
    _pick(page, "Panneau affiché", ALL_FOLDERS)
    for _ in range(6):  # a folder opened may hold closed ones
        clicked = page.evaluate(
            f"""() => {{ let n = 0;
            document.querySelectorAll('{PANEL} [data-sandbox-folder][aria-expanded=false]')
              .forEach(h => {{ if (h.checkVisibility()) {{ h.click(); n++; }} }});
            return n; }}"""
        )
        if not clicked:
            return
        # the script's next pass says the folders are open
        settled(
            lambda: page.evaluate(
                f"document.querySelectorAll('{PANEL} [aria-expanded=true]').length"
            )
        )


def _controls(page) -> list[tuple[str, str]]:
    """(role, name) of every control of the accessibility tree (CDP's computed names)."""
    cdp = page.context.new_cdp_session(page)
    try:
        nodes = cdp.send("Accessibility.getFullAXTree")["nodes"]
    finally:
        cdp.detach()
    found = []
    for node in nodes:
        role = node.get("role", {}).get("value", "")
        if node.get("ignored") or role not in INTERACTIVE:
            continue
        found.append((role, str(node.get("name", {}).get("value", "")).strip()))
    return found


def _unnamed(controls: list[tuple[str, str]]) -> list[tuple[str, str]]:
    return [(r, n) for r, n in controls if not n or ENGLISH.search(n) or "_" in n]


def test_every_control_has_a_french_name(context, served):
    page = _open(context, served, paused=True)
    # viser's warning of a 3D drawn without graphics card (headless Chromium, closed
    # after a few seconds): its close button has no words, only a cross
    crosses = page.locator(".mantine-CloseButton-root")
    assert wait_for(
        lambda: all(n == "Fermer" for n in crosses.evaluate_all("l => l.map(b => b.ariaLabel)")),
        timeout=5,
    )
    _show_every_folder(page)
    assert wait_for(lambda: not _unnamed(_controls(page)), timeout=5), _unnamed(_controls(page))
    controls = _controls(page)
    roles = {r for r, _ in controls}
    assert {"button", "slider", "textbox", "combobox", "checkbox"} <= roles, roles
    # a slider and its number box are named by the row's label, the unit after a comma
    sliders = [n for r, n in controls if r == "slider"]
    boxes = {n for r, n in controls if r == "textbox"}
    assert sliders and all(n in boxes for n in sliders), (sliders, boxes)
    assert not [n for n in sliders if "[" in n], sliders
    # the settings' panel behind the icon button: its switches and buttons too
    page.get_by_role("button", name="Configuration et diagnostic", exact=True).press("Enter")
    page.get_by_role("checkbox", name="Réglages de l'affichage", exact=True).press(" ")
    page.get_by_text("Mode sombre", exact=True).first.wait_for(timeout=5_000)
    assert wait_for(lambda: not _unnamed(_controls(page)), timeout=5), _unnamed(_controls(page))


def test_a_slider_says_its_value_and_unit(context, served_rotor):
    page = _open(context, served_rotor)
    thumb = page.get_by_role("slider", name=ROTOR_SPEED, exact=True)
    assert wait_for(lambda: thumb.get_attribute("aria-valuetext") == "1\u202f500 tr/min")
    assert page.get_by_role("textbox", name=ROTOR_SPEED, exact=True).count() == 1


def _focused(page) -> dict[str, str]:
    return page.evaluate(
        """() => { const e = document.activeElement;
        return {name: e.getAttribute('aria-label') || e.textContent.trim(),
                role: e.getAttribute('role') || e.tagName.toLowerCase(),
                folder: e.hasAttribute('data-sandbox-folder') ? 'yes' : 'no',
                ring: getComputedStyle(e).outlineStyle + ' ' + getComputedStyle(e).outlineWidth};
        }"""
    )


def _tab_to(page, name: str, *, folder: bool = False, most: int = 80) -> dict[str, str]:
    """Press Tab until the focus is on the element named ``name`` (at most ``most``)."""
    for _ in range(most):
        page.keyboard.press("Tab")
        now = _focused(page)
        if now["name"] == name and (now["folder"] == "yes") == folder:
            return now
    raise AssertionError(f"Tab never reached {name!r}")


def _header(page, name: str):
    return page.locator("[data-sandbox-folder]", has_text=re.compile(f"^{re.escape(name)}$"))


def test_tab_reaches_every_folder_and_opens_it(context, served):
    page = _open(context, served, paused=True)
    headers = page.locator(f"{PANEL} [data-sandbox-folder]")
    wanted = {
        headers.nth(i).inner_text().strip()
        for i in range(headers.count())
        if headers.nth(i).is_visible()
    }
    assert {"Simulation", "Paramètres", "Méthode numérique", "Affichage"} <= wanted, wanted
    reached, rings = set(), set()
    for _ in range(120):
        page.keyboard.press("Tab")
        now = _focused(page)
        rings.add(now["ring"])
        if now["folder"] == "yes":
            reached.add(now["name"])
        if wanted <= reached:
            break
    assert wanted <= reached, wanted - reached
    assert "none 0px" not in rings, rings  # everything reached draws a focus ring
    # a closed folder: Enter opens it, then Tab goes to its first control
    page.locator("body").focus()
    for name in ("Méthode numérique", "Affichage"):
        head = _header(page, name)
        assert head.get_attribute("aria-expanded") == "false"
        _tab_to(page, name, folder=True)
        page.keyboard.press("Enter")
        assert wait_for(lambda h=head: h.get_attribute("aria-expanded") == "true", timeout=5)
        # its opening slide has ended (the controls of a folder still opening are hidden)
        assert settled(lambda: page.evaluate(f"document.querySelector('{PANEL}').scrollHeight"))
        page.keyboard.press("Tab")
        inside = page.evaluate("() => document.activeElement.closest('[aria-hidden]') !== null")
        first = _focused(page)
        assert inside and first["folder"] == "no", first
        page.keyboard.press("Shift+Tab")
        page.keyboard.press(" ")  # Space closes it again
        assert wait_for(lambda h=head: h.get_attribute("aria-expanded") == "false", timeout=5)


def _overlay_speed(page) -> str:
    text = page.locator("#sandbox-overlay").inner_text()
    match = re.search(r"ω = ([\d\u202f]+)\u00a0tr/min", text)
    return re.sub(r"[\u202f\u00a0 ]", "", match.group(1)) if match else ""


def test_keyboard_only_slider_moves_the_server_value(context, served_rotor):
    page = _open(context, served_rotor)
    assert wait_for(lambda: _overlay_speed(page) == "1500")
    _tab_to(page, "Paramètres", folder=True)
    page.keyboard.press("Enter")  # closes the folder: its sliders leave the Tab order
    head = _header(page, "Paramètres")
    assert wait_for(lambda: head.get_attribute("aria-expanded") == "false", timeout=5)
    page.keyboard.press("Enter")
    assert wait_for(lambda: head.get_attribute("aria-expanded") == "true", timeout=5)
    now = _tab_to(page, ROTOR_SPEED, most=10)
    assert now["role"] == "slider"
    page.keyboard.press("ArrowRight")  # one step: the scene's 50 tr/min
    thumb = page.get_by_role("slider", name=ROTOR_SPEED, exact=True)
    assert wait_for(lambda: thumb.get_attribute("aria-valuenow") == "1550", timeout=5)
    # the server's simulation turns faster: its readout over the 3D view says so
    assert wait_for(lambda: _overlay_speed(page) == "1550"), _overlay_speed(page)
    page.keyboard.press("ArrowLeft")
    page.keyboard.press("ArrowLeft")
    assert wait_for(lambda: _overlay_speed(page) == "1450"), _overlay_speed(page)
    # the number box: the arrows up and down step it too
    page.keyboard.press("Tab")
    assert _focused(page)["name"] == ROTOR_SPEED and _focused(page)["role"] == "input"
    page.keyboard.press("ArrowUp")
    assert wait_for(lambda: _overlay_speed(page) == "1500"), _overlay_speed(page)


def test_arrows_on_a_slider_leave_the_3d_view_still(context, served_rotor):
    page = _open(context, served_rotor)
    # viser's own toast (software 3D) closes by itself over the view: not what is checked
    page.add_style_tag(content=".mantine-Notifications-root{display:none !important}")
    page.get_by_role("button", name="Pause", exact=True).press("Enter")
    page.get_by_role("button", name="Lecture", exact=True).wait_for(timeout=30_000)
    thumb = page.get_by_role("slider", name="Vitesse ×", exact=True)
    thumb.focus()
    view = {"x": 200, "y": 100, "width": 500, "height": 400}

    def shot() -> bytes:
        return page.screenshot(clip=view)

    # paused: the last frames are drawn, and the 3D labels (refreshed 4 times a second)
    assert settled(shot, polls=6)
    before = shot()
    page.keyboard.down("ArrowRight")  # held: viser would move the camera every frame
    assert wait_for(lambda: thumb.get_attribute("aria-valuenow") != "1", timeout=5)
    page.keyboard.up("ArrowRight")
    assert settled(shot, polls=2) and shot() == before
    # with the focus outside the controls, the arrows still move the view
    page.mouse.click(450, 600)  # below the rotor: the focus leaves the slider
    assert _focused(page)["role"] == "body"
    page.keyboard.down("ArrowRight")
    moved = wait_for(lambda: shot() != before, timeout=10)
    page.keyboard.up("ArrowRight")
    assert moved


def _status(page) -> tuple[float, str]:
    text = page.get_by_text(re.compile(r"^t = ")).first.inner_text()
    match = re.match(r"t = ([\d\u202f\u00a0 ,]+) s .*· (en cours|en pause)", text)
    assert match, text
    digits = re.sub(r"[\u202f\u00a0 ]", "", match.group(1)).replace(",", ".")
    return float(digits), match.group(2)


def test_space_pauses_and_plays(context, served_rotor):
    page = _open(context, served_rotor)
    assert wait_for(lambda: _status(page)[1] == "en cours")
    page.locator("body").focus()
    page.keyboard.press(" ")
    assert wait_for(lambda: _status(page)[1] == "en pause", timeout=10)
    assert page.locator(".sandbox-unseen[aria-live]").inner_text() == "Simulation en pause"
    stopped = _status(page)[0]
    assert settled(lambda: _status(page)[0], polls=5)  # simulated time no longer advances
    assert _status(page)[0] == stopped
    page.keyboard.press(" ")
    assert wait_for(lambda: _status(page) > (stopped, "en cours"), timeout=10)
    assert wait_for(lambda: _status(page)[0] > stopped + 0.1, timeout=10)
    # Space typed in a number box stays in the box: the simulation goes on
    box = page.get_by_role("textbox", name="Vitesse ×", exact=True)
    box.focus()
    page.keyboard.press(" ")
    typed = _status(page)[0]
    assert wait_for(lambda: _status(page)[0] > typed + 0.1, timeout=10)
    assert _status(page)[1] == "en cours"


_CONTRAST_JS = """(scope) => {
  function rgba(text) {
    const m = text.match(/rgba?\\(([^)]+)\\)/);
    if (!m) return null;
    const p = m[1].split(/[ ,/]+/).filter(Boolean).map(Number);
    return [p[0], p[1], p[2], p.length > 3 ? p[3] : 1];
  }
  function over(top, under) {  // top drawn over an opaque colour
    const a = top[3];
    return [0, 1, 2].map(i => top[i] * a + under[i] * (1 - a)).concat([1]);
  }
  function background(el) {
    const layers = [];
    for (let e = el; e; e = e.parentElement) {
      const c = rgba(getComputedStyle(e).backgroundColor);
      if (c && c[3] > 0) { layers.push(c); if (c[3] >= 1) break; }
    }
    let bg = [255, 255, 255, 1];
    for (let i = layers.length - 1; i >= 0; i--) bg = over(layers[i], bg);
    return bg;
  }
  function opacity(el) {
    let o = 1;
    for (let e = el; e; e = e.parentElement) o *= Number(getComputedStyle(e).opacity);
    return o;
  }
  function lum(c) {
    const v = c.slice(0, 3).map(x => { x /= 255;
      return x <= 0.04045 ? x / 12.92 : Math.pow((x + 0.055) / 1.055, 2.4); });
    return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
  }
  function visible(el) {
    const r = el.getBoundingClientRect();
    if (r.width < 1 || r.height < 1 || r.bottom < 0 || r.top > innerHeight ||
        r.right < 0 || r.left > innerWidth) return false;
    return el.checkVisibility({opacityProperty: true, visibilityProperty: true});
  }
  const out = [];
  function check(el, words, ink) {
    if (!visible(el) || el.closest('[disabled],[data-disabled],[aria-disabled=true]')) return;
    const color = rgba(ink);
    if (!color) return;
    color[3] *= opacity(el);
    if (color[3] === 0) return;
    const bg = background(el);
    const fg = over(color, bg);
    const a = lum(fg), b = lum(bg);
    const ratio = (Math.max(a, b) + 0.05) / (Math.min(a, b) + 0.05);
    out.push({text: words.slice(0, 40), ratio: Math.round(ratio * 100) / 100,
              size: getComputedStyle(el).fontSize, ink: ink,
              on: 'rgb(' + bg.slice(0, 3).map(Math.round).join(', ') + ')',
              where: (el.className && el.className.baseVal === undefined ?
                String(el.className) : el.tagName).slice(0, 60)});
  }
  document.querySelectorAll(scope).forEach(root => {
    const walk = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
    for (let n = walk.nextNode(); n; n = walk.nextNode()) {
      const words = n.nodeValue.trim();
      const el = n.parentElement;
      if (!words || !el || el.closest('svg')) continue;
      check(el, words, getComputedStyle(el).color);
    }
    root.querySelectorAll('svg text').forEach(t => check(t, t.textContent.trim(),
      getComputedStyle(t).fill));
    root.querySelectorAll('input').forEach(i => {
      if (i.value && !/^(hidden|checkbox|radio|range)$/.test(i.type))
        check(i, i.value, getComputedStyle(i).color);
    });
  });
  return out;
}"""


def _contrasts(page) -> list[dict]:
    return list(page.evaluate(_CONTRAST_JS, PANEL))


def _painted(page) -> None:
    """Wait until the browser has laid out and painted what changed (two animation
    frames: the next one starts after the layout of the current)."""
    page.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")


def _scrolled_through(page, read) -> list:
    """``read(page)`` at every scroll position of the control panel, top to bottom."""
    viewport = f"{PANEL} .mantine-ScrollArea-viewport"
    page.evaluate(f"document.querySelectorAll('{viewport}').forEach(v => v.scrollTop = 0)")
    found: list = []
    for _ in range(40):
        _painted(page)
        found += read(page)
        moved = page.evaluate(
            f"""() => {{ let moved = false;
            document.querySelectorAll('{viewport}').forEach(v => {{
              const top = v.scrollTop; v.scrollTop += v.clientHeight * 0.8;
              moved = moved || v.scrollTop !== top; }});
            return moved; }}"""
        )
        if not moved:
            break
    return found


def test_every_text_of_the_panel_reaches_4_5_to_1(context, served):
    page = _open(context, served, paused=True)
    _show_every_folder(page)
    page.mouse.move(640, 700)  # no hover colour
    found = _scrolled_through(page, _contrasts)
    assert len({f["text"] for f in found}) > 50  # labels, marks, tables, buttons...
    low = {(f["text"], f["ratio"], f["ink"], f["on"], f["where"]) for f in found}
    low = {f for f in low if f[1] < 4.5}
    assert not low, sorted(low)
    # a control's hint, shown when the pointer rests on the control
    control = page.get_by_role("button", name="Pas", exact=True).first
    tip = page.locator(".mantine-Tooltip-tooltip").first
    hints: list = []
    for _ in range(3):  # a status line that grew a line moves the button from the pointer
        control.evaluate("e => e.scrollIntoView({block: 'center'})")
        box = control.bounding_box()
        assert box
        page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
        shown = wait_for(
            lambda: tip.count() > 0 and tip.evaluate("e => getComputedStyle(e).opacity") == "1",
            timeout=5,
        )
        hints = page.evaluate(_CONTRAST_JS, ".mantine-Tooltip-tooltip") if shown else []
        if hints:
            break
        page.mouse.move(640, 700)
    assert hints and min(f["ratio"] for f in hints) >= 4.5, hints
    # the slider's end marks: as large as 7/8 of a label, not 12 px
    marks = page.locator(".mantine-Slider-markLabel").first
    assert float(marks.evaluate("e => parseFloat(getComputedStyle(e).fontSize)")) >= 14


def test_without_its_style_the_page_fails_the_contrast_check(context, served_rotor):
    """The check above can fail: viser's own grey labels are 3,3:1."""
    page = _open(context, served_rotor)
    page.evaluate(f"document.getElementById('{STYLE_ID}').remove()")
    low = [f for f in _contrasts(page) if f["ratio"] < 4.5]
    assert any(f["text"] == "Temps" for f in low), low


_CLIPPED_JS = """(scope) => {
  const out = [];
  document.querySelectorAll(scope + ' button').forEach(b => {
    const r = b.getBoundingClientRect();
    if (r.width < 1 || !b.checkVisibility()) return;
    const label = b.querySelector('.mantine-Button-label') || b;
    const l = label.getBoundingClientRect();
    const cut = label.scrollWidth > label.clientWidth + 1 ||
      b.scrollWidth > b.clientWidth + 1 || b.scrollHeight > b.clientHeight + 1 ||
      l.right > r.right + 1 || l.left < r.left - 1 || l.bottom > r.bottom + 1;
    if (cut) out.push(b.textContent.trim() + ' ' + Math.round(r.width) + 'x' +
      Math.round(r.height));
  });
  document.querySelectorAll(scope + ' input.mantine-Input-input').forEach(i => {
    const size = parseFloat(getComputedStyle(i).fontSize);
    if (i.checkVisibility() && i.clientHeight < 1.2 * size)
      out.push((i.getAttribute('aria-label') || 'case') + ' ' + i.clientHeight + ' px');
  });
  return out;
}"""


def test_no_button_or_box_is_cut_at_any_text_size(context, served_rotor):
    page = _open(context, served_rotor, paused=True)
    _show_every_folder(page)
    for px in FONT_SIZES:
        _pick(page, FONT_LABEL, font_option(px))
        assert wait_for(
            lambda p=px: (
                page.evaluate(
                    "getComputedStyle(document.documentElement)"
                    ".getPropertyValue('--mantine-font-size-sm').trim()"
                )
                == f"{p}px"
            )
        )
        page.evaluate("document.activeElement.blur()")
        _painted(page)
        cut = _scrolled_through(page, lambda p: p.evaluate(_CLIPPED_JS, PANEL))
        assert not cut, (px, sorted(set(cut)))
    # the check can fail: without the style, "Réinitialiser" is cut at 24 px
    page.evaluate(f"document.getElementById('{STYLE_ID}').remove()")
    _painted(page)
    assert _scrolled_through(page, lambda p: p.evaluate(_CLIPPED_JS, PANEL))


def test_space_finds_the_time_bar_buttons():
    """Space clicks the buttons of sandbox.web.panels.controls and of the replay by their words."""
    from sandbox.web.replay.player import ReplayPanel

    assert {"Pause", "Lecture"} <= set(PLAY_PAUSE)
    assert {k for k, v in COMMAND_KINDS.items() if isinstance(v, Pause | Play)} <= set(PLAY_PAUSE)
    assert REPLAY_TOGGLE in ReplayPanel.COMMANDS
    page = html()
    assert page.count("<script>") == 1 and page.count("</script>") == 1
