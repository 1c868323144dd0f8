"""The process's one loop thread: it runs the frames of every session, earliest due first,
on ticks shared by the sessions of one rate.
"""

from __future__ import annotations

import heapq
import logging
import math
import threading
import time
from collections.abc import Callable
from typing import Protocol

from sandbox.web.loop.governor import Governor

log = logging.getLogger(__name__)

IDLE_EXIT = 5.0
"""Seconds without any session after which the scheduler's thread ends."""


class Turns(Protocol):
    """What the scheduler runs: a session's turns at its rate (a
    :class:`~sandbox.web.loop.session.Session`). ``_turn`` and ``_end`` are the
    scheduler's hooks, called by nothing else."""

    period: float
    """Seconds between two turns [s]."""

    @property
    def stopping(self) -> bool:
        """True once the session was asked to stop (its next turn drops it)."""

    def _turn(self, now: float) -> bool:
        """One frame unless the session must end; False to drop it."""

    def _end(self) -> None:
        """Called once the session is dropped."""


def tick(now: float, period: float) -> float:
    """The first instant at or after ``now`` that is a whole number of ``period``: every
    session of one rate shares the same ticks, so the scheduler runs their frames in one
    burst per tick and sleeps between bursts (a core woken for every frame spends more
    on waking than on the frame: 1.4 ms instead of 0.13 ms measured for a rotor's)."""
    if not (period > 0 and math.isfinite(now)):
        return now
    return math.ceil(now / period - 1e-9) * period


class Scheduler:
    """One thread that runs the frames of every session of the process, earliest due first.

    One thread instead of one per browser: with thirty browsers, thirty threads waking
    sixty times a second spend more time handing the interpreter lock to each other
    than drawing. When the frames cost more than the machine has, the :attr:`governor`
    lowers every session's frame rate alike (each is served in turn, none starves) and
    each frame steps the wall time that passed: simulated time does not slow down.

    Args:
        clock: Wall clock [s] (monotonic) deciding when frames are due.
        threaded: Run the frames in the scheduler's own thread; False leaves it to
            :meth:`run_due` (tests drive it with a fake clock, without sleeping).
    """

    _shared: Scheduler | None = None
    _shared_lock = threading.Lock()

    def __init__(
        self, *, clock: Callable[[], float] = time.perf_counter, threaded: bool = True
    ) -> None:
        self.clock = clock
        self.threaded = threaded
        self._cond = threading.Condition()
        self._heap: list[tuple[float, int, Turns]] = []
        self._seq = 0
        self._thread: threading.Thread | None = None
        self.governor = Governor(clock=clock)
        """The frame rate every session runs at, at most its own."""

    @classmethod
    def shared(cls) -> Scheduler:
        """The process's scheduler (made on first use)."""
        with cls._shared_lock:
            if cls._shared is None:
                cls._shared = cls()
            return cls._shared

    def add(self, session: Turns) -> None:
        """Run ``session``'s frames from now on."""
        with self._cond:
            self._seq += 1
            heapq.heappush(self._heap, (tick(self.clock(), session.period), self._seq, session))
            if not self.threaded:
                return
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(
                    target=self._run, name="sandbox-sessions", daemon=True
                )
                self._thread.start()
            self._cond.notify()

    def wake(self) -> None:
        """Let the loop look at its sessions now (one was asked to stop)."""
        with self._cond:
            for i, (due, seq, session) in enumerate(self._heap):
                if session.stopping and due > 0:
                    self._heap[i] = (0.0, seq, session)
            heapq.heapify(self._heap)
            self._cond.notify()

    def in_loop(self) -> bool:
        """True when called from the scheduler's own thread."""
        return threading.current_thread() is self._thread

    def next_due(self) -> float | None:
        """When the earliest session is due [s on :attr:`clock`], None with no session."""
        with self._cond:
            return self._heap[0][0] if self._heap else None

    @property
    def sessions(self) -> int:
        """Sessions being served."""
        with self._cond:
            return len(self._heap)

    def run_due(self) -> int:
        """Run, in the calling thread, every frame due by :attr:`clock` (each session at
        most once); returns how many ran. For a scheduler made with ``threaded=False``."""
        with self._cond:
            due_now = self._pop_due()
        self._burst(due_now)
        return len(due_now)

    def _pop_due(self) -> list[tuple[float, int, Turns]]:
        """Every entry due by now, earliest first (the caller holds the condition)."""
        now = self.clock()
        due_now = []
        while self._heap and self._heap[0][0] <= now:
            due_now.append(heapq.heappop(self._heap))
        return due_now

    def _burst(self, due_now: list[tuple[float, int, Turns]]) -> None:
        """Serve the sessions due at one tick, in turn, and tell the governor what it
        took. (Holding every browser's messages until the last frame of the burst was
        measured: viser's sending thread, woken only between bursts, then coalesced
        frames and the class got fewer of them.)"""
        if not due_now:
            self.governor.update(sessions=self._driving(), served=self.sessions)
            return
        start, cpu = self.clock(), time.thread_time()
        stepping, held = 0.0, 0
        for due, seq, session in due_now:
            before = float(getattr(session, "stepping_cpu", 0.0))
            was = int(getattr(session, "held", 0))
            self._serve(due, seq, session)
            stepping += float(getattr(session, "stepping_cpu", 0.0)) - before
            held += int(getattr(session, "held", 0)) - was
        end = self.clock()
        self.governor.spent(
            end - start, time.thread_time() - cpu, len(due_now), stepping, held=held
        )
        self.governor.update(end, sessions=self._driving(), served=self.sessions)

    def _driving(self) -> int:
        """Sessions stepping a simulation of their own (not a view of another's)."""
        with self._cond:
            return sum(1 for _, _, s in self._heap if getattr(s, "drive", False))

    def _run(self) -> None:
        while True:
            with self._cond:
                while True:
                    if not self._heap:
                        if not self._cond.wait(IDLE_EXIT):
                            self._thread = None  # idle: the thread ends, add() restarts it
                            return
                        continue
                    delay = self._heap[0][0] - self.clock()
                    if delay <= 0:
                        due_now = self._pop_due()
                        break
                    self._cond.wait(delay)
            self._burst(due_now)

    def _serve(self, due: float, seq: int, session: Turns) -> None:
        """One turn of ``session``, then its next frame is due one period later."""
        now = self.clock()
        try:
            keep = session._turn(now)
        except Exception:  # never lose the loop to one session
            log.exception("session turn failed")
            keep = True
        if not keep:
            try:
                session._end()
            except Exception:  # the loop serves every other page: it outlives this one
                log.exception("session end failed")
            return
        after = self.clock()
        period = self.governor.period_of(session.period)
        following = due + period
        if following < after:  # late: the next tick of its rate, behind those waiting
            following = tick(after, period)
        with self._cond:
            heapq.heappush(self._heap, (following, seq, session))
