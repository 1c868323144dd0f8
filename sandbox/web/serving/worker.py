"""One worker process of ``sandbox serve --workers N``: what it is given
(:class:`WorkerSpec`), its body (:func:`worker_main`: a complete web app serving the
browsers the parent's front hands it), its side of the class board (:class:`WorkerHub`)
and its lifeline to the parent (:func:`watch_parent`).

A worker never outlives the parent, however the parent ends (``kill -9`` too, which runs
none of its code): each worker holds the reading end of a pipe whose only writer is the
parent, and a thread of the worker waits on it (:func:`watch_parent`). The operating
system closes a dead process's files and handles, so the read ends at once, on Linux,
macOS and Windows alike; the worker then stops as on Ctrl-C (sessions and recordings
closed) and exits within :data:`ORPHAN_GRACE` seconds anyway.
"""

from __future__ import annotations

import _thread
import logging
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from multiprocessing.queues import Queue
from typing import Any

from sandbox.errors import SandboxError
from sandbox.web.panels.board_rows import Board, Run
from sandbox.web.serving import network
from sandbox.web.serving.handoff import Adopter
from sandbox.web.serving.server import App, run_forever
from sandbox.web.serving.startup import start

log = logging.getLogger(__name__)

Event = tuple[str, int, object]
"""What a worker tells the parent: ("ready", index, port), ("error", index, reason) or
("board", index, (rows, wants)): its students' rows (wire dicts) and whether a teacher's
page there waits for the merged board; ("run", index, run): a challenge a teacher there
started or stopped (:meth:`sandbox.web.panels.board_rows.Run.wire`)."""

ORPHAN_GRACE = 2.0
"""Seconds a worker whose parent died gets to close its sessions before it exits anyway."""


@dataclass(frozen=True)
class WorkerSpec:
    """Everything a worker needs to start its app (picklable).

    Attributes:
        target: Scene name or MJCF path.
        host: Interface to listen on.
        port: TCP port shared by every worker.
        options: Keyword arguments for :func:`sandbox.web.serving.app.start`.
    """

    target: str
    host: str
    port: int
    options: Mapping[str, Any] = field(default_factory=dict)


def _interrupt_main() -> None:
    """Stop this worker as Ctrl-C would: KeyboardInterrupt in its main thread, which
    :func:`sandbox.web.serving.server.run_forever` answers by closing the sessions."""
    _thread.interrupt_main(signal.SIGINT)


def watch_parent(
    lifeline: Any,
    *,
    grace: float = ORPHAN_GRACE,
    stop: Callable[[], None] = _interrupt_main,
    exit: Callable[[int], None] = os._exit,
) -> threading.Thread:
    """Stop this process when the parent's end of ``lifeline`` closes.

    The parent never writes on the pipe and keeps its end open while it lives; when it
    ends, however it ends, the system closes that end and ``recv`` fails here. Works on
    every platform (a pipe, not ``prctl`` or signals).

    Args:
        lifeline: Reading end of a :func:`multiprocessing.Pipe` whose writer is the parent.
        grace: Seconds between ``stop`` and ``exit`` (the process normally ends in between,
            and this daemon thread with it).
        stop: Asks the process to stop cleanly (default: KeyboardInterrupt in the main
            thread, the Ctrl-C path).
        exit: Ends the process with the given status if it is still there after ``grace``.

    Returns:
        The watching thread (a daemon, started).
    """

    def watch() -> None:
        try:
            lifeline.recv()
        except (EOFError, OSError):
            pass  # the parent is gone (a message would mean "stop" just as well)
        log.warning("the server's main process stopped or is gone: stopping this worker")
        stop()
        time.sleep(grace)
        exit(1)

    thread = threading.Thread(target=watch, name="sandbox-lifeline", daemon=True)
    thread.start()
    return thread


class WorkerHub:
    """A worker's side of the class board: its rows go to the parent on ``events``; the
    merged board comes back on ``pipe`` and goes to ``deliver`` (from a thread).

    Args:
        events: The queue to the parent.
        index: This worker's index.
        pipe: Reading end of the parent's board pipe to this worker.
        deliver: Called with each merged board.
    """

    def __init__(
        self, events: Queue[Event], index: int, pipe: Any, deliver: Callable[[Board], None]
    ) -> None:
        self.events = events
        self.index = index
        self.pipe = pipe
        self.deliver = deliver
        self._thread = threading.Thread(target=self._receive, name="sandbox-board-in", daemon=True)
        self._thread.start()

    def publish(
        self, rows: list[dict[str, Any]], wants: bool, load: dict[str, Any] | None = None
    ) -> None:
        """This worker's students and what its sessions cost, to the parent (never
        blocks: the queue's own thread sends)."""
        self.events.put(("board", self.index, (rows, wants, load)))

    def announce(self, run: Run) -> None:
        """A teacher here started or stopped a challenge: to the parent, which tells every
        worker."""
        self.events.put(("run", self.index, run.wire()))

    def _receive(self) -> None:
        while True:
            try:
                data = self.pipe.recv()
            except (EOFError, OSError):
                return  # the parent is gone: the worker is stopping
            except Exception:  # not a board: skip it
                log.warning("an unreadable class board was dropped", exc_info=True)
                continue
            board = Board.from_wire(data)
            if board is not None:
                self.deliver(board)


def worker_main(
    spec: WorkerSpec,
    index: int,
    events: Queue[Event],
    pipe: Any,
    closed: Any,
    lifeline: Any,
    board: Any = None,
) -> None:
    """Body of a worker process: serve the connections the front hands over on ``pipe``
    until SIGTERM or SIGINT or the end of the parent (``lifeline``), then close sessions;
    the class board's rows go to the parent and its merged board comes on ``board``."""
    logging.basicConfig(level=logging.WARNING, format=f"sandbox[w{index}] %(message)s")
    app: App | None = None
    try:
        watch_parent(lifeline)
        # viser's banners: the parent prints the address
        sys.stdout = open(os.devnull, "w", encoding="utf-8")
        adopter = Adopter(pipe, closed, index)
        network.install(handoff=adopter)
        try:
            app = start(
                spec.target,
                host=spec.host,
                port=spec.port,
                open_message=False,
                check_port=False,
                **dict(spec.options),
            )
        except SandboxError as exc:
            events.put(("error", index, str(exc)))
            return
        except Exception as exc:  # reported by the parent as one line
            events.put(("error", index, f"{type(exc).__name__}: {exc}"))
            return
        classroom = app.classroom
        if board is not None:
            hub = WorkerHub(events, index, board, classroom.receive)
            classroom.relay(hub, source=f"w{index}")
        adopter.start()
        events.put(("ready", index, app.port))
    except KeyboardInterrupt:  # Ctrl-C, or the end of the parent, while starting
        if app is not None:
            app.stop()
        return
    try:
        run_forever(app)
    finally:  # sessions are closed: a second SIGTERM must not interrupt the exit
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
