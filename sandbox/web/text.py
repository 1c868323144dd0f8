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
