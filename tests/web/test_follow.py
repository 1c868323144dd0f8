"""Follow mode: the teacher drives one shared simulation; students watch it, leave for
their own copy and come back; the teacher sends settings to the copies."""

from __future__ import annotations

import urllib.error
import urllib.request

import pytest
from conftest import wait_for

from sandbox.scenes import SCENES
from sandbox.web.client.fields import param_label
from sandbox.web.serving.follow import FOLLOW, OWN, SEND_VALUES, FollowApp, teacher_path

MASS1 = param_label(next(p for p in SCENES["rotor"].params if p.name == "mass1_g"))


@pytest.fixture
def served_follow():
    from conftest import free_port

    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), open_message=False, follow=True, token="secret-1")
    try:
        yield app
    finally:
        app.stop()


def test_the_teacher_link_serves_the_page_and_only_that_path(served_follow):
    assert served_follow.teacher_url.endswith(teacher_path("secret-1"))
    with urllib.request.urlopen(served_follow.teacher_url, timeout=10) as page:
        assert page.status == 200 and b"<html" in page.read(2000).lower()
    with pytest.raises(urllib.error.HTTPError):
        urllib.request.urlopen(served_follow.url + teacher_path("guess"), timeout=10)


def test_one_shared_simulation_steps_whatever_the_number_of_watchers(served_follow):
    app: FollowApp = served_follow
    t0 = app.shared.sim.data.time
    assert wait_for(lambda: app.shared.sim.data.time > t0 + 0.2)  # runs with nobody


@pytest.mark.browser
@pytest.mark.slow  # three Chromium pages: 22-30 s
def test_students_follow_leave_come_back_and_receive_the_teachers_settings(
    open_page, served_follow
):
    app: FollowApp = served_follow
    teacher = open_page(app.teacher_url)
    teacher.get_by_text("La classe", exact=True).first.wait_for(timeout=30_000)
    student = open_page(app.url)
    student.get_by_text("Simulation du professeur", exact=True).first.wait_for(timeout=30_000)
    assert wait_for(lambda: app.counts() == (1, 1, 0))
    drivers = [s for s in app.sessions.values() if s.drive]
    assert drivers == []  # only the broadcast session steps the shared simulation
    # the teacher's slider drives the shared simulation
    row = teacher.locator("div.mantine-Flex-root", has=teacher.get_by_text(MASS1, exact=True)).last
    box = row.locator("input.mantine-NumberInput-input").first
    box.fill("40")
    box.press("Enter")
    assert wait_for(lambda: app.shared.sim.values["mass1_g"] == pytest.approx(40.0))
    # a student leaves for an own copy that starts from the teacher's settings
    student.get_by_role("button", name=OWN).click()
    student.get_by_role("button", name=FOLLOW).wait_for(timeout=30_000)
    assert wait_for(lambda: app.counts() == (1, 0, 1))
    (own,) = [s for s in app.sessions.values() if s.drive]
    assert own.controller.sim is not app.shared.sim
    assert own.controller.sim.values["mass1_g"] == pytest.approx(40.0)
    # the teacher changes a setting and sends it to the copies
    box.fill("70")
    box.press("Enter")
    assert wait_for(lambda: app.shared.sim.values["mass1_g"] == pytest.approx(70.0))
    teacher.get_by_role("button", name=SEND_VALUES).click()
    assert wait_for(lambda: own.controller.sim.values["mass1_g"] == pytest.approx(70.0))
    teacher.get_by_text("1 élève(s) en autonomie", exact=False).first.wait_for(timeout=10_000)
    # the student's own slider tells the truth: it shows the value the teacher sent
    own_box = (
        student.locator("div.mantine-Flex-root", has=student.get_by_text(MASS1, exact=True))
        .last.locator("input.mantine-NumberInput-input")
        .first
    )
    assert wait_for(lambda: own_box.input_value() == "70"), own_box.input_value()
    # and back to following: the own copy stops
    student.get_by_role("button", name=FOLLOW).click()
    student.get_by_role("button", name=OWN).wait_for(timeout=30_000)
    assert wait_for(lambda: app.counts() == (1, 1, 0))
    assert wait_for(lambda: own.finished)


@pytest.mark.browser
@pytest.mark.slow  # two Chromium pages: about 30 s
def test_a_lesson_step_sent_by_the_teacher_moves_the_students_sliders(open_page):
    """The teacher sends step 2 (3000 tr/min): the student's own copy runs at 3000 and its
    slider reads 3000, not the 1500 of step 1."""
    from conftest import free_port

    from sandbox.web.serving.app import start
    from sandbox.web.serving.follow import SEND_STEP

    app = start(
        "rotor", port=free_port(), open_message=False, follow=True, token="t", lesson="equilibrage"
    )
    try:
        teacher = open_page(app.teacher_url)
        teacher.get_by_text("étape 1/4", exact=False).first.wait_for(timeout=30_000)
        student = open_page(app.url)
        student.get_by_role("button", name=OWN).click()
        student.get_by_role("button", name=FOLLOW).wait_for(timeout=30_000)
        student.get_by_text("étape 1/4", exact=False).first.wait_for(timeout=30_000)
        (own,) = [s for s in app.sessions.values() if s.drive]
        teacher.get_by_text("Suivant", exact=False).first.click()
        teacher.get_by_text("étape 2/4", exact=False).first.wait_for(timeout=10_000)
        teacher.get_by_role("button", name=SEND_STEP).click()
        student.get_by_text("étape 2/4", exact=False).first.wait_for(timeout=10_000)
        assert wait_for(lambda: own.controller.sim.values["speed_rpm"] == 3000.0)
        speed = param_label(next(p for p in SCENES["rotor"].params if p.name == "speed_rpm"))
        box = (
            student.locator("div.mantine-Flex-root", has=student.get_by_text(speed, exact=True))
            .last.locator("input.mantine-NumberInput-input")
            .first
        )
        assert wait_for(lambda: box.input_value() == "3000"), box.input_value()
    finally:
        app.stop()


@pytest.mark.browser
@pytest.mark.slow  # three Chromium pages: about 30 s
def test_the_teachers_study_reaches_followers_and_own_copies(open_page, served_follow):
    """Issue 25: the teacher runs a study and sends it; a follower sees it in a folder of
    its page, a student on their own copy in « Étude paramétrique », with the dots."""
    from conftest import choose, pause

    from sandbox.web.serving.follow import SEND_STUDY, STUDY_FOLDER

    app: FollowApp = served_follow
    teacher = open_page(app.teacher_url)
    teacher.get_by_text("La classe", exact=True).first.wait_for(timeout=30_000)
    follower = open_page(app.url)
    follower.get_by_text("Simulation du professeur", exact=True).first.wait_for(timeout=30_000)
    own = open_page(app.url)
    # three pages drawing on two slow cores: the first click may wait for the page
    own.get_by_role("button", name=OWN).click(timeout=90_000)
    own.get_by_role("button", name=FOLLOW).wait_for(timeout=30_000)
    assert wait_for(lambda: app.counts() == (1, 1, 1))
    # a study does not need the motion: three pages drawing it took two slow cores
    pause(teacher)  # the followers' view too
    pause(own)
    teacher.get_by_role("button", name=SEND_STUDY).click()  # nothing to send yet
    teacher.get_by_text("Lancez d'abord une étude", exact=False).first.wait_for(timeout=10_000)
    choose(teacher, "Panneau affiché", "Étude paramétrique")
    teacher.get_by_role("button", name="Lancer l'étude").click()
    teacher.get_by_text("Étude terminée", exact=False).first.wait_for(timeout=60_000)
    teacher.get_by_role("button", name=SEND_STUDY).click()
    teacher.get_by_text("Étude envoyée à 2 élève(s).", exact=True).first.wait_for(timeout=10_000)
    follower.get_by_text(STUDY_FOLDER, exact=True).first.wait_for(timeout=10_000)
    follower.get_by_text("Étude terminée : 13 simulations", exact=False).first.wait_for(
        timeout=10_000
    )
    choose(own, "Panneau affiché", "Étude paramétrique")
    own.get_by_text("Étude du professeur. Étude terminée", exact=False).first.wait_for(
        timeout=10_000
    )
    views = [v for v in app._views.values() if v.study is not None and v.study.received]
    assert len(views) == 1 and views[0].study.job is app.study
    assert sum(1 for r in app.study.rows if r is not None) == 13


@pytest.mark.slow  # a server and a websocket student: ~5 s
def test_a_student_on_their_own_copy_gets_the_share_link_and_the_join_address():
    """Follow mode built its students' own pages by a second factory of its own, without
    « Partager » and « Rejoindre »: a student who left the teacher's simulation could
    neither share their setup nor read the address for a neighbour. One factory builds
    that page in every mode."""
    from conftest import free_port
    from test_challenge_panel import Recorder

    from sandbox.web.page.link import SHARE_FOLDER
    from sandbox.web.serving.app import start

    public = "http://salle-12.lycee.example:8080"
    app = start(
        "rotor", port=free_port(), open_message=False, follow=True, token="t-j", public_url=public
    )
    student = Recorder(app.url.replace("http", "ws"))
    try:
        assert wait_for(lambda: app.counts()[1] == 1, 30)
        (cid,) = [c for c, mode in app.modes.items() if mode == "follower"]
        before = len(student.inner)
        app.switch(app.server.get_clients()[cid], own=True)
        assert wait_for(lambda: app.counts()[2] == 1, 30)
        view = next(s for c, s in app.sessions.items() if c == cid).view
        assert view.join is not None and public in view.join.html.content

        def sent(text: bytes) -> bool:  # to this student, since they left the teacher's
            return any(text in m for m in student.inner[before:])

        assert wait_for(lambda: sent(SHARE_FOLDER.encode()), 30)
        assert wait_for(lambda: sent(b"salle-12.lycee.example"), 30)
    finally:
        student.close()
        app.stop()


def test_the_teachers_count_line_agrees_in_number():
    """A teacher's trial read « 1 suivent la projection »."""
    from sandbox.web.serving.follow import counts_text

    assert counts_text(1, 0) == "Élèves : 1 suit la projection, 0 en autonomie."
    assert counts_text(0, 2) == "Élèves : 0 suit la projection, 2 en autonomie."
    assert counts_text(12, 3) == "Élèves : 12 suivent la projection, 3 en autonomie."
