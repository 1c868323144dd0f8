"""The capacity estimate before any student arrives: one session measured for two seconds
at the server's start.

With no student connected there is nothing to measure in the class itself, yet the
teacher wants to know, before the lesson, how many students the laptop will hold. A
session of the served scene runs its frames for :data:`SECONDS` in a thread of its own
(not the class's loop), drawing and reading what a page asks: its stepping and frame
costs are timed on this thread's CPU clock; sending a frame to a browser, which this
measure cannot do, is counted as :data:`SENDING` of building it. The estimate is rougher
than the live one (:mod:`~sandbox.web.loop.capacity`), which replaces it as soon as
students are connected.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Collection

from sandbox.web.loop.capacity import Load
from sandbox.web.loop.controller import Controller
from sandbox.web.loop.frame import EVERY, FPS, Frame, Notice
from sandbox.web.loop.session import Session

SECONDS = 2.0
"""Wall seconds the first estimate measures."""

PANEL_RATE = 10.0
"""Readout refreshes a second, as a page's panels ask for them [Hz]."""

SENDING = 0.5
"""Sending a frame (serialising, compressing, framing and writing the websocket) costs
about this share of building it: the classroom benchmark's profile of a worker serving
the rotor spent 29 % of its time in viser's sending loop, the rest in the frames."""


class _Page:
    """What a page asks of a session: a picture each frame, every readout ten times a
    second."""

    draws = True

    def __init__(self) -> None:
        self._last = -1.0

    def wants(self, now: float) -> Collection[str] | None:
        if now - self._last < 1.0 / PANEL_RATE:
            return None
        self._last = now
        return EVERY

    def render(self, frame: Frame) -> None:
        pass

    def notify(self, notice: Notice) -> None:
        pass


def measure(
    controller: Callable[[], Controller],
    *,
    seconds: float = SECONDS,
    sleep: Callable[[float], None] = time.sleep,
    stop: threading.Event | None = None,
) -> Load:
    """One session of the served scene, its frames run for ``seconds`` at the page's rate:
    what a student costs, as the :class:`~sandbox.web.loop.capacity.Load` of one session.

    Args:
        controller: Makes the session's controller (the served scene and options).
        seconds: Wall seconds measured.
        sleep: Waits between frames (replaceable in tests).
        stop: Ends the measure early when set (the server stops).
    """
    ctl = controller()
    page = _Page()
    session = Session(ctl, page)
    wall0, cpu0 = ctl.clock(), time.thread_time()
    frames = 0
    while ctl.clock() - wall0 < seconds and not (stop is not None and stop.is_set()):
        session.run_once()
        frames += 1
        sleep(max(0.0, frames / FPS - (ctl.clock() - wall0)))
    wall = max(ctl.clock() - wall0, 1e-9)
    loop = time.thread_time() - cpu0
    stepping = ctl.step_cpu_total
    cpu = stepping + (loop - stepping) * (1.0 + SENDING)
    return Load(
        sessions=1,
        frames=frames / wall,
        cpu=cpu / wall,
        stepping=stepping / wall,
        fps=FPS,
    )
