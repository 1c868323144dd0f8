"""One headless client of the classroom benchmark: what it saw (:class:`ClientStats`,
counted inside the measurement :class:`Window`) and the browser it plays
(:func:`run_client`): connect, send the camera, press « Lecture » when the scene opens
paused, pick a readout folder, and toggle a parameter slider every :data:`PROBE_PERIOD` s,
timing each change until it shows.
"""

from __future__ import annotations

import asyncio
import itertools
import math
import random
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from sandbox.bench.classroom.browser import (
    camera_message,
    connect_as_browser,
    gui_message,
    slider_message,
)
from sandbox.bench.classroom.wire import (
    BIG_MESSAGE,
    TYPE_MARKER,
    find_gui,
    find_slider,
    is_update_frame,
    shows_rebuild,
    status_time,
    unpack,
)

if TYPE_CHECKING:
    from websockets.asyncio.client import ClientConnection


PROBE_PERIOD = 5.0
"""Seconds between two slider changes of one client."""

PANEL_PICKER = "Panneau affiché"
"""Label of the dropdown choosing the one readout folder shown (``panel=`` option)."""

TIME_BUTTONS = "Temps"
"""Label of the control panel's button group (Lecture/Pause, Pas, Réinitialiser)."""
PLAY = "Lecture"
"""The button that starts a scene that opens paused (the bench presses it, as a student
would, so that every scene is measured while it moves)."""
PAUSED = b"**en pause**"
"""What the status line says of a paused simulation (UTF-8, as on the wire)."""


@dataclass
class Window:
    """Measurement window on the ``time.perf_counter`` clock [s]."""

    start: float = math.inf
    end: float = math.inf

    def __contains__(self, now: float) -> bool:
        return self.start <= now < self.end


@dataclass
class ClientStats:
    """What one headless client saw; counts are inside the window only."""

    index: int
    first_frame: float | None = None  # perf_counter of the first update frame
    received: int = 0  # server messages, window or not
    last_frame: float | None = None  # perf_counter of the latest update frame
    max_gap: float = 0.0  # longest wait between two update frames in the window [s]
    big: int = 0  # messages of BIG_MESSAGE bytes or more in the window
    max_bytes: int = 0  # largest message in the window [bytes]
    error: str | None = None
    frames: int = 0
    frame_times: list[float] = field(default_factory=list)  # perf_counter, in the window
    ws_messages: int = 0
    viser_messages: int = 0
    wire_bytes: int = 0
    times: list[tuple[float, float]] = field(default_factory=list)  # (wall, sim) [s]
    delays: list[float] = field(default_factory=list)  # slider -> frame [s]
    not_shown: int = 0
    slider: dict[str, Any] | None = None
    picker: dict[str, Any] | None = None  # the panel dropdown, once chosen
    buttons: str | None = None  # uuid of the "Temps" button group, once seen
    played: bool = False  # "Lecture" pressed (the scene opened paused)
    pending: float | None = None  # perf_counter of the unshown slider change
    port: int | None = None  # local port of its connection (tells its server process)

    def feed(self, raw: bytes, now: float, window: Window) -> None:
        """Account for one server message received at ``now``."""
        inner = unpack(raw)
        self.received += 1
        frame = is_update_frame(inner)
        if frame and self.first_frame is None:
            self.first_frame = now
        if self.pending is not None and shows_rebuild(inner):
            self.delays.append(now - self.pending)
            self.pending = None
        if now in window:
            self.ws_messages += 1
            self.wire_bytes += len(raw)
            self.big += len(raw) >= BIG_MESSAGE
            self.max_bytes = max(self.max_bytes, len(raw))
            if frame and self.last_frame is not None:
                self.max_gap = max(self.max_gap, now - max(self.last_frame, window.start))
            self.viser_messages += inner.count(TYPE_MARKER)
            self.frames += frame
            if frame:
                self.frame_times.append(now)
            t = status_time(inner)
            if t is not None:
                self.times.append((now, t))
        if frame:
            self.last_frame = now

    def longest_gap(self, window: Window) -> float:
        """Longest time without an update frame inside the window, its end included [s]."""
        last = max(self.last_frame or window.start, window.start)
        return max(self.max_gap, window.end - min(last, window.end))

    def fps(self, window: Window) -> float:
        """Update frames per second over the window [1/s]."""
        return self.frames / (window.end - window.start)

    def sim_rate(self) -> float:
        """Simulated seconds per wall second seen in the status line (NaN if < 2 samples).
        A scene that starts its run again (the rolling cylinder past the plane's end: its
        time back to 0) is measured between its restarts (the two samples around one are
        left out: the end of the old run is not seen)."""
        pairs = [(w1 - w0, t1 - t0) for (w0, t0), (w1, t1) in itertools.pairwise(self.times)]
        wall = sum(w for w, t in pairs if t >= 0)
        return sum(t for _, t in pairs if t >= 0) / wall if wall > 0 else math.nan


async def run_client(
    url: str,
    stats: ClientStats,
    window: Window,
    *,
    origin: str,
    param: str | None,
    seed: int = 0,
    watchers: Sequence[ClientStats] | None = None,
    panel: str | None = None,
    play: bool = True,
) -> None:
    """One browser: connect, send the camera, read until cancelled, probe a slider.

    Args:
        url: ``ws://127.0.0.1:P`` (``/prof/<token>`` appended for the teacher).
        stats: Filled in place.
        window: Measurement window (frames and probes count inside it only).
        origin: ``Origin`` header, as a browser on the page would send.
        param: Parameter slider to toggle, or None for no probe.
        seed: Seeds the probe's start offset.
        watchers: Clients whose view should show the slider change (default this one).
        panel: Readout folder to pick in the :data:`PANEL_PICKER` dropdown, as a
            student would (None: the page's default).
        play: Press « Lecture » when the simulation shows paused (a scene that opens
            paused is measured while it moves).
    """
    try:
        async with connect_as_browser(url, origin, open_timeout=30) as ws:
            stats.port = _local_port(ws)
            await ws.send(camera_message())
            prober = None
            if param is not None:
                watch = [stats] if watchers is None else list(watchers)
                prober = asyncio.create_task(_probe(ws, stats, window, random.Random(seed), watch))
            try:
                async for raw in ws:
                    assert isinstance(raw, bytes)
                    if stats.received < 200:
                        if stats.buttons is None:
                            found = find_gui(unpack(raw), "ButtonGroup", TIME_BUTTONS)
                            stats.buttons = None if found is None else str(found["uuid"])
                        paused = stats.buttons is not None and PAUSED in unpack(raw)
                        if play and paused and not stats.played and stats.buttons is not None:
                            stats.played = True  # the scene opened paused: press "Lecture"
                            await ws.send(gui_message(stats.buttons, PLAY))
                        if param is not None and stats.slider is None:
                            stats.slider = find_slider(unpack(raw), param)
                        if panel is not None and stats.picker is None:
                            stats.picker = find_gui(unpack(raw), "Dropdown", PANEL_PICKER)
                            if stats.picker is not None:
                                await ws.send(gui_message(stats.picker["uuid"], panel))
                    stats.feed(raw, time.perf_counter(), window)
            finally:
                if prober is not None:
                    prober.cancel()
    except asyncio.CancelledError:
        raise
    except Exception as exc:  # reported per client, the bench goes on
        stats.error = f"{type(exc).__name__}: {exc}"


def _local_port(ws: Any) -> int | None:
    """The local port of a client connection (None when the transport does not say)."""
    address = getattr(ws, "local_address", None)
    return int(address[1]) if isinstance(address, tuple) and len(address) >= 2 else None


async def _probe(
    ws: ClientConnection,
    stats: ClientStats,
    window: Window,
    rng: random.Random,
    watchers: Sequence[ClientStats],
) -> None:
    """Toggle ``stats.slider`` every :data:`PROBE_PERIOD` s; each of ``watchers`` then
    waits for the change to show (its ``pending`` is the send time)."""
    while not math.isfinite(window.start) or stats.slider is None:
        await asyncio.sleep(0.1)
    slider = stats.slider
    low = float(slider["value"])
    props = slider["props"]
    span = float(props["max"]) - float(props["min"])
    high = low + 0.25 * span if low + 0.25 * span <= float(props["max"]) else low - 0.25 * span
    on = False
    next_at = window.start + rng.uniform(0.0, PROBE_PERIOD)
    while next_at < window.end - 0.5:
        await asyncio.sleep(max(0.0, next_at - time.perf_counter()))
        on = not on
        sent = time.perf_counter()
        for w in watchers:
            w.not_shown += w.pending is not None
            w.pending = sent
        await ws.send(slider_message(slider["uuid"], high if on else low))
        next_at += PROBE_PERIOD
    await asyncio.sleep(max(0.0, window.end - time.perf_counter()))
    for w in watchers:
        w.not_shown += w.pending is not None
        w.pending = None
