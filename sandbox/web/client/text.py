"""Text from files and browsers, made safe to show in viser's markdown and HTML.

viser renders markdown with raw HTML enabled: a recording header, an MJCF body name or a
lesson title shown as is could run script in the browser. Every such value goes through
:func:`plain` (inside markdown) or :func:`html_text` (inside HTML) before it is shown.
"""

from __future__ import annotations

import html
import re

MAX_SHOWN = 200
"""Longest untrusted value shown [characters]; the rest is cut with an ellipsis."""

_MARKDOWN = re.compile(r"([\\`*_{}\[\]()#+\-.!|~])")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _clip(value: object, limit: int) -> str:
    text = _CONTROL.sub(" ", str(value))
    return text if len(text) <= limit else text[: limit - 1] + "…"


def html_text(value: object, limit: int = MAX_SHOWN) -> str:
    """``value`` as HTML text: tags and entities escaped, control characters blanked."""
    return html.escape(_clip(value, limit), quote=True)


def plain(value: object, limit: int = MAX_SHOWN) -> str:
    """``value`` as literal text inside markdown: HTML escaped, markdown syntax backslashed,
    on one line, at most ``limit`` characters."""
    return html.escape(_MARKDOWN.sub(r"\\\1", _clip(value, limit)), quote=True)


def number(value: float, digits: int = 4, *, zero: float = 0.0) -> str:
    """``value`` as a French reader writes it: ``digits`` significant digits, a decimal
    comma, a narrow no-break space between thousands, ``×10⁻⁵`` instead of ``e-05``, the
    minus sign "−" (not a hyphen), "—" when not finite, and "0" when ``|value| <= zero``
    (below the scene's round-off, e.g. 1.959e-19 N). CSV and JSON files keep Python's dot
    and hyphen."""
    if value != value or value in (float("inf"), float("-inf")):
        return "—"
    if abs(value) <= zero or value == 0:
        return "0"
    if value < 0:
        return "\u2212" + number(-value, digits)
    exponent = int(f"{abs(value):.{max(digits - 1, 0)}e}".split("e")[1])
    if -4 <= exponent < digits + 2:
        decimals = max(digits - 1 - exponent, 0)
        text = f"{value:,.{decimals}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        return text.replace(",", "\u202f").replace(".", ",")
    mantissa, power = f"{value:.{max(digits - 1, 0)}e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".") if "." in mantissa else mantissa
    superscript = str(int(power)).translate(_SUPERSCRIPT)
    return f"{mantissa.replace('.', ',')}×10{superscript}"


GAP = "\u2007"
"""A figure space (a digit's width, no line break after it) written before every cell of
a table but the first: a table copied, read aloud or shown without cell padding never
runs two numbers together ("0,12130,1213"), and a narrow column never wraps a number
below an empty line (an en space, breakable, did: « −0,001115 » took two lines)."""


def table_row(*cells: str) -> str:
    """One markdown table row of ``cells`` (already escaped), a :data:`GAP` before each
    cell after the first."""
    return "| " + " | ".join([cells[0], *(GAP + c for c in cells[1:])]) + " |"


UNIT_SPACE = "\u00a0"
"""The no-break space between a number and its unit."""


def with_unit(shown: str, unit: str) -> str:
    """A written number and its unit as French typography has them: "54,4 N" with a
    no-break space (a narrow line never puts the unit alone on the next one), "29°" (an
    angle's degree sign follows the number), the number alone without a unit."""
    if not unit:
        return shown
    return f"{shown}{unit}" if unit == "°" else f"{shown}{UNIT_SPACE}{unit}"
