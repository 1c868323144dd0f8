"""One thread draws every matplotlib chart of the process.

Matplotlib is not thread-safe and a chart costs a few tenths of a second: drawn in
the sessions' loop it would freeze every browser of the process meanwhile, and drawn
from several threads at once it corrupts its text parser's state. Panels submit the
drawing here and pick the image up when it is ready.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, TypeVar

T = TypeVar("T")

_executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="sandbox-charts")


def submit(fn: Callable[..., T], *args: Any) -> Future[T]:
    """Run ``fn(*args)`` on the chart thread, after the charts already waiting."""
    return _executor.submit(fn, *args)
