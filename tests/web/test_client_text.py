"""viser's own sentences and chart numbers in French (sandbox/web/page/locale.py)."""

from __future__ import annotations

import re
from pathlib import Path

from conftest import wait_for

from sandbox.web.page import locale as client_text
from sandbox.web.page.locale import CLOSE_AFTER_S, FRENCH, french_page, page_script


def test_the_script_goes_first_in_the_head_and_cannot_be_closed_by_a_sentence():
    page = french_page("<!doctype html><html><head><title>x</title></head><body></body></html>")
    assert page is not None
    assert page.index("<script>") == page.index("<head>") + len("<head>")
    french = page_script()[: -len(client_text.page_additions()) or None]
    assert french.count("</script>") == 1 and french.count("<") == 2  # its own tags only
    assert page_script().startswith(french) and french.endswith("</script>")
    assert french_page("<html><body>no head</body></html>") is None
    assert "<title>Dynamique des solides</title>" in page and "<title>x</title>" not in page


def test_every_translation_is_french_and_one_to_one():
    assert len(set(FRENCH.values())) == len(FRENCH)
    for english, french in FRENCH.items():
        assert english != french and french.strip() == french, english
        assert not re.search(r"\b(the|is|your|browser|not|settings)\b", french), french


def test_install_is_idempotent_and_serves_a_copy_of_viser_s_page(tmp_path):
    import viser.infra as infra

    assert client_text.install() and client_text.install()
    assert infra.WebsockServer.__name__ == "FrenchClientServer"
    assert [c.__name__ for c in infra.WebsockServer.__mro__[:2]] == [
        "FrenchClientServer",
        "WebsockServer",
    ]  # wrapped once
    build = Path(infra.__file__).resolve().parent.parent / "client" / "build"
    root = client_text.french_root(build)
    assert root is not None and root == client_text.french_root(tmp_path)  # made once
    original = (build / "index.html").read_text()
    assert (root / "index.html").read_text() == french_page(original)


NOTICE_WATCH = """(() => {
  window.__notice = {seen: false, gone: false, english: false};
  setInterval(() => {
    const text = document.body ? document.body.innerText : "";
    const on = text.includes("Rendu 3D sans carte graphique");
    if (text.includes("Software WebGL rendering detected")) window.__notice.english = true;
    if (on) window.__notice.seen = true;
    else if (window.__notice.seen) window.__notice.gone = true;
  }, 100);
})();"""
"""Notes in the page whether viser's software-rendering warning showed, in English at any
reading, and went away."""


def test_the_page_reads_french_in_an_english_browser(browser):
    """An English-speaking browser without a graphics card: viser's warning toast is in
    French, the page says it is French, and numbers are formatted as uPlot formats its
    chart ticks (``Intl.NumberFormat(navigator.language)``): with a decimal comma."""
    from conftest import free_port

    from sandbox.web.serving.app import start
    from sandbox.web.serving.startup import PAGE_TITLE

    app = start("rotor", port=free_port(), open_message=False)
    context = browser.new_context(viewport={"width": 1280, "height": 720}, locale="en-US")
    # the warning comes when the 3D starts, often seconds before the panel on a loaded
    # machine, and closes itself 8 s later: the page notes when it saw it, and gone
    context.add_init_script(NOTICE_WATCH)
    try:
        page = context.new_page()
        page.goto(app.url)
        page.get_by_text("Simulation", exact=True).first.wait_for(timeout=30_000)
        assert page.evaluate("document.documentElement.lang") == "fr"
        assert page.evaluate("navigator.language") == "fr-FR"
        assert page.evaluate("new Intl.NumberFormat(navigator.language).format(0.25)") == "0,25"
        renderer = page.evaluate(
            "(() => { const gl = document.createElement('canvas').getContext('webgl2');"
            " const i = gl && gl.getExtension('WEBGL_debug_renderer_info');"
            " return i ? gl.getParameter(i.UNMASKED_RENDERER_WEBGL) : ''; })()"
        )
        software = re.search("swiftshader|llvmpipe|software", renderer, re.I)  # headless CI
        if software:
            assert wait_for(lambda: page.evaluate("window.__notice.seen"))
            assert not page.evaluate("window.__notice.english")
        body = page.inner_text("body")
        for english in FRENCH:
            assert english not in body, english
        if software:  # the warning leaves the projected 3D view by itself
            assert wait_for(lambda: page.evaluate("window.__notice.gone"), CLOSE_AFTER_S + 10)
        title = page.get_by_text(PAGE_TITLE, exact=True).first  # its settings button
        title.locator("xpath=ancestor::*[.//button][1]//button").last.click()
        page.get_by_text("Réglages de l'affichage", exact=True).click()  # English until now
        assert wait_for(lambda: "Résolution du rendu" in page.inner_text("body"))
        settings = page.inner_text("body")
        for english in ("Save Canvas", "Reset View", "Dev Settings", "Dark Mode", "Scene tree"):
            assert english not in settings, english
        # the chosen resolution (an input's value) in French; the scene tree's code names
        # (/WorldAxes, /arrows, /model) hidden
        chosen = "() => Array.from(document.querySelectorAll('input[readonly]')).map(i => i.value)"
        assert wait_for(lambda: "Adaptative" in page.evaluate(chosen))
        assert "Adaptive" not in page.evaluate(chosen)
        for code in ("WorldAxes", "arrow_labels", "Arbre de la scène"):
            assert code not in settings, code
        page.get_by_text("Réglages de l'affichage", exact=True).click()
    finally:
        context.close()
        app.stop()


def test_number_boxes_read_with_a_decimal_comma(browser):
    """viser's number box writes "0.25"; a label over it reads "0,25" while it is not being
    edited; a student may type "0,5" (the box takes it as 0.5)."""
    from conftest import free_port

    from sandbox.scenes import SCENES
    from sandbox.web.client.fields import param_label
    from sandbox.web.serving.app import start

    label = param_label(SCENES["wheel_balancer"].param("skew_deg"))  # 0.25° by default
    app = start("wheel_balancer", port=free_port(), open_message=False)
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    try:
        page = context.new_page()
        page.goto(app.url)
        page.get_by_text("Simulation", exact=True).first.wait_for(timeout=30_000)
        row = page.locator("div.mantine-Flex-root", has=page.get_by_text(label, exact=True))
        box = row.last.locator("input.mantine-NumberInput-input")
        shown = box.locator("xpath=following-sibling::span[@class='sandbox-comma']")
        assert wait_for(lambda: shown.count() == 1 and shown.inner_text() == "0,25")
        assert box.input_value() == "0.25"  # the box itself is viser's, unchanged
        assert box.evaluate("e => getComputedStyle(e).color") == "rgba(0, 0, 0, 0)"
        box.click()
        assert wait_for(lambda: shown.count() == 0)  # editing: the box's own text
        box.press("Control+a")
        box.type("0,5")
        box.press("Enter")
        page.locator("body").click(position={"x": 400, "y": 650})
        assert wait_for(lambda: shown.count() == 1 and shown.inner_text() == "0,5")
        assert box.input_value() == "0.5"
    finally:
        context.close()
        app.stop()


def test_a_page_whose_server_stops_says_so_in_french_and_clears_when_it_returns(browser):
    """viser greys its panel and spins a small red icon; the status line went on reading
    « en cours ». Once the server has not answered for a few seconds the page says, in
    French, that the simulation stopped; a page that connects again drops the line."""
    from conftest import free_port

    from sandbox.web.page.locale import LOST, LOST_AFTER_S, STOPPED
    from sandbox.web.serving.app import start

    port = free_port()
    app = start("rotor", port=port, open_message=False)
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    try:
        page = context.new_page()
        page.goto(app.url)
        page.get_by_text("Simulation", exact=True).first.wait_for(timeout=30_000)
        notice = page.locator("#sandbox-lost")
        assert notice.count() == 0
        app.stop()
        notice.wait_for(timeout=(LOST_AFTER_S + 20) * 1000)
        assert notice.inner_text() == LOST and notice.get_attribute("role") == "alert"
        status = page.get_by_text(STOPPED, exact=True)  # no longer « en cours »
        assert status.count() == 1 and "en cours" not in page.inner_text("body")
        app = start("rotor", port=port, open_message=False)  # the teacher starts it again
        notice.wait_for(state="detached", timeout=60_000)  # viser reconnected by itself
    finally:
        context.close()
        app.stop()


def test_the_page_waiting_for_its_server_reads_french(browser, tmp_path):
    """Before its first connection viser writes « Connecting... »: the page served by a
    server that is not there yet (here a plain file server) reads French."""
    import functools
    import http.server
    import threading

    import viser.infra as infra

    client_text.install()
    build = Path(infra.__file__).resolve().parent.parent / "client" / "build"
    root = client_text.french_root(build)
    assert root is not None

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args: object) -> None:
            pass

    handler = functools.partial(Quiet, directory=str(root))
    files = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=files.serve_forever, daemon=True).start()
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    try:
        page = context.new_page()
        page.goto(f"http://127.0.0.1:{files.server_address[1]}/index.html")
        page.get_by_text("Connexion au serveur…", exact=True).wait_for(timeout=30_000)
        assert "Connecting" not in page.inner_text("body")
    finally:
        context.close()
        files.shutdown()
