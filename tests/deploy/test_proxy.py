"""HAProxy (Debian's package) in front of several ``sandbox serve`` machines: deploy/.

The configuration shipped in ``deploy/haproxy.cfg`` is checked by ``haproxy -c``; the
``proxy`` tests run it for real on loopback, with its own directives (only addresses,
ports and the admin socket are changed, and the root-only lines dropped), in front of
two ``sandbox serve`` processes.
"""

from __future__ import annotations

import contextlib
import csv
import functools
import io
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from conftest import free_port

import sandbox

DEPLOY = Path(__file__).resolve().parents[2] / "deploy"
CONFIG = DEPLOY / "haproxy.cfg"
ERROR_PAGE = DEPLOY / "errors" / "503-fr.http"
COOKIE = "SANDBOX_SERVER"


def haproxy_path() -> str:
    """Debian's HAProxy; CI (SANDBOX_REQUIRE_BROWSER=1) fails instead of skipping."""
    path = shutil.which("haproxy") or "/usr/sbin/haproxy"
    if not os.path.exists(path):
        if os.environ.get("SANDBOX_REQUIRE_BROWSER"):
            pytest.fail("HAProxy not found; install it with apt-get install haproxy")
        pytest.skip("HAProxy not installed (apt-get install haproxy)")
    return path


def _wait_for(predicate: Callable[[], object], timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.2)
    raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")


# -- the configuration ---------------------------------------------------------------
def test_deploy_config_is_valid():
    done = subprocess.run(
        [haproxy_path(), "-c", "-f", str(CONFIG)],
        capture_output=True,
        text=True,
        timeout=30,
        cwd="/",  # the error page is found next to the file, whatever the directory
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "valid" in done.stdout


def test_deploy_config_has_the_directives_the_readme_promises():
    text = CONFIG.read_text()
    for directive in (
        "balance leastconn",
        "timeout tunnel",
        f"cookie {COOKIE} insert",
        "option httpchk",
        "http-check send meth GET uri /",
        "option redispatch",
        "errorfile 503 errors/503-fr.http",
    ):
        assert directive in text, directive


def test_error_page_is_a_complete_french_http_answer():
    raw = ERROR_PAGE.read_bytes()
    head, _, body = raw.partition(b"\r\n\r\n")
    lines = head.decode("ascii").split("\r\n")
    assert lines[0] == "HTTP/1.1 503 Service Unavailable"
    headers = dict(line.split(": ", 1) for line in lines[1:])
    assert headers["Content-Type"] == "text/html; charset=utf-8"
    assert int(headers["Content-Length"]) == len(body)
    text = body.decode("utf-8")
    assert 'lang="fr"' in text and "enseignant" in text and "recharge" in text
    assert len(raw) < 16384  # HAProxy's buffer (tune.bufsize) must hold the whole answer


# -- running it ----------------------------------------------------------------------
def local_config(*, port: int, backends: list[int], admin_socket: Path, stats_port: int) -> str:
    """deploy/haproxy.cfg on loopback: same directives, test addresses, no root needed."""
    text = CONFIG.read_text()

    def sub(pattern: str, replacement: str, count: int | None = None) -> None:
        nonlocal text
        text, n = re.subn(pattern, replacement, text, flags=re.M)
        assert n >= 1 if count is None else n == count, f"deploy/haproxy.cfg changed: {pattern}"

    sub(r"^\s*(log /dev/log|chroot|user|group|daemon)\b.*\n", "")
    sub(r"^(\s*stats socket) \S+", rf"\1 {admin_socket}", 1)
    sub(r"^(\s*bind) \*:80\b", rf"\1 127.0.0.1:{port}", 1)
    sub(r"^(\s*bind) 127\.0\.0\.1:8404\b", rf"\1 127.0.0.1:{stats_port}", 1)
    sub(r"^\s*server .*\n", "")
    servers = "".join(
        f"    server s{k} 127.0.0.1:{p} cookie s{k}\n" for k, p in enumerate(backends, 1)
    )
    sub(r"^(\s*default-server .*\n)", rf"\g<1>{servers}", 1)
    return text


def show_stat(admin_socket: Path) -> dict[str, dict[str, str]]:
    """HAProxy's ``show stat`` for the servers of backend ``sandbox``, by server name."""
    with socket.socket(socket.AF_UNIX) as sock:
        sock.settimeout(5)
        sock.connect(str(admin_socket))
        sock.sendall(b"show stat\n")
        chunks = []
        while chunk := sock.recv(65536):
            chunks.append(chunk)
    text = b"".join(chunks).decode().lstrip("# ")
    rows = csv.DictReader(io.StringIO(text))
    return {
        row["svname"]: row
        for row in rows
        if row["pxname"] == "sandbox" and row["svname"] not in ("FRONTEND", "BACKEND")
    }


def sessions(admin_socket: Path) -> dict[str, int]:
    """Connections open right now to each sandbox server (``scur``)."""
    return {name: int(row["scur"]) for name, row in show_stat(admin_socket).items()}


@contextlib.contextmanager
def running(command: list[str], log: Path, **options) -> Iterator[subprocess.Popen]:
    """A process (in its own process group) stopped, then killed, whatever happens."""
    with log.open("wb") as out:
        proc = subprocess.Popen(
            command, stdout=out, stderr=subprocess.STDOUT, start_new_session=True, **options
        )
    try:
        yield proc
    finally:
        stop(proc)


def stop(proc: subprocess.Popen) -> None:
    """SIGTERM to the process (a server stops its own workers), then SIGKILL to its group."""
    if proc.poll() is not None:
        return
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        # Not reaped yet, so the group id is still the one this test created.
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=5)


def http_get(url: str, timeout: float = 5.0) -> tuple[int, str]:
    try:
        with urllib.request.urlopen(url, timeout=timeout) as answer:
            return answer.status, answer.read().decode("utf-8", "replace")
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read().decode("utf-8", "replace")


def answers(url: str) -> bool:
    try:
        return http_get(url, timeout=2)[0] == 200
    except OSError:
        return False


@functools.cache
def serve_options() -> tuple[str, ...]:
    """``--workers 1`` if this version of ``sandbox serve`` has that option."""
    done = subprocess.run(
        [sys.executable, "-m", "sandbox.cli", "serve", "--help"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    return ("--workers", "1") if "--workers" in done.stdout else ()


def _env() -> dict[str, str]:
    """The servers import the same ``sandbox`` as the tests."""
    env = dict(os.environ)
    root = str(Path(sandbox.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
    return env


@contextlib.contextmanager
def proxy_in_front_of(
    backends: list[int], tmp_path: Path, port: int | None = None
) -> Iterator[tuple[str, Path]]:
    """HAProxy on loopback port ``port`` (None: a free one): (its URL, its admin socket)."""
    port, admin = port or free_port(), tmp_path / "admin.sock"
    shutil.copytree(DEPLOY / "errors", tmp_path / "errors")
    cfg = tmp_path / "haproxy.cfg"
    cfg.write_text(
        local_config(port=port, backends=backends, admin_socket=admin, stats_port=free_port())
    )
    with running([haproxy_path(), "-f", str(cfg), "-db"], tmp_path / "haproxy.log") as proc:
        _wait_for(lambda: proc.poll() is not None or admin.exists(), 30, "HAProxy's admin socket")
        assert proc.poll() is None, (tmp_path / "haproxy.log").read_text()
        yield f"http://127.0.0.1:{port}", admin


@pytest.mark.proxy
def test_every_machine_down_gives_the_french_503_page(tmp_path):
    dead = [free_port(), free_port()]  # nothing listens there
    with proxy_in_front_of(dead, tmp_path) as (url, _):
        status, body = http_get(url + "/", timeout=30)
    assert status == 503
    assert "Toutes les machines du sandbox sont occupées" in body


def _open_student(browser, url: str):
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    page.goto(url, timeout=60_000)
    page.locator('[data-readout="bearing_A"]').first.wait_for(timeout=60_000)
    assert page.locator("canvas").first.is_visible()
    for title in ("Simulation", "Grandeurs de la scène", "Panneau affiché"):
        assert page.get_by_text(title, exact=True).first.is_visible(), title
    return context, page


def _readout(page, name: str) -> float:
    # the cell shows "54,42"; its data-value attribute keeps the exact number for scripts
    value = page.locator(f'[data-readout="{name}"]').first.get_attribute("data-value")
    return float(value or "nan")


def _cookie(context) -> str:
    return next(c["value"] for c in context.cookies() if c["name"] == COOKIE)


@pytest.mark.proxy
@pytest.mark.browser
@pytest.mark.slow  # HAProxy, two servers and Chromium: ~50 s
def test_two_browsers_get_their_own_sessions_on_two_machines(tmp_path, browser):
    haproxy_path()  # skip (or fail in CI) before starting anything
    ports, public = [free_port(), free_port()], free_port()
    with contextlib.ExitStack() as stack:
        procs = []
        for port in ports:
            command = [sys.executable, "-m", "sandbox.cli", "serve", "rotor"]
            command += ["--host", "127.0.0.1", "--port", str(port), *serve_options()]
            # the page's websocket has Origin and Host = the proxy's address: served
            command += ["--public-url", f"http://127.0.0.1:{public}"]
            log = tmp_path / f"serve-{port}.log"
            procs.append(stack.enter_context(running(command, log, cwd=tmp_path, env=_env())))
            stack.callback(lambda log=log: print(log.read_text(errors="replace")[-2000:]))
        for port in ports:
            _wait_for(lambda port=port: answers(f"http://127.0.0.1:{port}/"), 120, f":{port}")
        assert all(proc.poll() is None for proc in procs)
        url, admin = stack.enter_context(proxy_in_front_of(ports, tmp_path, public))
        _wait_for(
            lambda: all(r["check_status"] == "L7OK" for r in show_stat(admin).values()),
            30,
            "HAProxy's health checks (GET /) to pass on both servers",
        )

        first, page1 = _open_student(browser, url)
        stack.callback(first.close)
        _wait_for(lambda: sorted(sessions(admin).values()) == [0, 1], 30, "one websocket")
        machine1 = _cookie(first)
        assert sessions(admin)[machine1] == 1  # the websocket followed the page's cookie

        second, page2 = _open_student(browser, url)
        stack.callback(second.close)
        _wait_for(lambda: sessions(admin) == {"s1": 1, "s2": 1}, 30, "one websocket each")
        assert _cookie(second) != machine1  # least connections sent it to the other one

        # Each browser has its own simulation: a correction mass in the first one
        # changes its bearing force and leaves the second one's alone.
        before1, before2 = _readout(page1, "bearing_A"), _readout(page2, "bearing_A")
        from sandbox.scenes import SCENES
        from sandbox.web.client.fields import param_label

        mass1 = param_label(SCENES["rotor"].param("mass1_g"))  # as the page names it
        row = page1.locator("div.mantine-Flex-root", has=page1.get_by_text(mass1, exact=True)).last
        box = row.locator("input.mantine-NumberInput-input").first
        box.fill("60")
        box.press("Enter")
        _wait_for(
            lambda: abs(_readout(page1, "bearing_A") - before1) > 0.05 * before1,
            20,
            "the first browser's bearing force to change",
        )
        assert _readout(page2, "bearing_A") == pytest.approx(before2, rel=0.01)

        # A reload stays on the same machine (cookie): still one websocket each.
        page1.reload(timeout=60_000)
        page1.locator('[data-readout="bearing_A"]').first.wait_for(timeout=60_000)
        assert _cookie(first) == machine1
        _wait_for(lambda: sessions(admin) == {"s1": 1, "s2": 1}, 30, "the reload to settle")

        # The first machine dies: the health checks take it out, and the first student
        # gets a new simulation on the other machine (at the latest when reloading).
        machine2 = _cookie(second)
        stop(procs[int(machine1[1:]) - 1])
        _wait_for(
            lambda: show_stat(admin)[machine1]["status"].startswith("DOWN"),
            30,
            f"HAProxy to mark {machine1} down",
        )
        page1.reload(timeout=60_000)
        page1.locator('[data-readout="bearing_A"]').first.wait_for(timeout=60_000)
        assert _cookie(first) == machine2
        _wait_for(lambda: sessions(admin) == {machine1: 0, machine2: 2}, 30, "both on one machine")
        assert _readout(page2, "bearing_A") == pytest.approx(before2, rel=0.01)


def handshake_status(port: int, *, host: str, origin: str | None) -> int:
    """HTTP status of a websocket handshake sent to 127.0.0.1:``port`` with ``Host: host``
    and ``Origin: origin`` (101 when accepted), as a browser's page would send it."""
    import viser

    lines = [
        "GET / HTTP/1.1",
        f"Host: {host}",
        "Upgrade: websocket",
        "Connection: Upgrade",
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
        "Sec-WebSocket-Version: 13",
        f"Sec-WebSocket-Protocol: viser-v{viser.__version__}",
    ]
    if origin is not None:
        lines.append(f"Origin: {origin}")
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
        head = b""
        while b"\r\n" not in head:
            chunk = sock.recv(4096)
            if not chunk:
                break
            head += chunk
    return int(head.split(b" ", 2)[1])


@pytest.mark.proxy
@pytest.mark.slow  # HAProxy and three server processes: ~10 s
def test_the_proxys_public_url_is_served_and_a_rebinding_host_is_not(tmp_path):
    """Behind HAProxy the websocket's Host and Origin are the proxy's address: accepted when
    it is the servers' --public-url (one server with worker processes, one without), and
    refused when a DNS-rebinding page sends its own name as both."""
    haproxy_path()
    ports, public = [free_port(), free_port()], free_port()
    with contextlib.ExitStack() as stack:
        for port, workers in zip(ports, ("2", "1"), strict=True):
            command = [sys.executable, "-m", "sandbox.cli", "serve", "rotor"]
            command += ["--host", "127.0.0.1", "--port", str(port)]
            command += ["--workers", workers] if serve_options() else []
            command += ["--public-url", f"http://sandbox.test:{public}"]
            log = tmp_path / f"serve-{port}.log"
            stack.enter_context(running(command, log, cwd=tmp_path, env=_env()))
            stack.callback(lambda log=log: print(log.read_text(errors="replace")[-2000:]))
        for port in ports:
            _wait_for(lambda port=port: answers(f"http://127.0.0.1:{port}/"), 120, f":{port}")
        _, admin = stack.enter_context(proxy_in_front_of(ports, tmp_path, public))
        _wait_for(
            lambda: all(r["check_status"] == "L7OK" for r in show_stat(admin).values()),
            30,
            "HAProxy's health checks (GET / with Host: sandbox) to pass on both servers",
        )
        name, evil = f"sandbox.test:{public}", f"evil.attacker:{public}"
        for _ in range(6):  # leastconn spreads them over both machines
            assert handshake_status(public, host=name, origin=f"http://{name}") == 101
            assert handshake_status(public, host=evil, origin=f"http://{evil}") == 403
            assert handshake_status(public, host=evil, origin=None) == 403
        # the loopback name on the proxy's port is neither the servers' port nor the proxy's
        local = f"127.0.0.1:{public}"
        assert handshake_status(public, host=local, origin=f"http://{local}") == 403
