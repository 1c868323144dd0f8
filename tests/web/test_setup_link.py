"""A setup shared as a link: reading and writing its fragment (untrusted text), and a page
opened from one, in one worker or two (headless Chromium)."""

from __future__ import annotations

import contextlib
import json
import os
import random
import signal
import subprocess
from urllib.parse import quote, urlencode

import pytest
from conftest import free_port, serve_workers, wait_for

from sandbox.bench import classroom
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene
from sandbox.web.page import link as client_link
from sandbox.web.page.link import BUTTON, LINK_LABEL, SHARE_FOLDER
from sandbox.web.panels import setup_link
from sandbox.web.panels.setup_link import RESERVED, Ignored, Setup, build, parse, read, slug

FOLDERS = ("Affichage", "Méthode numérique", "Torseurs", "Grandeurs de la scène")


@pytest.fixture(scope="module")
def rotor_page() -> setup_link.Page:
    return setup_link.page_of(
        Simulation(get_scene("rotor")), folders=FOLDERS, lessons={"equilibrage": 4}, lesson=None
    )


def _why(ignored: list[Ignored], part: str) -> str:
    found = [i.why for i in ignored if i.part == part]
    assert found, (part, ignored)
    return found[0]


# -- parse: syntax ------------------------------------------------------------------------
def test_parse_reads_names_and_values_with_or_without_the_hash():
    for text in ("#v=1&speed_rpm=1500&hide=mass2_g", "v=1&speed_rpm=1500&hide=mass2_g"):
        parts, ignored = parse(text)
        assert parts == [("v", "1"), ("speed_rpm", "1500"), ("hide", "mass2_g")]
        assert ignored == []


def test_parse_refuses_a_link_too_long_whole_and_never_reads_it():
    parts, ignored = parse("v=1&speed_rpm=1500&" + "a" * setup_link.MAX_CHARS)
    assert parts == []
    assert len(ignored) == 1 and "2000 caractères" in ignored[0].why


def test_parse_keeps_the_first_of_repeated_names():
    parts, ignored = parse("speed_rpm=1000&speed_rpm=5000")
    assert parts == [("speed_rpm", "1000")]
    assert _why(ignored, "speed_rpm=5000") == "réglage en double, le premier est gardé"


def test_parse_refuses_bad_names_bad_encodings_and_parts_past_the_limit():
    parts, ignored = parse(
        "=1&1abc=2&a-b=3&%C3%A9t%C3%A9=4&x=%FF&noequal&n=%0Aline&"
        + "&".join(f"k{i}=1" for i in range(setup_link.MAX_PARTS + 3))
    )
    assert _why(ignored, "=1") == "nom de réglage invalide"
    assert _why(ignored, "1abc=2") == "nom de réglage invalide"
    assert _why(ignored, "a-b=3") == "nom de réglage invalide"
    assert _why(ignored, "%C3%A9t%C3%A9=4") == "nom de réglage invalide"  # unicode name
    assert _why(ignored, "x=%FF") == "caractères illisibles"  # not UTF-8
    assert _why(ignored, "noequal") == "pas de la forme nom=valeur"
    assert _why(ignored, "n=%0Aline") == "valeur trop longue ou illisible"
    assert len(parts) == setup_link.MAX_PARTS - 7  # the 7 bad ones count among the parts
    assert sum("au-delà" in i.why for i in ignored) == 10


def test_parse_never_raises_on_anything():
    rng = random.Random(7)
    alphabet = "=&%#,.+-eE0123456789abcé<>\"'\\\x00\u202e😀"
    for _ in range(500):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randrange(60)))
        parts, ignored = parse(text)
        assert all(isinstance(n, str) and isinstance(v, str) for n, v in parts)
    assert parse(None) == ([], [Ignored("None", "lien illisible")])  # type: ignore[arg-type]


# -- validate: against the page -----------------------------------------------------------
def test_a_full_link_gives_its_setup(rotor_page):
    setup, ignored = read(
        "#v=1&speed_rpm=3000&mass1_g=12.5&speed=0.5&integrator=rk4&timestep=0.0005"
        "&open=Affichage,torseurs&hide=mass2_g&lock=speed_rpm,integrator"
        "&lesson=equilibrage&step=2",
        rotor_page,
    )
    assert ignored == []
    assert setup == Setup(
        settings=(
            ("speed_rpm", 3000.0),
            ("mass1_g", 12.5),
            ("speed", 0.5),
            ("integrator", "rk4"),
            ("timestep", 0.0005),
        ),
        open=("affichage", "torseurs"),
        hide=("mass2_g",),
        lock=("speed_rpm", "integrator"),
        lesson="equilibrage",
        step=2,
    )


def test_values_get_the_checks_of_the_slider_in_french(rotor_page):
    setup, ignored = read(
        "angle1_deg=999&mass1_g=-1&speed_rpm=nan&mass2_g=inf&skew_deg=1e999&angle2_deg=0x10"
        "&defect_mass_g=1,5&speed=9&integrator=<b>&timestep=1",
        rotor_page,
    )
    assert setup.settings == ()
    assert "999° refusé, choisissez entre −180 et 180°" in _why(ignored, "angle1_deg=999")
    assert "choisissez entre 0 et 200 g" in _why(ignored, "mass1_g=-1")
    for part in ("speed_rpm=nan", "mass2_g=inf", "angle2_deg=0x10", "defect_mass_g=1,5"):
        assert _why(ignored, part) == "un nombre écrit avec un point est attendu"
    assert _why(ignored, "skew_deg=1e999") == "un nombre fini est attendu"
    assert "Vitesse ×9 refusée" in _why(ignored, "speed=9")
    assert "Intégrateur « <b> » inconnu" in _why(ignored, "integrator=<b>")
    assert "Pas de temps dt = 1 s refusé" in _why(ignored, "timestep=1")


def test_unknown_names_folders_controls_and_lessons_are_ignored(rotor_page):
    setup, ignored = read(
        "foo=1&open=nowhere,affichage&hide=ghost,mass2_g&lock=mass2_g,speed_rpm"
        "&lesson=gyroscope&step=1",
        rotor_page,
    )
    assert _why(ignored, "foo=1") == "paramètre inconnu de cette scène"
    assert _why(ignored, "open=nowhere") == "dossier inconnu"
    assert _why(ignored, "hide=ghost") == "réglage inconnu"
    assert _why(ignored, "lesson=gyroscope") == "leçon inconnue pour cette scène"
    assert _why(ignored, "step=1") == "aucune leçon ouverte"
    assert setup.open == ("affichage",)
    assert setup.hide == ("mass2_g",) and setup.lock == ("speed_rpm",)  # hidden wins


def test_steps_are_counted_from_one_within_the_lesson(rotor_page):
    for step in ("0", "5", "-1", "2.0", "٣", "99999"):
        setup, ignored = read(f"lesson=equilibrage&step={quote(step)}", rotor_page)
        assert setup.step is None and _why(ignored, f"step={step}") == "étape de 1 à 4 attendue"
    page = setup_link.page_of(
        Simulation(get_scene("rotor")), lessons={"equilibrage": 4}, lesson="equilibrage"
    )
    assert read("step=4", page)[0].step == 4  # the page's own lesson


def test_another_version_is_refused_whole(rotor_page):
    setup, ignored = read("v=2&speed_rpm=3000", rotor_page)
    assert setup.empty
    assert ignored == [Ignored("v=2", "version de lien inconnue (seule 1)")]


def test_a_choice_takes_an_option_index_only():
    page = setup_link.page_of(Simulation(get_scene("rolling_cylinder")))
    assert read("race=1", page) == (Setup(settings=(("race", 1.0),)), [])
    assert "choisissez parmi 0 (Non) ; 1 (Oui)" in _why(read("race=0.5", page)[1], "race=0.5")


def test_a_file_without_parameters_says_so(pendulum_xml):
    page = setup_link.page_of(Simulation(pendulum_xml))
    setup, ignored = read("speed_rpm=1&timestep=0.002", page)
    assert _why(ignored, "speed_rpm=1") == "ce modèle n'a pas de paramètre"
    assert setup.settings == (("timestep", 0.002),)


def test_no_scene_parameter_takes_a_reserved_name():
    for name, scene in SCENES.items():
        spec = scene
        assert spec is not None
        assert not {p.name for p in spec.params} & set(RESERVED), name


# -- the French line ----------------------------------------------------------------------
def test_the_refusal_line_is_one_bounded_line_quoting_what_was_ignored(rotor_page):
    _, ignored = read(
        "x=%3Cimg%20src%3Dx%20onerror%3Dalert(1)%3E&a=1&b=2&c=3&d=4&e=" + "z" * 150, rotor_page
    )
    line = setup_link.refusal_line(ignored)
    assert "\n" not in line and len(line) < 600
    assert line.startswith("Parties du lien ignorées : « x=<img src=x onerror=alert(1)> »")
    assert "et 2 autres" in line and line.endswith("Le reste du lien est appliqué.")
    assert setup_link.refusal_line([]) == ""


# -- build: the link written back ---------------------------------------------------------
def test_build_writes_a_short_readable_fragment():
    setup = Setup(
        settings=(("speed_rpm", 1500.0), ("mass1_g", 0.0), ("timestep", 2e-05)),
        open=("affichage",),
        hide=("mass2_g",),
        lock=("speed_rpm",),
        lesson="equilibrage",
        step=2,
    )
    assert build(setup) == (
        "v=1&speed_rpm=1500&mass1_g=0&timestep=2e-05&open=affichage&hide=mass2_g"
        "&lock=speed_rpm&lesson=equilibrage&step=2"
    )
    assert setup_link.link("http://salle:8080/#old", setup).startswith("http://salle:8080/#v=1&")


def test_build_then_read_gives_the_same_setup_exactly(rotor_page):
    rng = random.Random(3)
    params = list(rotor_page.params.values())
    for _ in range(200):
        chosen = rng.sample(params, rng.randrange(1, len(params)))
        settings = tuple(
            (
                p.name,
                float(rng.randint(int(p.min), int(p.max)))
                if p.integer
                else rng.uniform(p.min, p.max),
            )
            for p in chosen
        )
        setup = Setup(settings=settings, open=("torseurs",), lock=(chosen[0].name,))
        back, ignored = read("#" + build(setup), rotor_page)
        assert ignored == [] and back == setup  # floats equal to the last bit


def test_slugs_match_the_page_script_rule():
    assert slug("Réglages avancés") == "reglages-avances"
    assert slug("Énergie et puissances") == "energie-et-puissances"
    assert slug("  Méthode  numérique ") == "methode-numerique"


# -- the page's side: what the websocket carries ------------------------------------------
def test_the_websocket_query_gives_the_fragment_and_the_page_bounded():
    query = urlencode({"sandbox_link": "v=1&a=" + "x" * 5000, "sandbox_page": "http://h:1/"})
    fragment, page = client_link.from_query(query)
    assert len(fragment) == setup_link.MAX_CHARS + 1 and page == "http://h:1/"
    assert client_link.from_query("&".join(["a=1"] * 100)) == ("", "")  # too many fields
    assert client_link.from_query("") == ("", "")


def test_only_a_plain_http_page_address_is_used():
    assert (
        client_link.page_address("https://salle.lycee.fr/td/", "") == "https://salle.lycee.fr/td/"
    )
    assert client_link.page_address("http://[::1]:8080/", "") == "http://[::1]:8080/"
    for bad in ("javascript:alert(1)", "http://a b/", "http://h/<x>", "http://h/" + "a" * 600):
        assert client_link.page_address(bad, "10.0.0.5:8080") == "http://10.0.0.5:8080/"
    assert client_link.page_address("data:x", "evil host") == ""


def test_a_link_never_carries_the_teacher_s_secret_path():
    secret = "/prof/s3cr3t"
    page = "http://10.0.0.5:8080" + secret
    assert client_link.page_address(page, "", secret) == "http://10.0.0.5:8080/"
    behind = "https://lycee.fr/sandbox" + secret  # a proxy serving under /sandbox
    assert client_link.page_address(behind, "", secret) == "https://lycee.fr/sandbox/"
    assert client_link.page_address("http://h:1/", "", "/") == "http://h:1/"


def test_the_page_script_cannot_be_closed_by_its_texts():
    script = client_link.html()
    assert script.startswith("<script>") and script.count("<") == 2  # its own tags only
    for text in (BUTTON, LINK_LABEL):
        assert json.dumps(text, ensure_ascii=True) in script


# -- in a browser ---------------------------------------------------------------------------
LINK = (
    "#v=1&speed_rpm=3000&mass1_g=12.5&open=affichage,torseurs&hide=mass2_g&lock=speed_rpm"
    "&lesson=equilibrage&step=2&foo=1&x=%3Cimg%20src%3Dx%20onerror%3Dwindow.hacked%3D1%3E"
)


def _row(page, label: str):
    return page.locator("div.mantine-Flex-root", has=page.get_by_text(label, exact=True)).last


def _open_folder(page, label: str) -> None:
    head = page.locator(".mantine-Paper-root > .mantine-Paper-root:first-child", has_text=label)
    head.first.click()


@pytest.mark.browser
@pytest.mark.slow  # a Chromium page: 5-15 s
def test_a_page_opened_from_a_link_applies_it_and_writes_it_back(browser):
    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), open_message=False)
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    context.grant_permissions(["clipboard-read", "clipboard-write"])
    try:
        page = context.new_page()
        page.goto(app.url + "/" + LINK)
        assert wait_for(lambda: len(app.sessions) == 1, timeout=30)
        session = next(iter(app.sessions.values()))
        sim, view = session.controller.sim, session.view
        assert wait_for(lambda: sim.values["speed_rpm"] == 3000.0, timeout=30)
        assert sim.values["mass1_g"] == 12.5
        assert view.lesson.position() == ("equilibrage", 1)
        assert view.shown == "Torseurs"
        # the refused parts, in one French line; nothing of them reaches the page's HTML
        notice = page.wait_for_function(
            """() => [...document.querySelectorAll("[class*=Notification] *")]
                .map(e => e.textContent).find(t => t.startsWith("Parties du lien ignorées"))""",
            timeout=60_000,
        ).json_value()
        assert "« foo=1 » (paramètre inconnu de cette scène)" in notice
        assert page.evaluate("window.hacked") is None
        assert page.locator("img[src=x]").count() == 0
        # the lesson's step, the open folder, the hidden and the locked controls
        page.get_by_text("étape 2/4", exact=False).first.wait_for(timeout=60_000)
        page.get_by_text("Ralenti", exact=True).wait_for(timeout=60_000)  # "Affichage" open
        labels = page.locator("label").all_inner_texts()
        assert "Masse de correction m₁ [g]" in labels and "Masse de correction m₂ [g]" not in labels
        speed = _row(page, "Vitesse de rotation ω [tr/min]")
        thumb, box = speed.locator(".mantine-Slider-thumb"), speed.locator("input[type=text]")
        assert wait_for(lambda: box.is_disabled(), timeout=30)
        assert thumb.get_attribute("aria-disabled") == "true"
        free = _row(page, "Masse de correction m₁ [g]")
        assert free.locator("input[type=text]").is_enabled()
        assert free.locator(".mantine-Slider-thumb").get_attribute("aria-disabled") != "true"
        # a crafted message to the locked slider changes nothing
        handle = view.controls.sliders["speed_rpm"]
        assert handle.disabled
        # the button writes the same setup back, at the page's own address, and copies it
        _open_folder(page, SHARE_FOLDER)
        page.get_by_role("button", name=BUTTON).click()
        field = _row(page, LINK_LABEL).locator("textarea").first
        assert wait_for(lambda: field.input_value().startswith(app.url + "/#v=1&"), timeout=30)
        link = field.input_value()
        back, ignored = read(
            link.partition("#")[2],
            setup_link.page_of(
                sim, folders=tuple(view.groups) + ("Affichage",), lessons={"equilibrage": 4}
            ),
        )
        assert ignored == []
        values = dict(back.settings)
        assert values["speed_rpm"] == 3000.0 and values["mass1_g"] == 12.5
        assert values == {n: sim.values[n] for n in values}  # each as the server holds it
        assert back.open == ("torseurs", "affichage")
        assert back.hide == ("mass2_g",) and back.lock == ("speed_rpm",)
        assert (back.lesson, back.step) == ("equilibrage", 2)
        assert field.evaluate("e => e.readOnly")
        page.get_by_text("Lien copié", exact=False).wait_for(timeout=30_000)
        assert page.evaluate("navigator.clipboard.readText()") == link
        # served on this computer only: the folder says the students cannot open it
        page.get_by_text("n'écoute que cet ordinateur", exact=False).wait_for(timeout=30_000)
    finally:
        context.close()
        app.stop()


def test_a_link_starts_at_the_address_students_use():
    """Links start with the first address students type (the network address printed at
    start, or --public-url), whatever address the teacher's page was opened at; a loopback
    page without one says the students cannot open it."""
    students = "http://192.168.1.20:8080"
    base, whose = client_link.link_base(
        [students, "http://10.0.0.7:8080"], "http://127.0.0.1:8080/"
    )
    assert base == students + "/" and whose.endswith("adresse des élèves : " + base)
    proxy = "https://salle-b12.lycee.fr/dynamique"
    assert client_link.link_base([proxy], "http://127.0.0.1:8080/")[0] == proxy + "/"
    for own in ("http://127.0.0.1:8080/", "http://localhost:8080/", "http://[::1]:8080/"):
        base, whose = client_link.link_base([], own)
        assert base == own and "n'écoute que cet ordinateur" in whose and "--host 0.0.0.0" in whose
    base, whose = client_link.link_base([], "http://10.0.0.5:8080/")
    assert base == "http://10.0.0.5:8080/" and "adresse de cette page" in whose
    assert client_link.link_base([], "") == ("", "")


@pytest.mark.browser
def test_the_teachers_link_opens_at_the_public_url(browser):
    """A teacher's page opened at 127.0.0.1 of a server behind a proxy: the copied link
    starts with ``--public-url`` and the folder says it is the students' address."""
    from sandbox.web.serving.app import start

    public = "https://salle-b12.lycee.fr/dynamique"
    app = start("rotor", port=free_port(), open_message=False, public_url=public)
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    try:
        page = context.new_page()
        page.goto(app.teacher_url)  # it opens on « Rejoindre » (students can reach it)
        assert wait_for(lambda: len(app.sessions) == 1, 30)
        (session,) = app.sessions.values()
        assert wait_for(lambda: session.view.shown == "Rejoindre", 30)
        _open_folder(page, SHARE_FOLDER)
        page.get_by_role("button", name=BUTTON).click()
        field = _row(page, LINK_LABEL).locator("textarea").first
        assert wait_for(lambda: field.input_value().startswith(public + "/#v=1"), timeout=30)
        assert "rejoindre" not in field.input_value()  # the teacher's panel, not the class's
        page.get_by_text(f"adresse des élèves : {public}/", exact=False).wait_for(timeout=30_000)
    finally:
        context.close()
        app.stop()


@pytest.mark.browser
@pytest.mark.slow  # two worker processes and two Chromium pages: 15-30 s
def test_every_worker_applies_the_link(browser, tmp_path):
    proc, port = serve_workers(tmp_path, workers=2)
    assert isinstance(proc, subprocess.Popen)
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    try:
        first = proc.stdout.readline() if proc.stdout else ""
        assert "by 2 worker processes" in first, first
        pages = []
        for _ in range(2):  # the front hands the second websocket to the other worker
            page = context.new_page()
            page.goto(f"http://127.0.0.1:{port}/#v=1&speed_rpm=4250&lock=mass1_g")
            pages.append(page)
        for page in pages:
            box = _row(page, "Vitesse de rotation ω [tr/min]").locator("input[type=text]")
            assert wait_for(lambda box=box: box.input_value() == "4250", timeout=40)
            mass = _row(page, "Masse de correction m₁ [g]").locator("input[type=text]")
            assert wait_for(mass.is_disabled, timeout=30)
        split = classroom.connections_per_process(proc.pid, port)
        assert sorted(split.values()) == [1, 1], split  # one page in each worker
    finally:
        context.close()
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGTERM)
        with contextlib.suppress(subprocess.TimeoutExpired):
            proc.wait(15)


def test_a_disabled_control_ignores_the_messages_only_a_crafted_page_sends():
    from types import SimpleNamespace

    from sandbox.web.client.fields import on_user

    callbacks, applied = [], []
    handle = SimpleNamespace(disabled=False, on_update=callbacks.append)
    on_user(handle, applied.append)  # type: ignore[arg-type]
    event = SimpleNamespace(client=object(), target=SimpleNamespace(value=42.0))
    callbacks[0](event)
    handle.disabled = True  # what a link's "lock" or "hide" does
    event.target.value = 6000.0
    callbacks[0](event)
    assert applied == [42.0]
