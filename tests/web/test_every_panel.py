"""Every number the page writes, in every panel of every scene, read as a student would.

The real page (every panel of :class:`~sandbox.web.views.browser.WebView`) on a fake browser; each
folder of "Panneau affiché" is shown in turn while the simulation runs, and every text
the page writes (tables, overlay, lesson, status) is read for: a number at or beyond
10¹⁵ or at most 10⁻¹⁵ in size that is not an exact 0 (a round-off or an overflow shown as
a number), English words (labels built from a doc), and numbers that run together in a
table (two cells without a space between them).
"""

from __future__ import annotations

import html
import math
import re
from pathlib import Path

import pytest

from sandbox.scenes import SCENES
from sandbox.web.client.text import GAP
from sandbox.web.views.browser import ALL_FOLDERS
from tests.robustness.test_hostile_web import Page

NUMBER = re.compile(r"(?<![\w.,])[−-]?\d[\d\u202f]*(?:,\d+)?(?:×10(?P<exp>[⁻]?[⁰¹²³⁴⁵⁶⁷⁸⁹]+))?")
SUPER = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
ENGLISH = re.compile(
    r"\b(the|and|of|with|kinetic|energy|theorem|integrated|drift|error|speed|torque|"
    r"bearing|force)\b|[a-z]+_[a-zA-Z]",
)
"""English words the labels built from docs left ("Dérive de kinetic-energy theorem,
integrated"), and contract names with an underscore ("bearing_A")."""
FRENCH_TOO = {"force"}  # also French: only English in a sentence around it counts


def visible(text: str) -> str:
    """What the browser shows of a markdown or HTML text: no tags, entities decoded."""
    text = re.sub(r"<(script|style)[^>]*>.*?</\1>", " ", text, flags=re.S)
    return html.unescape(re.sub(r"<[^>]+>", "", text))


def magnitude(token: str, exp: str | None) -> float:
    mantissa = token.split("×")[0].replace("\u202f", "").replace("−", "-").replace(",", ".")
    value = float(mantissa)
    if exp:
        value *= 10.0 ** int(exp.translate(SUPER))
    return value


def problems(text: str) -> list[str]:
    """What a student should not read in ``text``."""
    out = []
    shown = visible(text)
    for m in NUMBER.finditer(shown):
        try:
            value = magnitude(m.group(0), m.group("exp"))
        except ValueError:
            continue
        if value != 0 and (abs(value) >= 1e15 or abs(value) <= 1e-15):
            out.append(f"number {m.group(0)!r}")
    for m in ENGLISH.finditer(shown):
        if m.group(0).lower() not in FRENCH_TOO:
            out.append(
                f"English {m.group(0)!r} in …{shown[max(0, m.start() - 30) : m.end() + 30]}…"
            )
    for line in text.splitlines():
        if not line.startswith("|") or set(line) <= set("|:- "):
            continue
        cells = [visible(c) for c in line.strip().strip("|").split("|")]
        for left, right in zip(cells, cells[1:], strict=False):
            a, b = left.strip(" "), right.strip(" ")
            if a and b and (a[-1].isdigit() or a[-1] == "%") and (b[0].isdigit() or b[0] in "+−-"):
                out.append(f"cells run together: {a!r} | {b!r}")
    return out


@pytest.mark.slow  # every folder of every scene: ~20 s
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_every_panel_reads_right(scene: str, tmp_path: Path) -> None:
    page = Page(scene, tmp_path)
    try:
        page.send(page.find("button_group", "Temps"), "Lecture")
        page.tick(0.5)
        found: dict[str, list[str]] = {}
        for folder in [*page.view.groups, ALL_FOLDERS]:
            page.show(folder)
            page.tick(0.6)
            for handle in page.client.gui.handles:
                if handle.kind not in ("markdown", "html"):
                    continue
                for problem in problems(str(handle.content)):
                    found.setdefault(problem, []).append(folder)
        assert not found, "\n".join(f"{p} (in {sorted(set(f))})" for p, f in found.items())
    finally:
        page.session.stop()


def test_the_reader_finds_what_it_must():
    """The checks themselves: each catches its case, and passes clean text."""
    assert problems("| ω | 1 500 |") == []
    assert problems("M = 2,311×10⁻⁸ N·m") == []
    assert problems("Écart de fermeture 4,385×10⁻¹⁶ m") == ["number '4,385×10⁻¹⁶'"]
    assert problems("Erreur relative 2,4") == []  # "relative" is French too
    assert problems("3,2×10²⁸⁶") == ["number '3,2×10²⁸⁶'"]
    assert any("English" in p for p in problems("Dérive de kinetic-energy theorem (relatif)"))
    assert any("English" in p for p in problems("bearing_A [N]"))
    assert problems('<span data-readout="bearing_A">54,4</span>') == []  # attributes: unseen
    assert problems("| x | 0,1213 | 0,1213 | +0,00 % |") == [
        "cells run together: '0,1213' | '0,1213'",
        "cells run together: '0,1213' | '+0,00 %'",
    ]
    assert problems(f"| x |{GAP}0,1213 |{GAP}0,1213 |{GAP}+0,00 % |") == []
    assert not math.isnan(magnitude("1\u202f500", None))
