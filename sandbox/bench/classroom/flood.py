"""A hostile student for the classroom benchmark (``--flood``): one more browser that sets
the smallest timestep, a "Pas" of 0.02 s in « Affichage », and clicks « Avancer d'un
pas » every 100 ms (70 times), as issue 20 found it done. In ``--follow`` it first leaves
for « Ma simulation », so the teacher's projection is what it could slow.

The other browsers' frame rate during the flood is compared with theirs just before it
(:func:`flood_ratio`): a session may only slow itself.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from sandbox.bench.classroom.browser import (
    camera_message,
    connect_as_browser,
    gui_message,
    read_pages,
)
from sandbox.bench.classroom.client import ClientStats, Window
from sandbox.bench.classroom.phases import Side
from sandbox.bench.classroom.wire import messages

TIMESTEP = "Pas de temps dt [s]"
STEP_LENGTH = "Pas"
STEP_UNIT = "Unité du pas"
SECONDS = "secondes"
STEP_BUTTON = "Avancer d'un pas"
OWN = "Ma simulation"
"""Labels of the controls the flooder uses (the page's French words)."""

SMALLEST_TIMESTEP = 1e-6
STEP_SECONDS = 0.02
CLICKS = 70
CLICK_PERIOD = 0.1
"""The flood: 70 clicks 100 ms apart, each a "Pas" of 20,000 timesteps."""


@dataclass
class Flooder:
    """What the hostile browser did."""

    uuids: dict[str, str] = field(default_factory=dict)  # label -> uuid, latest seen
    clicks: int = 0
    refused: int = 0  # the page's refusals it was shown ("Pas refusé")
    error: str | None = None


def _learn(flooder: Flooder, inner: bytes) -> None:
    """Remember the uuid of every control the flood needs (their latest: a switch to
    « Ma simulation » rebuilds the panels)."""
    if b"Gui" not in inner:
        return
    wanted = (TIMESTEP, STEP_LENGTH, STEP_UNIT, STEP_BUTTON, OWN)
    for m in messages(inner):
        props = m.get("props")
        if isinstance(props, dict) and props.get("label") in wanted and "uuid" in m:
            flooder.uuids[str(props["label"])] = str(m["uuid"])
        if m.get("type") == "NotificationShowMessage" and "refusé" in str(m.get("props", "")):
            flooder.refused += 1


async def flood(
    url: str, origin: str, window: Window, flooder: Flooder, *, follow: bool = False
) -> None:
    """Connect, wait for the second half of ``window``, then flood; errors are kept."""
    try:
        async with connect_as_browser(url, origin, open_timeout=30) as ws:
            await ws.send(camera_message())
            reader = asyncio.create_task(read_pages(ws, lambda inner: _learn(flooder, inner)))
            try:
                await _wait_for(flooder, OWN if follow else STEP_BUTTON)
                if follow:
                    await ws.send(gui_message(flooder.uuids.pop(OWN), True))
                    flooder.uuids.pop(STEP_BUTTON, None)
                    await _wait_for(flooder, STEP_BUTTON)
                while not math.isfinite(window.start):
                    await asyncio.sleep(0.05)
                await asyncio.sleep(max(0.0, flood_start(window) - time.perf_counter()))
                ids = flooder.uuids
                await ws.send(gui_message(ids[TIMESTEP], SMALLEST_TIMESTEP))
                await ws.send(gui_message(ids[STEP_UNIT], SECONDS))
                await ws.send(gui_message(ids[STEP_LENGTH], STEP_SECONDS))
                for _ in range(CLICKS):
                    await ws.send(gui_message(ids[STEP_BUTTON], True))
                    flooder.clicks += 1
                    await asyncio.sleep(CLICK_PERIOD)
            finally:
                reader.cancel()
    except asyncio.CancelledError:
        raise
    except Exception as exc:
        flooder.error = f"{type(exc).__name__}: {exc}"


async def _wait_for(flooder: Flooder, label: str, timeout: float = 30.0) -> None:
    end = time.perf_counter() + timeout
    while label not in flooder.uuids:
        if time.perf_counter() > end:
            raise TimeoutError(f"no control labelled {label!r} on the page")
        await asyncio.sleep(0.05)


def flood_start(window: Window) -> float:
    """When the flood starts: the middle of the measurement window."""
    return window.start + 0.5 * (window.end - window.start)


def side(*, follow: bool = False) -> Side:
    """The flood as a task beside the classroom's clients
    (:func:`~sandbox.bench.classroom.phases.main_phase`'s ``side``): it returns the clients'
    frame rates before and during it (:func:`flood_ratio`)."""

    async def run(
        url: str, origin: str, window: Window, stats: list[ClientStats]
    ) -> dict[str, Any]:
        flooder = Flooder()
        task = asyncio.create_task(flood(url, origin, window, flooder, follow=follow))
        while not math.isfinite(window.end) or time.perf_counter() < window.end:
            await asyncio.sleep(0.1)
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
        out: dict[str, Any] = flood_ratio(stats, window, flood_start(window))
        out.update(clicks=flooder.clicks, refused=flooder.refused, error=flooder.error)
        return out

    return run


def fps_between(stats: ClientStats, start: float, end: float) -> float:
    """Update frames per second a client received between ``start`` and ``end``."""
    if end <= start:
        return math.nan
    return sum(1 for t in stats.frame_times if start <= t < end) / (end - start)


def flood_ratio(stats: Sequence[ClientStats], window: Window, start: float) -> dict[str, float]:
    """Frame rates before and during the flood (median over the clients) and the worst
    client's ratio of the two."""
    before = [fps_between(s, window.start, start) for s in stats]
    during = [fps_between(s, start, window.end) for s in stats]
    ratios = [d / b for b, d in zip(before, during, strict=True) if b > 0]
    return {
        "fps_before": _median(before),
        "fps_during": _median(during),
        "ratio_min": min(ratios) if ratios else math.nan,
    }


def _median(values: Sequence[float]) -> float:
    good = sorted(v for v in values if math.isfinite(v))
    if not good:
        return math.nan
    mid = len(good) // 2
    return good[mid] if len(good) % 2 else 0.5 * (good[mid - 1] + good[mid])
