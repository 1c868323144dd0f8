"""Folder "Sur un tour": French titles and series, curves against the crank angle."""

from __future__ import annotations

import contextlib

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.web.panels.cycle import CyclePanel


class Chart:
    def __init__(self, **kwargs) -> None:
        self.options = kwargs
        self.data = kwargs["data"]


class Gui:
    """Just enough of viser's GuiApi: keeps the charts created."""

    def __init__(self) -> None:
        self.charts: list[Chart] = []

    def add_folder(self, label):
        self.folder = label
        return contextlib.nullcontext()

    def add_uplot(self, **kwargs):
        self.charts.append(Chart(**kwargs))
        return self.charts[-1]


def test_compressor_cycle_speaks_french_and_draws_a_revolution():
    sim = Simulation(get_scene("compressor"))
    gui = Gui()
    panel = CyclePanel(gui, sim)  # type: ignore[arg-type]
    assert gui.folder == "Sur un tour" and len(gui.charts) == 2
    forces, torque = gui.charts
    assert forces.options["title"] == "Effets de pilon et de tamis sur un tour du vilebrequin"
    labels = [s["label"] for s in forces.options["series"]]
    assert labels[0] == "θ [°]" and "Effet de pilon [N]" in labels
    assert "Effet de tamis, cours" in labels
    for options in (forces.options, torque.options):
        text = "| " + " | ".join([options["title"], *(s["label"] for s in options["series"])])
        for code in ("| pilon", "motor_torque", "_ref", "manivelle"):
            assert code not in text, code
        assert options["axes"][0]["label"] == "Angle du vilebrequin θ [°]"
    sim.advance(0.05)
    panel.refresh(sim, now=10.0)
    angle = forces.data[0]
    assert len(angle) > 10 and 0.0 <= angle.min() and angle.max() < 360.0
    assert len(forces.data) == 5 and all(len(c) == len(angle) for c in forces.data)


def test_scenes_without_a_cycle_have_no_folder():
    gui = Gui()
    panel = CyclePanel(gui, Simulation(get_scene("rotor")))  # type: ignore[arg-type]
    assert panel.folder is None and not gui.charts
