"""How a readout is written for a reader: one definition for every view.

The page's tables, the projector overlay, the 3D labels, the follow mode's summary, the
class board, the lesson's goals, the X–Y cursor, the video and the static export all
write a readout's value through :func:`written`: its unit as the page shows it (a turning
speed in tr/min, an angle in degrees: :func:`~sandbox.physics.units.shown_scale`), a turn
counter modulo 360°, a flag in words, the scene's round-off written 0, and
:data:`DIGITS` significant digits with a decimal comma (:func:`sandbox.french.number`).
Two views of one readout at one instant therefore write the same characters. The time of
a frame is written by :func:`time_words`.

Files (CSV, JSON, recordings) keep the contract's units and Python's numbers: nothing
here is for them. A pure module: no UI import.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from datetime import datetime

from sandbox.french import number
from sandbox.physics.units import FLAGS, TURN_ANGLES, flag_words, shown_scale

DIGITS = 4
"""Significant digits of every readout a view writes (the tables' precision)."""

UNIT_SPACE = "\u00a0"
"""The no-break space between a number and its unit."""


def with_unit(shown: str, unit: str) -> str:
    """A written number and its unit as French typography has them: "54,4 N" with a
    no-break space (a narrow line never puts the unit alone on the next one), "29°" (an
    angle's degree sign follows the number), the number alone without a unit."""
    if not unit:
        return shown
    return f"{shown}{unit}" if unit == "°" else f"{shown}{UNIT_SPACE}{unit}"


@dataclass(frozen=True)
class Written:
    """A readout's value as a view writes it.

    Attributes:
        number: The written number ("1,004", "244,5", "−3,2×10⁻⁵"), « oui » / « non » for
            a flag, "—" when there is no finite value.
        unit: The unit the page shows ("tr/min", "°"; "" for a flag or a ratio).
        value: The value in that unit (a turn counter folded into [0, 360)), NaN when
            not finite: what a chart or a cursor places.
    """

    number: str
    unit: str
    value: float

    def __str__(self) -> str:
        return with_unit(self.number, self.unit)


def written(
    name: str,
    value: float,
    unit: str,
    *,
    zero: float = 0.0,
    floor: float = 0.0,
    digits: int = DIGITS,
) -> Written:
    """Readout ``name``'s ``value`` (in its contract ``unit``) as every view writes it.

    Args:
        name: The readout's contract name (it decides a turning speed, a turn counter, a
            flag).
        value: Its value in the contract unit.
        unit: The contract unit ("rad", "rad/s", "N"...).
        zero: The scene's round-off for that unit, in the contract unit (a value this
            small is written 0).
        floor: A floor already in the page's unit (the precision of the largest
            component of a vector, :func:`sandbox.web.panels.tables.written_floor`).
        digits: Significant digits (:data:`DIGITS`; a caption of the accuracy panel may
            ask for fewer).
    """
    shown_unit, factor = shown_scale(name, unit)
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v):
        return Written("—", "" if name in FLAGS else shown_unit, math.nan)
    if name in FLAGS:
        return Written(flag_words(v), "", 1.0 if v > 0.5 else 0.0)
    shown = v * factor
    bound = max(abs(zero) * factor, floor)
    if name in TURN_ANGLES and unit == "rad":
        shown %= 360.0
        # read at a turn's precision: with 4 digits, 0,05° (a θ that is 10⁻⁶° past a
        # whole number of turns is 0°, not 1,88×10⁻⁶°)
        bound = max(bound, 0.5 * 10.0 ** (3 - digits))
        text = number(shown, digits, zero=bound)
        if text == number(360.0, digits):  # 359,99996° rounds to 360: it is 0
            shown, text = 0.0, "0"
        return Written(text, shown_unit, shown)
    return Written(number(shown, digits, zero=bound), shown_unit, shown)


def date_words(stamp: object) -> str:
    """An ISO date as the page writes it: « 29/11/2026 à 11 h 20 (UTC) » (its own zone,
    named when the stamp has one); anything else as it is (a crafted file's text)."""
    try:
        when = datetime.fromisoformat(str(stamp))
    except ValueError:
        return str(stamp)
    zone = f" ({when.tzname()})" if when.tzinfo is not None and when.tzname() else ""
    return f"{when:%d/%m/%Y} à {when.hour} h {when:%M}{zone}"


def time_words(t: float) -> str:
    """A simulated time [s] as every view writes it: two decimals, a decimal comma
    ("13,46", "0,00", "1 234,50"), "—" when not finite."""
    if not math.isfinite(t):
        return "—"
    text = f"{abs(t):,.2f}".replace(",", "\u202f").replace(".", ",")
    return ("\u2212" if t < 0 and text.strip("0,\u202f") else "") + text


def time_line(t: float) -> str:
    """The simulated time's line over a picture (the video's overlay, the 3D export's,
    the followers' summary): « t = 81,20 s »."""
    return f"t = {with_unit(time_words(t), 's')}"


FLAT = 0.02
"""A curve flatter than this share of its size is drawn with this much room around it:
its axis ticks then differ where a number is read (a bearing force steady to 1e-6 N had
four ticks all reading « 54,4175 », a nutation rate steady to 3×10⁻⁷ °/s every tick
« 30 »)."""


def flat_limits(values: Iterable[float]) -> tuple[float, float] | None:
    """The vertical limits of a nearly flat curve (its middle ± :data:`FLAT` of its
    size; ±1 of its unit at 0), None when its own span is wide enough or it has no
    finite value: one rule for every chart (the page's X–Y plot, the video's strip)."""
    finite = [v for v in (float(x) for x in values) if math.isfinite(v)]
    if not finite:
        return None
    lo, hi = min(finite), max(finite)
    room = FLAT * max(abs(lo), abs(hi))
    if hi - lo >= 2 * room and hi > lo:
        return None
    room = room or 1.0
    middle = (lo + hi) / 2
    return middle - room, middle + room
