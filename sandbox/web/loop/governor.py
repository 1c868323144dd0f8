"""The frame rate of a process's sessions: lowered evenly when the machine gives the loop
less than its frames cost, raised again when it gives more; simulated time never slows.

A laptop that also drives a projector and a video call, or a class larger than it holds,
gives the loop thread less CPU than thirty sessions at 60 frames/s need. Without a
governor, the frames of every session come late together and each catches up by
stepping more, until a frame's step budget or the pacing's lag limit holds the motion
back: every student's simulation in slow motion, teaching wrong times and speeds. The
:class:`Governor` instead measures, over windows of :data:`WINDOW` seconds, the share of
wall time the loop spends running frames (a busy machine makes the same frames take
longer) and the frames each session got. When the loop is busy nearly all the time and
the sessions got fewer frames than asked, it asks every session for what they got (one
rate for all: even frames), a little less while that stays so, down to
:data:`FLOOR_FPS`; when the loop has time to spare again it raises the rate, up to the
sessions' own. Each frame then steps the simulated time the wall clock says
(:class:`~sandbox.web.loop.pacing.Pacing` gives a frame a step budget in proportion to
its length).

Below the floor the process is :attr:`Governor.saturated`: its new students follow the
teacher's projected simulation instead of getting one of their own
(:mod:`sandbox.web.serving.class_app`).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

from sandbox.web.loop.capacity import Load
from sandbox.web.loop.frame import FPS

FLOOR_FPS = 15.0
"""The lowest frame rate a session is lowered to [Hz]: below it a motion no longer looks
continuous (a crank at 50 turns a second is sampled anyway, stroboscopically)."""

WINDOW = 1.0
"""Seconds of wall time over which the loop's busy share is measured."""

TARGET = 0.93
"""Share of wall time the loop thread should spend running frames: the rest is the
websocket's sending thread's (it needs the interpreter too) and a margin for bursts.
Measured on the classroom benchmark: thirty engines at the frame rate the machine gives
kept the loop busy 0.80 to 0.85 of the time; with another program on one core it was
busy 0.96 of the time and the frames came unevenly (30 to 38 a second)."""

HIGH = 0.97
"""A busy share above this lowers the frame rate."""

LOW = 0.85
"""A busy share below this raises it again."""

KEPT_UP = 0.95
"""A session given this share of its frames per second is kept up with: a busy loop that
keeps up needs no lower rate (on a machine shared with another program the loop seems
busy all the time, the operating system handing its core to the other in turns)."""

HELD = 0.1
"""Share of a window's frames held back for their browsers' senders (a session draws
nothing while its sender still holds three frames) beyond which the sending, not the
loop, is what is short: the rate is lowered all the same, evenly, rather than leaving
each browser the frames its turn in the sending thread happens to give it."""

RAISE = 1.25
"""Largest factor one window raises the frame rate by (a quick fall, a slow climb: a
class that just connected costs more for a few seconds than it will)."""

SATURATED_AFTER = 3
"""Windows in a row at the floor and still over :data:`HIGH` before the process says it
is saturated (a one-second burst, a model rebuild, is not)."""


class Governor:
    """One frame rate for every session of a process.

    Args:
        clock: Wall clock [s] (monotonic), replaceable in tests.
        top: The sessions' own frame rate [Hz] (never exceeded).
        floor: The lowest rate [Hz].
        process_time: CPU seconds of the whole process (every thread), replaceable in
            tests.
    """

    def __init__(
        self,
        *,
        clock: Callable[[], float],
        top: float = FPS,
        floor: float = FLOOR_FPS,
        process_time: Callable[[], float] = time.process_time,
    ) -> None:
        self.clock = clock
        self.process_time = process_time
        self.top = top
        self.floor = floor
        self.fps = top
        self.share = 0.0  # the busy share of the last window
        self.saturated = False
        self._busy = 0.0
        self._cpu = 0.0
        self._frames = 0
        self._stepping = 0.0
        self._held = 0
        self._since = clock()
        self._process = process_time()
        self.load = Load()
        """What the sessions cost over the last window (:mod:`~sandbox.web.loop.capacity`)."""
        self._over = 0  # windows in a row at the floor and over HIGH
        self._lock = threading.Lock()
        self.cpu_per_frame = math.nan  # loop CPU of a drawn frame in the last window [s]
        self.frames_per_second = 0.0  # frames run per wall second, every session summed
        self.given = float(top)  # frames per second a session got in the last window

    @property
    def scale(self) -> float:
        """The governed rate over the sessions' own (1: not lowered)."""
        return self.fps / self.top

    def period_of(self, period: float) -> float:
        """Seconds between two frames of a session whose own period is ``period``: its
        rate times :attr:`scale`, never below the floor because of the governor (a
        follower's slow loop keeps its own)."""
        own = 1.0 / period
        return 1.0 / max(min(own, self.floor), own * self.scale)

    def spent(
        self,
        wall: float,
        cpu: float = 0.0,
        frames: int = 0,
        stepping: float = 0.0,
        *,
        held: int = 0,
    ) -> None:
        """A burst of frames ran: ``wall`` seconds of wall time, ``cpu`` seconds of the
        loop thread's CPU (``stepping`` of them stepping simulations), ``frames`` frames,
        ``held`` of which drew nothing because their browser's sender still held frames
        (the websocket's thread, not the loop, was short)."""
        with self._lock:
            self._busy += max(wall, 0.0)
            self._cpu += max(cpu, 0.0)
            self._frames += frames
            self._stepping += max(stepping, 0.0)
            self._held += max(held, 0)

    def update(self, now: float | None = None, *, sessions: int = 0, served: int = 0) -> bool:
        """Move the frame rate once a window has passed; True when it moved.

        Args:
            now: Wall clock [s].
            sessions: Simulations of their own the process drives now (for :attr:`load`).
            served: Sessions the loop serves now, every kind (a loop busy all the time
                gave each of them its frames per second over this: the rate is lowered
                at once below what it could give).
        """
        now = self.clock() if now is None else now
        with self._lock:
            elapsed = now - self._since
            if elapsed < WINDOW:
                return False
            share = self._busy / elapsed
            cpu, frames, stepping, held = self._cpu, self._frames, self._stepping, self._held
            self._busy = self._cpu = self._stepping = 0.0
            self._frames = self._held = 0
            self._since = now
            process, self._process = self._process, self.process_time()
            process = self._process - process
        self.share = share
        self.frames_per_second = frames / elapsed
        if frames:
            self.cpu_per_frame = cpu / frames
        old = self.fps
        drawn = frames - held  # frames that reached their browser's sender
        given = drawn / elapsed / served if served > 0 else self.fps  # a session's frames
        self.given = given
        sending = frames > 0 and held > HELD * frames  # the websocket's thread is short
        if (share > HIGH or sending) and given < KEPT_UP * self.fps:
            # the loop, busy all the time, or the sending could not give the rate asked
            # for: ask for what was given (every session alike), a little less while so
            lowered = self.fps * (max(0.5, TARGET / share) if share > HIGH else 0.95)
            self.fps = max(self.floor, min(given, lowered))
        elif share < LOW and not sending and self.fps < self.top:
            self.fps = min(self.top, self.fps * min(RAISE, TARGET / max(share, 1e-3)))
        self._over = self._over + 1 if self.fps <= self.floor and share > HIGH else 0
        if self._over >= SATURATED_AFTER:
            self.saturated = True
        elif self.fps > self.floor:
            self.saturated = False
        self.load = Load(
            sessions=sessions,
            frames=frames / elapsed,
            cpu=max(process, 0.0) / elapsed,
            stepping=stepping / elapsed,
            fps=self.fps,
            saturated=self.saturated,
        )
        return self.fps != old
