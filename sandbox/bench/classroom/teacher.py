"""The teacher's page during a classroom run: what « La classe » says of the laptop (its
capacity estimate, a lowered frame rate, saturation), read from its websocket as the
browser would show it, so that the benchmark prints the very estimate a teacher reads.
"""

from __future__ import annotations

import asyncio
import re
from typing import Any

from sandbox.bench.classroom.browser import camera_message, connect_as_browser
from sandbox.bench.classroom.wire import unpack

CAPACITY = re.compile("Ce portable tient environ \\*\\*([0-9]+) élève".encode())
"""The estimate's sentence on the teacher's board (UTF-8 bytes on the wire)."""
LOWERED = re.compile("images abaissées à ([0-9]+) par seconde".encode())
SATURATED = "Portable saturé".encode()
BOARD = b"sandbox-board"
"""The board's table (sandbox.web.panels.board_table.BOARD_CLASS)."""
FOLLOWING = b"suit la projection"
"""A follower's cell on the board."""


class TeacherPage:
    """Reads the teacher's board until cancelled; keeps the last values it showed."""

    def __init__(self) -> None:
        self.students: int | None = None
        self.estimates: list[int] = []
        self.lowered_fps: int | None = None
        self.saturated = False
        self.following = 0  # students following the projection, on the last board read
        self.error: str | None = None

    async def read(self, url: str, origin: str) -> None:
        """Open the teacher's page at ``url`` and read what its board says."""
        try:
            async with connect_as_browser(url, origin, open_timeout=30) as ws:
                await ws.send(camera_message())
                async for raw in ws:
                    if not isinstance(raw, bytes):
                        continue
                    inner = unpack(raw)
                    if b"Ce portable" in inner:
                        found = CAPACITY.findall(inner)
                        if found:
                            self.students = int(found[-1])
                            self.estimates.append(self.students)
                    lowered = LOWERED.findall(inner)
                    if lowered:
                        self.lowered_fps = int(lowered[-1])
                    if SATURATED in inner:
                        self.saturated = True
                    if BOARD in inner:
                        self.following = inner.count(FOLLOWING)
        except asyncio.CancelledError:
            raise
        except Exception as exc:  # the estimate is a figure of the run: its absence is said
            self.error = f"{type(exc).__name__}: {exc}"

    def results(self) -> dict[str, Any]:
        """What the teacher read: the last estimate, the estimates seen, the lowered
        frame rate and whether the laptop said it was saturated."""
        return {
            "students": self.students,
            "estimates": self.estimates[-20:],
            "lowered_fps": self.lowered_fps,
            "saturated": self.saturated,
            "following": self.following,
            "error": self.error,
        }
