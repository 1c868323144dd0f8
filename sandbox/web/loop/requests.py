"""Requests: what a GUI callback asks of the simulation loop, queued by any thread and
applied by the loop thread, repeated settings merged first.

A :class:`Request` holds the page's words (a kind, a value, a name: strings and values
from a browser, unvalidated, perhaps crafted); :func:`command` reads it as one of the
small typed requests of :data:`Command`, which the controller dispatches with ``match``.
"""

from __future__ import annotations

import queue
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any, TypeAlias


@dataclass(frozen=True)
class Request:
    """Something a GUI callback asks of the simulation loop.

    Attributes:
        kind: ``set_value``, ``play``, ``pause``, ``toggle``, ``step`` (timesteps),
            ``advance`` (a "Pas" in time or angle), ``reset``, ``speed``,
            ``integrator``, ``timestep`` or ``motion`` ("imposed" or "free"); ``challenge`` (a
            :class:`~sandbox.web.loop.secret.Secret`, or None to end it: built by the server,
            no control sends it).
        name: Parameter name for ``set_value``; ``s`` or ``deg`` for ``advance`` (the
            unit of ``value``: seconds, or degrees of the main rotating joint).
        value: The new value, unvalidated.

    :func:`command` reads it as a typed request.
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
    settings = ("set_value", "speed", "timestep", "integrator", "motion", "seek")
    last = {(r.kind, r.name): i for i, r in enumerate(requests) if r.kind in settings}
    return [
        r for i, r in enumerate(requests) if r.kind not in settings or last[(r.kind, r.name)] == i
    ]


@dataclass(frozen=True)
class Play:
    """Run the simulation (it takes over from a "Pas" in progress)."""


@dataclass(frozen=True)
class Pause:
    """Stop the simulation."""


@dataclass(frozen=True)
class Toggle:
    """Play when paused, pause when playing."""


@dataclass(frozen=True)
class Reset:
    """Start again from the initial state (plots restart)."""


@dataclass(frozen=True)
class Steps:
    """A "Pas" of timesteps.

    Attributes:
        count: Timesteps asked, unvalidated (None: one).
    """

    count: object = None


@dataclass(frozen=True)
class Advance:
    """A "Pas" in time or angle.

    Attributes:
        amount: Seconds, or degrees of the main rotating joint, unvalidated.
        unit: ``s`` or ``deg``, unvalidated.
    """

    amount: object
    unit: str


@dataclass(frozen=True)
class Speed:
    """A new speed factor.

    Attributes:
        factor: The factor (×), unvalidated.
    """

    factor: object


@dataclass(frozen=True)
class Seek:
    """Go to a time of a recording's timeline (a replay's scrubber; a live session
    refuses it).

    Attributes:
        seconds: The time on the timeline [s], unvalidated.
    """

    seconds: object


@dataclass(frozen=True)
class SetValue:
    """A new value of a scene parameter.

    Attributes:
        name: The parameter's name, unvalidated.
        value: The value (in the parameter's unit), unvalidated.
    """

    name: str
    value: object


@dataclass(frozen=True)
class Integrator:
    """Another integrator.

    Attributes:
        name: The integrator's name, unvalidated.
    """

    name: object


@dataclass(frozen=True)
class Timestep:
    """Another timestep.

    Attributes:
        seconds: The timestep dt [s], unvalidated.
    """

    seconds: object


@dataclass(frozen=True)
class Motion:
    """Impose the input's motion exactly, or simulate it.

    Attributes:
        name: "imposed" or "free", unvalidated.
    """

    name: object


@dataclass(frozen=True)
class Challenge:
    """Start or end a challenge (built by the server: no control sends it).

    Attributes:
        secret: A :class:`~sandbox.web.loop.secret.Secret` to start, None to end it (anything
            else is refused).
    """

    secret: object


@dataclass(frozen=True)
class Record:
    """Start recording."""


@dataclass(frozen=True)
class StopRecord:
    """Close the recording (the page offers the file)."""


@dataclass(frozen=True)
class Button:
    """A button of that label, which no button has (only a crafted message sends it).

    Attributes:
        label: The label, unvalidated.
    """

    label: object


@dataclass(frozen=True)
class Unknown:
    """A kind of request the loop does not know.

    Attributes:
        kind: The kind, as the page sent it.
    """

    kind: object


Command: TypeAlias = (
    Play
    | Pause
    | Toggle
    | Reset
    | Steps
    | Advance
    | Speed
    | Seek
    | SetValue
    | Integrator
    | Timestep
    | Motion
    | Challenge
    | Record
    | StopRecord
    | Button
    | Unknown
)
"""A typed request: what the controller does, one small class per kind."""

COMMANDS: Mapping[str, Callable[[Request], Command]] = {
    "play": lambda r: Play(),
    "pause": lambda r: Pause(),
    "toggle": lambda r: Toggle(),
    "reset": lambda r: Reset(),
    "step": lambda r: Steps(r.value),
    "advance": lambda r: Advance(r.value, r.name),
    "speed": lambda r: Speed(r.value),
    "seek": lambda r: Seek(r.value),
    "set_value": lambda r: SetValue(r.name, r.value),
    "integrator": lambda r: Integrator(r.value),
    "timestep": lambda r: Timestep(r.value),
    "motion": lambda r: Motion(r.value),
    "challenge": lambda r: Challenge(r.value),
    "record": lambda r: Record(),
    "stop_record": lambda r: StopRecord(),
    "button": lambda r: Button(r.value),
}
"""The typed request of each kind a :class:`Request` may name."""


def command(request: Request) -> Command:
    """``request`` as a typed request (:class:`Unknown` for a kind no control has)."""
    kind = request.kind
    make = COMMANDS.get(kind) if isinstance(kind, str) else None
    return make(request) if make is not None else Unknown(kind)
