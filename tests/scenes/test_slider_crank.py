"""The pieces the slider-crank scenes share: the fitted orders, the accuracy entry and the
round-off of the machines turning at constant speed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.scenes import SCENES
from sandbox.scenes.roundoff import ROUND_OFF
from sandbox.scenes.slider_crank import ACCURACY, fit_orders, peak_error, revolution_table


def test_fit_orders_reads_the_amplitudes_of_a_known_series():
    theta = np.linspace(0, 2 * math.pi, 64, endpoint=False)
    values = 0.5 + 3.0 * np.cos(theta + 0.2) - 1.5 * np.sin(2 * theta) + 0.25 * np.cos(7 * theta)
    amp = fit_orders(theta, values)
    assert amp == pytest.approx([0.5, 3.0, 1.5, 0.0, 0.0], abs=1e-12)


def test_peak_error_is_the_largest_gap_over_the_course_peak():
    series = {"pilon": [1.0, -2.1, 0.5], "pilon_ref": [1.0, -2.0, 0.4]}
    assert peak_error(series, {}) == pytest.approx(0.1 / 2.0)


def test_the_compressor_and_the_engine_share_one_accuracy_entry():
    assert SCENES["compressor"].accuracy is ACCURACY
    assert SCENES["engine"].accuracy is ACCURACY
    assert ACCURACY.error is peak_error
    assert ACCURACY.values == {"speed_rpm": 17000.0}


@pytest.mark.parametrize(
    ("name", "own"),
    [
        ("rotor", {"kg·m": 1e-13, "kg·m²": 1e-14, "Pa": 1e-3}),
        ("compressor", {"m": 1e-13, "Pa": 1e-3}),
        ("engine", {"m": 1e-15, "Pa": 1e-3}),
    ],
)
def test_the_machines_at_constant_speed_share_the_round_off_table(name, own):
    zero = dict(SCENES[name].zero)
    assert zero == {**ROUND_OFF, **own}
    assert ROUND_OFF == {
        "N": 5e-7,
        "N·m": 5e-9,
        "W": 1e-6,
        "J": 1e-12,
        "kg·m/s": 1e-12,
        "kg·m²/s": 1e-12,
    }


def test_a_revolution_table_is_sorted_by_the_crank_angle_in_one_turn():
    """Samples taken from θ = 5 rad on, past 2π: the chart's table starts at 0° and keeps
    each row whole (its θ as sampled, its values beside it)."""
    thetas = np.linspace(5.0, 5.0 + 2 * np.pi, 8, endpoint=False)
    rows = [(t, 10 * t, -t) for t in thetas]
    table = revolution_table(rows, ("a", "b"))
    assert list(table) == ["angle_deg", "theta", "a", "b"]
    assert np.all(np.diff(table["angle_deg"]) > 0)
    assert 0.0 <= table["angle_deg"][0] < 360 / 8 and table["angle_deg"][-1] < 360.0
    np.testing.assert_allclose(table["a"], 10 * table["theta"])
    np.testing.assert_allclose(table["b"], -table["theta"])
    np.testing.assert_allclose(np.radians(table["angle_deg"]), np.mod(table["theta"], 2 * np.pi))
