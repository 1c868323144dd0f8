"""Folder "Sur un tour": a scene's readouts over one cycle against the angle, with the
course's curves (e.g. pilon, tamis and motor torque over a crank revolution)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.web.panels.folder import Folder

if TYPE_CHECKING:
    import viser
    from viser import uplot

PERIOD = 2.0
"""Seconds between two looks at the cycle (redrawn only when it changed)."""

GROUPS = ((("pilon", "tamis"), "N"), (("motor_torque",), "N·m"))
"""Readouts drawn together, and their unit (one chart each)."""

TITLES = {
    ("pilon", "tamis"): "Effets de pilon et de tamis sur un tour du vilebrequin",
    ("motor_torque",): "Couple moteur sur un tour du vilebrequin",
}
"""Chart titles (default: the labels joined)."""
COLORS = {"pilon": "rgb(220,60,60)", "tamis": "rgb(60,140,220)", "motor_torque": "rgb(90,90,90)"}


FOLDER = "Sur un tour"
"""The folder's title (in « Panneau affiché »)."""


class CyclePanel:
    """Charts of ``scene.cycle`` (nothing when the scene has no cycle).

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation.
    """

    def __init__(self, gui: viser.GuiApi, sim: ReadOnlySimulation) -> None:
        self.sim = sim
        scene = sim.scene
        self.fn = scene.cycle if scene is not None else None
        self.charts: list[tuple[tuple[str, ...], viser.GuiUplotHandle]] = []
        self._shown: object = None
        self._at = -math.inf
        self.folder: viser.GuiFolderHandle | None = None
        if self.fn is None:
            return
        labels = {i.name: i.label or i.name for i in sim.readout_infos()}
        with gui.add_folder(FOLDER) as self.folder:
            for names, unit in GROUPS:
                series: list[uplot.Series] = [{"label": "θ [°]"}]
                for n in names:
                    color = COLORS.get(n, "black")
                    words = labels.get(n, n)
                    series.append({"label": f"{words} [{unit}]", "stroke": color, "width": 2})
                    series.append({"label": f"{words}, cours", "stroke": color, "dash": (6.0, 4.0)})
                empty = tuple(np.zeros(2) for _ in series)
                title = TITLES.get(names) or " et ".join(labels.get(n, n) for n in names)
                chart = gui.add_uplot(
                    data=empty,
                    series=tuple(series),
                    title=title,
                    scales={"x": {"time": False, "auto": False, "range": (0.0, 360.0)}},
                    axes=(
                        {"label": "Angle du vilebrequin θ [°]"},
                        {"label": unit, "size": 60},
                    ),
                    aspect=1.6,
                    legend={"live": False},  # names only, no "--" value cells
                    padding=(12, 24, 0, 0),
                )
                self.charts.append((names, chart))

    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché » (none when the scene has no cycle): computed
        from the simulation over a revolution, so a challenge closes it."""
        if self.folder is None:
            return []
        return [Folder(FOLDER, self.folder, lambda frame: self.refresh(self.sim, frame.now))]

    def refresh(self, sim: ReadOnlySimulation, now: float) -> None:
        """Redraw when the simulated cycle changed (new parameters or speed)."""
        if self.fn is None or now - self._at < PERIOD:
            return
        self._at = now
        with sim.lock:
            cycle = self.fn(sim.snapshot((), forces=True))
        if cycle is self._shown or len(cycle.get("angle_deg", ())) < 2:
            return
        self._shown = cycle
        for names, chart in self.charts:
            columns = [cycle["angle_deg"]]
            for n in names:
                columns += [cycle[n], cycle[f"{n}_ref"]]
            chart.data = tuple(np.asarray(c, dtype=float) for c in columns)
