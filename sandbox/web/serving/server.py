"""A viser server giving every browser its own session (:class:`App`): the sessions'
lifecycle, a full machine's message, the server opened on exactly its port, and the
loop that serves until Ctrl-C or SIGTERM (:func:`run_forever`).

:mod:`sandbox.web.serving.startup` builds one for a target; the class board's
(:class:`~sandbox.web.serving.class_app.ClassApp`) and follow mode's
(:class:`~sandbox.web.serving.follow.FollowApp`) build on it.
"""

from __future__ import annotations

import contextlib
import logging
import signal
import socket
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Mapping
from types import FrameType
from typing import TypedDict

import rich
import viser

from sandbox.errors import BadOption
from sandbox.web.loop import Session
from sandbox.web.page import locale as client_text
from sandbox.web.serving import network

log = logging.getLogger(__name__)


class SimOptions(TypedDict):
    """Keyword arguments of :class:`Simulation` given to every session of a server."""

    values: Mapping[str, object]
    integrator: str | None
    timestep: float | None
    motion: str | None


def check_port(host: str, port: int) -> None:
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


MAX_SESSIONS = 60
"""Browsers one server process accepts; the next one is told the machine is full."""


MAX_TOMBSTONES = 1000
"""Browsers remembered as gone before their connect callback ran (client ids grow)."""

FULL_MESSAGE = (
    "Ce serveur accueille déjà le nombre maximal de simulations. Attendez qu'un poste se "
    "libère puis rechargez la page, ou demandez à l'enseignant l'adresse d'une autre machine."
)


class App:
    """A running web app: one :class:`Session` per browser, made by ``factory``.

    The lifecycle cannot leak, whatever the order in which viser runs the connect and
    disconnect callbacks (it may run them concurrently): a disconnect that finds no
    session leaves a tombstone that the late connect honours, and every session also
    checks twice a second that its browser is still connected.

    Attributes:
        server: The viser server.
        host: Interface listened on.
        port: Port actually bound.
        sessions: Live sessions by client id.
        max_sessions: Browsers served at once; the next ones get a French message.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        host: str,
        factory: Callable[[viser.ClientHandle], Session],
        *,
        max_sessions: int = MAX_SESSIONS,
        port: int | None = None,
    ) -> None:
        self.server = server
        self.host = host
        self.port = server.get_port() if port is None else port
        self.factory = factory
        self.max_sessions = max_sessions
        self.sessions: dict[int, Session] = {}
        self._opening: set[int] = set()
        self._gone: set[int] = set()
        self._lock = threading.Lock()
        server.on_client_connect(self._connect)
        server.on_client_disconnect(self._disconnect)

    @property
    def url(self) -> str:
        """Address to open in a browser on this machine."""
        host = "127.0.0.1" if self.host in ("0.0.0.0", "", "::") else self.host
        return f"http://{bracket(host)}:{self.port}"

    def connected(self, client_id: int) -> bool:
        """True while the browser ``client_id`` is connected to the server."""
        return client_id in self.server.get_clients()

    def _connect(self, client: viser.ClientHandle) -> None:
        cid = client.client_id
        with self._lock:
            if cid in self._gone:  # the browser left before we got here
                self._gone.discard(cid)
                return
            if len(self.sessions) + len(self._opening) >= self.max_sessions:
                full = True
            else:
                full = False
                self._opening.add(cid)
        if full:
            log.warning("refused a browser: %d sessions already", self.max_sessions)
            _tell(client, "Machine pleine", FULL_MESSAGE)
            return
        try:
            session = self.factory(client)
        except Exception as exc:  # shown in that browser; the server keeps going
            with self._lock:
                self._opening.discard(cid)
                self._gone.discard(cid)
            log.exception("cannot open a session")
            _tell(client, "Erreur", f"La simulation n'a pas pu démarrer : {exc}")
            return
        session.alive = lambda: self.connected(cid)
        with self._lock:
            self._opening.discard(cid)
            left = cid in self._gone
            self._gone.discard(cid)
            if not left:
                self.sessions[cid] = session
        if left:
            session.stop()
        else:
            session.start()

    def _disconnect(self, client: viser.ClientHandle) -> None:
        cid = client.client_id
        with self._lock:
            session = self.sessions.pop(cid, None)
            if session is None:  # its connect callback is late, or still building it
                self._gone.add(cid)
                if len(self._gone) > MAX_TOMBSTONES:  # connect never came for the oldest
                    self._gone.discard(min(self._gone))
        if session is not None:
            session.stop()

    def reap(self) -> int:
        """Forget sessions whose loop has ended (browser gone); returns how many remain."""
        with self._lock:
            for cid in [c for c, s in self.sessions.items() if s.finished]:
                del self.sessions[cid]
            return len(self.sessions)

    def stop(self) -> None:
        """Stop every session (all at once, then wait), then the server."""
        with self._lock:
            sessions = list(self.sessions.values())
            self.sessions.clear()
        for session in sessions:
            session.request_stop()
        for session in sessions:
            session.stop()
        self.server.stop()


def _tell(client: viser.ClientHandle, title: str, text: str) -> None:
    """A lasting red message in one browser (never raises: it may be gone already)."""
    try:
        client.add_notification(title, text, color="red", with_close_button=False)
    except Exception:
        log.debug("could not notify a browser", exc_info=True)


def bracket(host: str) -> str:
    return f"[{host}]" if ":" in host else host


CLOSED_CONNECTION = r"Queued an? \w+ on a closed connection"
"""viser's UserWarning when a message goes to a browser that has left. A session draws
until it sees its browser gone (ALIVE_CHECK, half a second), so every browser that leaves
would warn of the messages of that last half second, which nobody needs."""


def quiet_closed_connections() -> None:
    """Ignore viser's :data:`CLOSED_CONNECTION` warning (that one only: other warnings,
    viser's included, are shown as before). Idempotent and cheap when already first."""
    if warnings.filters:
        action, message, category, _, _ = warnings.filters[0]
        pattern = getattr(message, "pattern", None)
        if (action, pattern, category) == ("ignore", CLOSED_CONNECTION, UserWarning):
            return
    warnings.filterwarnings("ignore", message=CLOSED_CONNECTION, category=UserWarning)


def open_server(host: str, port: int, label: str, *, check: bool = True) -> viser.ViserServer:
    """A viser server on exactly ``host:port`` (BadOption when the port is taken)."""
    if check:
        check_port(host, port)
    network.quiet_viewer_logs()
    quiet_closed_connections()
    # viser prints its own address box (with "localhost" for 0.0.0.0, and the websocket
    # URL) and "Server stopped" through rich's global console; the teacher reads the
    # sandbox's banner instead, which names the addresses students type.
    rich.reconfigure(quiet=True)
    client_text.install()  # viser's own warnings and chart ticks in French
    server = viser.ViserServer(host=host, port=port, label=label, verbose=False)
    # Again at each browser: a ``warnings.catch_warnings`` block (pytest runs each test in
    # one, a notebook cell may) puts the filters back as they were when it ends, and the
    # server may outlive it.
    server.on_client_connect(lambda _client: quiet_closed_connections())
    light_the_scene(server)
    if network.handing_off():  # a worker: the front listens on the port, not viser
        return server
    if port != 0 and server.get_port() != port:  # lost a race for the port
        server.stop()
        raise BadOption(f"port {port} is in use; choose another one with --port")
    return server


SKY = "/lumiere_ciel"
"""Scene node of the light that replaces viser's environment map."""


def light_the_scene(server: viser.ViserServer) -> None:
    """viser's default lights without their shadow maps, and a sky light instead of the
    image of an environment (an HDR picture reflected by every surface).

    No solid of a scene receives a shadow, yet each drawn frame would render them
    (cascaded maps: a third of a frame's cost on a laptop or phone that draws the 3D
    without a graphics card). The environment's picture is prefiltered by the browser
    when the page opens: three seconds during which a page drawn without a graphics card
    takes no click (Chromium's software WebGL, measured), then a costlier shading of
    every pixel. A hemisphere light, white from above and grey from below, lights the
    faces the default lights miss, as the picture did."""
    server.scene.configure_default_lights(enabled=True, cast_shadow=False)
    server.scene.configure_environment_map(hdri=None)
    server.scene.add_light_hemisphere(
        SKY, sky_color=(255, 255, 255), ground_color=(100, 100, 100), intensity=2.0
    )


@contextlib.contextmanager
def stop_signals() -> Iterator[None]:
    """Within the block, Ctrl-C and SIGTERM raise KeyboardInterrupt in the main thread,
    whatever this process inherited: started from a script's background job or a desktop
    launcher, SIGINT arrives ignored (SIG_IGN). The first signal interrupts; later ones
    (the terminal, a proxy and the worker pool may each send one) are let pass until the
    block ends. Outside the main thread, nothing changes."""
    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGTERM, signal.SIGINT)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def run_forever(app: App) -> None:
    """Block until Ctrl-C or SIGTERM, then stop ``app`` (recordings are closed); see
    :func:`stop_signals` (a caller that prints an address before calling this installs
    them first, so that a Ctrl-C right after the address is not lost)."""
    with stop_signals():
        try:
            while True:
                time.sleep(0.5)
                app.reap()
        except KeyboardInterrupt:
            pass
        finally:
            app.stop()


def serve_until_stopped(start: Callable[[], App]) -> None:
    """``start`` an app and :func:`run_forever` it, the stop signals installed from before
    ``start`` prints its address: a Ctrl-C right after it is not lost."""
    with stop_signals():
        try:
            app = start()
        except KeyboardInterrupt:
            return
        run_forever(app)


def _interrupt(signum: int, frame: FrameType | None) -> None:
    """One-shot: let the next signals pass, then interrupt the main loop."""
    signal.signal(signal.SIGTERM, _let_pass)
    signal.signal(signal.SIGINT, _let_pass)
    raise KeyboardInterrupt


def _let_pass(signum: int, frame: FrameType | None) -> None:
    """A later signal while stopping: nothing to do. A Python handler, not SIG_IGN: a
    signal already received when the handler turns to SIG_IGN makes Python print
    "OSError: Signal 15 ignored due to race condition" with a traceback."""
