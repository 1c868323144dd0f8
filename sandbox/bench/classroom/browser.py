"""What a headless browser sends, and how it connects: the websocket handshake as the
browser makes it (viser's subprotocol ``viser-v<version>``, the page's Origin), the first
``ViewerCameraMessage`` that starts the per-browser session, the ``GuiUpdateMessage`` of
an input set to a value, and a reader handing every page update to a script.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import msgspec
import viser
import websockets

from sandbox.bench.classroom.wire import unpack

if TYPE_CHECKING:
    from websockets.asyncio.client import connect


def _subprotocol() -> str:
    return f"viser-v{viser.__version__}"


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
