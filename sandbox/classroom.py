"""Classroom benchmark: one server, N headless browsers, what each of them gets.

Usage::

    sandbox bench --classroom 30 rotor [--seconds 15] [--follow] [--out r.json]

starts ``python -m sandbox.cli serve SCENE --port P`` on a free loopback port, opens N
websocket clients that speak viser's protocol exactly as the browser does (subprotocol
``viser-v<version>``, ``Origin: http://127.0.0.1:P``, a first ``ViewerCameraMessage``
that starts the per-browser session), waits for every client's first frame, warms up,
then measures for ``--seconds`` (all clients run in one asyncio loop and decode only
what they need). Afterwards it runs a connect-and-drop phase and an Origin probe, stops
the server and prints each target of issue 12 next to its value (PASS/FAIL words, never
asserted).

Definitions:

- **Update frame**: one websocket message from the server that carries at least one
  scene pose update (``SetPositionMessage``, ``SetOrientationMessage``, or new
  ``batched_positions`` / ``batched_wxyzs`` of batched nodes). Frames/s of
  a client = its update frames received in the measurement window / the window [s].
- **Simulated-time rate**: what the browser shows. The control panel's status line
  ``t = 12,35 s · vitesse ×1 …`` (``sandbox.web.panels.ControlPanel``, refreshed at
  10 Hz) is read from the wire; the rate of a client = (last t - first t) / (wall time
  between the two messages) inside the window [sim s per wall s].
- **Slider delay**: during the window each client toggles a parameter slider every
  :data:`PROBE_PERIOD` s between its initial value and that value plus a quarter of
  its range, as a ``GuiUpdateMessage`` (the browser's own message). It "shows" in the
  first server message received after the send that creates or removes a 3D node under
  ``/model``: the renderer rebuilt the geom the parameter changed (the rotor's
  correction mass ``mass1_g`` and the compressor's ``counterweight_mass`` appear or
  disappear). With ``--follow``, one extra client opens the teacher link the server
  prints (``/prof/<token>``) and toggles the shared simulation's slider; every one of the
  N followers waits for the change under ``/prof/model`` (N samples per change). Delay =
  receive time - send time [s]; a change not shown before the next toggle counts as
  *not shown*. Other scenes probe their first parameter, which may
  never show this way.
- **Server CPU**: user + system time (+ reaped children, on Linux) of the server
  process and all its descendants, over the window [cores]. **RSS**: sum of the
  resident sizes over that tree (shared pages count once per process) [bytes]. These,
  the threads' CPU and the browsers per worker process are read with psutil, the same
  way on Linux, macOS and Windows (the ``bench`` extra: ``pip install "sandbox[bench]"``).
- **Idle CPU**: after the main clients left and 3 s passed, 20 clients connect, send
  the camera message and close at once; the server tree's CPU is sampled each second
  for 10 s; idle = the mean over the last 2 s [cores].
- **Origin probe**: a handshake with ``Origin: http://evil.example``; *refused* means
  no session: the handshake fails, the connection closes, or no update frame arrives
  within 3 s.

``--out FILE.json`` also writes the results (other ``--out`` values are ignored here).
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import itertools
import math
import os
import random
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from collections.abc import Callable, Coroutine, Sequence
from dataclasses import dataclass, field
from types import ModuleType
from typing import TYPE_CHECKING, Any, TypeVar

import msgspec
import websockets
import websockets.exceptions
import zstandard

if TYPE_CHECKING:
    import psutil
    from websockets.asyncio.client import ClientConnection, connect

from sandbox.classroom_speed import SpeedProbe
from sandbox.classroom_workers import by_worker, worker_lines
from sandbox.cores import DEFAULT_WORKERS_CAP, default_workers
from sandbox.errors import BadOption

T = TypeVar("T")

Side = Callable[[str, str, "Window", list["ClientStats"]], Coroutine[Any, Any, dict[str, Any]]]
"""A task beside the clients of :func:`main_phase`: (url, origin, window, clients)."""

PROBE_PERIOD = 5.0
"""Seconds between two slider changes of one client."""

PANEL_PICKER = "Panneau affiché"
"""Label of the dropdown choosing the one readout folder shown (``panel=`` option)."""

TIME_BUTTONS = "Temps"
"""Label of the control panel's button group (Lecture/Pause, Pas, Réinitialiser)."""
PLAY = "Lecture"
"""The button that starts a scene that opens paused (the bench presses it, as a student
would, so that every scene is measured while it moves)."""
PAUSED = b"**en pause**"
"""What the status line says of a paused simulation (UTF-8, as on the wire)."""

PROBE_PARAMS = {
    "rotor": "mass1_g",
    "compressor": "counterweight_mass",
    "engine": "L",
}
"""Parameter slider toggled by the slider-delay probe (other scenes: their first). Each
changes what is drawn (the delay is seen as a 3D node made or removed) and hardly what a
step costs: the engine's first slider, its speed, would take half the class to 7250 rpm,
where the timestep is 3.5 times shorter (a class there costs what it costs: the benchmark
measures the scenes at their defaults); a longer rod keeps its timestep."""

POSE_MARKERS = (
    b"\xa4type\xb2SetPositionMessage",
    b"\xa4type\xb5SetOrientationMessage",
    b"\xb1batched_positions",
    b"\xadbatched_wxyzs",
)
"""msgpack bytes of ``"type": "SetPositionMessage"`` / ``"SetOrientationMessage"``, and of
the ``batched_positions`` / ``batched_wxyzs`` keys (batched meshes or axes moved by a
``SceneNodeUpdateMessage``), should the server draw the geoms that way."""

TYPE_MARKER = b"\xa4type"
STATUS_TIME = re.compile(rb"t = (-?[0-9](?:[0-9]|\xe2\x80\xaf)*(?:,[0-9]+)?) s \xc2\xb7 vitesse")
"""The simulated time in the control panel's status line (UTF-8 bytes on the wire)."""

FOREIGN_ORIGIN = "http://evil.example"
BIG_MESSAGE = 16_000
"""Bytes from which a server message counts as big (images, meshes, plot data)."""
_ZSTD = zstandard.ZstdDecompressor()


def _subprotocol() -> str:
    import viser

    return f"viser-v{viser.__version__}"


# -- statistics and processes --------------------------------------------------------------


def percentile(values: Sequence[float], q: float) -> float:
    """Linear-interpolation percentile (numpy's default); NaN for no values.

    Args:
        values: Samples.
        q: Percentile in [0, 100].
    """
    data = sorted(values)
    if not data:
        return math.nan
    pos = (len(data) - 1) * q / 100.0
    lo = math.floor(pos)
    hi = min(lo + 1, len(data) - 1)
    return data[lo] + (data[hi] - data[lo]) * (pos - lo)


def summary(values: Sequence[float]) -> dict[str, float]:
    """``min``, ``median``, ``p95`` and ``max`` of ``values`` (NaN when empty)."""
    if not values:
        return {k: math.nan for k in ("min", "median", "p95", "max")}
    return {
        "min": min(values),
        "median": statistics.median(values),
        "p95": percentile(values, 95),
        "max": max(values),
    }


PSUTIL_MISSING = (
    "the classroom benchmark measures the server's processes with psutil, which is not "
    'installed: pip install "sandbox[bench]" (or: pip install psutil)'
)


def _psutil() -> ModuleType:
    """psutil, imported on first use (the ``bench`` extra).

    Raises:
        BadOption: psutil is not installed; the message gives the install command.
    """
    try:
        import psutil
    except ImportError:
        raise BadOption(PSUTIL_MISSING) from None
    return psutil


def _tree(pid: int) -> list[psutil.Process]:
    """``pid``'s process and its live descendants (empty when ``pid`` is gone)."""
    ps = _psutil()
    try:
        root = ps.Process(pid)
        return [root, *root.children(recursive=True)]
    except ps.Error:
        return []


def process_tree(pid: int) -> list[int]:
    """``pid`` and all its live descendants (empty when ``pid`` is gone)."""
    return [p.pid for p in _tree(pid)]


def tree_cpu(pid: int) -> float:
    """CPU time [s] of ``pid`` and its descendants: user + system, reaped children too
    (the reaped children's part is known on Linux only; elsewhere psutil gives 0)."""
    ps, total = _psutil(), 0.0
    for p in _tree(pid):
        with contextlib.suppress(ps.Error):
            t = p.cpu_times()
            total += t.user + t.system + t.children_user + t.children_system
    return total


def tree_rss(pid: int) -> int:
    """Resident set size [bytes] summed over ``pid`` and its descendants."""
    ps, total = _psutil(), 0
    for p in _tree(pid):
        with contextlib.suppress(ps.Error):
            total += int(p.memory_info().rss)
    return total


def thread_cpu(pid: int) -> dict[tuple[int, int], float]:
    """CPU time [s] of every thread of ``pid``'s tree, keyed by (pid, tid).

    A process whose threads cannot be read (psutil's AccessDenied, e.g. another user's
    process on macOS) is left out: the figures then cover the threads that could be.
    """
    ps, out = _psutil(), {}
    for p in _tree(pid):
        with contextlib.suppress(ps.Error, NotImplementedError):
            for t in p.threads():
                out[(p.pid, t.id)] = t.user_time + t.system_time
    return out


def browsers_by_process(pid: int, port: int) -> dict[int, int]:
    """The process of ``pid``'s tree holding each established TCP connection on local
    ``port``: the connection's remote port (a browser's own) -> the process's pid."""
    ps, owner = _psutil(), {}
    for p in _tree(pid):
        with contextlib.suppress(ps.Error):
            # net_connections since psutil 6.0, connections before
            listed = getattr(p, "net_connections", None) or p.connections
            for c in listed(kind="tcp"):
                here = c.laddr and c.laddr.port == port
                if c.status == ps.CONN_ESTABLISHED and here and c.raddr:
                    owner[int(c.raddr.port)] = p.pid
    return owner


def connections_per_process(pid: int, port: int) -> dict[int, int]:
    """Established TCP connections on local ``port`` held by each process of the tree.

    Shows how the kernel spread the browsers over the server's worker processes.
    """
    return dict(collections.Counter(browsers_by_process(pid, port).values()))


def load_average() -> tuple[float, float, float] | None:
    """The system's 1, 5 and 15 min load averages; None where the OS has none (Windows)."""
    getloadavg = getattr(os, "getloadavg", None)
    if getloadavg is None:
        return None
    try:
        one, five, fifteen = getloadavg()
    except OSError:  # "load average was unobtainable"
        return None
    return (one, five, fifteen)


# -- the wire ------------------------------------------------------------------------------


def unpack(raw: bytes) -> bytes:
    """The msgpack part of a server websocket message (viser's zstd wire format).

    Layout: 8 bytes msgpack size, 8 bytes compressed size (little endian), the zstd
    frame, then raw binary buffers (meshes), which are not needed and not copied.
    """
    size = int.from_bytes(raw[:8], "little")
    clen = int.from_bytes(raw[8:16], "little")
    return _ZSTD.decompress(memoryview(raw)[16 : 16 + clen], max_output_size=size)


def is_update_frame(inner: bytes) -> bool:
    """True when the message carries a scene pose update (see module docstring)."""
    return any(marker in inner for marker in POSE_MARKERS)


def status_time(inner: bytes) -> float | None:
    """Simulated time [s] shown by the control panel's status line, if in the message."""
    found = STATUS_TIME.findall(inner)  # "1 234,56" (French: thin spaces, decimal comma)
    if not found:
        return None
    return float(found[-1].decode().replace("\u202f", "").replace(",", "."))


def messages(inner: bytes) -> list[dict[str, Any]]:
    """The decoded viser messages of one websocket message."""
    return msgspec.msgpack.decode(inner)["messages"]


def shows_rebuild(inner: bytes, prefixes: tuple[str, ...] = ("/model/", "/prof/model/")) -> bool:
    """True when a node under one of ``prefixes`` (a session's geoms, or the shared ones
    of ``--follow``) is created (has props) or removed."""
    if b"/model/" not in inner:
        return False
    for m in messages(inner):
        name = m.get("name")
        if isinstance(name, str) and name.startswith(prefixes):
            if "props" in m or m.get("type") == "RemoveSceneNodeMessage":
                return True
    return False


def find_gui(inner: bytes, kind: str, *names: str) -> dict[str, Any] | None:
    """The ``Gui<kind>Message`` labelled one of ``names`` or ``"name [unit]"``, if present."""
    if f"Gui{kind}Message".encode() not in inner:
        return None
    for m in messages(inner):
        if m.get("type") == f"Gui{kind}Message":
            label = str(m["props"]["label"])
            if any(label == name or label.startswith(f"{name} [") for name in names):
                return m
    return None


def find_slider(inner: bytes, param: str) -> dict[str, Any] | None:
    """The slider of parameter ``param``: the page labels it with the parameter's French
    words and unit ("Masse de correction m₁ [g]"), a file's parameter with its name."""
    from sandbox.scenes import SCENES

    words = {p.label for scene in SCENES.values() for p in scene.params if p.name == param}
    return find_gui(inner, "Slider", param, *sorted(w for w in words if w))


async def read_pages(ws: Any, learn: Callable[[bytes], None]) -> None:
    """Hand every binary websocket message, unpacked, to ``learn`` until the socket
    closes (a scripted student reading the page it is sent)."""
    async for raw in ws:
        if isinstance(raw, bytes):
            learn(unpack(raw))


def camera_message() -> bytes:
    """The browser's first message: its camera (starts the session)."""
    return msgspec.msgpack.encode(
        {
            "type": "ViewerCameraMessage",
            "wxyz": (1.0, 0.0, 0.0, 0.0),
            "position": (0.0, -1.0, 0.5),
            "fov": 1.0,
            "near": 0.01,
            "far": 1000.0,
            "image_height": 720,
            "image_width": 1280,
            "look_at": (0.0, 0.0, 0.0),
            "up_direction": (0.0, 0.0, 1.0),
        }
    )


def gui_message(uuid: str, value: Any) -> bytes:
    """The browser's message when the user sets an input (slider, dropdown) to ``value``."""
    return msgspec.msgpack.encode(
        {"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": value}}
    )


def slider_message(uuid: str, value: float) -> bytes:
    """The browser's message when a slider is moved to ``value``."""
    return gui_message(uuid, float(value))


# -- one headless client -------------------------------------------------------------------


@dataclass
class Window:
    """Measurement window on the ``time.perf_counter`` clock [s]."""

    start: float = math.inf
    end: float = math.inf

    def __contains__(self, now: float) -> bool:
        return self.start <= now < self.end


@dataclass
class ClientStats:
    """What one headless client saw; counts are inside the window only."""

    index: int
    first_frame: float | None = None  # perf_counter of the first update frame
    received: int = 0  # server messages, window or not
    last_frame: float | None = None  # perf_counter of the latest update frame
    max_gap: float = 0.0  # longest wait between two update frames in the window [s]
    big: int = 0  # messages of BIG_MESSAGE bytes or more in the window
    max_bytes: int = 0  # largest message in the window [bytes]
    error: str | None = None
    frames: int = 0
    frame_times: list[float] = field(default_factory=list)  # perf_counter, in the window
    ws_messages: int = 0
    viser_messages: int = 0
    wire_bytes: int = 0
    times: list[tuple[float, float]] = field(default_factory=list)  # (wall, sim) [s]
    delays: list[float] = field(default_factory=list)  # slider -> frame [s]
    not_shown: int = 0
    slider: dict[str, Any] | None = None
    picker: dict[str, Any] | None = None  # the panel dropdown, once chosen
    buttons: str | None = None  # uuid of the "Temps" button group, once seen
    played: bool = False  # "Lecture" pressed (the scene opened paused)
    pending: float | None = None  # perf_counter of the unshown slider change
    port: int | None = None  # local port of its connection (tells its server process)

    def feed(self, raw: bytes, now: float, window: Window) -> None:
        """Account for one server message received at ``now``."""
        inner = unpack(raw)
        self.received += 1
        frame = is_update_frame(inner)
        if frame and self.first_frame is None:
            self.first_frame = now
        if self.pending is not None and shows_rebuild(inner):
            self.delays.append(now - self.pending)
            self.pending = None
        if now in window:
            self.ws_messages += 1
            self.wire_bytes += len(raw)
            self.big += len(raw) >= BIG_MESSAGE
            self.max_bytes = max(self.max_bytes, len(raw))
            if frame and self.last_frame is not None:
                self.max_gap = max(self.max_gap, now - max(self.last_frame, window.start))
            self.viser_messages += inner.count(TYPE_MARKER)
            self.frames += frame
            if frame:
                self.frame_times.append(now)
            t = status_time(inner)
            if t is not None:
                self.times.append((now, t))
        if frame:
            self.last_frame = now

    def longest_gap(self, window: Window) -> float:
        """Longest time without an update frame inside the window, its end included [s]."""
        last = max(self.last_frame or window.start, window.start)
        return max(self.max_gap, window.end - min(last, window.end))

    def fps(self, window: Window) -> float:
        """Update frames per second over the window [1/s]."""
        return self.frames / (window.end - window.start)

    def sim_rate(self) -> float:
        """Simulated seconds per wall second seen in the status line (NaN if < 2 samples).
        A scene that starts its run again (the rolling cylinder past the plane's end: its
        time back to 0) is measured between its restarts (the two samples around one are
        left out: the end of the old run is not seen)."""
        pairs = [(w1 - w0, t1 - t0) for (w0, t0), (w1, t1) in itertools.pairwise(self.times)]
        wall = sum(w for w, t in pairs if t >= 0)
        return sum(t for _, t in pairs if t >= 0) / wall if wall > 0 else math.nan


def connect_as_browser(url: str, origin: str, *, open_timeout: float) -> connect:
    """A websocket connection opened as the browser opens it (viser's subprotocol, the
    page's Origin, no compression, no message size limit)."""
    return websockets.connect(
        url,
        subprotocols=[websockets.Subprotocol(_subprotocol())],
        origin=websockets.Origin(origin),
        max_size=None,
        compression=None,
        open_timeout=open_timeout,
        close_timeout=1,
    )


async def run_client(
    url: str,
    stats: ClientStats,
    window: Window,
    *,
    origin: str,
    param: str | None,
    seed: int = 0,
    watchers: Sequence[ClientStats] | None = None,
    panel: str | None = None,
    play: bool = True,
) -> None:
    """One browser: connect, send the camera, read until cancelled, probe a slider.

    Args:
        url: ``ws://127.0.0.1:P`` (``/prof/<token>`` appended for the teacher).
        stats: Filled in place.
        window: Measurement window (frames and probes count inside it only).
        origin: ``Origin`` header, as a browser on the page would send.
        param: Parameter slider to toggle, or None for no probe.
        seed: Seeds the probe's start offset.
        watchers: Clients whose view should show the slider change (default this one).
        panel: Readout folder to pick in the :data:`PANEL_PICKER` dropdown, as a
            student would (None: the page's default).
        play: Press « Lecture » when the simulation shows paused (a scene that opens
            paused is measured while it moves).
    """
    try:
        async with connect_as_browser(url, origin, open_timeout=30) as ws:
            stats.port = _local_port(ws)
            await ws.send(camera_message())
            prober = None
            if param is not None:
                watch = [stats] if watchers is None else list(watchers)
                prober = asyncio.create_task(_probe(ws, stats, window, random.Random(seed), watch))
            try:
                async for raw in ws:
                    assert isinstance(raw, bytes)
                    if stats.received < 200:
                        if stats.buttons is None:
                            found = find_gui(unpack(raw), "ButtonGroup", TIME_BUTTONS)
                            stats.buttons = None if found is None else str(found["uuid"])
                        paused = stats.buttons is not None and PAUSED in unpack(raw)
                        if play and paused and not stats.played and stats.buttons is not None:
                            stats.played = True  # the scene opened paused: press "Lecture"
                            await ws.send(gui_message(stats.buttons, PLAY))
                        if param is not None and stats.slider is None:
                            stats.slider = find_slider(unpack(raw), param)
                        if panel is not None and stats.picker is None:
                            stats.picker = find_gui(unpack(raw), "Dropdown", PANEL_PICKER)
                            if stats.picker is not None:
                                await ws.send(gui_message(stats.picker["uuid"], panel))
                    stats.feed(raw, time.perf_counter(), window)
            finally:
                if prober is not None:
                    prober.cancel()
    except asyncio.CancelledError:
        raise
    except Exception as exc:  # reported per client, the bench goes on
        stats.error = f"{type(exc).__name__}: {exc}"


def _local_port(ws: Any) -> int | None:
    """The local port of a client connection (None when the transport does not say)."""
    address = getattr(ws, "local_address", None)
    return int(address[1]) if isinstance(address, tuple) and len(address) >= 2 else None


async def _probe(
    ws: ClientConnection,
    stats: ClientStats,
    window: Window,
    rng: random.Random,
    watchers: Sequence[ClientStats],
) -> None:
    """Toggle ``stats.slider`` every :data:`PROBE_PERIOD` s; each of ``watchers`` then
    waits for the change to show (its ``pending`` is the send time)."""
    while not math.isfinite(window.start) or stats.slider is None:
        await asyncio.sleep(0.1)
    slider = stats.slider
    low = float(slider["value"])
    props = slider["props"]
    span = float(props["max"]) - float(props["min"])
    high = low + 0.25 * span if low + 0.25 * span <= float(props["max"]) else low - 0.25 * span
    on = False
    next_at = window.start + rng.uniform(0.0, PROBE_PERIOD)
    while next_at < window.end - 0.5:
        await asyncio.sleep(max(0.0, next_at - time.perf_counter()))
        on = not on
        sent = time.perf_counter()
        for w in watchers:
            w.not_shown += w.pending is not None
            w.pending = sent
        await ws.send(slider_message(slider["uuid"], high if on else low))
        next_at += PROBE_PERIOD
    await asyncio.sleep(max(0.0, window.end - time.perf_counter()))
    for w in watchers:
        w.not_shown += w.pending is not None
        w.pending = None


# -- the server ----------------------------------------------------------------------------


def free_port() -> int:
    """A TCP port free on 127.0.0.1 right now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


class Server:
    """``sandbox serve`` in its own process group; a context manager that always stops it.

    Args:
        scene: Scene, lesson or MJCF path.
        follow: Pass ``--follow``.
        workers: Pass ``--workers N`` when not None.
        timeout: Bound on the wait for the first HTTP answer [s].
    """

    def __init__(
        self, scene: str, *, follow: bool = False, workers: int | None = None, timeout: float = 60
    ) -> None:
        self.port = free_port()
        self.command = [sys.executable, "-m", "sandbox.cli", "serve", scene]
        self.command += ["--port", str(self.port)]
        self.command += ["--follow"] if follow else []
        self.command += ["--workers", str(workers)] if workers is not None else []
        self.timeout = timeout
        self.log = tempfile.TemporaryFile()
        self.proc: subprocess.Popen[bytes] | None = None

    @property
    def pid(self) -> int:
        """Process id of the server (root of its tree)."""
        assert self.proc is not None
        return self.proc.pid

    def __enter__(self) -> Server:
        self.proc = subprocess.Popen(
            self.command,
            stdin=subprocess.DEVNULL,
            stdout=self.log,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # POSIX: its own process group (ignored on Windows)
            # the French banner in the log, whatever the locale (cp1252 has no "≥" or "→")
            env={**os.environ, "PYTHONIOENCODING": "utf-8"},
        )
        try:
            self._wait_ready()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def output(self, *, head: bool = False) -> str:
        """What the server printed so far: its last 2000 characters (first 20,000 with
        ``head``, where the banner is)."""
        self.log.seek(0)
        if head:
            return self.log.read(20_000).decode(errors="replace")
        return self.log.read().decode(errors="replace")[-2000:]

    def teacher_path(self, timeout: float = 10.0) -> str | None:
        """``/prof/<token>`` from the teacher link the server printed (``--follow``)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            found = re.search(r"https?://\S+?(/prof/[A-Za-z0-9_-]+)", self.output(head=True))
            if found:
                return found.group(1)
            time.sleep(0.2)
        return None

    def _wait_ready(self) -> None:
        assert self.proc is not None
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise BadOption(
                    f"the server exited with code {self.proc.returncode}: "
                    f"{' '.join(self.command[2:])}\n{self.output().strip()}"
                )
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{self.port}/", timeout=1):
                    return
            except OSError:
                time.sleep(0.2)
        raise BadOption(f"the server did not answer on port {self.port} within {self.timeout} s")

    def stop(self) -> None:
        """SIGTERM (the server closes its sessions), then SIGKILL, to the whole group.

        Each signal gets a bounded wait; SIGINT is not used because a bench started in
        the background of a shell inherits it ignored, and so would the server. Where
        there are no process groups (Windows), the server's tree is terminated, then
        killed, through psutil.
        """
        proc = self.proc
        if proc is None:
            return
        if PROCESS_GROUPS:
            for sig, wait in ((signal.SIGTERM, 8.0), (signal.SIGKILL, 3.0)):
                if proc.poll() is not None:
                    break
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(proc.pid, sig)
                with contextlib.suppress(subprocess.TimeoutExpired):
                    proc.wait(wait)
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(proc.pid, signal.SIGKILL)  # leftovers of the group
        else:
            stop_tree(proc.pid)
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(3.0)
        self.log.close()
        self.proc = None


PROCESS_GROUPS = hasattr(os, "killpg")
"""POSIX: :meth:`Server.stop` signals the server's process group (it has its own)."""


def stop_tree(pid: int, *, wait: float = 8.0) -> None:
    """Terminate ``pid`` and its descendants, then kill those alive after ``wait`` [s]."""
    ps = _psutil()
    tree = _tree(pid)  # listed while the root lives: its children are found through it
    for p in tree:
        with contextlib.suppress(ps.Error):
            p.terminate()
    _, alive = ps.wait_procs(tree, timeout=wait)
    for p in alive:
        with contextlib.suppress(ps.Error):
            p.kill()
    ps.wait_procs(alive, timeout=3.0)


# -- the benchmark -------------------------------------------------------------------------


SERVE_WORKERS_CAP = DEFAULT_WORKERS_CAP
"""Worker processes ``sandbox serve`` starts at most by default (:mod:`sandbox.cores`)."""

_cores = default_workers
"""Worker processes ``sandbox serve`` starts by default (one count for both)."""


def probe_param(scene: str) -> str | None:
    """Slider toggled by the delay probe: :data:`PROBE_PARAMS`, else the scene's first."""
    if scene in PROBE_PARAMS:
        return PROBE_PARAMS[scene]
    from sandbox.scenes import SCENES

    params = SCENES[scene].params if scene in SCENES else ()
    return params[0].name if params else None


async def _wait_first_frames(
    stats: list[ClientStats], tasks: list[asyncio.Task[None]], limit: float
) -> None:
    deadline = time.perf_counter() + limit
    while time.perf_counter() < deadline:
        if all(s.first_frame is not None or t.done() for s, t in zip(stats, tasks, strict=True)):
            return
        await asyncio.sleep(0.1)


async def main_phase(
    server: Server,
    clients: int,
    *,
    seconds: float,
    warmup: float,
    param: str | None,
    teacher: str | None = None,
    panel: str | None = None,
    side: Side | None = None,
) -> dict[str, Any]:
    """N clients in this loop: warm up, then measure frames, sim rate, delays, CPU, RSS.

    Args:
        server: The running server.
        clients: Browsers measured.
        seconds: Measurement window [s].
        warmup: Wait after every client's first frame [s].
        param: Slider each client toggles (its own session), or None.
        teacher: With ``--follow``, the teacher's path (``/prof/<token>``): one more
            client opens it and toggles ``param`` on the shared simulation, and the
            delay is measured on every follower; the teacher is not in the statistics.
        panel: Readout folder every client picks (None: the default one).
        side: A task run beside the clients once they all draw (a hostile student:
            :mod:`sandbox.classroom_flood`), given the URL, the Origin, the window and
            the clients; what it returns is kept as ``main["side"]``.
    """
    url, origin = f"ws://127.0.0.1:{server.port}", f"http://127.0.0.1:{server.port}"
    window = Window()
    stats = [ClientStats(i) for i in range(clients)]
    tasks = []
    connect_start = time.perf_counter()
    for s in stats:
        probe = None if teacher else param
        tasks.append(
            asyncio.create_task(
                run_client(url, s, window, origin=origin, param=probe, seed=s.index, panel=panel)
            )
        )
    if teacher is not None:
        lead = ClientStats(-1)
        tasks.append(
            asyncio.create_task(
                run_client(url + teacher, lead, window, origin=origin, param=param, watchers=stats)
            )
        )
    try:
        await _wait_first_frames(stats, tasks[:clients], 30.0 + 0.5 * clients)
        ready = time.perf_counter() - connect_start
        beside = None
        if side is not None:
            beside = asyncio.create_task(side(url, origin, window, stats))
        await asyncio.sleep(warmup)
        speed = SpeedProbe()
        speed.start()
        own0, cpu0, threads0 = time.process_time(), tree_cpu(server.pid), thread_cpu(server.pid)
        window.start = time.perf_counter()
        window.end = window.start + seconds
        rss: list[int] = []
        while time.perf_counter() < window.end:
            rss.append(tree_rss(server.pid))
            await asyncio.sleep(min(1.0, max(0.0, window.end - time.perf_counter())))
        cpu1, threads1, own1 = tree_cpu(server.pid), thread_cpu(server.pid), time.process_time()
        machine_ms = speed.stop()
        rss.append(tree_rss(server.pid))
        processes = len(process_tree(server.pid))
        owner = browsers_by_process(server.pid, server.port)
        spread = sorted(collections.Counter(owner.values()).values(), reverse=True)
        side_result = None
        if beside is not None:
            side_result = await asyncio.wait_for(beside, timeout=30.0)
    finally:
        for t in tasks:
            t.cancel()
        await asyncio.wait(tasks, timeout=5.0)
    fps = [s.fps(window) for s in stats]
    rates = [r for r in (s.sim_rate() for s in stats) if math.isfinite(r)]
    delays = [d for s in stats for d in s.delays]
    used = {k: (threads1[k] - threads0.get(k, 0.0)) / seconds for k in threads1}
    threads = sorted(used.values(), reverse=True)
    frames = sum(s.frames for s in stats)
    ws_msgs = sum(s.ws_messages for s in stats)
    wire = sum(s.wire_bytes for s in stats)
    return {
        "clients": clients,
        "panel": panel,
        "panel_picked": sum(s.picker is not None for s in stats),
        "played": sum(bool(s.played) for s in stats),
        "connected": sum(s.first_frame is not None for s in stats),
        "errors": sorted({s.error for s in stats if s.error}),
        "ready_s": ready,
        "seconds": seconds,
        "warmup_s": warmup,
        "fps": summary(fps),
        "fps_per_client": fps,
        "messages_per_client": [s.ws_messages for s in stats],
        "sim_rate": summary(rates),
        "sim_rate_per_client": [s.sim_rate() for s in stats],
        "sim_rate_samples": len(rates),
        "slider_param": param,
        "slider_delay_s": summary(delays),
        "slider_samples": len(delays),
        "slider_not_shown": sum(s.not_shown for s in stats),
        "server_cpu_cores": (cpu1 - cpu0) / seconds,
        "server_cpu_ms_per_frame": (cpu1 - cpu0) * 1000.0 / frames if frames else math.nan,
        "server_processes": processes,
        "clients_per_process": spread,
        "server_threads": len(threads1),
        "server_top_thread_cores": threads[:6],
        "workers": by_worker(fps, [s.port for s in stats], owner, used),
        "server_rss_bytes": max(rss),
        "bench_cpu_cores": (own1 - own0) / seconds,
        "machine_probe_ms": machine_ms,
        "per_client_ws_messages_per_s": ws_msgs / seconds / clients,
        "per_client_kbytes_per_s": wire / seconds / clients / 1000.0,
        "bytes_per_ws_message": wire / ws_msgs if ws_msgs else math.nan,
        "viser_messages_per_ws_message": (
            sum(s.viser_messages for s in stats) / ws_msgs if ws_msgs else math.nan
        ),
        "update_frames_share": frames / ws_msgs if ws_msgs else math.nan,
        "longest_frame_gap_s": summary([s.longest_gap(window) for s in stats]),
        "big_messages_per_client_per_s": sum(s.big for s in stats) / seconds / clients,
        "largest_message_bytes": max((s.max_bytes for s in stats), default=0),
        "side": side_result,
    }


async def drop_phase(
    server: Server, *, clients: int = 20, settle: float = 3.0, seconds: float = 10.0
) -> dict[str, Any]:
    """Clients that connect, send the camera and drop; then the server's CPU each second.

    Returns:
        ``cores_per_s`` (one value per second after the drop) and ``idle_cores`` (mean
        of the last 2 s).
    """
    url, origin = f"ws://127.0.0.1:{server.port}", f"http://127.0.0.1:{server.port}"
    await asyncio.sleep(settle)
    camera = camera_message()

    async def one() -> bool:
        try:
            async with connect_as_browser(url, origin, open_timeout=10) as ws:
                await ws.send(camera)
            return True
        except Exception:
            return False

    ok = await asyncio.wait_for(asyncio.gather(*(one() for _ in range(clients))), 30.0)
    cores, last = [], (time.perf_counter(), tree_cpu(server.pid))
    for _ in range(int(seconds)):
        await asyncio.sleep(1.0)
        now = (time.perf_counter(), tree_cpu(server.pid))
        cores.append((now[1] - last[1]) / (now[0] - last[0]))
        last = now
    tail = cores[-2:] if cores else [math.nan]
    return {
        "clients": clients,
        "connected": sum(ok),
        "cores_per_s": cores,
        "idle_cores": sum(tail) / len(tail),
    }


async def origin_probe(
    port: int, *, origin: str = FOREIGN_ORIGIN, wait: float = 3.0
) -> tuple[bool, str]:
    """Whether a page from ``origin`` is refused a session, and how.

    Returns:
        (refused, detail): refused is True when no update frame arrived.
    """
    try:
        async with connect_as_browser(f"ws://127.0.0.1:{port}", origin, open_timeout=10) as ws:
            await ws.send(camera_message())
            deadline = time.perf_counter() + wait
            while (left := deadline - time.perf_counter()) > 0:
                try:
                    raw = await asyncio.wait_for(ws.recv(), left)
                except TimeoutError:
                    break
                if isinstance(raw, bytes) and is_update_frame(unpack(raw)):
                    return False, "accepted: the session sent update frames"
            return True, f"handshake accepted but no update frame within {wait:g} s"
    except websockets.exceptions.InvalidStatus as exc:
        return True, f"handshake refused (HTTP {exc.response.status_code})"
    except websockets.exceptions.ConnectionClosed as exc:
        code = exc.rcvd.code if exc.rcvd is not None else None
        return True, f"connection closed by the server (code {code})"
    except (websockets.exceptions.InvalidHandshake, OSError, TimeoutError) as exc:
        return True, f"handshake failed ({type(exc).__name__}: {exc})"


def run_async(coro: Coroutine[Any, Any, T]) -> T:
    """``asyncio.run(coro)`` in a thread of its own: the caller's thread may already run
    an event loop (Playwright's sync API does, in the test suite)."""
    values: list[T] = []
    errors: list[BaseException] = []

    def body() -> None:
        try:
            values.append(asyncio.run(coro))
        except BaseException as exc:  # re-raised in the caller's thread
            errors.append(exc)

    worker = threading.Thread(target=body, name="classroom-bench")
    worker.start()
    worker.join()
    if errors:
        raise errors[0]
    return values[0]


STALL = 2.0
"""A browser that waited this long [s] for a frame is a defect to explain: the report then
prints the end of the server's output (warnings, tracebacks) with the figures."""


def run_classroom(
    scene: str,
    clients: int,
    *,
    seconds: float = 15.0,
    warmup: float = 3.0,
    follow: bool = False,
    workers: int | None = None,
    drop_clients: int = 20,
    idle_seconds: float = 10.0,
    panel: str | None = None,
    progress: Callable[[str], None] | None = None,
    side: Side | None = None,
) -> dict[str, Any]:
    """Start a server, run the main phase, the connect-and-drop phase and the Origin probe.

    Args:
        scene: Scene (or lesson, or MJCF path) served.
        clients: Headless browsers in the main phase.
        seconds: Measurement window [s].
        warmup: Wait after every client's first frame [s].
        follow: Serve with ``--follow``: ``clients`` followers plus one teacher client
            (the link the server prints) that toggles the slider of the shared simulation.
        workers: Pass ``--workers`` to the server when not None.
        drop_clients: Connect-and-drop clients (0 skips that phase).
        idle_seconds: CPU sampling after the drop [s].
        panel: Readout folder every client picks in :data:`PANEL_PICKER` (e.g.
            ``"Tous les panneaux"``, ``"Précision et coût"``); None keeps the default.
        progress: Called with one line per phase.
        side: A task beside the clients (:func:`main_phase`).

    Returns:
        JSON-able results (see :func:`report`).
    """
    say = progress or (lambda _line: None)
    _psutil()  # missing: say how to install it before a server starts
    load = load_average()
    param = probe_param(scene)
    with Server(scene, follow=follow, workers=workers) as server:
        teacher = server.teacher_path() if follow else None
        if follow and teacher is None:
            say("no teacher link in the server's output: no slider probe")

        async def all_phases() -> dict[str, Any]:
            who = " following a teacher" if teacher else ""
            say(f"{clients} clients{who} on {scene} (port {server.port}) ...")
            main = await main_phase(
                server,
                clients,
                seconds=seconds,
                warmup=warmup,
                param=param if (teacher or not follow) else None,
                teacher=teacher,
                panel=panel,
                side=side,
            )
            out: dict[str, Any] = {"main": main}
            if main["longest_frame_gap_s"]["max"] >= STALL:  # what the server said then
                out["server_output"] = server.output()
            if drop_clients > 0:
                say(f"{drop_clients} connect-and-drop clients, then {idle_seconds:g} s idle ...")
                out["drop"] = await drop_phase(server, clients=drop_clients, seconds=idle_seconds)
            refused, detail = await origin_probe(server.port)
            out["origin"] = {"origin": FOREIGN_ORIGIN, "refused": refused, "detail": detail}
            return out

        results = run_async(all_phases())
    results.update(
        scene=scene,
        follow=follow,
        workers=workers,
        worker_count=1 if follow else (workers if workers is not None else _cores()),
        date=time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        cpus=os.cpu_count(),
        load_average_before=load,
        load_average_after=load_average(),
    )
    results["targets"] = targets(results)
    return results


@dataclass(frozen=True)
class Target:
    """One target of issue 12: ``value(results) op limit`` for ``browsers`` clients."""

    label: str
    key: str
    op: str  # ">=", "<=", "<" or "is"
    limit: float
    browsers: int | None = None


CLASS_TARGETS = (
    Target("median update frames/s >= 45", "fps.median", ">=", 45, 30),
    Target("min update frames/s >= 30", "fps.min", ">=", 30, 30),
    Target("simulated time >= 0.98 of real time (slowest)", "sim_rate.min", ">=", 0.98, 30),
    Target("server CPU per update frame <= 0.4 ms", "server_cpu_ms_per_frame", "<=", 0.4, 30),
    Target("worker sessions within one of each other", "split", "<=", 1),
)
"""Issue 20: what a class of 30, each with their own simulation, gets in every scene."""
CROWD_TARGETS = (
    Target("median update frames/s >= 30", "fps.median", ">=", 30, 60),
    Target("simulated time >= 0.98 of real time (slowest)", "sim_rate.min", ">=", 0.98, 60),
    Target("worker sessions within one of each other", "split", "<=", 1),
)
"""Sixty browsers on one laptop (the rotor): slower, never behind real time."""
FOLLOW_TARGETS = (
    Target("--follow: median update frames/s >= 30", "fps.median", ">=", 30, 120),
    Target("--follow: server CPU <= 1 core", "server_cpu_cores", "<=", 1.0, 120),
)
FLOOD_TARGET = Target(
    'a student flooding "Pas" leaves the others >= 80 % of their frames/s',
    "side.ratio_min",
    ">=",
    0.8,
)
COMMON_TARGETS = (
    Target("idle after 20 connect-and-drop: < 0.05 cores within 10 s", "idle", "<", 0.05),
    Target("a foreign Origin gets no session", "origin", "is", 1.0),
)
CROWD = 45
"""From this many browsers a run is judged by :data:`CROWD_TARGETS`."""


def split(results: dict[str, Any]) -> float:
    """Largest difference between the browsers of two worker processes (0 for one)."""
    counts = list(results["main"]["clients_per_process"])
    workers = results.get("worker_count") or len(counts)
    counts += [0] * max(0, int(workers) - len(counts))
    return float(max(counts) - min(counts)) if len(counts) > 1 else 0.0


def _value(results: dict[str, Any], key: str) -> float:
    if key == "idle":
        return results["drop"]["idle_cores"] if "drop" in results else math.nan
    if key == "origin":
        return float(results["origin"]["refused"])
    if key == "split":
        return split(results)
    value: Any = results["main"]
    for part in key.split("."):
        value = value[part]
    return float(value)


def targets(results: dict[str, Any]) -> list[dict[str, Any]]:
    """The targets that apply to this run, each with its value and PASS/FAIL."""
    chosen: tuple[Target, ...]
    if results["follow"]:
        chosen = FOLLOW_TARGETS
    elif results["main"]["clients"] >= CROWD:
        chosen = CROWD_TARGETS
    else:
        chosen = CLASS_TARGETS
    if isinstance(results["main"].get("side"), dict) and "ratio_min" in results["main"]["side"]:
        chosen += (FLOOD_TARGET,)
    out = []
    for t in chosen + COMMON_TARGETS:
        if t.key == "idle" and "drop" not in results:
            continue  # connect-and-drop phase not run
        if t.key == "origin" and "origin" not in results:
            continue
        value = _value(results, t.key)
        ok = {
            ">=": value >= t.limit,
            "<=": value <= t.limit,
            "<": value < t.limit,
            "is": value == t.limit,
        }[t.op]
        out.append(
            {
                "target": t.label,
                "key": t.key,
                "value": value,
                "browsers": t.browsers,
                "verdict": "PASS" if ok else "FAIL",
            }
        )
    return out


def report(results: dict[str, Any]) -> str:
    """Human-readable lines: measurements, then each target with PASS/FAIL."""
    m = results["main"]
    fps, rate, delay = m["fps"], m["sim_rate"], m["slider_delay_s"]
    mode = " --follow" if results["follow"] else ""
    lines = [
        f"classroom: {results['scene']}{mode}, {m['clients']} clients "
        f"({m['connected']} got frames, ready after {m['ready_s']:.1f} s), "
        f"{m['seconds']:g} s measured after {m['warmup_s']:g} s warm-up, {results['date']}"
        + (f"; {m['played']} pressed « Lecture »" if m.get("played") else "")
        + (
            f"; panel {m['panel']!r} picked by {m['panel_picked']}"
            if m.get("panel") is not None
            else ""
        ),
        f"  update frames/s per client   min {fps['min']:.1f}  median {fps['median']:.1f}"
        f"  max {fps['max']:.1f}",
        f"  simulated s per wall s       min {rate['min']:.3f}  median {rate['median']:.3f}"
        f"  ({m['sim_rate_samples']} clients)",
        f"  server CPU                   {m['server_cpu_cores']:.2f} cores "
        f"({m['server_processes']} process(es), clients per process "
        f"{'/'.join(str(n) for n in m['clients_per_process'])}, {m['server_threads']} threads; "
        "busiest " + ", ".join(f"{c:.2f}" for c in m["server_top_thread_cores"][:4]) + ")",
        f"  server CPU per update frame  {m['server_cpu_ms_per_frame']:.2f} ms (all clients' "
        "frames; lower is better, less sensitive to other load than frames/s)",
        *worker_lines(m.get("workers", [])),
        f"  server RSS                   {m['server_rss_bytes'] / 1e6:.0f} MB",
        f"  slider -> first frame        p95 {delay['p95'] * 1000:.0f} ms  median "
        f"{delay['median'] * 1000:.0f} ms  ({m['slider_param']}: {m['slider_samples']} "
        f"shown, {m['slider_not_shown']} not shown)",
        f"  traffic per client           {m['per_client_ws_messages_per_s']:.1f} messages/s, "
        f"{m['per_client_kbytes_per_s']:.1f} kB/s, {m['bytes_per_ws_message']:.0f} B and "
        f"{m['viser_messages_per_ws_message']:.1f} viser messages per websocket message",
        f"  longest wait for a frame     median {m['longest_frame_gap_s']['median']:.2f} s  "
        f"max {m['longest_frame_gap_s']['max']:.2f} s; messages >= {BIG_MESSAGE // 1000} kB: "
        f"{m['big_messages_per_client_per_s']:.2f}/s per client, largest "
        f"{m['largest_message_bytes'] / 1000:.0f} kB",
        f"  bench clients' own CPU       {m['bench_cpu_cores']:.2f} cores",
        f"  machine speed probe          {m.get('machine_probe_ms', math.nan):.2f} ms for a "
        "fixed piece of work, median over the window (lower is faster; the processor's "
        "speed on a small piece of work, whatever the server does)",
    ]
    if m["errors"]:
        lines.append(f"  client errors: {'; '.join(m['errors'][:3])}")
    said = results.get("server_output")
    if said:
        lines.append(f"  a browser waited over {STALL:g} s for a frame; the server's last lines:")
        lines += [f"    | {line}" for line in said.strip().splitlines()[-12:]]
    side = m.get("side")
    if isinstance(side, dict) and "ratio_min" in side:
        lines.append(
            f'  a student flooding "Pas"    {side["clicks"]} clicks ({side["refused"]} refused'
            f"): the others' frames/s median {side['fps_before']:.1f} before, "
            f"{side['fps_during']:.1f} during; worst client keeps {side['ratio_min']:.2f}"
            + (f"; flooder error: {side['error']}" if side.get("error") else "")
        )
    if isinstance(side, dict) and "students" in side:
        lines.append(
            f"  {side['students']} more students running {side.get('work', 'studies')}: "
            f"{side['studies_finished']} finished ({side['studies_started']} started); "
            f"the others' slowest frames/s {side['others_fps_min']:.1f}"
            + (f"; errors: {'; '.join(side['errors'][:2])}" if side.get("errors") else "")
        )
    if "drop" in results:
        d = results["drop"]
        series = " ".join(f"{c:.2f}" for c in d["cores_per_s"])
        lines.append(
            f"  after {d['clients']} connect-and-drop ({d['connected']} connected): "
            f"server cores each second {series}"
        )
    o = results["origin"]
    lines.append(
        f"  Origin {o['origin']}: {'refused' if o['refused'] else 'ACCEPTED'} ({o['detail']})"
    )
    lines.append("targets (issues 12 and 20; printed, never asserted):")
    for t in results["targets"]:
        note = ""
        if t["browsers"] is not None and t["browsers"] != m["clients"]:
            note = f"  (target for {t['browsers']} browsers, measured with {m['clients']})"
        if t["target"].endswith("no session"):
            value = "refused" if t["value"] else "accepted"
        elif "fps" in t["key"]:
            value = f"{t['value']:.1f}"
        else:
            value = f"{t['value']:.3f}"
        lines.append(f"  {t['verdict']:<4}  {t['target']:<58} {value}{note}")
    return "\n".join(lines)


def jsonable(value: Any) -> Any:
    """``value`` with NaN and infinities as None and tuples as lists (strict JSON)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    return value
