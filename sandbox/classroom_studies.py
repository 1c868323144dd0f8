"""Students running parameter studies during the classroom benchmark (``--studies K``):
K of the class's browsers open « Étude paramétrique » and run the scene's first study
again and again, while the others are measured (issue 25: with 30 browsers and 5 of them
running studies, the others keep 30 frames a second).

The studies go to the server's queue, one low-priority process
(:mod:`sandbox.web.study_queue`): what this measures is whether that process and the
studies' panels take frames from the live sessions.
"""

from __future__ import annotations

import asyncio
import math
import time
from dataclasses import dataclass, field
from typing import Any

from sandbox.classroom import (
    ClientStats,
    Side,
    Window,
    camera_message,
    connect_as_browser,
    gui_message,
    messages,
    read_pages,
)

PICKER = "Panneau affiché"
FOLDER = "Étude paramétrique"
RUN = "Lancer l'étude"
DONE = "Étude terminée".encode()
"""The page's words the students use and read (French labels, never code names)."""


@dataclass
class Student:
    """What one studying browser did."""

    uuids: dict[str, str] = field(default_factory=dict)
    studies: int = 0  # studies finished
    started: int = 0
    error: str | None = None
    finished: asyncio.Event = field(default_factory=asyncio.Event)


def _learn(student: Student, inner: bytes) -> None:
    if DONE in inner:
        student.finished.set()
    if b"Gui" not in inner:
        return
    for m in messages(inner):
        props = m.get("props")
        if isinstance(props, dict) and props.get("label") in (PICKER, RUN) and "uuid" in m:
            student.uuids[str(props["label"])] = str(m["uuid"])


async def study(url: str, origin: str, window: Window, student: Student) -> None:
    """Connect, open the folder, run its study until the window ends; errors kept."""
    try:
        async with connect_as_browser(url, origin, open_timeout=30) as ws:
            await ws.send(camera_message())
            reader = asyncio.create_task(read_pages(ws, lambda inner: _learn(student, inner)))
            try:
                end = time.perf_counter() + 30.0
                while not {PICKER, RUN} <= set(student.uuids):
                    if time.perf_counter() > end:
                        raise TimeoutError("no « Étude paramétrique » on the page")
                    await asyncio.sleep(0.05)
                await ws.send(gui_message(student.uuids[PICKER], FOLDER))
                while not math.isfinite(window.end) or time.perf_counter() < window.end:
                    student.finished.clear()
                    await ws.send(gui_message(student.uuids[RUN], True))
                    student.started += 1
                    try:
                        await asyncio.wait_for(student.finished.wait(), timeout=120.0)
                    except TimeoutError:
                        break
                    student.studies += 1
            finally:
                reader.cancel()
    except asyncio.CancelledError:
        raise
    except Exception as exc:
        student.error = f"{type(exc).__name__}: {exc}"


def side(students: int) -> Side:
    """``students`` browsers running studies beside the measured class (for
    :func:`~sandbox.classroom.main_phase`'s ``side``): returns how many studies they
    finished and the measured clients' slowest frame rate."""

    async def run(
        url: str, origin: str, window: Window, stats: list[ClientStats]
    ) -> dict[str, Any]:
        crowd = [Student() for _ in range(students)]
        tasks = [asyncio.create_task(study(url, origin, window, s)) for s in crowd]
        while not math.isfinite(window.end) or time.perf_counter() < window.end:
            await asyncio.sleep(0.1)
        for t in tasks:
            t.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)
        fps = [s.fps(window) for s in stats]
        return {
            "students": students,
            "studies_started": sum(s.started for s in crowd),
            "studies_finished": sum(s.studies for s in crowd),
            "errors": sorted({s.error for s in crowd if s.error}),
            "others_fps_min": min(fps) if fps else math.nan,
        }

    return run
