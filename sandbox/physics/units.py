"""Units as a French reader of the web page writes them.

The ``unit`` strings of parameters and readouts are contracts (``sandbox describe --json``,
CSV headers, recordings): they stay as they are. The web page shows
:func:`display_unit` instead: "tr/min" for "rpm", "°" for "deg", the rest (SI symbols
with a middle dot and superscripts, as the course writes them) unchanged.
"""

from __future__ import annotations

import math

FRENCH_UNITS: dict[str, str] = {"rpm": "tr/min", "deg": "°"}
"""Contract units that a French reader writes differently."""

DISPLAY_UNITS: frozenset[str] = frozenset(
    {
        "",  # dimensionless: a ratio (μ), a flag, a choice
        "g", "kg", "m", "s", "°", "rad", "tr/min", "rad/s", "m/s", "m/s²",
        "N", "N·m", "W", "J", "kg·m", "kg·m²", "kg·m/s", "kg·m²/s", "N·m·s/rad",
        "N/m", "N·s/m", "Hz", "Pa", "bar", "kg/m³", "MW", "mm",
    }
)  # fmt: skip
"""Every unit the web page may show (a test keeps the scenes and readouts inside it)."""


def display_unit(unit: str) -> str:
    """The unit the web page shows for the contract unit ``unit`` ("rpm" -> "tr/min")."""
    return FRENCH_UNITS.get(unit, unit)


TURN_SPEEDS: frozenset[str] = frozenset({"omega", "omega_m", "omega_g", "spin"})
"""Readouts of a solid's rotation speed [rad/s] whose scene sets that speed in tr/min
(the slider "Vitesse … [tr/min]"): the page shows them in tr/min too, one unit for one
quantity across the tables, the overlay, the lesson and the charts."""

MEGAWATTS: frozenset[str] = frozenset(
    {
        "P_wind", "P_rotor", "P_rotor_loss", "P_rotor_store", "P_gearbox_in",
        "P_gearbox_loss", "P_generator_store", "P_generator_in", "P_generator_loss",
        "P_electric", "P_transformer_loss", "P_transformer_out", "P_line_loss", "P_grid",
    }
)  # fmt: skip
"""A power chain's readouts [W] that the page shows in MW (a wind turbine's: the course
writes 5 MW, 3,75 MW), one unit for one quantity across every view."""

RAD_S_TO_RPM = 30.0 / math.pi
RAD_TO_DEG = 180.0 / math.pi
PA_TO_BAR = 1e-5


def shown_scale(name: str, unit: str) -> tuple[str, float]:
    """The unit the web page shows readout ``name`` in, and the factor from its contract
    ``unit`` to it: a turning speed in tr/min (:data:`TURN_SPEEDS`), an angle in degrees
    (the sliders' unit), a contact pressure in bar (the course's limit is 200 bar), a
    power chain's powers in MW (:data:`MEGAWATTS`), any
    other unit as :func:`display_unit` with factor 1. Files (CSV, JSON, recordings) keep
    the contract unit."""
    if unit == "rad/s" and name in TURN_SPEEDS:
        return "tr/min", RAD_S_TO_RPM
    if unit == "rad":
        return "°", RAD_TO_DEG
    if unit == "Pa":
        return "bar", PA_TO_BAR
    if unit == "W" and name in MEGAWATTS:
        return "MW", 1e-6
    return display_unit(unit), 1.0


TURN_ANGLES: frozenset[str] = frozenset({"theta"})
"""Readouts that count turns [rad], unwrapped in files: the page shows them modulo 360°."""

FLAGS: frozenset[str] = frozenset({"contact", "on_plane", "gimbal_lock"})
"""Readouts that are 0 or 1 (1 in files): the page says « oui » or « non »."""


def flag_words(value: float) -> str:
    """A flag readout as the page writes it: « oui » above one half, else « non »."""
    return "oui" if value > 0.5 else "non"
