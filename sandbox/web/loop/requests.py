"""Requests: what a GUI callback asks of the simulation loop, queued by any thread and
applied by the loop thread, repeated settings merged first.
"""

from __future__ import annotations

import queue
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Request:
    """Something a GUI callback asks of the simulation loop.

    Attributes:
        kind: ``set_value``, ``play``, ``pause``, ``toggle``, ``step`` (timesteps),
            ``advance`` (a "Pas" in time or angle), ``reset``, ``speed``,
            ``integrator`` or ``timestep``; ``challenge`` (a
            :class:`~sandbox.web.secret.Secret`, or None to end it: built by the server,
            no control sends it).
        name: Parameter name for ``set_value``; ``s`` or ``deg`` for ``advance`` (the
            unit of ``value``: seconds, or degrees of the main rotating joint).
        value: The new value, unvalidated.
    """

    kind: str
    value: Any = None
    name: str = ""


def pending(requests: queue.Queue[Request]) -> Iterator[Request]:
    """The requests waiting in ``requests``, removed as they are yielded."""
    while True:
        try:
            yield requests.get_nowait()
        except queue.Empty:
            return


def merged(requests: list[Request]) -> list[Request]:
    """``requests`` with repeated settings merged: of several values of one slider, of
    the speed, the timestep or the integrator, only the last is kept (at its place)."""
    settings = ("set_value", "speed", "timestep", "integrator", "seek")
    last = {(r.kind, r.name): i for i, r in enumerate(requests) if r.kind in settings}
    return [
        r for i, r in enumerate(requests) if r.kind not in settings or last[(r.kind, r.name)] == i
    ]
