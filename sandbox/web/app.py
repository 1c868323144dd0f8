"""The web app: a viser server giving every browser its own simulation of one target.

``serve`` blocks until Ctrl-C (``sandbox serve``); ``start`` returns a running
:class:`App` (tests, notebooks).
"""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import viser

from sandbox.errors import BadOption
from sandbox.physics.simulation import Simulation
from sandbox.web.session import Controller, Session
from sandbox.web.view import WebView

log = logging.getLogger(__name__)


def _check_port(host: str, port: int) -> None:
    """Fail early with a useful message when ``port`` is taken (viser would pick another)."""
    if port == 0:
        return
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((host, port))
        except OSError as exc:
            raise BadOption(
                f"cannot listen on {host}:{port} ({exc.strerror or exc}); the port is probably "
                f"in use: choose another one with --port, e.g. --port {port + 1}"
            ) from None


class App:
    """A running web app: one :class:`Session` per browser, made by ``factory``.

    Attributes:
        server: The viser server.
        host: Interface listened on.
        port: Port actually bound.
        sessions: Live sessions by client id.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        host: str,
        factory: Callable[[viser.ClientHandle], Session],
    ) -> None:
        self.server = server
        self.host = host
        self.port = server.get_port()
        self.factory = factory
        self.sessions: dict[int, Session] = {}
        self._lock = threading.Lock()
        server.on_client_connect(self._connect)
        server.on_client_disconnect(self._disconnect)

    @property
    def url(self) -> str:
        """Address to open in a browser."""
        host = "127.0.0.1" if self.host in ("0.0.0.0", "", "::") else self.host
        return f"http://{host}:{self.port}"

    def _connect(self, client: viser.ClientHandle) -> None:
        try:
            session = self.factory(client)
        except Exception as exc:  # shown in that browser; the server keeps going
            log.exception("cannot open a session")
            client.add_notification("Erreur", f"{type(exc).__name__}: {exc}", color="red")
            return
        with self._lock:
            self.sessions[client.client_id] = session
        session.start()

    def _disconnect(self, client: viser.ClientHandle) -> None:
        with self._lock:
            session = self.sessions.pop(client.client_id, None)
        if session is not None:
            session.stop()

    def stop(self) -> None:
        """Stop every session, then the server."""
        with self._lock:
            sessions = list(self.sessions.values())
            self.sessions.clear()
        for session in sessions:
            session.stop()
        self.server.stop()


def open_server(host: str, port: int, label: str) -> viser.ViserServer:
    """A viser server on exactly ``host:port`` (BadOption when the port is taken)."""
    _check_port(host, port)
    server = viser.ViserServer(host=host, port=port, label=label, verbose=False)
    if port != 0 and server.get_port() != port:  # lost a race for the port
        server.stop()
        raise BadOption(f"port {port} is in use; choose another one with --port")
    return server


def run_forever(app: App) -> None:
    """Block until Ctrl-C, then stop ``app``."""
    try:
        while True:
            time.sleep(0.5)
    except KeyboardInterrupt:
        pass
    finally:
        app.stop()


def start(
    target: str | Path,
    *,
    host: str = "127.0.0.1",
    port: int = 8080,
    values: Mapping[str, object] | None = None,
    integrator: str | None = None,
    timestep: float | None = None,
    lesson: str | None = None,
    open_message: bool = True,
) -> App:
    """Start the web app in background threads and return at once.

    The target is checked first by building one simulation, so a bad scene, file or
    value fails with its one-line message before any server starts.

    Args:
        target: Scene name or MJCF path.
        host: Interface to listen on.
        port: TCP port (0 picks a free one).
        values: Parameter values for every session.
        integrator: Integrator name overriding the scene's.
        timestep: Timestep [s] overriding the scene's.
        lesson: Lesson opened in every new browser (its scene is ``target``).
        open_message: Print the URL to open.

    Raises:
        SandboxError: bad target, value or option; BadOption when the port is taken.
    """
    options = {"values": dict(values or {}), "integrator": integrator, "timestep": timestep}
    Simulation(target, **options)
    server = open_server(host, port, "sandbox")

    def session(client: viser.ClientHandle) -> Session:
        controller = Controller(Simulation(target, **options))
        return Session(controller, WebView(client, controller, lesson=lesson))

    app = App(server, host, session)
    if open_message:
        print(f"sandbox: {target} served at {app.url} (Ctrl-C to stop)", flush=True)
    return app


def serve(target: str | Path, **options: Any) -> None:
    """Serve ``target`` until Ctrl-C (keyword arguments as for :func:`start`)."""
    run_forever(start(target, **options))
