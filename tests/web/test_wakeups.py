"""viser's "a message is waiting" event is only ever touched by its own event loop
(sandbox.web.client.wakeups): a session thread queueing a message leaves the loop's waiters alone,
and every message still reaches its browser."""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import threading
import time
from collections import deque
from collections.abc import Iterator

import pytest
from conftest import wait_for
from viser.infra._async_message_buffer import AsyncMessageBuffer
from viser.infra._messages import Message

from sandbox.web.client import wire  # noqa: F401  (installs the loop-bound events, as the app does)
from sandbox.web.client.wakeups import LoopEvent


class _Loop:
    """An event loop running in its own thread, as viser's server runs it."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()

    def close(self) -> None:
        async def cancel_the_rest() -> None:
            rest = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
            for task in rest:
                task.cancel()
            await asyncio.gather(*rest, return_exceptions=True)

        asyncio.run_coroutine_threadsafe(cancel_the_rest(), self.loop).result(5)
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


@dataclasses.dataclass
class _Note(Message):
    """A message as a session queues them (each one kept: distinct redundancy keys)."""

    n: int

    def redundancy_key(self) -> str:
        return f"note-{self.n}"


@contextlib.contextmanager
def _atomic(buffer: AsyncMessageBuffer) -> Iterator[None]:
    """viser's ``atomic()`` block on one buffer (a page being built)."""
    buffer.atomic_start()
    try:
        yield
    finally:
        buffer.atomic_end()


def _watched_waiter(loop: _Loop, event: asyncio.Event) -> tuple[_Watched, threading.Event]:
    waiters = _Watched(loop.thread)
    event._waiters = waiters  # type: ignore[attr-defined]
    woken = threading.Event()

    async def wait() -> None:
        await event.wait()
        woken.set()

    asyncio.run_coroutine_threadsafe(wait(), loop.loop)
    assert wait_for(lambda: len(waiters) == 1)
    return waiters, woken


def test_every_new_message_buffer_gets_an_event_bound_to_its_loop(loop):
    buffer = AsyncMessageBuffer(loop.loop, persistent_messages=False)
    assert type(buffer.message_event) is LoopEvent
    assert buffer.message_event.home is loop.loop


def test_a_session_thread_pushing_never_touches_the_loops_waiters(loop):
    """The direct set of ``push`` does nothing off the loop; the loop's own set, which
    ``push`` schedules right after, wakes the waiter."""
    buffer = AsyncMessageBuffer(loop.loop, persistent_messages=False)
    waiters, woken = _watched_waiter(loop, buffer.message_event)
    buffer.message_event.set()  # as push does, from a session thread
    assert not buffer.message_event.is_set()
    assert not woken.wait(0.2)  # nothing happened off the loop...
    buffer.push(_Note(0))  # ...and a real push wakes the waiter from the loop
    assert woken.wait(5)
    assert waiters.foreign == []  # only the loop ever touched its waiters


def test_a_push_inside_an_atomic_block_wakes_the_loop_when_the_block_ends(loop):
    buffer = AsyncMessageBuffer(loop.loop, persistent_messages=False)
    waiters, woken = _watched_waiter(loop, buffer.message_event)
    with _atomic(buffer):
        buffer.push(_Note(0))
        assert not woken.wait(0.2)  # viser sends nothing in the middle of a block
    assert woken.wait(5)
    assert waiters.foreign == []


def test_the_stock_event_walks_the_waiters_from_the_session_thread(loop):
    """What the patch prevents: asyncio's own event, set from another thread, resolves
    the loop's waiter from that thread (iterating a deque the loop changes)."""
    event = asyncio.Event()
    waiters, woken = _watched_waiter(loop, event)
    event.set()
    assert waiters.foreign == ["iterated"]
    loop.loop.call_soon_threadsafe(lambda: None)  # let the loop run the woken waiter
    assert woken.wait(5)


def test_messages_pushed_from_many_threads_all_reach_their_browser_without_delay(loop):
    """Four session threads queue bursts (some in atomic blocks) while the loop's window
    generator sends them: every message arrives, none waits for the next burst."""
    buffer = AsyncMessageBuffer(loop.loop, persistent_messages=False)
    received: list[int] = []

    async def browser() -> None:
        async for window in buffer.window_generator(client_id=1):
            received.extend(m.n for m in window if isinstance(m, _Note))

    asyncio.run_coroutine_threadsafe(browser(), loop.loop)
    counter = iter(range(1_000_000))
    lock = threading.Lock()

    def session(k: int) -> None:
        for burst in range(40):
            if burst % 3 == 0:
                buffer.atomic_start()
            for _ in range(5):
                with lock:
                    n = next(counter)
                buffer.push(_Note(n))
            if burst % 3 == 0:
                buffer.atomic_end()
            time.sleep(0.002)

    threads = [threading.Thread(target=session, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    # the last burst arrives in a window or two (1/60 s each), not at the next message
    assert wait_for(lambda: len(received) == 4 * 40 * 5, timeout=2), len(received)
    assert sorted(received) == list(range(4 * 40 * 5))
    buffer.set_done()
