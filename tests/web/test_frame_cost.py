"""What one session costs per drawn frame, counted (CI cannot time, it can count): the
viser messages it queues for its browser and the readout evaluations it makes, for every
scene, against bounds that fail when a frame starts doing more than it needs.

A real viser server and a real websocket client; the session's frames are run by the
test with a fake clock (1/60 s a frame), so every frame is a drawn frame.
"""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np
import pytest
from conftest import wait_for

from sandbox.bench import classroom
from sandbox.physics import imposed as imposed_module
from sandbox.physics import readouts as generic
from sandbox.physics import simulation as simulation_module
from sandbox.physics import torsors
from sandbox.physics.picture import body_groups
from sandbox.scenes import SCENES
from sandbox.scenes.revolutions import PerModel
from sandbox.web.client import wire
from sandbox.web.loop import Session
from sandbox.web.loop import frame as session_module
from sandbox.web.loop.requests import Pause, Play
from sandbox.web.serving import app as web_app
from sandbox.web.views.browser import IN_FLIGHT, MAX_HELD

FRAMES = 120
"""Frames counted (two seconds at 60 frames/s: 20 panel refreshes)."""

WARMUP = 30
"""Frames run first (first draw of every node, a scene's cached revolution)."""


class Clock:
    def __init__(self) -> None:
        self.now = time.perf_counter()

    def __call__(self) -> float:
        return self.now


@dataclass
class Counts:
    """What the counted frames did."""

    frames: int = 0
    pictures: int = 0
    panel_ticks: int = 0
    messages: list[int] = field(default_factory=list)  # per frame, drawn-only frames
    panel_messages: list[int] = field(default_factory=list)  # per frame with a refresh
    prepares: int = 0
    supports: int = 0
    readout_calls: int = 0
    revolutions: int = 0  # revolutions simulated ahead (compressor, engine)
    inverse: int = 0  # inverse-dynamics solves (an imposed motion)


@pytest.fixture
def served(monkeypatch) -> Iterator[callable]:
    """``open(scene)`` -> a session of ``scene`` with a browser connected, whose frames
    the test runs."""
    made: list[Session] = []
    monkeypatch.setattr(Session, "start", lambda self: made.append(self))
    apps: list[web_app.App] = []
    stop = threading.Event()

    def open_scene(scene: str) -> Session:
        made.clear()
        app = web_app.start(scene, port=0, open_message=False)
        apps.append(app)
        # the capacity's first measure (a session of its own for 2 s) is not counted
        assert wait_for(lambda: app.classroom.first is not None, timeout=30)
        url, origin = f"ws://127.0.0.1:{app.port}", f"http://127.0.0.1:{app.port}"

        async def read() -> None:
            stats = classroom.ClientStats(0)
            task = asyncio.create_task(
                classroom.run_client(
                    url, stats, classroom.Window(), origin=origin, param=None, play=False
                )
            )
            while not stop.is_set():
                await asyncio.sleep(0.05)
            task.cancel()

        threading.Thread(target=asyncio.run, args=(read(),), daemon=True).start()
        assert wait_for(lambda: len(made) == 1, timeout=30)
        return made[0]

    yield open_scene
    stop.set()
    for app in apps:
        app.stop()


def _count(session: Session, monkeypatch) -> Counts:
    """Run :data:`WARMUP` then :data:`FRAMES` frames, counting."""
    counts = Counts()
    ctl = session.controller
    clock = Clock()
    ctl.clock = clock
    ctl.submit(Play())  # scenes that open paused are counted while they move
    buffer = session.view.client._websock_connection.get_message_buffer()
    real_prepare, real_support = generic.prepare, generic.support_torsor
    real_readouts = type(ctl.sim).readouts

    def prepare(*args, **kwargs):
        counts.prepares += 1
        return real_prepare(*args, **kwargs)

    def support(*args, **kwargs):
        counts.supports += 1
        return real_support(*args, **kwargs)

    def readouts(self, *args, **kwargs):
        counts.readout_calls += 1
        return real_readouts(self, *args, **kwargs)

    real_put = PerModel.put

    def put(self, *args, **kwargs):
        counts.revolutions += 1
        return real_put(self, *args, **kwargs)

    monkeypatch.setattr(PerModel, "put", put)
    real_inverse = imposed_module.inverse_dynamics

    def inverse(*args, **kwargs):
        counts.inverse += 1
        return real_inverse(*args, **kwargs)

    monkeypatch.setattr(imposed_module, "inverse_dynamics", inverse)
    monkeypatch.setattr(generic, "prepare", prepare)
    monkeypatch.setattr(generic, "support_torsor", support)
    monkeypatch.setattr(torsors, "support_torsor", support)  # the scenes' revolutions
    monkeypatch.setattr(simulation_module.Simulation, "readouts", readouts)
    render = session.view.render
    seen: list[session_module.Frame] = []
    monkeypatch.setattr(session.view, "render", lambda frame: (seen.append(frame), render(frame)))
    for i in range(WARMUP + FRAMES):
        if i == WARMUP:
            counts.prepares = counts.supports = counts.readout_calls = counts.revolutions = 0
            counts.inverse = 0
        # as a browser's frames are paced: its sender has taken the previous frame
        assert wait_for(lambda: session.view.draws, timeout=5, poll=0.001)
        before = buffer.message_counter
        clock.now += 1 / 60
        session.run_once(clock.now)
        if i < WARMUP:
            continue
        sent = buffer.message_counter - before
        frame = seen[-1]
        counts.frames += 1
        counts.pictures += frame.picture is not None
        if frame.readouts is not None:
            counts.panel_ticks += 1
            counts.panel_messages.append(sent)
        else:
            counts.messages.append(sent)
    return counts


@pytest.mark.slow  # a server per scene: ~1 s each
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_a_drawn_frame_sends_only_what_moved_and_evaluates_once(scene, served, monkeypatch):
    session = served(scene)
    model = session.controller.sim.model
    groups = len(body_groups(model)[0])
    arrows = len(SCENES[scene].page.arrows)
    counts = _count(session, monkeypatch)
    assert counts.frames == FRAMES and not session.controller.diverged
    # every frame draws a new state, computed once (one picture, one forward pass)
    assert counts.pictures == FRAMES
    assert counts.prepares <= FRAMES + counts.panel_ticks // 10, counts
    # the frame's forces are computed once, for the arrows and the readouts alike
    if arrows:  # (a revolution simulated ahead samples at most 64 angles of its own)
        assert counts.supports <= FRAMES + counts.panel_ticks // 10 + 65 * counts.revolutions
    # readouts: once a panel refresh (10 a second), never at the frame rate
    assert 15 <= counts.panel_ticks <= 25
    assert counts.readout_calls <= counts.panel_ticks, counts
    # a revolution simulated ahead serves every reading while nothing changes (the one
    # simulated as the session started is simulated once more when it has settled)
    assert counts.revolutions <= 1, counts
    # an imposed motion is solved once a frame, at the instant drawn (the physics step
    # only places the mechanism): a revolution placed ahead adds its own 64 angles
    assert counts.inverse <= FRAMES + 65 * counts.revolutions, counts
    # messages of a drawn frame: a position and an orientation per moving group at most,
    # one message for every arrow, and one per point the arrows start from (its labels
    # ride on it; their texts change a few times a second, at the panels' refresh)
    points = len({a.point or a.name for a in SCENES[scene].page.arrows})
    per_frame = max(counts.messages)
    assert per_frame <= 2 * groups + 1 + points, (scene, counts.messages)
    # on average a frame sends what moves: far fewer than one message per geom
    assert np.mean(counts.messages) <= 2 * groups + 1 + points
    assert np.mean(counts.messages) < model.ngeom + 2 * arrows
    # a panel refresh (tables, plots, status, labels) stays a few dozen messages
    assert max(counts.panel_messages) <= 60, counts.panel_messages


def test_a_still_scene_sends_nothing(served):
    """Paused, nothing moves: no picture, and no message at the frame rate; the panels'
    refreshes, whose tables do not change, send next to nothing."""
    session = served("rotor")
    ctl = session.controller
    clock = Clock()
    ctl.clock = clock
    buffer = session.view.client._websock_connection.get_message_buffer()
    ctl.submit(Pause())
    for _ in range(20):  # the pause, then the status line and buttons saying it
        assert wait_for(lambda: session.view.draws, timeout=5, poll=0.001)
        clock.now += 1 / 60
        session.run_once(clock.now)
    quiet, pictures = [], 0
    render = session.view.render

    def counted(frame):
        nonlocal pictures
        pictures += frame.picture is not None
        render(frame)

    session.view.render = counted
    for _ in range(60):
        assert wait_for(lambda: session.view.draws, timeout=5, poll=0.001)
        before = buffer.message_counter
        clock.now += 1 / 60
        session.run_once(clock.now)
        quiet.append(buffer.message_counter - before)
    assert pictures == 0
    assert sum(quiet) <= 6, quiet


def test_a_browser_still_sending_its_last_frame_gets_no_new_one(served):
    """A slow link: the session skips drawing while its browser's sender holds
    IN_FLIGHT frames (viser would merge them), then draws again once it has caught up."""
    session = served("rotor")
    ctl = session.controller
    clock = Clock()
    ctl.clock = clock
    view = session.view
    real = wire.sent_marks
    stuck = [False]
    pictures = []
    render = view.render
    view.render = lambda frame: (pictures.append(frame.picture is not None), render(frame))

    def marks(client):
        got = real(client)
        return (got[0], -1) if got is not None and stuck[0] else got  # nothing taken

    try:
        wire.sent_marks = marks
        stuck[0] = True
        for _ in range(10):
            clock.now += 1 / 60
            session.run_once(clock.now)
        # IN_FLIGHT frames go while nothing is taken; then none until the sender catches up
        assert all(pictures[:IN_FLIGHT]) and not any(pictures[IN_FLIGHT:]) and not view.draws
        # ... or until MAX_HELD has passed: a browser is never left without its 3D view
        clock.now += MAX_HELD + 0.1
        assert view.draws
        stuck[0] = False
        assert wait_for(lambda: view.draws, timeout=5)
        clock.now += 1 / 60
        session.run_once(clock.now)
        assert pictures[-1]  # drawn again, at the current state
    finally:
        wire.sent_marks = real
