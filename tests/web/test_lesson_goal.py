"""A lesson step's goal in words with a progress bar, read from its check."""

from __future__ import annotations

import ast
import math

import pytest

from sandbox.lessons import compile_check
from sandbox.web.panels.lesson_goal import Part, Words, describe, fraction, goal_html, lines, parts

WORDS = Words(
    {"bearing_A": "Palier A", "bearing_B": "Palier B", "slip_velocity": "Glissement"},
    {"bearing_A": "N", "bearing_B": "N", "slip_velocity": "m/s", "x": "m"},
)


def test_the_balancing_goal_reads_like_the_issue():
    check = compile_check(
        "bearing_A < 0.01 * initial(bearing_A) and bearing_B < 0.01 * initial(bearing_B)"
    )
    shown = lines(
        check, WORDS, {"bearing_A": 0.9, "bearing_B": 20.0}, {"bearing_A": 54.0, "bearing_B": 15.0}
    )
    assert [line.text for line in shown] == [
        "Palier A : 0,9\u00a0N → objectif < 0,54\u00a0N",
        "Palier B : 20\u00a0N → objectif < 0,15\u00a0N",
    ]
    # 54 N -> 0.9 N out of 54 N -> 0.54 N on a log scale: log(60)/log(100) = 0.889
    assert shown[0].done == pytest.approx(math.log(60) / math.log(100))
    assert shown[1].done == 0.0  # the force grew: no progress
    assert lines(check, WORDS, {"bearing_A": 0.5}, None)[0].text.endswith("objectif < …")


def test_labels_fall_back_to_names_and_bounds_may_be_written_on_the_left():
    check = compile_check("0.05 < abs(slip_velocity) and x >= 2")
    shown = lines(check, WORDS, {"slip_velocity": -0.02, "x": 1.0}, {"slip_velocity": 0.0, "x": 0})
    assert [line.text for line in shown] == [
        "|Glissement| : 0,02\u00a0m/s → objectif > 0,05\u00a0m/s",
        "x : 1\u00a0m → objectif ≥ 2\u00a0m",
    ]
    assert shown[0].done == pytest.approx(0.4) and shown[1].done == pytest.approx(0.5)
    brief = lines(check, WORDS, {"slip_velocity": 0.0, "x": 1.0}, None, brief=True)
    assert [line.text for line in brief] == ["|Glissement| : 0\u00a0m/s", "x : 1\u00a0m"]


@pytest.mark.parametrize(
    ("op", "now", "start", "bound", "expected"),
    [
        (ast.Lt, 5.0, 10.0, 0.0, 0.5),  # linear when the bound is 0
        (ast.Lt, 1.0, 100.0, 0.01, 0.5),  # log: 100 -> 1 is half the way to 0.01
        (ast.Lt, 0.001, 100.0, 0.01, 1.0),  # reached
        (ast.Lt, 200.0, 100.0, 0.01, 0.0),  # worse than the start
        (ast.Gt, 0.5, 0.0, 1.0, 0.5),
        (ast.GtE, 1.0, 0.0, 1.0, 1.0),
        (ast.Gt, 1.0, 0.0, 1.0, 0.99),  # not reached yet at the bound itself
        (ast.Eq, 1.0, 0.0, 1.0, None),
        (ast.Lt, math.nan, 1.0, 0.5, None),
    ],
)
def test_fraction(op, now, start, bound, expected):
    part = Part("x", op, ast.Constant(0.0))
    done = fraction(part, now, start, bound)
    if expected is None:
        assert done is None
    elif expected == 0.99:
        assert done is not None and done < 1.0
    else:
        assert done == pytest.approx(expected)


def test_other_shapes_are_written_in_words_without_a_bar():
    check = compile_check("bearing_A < 2 or bearing_B > 1.5 * initial(bearing_A)")
    assert parts(check) is None
    assert describe(check, WORDS) == "Palier A < 2 ou Palier B > (1,5 × Palier A au départ)"
    (line,) = lines(check, WORDS, {}, {})
    assert line.done is None and line.text.startswith("Palier A < 2 ou")


def test_the_block_escapes_text_and_has_no_emoji():
    html = goal_html(
        lines(compile_check("bearing_A < 2"), Words({"bearing_A": "<b>x</b>"}, {}), {}, {}),
        state="En cours",
    )
    assert "<b>x</b>" not in html and "&lt;b&gt;x&lt;/b&gt;" in html
    assert "Objectif — En cours" in html and 'role="progressbar"' not in html  # NaN: no bar
    html = goal_html(lines(compile_check("x < 2"), WORDS, {"x": 3.0}, {"x": 4.0}), state="En cours")
    assert 'aria-valuenow="50"' in html and "50 %" in html


def test_values_under_the_round_off_are_written_0():
    words = Words({}, {"F": "N"}, {"F": 1e-9})
    assert words.quantity(1.959e-19, "F") == "0\u00a0N" and words.quantity(0.5, "F") == "0,5\u00a0N"
    assert words.label("F") == "F"
