"""Refusals: the checks of a value or command from the browser, and their French words.

A value the page sends is checked here (:func:`check_value`, :func:`check_speed`,
:func:`check_timestep`, ...) and refused with a French :class:`Refused`; a refusal of a
lower layer, whose message is English, is said in French by :func:`french_message`.
"""

from __future__ import annotations

import logging
import math

from sandbox.errors import (
    BadModel,
    BadOption,
    BadParameter,
    Diverged,
    SandboxError,
    UnknownParameter,
)
from sandbox.physics.display import rotation_speed
from sandbox.physics.limits import MAX_TIMESTEP, MIN_TIMESTEP
from sandbox.physics.model import INTEGRATORS
from sandbox.physics.simulation import Simulation
from sandbox.physics.units import display_unit
from sandbox.scenes.base import Param, as_scene
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


def advance_seconds(sim: Simulation, value: object, unit: object) -> float:
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


def shown_value(value: object, limit: int = 40) -> str:
    """A short, one-line picture of a value from a browser (it may be 1 MB long)."""
    text = value if isinstance(value, str) else repr(value)
    text = "".join(c if c.isprintable() else " " for c in text[: limit + 1])
    return text if len(text) <= limit else text[: limit - 1] + "…"


def shown_number(value: object) -> str:
    """A value from a browser as the page writes it: a finite number with a decimal
    comma (``0,005``), anything else as :func:`shown_value` (``nan``, ``abc``)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
        return text.number(float(value), 6)
    return shown_value(value)


def french_number(x: float) -> str:
    """``x`` with 3 significant digits and a decimal comma (``0,001``, ``1×10⁻⁶``)."""
    return text.number(x, 3)


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


def max_timestep(sim: Simulation) -> float:
    """Largest timestep [s] the simulation accepts (the scene's own bound, if any)."""
    scene = as_scene(sim.scene)
    return min(MAX_TIMESTEP, scene.max_timestep) if scene is not None else MAX_TIMESTEP


def timestep_range(sim: Simulation, value: object) -> str:
    shown = french_number(value) if isinstance(value, float) else shown_value(value)
    return (
        f"Pas de temps dt = {shown} s refusé : choisissez un pas entre "
        f"{french_number(MIN_TIMESTEP)} s et {french_number(max_timestep(sim))} s."
    )


def check_timestep(sim: Simulation, value: object) -> float:
    """A timestep [s] typed in the browser, between :data:`MIN_TIMESTEP` and the scene's
    maximum (Refused, giving the range, otherwise)."""
    try:
        dt = as_number(value, "Pas de temps")
    except Refused:
        raise Refused(timestep_range(sim, value)) from None
    if not MIN_TIMESTEP <= dt <= max_timestep(sim):
        raise Refused(timestep_range(sim, dt))
    return dt


def check_speed(value: object) -> float:
    """A speed factor within :data:`SPEEDS` (Refused otherwise)."""
    low, high = SPEEDS
    refusal = (
        f"Vitesse ×{shown_number(value)} refusée : choisissez entre ×{french_number(low)} "
        f"et ×{french_number(high)}."
    )
    try:
        speed = as_number(value, "Vitesse")
    except Refused:
        raise Refused(refusal) from None
    if not low <= speed <= high:
        raise Refused(refusal)
    return speed


def check_integrator(value: object) -> str:
    """An integrator name (Refused listing the valid ones otherwise)."""
    if not isinstance(value, str) or value not in INTEGRATORS:
        raise Refused(
            f"Intégrateur « {shown_value(value)} » inconnu : choisissez parmi "
            f"{', '.join(INTEGRATORS)}."
        )
    return value


def check_value(sim: Simulation, name: object, value: object) -> float:
    """A parameter value within its range (French refusals: unknown name, not a number,
    out of range)."""
    scene = as_scene(sim.scene)
    known = {p.name: p for p in scene.params} if scene is not None else {}
    if not isinstance(name, str) or name not in known:
        where = (
            f"parmi : {' ; '.join(param_words(p) for p in known.values())}"
            if known
            else "un fichier MJCF n'en a aucun"
        )
        raise Refused(f"Paramètre « {shown_value(name)} » inconnu ({where}).")
    p = known[name]
    unit = french_unit(p.unit)
    unit = unit if unit in ("", "°") else f" {unit}"
    is_number = isinstance(value, (int, float)) and not isinstance(value, bool)
    numeric = is_number and math.isfinite(value)  # type: ignore[arg-type]
    shown = shown_number(value)
    given = f"{shown}{unit}" if numeric else f"« {shown} »"
    refusal = (
        f"{param_words(p)} : {given} refusé, choisissez entre {text.number(p.min, 6)} et "
        f"{text.number(p.max, 6)}{unit}."
    )
    try:
        number = as_number(value, param_words(p))
    except Refused:
        raise Refused(refusal) from None
    if not p.min <= number <= p.max:
        raise Refused(refusal)
    return number


def french_unit(unit: str) -> str:
    """``unit`` as the page writes it (``rpm`` -> ``tr/min``, ``deg`` -> ``°``)."""
    return display_unit(unit)


def param_words(p: Param) -> str:
    """A parameter as the page names it: its French label, else its name."""
    return p.label or p.name


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


FRENCH_REFUSALS: tuple[tuple[type[SandboxError], str], ...] = (
    (UnknownParameter, "Ce paramètre n'existe pas pour cette scène : rien n'a changé."),
    (BadParameter, "Cette valeur de paramètre est hors de son domaine : rien n'a changé."),
    (
        BadOption,
        "Réglage refusé (pas de temps dt ou intégrateur hors de ce que la scène accepte) : "
        "rien n'a changé.",
    ),
    (BadModel, "Le modèle ne se construit pas avec cette valeur : rien n'a changé."),
    (Diverged, "Le calcul diverge avec ce réglage : rien n'a changé."),
)
"""French words for the refusals of the lower layers, whose messages are English (they
speak to the command line); the English detail goes to the server's log only."""


def french_message(exc: SandboxError) -> str:
    """The message of a refusal for a French page: a :class:`Refused` is French already;
    an English one from a lower layer is said in French by its kind (its detail is
    logged)."""
    if isinstance(exc, Refused):
        return str(exc)
    log.info("refused: %s", shown_value(str(exc), 300))
    for kind, words in FRENCH_REFUSALS:
        if isinstance(exc, kind):
            return words
    return "Modification refusée : rien n'a changé."
