"""In a worker of ``sandbox serve --workers N``: the connections the front hands over
(:mod:`sandbox.web.serving.front`), adopted by viser's websocket server.

viser's server is opened on a socket that never listens; the protocol factory that
websockets gives asyncio is kept (:meth:`Adopter.attach`, from :func:`network.install`),
and each socket received on the pipe joins viser's event loop as an accepted connection
(``loop.connect_accepted_socket``, public asyncio). The worker counts the websockets it
closes in the array it shares with the front, which balances the next ones on it.
"""

from __future__ import annotations

import asyncio
import logging
import socket
import threading
from collections.abc import Callable, MutableSequence
from typing import Any

log = logging.getLogger(__name__)


class Adopter:
    """Receives ``(is_websocket, socket)`` on ``pipe`` and serves them in viser's loop.

    Args:
        pipe: The worker's end of its pipe from the front.
        closed: Websockets closed by each worker (shared with the front).
        index: This worker's slot in ``closed``.
    """

    def __init__(self, pipe: Any, closed: MutableSequence[int], index: int) -> None:
        self.pipe = pipe
        self.closed = closed
        self.index = index
        self.loop: asyncio.AbstractEventLoop | None = None
        self.factory: Callable[[], asyncio.BaseProtocol] | None = None
        self._attached = threading.Event()
        self._thread: threading.Thread | None = None

    def attach(
        self, loop: asyncio.AbstractEventLoop, factory: Callable[[], asyncio.BaseProtocol]
    ) -> None:
        """The server's event loop and protocol factory (websockets' own)."""
        self.loop, self.factory = loop, factory
        self._attached.set()

    def start(self) -> None:
        """Receive connections in a thread of their own (until the pipe closes)."""
        self._thread = threading.Thread(target=self._receive, name="sandbox-adopt", daemon=True)
        self._thread.start()

    def _receive(self) -> None:
        self._attached.wait()
        loop = self.loop
        assert loop is not None
        while True:
            try:
                websocket, sock = self.pipe.recv()
            except (EOFError, OSError):
                return  # the front is gone: the worker is stopping
            except Exception:  # a socket that could not be rebuilt: drop it, keep going
                log.warning("a handed-over connection was lost", exc_info=True)
                continue
            try:
                asyncio.run_coroutine_threadsafe(self._adopt(bool(websocket), sock), loop)
            except RuntimeError:  # the loop has stopped
                sock.close()
                return

    async def _adopt(self, websocket: bool, sock: socket.socket) -> None:
        assert self.loop is not None and self.factory is not None
        try:
            sock.setblocking(False)
            _, connection = await self.loop.connect_accepted_socket(self.factory, sock)
        except OSError:
            sock.close()
            if websocket:
                self.closed[self.index] += 1
            return
        if not websocket:
            return
        try:
            await connection.wait_closed()  # type: ignore[attr-defined]
        finally:
            self.closed[self.index] += 1
