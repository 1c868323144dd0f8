"""The front of ``sandbox serve --workers N``: one listening socket in the parent process,
and every new connection handed to the worker that serves the fewest browsers.

The kernel's ``SO_REUSEPORT`` hash spread a class of 30 browsers 22/8 and even 30/0
over two workers (they all come from a few addresses), macOS does not balance it and
Windows lacks it. Here the parent accepts each connection, reads the start of its request
without consuming it (``MSG_PEEK``) to tell a browser's websocket (a session) from a
request for the page or a file, and passes the socket itself, not its bytes (this is no
proxy), to a worker over a pipe: multiprocessing pickles sockets on every platform
(``SCM_RIGHTS`` on Unix, ``WSADuplicateSocket`` on Windows). A websocket goes to the
worker with the fewest live websockets, so the sessions of two workers differ by at most
one; a page request goes to the workers in turn. A worker counts the websockets it closes
(:class:`sandbox.web.serving.handoff.Adopter`) in an array both processes share.
"""

from __future__ import annotations

import logging
import selectors
import socket
import time
from collections.abc import Callable, MutableSequence, Sequence
from dataclasses import dataclass
from typing import Any

log = logging.getLogger(__name__)

PEEK = 8192
"""Bytes of a request looked at to classify it (a browser's headers take 0.5-1 kB)."""

HEADERS_WAIT = 5.0
"""Seconds a connection may take to send its request line and headers; past them it is
handed over as it is (the worker's server then times it out)."""

RECHECK = 0.02
"""Seconds before a request seen incomplete is looked at again (it stays readable: a
second look at once would spin)."""

MAX_PENDING = 512
"""Connections waiting for their headers; past them, the oldest is handed over at once
(a page opening hundreds of idle connections must not exhaust the parent's files)."""

MAX_ACCEPT = 64
"""Connections accepted per readiness of the listening socket."""


def is_websocket(head: bytes) -> bool | None:
    """Whether the request starting with ``head`` asks for a websocket (an ``Upgrade:
    websocket`` header); None while its headers are incomplete."""
    end = head.find(b"\r\n\r\n")
    if end < 0:
        if len(head) < PEEK:
            return None
        end = len(head)
    for line in head[:end].split(b"\r\n")[1:]:
        name, _, value = line.partition(b":")
        if name.strip().lower() == b"upgrade" and b"websocket" in value.lower():
            return True
    return False


@dataclass
class _Pending:
    sock: socket.socket
    since: float
    again: float = 0.0  # when an incomplete request is looked at again (0: registered)


class Front:
    """Accepts on ``listener`` and hands each connection to a worker's pipe.

    Args:
        listener: The bound, listening socket of the public address.
        pipes: One connection per worker; ``(is_websocket, socket)`` is sent on it.
        closed: Websockets each worker has closed so far (shared, written by the workers).
        clock: Monotonic clock [s].
    """

    def __init__(
        self,
        listener: socket.socket,
        pipes: Sequence[Any],
        closed: Sequence[int],
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.listener = listener
        self.pipes: MutableSequence[Any] = list(pipes)
        self.closed = closed
        self.clock = clock
        self.sent = [int(c) for c in closed]  # websockets handed to each worker
        self.ready = [True] * len(self.pipes)
        self._turn = 0
        self._pending: dict[int, _Pending] = {}
        listener.setblocking(False)
        self._selector = selectors.DefaultSelector()
        self._selector.register(listener, selectors.EVENT_READ)

    def live(self) -> list[int]:
        """Websockets open on each worker."""
        return [max(0, s - int(c)) for s, c in zip(self.sent, self.closed, strict=True)]

    def replace(self, index: int, pipe: Any) -> None:
        """A restarted worker: its pipe, and none of its websockets (they died with it);
        it gets connections once :meth:`set_ready`."""
        self.pipes[index] = pipe
        self.sent[index] = int(self.closed[index])
        self.ready[index] = False

    def set_ready(self, index: int) -> None:
        """Worker ``index`` serves: hand it connections."""
        self.ready[index] = True

    def choose(self, websocket: bool) -> int:
        """The worker for a new connection: fewest live websockets (ties, and pages: in
        turn), among the ready ones."""
        ready = [k for k, ok in enumerate(self.ready) if ok] or list(range(len(self.pipes)))
        n = len(self.pipes)
        order = sorted(ready, key=lambda k: (k - self._turn) % n)
        if websocket:
            live = self.live()
            pick = min(order, key=lambda k: live[k])
        else:
            pick = order[0]
        self._turn = (pick + 1) % n
        return pick

    def poll(self, timeout: float) -> int:
        """Wait up to ``timeout`` seconds for connections and hand over those whose
        request is known; returns how many were handed over."""
        now = self.clock()
        waits = [p.again - now for p in self._pending.values() if p.again > 0]
        waits += [p.since + HEADERS_WAIT - now for p in self._pending.values()]
        wait = max(0.0, min([timeout, *waits]))
        handed = 0
        for key, _ in self._selector.select(wait):
            if key.fileobj is self.listener:
                self._accept()
            else:
                handed += self._look(key.fd)
        now = self.clock()
        for fd, p in list(self._pending.items()):
            if p.again and now >= p.again:
                p.again = 0.0
                handed += self._look(fd, registered=False)
            elif now - p.since >= HEADERS_WAIT:
                handed += self._hand(fd, websocket=False)
        return handed

    def _accept(self) -> None:
        for _ in range(MAX_ACCEPT):
            try:
                sock, _ = self.listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:  # out of files, a reset before accept: keep serving
                log.warning("accept failed: %s", exc)
                return
            sock.setblocking(False)
            if len(self._pending) >= MAX_PENDING:
                oldest = min(self._pending, key=lambda fd: self._pending[fd].since)
                self._hand(oldest, websocket=False)
            self._pending[sock.fileno()] = _Pending(sock, self.clock())
            self._selector.register(sock, selectors.EVENT_READ)

    def _look(self, fd: int, *, registered: bool = True) -> int:
        """Peek at a pending connection: hand it over once its headers are in."""
        p = self._pending.get(fd)
        if p is None:
            return 0
        try:
            head = p.sock.recv(PEEK, socket.MSG_PEEK)
        except (BlockingIOError, InterruptedError):
            return 0
        except OSError:
            head = b""
        if not head:  # closed before asking anything
            self._drop(fd)
            return 0
        kind = is_websocket(head)
        if kind is None:  # not all there yet: look again a little later
            if registered:
                self._selector.unregister(p.sock)
            p.again = self.clock() + RECHECK
            return 0
        if not registered:
            self._selector.register(p.sock, selectors.EVENT_READ)
        return self._hand(fd, websocket=kind)

    def _hand(self, fd: int, *, websocket: bool) -> int:
        p = self._pending.pop(fd)
        if not p.again:
            self._selector.unregister(p.sock)
        k = self.choose(websocket)
        try:
            self.pipes[k].send((websocket, p.sock))
        except (OSError, ValueError) as exc:  # the worker is gone: its restart will come
            log.warning("could not hand a connection to worker %d: %s", k, exc)
            p.sock.close()
            return 0
        if websocket:
            self.sent[k] += 1
        p.sock.close()  # the worker has its own copy now
        return 1

    def _drop(self, fd: int) -> None:
        p = self._pending.pop(fd)
        if not p.again:
            self._selector.unregister(p.sock)
        p.sock.close()

    def close(self) -> None:
        """Close the listening socket and the connections still waiting."""
        for fd in list(self._pending):
            self._drop(fd)
        self._selector.close()
        self.listener.close()
