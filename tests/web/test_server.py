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


def test_the_scene_is_lit_without_shadows_nor_an_environment_picture():
    """What every browser gets at connect: the default lights without shadow maps, no
    environment map (an HDR picture a page without a graphics card spent 3 s
    prefiltering, taking no click meanwhile), and the sky light in its place."""
    from viser import _messages

    from sandbox.web.serving.server import SKY, light_the_scene

    sent: list[object] = []

    class Scene:
        def configure_default_lights(self, enabled: bool, cast_shadow: bool) -> None:
            sent.append(_messages.EnableLightsMessage(enabled, cast_shadow))

        def configure_environment_map(self, hdri: object = "city", **_: object) -> None:
            sent.append(("environment", hdri))

        def add_light_hemisphere(self, name: str, **props: object) -> None:
            sent.append(("hemisphere", name, props))

    class Server:
        scene = Scene()

    light_the_scene(Server())  # type: ignore[arg-type]
    assert sent[0] == _messages.EnableLightsMessage(True, False)
    assert ("environment", None) in sent
    (sky,) = [m for m in sent if isinstance(m, tuple) and m[0] == "hemisphere"]
    assert sky[1] == SKY and sky[2]["intensity"] > 1.0
    assert sky[2]["ground_color"] < sky[2]["sky_color"]  # darker from below
