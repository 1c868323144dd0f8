"""Challenges ("Défis") on the pages: the teacher starts one from the board, each student
gets a secret that nothing their browser receives reveals, tries are counted on the board,
and stopping shows the solutions."""

from __future__ import annotations

import dataclasses
import math
import re
import struct
import threading
import time
from collections.abc import Iterator

import numpy as np
import pytest
from conftest import free_port, wait_for

from sandbox.bench.classroom import gui_message, unpack
from sandbox.bench.classroom.wire import messages
from sandbox.challenges import CHALLENGES, Challenge
from sandbox.physics.picture import geom_local_poses
from sandbox.scenes import get_scene
from sandbox.web.client.text import UNIT_SPACE, number
from sandbox.web.loop.requests import Pause, Record, SetValue
from sandbox.web.panels.board_rows import Run
from sandbox.web.panels.challenge import FOLDER, solution_lines

SECRET = {"defect_mass_g": 53.0, "skew_deg": -3.3}
"""A rotor's secret, fixed for the test (drawn numbers are tested in test_challenges)."""


class Recorder:
    """A student's browser on the websocket: every message kept (decoded)."""

    def __init__(self, url: str) -> None:
        import viser
        from websockets.sync.client import connect

        from sandbox.bench.classroom import camera_message

        self.ws = connect(
            url,
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            open_timeout=30,
            max_size=None,
        )
        self.ws.send(camera_message())
        self.inner: list[bytes] = []  # msgpack of each message, decompressed
        self.raw: list[bytes] = []  # and the whole message (meshes' buffers included)
        self._seen: dict[bytes, tuple[bool, int]] = {}
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        try:
            for raw in self.ws:
                if not isinstance(raw, bytes):
                    continue
                try:
                    inner = bytes(unpack(raw))
                except Exception:  # not viser's compressed format: kept whole
                    inner = raw
                self.raw.append(raw)
                self.inner.append(inner)
        except Exception:
            pass  # closed

    def since(self, k: int) -> bytes:
        return b"".join(self.inner[k:]) + b"".join(self.raw[k:])

    def words_since(self, k: int) -> str:
        """Every text the messages since the ``k``-th carried (labels, markdown, HTML,
        options), without their binary buffers: a French number such as « 0,53 » is
        looked for there, not in a mesh's bytes, where those four bytes may stand."""
        out: list[str] = []
        for inner in self.inner[k:]:
            try:
                out.extend(_strings(messages(inner)))
            except Exception:  # not viser's format: every byte is searched
                out.append(inner.decode("utf-8", "replace"))
        return "\n".join(out)

    def saw(self, text: bytes) -> bool:
        """Whether a message so far held ``text`` (only the new ones are searched)."""
        found, upto = self._seen.get(text, (False, 0))
        end = len(self.inner)
        found = found or any(text in m for m in self.inner[upto:end])
        self._seen[text] = (found, end)
        return found

    def close(self) -> None:
        self.ws.close()


def _strings(value: object) -> Iterator[str]:
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for key, item in value.items():
            yield from _strings(key)
            yield from _strings(item)
    elif isinstance(value, list | tuple):
        for item in value:
            yield from _strings(item)


def encodings(value: float) -> list[bytes]:
    """How a number may travel: msgpack's big-endian floats, numpy's little-endian ones."""
    return [struct.pack(f, value) for f in (">d", "<d", ">f", "<f")]


WHEEL_SECRET = {
    "defect_mass_g": 47.5,
    "defect_angle_deg": 137.0,
    "skew_deg": 0.53,
    "skew_angle_deg": 219.0,
}
"""A wheel's secret, fixed for the test."""


def _serve(monkeypatch, scene: str, secret: dict[str, float]) -> Iterator[object]:
    from sandbox.web.serving.app import start

    monkeypatch.setattr(Challenge, "draw", lambda self, defaults, rng, tries=1000: dict(secret))
    app = start(scene, port=free_port(), open_message=False, token="t-ch")
    try:
        yield app
    finally:
        app.stop()


@pytest.fixture
def rotor_class(monkeypatch) -> Iterator[object]:
    yield from _serve(monkeypatch, "rotor", SECRET)


@pytest.fixture
def wheel_class(monkeypatch) -> Iterator[object]:
    yield from _serve(monkeypatch, "wheel_balancer", WHEEL_SECRET)


def _never_sent(
    seen: bytes, words: str, ctl, secret: dict[str, float], texts: tuple[str, ...]
) -> None:
    """Nothing in ``seen`` (a student's stream since the start) tells ``secret``: neither
    its values nor their radians, nor the solution's fractional numbers (what a withheld
    readout would give), nor ``texts``, nor a number of the real shapes that differs from
    the public twin's (a tilted disk or tyre, a defect's size and place)."""
    numbers = [*secret.values(), *(math.radians(v) for v in secret.values())]
    attempt = ctl.secret.attempt
    solution = attempt.challenge.solution(attempt.values(ctl.sim.values))
    numbers += [v for v in solution.values() if abs(v - round(v)) > 1e-3]
    for value in numbers:
        for enc in encodings(value):
            assert enc not in seen, (value, enc)
    suffixes = {
        "_g": UNIT_SPACE + "g",
        "_deg": "°",
    }  # the solution as a table or the overlay writes it
    written = [
        f"{number(v, 3)}{unit}"
        for name, v in solution.items()
        for end, unit in suffixes.items()
        if name.endswith(end) and abs(v) >= 1.0
    ]
    for text in (*texts, *written):
        found = re.search(rf"(?<![0-9,]){re.escape(text)}(?![0-9])", words)  # not in 10,531
        assert found is None, (text, words[max(0, found.start() - 120) :][:160])
    real, twin = geom_local_poses(ctl.sim.model), geom_local_poses(ctl.secret.twin(ctl.sim))
    told = {float(x) for x in real[np.abs(real - twin) > 1e-6]}
    assert told  # the secret does change the real shapes...
    for x in told:  # ... and none of those numbers was sent
        assert all(enc not in seen for enc in encodings(x)), x


FRAMES: dict[int, list[int]] = {}  # frames rendered by each session _started watches


def renders_of(session) -> int:
    """Frames ``session``'s view rendered since :func:`_started` began counting."""
    return FRAMES[id(session)][0]


def _started(app, student: Recorder, name: str):
    """``name`` started for the one student of ``app``, every folder their page may still
    show opened: (their session, what their browser received since the start)."""
    assert wait_for(lambda: len(app.sessions) == 1, 30)
    ((cid, session),) = app.sessions.items()  # a session is listed once its page is built
    # A page still arriving, or a table still changing, when the run is announced would
    # send its public labels after ``before``, as if the secret page had shown them. The
    # student pauses (nothing changes any more; the challenge then runs from its start),
    # and viser sends one client's messages in order: once a marker added after the
    # pause has arrived, everything of the public page has.
    # The frame that applies the pause still draws its tables after ``playing`` turns
    # False: the marker waits for two more frames drawn (the second one started after).
    renders = [0]
    panels = [0]  # frames that refreshed the panels
    render = session.view.render

    def counted(frame):
        render(frame)
        renders[0] += 1
        panels[0] += frame.readouts is not None

    session.view.render = counted
    FRAMES[id(session)] = renders
    session.controller.submit(Pause())
    assert wait_for(lambda: not session.controller.playing, 30)
    paused_at = renders[0]
    assert wait_for(lambda: renders[0] >= paused_at + 2, 30)
    marker = app.server.get_clients()[cid].gui.add_markdown("page-built-marker")
    assert wait_for(lambda: student.saw(b"page-built-marker"), 60)
    marker.remove()
    before = len(student.inner)
    app.classroom.announce(Run(f"run-{name}", name, time.time()))
    assert wait_for(lambda: session.controller.secret is not None, 10)
    session.view.show_folder("Tous les panneaux")
    assert wait_for(lambda: session.view.shown == "Tous les panneaux", 10)
    # every folder refreshed 20 times (2 s of the page) with the secret in force, then
    # a marker: what those refreshes sent has reached the student
    shown_at = panels[0]
    assert wait_for(lambda: panels[0] >= shown_at + 20, 60)
    marker = app.server.get_clients()[cid].gui.add_markdown("all-panels-marker")
    assert wait_for(lambda: student.saw(b"all-panels-marker"), 60)
    marker.remove()
    return session, student.since(before), student.words_since(before)


@pytest.mark.slow  # a server and a websocket student: ~10 s
def test_a_student_s_secret_never_reaches_their_browser(rotor_class):
    app = rotor_class
    student = Recorder(app.url.replace("http", "ws"))
    try:
        session, seen, words = _started(app, student, "rotor_balance")
        ctl, view = session.controller, session.view
        assert all(ctl.sim.values[k] == v for k, v in SECRET.items())  # simulated...
        assert b"Rotor myst\xc3\xa8re" in seen  # the goal reached the page...
        assert "Rotor mystère" in words  # ... and the texts searched below
        hidden = ("53 g", f"53{UNIT_SPACE}g", "-3,3", "3,3°", "Balourd statique",
                  "Produits d'inertie", "tournant")  # fmt: skip
        _never_sent(seen, words, ctl, SECRET, hidden)
        # the readouts: the page's values never hold the withheld ones
        shown = view.lesson.values
        assert "bearing_A" in shown and not set(shown) & set(ctl.secret.withheld)
        slider = view.controls.sliders["defect_mass_g"]
        assert not slider.visible and slider.value == 1.0 and slider.disabled
        assert "Isoler un solide" not in view.picker.options
        # a crafted message setting the hidden slider, and a recording, are refused
        student.ws.send(gui_message(slider._impl.uuid, 20.0))
        ctl.submit(Record())
        # the refusal of the recording is applied by the loop; the crafted message came
        # first on the student's websocket, so a frame drawn after the refusal has seen it
        assert wait_for(lambda: ctl.refusals >= 1 and ctl.requests.empty(), 10)
        refused_at = renders_of(session)
        assert wait_for(lambda: renders_of(session) >= refused_at + 2, 10)
        assert ctl.sim.values["defect_mass_g"] == SECRET["defect_mass_g"]
        assert ctl.recorder is None and ctl.refusals >= 1
    finally:
        student.close()


@pytest.mark.slow  # a server and a websocket student: ~10 s
def test_a_wheel_s_heavy_spot_and_wobble_never_reach_the_browser(wheel_class):
    app = wheel_class
    student = Recorder(app.url.replace("http", "ws"))
    try:
        session, seen, words = _started(app, student, "wheel_balance")
        ctl, view = session.controller, session.view
        assert "Roue mystère".encode() in seen and "Roue mystère" in words
        hidden = ("47,5", "137°", "0,53°", "219°")  # not « 0,53 »: « t = 0,53 s » tells nothing
        _never_sent(seen, words, ctl, WHEEL_SECRET, hidden)
        assert not [t for t, label, _ in view.renderer.labels.values() if label.visible]
        hidden = [n for n, h in view.controls.sliders.items() if not h.visible]
        assert sorted(hidden) == sorted(WHEEL_SECRET)
        assert view.controls.sliders["supports"].disabled  # fixed for everyone: locked
    finally:
        student.close()


@pytest.mark.slow  # a server and a websocket student: ~10 s
def test_tries_are_counted_on_the_board_and_the_end_shows_the_solution(rotor_class):
    app = rotor_class
    student = Recorder(app.url.replace("http", "ws"))
    try:
        assert wait_for(lambda: len(app.sessions) == 1, 30)
        (session,) = app.sessions.values()
        ctl, panel = session.controller, session.view.challenge
        assert panel is not None and not panel.folder.visible
        app.classroom.announce(Run("run-2", "rotor_balance", time.time()))
        assert wait_for(lambda: ctl.secret is not None, 10)
        assert panel.folder.visible and panel.folder.label == FOLDER
        # the start announces itself, wherever the student has scrolled
        assert wait_for(lambda: student.saw("Défi lancé".encode()), 30)
        panel._clicked(None)  # a try on the bare machine: not yet
        assert "Essai 1 : pas encore" in panel.feedback.content
        assert "100 %" in panel.feedback.content
        with ctl.sim.lock:
            values = {**ctl.sim.values}
        for name, value in CHALLENGES["rotor_balance"].solution(values).items():
            ctl.submit(SetValue(name, round(value, 1)))  # the sliders' steps
        wanted = CHALLENGES["rotor_balance"].solution(values)
        assert wait_for(
            lambda: all(ctl.sim.values[k] == pytest.approx(round(v, 1)) for k, v in wanted.items()),
            5,
        )
        panel._clicked(None)
        assert panel.feedback.content.startswith("**Réussi**"), panel.feedback.content
        (row,) = app.classroom.rows()
        assert (row.challenge, row.tries) == ("rotor_balance", 2) and math.isfinite(row.solved_s)
        # the teacher stops it: the page shows the solution and the secret controls again
        app.classroom.announce(Run("run-2", "rotor_balance", time.time() - 60, ended=time.time()))
        assert wait_for(lambda: ctl.secret is None, 10)
        text = panel.feedback.content
        assert "Défi terminé" in text and f"Masselotte de défaut : 53{UNIT_SPACE}g" in text, text
        assert "Inclinaison du disque : −3,3°" in text
        assert "×10" not in text  # the solver's round-off (an angle of 8,48×10⁻¹⁴°) reads 0
        slider = session.view.controls.sliders["defect_mass_g"]
        assert wait_for(lambda: slider.visible and slider.value == 53.0, 5)
        assert "Isoler un solide" in session.view.picker.options
    finally:
        student.close()


def test_the_solution_is_written_with_the_sliders_words():
    import sandbox.scenes  # noqa: F401  (the registry)
    from sandbox.physics.simulation import Simulation

    sim = Simulation(get_scene("rotor"))
    params = {p.name: p for p in sim.scene.params}
    values = {**sim.values, **SECRET, "speed_rpm": 1500.0}
    text = solution_lines(CHALLENGES["rotor_balance"], values, params)
    assert text.startswith("Masse de correction m₁ : ")
    assert "\u00a0g ; Angle de la masse m₁ α₁ : " in text
    speed = solution_lines(CHALLENGES["rotor_speed"], values, params)
    assert speed.startswith("Vitesse ω pour 100 N au palier A : ") and speed.endswith("tr/min")
    # the solver's round-off is no number: an angle found as 8,48×10⁻¹⁴° reads 0°
    noisy = dataclasses.replace(
        CHALLENGES["rotor_balance"], solution=lambda _v: {"mass1_g": 15.5, "angle1_deg": 8.48e-14}
    )
    assert solution_lines(noisy, values, params).endswith("Angle de la masse m₁ α₁ : 0°")


def test_every_secret_parameter_is_a_slider():
    """A secret's control is hidden with its stand-in value: a slider's number (a
    dropdown or a typed box would need their own stand-ins)."""
    import sandbox.scenes  # noqa: F401
    from sandbox.scenes import get_scene
    from sandbox.web.client.fields import choices, typed

    for c in CHALLENGES.values():
        params = {p.name: p for p in get_scene(c.scene).params}
        for name in c.hidden:
            assert not choices(params[name]) and not typed(params[name]), (c.name, name)


@pytest.mark.browser
@pytest.mark.slow  # two worker processes, one Chromium page, four websocket students: ~40 s
def test_the_teacher_starts_and_stops_a_challenge_for_students_of_both_workers(open_page, tmp_path):
    import re

    from test_board import _board_text, _start_workers, _stop

    from sandbox.web.panels.board import START_BUTTON, STOP_BUTTON

    proc, port, teacher_url = _start_workers(tmp_path)
    students: list[Recorder] = []
    try:
        teacher = open_page(teacher_url)
        teacher.get_by_role("button", name=START_BUTTON).wait_for(timeout=60_000)
        students = [Recorder(f"ws://127.0.0.1:{port}") for _ in range(4)]
        assert wait_for(lambda: "4 élèves connectés." in teacher.content(), 60)
        teacher.get_by_role("button", name=START_BUTTON).click()
        goal = "Rotor mystère à équilibrer".encode()
        # every student, whichever worker serves them, gets the goal on their page
        assert wait_for(lambda: all(s.saw(goal) for s in students), 30), (
            [s.saw(goal) for s in students],
            [len(s.inner) for s in students],
            "Défi en cours" in teacher.content(),
        )
        assert wait_for(lambda: len(re.findall("aucun essai", _board_text(teacher))) == 4, 30), (
            _board_text(teacher)
        )
        assert "Défi en cours depuis" in teacher.content()
        teacher.get_by_role("button", name=STOP_BUTTON).click()
        done = "Défi terminé".encode()
        assert wait_for(lambda: all(s.saw(done) for s in students), 30)
        assert wait_for(lambda: "les élèves voient la solution" in teacher.content(), 10)
    finally:
        for s in students:
            s.close()
        _stop(proc)


@pytest.mark.slow  # a follow-mode server and a websocket student: ~10 s
def test_in_follow_mode_a_student_on_their_own_simulation_keeps_one_secret(monkeypatch):
    """Followers watch the teacher's machine: the challenge reaches a student once they
    choose "Ma simulation", and the same secret (tries included) when they come back."""
    from sandbox.web.serving.app import start

    monkeypatch.setattr(Challenge, "draw", lambda self, defaults, rng, tries=1000: dict(SECRET))
    app = start("rotor", port=free_port(), open_message=False, follow=True, token="t-f")
    student = Recorder(app.url.replace("http", "ws"))
    try:
        assert wait_for(lambda: app.counts()[1] == 1, 30)
        (cid,) = [c for c, mode in app.modes.items() if mode == "follower"]
        client = app.server.get_clients()[cid]
        app.classroom.announce(Run("run-f", "rotor_balance", time.time()))
        assert wait_for(lambda: app.classroom.run is not None, 5)
        app.switch(client, own=True)
        assert wait_for(lambda: app.counts()[2] == 1, 30)

        def own():
            return next(s for c, s in app.sessions.items() if c == cid)

        assert wait_for(lambda: own().controller.secret is not None, 10)
        first = own().controller.secret.attempt
        own().view.challenge._clicked(None)
        assert first.tries == 1
        app.switch(client, own=False)
        assert wait_for(lambda: app.counts()[1] == 1, 30)
        app.switch(client, own=True)
        assert wait_for(lambda: app.counts()[2] == 1, 30)
        assert wait_for(lambda: own().controller.secret is not None, 10)
        assert own().controller.secret.attempt is first and first.tries == 1
        assert own().controller.sim.values["defect_mass_g"] == SECRET["defect_mass_g"]
    finally:
        student.close()
        app.stop()


@pytest.mark.browser
@pytest.mark.slow  # two Chromium pages: ~25 s
def test_the_challenge_s_controls_are_named_in_french_and_readable(open_page, rotor_class):
    """The teacher's "Défi" controls and the student's "Défi" folder: every control has a
    French accessible name, every text of both panels reaches 4,5:1 (the green "Lancer le
    défi" included), the answer box says its unit."""
    from conftest import pause
    from test_browser_access import _contrasts, _controls, _scrolled_through, _unnamed

    from sandbox.web.panels.board import START_BUTTON

    app = rotor_class
    teacher = open_page(app.teacher_url)
    teacher.get_by_role("button", name=START_BUTTON).wait_for(timeout=60_000)
    pause(teacher)  # words and contrasts: no motion needed (two pages drawing it took 36 s)
    student = open_page(app.url)
    assert wait_for(lambda: app.classroom.students() == 1, 30)
    pause(student)
    teacher.mouse.move(640, 700)
    low = [f for f in _scrolled_through(teacher, _contrasts) if f["ratio"] < 4.5]
    assert not low, low
    assert not _unnamed(_controls(teacher))
    app.classroom.announce(Run("run-a", "rotor_speed", time.time()))
    answer = student.get_by_role("textbox", name="Vitesse ω pour 100 N au palier A")
    answer.wait_for(timeout=30_000)
    assert wait_for(lambda: "tr/min" in (answer.get_attribute("aria-label") or ""), 10)
    assert student.get_by_role("button", name="Proposer").is_visible()
    assert not _unnamed(_controls(student))
    student.mouse.move(640, 700)
    low = [f for f in _scrolled_through(student, _contrasts) if f["ratio"] < 4.5]
    assert not low, low
    # a proposal typed and sent from the page: counted, and judged by the server
    answer.fill("1234")
    answer.press("Enter")
    (session,) = [s for s in app.sessions.values() if s.view.challenge.attempt is not None]
    assert wait_for(lambda: session.view.challenge.answer.value == 1234, 10)
    student.get_by_role("button", name="Proposer").click()
    assert wait_for(lambda: session.view.challenge.attempt.tries == 1, 10)
    student.get_by_text("Essai 1 : pas encore", exact=False).wait_for(timeout=10_000)
