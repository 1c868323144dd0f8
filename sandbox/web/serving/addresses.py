"""The addresses of a web server: which ones it answers to, and which ones students type.

A websocket handshake is accepted only when its ``Host`` and its ``Origin`` (when
present: a browser's page) each name one of the addresses this server serves
(:class:`Served`: the localhost names, the interface it listens on, this machine's LAN
addresses and name when it listens on all of them, the address the connection reached,
each on the port the connection reached; and the proxy's ``--public-url``). They are
never compared with each other: a DNS-rebinding page controls both
(:func:`origin_refusal`, used by :mod:`sandbox.web.serving.network`).

Students type this machine's LAN addresses (:func:`lan_addresses`,
:func:`student_urls`), found without sending a packet, on Linux, macOS and Windows.
"""

from __future__ import annotations

import dataclasses
import ipaddress
import socket
import struct
import sys
from collections.abc import Mapping
from urllib.parse import urlsplit

_DEFAULT_PORTS = {"http": 80, "https": 443, "ws": 80, "wss": 443}
_WILDCARDS = ("0.0.0.0", "", "::")
LOCAL_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})
"""Loopback names every server answers to (and any ``*.localhost``, which browsers
resolve to loopback themselves)."""


def _name(text: str) -> str:
    """A host name as compared: lower case, no final dot, an IP in its canonical form
    (an IPv4-mapped IPv6 address as IPv4), an IPv6 zone dropped."""
    name = text.strip().strip("[]").lower().rstrip(".")
    try:
        ip = ipaddress.ip_address(name.partition("%")[0])
    except ValueError:
        return name
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        return str(ip.ipv4_mapped)
    return ip.compressed


@dataclasses.dataclass(frozen=True)
class Served:
    """The addresses one server answers to.

    Attributes:
        names: Host names and IP addresses reached directly (no proxy): they are served
            on :attr:`port`. Any ``*.localhost`` is served too.
        port: The port the connection reached (the one the server listens on, or the
            front's in a worker); None before a connection is known: no direct name is
            served then.
        public: ``(host, port)`` of the proxy's public address (``--public-url``).
    """

    names: frozenset[str]
    port: int | None = None
    public: frozenset[tuple[str, int]] = frozenset()

    @classmethod
    def of(cls, host: str | None, *, public_url: str | None = None) -> Served:
        """The addresses of a server listening on interface ``host``.

        Args:
            host: The interface (``0.0.0.0``/``::``/None: all, which adds this machine's
                LAN addresses and name).
            public_url: The proxy's public address students type (``--public-url``).

        Raises:
            ValueError: ``public_url`` has no host name.
        """
        names = set(LOCAL_NAMES)
        if host is None or host in _WILDCARDS:
            names.update(lan_addresses())
            machine = socket.gethostname()
            short = machine.partition(".")[0]
            names.update({machine, short, short + ".local"} if short else ())
        else:
            names.add(host)
        public = frozenset({netloc(public_url)}) if public_url else frozenset()
        return cls(frozenset(_name(n) for n in names if n), None, public)

    def on(self, address: object) -> Served:
        """These addresses for one connection whose local socket address (``getsockname``)
        is ``address``: its IP is served too, on its port."""
        if not isinstance(address, tuple) or len(address) < 2:
            return self
        ip, port = address[0], address[1]
        names = self.names | {_name(str(ip))} if isinstance(ip, str) else self.names
        return dataclasses.replace(self, names=names, port=int(port))

    def serves(self, host: str, port: int | None) -> bool:
        """Whether ``host:port`` (``port`` None: the default one, 80 or 443) is served."""
        name = _name(host)
        ports = {port} if port is not None else {80, 443}
        if any((name, p) in self.public for p in ports):
            return True
        direct = name in self.names or name.endswith(".localhost")
        return direct and self.port is not None and self.port in ports

    def describe(self, limit: int = 6) -> str:
        """The addresses in one line, e.g. ``localhost, 127.0.0.1 on port 8080``."""
        names = sorted(self.names, key=lambda n: (n not in LOCAL_NAMES, n))
        shown = ", ".join(names[:limit]) + (", ..." if len(names) > limit else "")
        text = f"{shown} on port {self.port}" if self.port is not None else shown
        for host, port in sorted(self.public):
            text += f"; {host}:{port}"
        return text


def origin_refusal(headers: Mapping[str, str], served: Served) -> str | None:
    """Why a handshake with these request headers is refused, or None to accept it.

    Only websocket upgrades are judged; plain HTTP requests (the page, its scripts)
    are always served. The ``Host`` header (when present) and the ``Origin`` (when
    present: a browser's page) must each name an address ``served`` by this server;
    they are never compared with each other, since a DNS-rebinding page controls both.

    Args:
        headers: The request headers (websockets' ``Headers``, or any mapping).
        served: What this server serves, for this connection (:meth:`Served.on`).
    """
    if str(headers.get("Upgrade", "")).lower() != "websocket":
        return None
    origin = headers.get("Origin")
    host = headers.get("Host")
    if not host:
        return None if origin is None else "no Host header"
    fix = (
        f"(this server serves {served.describe()}; if students reach it through a proxy or "
        "a name of its own, start it with --public-url http://THAT-ADDRESS)"
    )
    try:
        name, port = _host_port(str(host))
    except ValueError:
        return f"malformed Host {str(host)[:80]!r}"
    if not served.serves(name, port):
        return f"foreign Host {str(host)[:80]!r} {fix}"
    if origin is None:
        return None
    try:
        seen = netloc(str(origin))
    except ValueError:
        return f"malformed Origin {str(origin)[:80]!r}"
    if not served.serves(*seen):
        return f"foreign Origin {str(origin)[:80]!r} {fix}"
    return None


def _host_port(host: str) -> tuple[str, int | None]:
    """A Host header's name and port (None when it names none)."""
    parts = urlsplit("//" + host)
    if not parts.hostname or parts.username is not None or parts.path or parts.query:
        raise ValueError(host)
    return parts.hostname, parts.port


def netloc(url: str) -> tuple[str, int]:
    """A URL's host name (as compared) and port (its scheme's when it names none).

    Raises:
        ValueError: the URL has no host name, or no port and a scheme without one.
    """
    parts = urlsplit(url)
    if parts.hostname is None:
        raise ValueError(url)
    port = parts.port or _DEFAULT_PORTS.get(parts.scheme.lower())
    if port is None:
        raise ValueError(url)
    return _name(parts.hostname), port


# -- addresses students can type ---------------------------------------------------------
def lan_addresses() -> list[str]:
    """IPv4 addresses of this machine that other machines can reach (no loopback).

    Private (LAN) addresses come first. Empty when the machine has no network.
    """
    found: set[str] = set()
    found.update(_interface_addresses())
    found.update(_routed_addresses())
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


ROUTE_PROBES = ("10.255.255.255", "172.31.255.255", "192.168.255.255", "192.0.2.1")
"""Addresses a UDP socket is "connected" to (no packet is sent) so that the system names
the source address it would use: the LAN address on macOS and Windows too."""


def _routed_addresses() -> list[str]:
    """The addresses this machine would send from towards the private networks (the
    UDP-connect trick: portable, no packet leaves; nothing without a route)."""
    out = []
    for probe in ROUTE_PROBES:
        try:
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
                sock.connect((probe, 9))
                out.append(str(sock.getsockname()[0]))
        except OSError:  # no route there
            continue
    return out


def _interface_addresses() -> list[str]:
    """IPv4 address of every interface (Linux ioctl SIOCGIFADDR; elsewhere nothing)."""
    if not sys.platform.startswith("linux"):
        return []
    import fcntl  # POSIX only: there is none on Windows

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
