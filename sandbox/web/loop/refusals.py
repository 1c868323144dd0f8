"""Refusals: the checks of a command from the browser, and the French words of every
refusal a request meets.

A parameter value, a timestep or an integrator is checked once, by the simulation
(``Simulation.check_value``, ``check_timestep``, ``check_integrator``), whose refusal
carries English for the command line and French for the page (``SandboxError.french``);
here are the checks only the page has (speed, "Pas", a number typed as text), refused
with a French :class:`Refused`, and :func:`french_message`, what the page says of any.
"""

from __future__ import annotations

import logging
import math

from sandbox.errors import Diverged, SandboxError
from sandbox.french import shown_number, shown_value
from sandbox.physics.display import rotation_speed
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.web.client import text

log = logging.getLogger(__name__)

SPEEDS = (0.01, 4.0)
"""Allowed speed factors (slowest, fastest): ×0.01 ("Ralenti") makes a 6000 rpm rotor
turn 6° between two frames at 60 frames per second."""

MAX_STEP_REQUEST = 1000
"""Most timesteps one "Pas" request may ask for."""

MAX_ADVANCE = 10.0
"""Longest "Pas" in time [s] (or its angle converted at the current speed)."""


class Refused(SandboxError):
    """A value or command from the browser that the session refuses (French message)."""

    def __init__(self, message: str) -> None:
        super().__init__(message, french=message)


DIVERGENCE_CAUSES = {
    "BADQACC": "accélérations démesurées",
    "BADQVEL": "vitesses démesurées",
    "BADQPOS": "positions démesurées",
    "NaN or Inf": "valeurs non numériques dans l'état",
}
"""French words for the causes a :class:`~sandbox.errors.Diverged` names."""


def divergence_message(exc: Diverged) -> str:
    """What the page says when the simulation blows up (French, decimal comma)."""
    detail = str(exc)
    cause = next((v for k, v in DIVERGENCE_CAUSES.items() if k in detail), "état non physique")
    return (
        f"La simulation a divergé à t = {text.number(exc.time, 4)} s ({cause}). "
        "Réduisez le pas de temps dt ou choisissez l'intégrateur Runge-Kutta 4 ou "
        "Implicite rapide, puis cliquez sur « Réinitialiser »."
    )


def advance_seconds(sim: ReadOnlySimulation, value: object, unit: object) -> float:
    """Seconds of motion of a "Pas" of ``value`` in ``unit`` (``s``, or ``deg`` of the
    mechanism's main rotating joint at its current speed).

    Raises:
        Refused: not a positive number within :data:`MAX_ADVANCE`, an unknown unit, or
            an angle while no joint turns.
    """
    if unit not in ("s", "deg"):
        raise Refused(f"Unité de pas « {shown_value(unit)} » inconnue : s ou °.")
    what = "Pas en temps" if unit == "s" else "Pas en angle"
    number = as_number(value, what)
    if unit == "s":
        if not 0 < number <= MAX_ADVANCE:
            raise Refused(
                f"Pas de {text.number(number, 3)} s refusé : choisissez entre 0 et "
                f"{text.number(MAX_ADVANCE)} s."
            )
        return number
    if not 0 < number <= 3600:
        raise Refused(f"Pas de {text.number(number, 3)}° refusé : choisissez entre 0 et 3600°.")
    w = rotation_speed(sim.model, sim.data)
    if w < 1e-6:
        raise Refused("Aucune pièce ne tourne : choisissez un pas en temps (s).")
    seconds = math.radians(number) / w
    if seconds > MAX_ADVANCE:
        raise Refused(
            f"Pas de {text.number(number, 3)}° refusé : à cette vitesse il durerait "
            f"{text.number(seconds, 3)} s (au plus {text.number(MAX_ADVANCE)} s)."
        )
    return seconds


def as_number(value: object, what: str) -> float:
    """``value`` as a finite float (numbers and numeric strings; not bool or None).

    Raises:
        Refused: naming ``what``.
    """
    if isinstance(value, bool) or value is None:
        raise Refused(f"{what} : un nombre est attendu, reçu « {shown_value(value)} ».")
    if isinstance(value, str) and len(value) > 64:
        raise Refused(f"{what} : un nombre est attendu, reçu « {shown_value(value)} ».")
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise Refused(f"{what} : un nombre est attendu, reçu « {shown_value(value)} ».") from None
    if not math.isfinite(number):
        raise Refused(f"{what} : un nombre fini est attendu, reçu « {shown_value(value)} ».")
    return number


def check_timestep(sim: ReadOnlySimulation, value: object) -> float:
    """A timestep [s] typed in the browser (a number, or a numeric text of a link), checked
    by the simulation: BadOption giving the range (``french``) otherwise."""
    try:
        dt = as_number(value, "Pas de temps")
    except Refused:
        sim.check_timestep(value)  # refuses it in both languages
        raise
    return sim.check_timestep(dt)


def check_speed(value: object) -> float:
    """A speed factor within :data:`SPEEDS` (Refused otherwise)."""
    low, high = SPEEDS
    refusal = (
        f"Vitesse ×{shown_number(value)} refusée : choisissez entre ×{text.number(low, 3)} "
        f"et ×{text.number(high, 3)}."
    )
    try:
        speed = as_number(value, "Vitesse")
    except Refused:
        raise Refused(refusal) from None
    if not low <= speed <= high:
        raise Refused(refusal)
    return speed


def step_count(value: object) -> int:
    """Timesteps asked by a "Pas" request: 1 by default, at most :data:`MAX_STEP_REQUEST`."""
    if value is None:
        return 1
    refusal = f"Nombre de pas « {shown_value(value)} » refusé : entre 1 et {MAX_STEP_REQUEST}."
    try:
        number = as_number(value, "Pas")
    except Refused:
        raise Refused(refusal) from None
    if number != int(number) or not 1 <= number <= MAX_STEP_REQUEST:
        raise Refused(refusal)
    return int(number)


def french_message(exc: SandboxError) -> str:
    """The message of a refusal for a French page: its own French words, written where
    the check was made (``exc.french``); a divergence as :func:`divergence_message`; else
    a general refusal, the English detail logged for the teacher."""
    if exc.french is not None:
        return exc.french
    if isinstance(exc, Diverged):
        return divergence_message(exc)
    log.info("refused: %s", shown_value(str(exc), 300))
    return "Modification refusée : rien n'a changé."
