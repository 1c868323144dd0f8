"""Several server processes behind one address: every core serves its share of browsers.

``sandbox serve`` starts ``workers`` processes (spawned, so each has its own Python
interpreter and its own lock). Each runs a complete web app and owns the sessions of the
browsers it was handed. The parent listens on the address, hands every new connection to
the worker serving the fewest browsers (:class:`sandbox.web.serving.front.Front`, on every
platform), prints the address, restarts a worker that dies, and stops them all on Ctrl-C
or SIGTERM; a stopping worker closes its sessions, so recordings in progress are
finished, never lost.

A worker never outlives the parent, however the parent ends (``kill -9`` too): each
worker holds the reading end of a pipe whose only writer is the parent
(:func:`sandbox.web.serving.worker.watch_parent`); a worker's body is
:func:`sandbox.web.serving.worker.worker_main`.

The class board ("La classe" on the teacher's page) sees the students of every worker:
each worker puts its students' rows on the ``events`` queue once a second
(:class:`~sandbox.web.serving.worker.WorkerHub`), the parent merges them
(:class:`sandbox.web.serving.roster.Roster`) and sends the merged board, on a pipe of its own per
worker, to the workers that serve a teacher's page; a thread sends it
(:class:`BoardRelay`), so the parent's loop never waits on a worker.
"""

from __future__ import annotations

import contextlib
import logging
import math
import multiprocessing
import os
import queue
import signal
import socket
import threading
import time
from collections.abc import Iterator
from dataclasses import replace
from multiprocessing.process import BaseProcess
from multiprocessing.queues import Queue
from types import FrameType
from typing import Any

from sandbox.cores import DEFAULT_WORKERS_CAP as DEFAULT_WORKERS_CAP  # re-exported
from sandbox.cores import default_workers as default_workers  # re-exported
from sandbox.errors import BadOption
from sandbox.web.loop.capacity import Load
from sandbox.web.panels.board_rows import MAX_ROWS, REFRESH, SETTLE, Run, from_wire
from sandbox.web.serving.front import Front
from sandbox.web.serving.roster import Roster
from sandbox.web.serving.worker import Event, WorkerSpec, worker_main

log = logging.getLogger(__name__)

START_TIMEOUT = 60.0
"""Seconds a worker may take to import, build its first simulation and listen."""

STOP_TIMEOUT = 5.0
"""Seconds a worker gets to close its sessions before it is killed."""

LISTEN_BACKLOG = 128
"""Connections the kernel queues before the front accepts them (a class arriving at once)."""

MAX_RESTARTS = 5
"""Restarts of dead workers allowed per minute before the server gives up."""

GRACEFUL_SIGTERM = os.name == "posix"
"""SIGTERM lets a process clean up (POSIX); on Windows os.kill(pid, SIGTERM) is
TerminateProcess, an immediate kill: workers are then stopped through their lifeline."""

POLL = 0.1
"""Seconds the parent's loop waits for connections before it looks at its workers (their
restarts, the class board's rows: a student arriving reaches the teacher's board a tenth
of a second sooner than with a quarter)."""


class BoardRelay:
    """Sends the merged board to the workers that asked for it, from a thread of its own
    (a worker slow to read its pipe delays only its own board)."""

    def __init__(self) -> None:
        self._pipes: dict[int, Any] = {}
        self._pending: dict[int, object] = {}
        self._cv = threading.Condition()
        self._closed = False
        self._thread = threading.Thread(target=self._run, name="sandbox-board-out", daemon=True)
        self._thread.start()

    def replace(self, index: int, pipe: Any) -> None:
        """Worker ``index``'s (new) pipe; a previous one is closed."""
        with self._cv:
            old = self._pipes.get(index)
            self._pipes[index] = pipe
            self._pending.pop(index, None)
        if old is not None:
            old.close()

    def send(self, index: int, payload: object) -> None:
        """Send ``payload`` to worker ``index`` (replaces one not sent yet)."""
        with self._cv:
            self._pending[index] = payload
            self._cv.notify()

    def _run(self) -> None:
        while True:
            with self._cv:
                while not self._pending and not self._closed:
                    self._cv.wait()
                if self._closed:
                    return
                todo = [(self._pipes.get(k), p) for k, p in self._pending.items()]
                self._pending.clear()
            for pipe, payload in todo:
                if pipe is None:
                    continue
                try:
                    pipe.send(payload)
                except (OSError, ValueError):  # a worker gone: its restart gets a new pipe
                    log.debug("class board not sent", exc_info=True)

    def close(self) -> None:
        """Stop the thread and close the pipes."""
        with self._cv:
            self._closed = True
            self._cv.notify()
            pipes = list(self._pipes.values())
            self._pipes.clear()
        for pipe in pipes:
            pipe.close()


@contextlib.contextmanager
def _terminal_interrupts_ignored() -> Iterator[None]:
    """Start a worker with SIGINT ignored, as a process started in the background is: a
    Ctrl-C reaches every process of the terminal's group, and one landing while a worker
    still imports its modules printed a KeyboardInterrupt traceback through them. The
    parent stops its workers itself (SIGTERM, the lifeline); a worker's own handler is
    set once it serves (:func:`~sandbox.web.serving.server.run_forever`). No effect outside the main
    thread or where SIGINT dispositions are not inherited (Windows: the console's Ctrl-C
    is then the worker's own)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class WorkerPool:
    """The worker processes of one ``sandbox serve``.

    Args:
        spec: What every worker serves.
        workers: How many processes.
    """

    def __init__(self, spec: WorkerSpec, workers: int) -> None:
        if workers < 1:
            raise BadOption(f"--workers must be 1 or more, got {workers!r}")
        self.spec = spec
        self.count = workers
        self._ctx = multiprocessing.get_context("spawn")
        self._events: Queue[Event] = self._ctx.Queue()
        self.processes: dict[int, BaseProcess] = {}
        self._restarts: list[float] = []
        self.closed = self._ctx.Array("q", workers, lock=False)  # websockets closed, by worker
        self.pipes: dict[int, Any] = {}  # the front's end of each worker's pipe
        self.roster = Roster(time.time(), settle=SETTLE)  # the class board, merged
        self.relay = BoardRelay()  # ... sent to the workers serving a teacher
        self._teachers: set[int] = set()  # those workers
        self.run: Run | None = None  # the class's challenge
        self._told: set[int] = set()  # workers that know it
        self._who: tuple[object, ...] = ()  # who was on the board last sent, and when
        self._sent = -math.inf
        self._lifelines: dict[int, Any] = {}  # kept open while this process lives
        self.front: Front | None = None

    def _spawn(self, index: int) -> None:
        receiver, sender = self._ctx.Pipe(duplex=False)
        watched, lifeline = self._ctx.Pipe(duplex=False)
        board_in, board_out = self._ctx.Pipe(duplex=False)
        proc = self._ctx.Process(
            target=worker_main,
            args=(self.spec, index, self._events, receiver, self.closed, watched, board_in),
            name=f"sandbox-worker-{index}",
            daemon=False,
        )
        with _terminal_interrupts_ignored():
            proc.start()
        receiver.close()  # the worker has its own
        watched.close()  # the worker has its own; the parent keeps only the writing end
        board_in.close()
        self.relay.replace(index, board_out)
        if index in self.processes:  # a restart: the students of the dead one left
            self.roster.drop(index, time.time())
            self._teachers.discard(index)
            self._told.discard(index)
        for old in (self.pipes.get(index), self._lifelines.get(index)):
            if old is not None:
                old.close()
        self.pipes[index] = sender
        self._lifelines[index] = lifeline
        self.processes[index] = proc
        if self.front is not None:
            self.front.replace(index, sender)

    def start(self) -> None:
        """Start every worker and wait until all listen.

        Raises:
            SandboxError: a worker could not start (its one-line reason).
        """
        for index in range(self.count):
            self._spawn(index)
        ready: set[int] = set()
        deadline = time.monotonic() + START_TIMEOUT
        while len(ready) < self.count:
            left = deadline - time.monotonic()
            try:
                kind, index, detail = self._events.get(timeout=max(0.1, min(left, 1.0)))
            except queue.Empty:
                dead = [i for i, p in self.processes.items() if p.exitcode is not None]
                if dead or left <= 0:
                    self.stop()
                    why = "exited" if dead else f"did not start within {START_TIMEOUT:g} s"
                    raise BadOption(f"a server worker {why}; try --workers 1 to see why") from None
                continue
            if kind == "error":
                self.stop()
                raise BadOption(str(detail))
            if kind == "board":
                self._board(index, detail)
            elif kind == "run":
                self._run(detail)
            else:
                ready.add(index)

    def watch(self) -> bool:
        """Restart workers that died (a crash must not leave a core's students out).

        Returns:
            False when a worker ended by itself with exit code 0: it was asked to stop (a
            Ctrl-C reached it), so the whole server stops, not restarts it.

        Raises:
            SandboxError: workers keep dying (more than :data:`MAX_RESTARTS` a minute).
        """
        for index, proc in list(self.processes.items()):
            if proc.exitcode is None:
                continue
            if proc.exitcode == 0:
                print(f"sandbox: worker {index} was asked to stop: stopping the server", flush=True)
                return False
            now = time.monotonic()
            self._restarts = [t for t in self._restarts if now - t < 60.0] + [now]
            if len(self._restarts) > MAX_RESTARTS:
                raise BadOption(
                    f"server workers keep stopping (last exit code {proc.exitcode}); "
                    "try --workers 1 to see why"
                )
            log.warning("worker %d stopped (exit code %s): restarting it", index, proc.exitcode)
            print(
                f"sandbox: worker {index} stopped (exit code {proc.exitcode}); restarting it",
                flush=True,
            )
            self._spawn(index)
        self._drain_events()
        return True

    def _drain_events(self) -> None:
        while True:
            try:
                kind, index, detail = self._events.get_nowait()
            except queue.Empty:
                return
            if kind == "error":
                print(f"sandbox: worker {index}: {detail}", flush=True)
            elif kind == "ready" and self.front is not None:
                self.front.set_ready(index)
            elif kind == "board":
                self._board(index, detail)
            elif kind == "run":
                self._run(detail)

    def _board(self, index: int, detail: object) -> None:
        """A worker's students: merged; the board to the workers where a teacher waits,
        once a second, and at once when someone arrives, leaves or is named."""
        if not (
            isinstance(detail, tuple) and len(detail) in (2, 3) and isinstance(detail[0], list)
        ):
            log.warning("worker %d sent an unreadable class board", index)
            return
        rows: list[object] = detail[0]
        checked = [r for r in (from_wire(d) for d in rows[:MAX_ROWS]) if r is not None]
        now = time.time()
        load = Load.from_wire(detail[2]) if len(detail) == 3 else None
        self.roster.update(index, checked, now, load)
        if detail[1]:
            self._teachers.add(index)
        else:
            self._teachers.discard(index)
        if self.run is not None and index not in self._told:  # a worker started since
            self._told.add(index)
            self.relay.send(index, replace(self.roster.board(now), run=self.run).wire())
        if not self._teachers:
            return
        board = replace(self.roster.board(now), run=self.run)
        who = tuple((r.key, r.number, r.name, r.connected) for r in board.rows)
        if who == self._who and now - self._sent < REFRESH:
            return  # only values changed: they wait for the next second
        self._who, self._sent = who, now
        wire = board.wire()
        for k in self._teachers:
            self.relay.send(k, wire)

    def _run(self, detail: object) -> None:
        """A teacher started or stopped a challenge: every worker is told at once (their
        students get their secret, or the solution)."""
        run = Run.from_wire(detail)
        if run is None:
            log.warning("a worker sent an unreadable challenge")
            return
        self.run = run
        wire = replace(self.roster.board(time.time()), run=run).wire()
        self._told = set(self.processes)
        for k in self.processes:
            self.relay.send(k, wire)

    def alive(self) -> int:
        """How many workers are running."""
        return sum(1 for p in self.processes.values() if p.exitcode is None)

    def stop(self) -> None:
        """Ask every worker to close its sessions (recordings included), wait, then kill
        stragglers. POSIX asks with SIGTERM; where SIGTERM kills at once (Windows'
        TerminateProcess, which would leave recordings unclosed) the parent closes the
        workers' lifelines, which they answer as Ctrl-C (:func:`watch_parent`)."""
        if not GRACEFUL_SIGTERM:
            for lifeline in self._lifelines.values():
                lifeline.close()
            self._lifelines.clear()
        for proc in self.processes.values():
            if GRACEFUL_SIGTERM and proc.exitcode is None and proc.pid is not None:
                try:
                    os.kill(proc.pid, signal.SIGTERM)
                except ProcessLookupError:
                    pass
        deadline = time.monotonic() + STOP_TIMEOUT
        for proc in self.processes.values():
            proc.join(max(0.0, deadline - time.monotonic()))
        self.relay.close()
        for proc in self.processes.values():
            if proc.exitcode is None:
                proc.kill()
                proc.join(1.0)


def listen(host: str, port: int) -> socket.socket:
    """The public address's listening socket, in the parent (BadOption when taken)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    if os.name != "nt":  # a restart finds the port in TIME_WAIT (Windows: would share it)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
        sock.listen(LISTEN_BACKLOG)
    except OSError as exc:
        sock.close()
        raise BadOption(
            f"cannot listen on {host}:{port} ({exc.strerror or exc}); the port is probably "
            f"in use: choose another one with --port, e.g. --port {port + 1}"
        ) from None
    return sock


def serve_pool(spec: WorkerSpec, workers: int, *, banner: str) -> None:
    """Run ``workers`` worker processes behind the front until Ctrl-C or SIGTERM; print
    ``banner`` once they all serve."""

    def terminate(signum: int, frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    # Ctrl-C and SIGTERM stop the server whatever this process inherited: started from a
    # script's background job or a desktop launcher, SIGINT arrives ignored (SIG_IGN),
    # and the workers stopped by a Ctrl-C were restarted instead.
    previous = {sig: signal.signal(sig, terminate) for sig in (signal.SIGTERM, signal.SIGINT)}
    listener = listen(spec.host, spec.port)
    pool = WorkerPool(spec, workers)
    try:
        pool.start()
        pool.front = Front(listener, [pool.pipes[k] for k in range(workers)], pool.closed)
        print(banner, flush=True)
        serving = True
        while serving:
            pool.front.poll(POLL)
            serving = pool.watch()
    except KeyboardInterrupt:
        pass
    finally:
        if pool.front is not None:
            pool.front.close()
        else:
            listener.close()
        pool.stop()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
