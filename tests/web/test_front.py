"""The front of ``serve --workers N``: each new connection to the least busy worker, on
any platform (no ``SO_REUSEPORT``): sessions of two workers differ by at most one."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import threading
import time

import pytest

from sandbox.web.serving.front import HEADERS_WAIT, Front, is_websocket

UPGRADE = (
    b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
    b"Sec-WebSocket-Version: 13\r\n\r\n"
)
PAGE = b"GET /index.html HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"


def test_a_websocket_request_is_told_from_a_page_request():
    assert is_websocket(UPGRADE) is True
    assert is_websocket(PAGE) is False
    assert is_websocket(UPGRADE.replace(b"Upgrade: websocket", b"UPGRADE:  WebSocket")) is True
    assert is_websocket(b"GET / HTTP/1.1\r\nHost: x\r\n") is None  # headers not all in
    assert is_websocket(b"X-Upgrade: websocket\r\n" * 1000) is False  # full, never ends
    # a header value naming websocket elsewhere does not count
    assert is_websocket(b"GET /websocket HTTP/1.1\r\nX-Note: websocket\r\n\r\n") is False


class Pipe:
    """A worker's pipe: what the front sends (the socket stays open for the test)."""

    def __init__(self) -> None:
        self.got: list[tuple[bool, socket.socket]] = []

    def send(self, item) -> None:
        websocket, sock = item
        self.got.append((websocket, sock.dup()))


@pytest.fixture
def front():
    listener = socket.create_server(("127.0.0.1", 0))
    pipes = [Pipe(), Pipe()]
    closed = [0, 0]
    made = Front(listener, pipes, closed)
    yield made, pipes, closed, listener.getsockname()[1]
    made.close()
    for pipe in pipes:
        for _, sock in pipe.got:
            sock.close()


def _connect(port: int, request: bytes | None) -> socket.socket:
    sock = socket.create_connection(("127.0.0.1", port))
    if request is not None:
        sock.sendall(request)
    return sock


def _poll_until(front: Front, count, timeout: float = 5.0) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end and not count():
        front.poll(0.05)


def test_websockets_go_to_the_worker_with_fewest_and_pages_in_turn(front):
    made, pipes, closed, port = front
    clients = [_connect(port, UPGRADE) for _ in range(31)]
    _poll_until(made, lambda: sum(len(p.got) for p in pipes) == 31)
    counts = [sum(ws for ws, _ in p.got) for p in pipes]
    assert sorted(counts) == [15, 16] and made.live() == counts
    # students of worker 0 leave: the next ones go to it until it catches up
    closed[0] += 5
    more = [_connect(port, UPGRADE) for _ in range(6)]
    _poll_until(made, lambda: sum(len(p.got) for p in pipes) == 37)
    live = made.live()
    assert abs(live[0] - live[1]) <= 1 and sum(live) == 37 - 5
    # page and file requests alternate, whatever the sessions
    before = [len(p.got) for p in pipes]
    pages = [_connect(port, PAGE) for _ in range(4)]
    _poll_until(made, lambda: sum(len(p.got) for p in pipes) == 41)
    assert [len(p.got) - b for p, b in zip(pipes, before, strict=True)] == [2, 2]
    assert made.live() == live  # pages are no sessions
    for sock in clients + more + pages:
        sock.close()


def test_slow_silent_and_vanishing_clients_hold_nobody(front, monkeypatch):
    made, pipes, _, port = front
    # headers in two parts: handed over once they are all in, as a websocket
    slow = _connect(port, UPGRADE[:20])
    made.poll(0.1)
    assert not any(p.got for p in pipes)
    slow.sendall(UPGRADE[20:])
    _poll_until(made, lambda: any(p.got for p in pipes))
    assert [ws for p in pipes for ws, _ in p.got] == [True]
    # a client that connects and leaves without a word is dropped
    gone = _connect(port, None)
    gone.close()
    for _ in range(5):
        made.poll(0.05)
    assert sum(len(p.got) for p in pipes) == 1 and not made._pending
    # a silent client is handed over as a page after HEADERS_WAIT (the worker times it out)
    now = [time.monotonic()]
    made.clock = lambda: now[0]
    silent = _connect(port, None)
    made.poll(0.1)
    assert len(made._pending) == 1
    now[0] += HEADERS_WAIT + 0.1
    made.poll(0.01)
    assert sum(len(p.got) for p in pipes) == 2 and not made._pending
    for sock in (slow, silent):
        sock.close()


def test_a_restarted_worker_starts_empty_and_waits_until_ready(front):
    made, pipes, closed, port = front
    socks = [_connect(port, UPGRADE) for _ in range(4)]
    _poll_until(made, lambda: sum(len(p.got) for p in pipes) == 4)
    assert made.live() == [2, 2]
    fresh = Pipe()
    made.replace(1, fresh)  # worker 1 died with its two sessions
    assert made.live() == [2, 0]
    socks.append(_connect(port, UPGRADE))
    _poll_until(made, lambda: len(pipes[0].got) == 3)
    assert not fresh.got  # not ready yet: the others take the newcomers
    made.set_ready(1)
    socks += [_connect(port, UPGRADE) for _ in range(3)]
    _poll_until(made, lambda: len(fresh.got) == 3)
    assert made.live() == [3, 3]
    for sock in socks:
        sock.close()


@pytest.mark.slow  # two worker processes and 31 websocket sessions: ~8 s
def test_thirty_one_browsers_split_16_15_over_two_workers_without_so_reuseport(tmp_path):
    """A real ``serve --workers 2`` and 31 headless browsers opening sessions at once:
    each worker holds 15 or 16 (the kernel's hash gave 22/8 and 30/0), and only the
    parent listens on the port: no ``SO_REUSEPORT`` (which macOS does not balance and
    Windows lacks)."""
    import asyncio

    from sandbox.bench import classroom
    from tests.conftest import serve_workers

    proc, port = serve_workers(tmp_path)
    try:
        assert "by 2 worker processes" in proc.stdout.readline()
        window = classroom.Window()
        stats = [classroom.ClientStats(i) for i in range(31)]
        done = threading.Event()

        async def browsers() -> None:
            url, origin = f"ws://127.0.0.1:{port}", f"http://127.0.0.1:{port}"
            tasks = [
                asyncio.create_task(classroom.run_client(url, s, window, origin=origin, param=None))
                for s in stats
            ]
            while not done.is_set():
                await asyncio.sleep(0.1)
            for t in tasks:
                t.cancel()

        thread = threading.Thread(target=asyncio.run, args=(browsers(),))
        thread.start()
        try:
            end = time.monotonic() + 60
            while time.monotonic() < end and not all(s.first_frame for s in stats):
                time.sleep(0.2)
            assert all(s.first_frame for s in stats), [s.error for s in stats if s.error]
            split = sorted(classroom.connections_per_process(proc.pid, port).values())
            assert split == [15, 16], split
            # one listening socket on the public port, the parent's: nothing shares it
            assert _listeners(proc.pid, port) == {proc.pid: 1}
        finally:
            done.set()
            thread.join(10)
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)


def _listeners(pid: int, port: int) -> dict[int, int]:
    """Sockets listening on ``port`` held by each process of ``pid``'s tree (Linux /proc):
    with SO_REUSEPORT every worker would hold one."""
    from sandbox.bench import classroom

    inodes: dict[str, int] = {}
    for p in classroom.process_tree(pid):
        try:
            fds = os.listdir(f"/proc/{p}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                link = os.readlink(f"/proc/{p}/fd/{fd}")
            except OSError:
                continue
            if link.startswith("socket:["):
                inodes[link[8:-1]] = p
    out: dict[int, int] = {}
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as fh:
            for line in fh.readlines()[1:]:
                cols = line.split()
                local, state, inode = cols[1], cols[3], cols[9]
                if state == "0A" and int(local.rsplit(":", 1)[1], 16) == port and inode in inodes:
                    out[inodes[inode]] = out.get(inodes[inode], 0) + 1
    return out
