"""Commands: what a GUI callback asks of the simulation loop, queued by any thread and
applied by the loop thread, repeated settings merged first.

Each is one small frozen dataclass of :data:`Command`, built by the control that sends
it; its values come from a browser (unvalidated, perhaps crafted) and are checked where
they are applied. The live controller and the replay player dispatch them with ``match``.
"""

from __future__ import annotations

import queue
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TypeAlias


def pending(commands: queue.Queue[Command]) -> Iterator[Command]:
    """The commands waiting in ``commands``, removed as they are yielded."""
    while True:
        try:
            yield commands.get_nowait()
        except queue.Empty:
            return


def merged(commands: list[Command]) -> list[Command]:
    """``commands`` with repeated settings merged: of several values of one slider, of
    the speed, the timestep, the integrator, the motion or a replay's position, only the
    last is kept (at its place)."""

    def key(cmd: Command) -> tuple[type, str]:
        return (type(cmd), cmd.name if isinstance(cmd, SetValue) else "")

    last = {key(c): i for i, c in enumerate(commands) if isinstance(c, SETTINGS)}
    return [c for i, c in enumerate(commands) if not isinstance(c, SETTINGS) or last[key(c)] == i]


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
)
"""A typed request: what the controller does, one small class per kind."""

SETTINGS = (Speed, Seek, SetValue, Integrator, Timestep, Motion)
"""Commands that set a value: of several queued, the last one is applied."""

WORDS: Mapping[type, str] = {
    Play: "Lecture",
    Pause: "Pause",
    Toggle: "Lecture/Pause",
    Reset: "Réinitialiser",
    Steps: "Pas",
    Advance: "Pas",
    Speed: "Vitesse",
    Seek: "Position dans l'enregistrement",
    SetValue: "Réglage d'un paramètre",
    Integrator: "Intégrateur",
    Timestep: "Pas de temps",
    Motion: "Mouvement",
    Challenge: "Défi",
    Record: "Enregistrer",
    StopRecord: "Arrêter l'enregistrement",
    Button: "Bouton",
}
"""The page's words for each command (messages name the control, never a code name)."""


def words(cmd: Command) -> str:
    """The control ``cmd`` comes from, in the page's words."""
    return WORDS.get(type(cmd), "Commande")
