"""Live plots: samples, sliding window, stable vertical range."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.scenes import get_scene
from sandbox.web.panels.plots import Plot, group_by_unit, nice_ceil, nice_range


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
    t, a, _ = plot.arrays()
    assert t[-1] - t[0] <= 1.0 + 1e-9 and a[-1] == 29.0
    plot.append({"time": 3.0, "a": math.inf})
    assert math.isnan(plot.arrays()[1][-1])
    plot.append({"time": 0.0, "a": 1.0})  # reset: the plot starts again
    assert len(plot.t) == 1 and len(plot.arrays()[0]) == 2  # uPlot needs two points


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
    for bound in ("min", "max"):  # 0 kept in view, the headroom is the range series'
        assert created["y"]["range"][bound] == {"pad": 0.0, "soft": 0.0, "mode": 1}
    assert created["x"] == {"time": False}
    for k in range(60):  # the range grows 50-fold, then the sign changes
        plot.append({"time": 0.1 * k, "v": 0.5 * k if k < 50 else -100.0})
        plot.push()
        t, v, bounds = plot.handle.data
        n = max(k + 1, 2)
        assert t[-1] == pytest.approx(0.1 * k) or k == 0
        assert len(t) == len(v) == len(bounds) == n
        assert (bounds[0], bounds[-1]) == plot.y_range() and np.isnan(bounds[1:-1]).all()
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


def test_rotor_bearing_components_are_constant_in_the_rotating_basis():
    """Course 7.2: the bearing forces are fixed in the rotor. Their B1 components stay
    put while the rotor turns, and they make up the magnitude the table shows."""
    import mujoco
    import numpy as np

    from sandbox.physics.simulation import Simulation
    from sandbox.web.panels.plots import component_plot

    sim = Simulation(get_scene("rotor"))
    scene = sim.scene
    plot = component_plot(scene)
    assert plot is not None and plot.spec.basis == "B1"
    assert [label.split(", ")[-1] for label in plot.labels] == ["y₁", "z₁", "y₁", "z₁"]
    assert all("Palier" in label for label in plot.labels)
    assert "composantes dans B₁" in plot.title() and "[N]" in plot.title()
    assert not any("_" in label for label in plot.labels)
    body = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, scene.page.body_frame)
    seen, turned = [], []
    for _ in range(5):
        sim.advance(0.013)  # not a whole number of turns
        snapshot = sim.snapshot(("sup_R_x", "dyn_R_x"))
        basis = sim.data.xmat[body].reshape(3, 3).copy()
        values = plot.values(snapshot, basis)
        seen.append([values[n] for n in plot.names])
        world = plot.values(snapshot, np.eye(3))
        magnitude = math.hypot(values["bearing_A.1"], values["bearing_A.2"])
        assert magnitude == pytest.approx(sim.readouts(["bearing_A"])["bearing_A"], rel=1e-6)
        turned.append(abs(world["bearing_A.1"] - values["bearing_A.1"]) > 1e-3 * magnitude)
    assert any(turned)  # in B0 the same force turns
    seen_array = np.array(seen)
    assert np.ptp(seen_array, axis=0).max() < 1e-6 * np.abs(seen_array).max()
    series = plot.series()
    assert "dash" not in series[1] and series[2]["dash"] == (8.0, 4.0)


def test_scenes_without_component_plot():
    from sandbox.physics.simulation import Simulation
    from sandbox.web.panels.plots import component_plot

    assert component_plot(None) is None
    assert component_plot(Simulation(get_scene("rolling_cylinder")).scene) is None
    gyro = component_plot(Simulation(get_scene("gyroscope")).scene)
    assert gyro is not None and gyro.spec.basis == "B0" and len(gyro.names) == 3


def test_round_off_is_drawn_as_zero():
    (plot,) = group_by_unit(["F"], {"F": "N"}, {}, labels={"F": "Effort F"}, zero={"N": 1e-9})
    plot.append({"time": 0.0, "F": 3e-12})
    plot.append({"time": 0.1, "F": -2.0})
    assert list(plot.arrays()[1]) == [0.0, -2.0]
    assert plot.labels == ("Effort F",) and plot.series()[1]["label"] == "Effort F [N]"


def test_a_nearly_constant_signal_sits_below_the_top_edge():
    """The heavy top's ψ' = 0,7858 rad/s ± 10⁻⁹: uPlot alone ranged [0 ; 0,7858] and drew
    the line on the top edge; the range series asks for [0 ; 1]."""
    plot = Plot(["psi"], "rad/s", [(0, 0, 0)], labels=["ψ'"])
    for k in range(20):
        plot.append({"time": 0.1 * k, "psi": 0.7857610 + 1e-9 * k})
    *_, bounds = plot.arrays()
    assert (bounds[0], bounds[-1]) == (0.0, 1.0)
    series = plot.series()
    assert len(series) == 3 and series[-1]["stroke"] == "rgba(0,0,0,0)"
    assert series[-1]["width"] == 0 and series[-1]["label"] == "\u2009"


def test_a_paused_simulation_keeps_one_sample_showing_the_last_values():
    plot = Plot(["a"], "N", [(0, 0, 0)])
    plot.append({"time": 1.0, "a": 1.0})
    for k in range(50):  # paused: the same time, a parameter moved
        plot.append({"time": 2.0, "a": float(k)})
    assert list(plot.t) == [1.0, 2.0] and list(plot.y[0]) == [1.0, 49.0]


def test_nice_range_holds_zero_every_finite_value_and_its_headroom():
    assert nice_range([3.0, 7.0, math.nan]) == (0.0, 8.0)  # 7 + 0.7 → 8
    assert nice_range([-2.0, 1.0]) == (-2.5, 1.5)  # pad 0.3 each side
    assert nice_range([0.0], 0.08) == (0.0, 1.0)  # nothing to hold: a unit range
    assert nice_range([95.0], 0.08) == (0.0, 150.0)  # 95 + 7.6 → 150
