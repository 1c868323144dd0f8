"""Untrusted text made safe, and numbers written the French way."""

from __future__ import annotations

import math

import pytest

from sandbox.web.client.text import html_text, number, plain


def test_plain_shows_html_and_markdown_as_text():
    shown = plain("<img src=x onerror=alert(1)> **b** [a](javascript:x)")
    assert "<" not in shown and "&lt;img" in shown
    assert r"\*\*b\*\*" in shown and r"\[a\]\(javascript:x\)" in shown


def test_html_text_cuts_long_values_and_blanks_control_characters():
    assert html_text("a\x00b\nc") == "a b c"
    assert html_text("x" * 500, limit=10) == "x" * 9 + "…"


@pytest.mark.parametrize(
    "value, digits, zero, expected",
    [
        (54.4213, 4, 0.0, "54,42"),
        (1500.0, 4, 0.0, "1\u202f500"),
        (0.0004216, 4, 0.0, "0,0004216"),
        (1.5e-7, 4, 0.0, "1,5×10⁻⁷"),
        (2e9, 4, 0.0, "2×10⁹"),
        (-3.14159, 4, 0.0, "−3,142"),  # the minus sign, not a hyphen
        (-1.2e-7, 4, 0.0, "−1,2×10⁻⁷"),
        (1.959e-19, 4, 1e-12, "0"),
        (1.959e-19, 4, 0.0, "1,959×10⁻¹⁹"),
        (math.nan, 4, 0.0, "—"),
        (0.1, 3, 0.0, "0,1"),
    ],
)
def test_numbers_have_a_decimal_comma_and_no_round_off_noise(value, digits, zero, expected):
    assert number(value, digits, zero=zero) == expected


def test_a_number_and_its_unit_as_french_typography_writes_them():
    from sandbox.web.client.text import with_unit

    assert with_unit("54,4", "N") == "54,4\u00a0N"  # no line break before the unit
    assert with_unit("29", "°") == "29°"  # the degree sign of an angle follows the number
    assert with_unit("0,25", "") == "0,25"


def test_the_gap_before_a_cell_never_breaks_a_line():
    """A narrow column wrapped « −0,001115 » below an empty line after the en space that
    was the gap: the gap is a space of Unicode's no-break class (GL: U+00A0, U+2007,
    U+202F), and still a space (numbers never run together)."""
    from sandbox.web.client.text import GAP, table_row

    assert GAP in ("\u00a0", "\u2007", "\u202f")
    assert table_row("Effet de pilon", "−0,001115") == f"| Effet de pilon | {GAP}−0,001115 |"
