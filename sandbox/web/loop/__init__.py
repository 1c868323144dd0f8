"""One browser's simulation: a request queue, real-time pacing and the frame loop.

:class:`Controller` owns the :class:`~sandbox.physics.simulation.Simulation` and the
queue; it knows nothing about viser, so tests drive it directly. :class:`Session`
runs the frames that drain the queue, step in real time and ask a :class:`View` (the
viser panels, or anything with the same methods) to draw; the process's
:class:`Scheduler` runs every session's frames in one thread. Nothing here imports viser.

Modules, lowest first: :mod:`~sandbox.web.loop.frame` (what a tick shows, the view's
protocol), :mod:`~sandbox.web.loop.requests` (what the page asks),
:mod:`~sandbox.web.loop.refusals` (checks and French refusals),
:mod:`~sandbox.web.loop.pacing` (stepping in real time),
:mod:`~sandbox.web.loop.controller` (requests applied, recording),
:mod:`~sandbox.web.loop.scheduler` (the loop thread) and
:mod:`~sandbox.web.loop.session` (one browser's frames).
"""

from sandbox.web.loop.controller import Controller
from sandbox.web.loop.frame import EVERY, FPS, Frame, Notice, View
from sandbox.web.loop.refusals import (
    SPEEDS,
    Refused,
    as_number,
    check_speed,
    check_timestep,
    divergence_message,
    french_message,
    shown_value,
    step_count,
)
from sandbox.web.loop.requests import Command, merged, pending
from sandbox.web.loop.scheduler import Scheduler
from sandbox.web.loop.session import Session

__all__ = [
    "EVERY",
    "FPS",
    "SPEEDS",
    "Command",
    "Controller",
    "Frame",
    "Notice",
    "Refused",
    "Scheduler",
    "Session",
    "View",
    "as_number",
    "check_speed",
    "check_timestep",
    "divergence_message",
    "french_message",
    "merged",
    "pending",
    "shown_value",
    "step_count",
]
