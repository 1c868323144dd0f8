"""viser's "a message is waiting" event, made safe to set from the session threads.

Every message a session queues goes through viser's ``AsyncMessageBuffer.push``, which
sets the buffer's ``asyncio.Event`` directly in the calling thread, and then (at once, or
when an ``atomic()`` block ends) asks the event loop to set it again with
``call_soon_threadsafe``. ``asyncio.Event`` belongs to its loop: setting it from another
thread walks its waiters while the loop adds or removes them, and a loaded server then
lost a session now and then ("RuntimeError: deque mutated during iteration", a browser
without frames, or « Erreur interne » for that student).

:func:`install` (called when :mod:`sandbox.web.wire` is imported, before any server
exists) makes the event of every buffer created afterwards a :class:`LoopEvent`: set
from another thread, it only records that it is set (what viser reads synchronously);
set in its loop, it wakes every waiter, even when another thread recorded it first (the
loop's own call, which viser always makes, then wakes them: no wake-up is lost).
"""

from __future__ import annotations

import asyncio
from typing import Any

from sandbox.web.patches import internals_present

_installed = False


class LoopEvent(asyncio.Event):
    """An ``asyncio.Event`` whose :meth:`set` touches its waiters only in its own loop."""

    def set(self) -> None:
        """Record the event; wake the waiters when called in the loop they wait in."""
        try:
            running: asyncio.AbstractEventLoop | None = asyncio.get_running_loop()
        except RuntimeError:  # no loop runs in this thread: a session's or viser's pool
            running = None
        bound = getattr(self, "_loop", None)  # the loop of its first waiter (None before)
        if running is None or (bound is not None and running is not bound):
            self._value = True  # the loop's own set (call_soon_threadsafe) wakes them
            return
        self._value = True
        for waiter in list(self._waiters):
            if not waiter.done():
                waiter.set_result(True)


def _has_internals() -> bool:
    from viser.infra._async_message_buffer import AsyncMessageBuffer

    event = asyncio.Event()
    return (
        hasattr(event, "_waiters")
        and hasattr(event, "_value")
        and bool(getattr(AsyncMessageBuffer, "__dataclass_fields__", {}).get("message_event"))
    )


def install() -> bool:
    """Make the message events of viser's buffers created from now on
    :class:`LoopEvent`s, once per process; True when done (a viser or Python without
    the internals used here is left as it is, with one warning)."""
    global _installed
    if _installed:
        return True
    if not internals_present(  # pragma: no cover - depends on the installed viser and Python
        _has_internals, "this viser's message buffer differs: its events stay as they are"
    ):
        return False
    from viser.infra._async_message_buffer import AsyncMessageBuffer

    made = AsyncMessageBuffer.__init__

    def init(buffer: AsyncMessageBuffer, *args: Any, **kwargs: Any) -> None:
        made(buffer, *args, **kwargs)
        for name in ("message_event", "flush_event"):
            event = getattr(buffer, name)
            if type(event) is asyncio.Event:  # nobody waits yet: same object, safe class
                event.__class__ = LoopEvent

    AsyncMessageBuffer.__init__ = init  # type: ignore[method-assign,assignment]
    _installed = True
    return True
