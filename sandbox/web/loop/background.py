"""Work a server process hands to other processes below its live sessions: parameter
studies (:mod:`sandbox.web.loop.study_queue`) and videos (:mod:`sandbox.web.video.export`).

A :class:`BackgroundPool` starts its worker processes (spawned: no fork of a threaded
server) at the lowest priority only when the first job comes, and its owner stops it
once nothing is left to run, so idle pages leave no process behind.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from multiprocessing import get_context
from typing import Any, TypeVar

log = logging.getLogger(__name__)

NICE = 19
"""How much lower the study and video processes run on Linux and macOS (0 normal, 19
lowest): at 10, 2 pages exporting videos took a class of 28 on the rotor from 51 to 45
frames/s; at 19 it kept 51 (``sandbox bench --classroom 30 rotor --videos 2``)."""

T = TypeVar("T")


def lower_priority() -> None:
    """Lower this process's CPU priority (a worker's initializer): ``os.nice`` where it
    exists (Linux, macOS), else psutil's "below normal" class (Windows); nothing, with a
    log line, when neither is available."""
    if hasattr(os, "nice"):
        try:
            os.nice(NICE)
        except OSError:  # already at the lowest, or not allowed
            log.debug("could not lower the background process's priority", exc_info=True)
        return
    try:
        import psutil  # optional here: a Windows laptop without it runs studies unlowered
    except ImportError:
        log.info("studies run at normal priority: pip install psutil to lower it")
        return
    psutil.Process().nice(getattr(psutil, "BELOW_NORMAL_PRIORITY_CLASS", NICE))


class BackgroundPool:
    """Worker processes at the lowest priority, started by the first :meth:`submit` and
    ended by :meth:`stop` (the owner knows when nothing is left; not thread-safe: the
    owner holds its lock around both).

    Args:
        workers: How many processes.
    """

    def __init__(self, workers: int = 1) -> None:
        self.workers = workers
        self._pool: ProcessPoolExecutor | None = None

    def submit(self, fn: Callable[..., T], *args: Any) -> Future[T]:
        """Run ``fn(*args)`` in a worker (starting the processes if none runs)."""
        if self._pool is None:
            self._pool = ProcessPoolExecutor(
                max_workers=self.workers,
                mp_context=get_context("spawn"),
                initializer=lower_priority,
            )
        return self._pool.submit(fn, *args)

    def stop(self) -> None:
        """End the processes (without waiting; jobs not started are dropped)."""
        pool, self._pool = self._pool, None
        if pool is not None:
            pool.shutdown(wait=False, cancel_futures=True)

    @property
    def processes(self) -> int:
        """Worker processes alive now (0 when stopped)."""
        pool = self._pool
        procs = getattr(pool, "_processes", None) if pool is not None else None
        return sum(1 for p in (procs or {}).values() if p.is_alive())
