"""The wire, as a browser reads it: viser's server messages (zstd-framed msgpack) decoded,
and what the benchmark looks for in them (scene pose updates, the simulated time of the
control panel's status line, 3D nodes made or removed, a labelled control).
"""

from __future__ import annotations

import re
import threading
from typing import Any

import msgspec
import zstandard

from sandbox.scenes import SCENES

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


BIG_MESSAGE = 16_000
"""Bytes from which a server message counts as big (images, meshes, plot data)."""
_LOCAL = threading.local()
"""One zstd decompressor per thread: an instance is not safe for concurrent use (python-
zstandard says so; four students' reader threads sharing one crashed the process)."""


def _decompressor() -> zstandard.ZstdDecompressor:
    dctx = getattr(_LOCAL, "dctx", None)
    if dctx is None:
        dctx = _LOCAL.dctx = zstandard.ZstdDecompressor()
    return dctx


def unpack(raw: bytes) -> bytes:
    """The msgpack part of a server websocket message (viser's zstd wire format).

    Layout: 8 bytes msgpack size, 8 bytes compressed size (little endian), the zstd
    frame, then raw binary buffers (meshes), which are not needed and not copied.
    """
    size = int.from_bytes(raw[:8], "little")
    clen = int.from_bytes(raw[8:16], "little")
    return _decompressor().decompress(memoryview(raw)[16 : 16 + clen], max_output_size=size)


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
    words = {p.label for scene in SCENES.values() for p in scene.params if p.name == param}
    return find_gui(inner, "Slider", param, *sorted(w for w in words if w))
