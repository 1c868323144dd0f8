"""Units as a French reader of the web page writes them.

The ``unit`` strings of parameters and readouts are contracts (``sandbox describe --json``,
CSV headers, recordings): they stay as they are. The web page shows
:func:`display_unit` instead: "tr/min" for "rpm", "°" for "deg", the rest (SI symbols
with a middle dot and superscripts, as the course writes them) unchanged.
"""

from __future__ import annotations

FRENCH_UNITS: dict[str, str] = {"rpm": "tr/min", "deg": "°"}
"""Contract units that a French reader writes differently."""

DISPLAY_UNITS: frozenset[str] = frozenset(
    {
        "",  # dimensionless: a ratio (μ), a flag, a choice
        "g", "kg", "m", "s", "°", "rad", "tr/min", "rad/s", "m/s", "m/s²",
        "N", "N·m", "W", "J", "kg·m", "kg·m²", "kg·m/s", "kg·m²/s", "N·m·s/rad",
        "N/m", "N·s/m", "Hz",
    }
)  # fmt: skip
"""Every unit the web page may show (a test keeps the scenes and readouts inside it)."""


def display_unit(unit: str) -> str:
    """The unit the web page shows for the contract unit ``unit`` ("rpm" -> "tr/min")."""
    return FRENCH_UNITS.get(unit, unit)
