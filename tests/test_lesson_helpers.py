"""The helpers the modules of ``sandbox.lessons`` share: errors naming ``file:line``,
``NAME=VALUE`` pairs, and the arithmetic of checks."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import pytest

from sandbox.lessons.checks import compile_check
from sandbox.lessons.evaluation import COMPARE, MAX_EXPONENT, CheckError, power_of, truth_of
from sandbox.lessons.model import BadLesson, fail
from sandbox.lessons.reader import parse_pairs


def test_fail_names_the_file_and_line():
    error = fail(Path("lessons/x.md"), 12, "write it so")
    assert isinstance(error, BadLesson)
    assert str(error) == f"{Path('lessons/x.md')}:12: write it so"


def test_parse_pairs_reads_names_and_finite_numbers():
    assert parse_pairs(" mass1_g=32, angle1_deg = 180 ,", "preset") == (
        ("mass1_g", 32.0),
        ("angle1_deg", 180.0),
    )
    assert parse_pairs("", "preset") == ()
    with pytest.raises(ValueError, match="preset expects NAME=VALUE"):
        parse_pairs("mass1_g", "preset")
    with pytest.raises(ValueError, match="expects a number"):
        parse_pairs("mass1_g=heavy", "solution")
    with pytest.raises(ValueError, match="expects a finite number"):
        parse_pairs("mass1_g=inf", "solution")


def test_power_of_computes_real_bounded_powers():
    assert power_of(2.0, 10.0) == 1024.0
    assert power_of(-2.0, 3.0) == -8.0
    assert power_of(4.0, 0.5) == 2.0
    with pytest.raises(CheckError, match="too large") as exc:
        power_of(2.0, MAX_EXPONENT + 1)
    assert "exposant" in exc.value.french
    with pytest.raises(CheckError, match="division by zero"):
        power_of(0.0, -1.0)
    with pytest.raises(CheckError, match="not a real number"):
        power_of(-8.0, 0.5)
    with pytest.raises(CheckError, match="overflows"):
        power_of(1e300, 2.0)
    assert math.isinf(power_of(math.inf, 2.0))  # an infinite input is not an overflow


def test_truth_of_evaluates_a_compiled_condition():
    check = compile_check("x < 2 * initial(x) and not y >= 1")
    assert check.tree is not None
    body = check.tree.body
    assert truth_of(body, {"x": 1.0, "y": 0.0}, {"x": 1.0})
    assert not truth_of(body, {"x": 3.0, "y": 0.0}, {"x": 1.0})
    assert not truth_of(body, {"x": 1.0, "y": 1.0}, {"x": 1.0})
    with pytest.raises(CheckError, match="no readout 'y' now"):
        truth_of(body, {"x": 1.0}, {"x": 1.0})


def test_compare_holds_the_six_comparisons():
    assert set(COMPARE) == {ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.Eq, ast.NotEq}
    assert COMPARE[ast.LtE](1.0, 1.0) and not COMPARE[ast.Lt](1.0, 1.0)
    assert COMPARE[ast.NotEq](1.0, 2.0) and not COMPARE[ast.Eq](1.0, 2.0)
