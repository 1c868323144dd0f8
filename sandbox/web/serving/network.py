"""What the web server does on the network: which handshakes it accepts, how several
processes share one port (the addresses it serves and students type:
:mod:`sandbox.web.serving.addresses`).

viser opens its websocket server with ``websockets.asyncio.server.serve`` and exposes
none of its options, so :func:`install` wraps that one function, once per process, to
add two of them:

* ``process_request`` refuses (HTTP 403) a websocket handshake whose ``Host`` or
  ``Origin`` is not one of the addresses this server serves
  (:class:`~sandbox.web.serving.addresses.Served`: the
  localhost names, the interface it listens on, this machine's LAN addresses and name
  when it listens on all of them, the address the connection reached, each on the port
  the connection reached; and the proxy's ``--public-url``). They are never compared
  with each other: a DNS-rebinding page (``http://evil.attacker:P`` whose name now
  points at this machine) controls both, and a web page the teacher happens to visit
  must not open sessions or press buttons on a classroom server. A handshake without
  ``Origin`` comes from a program, not from a page, and is let through (if its Host,
  when it sends one, is served). Plain HTTP requests (the page, its scripts: nothing
  private, and the teacher's path is a secret) are served whatever their Host, because
  the health check of ``deploy/haproxy.cfg`` sends ``Host: sandbox``.
* ``process_request`` also answers HTTP 400 (Bad Request), in one log line, to a request
  no browser sends (:func:`request_refusal`: a doubled ``Host``, a path segment longer
  than a file name) and to any request that makes viser's page handler raise: client
  garbage is never a 500 with a traceback in the teacher's terminal.
* ``handoff``: in a worker process of ``sandbox serve --workers N``, the server listens
  on no address of its own; the connections come from the parent's front, which hands
  each to the least busy worker (:mod:`sandbox.web.serving.front`,
  :mod:`sandbox.web.serving.handoff`).
"""

from __future__ import annotations

import asyncio
import dataclasses
import http
import inspect
import logging
import math
import socket
import threading
import time
from collections.abc import Awaitable, Callable
from typing import TYPE_CHECKING, Any
from urllib.parse import urlsplit

import websockets.asyncio.server as ws_server
from websockets.exceptions import ConnectionClosed

from sandbox.errors import BadOption
from sandbox.web.client import viser_internals
from sandbox.web.serving.addresses import Served, netloc, origin_refusal

if TYPE_CHECKING:
    import viser
    from websockets.asyncio.server import ServerConnection
    from websockets.datastructures import Headers
    from websockets.http11 import Request, Response

    from sandbox.web.serving.handoff import Adopter

    ProcessRequest = Callable[
        [ServerConnection, Request], Awaitable[Response | None] | Response | None
    ]
    """websockets' ``process_request`` hook (viser's serves the page over HTTP)."""

log = logging.getLogger(__name__)

_lock = threading.Lock()
_installed = False
_handoff: Adopter | None = None
_public_url: str | None = None
_aliases: set[str] = set()


def reached_through(public_url: str | None) -> None:
    """Serve the proxy's public address ``public_url`` (``--public-url``; None: no proxy)
    too, in the servers this process opens after the call (:class:`Served`).

    Raises:
        BadOption: ``public_url`` is not an http(s) address with a host name.
    """
    global _public_url
    if public_url is not None:
        try:
            netloc(public_url)
            ok = urlsplit(public_url).scheme.lower() in ("http", "https")
        except ValueError:
            ok = False
        if not ok:
            raise BadOption(
                f"--public-url must be an http:// or https:// address, got {public_url[:80]!r}"
                "; e.g. --public-url http://sandbox.lycee.fr"
            )
    with _lock:
        _public_url = public_url


def install(*, handoff: Adopter | None = None) -> None:
    """Wrap the websocket server of viser with the Origin check (and, in a worker, the
    handover of the front's connections).

    Idempotent; ``handoff`` (None: unchanged) applies to the servers opened after the call.
    """
    global _installed, _handoff
    with _lock:
        if handoff is not None:
            _handoff = handoff
        if _installed:
            return
        if _one_line not in log.filters:  # a handler's failure on a request: one line
            log.addFilter(_one_line)
        original = ws_server.serve

        def serve(
            handler: Callable[[ServerConnection], Awaitable[None]], *args: Any, **kwargs: Any
        ) -> ws_server.serve:  # viser's arguments, passed through
            host = args[0] if args else kwargs.get("host")
            served = Served.of(host, public_url=_public_url)
            kwargs["process_request"] = _guarded(kwargs.get("process_request"), served)
            adopter = _handoff
            if adopter is None:
                return original(handler, *args, **kwargs)
            return _adopting(original, adopter, handler, **kwargs)

        # serve is a class in websockets; a function returning its instance does the same
        # job for viser's single call (mypy sees a class replaced by a function).
        ws_server.serve = serve  # type: ignore[assignment,misc]
        _installed = True


def handing_off() -> bool:
    """True in a worker whose connections come from the front (it listens on no address
    of its own: viser's port is not the one browsers use)."""
    return _handoff is not None


def _adopting(original: Any, adopter: Adopter, handler: Any, **kwargs: Any) -> Any:
    """viser's server on a loopback port of its own that nobody is told (websockets
    answers 503 while its server does not serve), its protocol factory given to
    ``adopter`` for the connections the front hands over. The factory is what websockets
    passes to the running loop's ``create_server``, caught for that one call."""
    loop = asyncio.get_running_loop()
    create = loop.create_server

    def create_server(factory: Any, *args: Any, **options: Any) -> Any:
        adopter.attach(loop, factory)
        return create(factory, *args, **options)

    idle = socket.socket(socket.AF_INET, socket.SOCK_STREAM)  # closed with the server
    idle.bind(("127.0.0.1", 0))
    loop.create_server = create_server  # type: ignore[method-assign,assignment]
    try:
        return original(handler, sock=idle, **kwargs)
    finally:
        del loop.create_server  # the loop's own method again


class OneLine(logging.Filter):
    """Turn the tracebacks that viser's websocket layer logs for a browser's bad frame
    (``websockets.server``: "connection handler failed"; ``asyncio``: "Task exception was
    never retrieved") into one warning line, and say a repeated one once per
    :attr:`QUIET` seconds: a hostile browser must not fill the teacher's terminal."""

    QUIET = 10.0

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__()
        self.clock = clock
        self.last: dict[tuple[str, str], float] = {}

    def filter(self, record: logging.LogRecord) -> bool:
        if not record.exc_info or record.exc_info[1] is None:
            return True
        exc = record.exc_info[1]
        if _vanished(exc):  # a tab closed or a reload while its websocket opened: no fault
            record.levelno, record.levelname = logging.DEBUG, "DEBUG"
            record.exc_info = record.exc_text = None
            return logging.getLogger(record.name).isEnabledFor(logging.DEBUG)
        key = (record.name, type(exc).__name__)
        now = self.clock()
        if now - self.last.get(key, -math.inf) < self.QUIET:
            return False
        self.last[key] = now
        detail = " ".join(str(exc).split())[:160]
        record.msg = (
            f"{record.getMessage()}: {type(exc).__name__}: {detail} (browser input dropped)"
        )
        record.args = None
        record.exc_info = record.exc_text = record.stack_info = None
        record.levelno, record.levelname = logging.WARNING, "WARNING"
        return True


def _vanished(exc: BaseException) -> bool:
    """Whether ``exc`` says the browser went away without a word (no close frame either
    way: the connection just ended), rather than sent something wrong."""
    return isinstance(exc, ConnectionClosed) and exc.rcvd is None and exc.sent is None


VIEWER_LOGGERS = ("websockets.server", "websockets", "asyncio")
"""Loggers of the libraries under viser that report a browser's bad input."""

_one_line = OneLine()


def quiet_viewer_logs() -> None:
    """Install :class:`OneLine` on :data:`VIEWER_LOGGERS` (idempotent)."""
    for name in VIEWER_LOGGERS:
        logger = logging.getLogger(name)
        if _one_line not in logger.filters:
            logger.addFilter(_one_line)


def page_alias(path: str) -> None:
    """Serve the sandbox page at ``path`` too (e.g. the teacher's link); its websocket
    then connects to the same path, which :func:`request_path` tells the app."""
    with _lock:
        _aliases.add(path.rstrip("/"))


MAX_SEGMENT = 255
"""Longest segment of a request's path, in characters (a file name's limit on Linux and
macOS): no page or script of the sandbox has a longer one."""

SINGLE_HEADERS = ("Host", "Origin", "Upgrade")
"""Headers a request sends at most once (RFC 9110: a doubled Host is a Bad Request)."""

BAD_REQUEST = "Requête invalide.\n"
"""Body of the HTTP 400 answer (short: nothing about the server)."""


def request_refusal(headers: Headers, path: str) -> str | None:
    """Why a request is answered HTTP 400 (Bad Request) before anyone reads it, or None.

    Args:
        headers: The request headers (``get_all`` gives every value of a name).
        path: The request's path (with its query).
    """
    for name in SINGLE_HEADERS:
        count = len(headers.get_all(name))
        if count > 1:
            return f"{count} {name} headers (a request sends one)"
    longest = max(len(segment) for segment in path.partition("?")[0].split("/"))
    if longest > MAX_SEGMENT:
        return f"a path segment of {longest} characters (at most {MAX_SEGMENT})"
    return None


def _bad_request(connection: ServerConnection, request: Request, reason: str) -> Response:
    log.info("answered 400 to %r: %s", request.path[:80], reason)
    return connection.respond(http.HTTPStatus.BAD_REQUEST, BAD_REQUEST)


def _failed(connection: ServerConnection, request: Request, exc: Exception) -> Response:
    """HTTP 400 for a request the page handler raised on; the exception in one line
    (:class:`OneLine`, at most once per window and kind)."""
    log.warning("answered 400 to a request the page handler failed on", exc_info=exc)
    return connection.respond(http.HTTPStatus.BAD_REQUEST, BAD_REQUEST)


def _guarded(inner: ProcessRequest | None, served: Served) -> ProcessRequest:
    def judge(
        connection: ServerConnection, request: Request
    ) -> Awaitable[Response | None] | Response | None:
        reason = request_refusal(request.headers, request.path)
        if reason is not None:
            return _bad_request(connection, request, reason)
        try:
            here = served.on(connection.local_address)
        except (AttributeError, OSError):  # no transport: only public addresses are served
            here = served
        reason = origin_refusal(request.headers, here)
        if reason is not None:
            log.warning("refused a websocket handshake: %s", reason)
            return connection.respond(
                http.HTTPStatus.FORBIDDEN,
                "Connexion refusée : cette page n'est pas celle du serveur du sandbox.\n",
            )
        if inner is None:
            return None
        upgrade = str(request.headers.get("Upgrade", "")).lower() == "websocket"
        if not upgrade and request.path.partition("?")[0].rstrip("/") in _aliases:
            request = dataclasses.replace(request, path="/")
        return inner(connection, request)

    async def awaited(
        connection: ServerConnection, request: Request, pending: Awaitable[Response | None]
    ) -> Response | None:
        try:
            return await pending
        except Exception as exc:  # a handler of a later viser may be a coroutine
            return _failed(connection, request, exc)

    def process_request(
        connection: ServerConnection, request: Request
    ) -> Awaitable[Response | None] | Response | None:
        try:
            answer = judge(connection, request)
        except Exception as exc:  # client garbage (a doubled header viser reads...): 400
            return _failed(connection, request, exc)
        if inspect.isawaitable(answer):
            return awaited(connection, request, answer)
        return answer

    return process_request


def request_path(server: viser.ViserServer, client_id: int) -> str:
    """The path the browser's websocket connected to ("" if unknown).

    viser keeps the handshake of each live connection; this is the only place the
    page's address reaches the server (the teacher's link is a path).
    """
    request = viser_internals.handshake(server, client_id)
    return "" if request is None else request.path.partition("?")[0].rstrip("/")
