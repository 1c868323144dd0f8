"""Lesson text: Markdown without raw HTML, formulas between ``$...$`` (a LaTeX subset
rendered as HTML).

``<`` is shown as text (also inside code spans, where it appears as ``&lt;``: write ``$<$``
or ``\\le`` instead), links and images only go to ``http(s)://`` addresses, reference
definitions are shown as text.
"""

from __future__ import annotations

import html
import re

_SYMBOLS = {
    "alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "Delta": "Δ", "theta": "θ",
    "lambda": "λ", "mu": "μ", "pi": "π", "rho": "ρ", "sigma": "σ", "tau": "τ", "phi": "φ",
    "psi": "ψ", "omega": "ω", "Omega": "Ω", "Gamma": "Γ", "wedge": "∧", "times": "×",
    "cdot": "·", "le": "≤", "ge": "≥", "approx": "≈", "neq": "≠", "infty": "∞", "in": "∈",
    "to": "→", "otimes": "⊗", "sum": "Σ", "quad": " ", "{": "{", "}": "}", "|": "‖",
    "partial": "∂", "pm": "±", "ll": "≪", "gg": "≫", "Sigma": "Σ", "Lambda": "Λ",
    "cos": "cos", "sin": "sin", "tan": "tan", "ln": "ln", "exp": "exp", "dot": "˙",
    "nabla": "∇", "cdots": "⋯", "ldots": "…", "Rightarrow": "⇒", "iff": "⇔",
}  # fmt: skip
_GROUP = r"\{([^{}]*)\}"


def formula_html(tex: str) -> str:
    """A LaTeX subset as HTML: Greek letters and operators, ``_{}``/``^{}``, ``\\frac``,
    ``\\sqrt``, ``\\vec``/``\\overrightarrow`` (arrow above), ``\\mathrm``, ``\\text``.

    The formula is text: ``<``, ``>`` and ``&`` are escaped first, so the only tags in the
    result are the ``<i>``, ``<sub>`` and ``<sup>`` made here.

    Raises:
        ValueError: an unknown command (named).
    """
    s = html.escape(tex, quote=False)
    for _ in range(4):  # nested groups, innermost first
        s = re.sub(r"\\frac" + _GROUP + _GROUP, r"(\1)/(\2)", s)
        s = re.sub(r"\\sqrt" + _GROUP, r"√(\1)", s)
        s = re.sub(r"\\(?:vec|overrightarrow)" + _GROUP, lambda m: m.group(1) + "\u20d7", s)
        s = re.sub(r"\\(?:mathrm|text|mathbf|operatorname)" + _GROUP, r"\1", s)
        s = re.sub(r"_" + _GROUP, r"<sub>\1</sub>", s)
        s = re.sub(r"\^" + _GROUP, r"<sup>\1</sup>", s)
    s = re.sub(r"_([A-Za-z0-9])", r"<sub>\1</sub>", s)
    s = re.sub(r"\^([A-Za-z0-9])", r"<sup>\1</sup>", s)

    def symbol(m: re.Match[str]) -> str:
        name = m.group(1)
        if name not in _SYMBOLS:
            raise ValueError(f"unknown formula command \\{name[:40]}")
        return _SYMBOLS[name]

    s = re.sub(r"\\([A-Za-z]+|[{}|])", symbol, s)
    s = s.replace("{", "").replace("}", "")
    return f"<i>{s}</i>"


_FORMULA = re.compile(r"\$([^$]+)\$")
_SLOT = "\ue000"  # stands for a rendered formula while the Markdown around it is cleaned
_SLOT_RE = re.compile(_SLOT + r"(\d+)" + _SLOT)
_DESTINATION = re.compile(r"\]\(")
_SAFE_URL = re.compile(r"[ \t]*\n?[ \t]*https?://", re.IGNORECASE)
_DEFINITION = re.compile(r"\[(?=[^\]\n]*\]:)")


def _unlink(text: str) -> str:
    """Break every Markdown link or image whose address is not ``http(s)://`` (it stays
    as text), and every reference definition (``[x]: url``)."""
    out = []
    pos = 0
    for m in _DESTINATION.finditer(text):
        if not _SAFE_URL.match(text, m.end()):
            out.append(text[pos : m.start()] + "]\\(")
            pos = m.end()
    out.append(text[pos:])
    return _DEFINITION.sub(r"\\[", "".join(out))


def render_text(text: str) -> str:
    """Lesson Markdown for viser's Markdown: every ``$...$`` formula rendered by
    :func:`formula_html`, raw HTML shown as text (``<`` escaped), links and images kept
    only towards ``http(s)://`` addresses.

    Raises:
        ValueError: an unknown formula command (named).
    """
    text = text.replace(_SLOT, "")
    formulas: list[str] = []

    def slot(m: re.Match[str]) -> str:
        formulas.append(formula_html(m.group(1)))
        return f"{_SLOT}{len(formulas) - 1}{_SLOT}"

    text = _FORMULA.sub(slot, text)
    text = _unlink(text.replace("<", "&lt;"))
    return _SLOT_RE.sub(lambda m: formulas[int(m.group(1))], text)
