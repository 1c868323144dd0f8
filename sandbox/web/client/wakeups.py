"""viser's "a message is waiting" event, touched only by the event loop it belongs to.

Every message a session queues goes through viser's ``AsyncMessageBuffer.push``, which
sets the buffer's ``asyncio.Event`` directly in the calling thread and then (at once, or
when an ``atomic()`` block ends) asks the buffer's loop to set it again with
``call_soon_threadsafe``. An ``asyncio.Event`` is not thread-safe: the direct set walks
the loop's waiters while the loop adds and removes them, and a loaded server now and then
lost a page that way ("RuntimeError: deque mutated during iteration": a browser without
frames, or « Erreur interne » for that student).

:func:`install` (called when :mod:`sandbox.web.client.wire` is imported, before any server
exists) makes the message event of every buffer created afterwards a :class:`LoopEvent`
that knows its buffer's loop: set in that loop, it is asyncio's event exactly; set from any
other thread, the call does nothing, since the loop's own set that viser always schedules
next (or when the ``atomic()`` block ends) is the one that wakes the waiters. The event's
state is then read and written by one thread only, as asyncio requires.
"""

from __future__ import annotations

import asyncio
from typing import Any

from sandbox.web.client import viser_internals
from sandbox.web.client.patches import install_once


class LoopEvent(asyncio.Event):
    """An ``asyncio.Event`` whose :meth:`set` acts only in the loop :attr:`home`."""

    home: asyncio.AbstractEventLoop | None = None
    """The loop whose tasks wait on the event (None: every set acts, as asyncio's)."""

    def set(self) -> None:
        """Set the event and wake its waiters, when called in :attr:`home`; from another
        thread, leave both to the loop's own set, which is always scheduled too."""
        if self.home is not None:
            try:
                running: asyncio.AbstractEventLoop | None = asyncio.get_running_loop()
            except RuntimeError:  # no loop runs in this thread: a session's, viser's pool
                running = None
            if running is not self.home:
                return
        super().set()


def install() -> bool:
    """Give the buffers viser creates from now on a :class:`LoopEvent` as their message
    event, once per process; True when done (a viser without the internals used here is
    left as it is, with one warning)."""
    return install_once(
        __name__,
        viser_internals.has_message_event,
        "this viser's message buffer differs: its events stay as they are",
        _bind_new_events,
    )


def _bind_new_events() -> None:
    buffers = viser_internals.message_buffer_class()
    made = buffers.__init__

    def init(buffer: Any, *args: Any, **kwargs: Any) -> None:
        made(buffer, *args, **kwargs)
        event = buffer.message_event
        if type(event) is asyncio.Event:  # brand new: nobody waits on it yet
            event.__class__ = LoopEvent
            event.home = buffer.event_loop  # type: ignore[attr-defined]

    buffers.__init__ = init
