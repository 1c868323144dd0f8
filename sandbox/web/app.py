"""The web app: a viser server giving every browser its own simulation of one target.

``serve`` blocks until Ctrl-C (``sandbox serve``); ``start`` returns a running
:class:`App` (tests, notebooks).
"""

from __future__ import annotations

import logging
import secrets
import signal
import socket
import sys
import threading
import time
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from types import FrameType
from typing import Any, TypedDict

import rich
import viser

from sandbox.errors import BadOption
from sandbox.lessons import is_lesson_file, open_lesson_file
from sandbox.physics.simulation import Simulation
from sandbox.web import client_text, network, share_panel
from sandbox.web.loop import Controller, Session
from sandbox.web.view import WebView

log = logging.getLogger(__name__)


class SimOptions(TypedDict):
    """Keyword arguments of :class:`Simulation` given to every session of a server."""

    values: Mapping[str, object]
    integrator: str | None
    timestep: float | None


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


MAX_SESSIONS = 60
"""Browsers one server process accepts; the next one is told the machine is full."""

SWITCH_INTERVAL = 0.0005
"""Seconds a thread may hold the interpreter lock while another waits (Python's
default 5 ms). The sessions' loop releases the lock inside every MuJoCo call; with
the default, each release could cost it 5 ms behind viser's sending thread."""

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
        return f"http://{_bracket(host)}:{self.port}"

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


def _bracket(host: str) -> str:
    return f"[{host}]" if ":" in host else host


PAGE_TITLE = "Dynamique des solides"
"""The page's name, at the top of its control panel (the product is ``sandbox`` only on
the command line)."""


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
        _check_port(host, port)
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
    if network.handing_off():  # a worker: the front listens on the port, not viser
        return server
    if port != 0 and server.get_port() != port:  # lost a race for the port
        server.stop()
        raise BadOption(f"port {port} is in use; choose another one with --port")
    return server


def run_forever(app: App) -> None:
    """Block until Ctrl-C or SIGTERM, then stop ``app`` (recordings are closed).

    The first signal stops the loop; later ones (the terminal, a proxy and the worker pool
    may each send one) are ignored until the recordings are closed."""
    main = threading.current_thread() is threading.main_thread()
    previous = {}
    if main:
        previous = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGTERM, signal.SIGINT)}
    try:
        while True:
            time.sleep(0.5)
            app.reap()
    except KeyboardInterrupt:
        pass
    finally:
        try:
            app.stop()
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)


def _interrupt(signum: int, frame: FrameType | None) -> None:
    """One-shot: let the next signals pass, then interrupt the main loop."""
    signal.signal(signal.SIGTERM, _let_pass)
    signal.signal(signal.SIGINT, _let_pass)
    raise KeyboardInterrupt


def _let_pass(signum: int, frame: FrameType | None) -> None:
    """A later signal while stopping: nothing to do. A Python handler, not SIG_IGN: a
    signal already received when the handler turns to SIG_IGN makes Python print
    "OSError: Signal 15 ignored due to race condition" with a traceback."""


def start(
    target: str | Path,
    *,
    host: str = "127.0.0.1",
    port: int = 8080,
    values: Mapping[str, object] | None = None,
    integrator: str | None = None,
    timestep: float | None = None,
    lesson: str | Path | None = None,
    open_message: bool = True,
    check_port: bool = True,
    max_sessions: int = MAX_SESSIONS,
    follow: bool = False,
    token: str | None = None,
    public_url: str | None = None,
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
        lesson: Lesson opened in every new browser (its scene is ``target``): a lesson's
            name, or the path of a lesson file (``*.md``, offered in this process with
            the shipped lessons, see :func:`sandbox.lessons.open_lesson_file`).
        open_message: Print the URL to open.
        check_port: Fail early when the port is taken (worker processes sharing the
            port skip it).
        max_sessions: Browsers served at once by this process.
        follow: One shared simulation driven by the teacher (link printed at start),
            watched by every other browser (:mod:`sandbox.web.follow`).
        token: Secret of the teacher's link (random when None).
        public_url: The address students type when they come through a proxy (shown
            in "Rejoindre" and printed instead of this machine's addresses); the
            websockets of pages loaded from it are accepted.

    Raises:
        SandboxError: bad target, value or option; BadOption when the port is taken.
    """
    network.install()
    network.reached_through(public_url)  # its handshakes are accepted too
    sys.setswitchinterval(SWITCH_INTERVAL)
    opened = None if lesson is None else str(lesson)
    if opened is not None and is_lesson_file(opened):  # in each worker too
        opened = open_lesson_file(Path(opened)).name
    options: SimOptions = {
        "values": dict(values or {}),
        "integrator": integrator,
        "timestep": timestep,
    }
    Simulation(target, **options)
    server = open_server(host, port, PAGE_TITLE, check=check_port)
    bound = port if network.handing_off() else server.get_port()
    urls = join_urls(host, bound, public_url)

    if follow:
        from sandbox.web.follow import FollowApp

        app: App = FollowApp(
            server, host, target, options, lesson=opened, token=token, join_urls=tuple(urls)
        )
    else:

        def session(client: viser.ClientHandle) -> Session:
            controller = Controller(Simulation(target, **options))
            view = WebView(client, controller, lesson=opened, join_urls=urls)
            share_panel.attach(server, client, view, lesson=opened)  # "Partager", a link
            return Session(controller, view)

        from sandbox.web.board_panel import ClassApp  # it builds on App: a cycle at import

        app = ClassApp(server, host, session, token=token, max_sessions=max_sessions, port=bound)
    if open_message:
        teacher = getattr(app, "teacher_url", None)
        print(banner(target, host, app.port, teacher=teacher, public_url=public_url), flush=True)
    return app


def _public(host: str) -> bool:
    """True when other machines can reach a server listening on ``host``."""
    return host not in ("127.0.0.1", "localhost", "::1") and not host.startswith("127.")


def join_urls(host: str, port: int, public_url: str | None = None) -> list[str]:
    """Addresses students type: ``public_url`` (a proxy's) when given, else this machine's
    LAN addresses when it listens beyond loopback, else none."""
    if public_url:
        return [public_url]
    return network.student_urls(host, port) if _public(host) else []


def banner(
    target: str | Path,
    host: str,
    port: int,
    *,
    workers: int = 1,
    teacher: str | None = None,
    public_url: str | None = None,
) -> str:
    """What ``sandbox serve`` prints once it listens: the addresses to open."""
    local = "127.0.0.1" if host in ("0.0.0.0", "", "::") else host
    local = f"[{local}]" if ":" in local else local
    how = f" by {workers} worker processes" if workers > 1 else ""
    lines = [f"sandbox: {target} served at http://{local}:{port}{how} (Ctrl-C to stop)"]
    if _public(host) or public_url:
        urls = join_urls(host, port, public_url)
        if urls:
            lines.append("sandbox: students open " + "  or  ".join(urls))
        else:
            lines.append("sandbox: no network address found: students cannot reach this machine")
    if teacher:
        lines.append(f"sandbox: teacher link (keep it to yourself) {teacher}")
    return "\n".join(lines)


def serve(target: str | Path, *, workers: int | None = None, **options: Any) -> None:
    """Serve ``target`` until Ctrl-C or SIGTERM (keyword arguments as for :func:`start`).

    Args:
        target: Scene name or MJCF path.
        workers: Server processes sharing the port (default one per core, at most 4; 1 serves
            from this process).
    """
    from sandbox.web.board_panel import teacher_path  # builds on App: a cycle at import
    from sandbox.web.workers import WorkerSpec, default_workers, serve_pool

    if options.get("follow"):
        if workers is not None and workers > 1:
            raise BadOption(
                "--follow serves one shared simulation from one process; drop --workers"
            )
        workers = 1
    count = default_workers() if workers is None else workers
    if count < 1:
        raise BadOption(f"--workers must be 1 or more, got {count!r}")
    if count == 1:
        run_forever(start(target, **options))
        return
    host = str(options.pop("host", "127.0.0.1"))
    port = int(options.pop("port", 8080))
    options.pop("open_message", None)
    options = {k: (dict(v) if k == "values" else v) for k, v in options.items()}
    Simulation(
        target,
        values=options.get("values") or {},
        integrator=options.get("integrator"),
        timestep=options.get("timestep"),
    )
    _check_port(host, port)
    if port == 0:
        port = _free_port(host)
    options["token"] = options.get("token") or secrets.token_urlsafe(9)  # one for every worker
    spec = WorkerSpec(str(target), host, port, options)
    local = "127.0.0.1" if host in ("0.0.0.0", "", "::") else host
    teacher = f"http://{_bracket(local)}:{port}{teacher_path(options['token'])}"
    text = banner(
        target, host, port, workers=count, teacher=teacher, public_url=options.get("public_url")
    )
    serve_pool(spec, count, banner=text)


def _free_port(host: str) -> int:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return int(sock.getsockname()[1])
