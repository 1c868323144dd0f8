"""Every use of viser's private internals, in this one module.

viser gives no public way to a few things a classroom needs: a browser's websocket
handshake (the teacher's link is its path, the share link its ``Host``), whether a
browser's sender took the frames queued for it (a slow link), the scene messages queued
without viser's per-property copies (poses at 60 frames a second for 30 browsers), the
upload handlers (capped here), the message buffer's event (woken from any thread), and
the panel a folder sits in. They are private: a later viser may rename them. So they are
read here only, :func:`missing` says which of them this viser lacks, and
:func:`version_line` says, in French and English, which viser is required; the server
logs that line at start (:func:`warn_at_start`). ``pyproject.toml`` allows the releases
tested (:data:`TESTED`); every caller falls back on viser's public behaviour when a piece
is absent.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from importlib import metadata
from typing import TYPE_CHECKING, Any

import viser
from viser import _messages as messages

if TYPE_CHECKING:
    from viser._gui_api import GuiApi as GuiApi
    from viser._messages import FileTransferPart as FileTransferPart
    from viser._messages import FileTransferStartUpload as FileTransferStartUpload


log = logging.getLogger(__name__)

TESTED = ">=1.1,<1.2"
"""The viser releases this package is tested with (``pyproject.toml`` asks for them)."""
LOWEST = (1, 1)
"""Lowest release of :data:`TESTED` (major, minor)."""
ABOVE = (1, 2)
"""First release past :data:`TESTED` (major, minor)."""


# -- the checks ------------------------------------------------------------------------
def version() -> str:
    """The installed viser's version ("" when unknown)."""
    try:
        return metadata.version("viser")
    except metadata.PackageNotFoundError:  # pragma: no cover - run from a source tree
        return str(getattr(viser, "__version__", ""))


def _release(text: str) -> tuple[int, int] | None:
    parts = text.split(".")
    try:
        return int(parts[0]), int(parts[1])
    except (IndexError, ValueError):
        return None


def in_tested_range(text: str | None = None) -> bool:
    """True when viser ``text`` (the installed one by default) is among :data:`TESTED`."""
    release = _release(version() if text is None else text)
    return release is not None and LOWEST <= release < ABOVE


def has_fast_poses() -> bool:
    """The scene messages and the node state the fast pose path writes."""
    needed = ("SetPositionMessage", "SetOrientationMessage", "SceneNodeUpdateMessage")
    if not all(hasattr(messages, name) for name in needed):
        return False
    from viser._scene_api import SceneApi  # private module: absent from some releases
    from viser._scene_handles import _SceneNodeHandleState  # idem

    fields = getattr(_SceneNodeHandleState, "__dataclass_fields__", {})
    return hasattr(SceneApi, "_queue_scene_message") and {
        "name",
        "api",
        "wxyz",
        "position",
        "props",
        "removed",
    } <= set(fields)


def has_upload_handlers() -> bool:
    """The upload handlers and state the upload cap wraps."""
    from viser._gui_api import GuiApi  # private module: absent from some releases
    from viser._gui_handles import GuiUploadButtonHandle  # noqa: F401  (idem)

    names = (
        "_handle_file_transfer_start",
        "_handle_file_transfer_part",
        "_drop_uploads_from_client",
    )
    return all(hasattr(GuiApi, name) for name in names)


def has_message_event() -> bool:
    """The message buffer's event and loop, which a worker thread's wake-ups set."""
    from viser.infra._async_message_buffer import AsyncMessageBuffer  # private module

    fields = getattr(AsyncMessageBuffer, "__dataclass_fields__", {})
    return "message_event" in fields and "event_loop" in fields


CHECKS: dict[str, Callable[[], bool]] = {
    "fast poses": has_fast_poses,
    "upload cap": has_upload_handlers,
    "wake-ups": has_message_event,
}
"""What each piece of this module needs, by what it serves."""


def missing() -> list[str]:
    """The pieces this viser lacks (their callers then use viser's public behaviour)."""
    out = []
    for name, check in CHECKS.items():
        try:
            ok = check()
        except ImportError:
            ok = False
        if not ok:
            out.append(name)
    return out


def version_line() -> str | None:
    """One line in French and English when the installed viser is not a tested one or
    lacks a piece used here; None when all is well."""
    found, lacking = version() or "?", missing()
    if in_tested_range() and not lacking:
        return None
    what = f" (il manque / lacks: {', '.join(lacking)})" if lacking else ""
    return (
        f"viser {found} n'est pas une version testée : installez viser{TESTED} / "
        f"viser {found} is not a tested release: install viser{TESTED}{what}"
    )


def warn_at_start() -> None:
    """Log :func:`version_line` once, when there is something to say."""
    line = version_line()
    if line is not None:
        log.warning(line)


# -- connections ----------------------------------------------------------------------
def live_connection(server: viser.ViserServer, client_id: int) -> Any | None:
    """viser's live websocket connection of browser ``client_id`` (None if unknown)."""
    try:
        return server._websock_server._live_connections.get(client_id)
    except AttributeError:
        return None


def handshake(server: viser.ViserServer, client_id: int) -> Any | None:
    """The websocket handshake request of browser ``client_id`` (path, headers)."""
    connection = live_connection(server, client_id)
    return getattr(connection, "request", None) if connection is not None else None


def server_of(client: viser.ClientHandle) -> viser.ViserServer:
    """The server a browser's handle belongs to."""
    return client._viser_server


def event_loop(server: viser.ViserServer) -> Any:
    """The asyncio loop viser serves in."""
    return server._event_loop


def sent_marks(client: Any) -> tuple[int, int] | None:
    """(last message queued for a browser, last one its sender has taken), as viser's
    message ids; None when this viser does not tell."""
    try:
        connection = client._websock_connection
        buffer = connection.get_message_buffer()
        cursor = buffer.generator_cursors.get(connection.client_id)
        queued = buffer.message_counter - 1
    except AttributeError:
        return None
    return None if cursor is None else (int(queued), int(cursor))


# -- scene nodes ----------------------------------------------------------------------
def node_state(node: Any) -> Any | None:
    """A scene node's internal state (name, api, pose, props, removed); None for a
    stand-in without one."""
    return getattr(node, "_impl", None)


def queue_scene_message(state: Any, message: Any) -> None:
    """Queue ``message`` for the scene of a node's ``state``, without viser's copies."""
    state.api._queue_scene_message(message)


def panel_of(gui: viser.GuiApi, folder: viser.GuiFolderHandle) -> Any | None:
    """The panel (a column) a folder sits in, through its tab; None if unknown."""
    try:
        tab = gui._resolve_container_handle(folder._impl.parent_container_id)
    except (AttributeError, KeyError):
        return None
    return getattr(tab, "_parent", None)


# -- uploads --------------------------------------------------------------------------
def upload_button(gui: GuiApi, uuid: Any) -> Any | None:
    """The upload button of id ``uuid`` in ``gui``, when it is one and not removed."""
    from viser._gui_handles import GuiUploadButtonHandle  # private module (checked)

    handle = gui._gui_input_handle_from_uuid.get(uuid)
    if isinstance(handle, GuiUploadButtonHandle) and not handle._impl.removed:
        return handle
    return None


def upload_states(gui: GuiApi) -> dict[Any, Any]:
    """The uploads in progress of ``gui`` by transfer id (viser's own dicts)."""
    states: dict[Any, Any] = gui._current_file_upload_states
    return states


def drop_uploads(gui: GuiApi, client_id: Any) -> None:
    """Forget every upload in progress of browser ``client_id`` in ``gui``."""
    gui._drop_uploads_from_client(client_id)


def wrap_upload_handlers(
    wrap: Callable[[Callable[..., None], Callable[..., None]], tuple[Any, Any]],
) -> None:
    """Replace viser's two upload handlers by ``wrap(start, part)``'s (for every GUI
    made afterwards)."""
    from viser._gui_api import GuiApi  # private module (checked)

    start, part = wrap(GuiApi._handle_file_transfer_start, GuiApi._handle_file_transfer_part)
    GuiApi._handle_file_transfer_start = start  # type: ignore[method-assign]
    GuiApi._handle_file_transfer_part = part  # type: ignore[method-assign]


# -- message buffers ------------------------------------------------------------------
def message_buffer_class() -> Any:
    """viser's message buffer class (its ``message_event`` wakes the sender)."""
    from viser.infra._async_message_buffer import AsyncMessageBuffer  # private (checked)

    return AsyncMessageBuffer
