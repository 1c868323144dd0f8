"""viser's "a message is waiting" event is set from the session threads without touching
the waiters of the loop (sandbox.web.wakeups)."""

from __future__ import annotations

import asyncio
import threading
from collections import deque

import pytest
from conftest import wait_for
from viser.infra._async_message_buffer import AsyncMessageBuffer

from sandbox.web import wire  # noqa: F401  (installs the safe events, as the app does)
from sandbox.web.wakeups import LoopEvent


class _Loop:
    """An event loop running in its own thread, as viser's server runs it."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()

    def run(self, coro, timeout: float = 5.0):
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def close(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(5)
        self.loop.close()


@pytest.fixture
def loop():
    running = _Loop()
    yield running
    running.close()


class _Watched(deque):
    """Waiters that note the threads walking or changing them."""

    def __init__(self, owner: threading.Thread) -> None:
        super().__init__()
        self.owner = owner
        self.foreign: list[str] = []

    def _check(self, what: str) -> None:
        if threading.current_thread() is not self.owner:
            self.foreign.append(what)

    def __iter__(self):
        self._check("iterated")
        return super().__iter__()

    def append(self, item) -> None:
        self._check("appended")
        super().append(item)

    def remove(self, item) -> None:
        self._check("removed")
        super().remove(item)


def test_every_new_message_buffer_gets_loop_events(loop):
    buffer = AsyncMessageBuffer(loop.loop, persistent_messages=False)
    assert type(buffer.message_event) is LoopEvent
    assert type(buffer.flush_event) is LoopEvent


def test_a_session_thread_setting_the_event_never_walks_the_loops_waiters(loop):
    """Set from another thread, the event is only recorded (what viser reads at once);
    the loop's own set, which viser always asks for with call_soon_threadsafe, wakes the
    waiter, although the event was already recorded as set (no wake-up lost)."""
    buffer = AsyncMessageBuffer(loop.loop, persistent_messages=False)
    event = buffer.message_event
    waiters = _Watched(loop.thread)
    event._waiters = waiters  # type: ignore[attr-defined]
    woken = threading.Event()

    async def wait() -> None:
        await event.wait()
        woken.set()

    asyncio.run_coroutine_threadsafe(wait(), loop.loop)
    assert wait_for(lambda: len(waiters) == 1)
    event.set()  # a session thread pushing a message
    assert event.is_set()
    assert not woken.wait(0.2)  # not woken from the wrong thread...
    loop.loop.call_soon_threadsafe(event.set)  # ...but by viser's follow-up in the loop
    assert woken.wait(5)
    assert waiters.foreign == []  # nothing but the loop ever touched its waiters


def test_the_stock_event_walks_the_waiters_from_the_session_thread(loop):
    """What the patch prevents: asyncio's own event, set from another thread, resolves
    the loop's waiter from that thread (iterating a deque the loop changes)."""
    event = asyncio.Event()
    waiters = _Watched(loop.thread)
    event._waiters = waiters  # type: ignore[attr-defined]

    async def wait() -> None:
        await event.wait()

    asyncio.run_coroutine_threadsafe(wait(), loop.loop)
    assert wait_for(lambda: len(waiters) == 1)
    event.set()
    assert waiters.foreign == ["iterated"]
    loop.loop.call_soon_threadsafe(lambda: None)  # let the waiter finish


def test_a_viser_without_the_internals_is_left_as_it_is_with_one_warning(caplog):
    from sandbox.web.patches import internals_present

    def missing() -> bool:
        raise ImportError("no such module")

    assert internals_present(lambda: True, "unused")
    assert not internals_present(lambda: False, "events stay as they are")
    assert not internals_present(missing, "uploads are not capped")
    assert [r.getMessage() for r in caplog.records] == [
        "events stay as they are",
        "uploads are not capped",
    ]
