"""The app's session lifecycle: whatever order viser runs connect and disconnect in,
no session outlives its browser."""

from __future__ import annotations

import random
import threading
import time
from collections.abc import Callable
from typing import Any

import pytest
from conftest import LESSON_FILE, wait_for

from sandbox.physics.simulation import Simulation
from sandbox.web.loop import Controller, Scheduler, Session
from sandbox.web.serving.server import App

PENDULUM = """
<mujoco><option timestep="0.01"/><worldbody>
  <body name="arm"><joint name="hinge" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1"/></body>
</worldbody></mujoco>
"""


class FakeClient:
    def __init__(self, client_id: int) -> None:
        self.client_id = client_id
        self.notifications: list[tuple[str, str]] = []

    def add_notification(self, title: str, body: str, **_: object) -> None:
        self.notifications.append((title, body))


class FakeServer:
    """The three callbacks and the client list of a viser server, driven by the test."""

    def __init__(self) -> None:
        self.clients: dict[int, FakeClient] = {}
        self.connect_cb = None
        self.disconnect_cb = None
        self.stopped = False

    def get_port(self) -> int:
        return 1

    def on_client_connect(self, cb) -> None:
        self.connect_cb = cb

    def on_client_disconnect(self, cb) -> None:
        self.disconnect_cb = cb

    def get_clients(self) -> dict[int, FakeClient]:
        return dict(self.clients)

    def stop(self) -> None:
        self.stopped = True


class NullView:
    draws = False

    def wants(self, now) -> None:
        return None

    def render(self, frame) -> None:
        pass

    def notify(self, notice) -> None:
        pass


@pytest.fixture
def pendulum(tmp_path):
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM)
    return path


def _served() -> int:
    """Sessions whose frames the process's scheduler still runs."""
    return Scheduler.shared().sessions


def _factory(pendulum, gate: threading.Event | None = None, entered: threading.Event | None = None):
    def make(client) -> Session:
        if entered is not None:
            entered.set()
        if gate is not None:
            gate.wait(5.0)
        return Session(Controller(Simulation(pendulum)), NullView(), fps=30)

    return make


def test_disconnect_during_a_slow_connect_leaves_no_session(pendulum):
    server = FakeServer()
    gate, entered = threading.Event(), threading.Event()
    app = App(server, "127.0.0.1", _factory(pendulum, gate, entered))
    client = FakeClient(1)
    server.clients[1] = client
    connecting = threading.Thread(target=server.connect_cb, args=(client,))
    connecting.start()
    assert entered.wait(5.0)  # the factory is building the simulation, held by the gate
    del server.clients[1]
    server.disconnect_cb(client)  # finds no session yet: the race of the issue
    gate.set()
    connecting.join(5.0)
    assert app.sessions == {}
    assert wait_for(lambda: _served() == 0)


def test_a_session_whose_browser_vanished_stops_by_itself(pendulum):
    server = FakeServer()
    app = App(server, "127.0.0.1", _factory(pendulum))
    client = FakeClient(7)
    server.clients[7] = client
    server.connect_cb(client)
    session = app.sessions[7]
    assert wait_for(lambda: session.running)
    del server.clients[7]  # gone without a disconnect callback
    start = time.monotonic()
    assert wait_for(lambda: not session.running, timeout=3.0)
    assert time.monotonic() - start < 2.0
    assert app.reap() == 0


def test_connect_and_drop_storm_returns_to_idle(pendulum):
    """Many browsers connecting and leaving at once, callbacks in any order and on
    several threads: afterwards no session and no session thread remain."""
    server = FakeServer()
    app = App(server, "127.0.0.1", _factory(pendulum))
    rng = random.Random(12)
    threads = []
    for cid in range(40):
        client = FakeClient(cid)
        server.clients[cid] = client
        order = rng.choice(["connect-first", "disconnect-first", "together"])

        def connect(c=client):
            server.connect_cb(c)

        def drop(c=client):
            time.sleep(rng.random() * 0.01)
            server.clients.pop(c.client_id, None)
            server.disconnect_cb(c)

        pair = [threading.Thread(target=connect), threading.Thread(target=drop)]
        if order == "disconnect-first":
            pair.reverse()
        threads += pair
        for t in pair:
            t.start()
        if order != "together":
            pair[0].join()
    for t in threads:
        t.join(10.0)
    assert wait_for(lambda: _served() == 0, timeout=4.0), _served()
    assert app.reap() == 0


def test_a_full_server_says_so_in_french(pendulum):
    server = FakeServer()
    app = App(server, "127.0.0.1", _factory(pendulum), max_sessions=2)
    clients = [FakeClient(i) for i in range(3)]
    for c in clients:
        server.clients[c.client_id] = c
        server.connect_cb(c)
    try:
        assert len(app.sessions) == 2
        title, body = clients[2].notifications[0]
        assert title == "Machine pleine" and "rechargez la page" in body
    finally:
        app.stop()
    assert server.stopped and not app.sessions
    assert wait_for(lambda: _served() == 0)


def test_a_failing_factory_tells_the_browser_and_keeps_serving(pendulum):
    server = FakeServer()

    def broken(client):
        raise RuntimeError("boom")

    app = App(server, "127.0.0.1", broken)
    client = FakeClient(3)
    server.clients[3] = client
    server.connect_cb(client)
    assert app.sessions == {}
    assert client.notifications and client.notifications[0][0] == "Erreur"


def _visit(port: int, until: Callable[[dict[str, Any]], bool] | None = None) -> bool:
    """A browser's short visit: handshake, camera, a few messages (or, with ``until``, the
    messages until one satisfies it: True then), then it leaves."""
    import viser
    from websockets.sync.client import connect

    from sandbox.bench.classroom import camera_message, messages, unpack

    with connect(
        f"ws://127.0.0.1:{port}",
        origin=f"http://127.0.0.1:{port}",  # type: ignore[arg-type]
        subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
        max_size=None,
        compression=None,
        open_timeout=10,
    ) as ws:
        ws.send(camera_message())
        for _ in range(5 if until is None else 500):
            raw = ws.recv(timeout=10)
            if until is not None and isinstance(raw, bytes):
                if any(until(m) for m in messages(unpack(raw))):
                    return True
    return False


def test_a_browser_that_leaves_brings_no_closed_connection_warning(recwarn):
    """viser warns of every message queued for a browser that has left; a session sends
    some during its last half second. That warning (only it) is ignored, also when the
    server outlives the warnings filters it started with (pytest's module fixtures)."""
    import warnings

    from conftest import free_port

    from sandbox.web.serving.app import start

    with warnings.catch_warnings():  # ends as a test that started a shared server ends
        app = start("rotor", port=free_port(), open_message=False)
    left = []
    app.server.on_client_connect(left.append)
    try:
        _visit(app.port)
        assert wait_for(lambda: left and not app.connected(left[0].client_id))
        left[0].add_notification("après le départ", "jamais reçu")  # a closed connection
        wait_for(lambda: not app.reap(), timeout=5)
        warnings.warn("another warning", UserWarning, stacklevel=1)
    finally:
        app.stop()
    shown = [str(w.message) for w in recwarn.list]
    assert not [m for m in shown if "closed connection" in m], shown
    assert "another warning" in shown  # the others still show


def _picks_my_lesson(message: dict[str, Any]) -> bool:
    """The lesson picker, showing the lesson of :data:`LESSON_FILE`."""
    return (
        message.get("type") == "GuiDropdownMessage"
        and message.get("props", {}).get("label") == "Leçon"
        and message.get("value") == "Ma leçon à moi"
    )


def test_a_lesson_file_opens_in_every_new_browser(tmp_path, monkeypatch):
    """``sandbox serve FILE.md``: the file, named like no shipped lesson, is the lesson
    picked in the page (as a worker process opens it: from its path)."""
    from conftest import free_port

    from sandbox.lessons import registry as lessons
    from sandbox.web.serving.app import start

    monkeypatch.setattr(lessons, "_opened", {}, raising=False)  # opened in this test only
    lessons.catalogue.cache_clear()
    path = tmp_path / "ma-lecon.md"
    path.write_text(LESSON_FILE, encoding="utf-8")
    try:
        app = start("compressor", port=free_port(), open_message=False, lesson=str(path))
        try:
            assert _visit(app.port, until=_picks_my_lesson)
        finally:
            app.stop()
    finally:
        monkeypatch.undo()
        lessons.catalogue.cache_clear()
