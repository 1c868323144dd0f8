"""The parameter studies of every browser a server holds, run in the background below the
live sessions (folder "Étude paramétrique").

One queue per server process, shared by all its browsers. Runs go to a small pool of
worker processes whose priority is lowered (``nice`` 19 on Linux and macOS, "below normal"
on Windows through psutil), so that a study only takes the CPU the live sessions leave:
a class keeps its frame rate while some students run studies. The queue is bounded (runs
waiting in all), a browser has one study at a time, and studies take turns run by run
(one long study does not hold back a short one that came later). The pool is started
for the first study and shut down once nothing is left to run: a finished or cancelled
study leaves no process behind.

No viser here: the panel (:mod:`sandbox.web.panels.study`) submits jobs and reads them.
"""

from __future__ import annotations

import atexit
import functools
import logging
import threading
import time
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from typing import Any

from sandbox.sweep import Study, run_one
from sandbox.web.loop.background import NICE, BackgroundPool, lower_priority

__all__ = ["NICE", "StudyJob", "StudyQueue", "lower_priority", "progress_words"]

log = logging.getLogger(__name__)

WORKERS = 1
"""Processes running studies: one core's worth at a low priority (a 2-core laptop keeps
the other for its live sessions, and lends the first when they leave it idle)."""

MAX_WAITING = 400
"""Runs waiting in all the server's studies; a study that would pass it is refused."""

IN_FLIGHT = 2
"""Runs handed to the pool ahead (one running per process, one waiting): a cancelled
study stops within a run or two."""


class StudyJob:
    """One browser's study: its runs, the rows as they come, its state.

    Args:
        study: The checked study.
        points: Its grid (see :meth:`~sandbox.sweep.Study.points`).
        x: What its chart puts on the horizontal axis instead of the first parameter
            (words, function of a run's values): a preset's, e.g. R/L.
    """

    def __init__(
        self,
        study: Study,
        points: list[dict[str, float]],
        *,
        x: tuple[str, Callable[[Mapping[str, float]], float]] | None = None,
    ) -> None:
        self.study = study
        self.x = x
        self.points = points
        self.rows: list[dict[str, Any] | None] = [None] * len(points)
        self.done = 0
        self.failed = 0  # runs that raised (counted as done, row None)
        self.cancelled = False
        self.started = time.monotonic()
        self.ended: float | None = None
        self._next = 0  # index of the next run to hand out

    @property
    def total(self) -> int:
        """Runs in the study."""
        return len(self.points)

    @property
    def finished(self) -> bool:
        """Every run came back, or the study was cancelled."""
        return self.cancelled or self.done >= self.total

    def pending(self) -> int:
        """Runs not yet handed to the pool."""
        return 0 if self.cancelled else self.total - self._next


class StudyQueue:
    """The server's studies and the pool that runs them.

    Args:
        workers: Processes of the pool.
        max_waiting: Runs that may wait in all.
        run: The function of one run (``sweep.run_one``; a test may count its calls).
    """

    _shared: StudyQueue | None = None
    _shared_lock = threading.Lock()

    def __init__(
        self,
        workers: int = WORKERS,
        max_waiting: int = MAX_WAITING,
        run: Callable[[Study, dict[str, float]], dict[str, Any]] = run_one,
    ) -> None:
        self.workers = workers
        self.max_waiting = max_waiting
        self.run = run
        self.jobs: list[StudyJob] = []
        self._pool = BackgroundPool(workers)
        self._in_flight = 0
        self._turn = 0
        self._closed = False
        self._lock = threading.RLock()

    @classmethod
    def shared(cls) -> StudyQueue:
        """The queue of this server process (a new one after :meth:`close`)."""
        with cls._shared_lock:
            if cls._shared is None or cls._shared._closed:
                cls._shared = cls()
            return cls._shared

    # -- from the panels (viser's threads) -----------------------------------------------
    def submit(self, job: StudyJob) -> None:
        """Queue ``job``'s runs (they start at once when the pool is free).

        Raises:
            OverflowError: the server's queue is full (the panel says it in French).
        """
        with self._lock:
            if self._closed:
                raise OverflowError("the server is stopping")
            if self.waiting() + job.total > self.max_waiting:
                raise OverflowError(f"{self.waiting()} runs already wait")
            self.jobs.append(job)
            self._feed()

    def cancel(self, job: StudyJob) -> None:
        """Stop ``job``: its runs not started are dropped, those running are ignored."""
        with self._lock:
            job.cancelled = True
            job.ended = job.ended or time.monotonic()
            self._forget_finished()

    def waiting(self) -> int:
        """Runs of every study not yet handed to the pool."""
        with self._lock:
            return sum(j.pending() for j in self.jobs)

    def ahead_of(self, job: StudyJob) -> int:
        """Runs of other studies waiting (those taking turns with ``job``'s)."""
        with self._lock:
            return sum(j.pending() for j in self.jobs if j is not job)

    @property
    def processes(self) -> int:
        """Worker processes alive now (0 when no study runs)."""
        return self._pool.processes

    def close(self) -> None:
        """Cancel every study and stop the pool (the server stops)."""
        with self._lock:
            self._closed = True
            for job in self.jobs:
                job.cancelled = True
            self.jobs.clear()
            self._pool.stop()

    # -- inside ----------------------------------------------------------------------------
    def _feed(self) -> None:
        """Hand runs to the pool, studies taking turns, while fewer than
        :data:`IN_FLIGHT` × workers are in it."""
        while self._in_flight < IN_FLIGHT * self.workers:
            active = [j for j in self.jobs if j.pending() > 0]
            if not active:
                break
            job = active[self._turn % len(active)]
            self._turn += 1
            k = job._next
            job._next += 1
            future = self._pool.submit(self.run, job.study, job.points[k])
            self._in_flight += 1
            future.add_done_callback(functools.partial(self._done, job, k))

    def _done(self, job: StudyJob, k: int, future: Future[dict[str, Any]]) -> None:
        with self._lock:
            self._in_flight -= 1
            if not job.cancelled:
                try:
                    job.rows[k] = future.result()
                except Exception as exc:  # a run that fails is a gap, the study goes on
                    job.failed += 1
                    log.warning("a study's run failed: %s: %s", type(exc).__name__, exc)
                job.done += 1
                if job.done >= job.total:
                    job.ended = time.monotonic()
            if not self._closed:
                self._feed()
            self._forget_finished()

    def _forget_finished(self) -> None:
        self.jobs = [j for j in self.jobs if not j.finished]
        if not self.jobs and self._in_flight == 0:
            self._pool.stop()


def progress_words(job: StudyJob, ahead: int) -> str:
    """The study's state for the page, in French."""
    if job.cancelled:
        return f"Étude annulée : {job.done} simulations sur {job.total} faites."
    if job.finished:
        seconds = (job.ended or time.monotonic()) - job.started
        failed = f", {job.failed} en échec" if job.failed else ""
        return (
            f"Étude terminée : {job.total} simulations en "
            f"{str(round(seconds, 1)).replace('.', ',')} s{failed}."
        )
    share = f" (à tour de rôle avec {ahead} simulations d'autres élèves)" if ahead else ""
    return f"{job.done} simulations sur {job.total} faites{share}."


def _close_shared() -> None:
    queue = StudyQueue._shared
    if queue is not None:
        queue.close()


atexit.register(_close_shared)
