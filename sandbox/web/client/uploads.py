"""Files sent by browsers: taken only for an upload button, and only up to a cap.

viser buffers every ``FileTransferPart`` of an upload a browser announces with
``FileTransferStartUpload`` for *any* input id (a slider's will do), and believes the
size and part count the browser declares: a crafted page sending 8 MiB parts of a
"file" of 10⁹ parts grew a server by 500 MB, which stayed after the page left. The page
of this app has no upload control; :func:`install` (called when :mod:`sandbox.web.client.wire`
is imported, before any server exists) wraps viser's two upload handlers so that:

* an upload is taken only for an upload button (``gui.add_upload_button``, shared or of
  that browser) that is shown and enabled, declaring at most :data:`MAX_UPLOAD_BYTES` in
  at most :data:`MAX_UPLOAD_PARTS` parts, while the browser's other uploads in progress
  leave room under :data:`MAX_CONNECTION_UPLOAD_BYTES`;
* a part is stored only when it belongs to an upload taken from that same browser, for
  the same button, and fits in the size declared. Everything else is dropped before
  viser sees it: no part of it is kept.

What viser's page can send, a file too big for an upload button, is refused and its
parts (at most the number announced, each at most :data:`PAGE_PART_BYTES`) are dropped:
the page stays open (its button waits for an answer that never comes). What the page
never sends (an upload to a control that takes none, a part nobody announced or beyond
the declared size, more parts of a refused file than announced) aborts that browser's
connection at once, so nothing more of the flood is read, and gives the freed memory
back to the system (:func:`_trim_soon`); the other browsers are not touched. Either way
one log line per connection at most.
"""

from __future__ import annotations

import asyncio
import ctypes
import logging
import weakref
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

from viser import ClientHandle

from sandbox.web.client import viser_internals
from sandbox.web.client.patches import install_once

if TYPE_CHECKING:
    from sandbox.web.client.viser_internals import (
        FileTransferPart,
        FileTransferStartUpload,
        GuiApi,
    )

log = logging.getLogger(__name__)

MIB = 2**20
MAX_UPLOAD_BYTES = 16 * MIB
"""Largest file a browser may upload [bytes]: the declared size, checked at the start,
before any part is stored; each part must then fit in what is left of it."""
MAX_CONNECTION_UPLOAD_BYTES = 16 * MIB
"""Most bytes the uploads in progress of one connection may declare together [bytes]."""
MAX_UPLOAD_PARTS = 1024
"""Most parts an upload may declare (viser's page sends 512 KiB parts: 32 for 16 MiB)."""
PAGE_PART_BYTES = 512 * 1024
"""Size of the parts viser's page sends [bytes]: the largest part of a refused file that
is dropped quietly (a bigger one closes the connection)."""
MAX_REFUSED = 8
"""Files refused on one connection before the next refusal closes it."""
TRIM_DELAY = 1.0
"""Delay between closing a connection and giving its memory back [s]."""

_SOURCE = "sandbox_source"  # extra key in viser's upload state: the button's id


@dataclass
class _Ledger:
    """What is remembered of one connection (forgotten with its ClientHandle)."""

    refused: dict[str, int] = field(default_factory=dict)  # transfer -> parts to drop
    logged: bool = False
    closed: bool = False


_ledgers: weakref.WeakKeyDictionary[ClientHandle, _Ledger] = weakref.WeakKeyDictionary()


def install() -> bool:
    """Wrap viser's upload handlers, once per process; True when they are wrapped.

    Applies to the GUIs made after the call (viser binds its handlers then). A viser
    without the internals used here is left as it is, with one warning.
    """
    return install_once(
        __name__,
        viser_internals.has_upload_handlers,
        "this viser lacks the upload internals: uploads are not capped",
        _wrap_handlers,
    )


def _wrap_handlers() -> None:
    def wrap(start: Callable[..., None], part: Callable[..., None]) -> tuple[Any, Any]:
        def guarded_start(api: GuiApi, client_id: Any, message: FileTransferStartUpload) -> None:
            owner = _take_start(api, message)
            if owner is not None:
                start(owner, client_id, message)
                state = viser_internals.upload_states(owner).get(message.transfer_uuid)
                if state is not None:
                    cast(dict[str, Any], state)[_SOURCE] = message.source_component_uuid

        def guarded_part(api: GuiApi, client_id: Any, message: FileTransferPart) -> None:
            owner = _take_part(api, message)
            if owner is not None:
                part(owner, client_id, message)

        return guarded_start, guarded_part

    viser_internals.wrap_upload_handlers(wrap)


def _apis(client: ClientHandle) -> tuple[GuiApi, GuiApi]:
    """The GUIs a browser sees: its own and the server's shared one."""
    return client.gui, viser_internals.server_of(client).gui


def _browser(api: GuiApi) -> tuple[ClientHandle, _Ledger] | None:
    """The browser whose own GUI ``api`` is, and its ledger; None for the server's
    shared GUI, or once the connection is closed here.

    Both GUIs get each message of a browser, in two tasks; only the browser's own one
    (there from the connection's first message) judges it, and hands what it takes to
    the GUI of the button. Judged twice, the last part of an upload finished by the
    first GUI would look unannounced to the second.
    """
    client = getattr(api, "_owner", None)
    if not isinstance(client, ClientHandle):
        return None
    ledger = _ledgers.setdefault(client, _Ledger())
    return None if ledger.closed else (client, ledger)


def _take_start(api: GuiApi, message: FileTransferStartUpload) -> GuiApi | None:
    """The GUI of the upload button ``message`` announces a file for, when the file is
    taken; None when it is refused (or ``api`` is not the browser's own GUI)."""
    found = _browser(api)
    if found is None:
        return None
    client, ledger = found
    uuid, tid = message.source_component_uuid, message.transfer_uuid
    owner = button = None
    for gui in _apis(client):
        handle = viser_internals.upload_button(gui, uuid)
        if handle is not None:
            owner, button = gui, handle
    if owner is None or button is None:
        _hostile(client, ledger, f"upload to {str(uuid)[:40]!r}, no upload button")
        return None
    size, parts = message.size_bytes, message.part_count
    if not (
        isinstance(size, int)
        and isinstance(parts, int)
        and 0 <= parts <= min(size, MAX_UPLOAD_PARTS)
        and (parts == 0) == (size == 0)
    ):
        _hostile(client, ledger, f"upload of {size!r} bytes in {parts!r} parts")
        return None
    held = _in_progress(client)
    if tid in held or tid in ledger.refused:
        _hostile(client, ledger, f"upload {str(tid)[:40]!r} announced twice")
        return None
    if button.disabled or not button.visible:
        reason = "an upload to a hidden or disabled button"
    elif size > MAX_UPLOAD_BYTES:
        reason = f"a file of {size} bytes (at most {MAX_UPLOAD_BYTES})"
    elif sum(held.values()) + size > MAX_CONNECTION_UPLOAD_BYTES:
        reason = f"uploads of {sum(held.values()) + size} bytes at once"
    else:
        return owner
    if len(ledger.refused) >= MAX_REFUSED:
        _hostile(client, ledger, f"{MAX_REFUSED + 1} files refused")
        return None
    ledger.refused[tid] = parts
    _note(client, ledger, f"refused {reason}; its parts are dropped")
    return None


def _take_part(api: GuiApi, message: FileTransferPart) -> GuiApi | None:
    """The GUI that stores this part, of an upload it took from this browser; None when
    the part is dropped (or ``api`` is not the browser's own GUI)."""
    found = _browser(api)
    if found is None:
        return None
    client, ledger = found
    tid, index = message.transfer_uuid, message.part_index
    size = len(message.content) if isinstance(message.content, bytes) else -1
    for owner in _apis(client):
        state = viser_internals.upload_states(owner).get(tid)
        if state is not None and state["client_id"] == client.client_id:
            break
    else:
        if ledger.refused.get(tid, 0) > 0 and 0 < size <= PAGE_PART_BYTES:
            ledger.refused[tid] -= 1
            return None
        _hostile(client, ledger, f"part {index!r} of an upload not taken")
        return None
    if (
        message.source_component_uuid != cast(dict[str, Any], state).get(_SOURCE)
        or not isinstance(index, int)
        or not 0 <= index < state["part_count"]
        or index in state["parts"]
        or not 0 < size <= state["total_bytes"] - state["transferred_bytes"]
    ):
        _hostile(client, ledger, f"part {index!r} of {size} bytes out of its upload")
        return None
    return owner


def _in_progress(client: ClientHandle) -> dict[str, int]:
    """Declared sizes [bytes] of this browser's uploads in progress, by transfer id."""
    return {
        tid: state["total_bytes"]
        for gui in _apis(client)
        for tid, state in viser_internals.upload_states(gui).items()
        if state["client_id"] == client.client_id
    }


def _note(client: ClientHandle, ledger: _Ledger, text: str) -> None:
    """Log ``text`` unless something was logged already for this connection."""
    if not ledger.logged:
        ledger.logged = True
        log.warning("browser %s: %s", client.client_id, text)


def _hostile(client: ClientHandle, ledger: _Ledger, reason: str) -> None:
    """Drop this browser's uploads and abort its connection: viser's page never sends
    what led here, and a closing handshake would go on reading the flood."""
    ledger.closed = True
    for gui in _apis(client):
        viser_internals.drop_uploads(gui, client.client_id)
    _note(client, ledger, f"{reason}: connection closed")
    server = viser_internals.server_of(client)
    connection = viser_internals.live_connection(server, client.client_id)
    transport = getattr(connection, "transport", None)
    if transport is None:  # pragma: no cover - its messages are dropped all the same
        return
    transport.abort()
    _trim_soon(viser_internals.event_loop(server))


def _libc_trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim``, or None elsewhere (macOS, musl; Windows, where
    ``CDLL(None)`` is a TypeError)."""
    try:
        return cast(Callable[[int], int], ctypes.CDLL(None).malloc_trim)
    except (AttributeError, OSError, TypeError):
        return None


_malloc_trim = _libc_trim()
_trim_pending = False


def _trim_soon(loop: asyncio.AbstractEventLoop) -> None:
    """Give the memory of the flood's frames back to the system, once their connection
    is gone.

    The frames are freed once read, but glibc keeps the freed pages of the event loop's
    arena: without a trim, each connection closed here left the server about 10 MiB
    bigger (5 floods: +52 MiB; with the trim, within 10 MiB of idle, as for 5 ordinary
    visits). One trim (a few ms) for all the connections closed within
    :data:`TRIM_DELAY`.
    """
    global _trim_pending
    if _malloc_trim is None or _trim_pending:
        return
    _trim_pending = True
    loop.call_later(TRIM_DELAY, _trim)


def _trim() -> None:
    global _trim_pending
    _trim_pending = False
    if _malloc_trim is not None:
        _malloc_trim(0)
