"""How many students this laptop holds on this scene: from what the frames cost right now.

A session costs the CPU of its stepping (per wall second, whatever its frame rate) plus
the CPU of each frame it draws and sends (the picture, the tables, the websocket). Each
server process measures both over the governor's windows (:class:`Load`); the teacher's
board adds the processes' loads up and :func:`students_at` turns them into « about N
students at 30 frames/s ». ``sandbox bench --classroom`` prints the same estimate from
its own measures (:func:`students_for`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass
from typing import Any

ESTIMATE_FPS = 30.0
"""The frame rate the estimate is for [Hz]: fluid enough for a class."""

USABLE = 0.85
"""Share of the machine's cores the estimate counts on (the system, the projector's page
and the teacher's own browser take the rest)."""


@dataclass(frozen=True)
class Load:
    """What one server process's sessions cost, over the last measure.

    Attributes:
        sessions: Simulations of their own the process drives (students, the teacher).
        frames: Frames per wall second, every session summed.
        cpu: CPU seconds per wall second of the whole process (every thread).
        stepping: Of which the stepping of the simulations.
        fps: The frame rate the governor runs the sessions at [Hz].
        saturated: The process is past its lowest frame rate.
    """

    sessions: int = 0
    frames: float = 0.0
    cpu: float = 0.0
    stepping: float = 0.0
    fps: float = 60.0
    saturated: bool = False

    def wire(self) -> dict[str, Any]:
        """As plain values (a pipe between processes)."""
        return asdict(self)

    @classmethod
    def from_wire(cls, data: object) -> Load | None:
        """Back from :meth:`wire`, every field checked (None when it is not a load)."""
        if not isinstance(data, Mapping):
            return None
        out: dict[str, Any] = {}
        for name, kind in (("sessions", int), ("frames", float), ("cpu", float),
                           ("stepping", float), ("fps", float)):  # fmt: skip
            value = data.get(name, 0)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                return None
            if not math.isfinite(value) or value < 0 or value > 1e6:
                return None
            out[name] = kind(value)
        saturated = data.get("saturated", False)
        if not isinstance(saturated, bool):
            return None
        return cls(**out, saturated=saturated)


def merged(loads: Iterable[Load]) -> Load:
    """The processes' loads added up (the lowest frame rate, saturated if any is)."""
    loads = list(loads)
    if not loads:
        return Load()
    return Load(
        sessions=sum(x.sessions for x in loads),
        frames=sum(x.frames for x in loads),
        cpu=sum(x.cpu for x in loads),
        stepping=sum(x.stepping for x in loads),
        fps=min(x.fps for x in loads),
        saturated=any(x.saturated for x in loads),
    )


def students_for(
    step_cpu: float, frame_cpu: float, *, cores: int | None = None, fps: float = ESTIMATE_FPS
) -> int:
    """Students ``cores`` hold when each costs ``step_cpu`` CPU seconds of stepping per
    wall second and ``frame_cpu`` CPU seconds per frame drawn and sent, at ``fps``.

    Args:
        step_cpu: Stepping of one simulation [CPU s per wall s].
        frame_cpu: One frame of one session, everything but stepping [CPU s].
        cores: The machine's cores (default: this machine's).
        fps: The frame rate asked for [Hz].
    """
    cores = cores if cores is not None else (os.cpu_count() or 1)
    per = max(step_cpu, 0.0) + fps * max(frame_cpu, 0.0)
    if not per > 0:
        return 0
    return max(0, int(math.floor(cores * USABLE / per)))


def students_at(load: Load, *, cores: int | None = None, fps: float = ESTIMATE_FPS) -> int | None:
    """Students the machine holds at ``fps`` by ``load`` (every process's, merged), or
    None before anything was measured."""
    if load.sessions <= 0 or load.frames <= 0:
        return None
    step = load.stepping / load.sessions
    frame = max(load.cpu - load.stepping, 0.0) / load.frames
    return students_for(step, frame, cores=cores, fps=fps)
