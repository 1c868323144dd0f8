"""What a panel may know of its session: a read-only view of the state it shows, and the
few ways it acts, all of them queued or bounded (:class:`SessionState`).

Panels are typed against this protocol, never against the
:class:`~sandbox.web.loop.controller.Controller`: they read the simulation, the speed, the
recording and the challenge in force, and they act by :meth:`~SessionState.submit`
(a request the loop thread applies before its next frame) and
:meth:`~SessionState.on_close`; the one thing a panel sets is the lesson the page follows
(:attr:`~SessionState.lesson`, recorded with the session). The controller satisfies it
as it is.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.recording import Recorder
from sandbox.web.loop.probe import Probe
from sandbox.web.loop.requests import Command
from sandbox.web.loop.rewind import Rewind
from sandbox.web.loop.secret import Secret


class SessionState(Protocol):
    """One live session as its panels see it."""

    @property
    def sim(self) -> ReadOnlySimulation:
        """The session's simulation, read only (parameter values, model, readouts): a
        panel changes it by :meth:`submit`."""

    @property
    def speed(self) -> float:
        """Simulated seconds per wall second."""

    @property
    def playing(self) -> bool:
        """The simulation runs."""

    @property
    def diverged(self) -> str | None:
        """Why the simulation stopped diverging (None: it did not)."""

    @property
    def refusals(self) -> int:
        """Requests refused so far (the panels then show the real values)."""

    @property
    def recorder(self) -> Recorder | None:
        """The recording in progress."""

    @property
    def secret(self) -> Secret | None:
        """What the page keeps while a challenge runs."""

    lesson: str | None
    """The lesson the page follows (set by the lesson panel, recorded with the session)."""

    lesson_step: int | None
    """The lesson's step the page shows (0 for the first; a recording starts with it)."""

    @property
    def cost(self) -> float:
        """CPU seconds of stepping per simulated second (NaN before any step)."""

    @property
    def probe(self) -> Probe:
        """Readouts sampled between frames, for an X–Y plot."""

    @property
    def rewind(self) -> Rewind:
        """The last seconds, for « Exporter une vidéo »."""

    def slowed(self, now: float | None = None) -> bool:
        """The status says "slower than real time"."""

    def pending(self) -> bool:
        """Requests wait for the loop (a control may be ahead of the simulation)."""

    def submit(self, request: Command) -> None:
        """Queue a request; the loop thread applies it before its next frame."""

    def on_close(self, cleanup: Callable[[], None]) -> None:
        """Run ``cleanup`` when the session ends."""
