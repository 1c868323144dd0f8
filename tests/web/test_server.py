"""The server helpers made public by the split of :mod:`sandbox.web.serving.app`."""

from __future__ import annotations

import socket

import pytest

from sandbox.errors import BadOption
from sandbox.web.serving.server import bracket, check_port


def test_bracket_wraps_an_ipv6_address_only():
    assert bracket("::1") == "[::1]"
    assert bracket("127.0.0.1") == "127.0.0.1"
    assert bracket("localhost") == "localhost"


def test_check_port_names_a_taken_port_and_passes_a_free_one():
    check_port("127.0.0.1", 0)  # 0: any free port, nothing to check
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        with pytest.raises(BadOption, match=f"--port {port + 1}"):
            check_port("127.0.0.1", port)
