"""Starting the web app in this process: ``start`` returns a running app for one target
(tests, notebooks, each worker of ``sandbox serve --workers N``), with the banner that
names the addresses to open.
"""

from __future__ import annotations

import logging
import sys
import threading
from collections.abc import Callable, Mapping
from pathlib import Path

import viser

from sandbox.lessons import is_lesson_file, open_lesson_file
from sandbox.physics.limits import machine_bytes
from sandbox.physics.simulation import Simulation
from sandbox.scenes import resolve
from sandbox.web.loop import Controller, first_estimate
from sandbox.web.serving import addresses, network
from sandbox.web.serving.class_app import ClassApp
from sandbox.web.serving.class_board import Classroom
from sandbox.web.serving.follow import FollowApp
from sandbox.web.serving.own_page import OwnPage, own_page
from sandbox.web.serving.server import MAX_SESSIONS, SimOptions, open_server

log = logging.getLogger(__name__)

SWITCH_INTERVAL = 0.0005
"""Seconds a thread may hold the interpreter lock while another waits (Python's
default 5 ms). The sessions' loop releases the lock inside every MuJoCo call; with
the default, each release could cost it 5 ms behind viser's sending thread."""


PAGE_TITLE = "Dynamique des solides"
"""The page's name, at the top of its control panel (the product is ``sandbox`` only on
the command line)."""


def start(
    target: str | Path,
    *,
    host: str = "127.0.0.1",
    port: int = 8080,
    values: Mapping[str, object] | None = None,
    integrator: str | None = None,
    timestep: float | None = None,
    motion: str | None = None,
    lesson: str | Path | None = None,
    open_message: bool = True,
    check_port: bool = True,
    max_sessions: int = MAX_SESSIONS,
    follow: bool = False,
    token: str | None = None,
    public_url: str | None = None,
    max_memory: float | None = None,
) -> ClassApp | FollowApp:
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
        motion: "imposed" or "free" for a scene with an imposed input (None: its own).
        lesson: Lesson opened in every new browser (its scene is ``target``): a lesson's
            name, or the path of a lesson file (``*.md``, offered in this process with
            the shipped lessons, see :func:`sandbox.lessons.open_lesson_file`).
        open_message: Print the URL to open.
        check_port: Fail early when the port is taken (worker processes sharing the
            port skip it).
        max_sessions: Browsers served at once by this process.
        follow: One shared simulation driven by the teacher (link printed at start),
            watched by every other browser (:mod:`sandbox.web.serving.follow`).
        token: Secret of the teacher's link (random when None).
        public_url: The address students type when they come through a proxy (shown
            in "Rejoindre" and printed instead of this machine's addresses); the
            websockets of pages loaded from it are accepted.
        max_memory: What the MJCF file ``target`` names may take to compile [MB]
            (``--max-memory``; None: half the machine's memory). Files a browser sends
            keep their own limit.

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
        "motion": motion,
    }
    source = resolve(target, max_bytes=machine_bytes(max_memory))
    Simulation(source, **options)
    server = open_server(host, port, PAGE_TITLE, check=check_port)
    bound = port if network.handing_off() else server.get_port()
    urls = join_urls(host, bound, public_url)

    if follow:
        app: ClassApp | FollowApp = FollowApp(
            server, host, source, options, lesson=opened, token=token, join_urls=tuple(urls)
        )
    else:

        def session(client: viser.ClientHandle) -> OwnPage:
            controller = Controller(Simulation(source, **options))
            return own_page(server, client, controller, lesson=opened, join_urls=urls)

        app = ClassApp(
            server,
            host,
            session,
            token=token,
            max_sessions=max_sessions,
            port=bound,
            shared=lambda: Controller(Simulation(source, **options)),
        )
    measure_capacity(app.classroom, lambda: Controller(Simulation(source, **options)))
    if open_message:
        teacher = app.teacher_url
        print(banner(target, host, app.port, teacher=teacher, public_url=public_url), flush=True)
    return app


STOP_WAIT = 15.0
"""Seconds a stopping server waits at most for its first capacity estimate to end."""


def measure_capacity(classroom: Classroom, controller: Callable[[], Controller]) -> None:
    """The first capacity estimate, before any student: one session of the served scene
    measured for two seconds in a thread of its own (:mod:`sandbox.web.loop.first_estimate`),
    then given to the class board."""

    stop = threading.Event()

    def run() -> None:
        try:
            load = first_estimate.measure(controller, stop=stop)
            if not stop.is_set():
                classroom.first = load
        except Exception:  # an estimate is a bonus: the board waits for the live one
            log.exception("the first capacity estimate failed")

    thread = threading.Thread(target=run, name="sandbox-capacity", daemon=True)

    def cleanup() -> None:  # a server stopped within its first seconds: wait for it
        stop.set()
        # The stop is seen between two frames; building the session (compiling the
        # model) is not interrupted, and a busy machine may take seconds over it. A
        # process that exits while this thread is still in MuJoCo's C code can crash
        # (seen once: a Ctrl-C right after the address, the machine loaded, exit -11).
        thread.join(STOP_WAIT)

    classroom.cleanups.append(cleanup)
    thread.start()


def _public(host: str) -> bool:
    """True when other machines can reach a server listening on ``host``."""
    return host not in ("127.0.0.1", "localhost", "::1") and not host.startswith("127.")


def join_urls(host: str, port: int, public_url: str | None = None) -> list[str]:
    """Addresses students type: ``public_url`` (a proxy's) when given, else this machine's
    LAN addresses when it listens beyond loopback, else none."""
    if public_url:
        return [public_url]
    return addresses.student_urls(host, port) if _public(host) else []


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
