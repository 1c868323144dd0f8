"""Students running background work during the classroom benchmark: ``--studies K``, K of
the class's browsers open « Étude paramétrique » and run the scene's first study again
and again (issue 25: with 30 browsers and 5 of them running studies, the others keep 30
frames a second); ``--videos K``, K browsers click « Exporter une vidéo » again and again
(issue 26: no frame lost for the other browsers), while the others are measured.

The studies go to the server's queue, one low-priority process
(:mod:`sandbox.web.loop.study_queue`): what this measures is whether that process and the
studies' panels take frames from the live sessions.
"""

from __future__ import annotations

import asyncio
import math
import time
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

PICKER = "Panneau affiché"
FOLDER = "Étude paramétrique"
RUN = "Lancer l'étude"
DONE = "Étude terminée".encode()
"""The page's words the students use and read (French labels, never code names)."""


@dataclass(frozen=True)
class Work:
    """What a student does: the folder it picks (None: a folder always there), the
    button it clicks, the words that say it is done."""

    folder: str | None
    button: str
    done: bytes


STUDY = Work(FOLDER, RUN, DONE)
VIDEO = Work(None, "Exporter une vidéo", "Vidéo prête".encode())


@dataclass
class Student:
    """What one studying browser did."""

    work: Work = STUDY
    uuids: dict[str, str] = field(default_factory=dict)
    studies: int = 0  # studies (or videos) finished
    started: int = 0
    error: str | None = None
    finished: asyncio.Event = field(default_factory=asyncio.Event)


def _learn(student: Student, inner: bytes) -> None:
    if student.work.done in inner:
        student.finished.set()
    if b"Gui" not in inner:
        return
    wanted = (PICKER, student.work.button)
    for m in messages(inner):
        props = m.get("props")
        if isinstance(props, dict) and props.get("label") in wanted and "uuid" in m:
            student.uuids[str(props["label"])] = str(m["uuid"])


async def study(url: str, origin: str, window: Window, student: Student) -> None:
    """Connect, open the folder, run its study until the window ends; errors kept."""
    try:
        async with connect_as_browser(url, origin, open_timeout=30) as ws:
            await ws.send(camera_message())
            reader = asyncio.create_task(read_pages(ws, lambda inner: _learn(student, inner)))
            try:
                work = student.work
                needed = {PICKER, work.button} if work.folder else {work.button}
                end = time.perf_counter() + 30.0
                while not needed <= set(student.uuids):
                    if time.perf_counter() > end:
                        raise TimeoutError(f"no « {work.button} » on the page")
                    await asyncio.sleep(0.05)
                if work.folder is not None:
                    await ws.send(gui_message(student.uuids[PICKER], work.folder))
                await asyncio.sleep(2.0)  # a video needs some seconds of motion
                while not math.isfinite(window.end) or time.perf_counter() < window.end:
                    student.finished.clear()
                    await ws.send(gui_message(student.uuids[work.button], True))
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


def side(students: int, work: Work = STUDY) -> Side:
    """``students`` browsers doing ``work`` beside the measured class (for
    :func:`~sandbox.bench.classroom.phases.main_phase`'s ``side``): returns how many they
    finished and the measured clients' slowest frame rate."""

    async def run(
        url: str, origin: str, window: Window, stats: list[ClientStats]
    ) -> dict[str, Any]:
        crowd = [Student(work) for _ in range(students)]
        tasks = [asyncio.create_task(study(url, origin, window, s)) for s in crowd]
        while not math.isfinite(window.end) or time.perf_counter() < window.end:
            await asyncio.sleep(0.1)
        for t in tasks:
            t.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)
        fps = [s.fps(window) for s in stats]
        return {
            "students": students,
            "work": "videos" if work is VIDEO else "studies",
            "studies_started": sum(s.started for s in crowd),
            "studies_finished": sum(s.studies for s in crowd),
            "errors": sorted({s.error for s in crowd if s.error}),
            "others_fps_min": min(fps) if fps else math.nan,
        }

    return run
