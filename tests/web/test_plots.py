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


class Gui:
    """Stands for viser's GuiApi: keeps the options the chart was created with."""

    def __init__(self) -> None:
        self.created: dict = {}
        self.handle = Handle()

    def add_uplot(self, **kwargs):
        self.created = kwargs
        self.handle.data = kwargs["data"]
        return self.handle


def test_scales_are_sent_once_and_every_push_sends_the_data():
    """Issue 14: a new ``scales`` rebuilt the browser's chart, which then drew nothing,
    then one second of data 8 s late. The range now moves in the browser."""
    plot = Plot(["v"], "m/s", [(0, 0, 0)])
    gui = Gui()
    plot.attach(gui, title="v")
    created = gui.created["scales"]
    assert created["y"]["auto"] is True and "range" in created["y"]
    for bound in ("min", "max"):  # 10 % headroom, 0 kept in view
        assert created["y"]["range"][bound] == {"pad": 0.1, "soft": 0.0, "mode": 1}
    assert created["x"] == {"time": False}
    for k in range(60):  # the range grows 50-fold, then the sign changes
        plot.append({"time": 0.1 * k, "v": 0.5 * k if k < 50 else -100.0})
        plot.push()
        t, v = plot.handle.data
        assert t[-1] == pytest.approx(0.1 * k) and len(t) == len(v) == k + 1
    assert plot.handle.scales_sent == 0
    assert plot.scales() == created  # and a copy: a caller cannot change the shared one
    plot.scales()["y"]["auto"] = False
    assert plot.scales()["y"]["auto"] is True


def test_y_range_includes_zero_and_headroom():
    plot = Plot(["a"], "N", [(0, 0, 0)])
    for k in range(50):
        plot.append({"time": 0.01 * k, "a": 54.0 + 0.01 * math.sin(k)})
    assert plot.y_range() == (0.0, 60.0)
    plot.append({"time": 1.0, "a": -3.0})
    assert plot.y_range()[0] < -3.0


def test_group_by_unit():
    plots = group_by_unit(["F", "T", "G"], {"F": "N", "G": "N", "T": "J"}, {})
    assert [(p.names, p.unit) for p in plots] == [(("F", "G"), "N"), (("T",), "J")]
