"""Hostile uploads: viser would buffer the parts of a "file" announced for any input id
(issue 22, item 2). A crafted upload closes that connection, stores nothing and leaves
the server's memory at idle; a real upload button still takes files up to the cap.

The flood runs against ``sandbox serve`` in a child process, whose resident memory is
read from ``/proc``; the upload buttons (the app has none) are made on a bare viser
server in this process, with :mod:`sandbox.web.client.uploads` installed as the app installs it.
"""

from __future__ import annotations

import asyncio
import logging
import subprocess
import sys
import threading
import time
from collections.abc import Awaitable, Callable, Iterator
from pathlib import Path
from typing import Any

import msgspec
import pytest
from conftest import wait_for

from sandbox.web.client import uploads

MIB = 2**20
FLOOD_PART = 8 * MIB  # the parts
FLOOD_PARTS = 14  # 112 MiB offered by each browser
FLOOD_VISITS = 3
RSS_BOUND = 30 * 10**6  # growth allowed after the flood [bytes]; the issue saw +511 MB
PAGE_PART = 512 * 1024  # what viser's page sends

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")


def _free_port() -> int:
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _rss(pid: int) -> int:
    """Resident memory of process ``pid`` [bytes] (VmRSS)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    raise AssertionError("no VmRSS")


def _start(source: str, transfer: str, size: int, parts: int) -> bytes:
    return msgspec.msgpack.encode(
        {
            "type": "FileTransferStartUpload",
            "source_component_uuid": source,
            "transfer_uuid": transfer,
            "filename": "x.bin",
            "mime_type": "application/octet-stream",
            "part_count": parts,
            "size_bytes": size,
        }
    )


def _part(source: str, transfer: str, index: int, content: bytes) -> bytes:
    return msgspec.msgpack.encode(
        {
            "type": "FileTransferPart",
            "source_component_uuid": source,
            "transfer_uuid": transfer,
            "part_index": index,
            "content": content,
        }
    )


def _page_upload(source: str, transfer: str, data: bytes) -> list[bytes]:
    """The messages viser's page sends for ``data`` (512 KiB parts)."""
    chunks = [data[i : i + PAGE_PART] for i in range(0, len(data), PAGE_PART)]
    return [_start(source, transfer, len(data), len(chunks))] + [
        _part(source, transfer, i, c) for i, c in enumerate(chunks)
    ]


class Raw:
    """A raw websocket browser: the GUI messages it was sent, acks, whether it was closed."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.guis: dict[str, str] = {}  # label -> uuid
        self.acks: list[dict[str, Any]] = []
        self.closed = False
        self.sent = 0
        self.stored = -1  # uploads the server held at some point of the visit

    def connect(self) -> Any:
        from sandbox.bench.classroom import connect_as_browser

        url, origin = f"ws://127.0.0.1:{self.port}", f"http://127.0.0.1:{self.port}"
        return connect_as_browser(url, origin, open_timeout=10)

    async def read(self, ws: Any, until: Callable[[], bool], timeout: float) -> None:
        from sandbox.bench.classroom import messages, unpack

        end = time.monotonic() + timeout
        while time.monotonic() < end and not until():
            try:
                raw = await asyncio.wait_for(ws.recv(), 0.2)
            except TimeoutError:
                continue
            except Exception:  # closed by the server
                self.closed = True
                return
            for m in messages(unpack(raw)):
                if "label" in m.get("props", {}):
                    self.guis[str(m["props"]["label"])] = str(m["uuid"])
                elif m.get("type") == "FileTransferPartAck":
                    self.acks.append(m)

    async def send(self, ws: Any, frames: list[bytes]) -> None:
        """Send ``frames`` until the server closes the connection."""
        try:
            for frame in frames:
                await ws.send(frame)
                self.sent += 1
        except Exception:
            self.closed = True


def _visit(fn: Callable[[], Awaitable[None]]) -> None:
    """Run one browser's visit on its own thread and event loop."""
    failure: list[BaseException] = []

    def run() -> None:
        try:
            asyncio.run(asyncio.wait_for(fn(), 60))
        except BaseException as exc:  # noqa: BLE001  (raised in the test below)
            failure.append(exc)

    thread = threading.Thread(target=run)
    thread.start()
    thread.join(70)
    if failure:
        raise failure[0]


# -- the flood, against `sandbox serve` in a child process ----------------------------------


class Served:
    def __init__(self, proc: subprocess.Popen[str], port: int, log: Path) -> None:
        self.proc, self.port, self.log = proc, port, log

    def visit(self, actions: Callable[[Any, Raw], Awaitable[None]] | None = None) -> Raw:
        """A browser that opens the page (waits for its controls), then ``actions``."""
        from sandbox.bench.classroom import camera_message

        b = Raw(self.port)

        async def go() -> None:
            async with b.connect() as ws:
                await ws.send(camera_message())
                await b.read(ws, lambda: "Solide" in b.guis, timeout=15.0)
                if actions is not None:
                    await actions(ws, b)

        _visit(go)
        return b


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    cwd = tmp_path_factory.mktemp("serve")
    port = _free_port()
    log = cwd / "server.log"
    with log.open("w") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "sandbox.cli", "serve", "rotor", "--port", str(port)]
            + ["--workers", "1"],
            stdout=out,
            stderr=subprocess.STDOUT,
            text=True,
            cwd=cwd,
            start_new_session=True,
        )
    try:
        end = time.monotonic() + 30
        while "served at" not in log.read_text() and time.monotonic() < end:
            assert proc.poll() is None, log.read_text()
            time.sleep(0.1)
        s = Served(proc, port, log)
        for _ in range(2):  # warm up: the first sessions' allocations are not the flood's
            s.visit()
        sizes = [_rss(proc.pid)]  # then its size settles (three reads within 1 MiB)

        def settled() -> bool:
            sizes.append(_rss(proc.pid))
            return len(sizes) >= 3 and max(sizes[-3:]) - min(sizes[-3:]) < MIB

        wait_for(settled, timeout=10, poll=0.2)
        yield s
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.mark.parametrize("target", ["made-up id", "slider"])
def test_an_upload_flood_closes_that_connection_and_memory_returns_to_idle(served, target):
    """Three browsers each offer 112 MiB in 8 MiB parts of a "file" of 10⁹ parts: each
    connection is closed at its first upload message, and once they are gone the server
    is within 30 MB of its size before. viser alone (measured with this test) kept them:
    +112 MiB against a slider for one browser, and +45 MiB for a made-up id, where
    nothing is stored but the freed frames were never given back to the system."""
    logged = len(served.log.read_text().splitlines())
    before = _rss(served.proc.pid)

    async def flood(ws: Any, b: Raw) -> None:
        source = b.guis["Vitesse ×"] if target == "slider" else "no-such-id"
        blob = b"\0" * FLOOD_PART
        frames = [_start(source, "t", FLOOD_PART * 10**9, 10**9)]
        frames += [_part(source, "t", i, blob) for i in range(FLOOD_PARTS)]
        await b.send(ws, frames)
        await b.read(ws, lambda: b.closed, timeout=3.0)

    browsers = [served.visit(flood) for _ in range(FLOOD_VISITS)]
    # the memory is given back TRIM_DELAY after the connections closed (a loaded machine
    # may free later)
    wait_for(lambda: _rss(served.proc.pid) - before < RSS_BOUND, uploads.TRIM_DELAY + 6, 0.2)
    after = _rss(served.proc.pid)
    assert after - before < RSS_BOUND, f"{before / MIB:.0f} -> {after / MIB:.0f} MiB"
    assert all(b.closed for b in browsers)
    # the server goes on serving, and said it once per connection
    assert "Solide" in served.visit().guis and served.proc.poll() is None
    lines = served.log.read_text().splitlines()[logged:]
    assert len([line for line in lines if "upload" in line]) == FLOOD_VISITS, lines
    assert not [line for line in lines if "Traceback" in line], lines


# -- upload buttons, on a bare viser server in this process ---------------------------------


class Buttons:
    """A viser server with a shared upload button and one per browser, and a slider."""

    def __init__(self) -> None:
        import viser

        uploads.install()
        self.files: list[tuple[str, bytes]] = []
        self.arrived = threading.Condition()
        self.server = viser.ViserServer(host="127.0.0.1", port=_free_port(), verbose=False)
        self.port = self.server.get_port()
        self.shared = self.server.gui.add_upload_button("Partagé")
        self.shared.on_upload(lambda e: self._got("Partagé", e.target.value.content))
        self.server.gui.add_slider("Curseur", min=0.0, max=1.0, step=0.1, initial_value=0.5)

        @self.server.on_client_connect
        def _(client: Any) -> None:
            own = client.gui.add_upload_button("Le mien")
            own.on_upload(lambda e: self._got("Le mien", e.target.value.content))

    def _got(self, label: str, content: bytes) -> None:
        with self.arrived:
            self.files.append((label, content))
            self.arrived.notify_all()

    def wait_files(self, count: int, timeout: float = 10.0) -> list[tuple[str, bytes]]:
        with self.arrived:
            self.arrived.wait_for(lambda: len(self.files) >= count, timeout)
            return list(self.files)

    def buffered(self) -> int:
        """Upload transfers viser holds, shared and of every browser."""
        guis = [self.server.gui] + [c.gui for c in self.server.get_clients().values()]
        return sum(len(g._current_file_upload_states) for g in guis)

    def visit(self, actions: Callable[[Any, Raw], Awaitable[None]]) -> Raw:
        """A browser that opens the page (viser takes it in at its first camera message)
        and waits for the three controls, then ``actions``."""
        from sandbox.bench.classroom import camera_message

        b = Raw(self.port)

        async def go() -> None:
            async with b.connect() as ws:
                await ws.send(camera_message())
                await b.read(ws, lambda: {"Partagé", "Le mien", "Curseur"} <= set(b.guis), 10)
                await actions(ws, b)

        _visit(go)
        return b


@pytest.fixture
def buttons() -> Iterator[Buttons]:
    app = Buttons()
    try:
        yield app
    finally:
        app.server.stop()


def _upload_lines(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == uploads.__name__]


def test_files_up_to_the_cap_reach_both_upload_buttons(buttons, caplog):
    """16 MiB to the shared button and a 3-part file to the browser's own, as the page
    sends them: both arrive whole, acknowledged part by part; nothing is left buffered."""
    big = bytes(range(256)) * (uploads.MAX_UPLOAD_BYTES // 256)
    small = b"abc" * 400_000  # 1.2 MB: 3 parts

    async def actions(ws: Any, b: Raw) -> None:
        await b.send(ws, _page_upload(b.guis["Partagé"], "t1", big))
        await b.read(ws, lambda: len(b.acks) == 32, timeout=10.0)
        await b.send(ws, _page_upload(b.guis["Le mien"], "t2", small))
        await b.read(ws, lambda: len(b.acks) == 35, timeout=10.0)

    b = buttons.visit(actions)
    assert not b.closed and len(b.acks) == 35
    assert b.acks[31]["transferred_bytes"] == b.acks[31]["total_bytes"] == len(big)
    assert sorted(buttons.wait_files(2)) == [("Le mien", small), ("Partagé", big)]
    assert buttons.buffered() == 0 and _upload_lines(caplog) == []


def test_a_file_over_the_cap_is_refused_and_the_page_stays_open(buttons, caplog):
    """One byte over 16 MiB: no part is stored nor acknowledged, the connection stays
    open (a real page can do this) and a file within the cap goes through after it."""
    caplog.set_level(logging.WARNING)
    over = b"x" * (uploads.MAX_UPLOAD_BYTES + 1)

    async def actions(ws: Any, b: Raw) -> None:
        await b.send(ws, _page_upload(b.guis["Partagé"], "big", over))
        await b.read(ws, lambda: False, timeout=1.0)
        b.stored = buttons.buffered()
        await b.send(ws, _page_upload(b.guis["Partagé"], "ok", b"fine"))
        await b.read(ws, lambda: len(b.acks) == 1, timeout=5.0)

    b = buttons.visit(actions)
    assert b.stored == 0 and not b.closed
    assert [a["transfer_uuid"] for a in b.acks] == ["ok"]
    assert buttons.wait_files(1) == [("Partagé", b"fine")]
    assert _upload_lines(caplog) == [
        f"browser 0: refused a file of {len(over)} bytes (at most {uploads.MAX_UPLOAD_BYTES});"
        " its parts are dropped"
    ]


def _crafted(case: str, b: Raw) -> list[bytes]:
    """The messages of ``case`` (see CRAFTED), for browser ``b``."""
    shared, own, slider = b.guis["Partagé"], b.guis["Le mien"], b.guis["Curseur"]
    kib = b"y" * 1024
    return {
        "to a slider": [_start(slider, "t", 1024, 1), _part(slider, "t", 0, kib)],
        "part never announced": [_part(shared, "t", 0, kib)],
        "beyond the declared size": [_start(shared, "t", 1024, 2), _part(shared, "t", 0, kib * 2)],
        "10⁹ parts": [_start(shared, "t", MIB, 10**9)],
        "other button's part": [_start(shared, "t", 2048, 2), _part(own, "t", 0, kib)],
        "announced twice": [_start(shared, "t", 2048, 2)] * 2,
        "big part of a refused file": [
            _start(shared, "t", 10**9, 1000),
            _part(shared, "t", 0, b"z" * (PAGE_PART + 1)),
        ],
        "more parts than announced": [_start(shared, "t", 10**9, 2)]
        + [_part(shared, "t", i, kib) for i in range(3)],
        "nine files too big": [_start(shared, f"t{i}", 10**9, 1000) for i in range(9)],
    }[case]


CRAFTED = [
    "to a slider",
    "part never announced",
    "beyond the declared size",
    "10⁹ parts",
    "other button's part",
    "announced twice",
    "big part of a refused file",
    "more parts than announced",
    "nine files too big",
]
"""Upload messages viser's page never sends."""


@pytest.mark.parametrize("case", CRAFTED)
def test_a_crafted_upload_closes_that_connection_only(buttons, caplog, case):
    """What viser's page never sends: that connection is closed with one log line and
    nothing buffered, while another browser, connected all along, still uploads."""
    caplog.set_level(logging.WARNING)
    ready, done = threading.Event(), threading.Event()
    bystander: list[Raw] = []

    async def stay(ws: Any, b: Raw) -> None:
        ready.set()
        while not done.is_set():
            await b.read(ws, lambda: False, timeout=0.2)
        await b.send(ws, _page_upload(b.guis["Le mien"], "mine", b"still here"))
        await b.read(ws, lambda: len(b.acks) == 1, timeout=5.0)

    thread = threading.Thread(target=lambda: bystander.append(buttons.visit(stay)))
    thread.start()
    assert ready.wait(15)

    async def actions(ws: Any, b: Raw) -> None:
        await b.send(ws, _crafted(case, b))
        await b.read(ws, lambda: b.closed, timeout=3.0)

    b = buttons.visit(actions)
    done.set()
    thread.join(30)
    assert b.closed and buttons.buffered() == 0
    assert not bystander[0].closed and len(bystander[0].acks) == 1
    assert buttons.wait_files(1) == [("Le mien", b"still here")]
    lines = _upload_lines(caplog)
    assert len(lines) == 1, lines  # a refused file's line, or the closing one
    assert lines[0].endswith("connection closed") or "refused a file" in lines[0], lines


def test_files_over_the_connection_cap_at_once_are_refused(buttons, caplog):
    """10 MiB announced to each button at once: the second is refused (16 MiB in
    progress at most per connection); once the first is done, a second goes through."""
    caplog.set_level(logging.WARNING)
    ten = b"t" * (10 * MIB)

    async def actions(ws: Any, b: Raw) -> None:
        first = _page_upload(b.guis["Partagé"], "a", ten)
        await b.send(ws, first[:1] + _page_upload(b.guis["Le mien"], "b", ten) + first[1:])
        await b.read(ws, lambda: len(b.acks) == 20, timeout=10.0)
        await b.send(ws, _page_upload(b.guis["Le mien"], "c", ten))
        await b.read(ws, lambda: len(b.acks) == 40, timeout=10.0)

    b = buttons.visit(actions)
    assert not b.closed and {a["transfer_uuid"] for a in b.acks} == {"a", "c"}
    assert sorted(buttons.wait_files(2)) == [("Le mien", ten), ("Partagé", ten)]
    assert _upload_lines(caplog) == [
        f"browser 0: refused uploads of {20 * MIB} bytes at once; its parts are dropped"
    ]


def test_no_malloc_trim_outside_glibc(monkeypatch):
    """Windows has no CDLL(None) (TypeError), macOS no malloc_trim (AttributeError): the
    memory hand-back is then skipped, never an error at import."""
    import ctypes

    from sandbox.web.client import uploads

    for error in (TypeError, AttributeError, OSError):

        def missing(*_args, _error=error, **_kwargs):
            raise _error("not here")

        monkeypatch.setattr(ctypes, "CDLL", missing)
        assert uploads._libc_trim() is None
