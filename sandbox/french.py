"""French writing shared by the page and the refusals of every layer: numbers as the
course writes them (decimal comma, ``×10⁻⁵``, the minus sign "−") and a short picture
of a value someone typed or sent.

The lower layers raise their refusals with French words beside the English ones
(``SandboxError.french``); this module lets them write numbers the page's way without
importing the web layer.
"""

from __future__ import annotations

_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


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


def shown_value(value: object, limit: int = 40) -> str:
    """A short, one-line picture of a value from a user or a browser (it may be 1 MB
    long): printable characters only, cut with "…" past ``limit``."""
    text = value if isinstance(value, str) else repr(value)
    text = "".join(c if c.isprintable() else " " for c in text[: limit + 1])
    return text if len(text) <= limit else text[: limit - 1] + "…"


def shown_number(value: object) -> str:
    """A value as the page writes it: a finite number with a decimal comma (``0,005``),
    anything else as :func:`shown_value` (``nan``, ``abc``)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value == value:
        if value not in (float("inf"), float("-inf")):
            return number(float(value), 6)
    return shown_value(value)
