"""Text from files and browsers, made safe to show in viser's markdown and HTML.

viser renders markdown with raw HTML enabled: a recording header, an MJCF body name or a
lesson title shown as is could run script in the browser. Every such value goes through
:func:`plain` (inside markdown) or :func:`html_text` (inside HTML) before it is shown.
"""

from __future__ import annotations

import html
import re

from sandbox.french import number
from sandbox.written import UNIT_SPACE as UNIT_SPACE  # the readouts' typography, one place
from sandbox.written import with_unit as with_unit

__all__ = [
    "GAP",
    "MAX_SHOWN",
    "UNIT_SPACE",
    "html_text",
    "number",
    "plain",
    "table_row",
    "with_unit",
]

MAX_SHOWN = 200
"""Longest untrusted value shown [characters]; the rest is cut with an ellipsis."""

_MARKDOWN = re.compile(r"([\\`*_{}\[\]()#+\-.!|~])")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


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


GAP = "\u2007"
"""A figure space (a digit's width, no line break after it) written before every cell of
a table but the first: a table copied, read aloud or shown without cell padding never
runs two numbers together ("0,12130,1213"), and a narrow column never wraps a number
below an empty line (an en space, breakable, did: « −0,001115 » took two lines)."""


def table_row(*cells: str) -> str:
    """One markdown table row of ``cells`` (already escaped), a :data:`GAP` before each
    cell after the first."""
    return "| " + " | ".join([cells[0], *(GAP + c for c in cells[1:])]) + " |"
