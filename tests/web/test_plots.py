"""Live plots: samples, sliding window, stable vertical range."""

from __future__ import annotations

import math

import pytest

from sandbox.web.plots import Plot, group_by_unit, nice_ceil


class Handle:
    def __init__(self) -> None:
        self.data = None
        self.scales_sent = 0
        self._scales = None

    @property
    def scales(self):
        return self._scales

    @scales.setter
    def scales(self, value):
        self.scales_sent += 1
        self._scales = value


@pytest.mark.parametrize(
    ("x", "want"), [(0.9, 1.0), (1.0, 1.0), (1.01, 1.5), (59.9, 60.0), (7e-4, 8e-4), (0, 1.0)]
)
def test_nice_ceil(x, want):
    assert nice_ceil(x) == pytest.approx(want)


def test_window_nan_and_time_going_back():
    plot = Plot(["a"], "N", [(0, 0, 0)], window=1.0)
    for k in range(30):
        plot.append({"time": 0.1 * k, "a": float(k)})
    t, a = plot.arrays()
    assert t[-1] - t[0] <= 1.0 + 1e-9 and a[-1] == 29.0
    plot.append({"time": 3.0, "a": math.inf})
    assert math.isnan(plot.arrays()[1][-1])
    plot.append({"time": 0.0, "a": 1.0})  # reset: the plot starts again
    assert len(plot.arrays()[0]) == 1


def test_range_is_only_resent_when_it_changes():
    plot = Plot(["a"], "N", [(0, 0, 0)])
    plot.handle = Handle()
    for k in range(50):
        plot.append({"time": 0.01 * k, "a": 54.0 + 0.01 * math.sin(k)})
        plot.push()
    assert plot.handle.scales_sent == 1
    assert plot.handle.scales["y"]["range"] == (0.0, 60.0)
    plot.append({"time": 1.0, "a": -3.0})
    plot.push()
    assert plot.handle.scales_sent == 2 and plot.handle.scales["y"]["range"][0] < -3.0


def test_group_by_unit():
    plots = group_by_unit(["F", "T", "G"], {"F": "N", "G": "N", "T": "J"}, {})
    assert [(p.names, p.unit) for p in plots] == [(("F", "G"), "N"), (("T",), "J")]
