"""How many students the laptop holds (sandbox.web.loop.capacity, first_estimate), the
board's words for it, and the students who arrive on a saturated process following the
projected simulation (sandbox.web.serving.class_app)."""

from __future__ import annotations

import threading
import time
from types import SimpleNamespace

import pytest
from conftest import free_port, wait_for

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.web.loop.capacity import Load, merged, students_at, students_for
from sandbox.web.loop.controller import Controller
from sandbox.web.loop.first_estimate import measure
from sandbox.web.panels.board_rows import Board
from sandbox.web.panels.board_table import capacity_words
from sandbox.web.serving.roster import Roster


def test_a_load_travels_between_processes_and_a_crafted_one_is_dropped():
    load = Load(sessions=15, frames=900.0, cpu=0.9, stepping=0.2, fps=45.0, saturated=False)
    assert Load.from_wire(load.wire()) == load
    for bad in ([1], {"sessions": "15"}, {"cpu": float("nan")}, {"frames": -1},
                {"saturated": "yes"}, {"sessions": True}):  # fmt: skip
        assert Load.from_wire(bad) is None


def test_the_estimate_is_the_cores_over_a_student_s_cost_at_30_frames():
    # 1 ms a frame, no stepping: 30 frames/s is 0.03 core a student; 2 cores at 85 %
    assert students_for(0.0, 1e-3, cores=2) == 56
    assert students_for(0.03, 1e-3, cores=2) == 28  # stepping doubles it
    load = Load(sessions=30, frames=30 * 45.0, cpu=30 * (0.01 + 45 * 0.5e-3), stepping=0.3)
    # a student: 0.01 core of stepping and 0.5 ms a frame -> 0.025 core at 30 frames/s
    assert students_at(load, cores=2) == 68
    assert students_at(Load(), cores=2) is None


def test_the_board_adds_the_workers_loads_and_says_it_in_words():
    roster = Roster(0.0)
    one = Load(sessions=15, frames=675.0, cpu=0.45, stepping=0.15, fps=45.0)
    two = Load(sessions=15, frames=675.0, cpu=0.45, stepping=0.15, fps=40.0)
    roster.update(0, [], 1.0, one)
    roster.update(1, [], 1.0, two)
    board = roster.board(1.0)
    assert board.load == merged([one, two])
    assert Board.from_wire(board.wire()) == board
    words = capacity_words(board.load)
    assert "Ce portable tient environ **" in words and "élèves** sur cette scène" in words
    assert "images abaissées à 40 par seconde pour tous" in words
    saturated = capacity_words(Load(sessions=30, frames=450, cpu=1.9, stepping=1.0,
                                    fps=15.0, saturated=True))  # fmt: skip
    assert "Portable saturé : les nouveaux élèves suivent votre simulation" in saturated
    assert capacity_words(None) == ""
    roster.drop(1, 2.0)
    assert roster.board(2.0).load == one


def test_the_first_estimate_measures_one_session_of_the_scene():
    """Two seconds of one session's frames (a fake clock: no wait), its stepping and
    its frames on this thread's CPU."""

    class Clock:
        now = 0.0

        def __call__(self) -> float:
            return self.now

    clock = Clock()

    def sleep(seconds: float) -> None:
        clock.now += max(seconds, 1 / 60)

    load = measure(lambda: Controller(Simulation(get_scene("rotor")), clock=clock), sleep=sleep)
    assert load.sessions == 1
    assert load.frames == pytest.approx(60.0, rel=0.05)
    assert load.cpu > load.stepping > 0
    assert students_at(load) is not None and students_at(load) > 0


@pytest.mark.slow  # a server and two websocket students: a few seconds
def test_a_student_arriving_on_a_saturated_process_follows_the_projected_simulation(
    monkeypatch,
):
    from test_board import FakeStudent

    from sandbox.web.serving import class_app
    from sandbox.web.serving.app import start

    monkeypatch.setattr(class_app, "SHED_CHECK", 3600.0)  # arrivals only (shed: below)
    app = start("rotor", port=free_port(), open_message=False, token="tok-sat")
    url = app.url.replace("http", "ws")
    students = []
    try:
        students.append(FakeStudent(url))
        assert wait_for(lambda: len(app.sessions) == 1, 30)
        assert not app.overflow  # its own simulation
        # what the governor decides after three windows at 15 frames/s still too costly
        # (tests/web/test_governor.py): here, a loop whose governor says so
        app.scheduler = SimpleNamespace(governor=SimpleNamespace(saturated=True))
        students.append(FakeStudent(url))
        assert wait_for(lambda: len(app.sessions) == 2, 30)
        assert len(app.overflow) == 1  # following, drawn once for every such student
        assert app.broadcast is not None
        follower = app.sessions[next(iter(app.overflow))]
        assert follower.drive is False and follower.controller is app.broadcast.controller
    finally:
        for s in students:
            s.close()
        app.stop()


@pytest.mark.slow  # a server and four websocket students: a few seconds
def test_students_arriving_together_on_a_saturated_process_share_one_broadcast(monkeypatch):
    """Browsers connect on threads of their own: four arriving at once get one broadcast
    (two would name the same nodes, the second's replacing the first's while it drew)."""
    from test_board import FakeStudent

    from sandbox.web.serving import class_app
    from sandbox.web.serving.app import start

    made: list[object] = []
    real = class_app.BroadcastView

    def counted(*args, **kwargs):
        time.sleep(0.3)  # slow to build, as on a saturated laptop
        made.append(real(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(class_app, "BroadcastView", counted)
    monkeypatch.setattr(class_app, "SHED_CHECK", 3600.0)
    app = start("rotor", port=free_port(), open_message=False, token="tok-together")
    app.scheduler = SimpleNamespace(governor=SimpleNamespace(saturated=True))
    url = app.url.replace("http", "ws")
    students = []
    try:
        threads = [
            threading.Thread(target=lambda: students.append(FakeStudent(url))) for _ in range(4)
        ]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        assert wait_for(lambda: len(app.overflow) == 4, 30)
        assert len(made) == 1 and app.broadcast is made[0]
        followed = {app.sessions[cid].controller for cid in app.overflow}
        assert followed == {app.broadcast.controller}
    finally:
        for s in students:
            s.close()
        app.stop()


@pytest.mark.slow  # a server and four websocket students: a few seconds
def test_a_class_that_arrived_together_is_moved_to_the_projection_when_it_saturates(
    monkeypatch,
):
    """Four students arrive before the governor can tell: each has a simulation of their
    own. Once saturated with each session given 10 frames/s for a floor of 15, a third of
    them (the last to arrive, at least one) follow the projected simulation, reading why;
    nothing more until SHED_PAUSE has passed; a student who arrived over SHED_RECENT s
    ago or who records keeps their own; nothing moves while the process is not saturated."""
    from test_board import FakeStudent

    from sandbox.web.serving import class_app
    from sandbox.web.serving.app import start

    monkeypatch.setattr(class_app, "SHED_CHECK", 3600.0)  # the test calls shed() itself
    monkeypatch.setattr(class_app, "SHED_MIN", 4)  # a class of four here (six: a class)
    app = start("rotor", port=free_port(), open_message=False, token="tok-shed")
    url = app.url.replace("http", "ws")
    students = []
    try:
        for k in range(4):
            students.append(FakeStudent(url))
            assert wait_for(lambda k=k: len(app.sessions) == k + 1, 30)
        assert wait_for(lambda: len(app.arrived) == 4, 30) and not app.overflow
        order = sorted(app.arrived, key=app.arrived.__getitem__)
        governor = SimpleNamespace(saturated=False, given=10.0, floor=15.0)
        app.scheduler = SimpleNamespace(governor=governor)
        now = time.monotonic()
        assert app.shed(now) == 0  # not saturated: nobody moves
        monkeypatch.setattr(class_app, "SHED_MIN", 5)
        governor.saturated = True
        assert app.shed(now) == 0  # four students are not a class arriving together
        monkeypatch.setattr(class_app, "SHED_MIN", 4)
        governor.saturated = False
        governor.saturated = True
        # the first arrived long ago; the third records
        app.arrived[order[0]] -= class_app.SHED_RECENT + 1
        recording = SimpleNamespace(frame=lambda row: None, full=False)  # rows dropped
        app.sessions[order[2]].controller.recorder = recording
        assert app.shed(now) == 2  # ceil(4 x (1 - 10/15)) = 2: the last two that may
        assert app.overflow == {order[3], order[1]}
        for cid in app.overflow:
            session = app.sessions[cid]
            assert session.drive is False and session.controller is app.broadcast.controller
        assert app.shed(now + 0.1) == 0  # the governor sees the lighter load first
        app.sessions[order[2]].controller.recorder = None
        assert app.shed(now + class_app.SHED_PAUSE) == 1  # the third, done recording
        assert app.shed(now + 2 * class_app.SHED_PAUSE) == 0  # the first stays: not new
        assert order[0] not in app.overflow and len(app.overflow) == 3
        assert app.shed_count == 3
    finally:
        for s in students:
            s.close()
        app.stop()


@pytest.mark.slow  # a server and a websocket student: a few seconds
def test_a_student_whose_move_to_the_projection_fails_keeps_a_simulation_of_their_own(
    monkeypatch,
):
    """The projection cannot be built (a fault): the student moved while the process
    is saturated gets their own simulation back, never no page at all."""
    from test_board import FakeStudent

    from sandbox.web.serving import class_app
    from sandbox.web.serving.app import start

    monkeypatch.setattr(class_app, "SHED_CHECK", 3600.0)
    monkeypatch.setattr(class_app, "SHED_MIN", 1)
    app = start("rotor", port=free_port(), open_message=False, token="tok-shed-fail")
    url = app.url.replace("http", "ws")
    student = FakeStudent(url)
    try:
        assert wait_for(lambda: len(app.arrived) == 1, 30)
        (cid,) = app.arrived
        old = app.sessions[cid]

        def broken(client):
            raise RuntimeError("no projection")

        monkeypatch.setattr(app, "_follower", broken)
        app.scheduler = SimpleNamespace(governor=SimpleNamespace(saturated=True, given=5.0))
        assert app.shed() == 1
        session = app.sessions[cid]
        assert session is not old and session.drive and not app.overflow
    finally:
        student.close()
        app.stop()
