"""What the web server does on the network: which handshakes it accepts, how several
processes share one port, and which addresses students can type.

viser opens its websocket server with ``websockets.asyncio.server.serve`` and exposes
none of its options, so :func:`install` wraps that one function, once per process, to
add two of them:

* ``process_request`` refuses a websocket handshake whose ``Origin`` is not the page's
  own address (a web page the teacher happens to visit must not open sessions or press
  buttons on a classroom server); a handshake without ``Origin`` comes from a program,
  not from a page, and is let through.
* ``handoff``: in a worker process of ``sandbox serve --workers N``, the server listens
  on no address of its own; the connections come from the parent's front, which hands
  each to the least busy worker (:mod:`sandbox.web.front`, :mod:`sandbox.web.handoff`).
"""

from __future__ import annotations

import asyncio
import dataclasses
import http
import ipaddress
import logging
import math
import socket
import struct
import sys
import threading
import time
from collections.abc import Awaitable, Callable, Mapping
from typing import TYPE_CHECKING, Any
from urllib.parse import urlsplit

if TYPE_CHECKING:
    import viser
    from websockets.asyncio.server import ServerConnection
    from websockets.http11 import Request, Response

    from sandbox.web.handoff import Adopter

    ProcessRequest = Callable[
        [ServerConnection, Request], Awaitable[Response | None] | Response | None
    ]
    """websockets' ``process_request`` hook (viser's serves the page over HTTP)."""

log = logging.getLogger(__name__)

_DEFAULT_PORTS = {"http": 80, "https": 443, "ws": 80, "wss": 443}
_lock = threading.Lock()
_installed = False
_handoff: Adopter | None = None
_aliases: set[str] = set()


def origin_refusal(headers: Mapping[str, str]) -> str | None:
    """Why a handshake with these request headers is refused, or None to accept it.

    Only websocket upgrades are judged; plain HTTP requests (the page, its scripts)
    are always served. The Origin must name the same host and port as the Host header
    the browser sent (that is how the page reached this server, through a proxy too).

    Args:
        headers: The request headers (websockets' ``Headers``, or any mapping).
    """
    if str(headers.get("Upgrade", "")).lower() != "websocket":
        return None
    origin = headers.get("Origin")
    if origin is None:
        return None
    host = headers.get("Host")
    if not host:
        return "no Host header"
    try:
        seen = _netloc(str(origin))
        wanted = _netloc("http://" + str(host), default_scheme_of=str(origin))
    except ValueError:
        return f"malformed Origin {str(origin)[:80]!r}"
    if seen != wanted:
        return f"foreign Origin {str(origin)[:80]!r} (this server is {str(host)[:80]!r})"
    return None


def _netloc(url: str, *, default_scheme_of: str | None = None) -> tuple[str, int]:
    parts = urlsplit(url)
    scheme = urlsplit(default_scheme_of).scheme if default_scheme_of else parts.scheme
    if parts.hostname is None:
        raise ValueError(url)
    port = parts.port or _DEFAULT_PORTS.get(scheme.lower())
    if port is None:
        raise ValueError(url)
    return parts.hostname.lower(), port


def install(*, handoff: Adopter | None = None) -> None:
    """Wrap the websocket server of viser with the Origin check (and, in a worker, the
    handover of the front's connections).

    Idempotent; ``handoff`` (None: unchanged) applies to the servers opened after the call.
    """
    global _installed, _handoff
    import websockets.asyncio.server as ws_server

    with _lock:
        if handoff is not None:
            _handoff = handoff
        if _installed:
            return
        original = ws_server.serve

        def serve(
            handler: Callable[[ServerConnection], Awaitable[None]], *args: Any, **kwargs: Any
        ) -> ws_server.serve:  # viser's arguments, passed through
            kwargs["process_request"] = _guarded(kwargs.get("process_request"))
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


def _guarded(inner: ProcessRequest | None) -> ProcessRequest:
    def process_request(
        connection: ServerConnection, request: Request
    ) -> Awaitable[Response | None] | Response | None:
        reason = origin_refusal(request.headers)
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

    return process_request


def request_path(server: viser.ViserServer, client_id: int) -> str:
    """The path the browser's websocket connected to ("" if unknown).

    viser keeps the handshake of each live connection; this is the only place the
    page's address reaches the server (the teacher's link is a path).
    """
    try:  # viser's private attributes: a later viser may rename them
        connection = server._websock_server._live_connections.get(client_id)
    except AttributeError:
        return ""
    request = connection.request if connection is not None else None
    return "" if request is None else request.path.partition("?")[0].rstrip("/")


# -- addresses students can type ---------------------------------------------------------
def lan_addresses() -> list[str]:
    """IPv4 addresses of this machine that other machines can reach (no loopback).

    Private (LAN) addresses come first. Empty when the machine has no network.
    """
    found: set[str] = set()
    found.update(_interface_addresses())
    try:
        found.update(
            str(info[4][0])  # AF_INET: (host, port)
            for info in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)
        )
    except OSError:
        pass
    usable = []
    for text in found:
        try:
            ip = ipaddress.IPv4Address(text)
        except ValueError:
            continue
        if ip.is_loopback or ip.is_link_local or ip.is_unspecified or ip.is_multicast:
            continue
        usable.append(ip)
    return [str(ip) for ip in sorted(usable, key=lambda ip: (not ip.is_private, ip))]


def _interface_addresses() -> list[str]:
    """IPv4 address of every interface (Linux ioctl SIOCGIFADDR; elsewhere nothing)."""
    if not sys.platform.startswith("linux"):
        return []
    import fcntl

    out = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        for _, name in socket.if_nameindex():
            try:
                packed = fcntl.ioctl(sock.fileno(), 0x8915, struct.pack("256s", name.encode()[:15]))
            except OSError:  # no IPv4 address on that interface
                continue
            out.append(socket.inet_ntoa(packed[20:24]))
    return out


def student_urls(host: str, port: int) -> list[str]:
    """The addresses students type to reach a server listening on ``host:port``.

    A wildcard host gives every LAN address; a specific one gives itself.
    """
    if host in ("0.0.0.0", "", "::"):
        return [f"http://{ip}:{port}" for ip in lan_addresses()]
    shown = f"[{host}]" if ":" in host else host
    return [f"http://{shown}:{port}"]
