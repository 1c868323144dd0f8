"""Folder "Tracé X–Y": any readout against any other (or against time), with the
course's value dashed, a cursor reading X, Y and the slope, and downloads.

The scene's presets (:attr:`~sandbox.physics.page.Page.xy_presets`) show its laws in one
click: the compressor's pilon and tamis over a crank revolution, the rotor's bearing
forces against ω during a slow start. Samples come from the session's
:class:`~sandbox.web.loop.probe.Probe`, taken between frames, only while the folder is shown
and the plot is not frozen.
"""

from __future__ import annotations

import copy
import math
import threading
import time
from collections.abc import Mapping, Sequence
from typing import Any

import viser
from viser import uplot

from sandbox.physics.presets import TIME, XYPreset
from sandbox.web.loop.requests import Reset, SetValue
from sandbox.web.loop.state import SessionState
from sandbox.web.panels.folder import Folder
from sandbox.web.panels.plots import PALETTE, RANGE_SERIES, dashed, dots, replace_chart
from sandbox.web.panels.preset_picker import PresetPicker
from sandbox.web.panels.xy_data import TIME_AXIS, Axis, XYData

FOLDER = "Tracé X–Y"
NONE = "— aucune —"
FREEZE = "Figer le tracé"
RESUME = "Reprendre le tracé"
Y_SLOTS = 3
PUSH_PERIOD = 0.25
"""Seconds between two sendings of the chart (it holds up to 720 points per series)."""


def _css(rgb: tuple[int, int, int]) -> str:
    return f"rgb({rgb[0]},{rgb[1]},{rgb[2]})"


def _hex(rgb: tuple[int, int, int]) -> str:
    return f"#{rgb[0]:02x}{rgb[1]:02x}{rgb[2]:02x}"


class XYPanel:
    """The folder, its chart and the probe it reads.

    Args:
        gui: A viser ``GuiApi``.
        controller: The live session (its probe samples the chosen readouts).
    """

    def __init__(self, gui: viser.GuiApi, controller: SessionState) -> None:
        self.gui = gui
        self.controller = controller
        sim = controller.sim
        scene = sim.scene
        self.presets: dict[str, XYPreset] = {
            p.label: p for p in (scene.page.xy_presets if scene else ())
        }
        self.zero: Mapping[str, float] = dict(scene.zero) if scene is not None else {}
        colors = {a.name: a.color for a in (scene.page.arrows if scene is not None else ())}
        self.colors = colors
        self.axes: dict[str, Axis] = {TIME: TIME_AXIS}
        for info in sim.readout_infos():
            if info.name != TIME:
                self.axes[info.name] = Axis.of(info.name, info.label or info.name, info.unit)
        self.words: dict[str, str] = {}  # dropdown text -> readout name
        for name, axis in self.axes.items():
            text = axis.title if axis.title not in self.words else f"{axis.title} ({name})"
            self.words[text] = name
        self.title_of = {n: t for t, n in self.words.items()}
        self._lock = threading.Lock()
        self._pending: dict[str, Any] = {}
        self.frozen = False
        self.cursor = 0.5
        self._seq = 0
        self._pushed = -math.inf
        self._dirty = True
        # shown at the start: a preset that changes no parameter (choosing one that does,
        # such as a start from rest, restarts the simulation: the user's click only)
        first = next((p for p in self.presets.values() if not p.values), None)
        x, ys, refs = self._choice(first)
        self.data = XYData(self.axes[x], [self.axes[y] for y in ys], refs)
        self.title = first.label if first is not None else ""
        readouts = tuple(t for t, n in self.words.items() if n != TIME)
        with gui.add_folder(FOLDER, expand_by_default=True) as self.folder:
            self.picker = PresetPicker(
                gui,
                "Tracé proposé",
                tuple(self.presets),
                first=first.label if first is not None else None,
                hint="Des tracés qui montrent les lois du cours pour cette scène",
                shown=first.hint if first is not None else "",
            )
            self.preset, self.hint = self.picker.dropdown, self.picker.hint
            self.x_pick = gui.add_dropdown(
                "Axe horizontal X",
                tuple(self.words),
                initial_value=self.title_of[x],
                hint="Le temps ou n'importe quelle grandeur de la scène",
            )
            self.y_picks = [
                gui.add_dropdown(
                    f"Courbe {k + 1} (axe vertical Y)",
                    readouts if k == 0 else (NONE, *readouts),
                    initial_value=self.title_of[ys[k]] if k < len(ys) else NONE,
                    hint="Grandeur tracée en fonction de X ; la valeur du cours est en "
                    "tirets quand la scène en a une",
                )
                for k in range(Y_SLOTS)
            ]
            self.chart = self._new_chart()
            self.cursor_pick = gui.add_slider(
                "Curseur sur X [%]",
                min=0.0,
                max=100.0,
                step=1.0,
                initial_value=50.0,
                hint="Position du curseur dans l'étendue de X : il lit X, Y et la pente dY/dX",
            )
            self.reading = gui.add_markdown("")
            self.freeze = gui.add_button(
                FREEZE, hint="Arrête d'ajouter des points (et de les calculer)"
            )
            self.clear = gui.add_button("Effacer le tracé", color="gray")
            self.csv = gui.add_button("Télécharger le tracé (CSV)", color="gray")
            self.png = gui.add_button("Télécharger le tracé (PNG)", color="gray")
        self._connect()

    # -- choices -------------------------------------------------------------------------
    def _choice(self, preset: XYPreset | None) -> tuple[str, list[str], dict[str, str]]:
        """(X, Ys, course readouts by Y) of ``preset``, or time and the scene's first
        plot when there is none; a Y without a course value given uses ``<Y>_ref``."""
        if preset is not None:
            x, ys = preset.x, [y for y in preset.ys if y in self.axes][:Y_SLOTS]
        else:
            scene = self.controller.sim.scene
            plots = [n for n in (scene.page.plots if scene is not None else ()) if n in self.axes]
            x, ys = TIME, plots[:1] or ["T"]
        refs = dict(preset.refs) if preset is not None else {}
        for y in ys:
            if y not in refs and f"{y}_ref" in self.axes:
                refs[y] = f"{y}_ref"
        return (
            (x if x in self.axes else TIME),
            ys,
            {y: r for y, r in refs.items() if r in self.axes},
        )

    def _connect(self) -> None:
        def later(key: str, value: Any) -> None:
            with self._lock:
                self._pending[key] = value

        @self.preset.on_update
        def _(event: viser.GuiEvent[viser.GuiDropdownHandle[str]]) -> None:
            if event.client is not None:
                later("preset", str(event.target.value))

        for handle in (self.x_pick, *self.y_picks):
            handle.on_update(lambda e: later("axes", True) if e.client is not None else None)

        @self.cursor_pick.on_update
        def _(event: viser.GuiEvent[viser.GuiSliderHandle[float]]) -> None:
            later("cursor", float(event.target.value))

        self.freeze.on_click(lambda _: later("freeze", True))
        self.clear.on_click(lambda _: later("clear", True))
        self.csv.on_click(lambda e: self._download(e.client, "csv"))
        self.png.on_click(lambda e: self._download(e.client, "png"))

    def _apply(self) -> None:
        with self._lock:
            pending, self._pending = self._pending, {}
        if not pending:
            return
        if "preset" in pending:
            preset = self.presets.get(pending["preset"])
            x, ys, refs = self._choice(preset)
            self.x_pick.value = self.title_of[x]  # type: ignore[misc]
            for k, pick in enumerate(self.y_picks):
                pick.value = self.title_of[ys[k]] if k < len(ys) else NONE  # type: ignore[misc]
            self.picker.show(preset.hint if preset is not None else "")
            self.title = preset.label if preset is not None else ""
            self._rebuild(x, ys, refs)
            if preset is not None and preset.values:
                for name, value in preset.values.items():
                    self.controller.submit(SetValue(name, value))
                self.controller.submit(Reset())
        elif "axes" in pending:
            x = self.words.get(str(self.x_pick.value), TIME)
            ys = [self.words[str(p.value)] for p in self.y_picks if str(p.value) in self.words]
            ys = list(dict.fromkeys(n for n in ys if n != TIME)) or [self.data.ys[0].name]
            refs = {y: f"{y}_ref" for y in ys if f"{y}_ref" in self.axes}
            self.picker.free()
            self.title = ""
            self._rebuild(x, ys, refs)
        if "cursor" in pending:
            self.cursor = min(max(pending["cursor"] / 100.0, 0.0), 1.0)
            self._dirty = True
        if pending.get("freeze"):
            self.frozen = not self.frozen
            self.freeze.label = RESUME if self.frozen else FREEZE
        if pending.get("clear"):
            self.data.clear()
            self._dirty = True

    def _rebuild(self, x: str, ys: Sequence[str], refs: Mapping[str, str]) -> None:
        self.data = XYData(self.axes[x], [self.axes[y] for y in ys], refs)
        self._seq = self.controller.probe.since(0)[0]  # only samples of the new choice
        self.chart = replace_chart(self.folder, self.chart, self._new_chart)
        self._dirty = True

    # -- the chart -----------------------------------------------------------------------
    def rgb(self, k: int, name: str) -> tuple[int, int, int]:
        """The colour of the k-th Y: its arrow's when it has one."""
        return self.colors.get(name, PALETTE[k % len(PALETTE)])

    def heading(self) -> str:
        """The chart's title: the preset's, or the Ys against X in words."""
        if self.title:
            return self.title
        ys = " et ".join(y.words for y in self.data.ys)
        return f"{ys}, en fonction de : {self.data.x.words}"

    def _new_chart(self, order: float | None = None) -> viser.GuiUplotHandle:
        data = self.data
        series: list[uplot.Series] = [{"label": data.x.title}]
        index = {y.name: k for k, y in enumerate(data.ys)}
        lines = data.x.name == TIME or data.x.folds
        for role, y in data.layout():
            color = _css(self.rgb(index[y.name], y.name))
            if role == "y":
                style: uplot.Series = {"label": y.title, "stroke": color, "width": 2}
                if not lines:  # a cloud of points: lines would join far-apart samples
                    style = dots(y.title, color)
                series.append(style)
            elif role == "range":
                series.append(copy.deepcopy(RANGE_SERIES))
            elif role == "ref":
                series.append(dashed(f"{y.words}, cours", color, 1.5, (6.0, 4.0)))
            else:
                series.append(dashed(f"{y.words} au curseur", color, 1, (2.0, 3.0)))
        # x follows the samples: viser re-ranges y only when it re-ranges an automatic x
        # (a fixed x range left the y axis of the first, empty data for good)
        x_scale: uplot.Scale = {"time": False}
        units = {y.shown for y in data.ys}
        return self.gui.add_uplot(
            data=data.arrays(self.cursor),
            series=tuple(series),
            title=None,  # the preset's name is above it; a phone cut long titles
            scales={"x": x_scale, "y": {"auto": True}},
            axes=(
                {"label": data.x.title},
                {"label": units.pop() if len(units) == 1 else "", "size": 60},
            ),
            legend={"live": False},
            padding=(12, 24, 0, 0),
            aspect=1.3,
            order=order,
        )

    # -- from the session loop -----------------------------------------------------------
    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché »: it samples the simulation between frames
        (only while shown), so a challenge closes it."""
        return [
            Folder(FOLDER, self.folder, lambda frame: self.refresh(frame.now), watch=self.watch)
        ]

    def watch(self, shown: bool) -> None:
        """Sample while the folder is shown and the plot not frozen (every tick)."""
        if shown and not self.frozen:
            self.controller.probe.want(self, self.data.names)
        else:
            self.controller.probe.release(self)

    def refresh(self, now: float) -> None:
        """Apply the page's choices, take the new samples, send the chart at most every
        :data:`PUSH_PERIOD` s when it changed."""
        self._apply()
        seq, samples = self.controller.probe.since(self._seq)
        self._seq = seq
        if samples and not self.frozen:
            self.data.add(samples)
            self._dirty = True
        if not self._dirty or now - self._pushed < PUSH_PERIOD:
            return
        self._pushed, self._dirty = now, False
        self.chart.data = self.data.arrays(self.cursor)
        self.reading.content = self.data.reading(self.cursor, self.zero)

    def _download(self, client: viser.ClientHandle | None, kind: str) -> None:
        if client is None:
            return
        stamp = time.strftime("%Y%m%d-%H%M%S")
        scene = self.controller.sim.scene
        name = f"trace_xy_{scene.name if scene is not None else 'modele'}_{stamp}"
        if kind == "csv":
            client.send_file_download(f"{name}.csv", self.data.csv_text().encode("utf-8"))
            return
        colors = [_hex(self.rgb(k, y.name)) for k, y in enumerate(self.data.ys)]
        client.send_file_download(f"{name}.png", self.data.png(self.heading(), colors))
