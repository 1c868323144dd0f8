"""One thread draws every matplotlib chart of the process, under one lock.

Matplotlib is not thread-safe and a chart costs a few tenths of a second: drawn in
the sessions' loop it would freeze every browser of the process meanwhile, and drawn
from several threads at once it corrupts its text parser's state (mathtext
``ParseException``, charts lost). Panels submit the drawing here and pick the image up
when it is ready; the drawing itself uses :class:`~matplotlib.figure.Figure` objects
(no pyplot state) and holds :data:`LOCK`, which every other drawer of the process
(``sandbox bench``'s charts) holds too.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import ParamSpec, TypeVar

from sandbox.bench.plot import LOCK

__all__ = ["LOCK", "submit"]

T = TypeVar("T")
P = ParamSpec("P")

_executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="sandbox-charts")


def submit(fn: Callable[P, T], *args: P.args, **kwargs: P.kwargs) -> Future[T]:
    """Run ``fn(*args, **kwargs)`` on the chart thread, holding :data:`LOCK`, after the
    charts already waiting."""

    def locked() -> T:
        with LOCK:
            return fn(*args, **kwargs)

    return _executor.submit(locked)
