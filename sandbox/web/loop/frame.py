"""What one display tick shows: the :class:`Frame` built once per tick, the :class:`Notice`
messages for the user, the :class:`View` protocol of a display (the viser panels, or
anything with the same methods) the loop hands them to, and the :class:`Source` protocol
of what a session shows (a live controller, or a replay).
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from typing import Protocol

from sandbox.physics.picture import Picture
from sandbox.physics.simulation import Simulation
from sandbox.physics.snapshot import Snapshot
from sandbox.web.loop.requests import Command
from sandbox.web.loop.secret import Secret

FPS = 60.0
"""Frame rate of pose updates sent to the browser [Hz]."""


@dataclass(frozen=True)
class Notice:
    """A message for the user: ``level`` is ``error``, ``diverged``, ``info`` or ``file``
    (``text`` is then the path of a file to offer for download)."""

    level: str
    title: str
    text: str


EVERY = frozenset({"*"})
"""What a view wants when it needs every readout (an open lesson may check any)."""


@dataclass(frozen=True)
class Frame:
    """What one display tick shows, built once by the session loop and handed to every
    consumer (the browser's view, the recorder).

    Attributes:
        now: Wall clock of the tick [s].
        time: Simulated time drawn [s] (the display time, between two physics steps).
        generation: Bumped on every reset (plots restart).
        model_id: Identity of the compiled model (a new one rebuilds the 3D nodes).
        playing: The simulation runs.
        diverged: The divergence message, or None.
        notices: Messages raised since the previous tick.
        readouts: Values of the readouts asked for this tick (computed once, only the
            names a consumer needs); None on ticks that refresh no panel.
        picture: What the 3D view draws (poses, arrows), computed once when the drawn
            state changed and a view draws; None otherwise (nothing moved: nothing sent).
        state: The state ``readouts`` were computed from (the drawn state, its forces
            prepared), for the panels that compute their own numbers from a state
            (« Isoler un solide », the basis of a solid): one instant for the whole
            frame. None: the physics state's (while recording, a replay), or no readouts.
        held: While a fast rotation's numbers are held at one angle
            (:mod:`sandbox.physics.strobe`), the arrows evaluated at that instant (their
            labels and components write them; ``readouts`` and ``state`` are that
            instant's too); None otherwise.
    """

    now: float
    time: float
    generation: int
    model_id: int
    playing: bool
    diverged: str | None
    notices: tuple[Notice, ...] = ()
    readouts: Mapping[str, float] | None = None
    picture: Picture | None = None
    state: Snapshot | None = None
    held: Picture | None = None

    @property
    def key(self) -> tuple[int, float, int]:
        """Changes whenever the drawn state changes (model, time, reset)."""
        return (self.model_id, self.time, self.generation)


class View(Protocol):
    """What the loop needs from a display (the viser panels implement it)."""

    @property
    def draws(self) -> bool:
        """True when :meth:`render` draws the 3D scene: each new drawn state then comes
        with a :class:`~sandbox.physics.picture.Picture`."""

    def wants(self, now: float) -> Collection[str] | None:
        """Readouts needed at this tick: names, :data:`EVERY`, or None (no panel
        refresh now)."""

    def render(self, frame: Frame) -> None:
        """Draw the tick (called at up to :data:`FPS`)."""

    def notify(self, notice: Notice) -> None:
        """Show a message to the user."""


class Source(Protocol):
    """What a session reads from the source it shows, whichever it is: a live
    :class:`~sandbox.web.loop.controller.Controller`, or a replay moving along its
    recording (:class:`~sandbox.web.replay.player.ReplayController`, which draws its
    simulation's own state, records nothing, measures no cost and has no challenge).
    The session asks the same of both: no ``isinstance`` on the source."""

    @property
    def sim(self) -> Simulation:
        """The simulation whose state is drawn."""

    @property
    def clock(self) -> Callable[[], float]:
        """Wall clock [s]."""

    @property
    def playing(self) -> bool:
        """True while it runs."""

    @property
    def diverged(self) -> str | None:
        """The divergence message, or None."""

    @property
    def generation(self) -> int:
        """Bumped when the plots restart."""

    @property
    def cleanups(self) -> list[Callable[[], None]]:
        """Run when its session ends."""

    @property
    def secret(self) -> Secret | None:
        """A challenge's secret in force (never for a replay)."""

    @property
    def drawn_time(self) -> float:
        """Simulated time drawn [s] (between physics steps for a live source)."""

    @property
    def step_cpu_total(self) -> float:
        """CPU seconds spent stepping so far (0 for a replay)."""

    def submit(self, request: Command) -> None:
        """Queue a typed command; the loop thread applies it before its next frame (what
        a replay cannot do is refused there, in French)."""

    def frame(self, now: float | None = None, *, record: bool = True) -> list[Notice]:
        """Apply the requests and move on (step, or along the recording); returns the
        messages. ``record``: write the recording's row now (the session records itself
        after reading the state once)."""

    def drawn(self, names: Collection[str] = (), *, forces: bool = False) -> Snapshot:
        """The state to draw, its forces brought up to date when ``forces`` is set."""

    def held(self) -> Snapshot | None:
        """The state a fast rotation's numbers are read at (:mod:`sandbox.physics.strobe`),
        or None: they are read at the drawn instant."""

    def shown_readouts(
        self, names: Collection[str], *, snapshot: Snapshot | None = None
    ) -> Mapping[str, float]:
        """The readouts a view shows (of ``snapshot`` when given)."""

    def readouts(self, names: Collection[str]) -> Mapping[str, float]:
        """The readouts of the physics state (a recording's row)."""

    def readouts_due(self) -> bool:
        """True when a recording row is due at this tick."""

    def record(self, values: Mapping[str, float] | None = None) -> None:
        """Write the recording's row (``values``: already computed) when one is due."""

    def stop_recording(self) -> object:
        """Close the recording in progress (nothing for a replay)."""
