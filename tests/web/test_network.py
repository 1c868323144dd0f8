"""Handshakes the server accepts, the addresses it prints and the join panel."""

from __future__ import annotations

import asyncio
import concurrent.futures
import ipaddress
import threading

import pytest
import viser

from sandbox.cli import build_parser
from sandbox.errors import BadOption
from sandbox.web.panels.join import join_html
from sandbox.web.serving import addresses, network
from sandbox.web.serving.app import banner

UPGRADE = {"Upgrade": "websocket", "Host": "192.168.1.20:8080"}
SERVED = network.Served(
    frozenset({"localhost", "127.0.0.1", "::1", "192.168.1.20"}),
    8080,
    frozenset({("sandbox.lycee.fr", 80), ("tls.lycee.fr", 443)}),
)
"""A server reached at 192.168.1.20:8080 (or on loopback), behind two proxies."""

REBINDING = {
    "Upgrade": "websocket",
    "Host": "evil.attacker:8080",
    "Origin": "http://evil.attacker:8080",
}
"""A DNS-rebinding page: evil.attacker now resolves to the server, the browser sends the
attacker's name as both Host and Origin (they agree with each other)."""


@pytest.mark.parametrize(
    "headers",
    [
        REBINDING,
        dict(REBINDING, Host="evil.attacker", Origin="http://evil.attacker"),
        dict(REBINDING, Host="evil.attacker:80", Origin="http://sandbox.lycee.fr"),
        dict(UPGRADE, Origin="http://evil.example"),
        dict(UPGRADE, Origin="http://192.168.1.20:8081"),  # another port on the same machine
        dict(UPGRADE, Origin="null"),
        dict(UPGRADE, Origin="http://192.168.1.20.evil.example:8080"),
        dict(UPGRADE, Origin="http://localhost.evil.example:8080"),
        dict(UPGRADE, Host="192.168.1.20:8081", Origin="http://192.168.1.20:8081"),
        # the proxy's name on the machine's own port is not the proxy's address
        dict(UPGRADE, Host="sandbox.lycee.fr:8080", Origin="http://sandbox.lycee.fr:8080"),
        dict(UPGRADE, Host="tls.lycee.fr", Origin="http://tls.lycee.fr"),  # 80, not 443
        {"Upgrade": "websocket", "Host": "evil.attacker:8080"},  # a program, foreign Host
        dict(UPGRADE, Host="a b:8080"),
        dict(UPGRADE, Host="user@127.0.0.1:8080"),
        {"Upgrade": "websocket", "Origin": "http://127.0.0.1:8080"},  # no Host
    ],
)
def test_a_foreign_or_rebound_handshake_is_refused(headers):
    assert network.origin_refusal(headers, SERVED) is not None


@pytest.mark.parametrize(
    "headers",
    [
        dict(UPGRADE, Origin="http://192.168.1.20:8080"),
        dict(UPGRADE, Origin="HTTP://192.168.1.20:8080"),
        # behind a TLS proxy the browser's Origin is https with the address it reached
        dict(UPGRADE, Origin="https://192.168.1.20:8080"),
        {"Upgrade": "websocket", "Host": "127.0.0.1:8080", "Origin": "http://127.0.0.1:8080"},
        {"Upgrade": "websocket", "Host": "localhost:8080", "Origin": "http://localhost:8080"},
        {"Upgrade": "websocket", "Host": "LocalHost.:8080", "Origin": "http://localhost:8080"},
        {"Upgrade": "websocket", "Host": "[::1]:8080", "Origin": "http://[::1]:8080"},
        {
            "Upgrade": "websocket",
            "Host": "app.localhost:8080",
            "Origin": "http://app.localhost:8080",
        },
        {"Upgrade": "websocket", "Host": "127.0.0.1:8080", "Origin": "http://localhost:8080"},
        {"Upgrade": "websocket", "Host": "sandbox.lycee.fr", "Origin": "http://sandbox.lycee.fr"},
        {
            "Upgrade": "websocket",
            "Host": "sandbox.lycee.fr:80",
            "Origin": "http://sandbox.lycee.fr",
        },
        {"Upgrade": "websocket", "Host": "tls.lycee.fr", "Origin": "https://tls.lycee.fr"},
        dict(UPGRADE),  # no Origin: a program, not a web page
        {"Upgrade": "websocket"},  # a program that sends no Host either
        # plain HTTP: the page itself, whatever its Host (deploy/haproxy.cfg's health
        # check sends "Host: sandbox"; the page holds nothing private)
        {"Host": "evil.attacker:8080", "Origin": "http://evil.attacker:8080"},
    ],
)
def test_the_servers_own_pages_and_programs_are_accepted(headers):
    assert network.origin_refusal(headers, SERVED) is None


def test_the_served_addresses_follow_the_interface_and_the_proxy(monkeypatch):
    monkeypatch.setattr(addresses, "lan_addresses", lambda: ["192.168.1.20", "10.0.0.5"])
    everywhere = network.Served.of("0.0.0.0").on(("::ffff:172.16.0.9", 8080, 0, 0))
    assert {"localhost", "127.0.0.1", "::1", "192.168.1.20", "10.0.0.5"} <= everywhere.names
    assert "172.16.0.9" in everywhere.names  # the address this connection reached
    assert everywhere.serves("10.0.0.5", 8080) and not everywhere.serves("10.0.0.5", 8081)
    one = network.Served.of("192.168.1.20", public_url="https://Sandbox.Lycee.fr/")
    assert "10.0.0.5" not in one.names and one.public == {("sandbox.lycee.fr", 443)}
    assert not one.serves("192.168.1.20", 8080)  # no connection yet: no port known
    assert one.on(("192.168.1.20", 8080)).serves("192.168.1.20", 8080)
    assert one.serves("sandbox.lycee.fr", None)
    with pytest.raises(BadOption, match="--public-url must be an http"):
        network.reached_through("ftp://sandbox.lycee.fr")
    network.reached_through(None)


def _handshake(
    port: int, origin: str | None, *, host: str | None = None, address: str = "127.0.0.1"
) -> int:
    """HTTP status of a websocket handshake to ``address:port`` (101 when accepted),
    with ``Host: host`` (default: the address itself) and ``Origin: origin``."""
    import socket

    import websockets.asyncio.client as ws_client
    from websockets.exceptions import InvalidStatus

    async def attempt() -> int:
        headers = {"Origin": origin} if origin else None
        sock = socket.create_connection((address, port), timeout=5)
        try:
            async with ws_client.connect(
                f"ws://{host or f'{address}:{port}'}/",
                sock=sock,  # the Host header names ``host``, the socket reaches ``address``
                additional_headers=headers,
                subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
                open_timeout=5,
            ):
                return 101
        except InvalidStatus as exc:
            return exc.response.status_code

    # In a thread of its own: Playwright's sync API may hold an event loop in this one.
    result: list[int] = []
    worker = threading.Thread(target=lambda: result.append(asyncio.run(attempt())))
    worker.start()
    worker.join(20)
    return result[0]


def _page_status(port: int, host: str, address: str = "127.0.0.1") -> int:
    """HTTP status of ``GET /`` to ``address:port`` with ``Host: host``."""
    import http.client

    connection = http.client.HTTPConnection(address, port, timeout=10)
    try:
        connection.request("GET", "/", headers={"Host": host})
        return connection.getresponse().status
    finally:
        connection.close()


def test_the_real_server_refuses_a_foreign_origin(served_rotor):
    port = served_rotor.port
    assert _handshake(port, "http://evil.example") == 403
    assert _handshake(port, f"http://127.0.0.1:{port}") == 101
    assert _handshake(port, None) == 101


def test_the_real_server_refuses_a_dns_rebinding_page(served_rotor):
    port = served_rotor.port
    evil = f"evil.attacker:{port}"
    assert _handshake(port, f"http://{evil}", host=evil) == 403
    assert _handshake(port, None, host=evil) == 403  # a program must name this server too
    assert _handshake(port, f"http://localhost:{port}", host=f"localhost:{port}") == 101
    assert _handshake(port, f"http://127.0.0.1:{port}", host=f"localhost:{port}") == 101
    # The page itself is served whatever its Host (see the docstring of network.py).
    assert _page_status(port, evil) == 200


def test_a_server_on_every_interface_serves_this_machines_lan_address():
    from sandbox.web.serving.app import start
    from tests.conftest import free_port

    lan = addresses.lan_addresses()
    if not lan:
        pytest.skip("this machine has no network address besides loopback")
    app = start("rotor", host="0.0.0.0", port=free_port(), open_message=False)
    try:
        port, ip = app.port, lan[0]
        assert _handshake(port, f"http://{ip}:{port}", address=ip) == 101
        assert _handshake(port, f"http://localhost:{port}", host=f"localhost:{port}") == 101
        evil = f"evil.attacker:{port}"
        assert _handshake(port, f"http://{evil}", host=evil, address=ip) == 403
        assert _handshake(port, f"http://{ip}:{port + 1}", address=ip) == 403
    finally:
        app.stop()


def test_a_server_behind_a_proxy_serves_the_public_url():
    from sandbox.web.serving.app import start
    from tests.conftest import free_port

    app = start("rotor", port=free_port(), open_message=False, public_url="https://sb.test")
    try:
        port = app.port
        assert _handshake(port, "https://sb.test", host="sb.test") == 101
        assert _handshake(port, "https://sb.test", host="sb.test:443") == 101
        assert _handshake(port, f"http://sb.test:{port}", host=f"sb.test:{port}") == 403
        assert _handshake(port, "https://evil.attacker", host="evil.attacker") == 403
    finally:
        app.stop()


def test_lan_addresses_are_reachable_ipv4_addresses():
    for text in addresses.lan_addresses():
        ip = ipaddress.IPv4Address(text)
        assert not ip.is_loopback and not ip.is_link_local


def test_lan_addresses_outside_linux_come_from_the_routing_table(monkeypatch):
    """macOS and Windows have no SIOCGIFADDR: the UDP-connect trick names the address
    the machine sends from, the one the Linux path finds here first."""
    linux = addresses.lan_addresses()
    monkeypatch.setattr(addresses.sys, "platform", "darwin")
    assert addresses._interface_addresses() == []
    elsewhere = addresses.lan_addresses()
    if not linux:
        pytest.skip("this machine has no LAN address")
    assert elsewhere and set(elsewhere) <= set(linux)
    assert elsewhere[0] == linux[0]


def test_student_urls_and_banner(monkeypatch):
    monkeypatch.setattr(addresses, "lan_addresses", lambda: ["192.168.1.20", "10.0.0.5"])
    assert addresses.student_urls("0.0.0.0", 8080) == [
        "http://192.168.1.20:8080",
        "http://10.0.0.5:8080",
    ]
    assert addresses.student_urls("192.168.1.20", 9000) == ["http://192.168.1.20:9000"]
    text = banner("rotor", "0.0.0.0", 8080, workers=2)
    assert "http://127.0.0.1:8080 by 2 worker processes" in text
    assert "students open http://192.168.1.20:8080" in text
    assert "127.0.0.1" not in text.splitlines()[1]
    assert "students" not in banner("rotor", "127.0.0.1", 8080)
    monkeypatch.setattr(addresses, "lan_addresses", lambda: [])
    assert "no network address" in banner("rotor", "0.0.0.0", 8080)


def test_join_panel_shows_the_address_and_a_qr_code_escaped():
    page = join_html(["http://192.168.1.20:8080", "http://<b>x</b>:1"])
    assert "http://192.168.1.20:8080" in page and "<svg" in page
    assert "<b>x</b>" not in page and "&lt;b&gt;" in page
    assert "réseau local" in join_html([])


@pytest.mark.parametrize(
    "argv, host, port, workers",
    [
        (["--host", "0.0.0.0", "--port", "9001", "serve", "rotor"], "0.0.0.0", 9001, None),
        (["serve", "rotor", "--host", "0.0.0.0", "--port", "9002"], "0.0.0.0", 9002, None),
        (["--port", "9003", "serve", "rotor", "--workers", "1"], "127.0.0.1", 9003, 1),
        (["--workers", "3", "serve"], "127.0.0.1", 8080, 3),
        (["--host", "0.0.0.0"], "0.0.0.0", 8080, None),
    ],
)
def test_host_and_port_count_before_and_after_the_command(argv, host, port, workers):
    args = build_parser().parse_args(argv)
    assert (args.host, args.port, args.workers) == (host, port, workers)


def test_serve_passes_its_options_on(monkeypatch):
    from sandbox import cli
    from sandbox.web.serving import app

    seen = {}
    monkeypatch.setattr(app, "serve", lambda target, **kw: seen.update(kw, target=target))
    assert cli.main(["--host", "0.0.0.0", "--port", "9010", "serve", "rotor"]) == 0
    assert (seen["host"], seen["port"], seen["target"]) == ("0.0.0.0", 9010, "rotor")
    assert cli.main(["serve", "rotor", "--workers", "0"]) == 2


@pytest.mark.slow  # spawns worker processes that import mujoco and viser: 2.7-6 s
def test_workers_share_one_port_and_stop_cleanly(tmp_path):
    """`sandbox serve --workers 2`: two processes listen on the printed port, both
    accept handshakes, and SIGTERM stops everything."""
    import os
    import signal
    import time
    import urllib.request

    from tests.conftest import serve_workers

    proc, port = serve_workers(tmp_path)
    try:
        first = proc.stdout.readline()
        assert f"http://127.0.0.1:{port} by 2 worker processes" in first, first
        children = _children(proc.pid)
        assert len(children) >= 2, children
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10) as page:
            assert page.status == 200
        for _ in range(6):  # the kernel spreads them; every worker answers
            assert _handshake(port, None) == 101
        assert _handshake(port, "http://evil.example") == 403
        # every worker checks the addresses the parent serves, not the request's Host
        evil = f"evil.attacker:{port}"
        for _ in range(4):
            assert _handshake(port, f"http://{evil}", host=evil) == 403
            assert _handshake(port, f"http://localhost:{port}", host=f"localhost:{port}") == 101
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=15) == 0
        end = time.monotonic() + 5.0  # multiprocessing's helper leaves just after
        while time.monotonic() < end and [p for p in children if os.path.exists(f"/proc/{p}")]:
            time.sleep(0.1)
        assert not [p for p in children if os.path.exists(f"/proc/{p}")]
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)


def _children(pid: int) -> list[int]:
    """Direct child processes of ``pid`` (Linux /proc)."""
    import pathlib

    out = []
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def test_a_proxys_address_replaces_the_machines_own(monkeypatch):
    from sandbox.web.serving.startup import join_urls

    monkeypatch.setattr(addresses, "lan_addresses", lambda: ["192.168.1.20"])
    assert join_urls("0.0.0.0", 8080, "http://sandbox.lycee.fr") == ["http://sandbox.lycee.fr"]
    assert join_urls("0.0.0.0", 8080) == ["http://192.168.1.20:8080"]
    assert join_urls("127.0.0.1", 8080) == []
    text = banner("rotor", "127.0.0.1", 8080, public_url="http://sandbox.lycee.fr")
    assert "students open http://sandbox.lycee.fr" in text


def test_a_bad_public_url_is_refused_in_one_line(monkeypatch, capsys):
    from sandbox import cli
    from sandbox.web.serving import app

    monkeypatch.setattr(app, "serve", lambda target, **kw: pytest.fail("served"))
    assert cli.main(["serve", "rotor", "--public-url", "javascript:alert(1)"]) == 2
    assert "--public-url must be an http" in capsys.readouterr().err


def test_a_browser_traceback_becomes_one_warning_line_said_once_per_quiet_window():
    import logging

    from sandbox.web.serving.network import OneLine

    now = [0.0]
    one = OneLine(clock=lambda: now[0])

    def record(exc: BaseException) -> logging.LogRecord:
        try:
            raise exc
        except BaseException:
            import sys

            return logging.LogRecord(
                "websockets.server",
                logging.ERROR,
                "f",
                1,
                "connection handler failed",
                None,
                sys.exc_info(),
            )

    first = record(ValueError("bad\nframe"))
    assert one.filter(first)
    assert (first.levelno, first.exc_info, first.getMessage()) == (
        logging.WARNING,
        None,
        "connection handler failed: ValueError: bad frame (browser input dropped)",
    )
    assert not one.filter(record(ValueError("again")))  # same kind within the window
    assert one.filter(record(KeyError("other kind")))
    now[0] += OneLine.QUIET
    assert one.filter(record(ValueError("later")))
    plain = logging.LogRecord("asyncio", logging.INFO, "f", 1, "no exception", None, None)
    assert one.filter(plain) and plain.levelno == logging.INFO


def test_a_browser_gone_while_its_websocket_opened_is_no_warning(caplog):
    """A tab closed or reloaded during the opening handshake ends it without a close frame:
    websockets logs "opening handshake failed" as an error; it is no bad input, so the
    teacher's terminal hears nothing of it (debug level), whereas a close frame carrying a
    protocol error still makes a warning."""
    import logging
    import sys

    from websockets.exceptions import ConnectionClosedError
    from websockets.frames import Close, CloseCode

    from sandbox.web.serving.network import OneLine

    one = OneLine(clock=lambda: 0.0)

    def record(exc: BaseException) -> logging.LogRecord:
        try:
            raise exc
        except BaseException:
            return logging.LogRecord(
                "websockets.server", logging.ERROR, "f", 1, "opening handshake failed",
                None, sys.exc_info(),
            )  # fmt: skip

    gone = record(ConnectionClosedError(None, None))
    assert not one.filter(gone) and gone.exc_info is None
    caplog.set_level(logging.DEBUG, logger="websockets.server")
    assert one.filter(gone) and gone.levelno == logging.DEBUG  # kept when asked for
    bad = record(ConnectionClosedError(Close(CloseCode.PROTOCOL_ERROR, "bad"), None))
    assert one.filter(bad) and bad.levelno == logging.WARNING


def _raw(port: int, request: bytes) -> tuple[int, bytes]:
    """(HTTP status, body) of ``request`` sent as is on a socket to ``127.0.0.1:port``."""
    import socket

    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.sendall(request)
        data = b""
        while chunk := sock.recv(65536):
            data += chunk
            if len(data) > 4096 and not data.startswith(b"HTTP/1.1 4"):
                break  # the page itself: its status is enough
    head, _, body = data.partition(b"\r\n\r\n")
    return int(head.split(b" ", 2)[1]), body


HANDSHAKE = (
    b"Upgrade: websocket\r\nConnection: Upgrade\r\n"
    b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
)


@pytest.mark.parametrize(
    "request_bytes",
    [
        b"GET /" + b"a" * 300 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
        b"GET /assets/" + b"b" * 256 + b".js?x=1 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: 127.0.0.1\r\n\r\n",
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: 127.0.0.1\r\n" + HANDSHAKE + b"\r\n",
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n" + HANDSHAKE + b"\r\n",
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nOrigin: http://a\r\nOrigin: http://b\r\n"
        + HANDSHAKE
        + b"\r\n",
        # a header sent twice that viser's page handler reads: it raises
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nAccept-Encoding: gzip\r\n"
        b"Accept-Encoding: br\r\n\r\n",
    ],
    ids=[
        "long-segment",
        "long-file-name",
        "two-hosts",
        "two-hosts-handshake",
        "two-upgrades",
        "two-origins",
        "handler-raises",
    ],
)
def test_a_malformed_request_is_a_bad_request_not_a_server_error(
    served_rotor, caplog, request_bytes
):
    caplog.set_level("INFO")
    status, body = _raw(served_rotor.port, request_bytes)
    assert status == 400  # Bad Request, not 500 Internal Server Error
    assert len(body) < 100 and b"Traceback" not in body
    noisy = [r for r in caplog.records if r.exc_info or r.exc_text or r.levelname == "ERROR"]
    assert not noisy, [r.getMessage() for r in noisy]
    assert not [r for r in caplog.records if "500" in r.getMessage()]
    # the page and a 255-character segment are still served
    assert _raw(served_rotor.port, b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")[0] == 200
    ok = b"GET /" + b"c" * 255 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"
    assert _raw(served_rotor.port, ok)[0] == 404


class _Connection:
    """What the guard uses of websockets' ServerConnection."""

    local_address = ("127.0.0.1", 8080)

    def respond(self, status: int, text: str) -> tuple[int, str]:
        return status, text


def test_a_page_handler_that_raises_answers_400_in_one_log_line(caplog):
    from websockets.datastructures import Headers
    from websockets.http11 import Request

    def broken(connection, request):
        raise RuntimeError("viser\nfailed")

    async def broken_later(connection, request):
        raise RuntimeError("later")

    network.install()  # the one-line filter of the guard's logger
    network._one_line.last.clear()  # said once per window: forget earlier tests
    request = Request("/", Headers({"Host": "127.0.0.1:8080"}))
    guard = network._guarded(broken, SERVED)
    assert guard(_Connection(), request) == (400, network.BAD_REQUEST)
    later = network._guarded(broken_later, SERVED)(_Connection(), request)
    # In its own thread: the browser tests' Playwright keeps a loop running in this one.
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        assert pool.submit(asyncio.run, later).result() == (400, network.BAD_REQUEST)
    failures = [r for r in caplog.records if r.name == network.__name__]
    assert failures and all(r.exc_info is None and "\n" not in r.getMessage() for r in failures)
