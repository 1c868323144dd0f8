"""The chart of a parameter study: one dot per run as runs finish, the course's closed
form dashed, a curve per value of a second parameter, and its files. Drawn by the
student's « Étude paramétrique » and by a follower's page when the teacher sends a study.
"""

from __future__ import annotations

import io
import math
import time
from collections.abc import Callable, Mapping, Sequence

import numpy as np
import viser
from viser import uplot

from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.spec import Param
from sandbox.sweep import plot, write_csv
from sandbox.web.client.fields import param_label, param_unit
from sandbox.web.client.text import number, with_unit
from sandbox.web.loop.study_queue import StudyJob
from sandbox.web.panels.plots import PALETTE, dashed, dots, nice_range, replace_chart
from sandbox.web.panels.xy_data import Axis

XAxis = tuple[str, Callable[[Mapping[str, float]], float]]

STAT_LABELS = {
    "final": "Valeur à la fin",
    "mean": "Moyenne",
    "max": "Maximum",
    "amplitude": "Amplitude (demi-écart crête à crête)",
    "order1": "Amplitude d'ordre 1 sur le dernier tour",
    "order2": "Amplitude d'ordre 2 sur le dernier tour",
    "period": "Période des oscillations",
    "onset": "Instant où elle quitte sa valeur de départ (glissement, décollement…)",
}
"""What a run's samples are reduced to, in words (see :data:`sandbox.sweep.STATISTICS`)."""

TITLE_WORDS = {
    "final": "",
    "mean": ", moyenne",
    "max": ", maximum",
    "amplitude": ", amplitude",
    "order1": ", ordre 1",
    "order2": ", ordre 2",
    "period": "Période",
    "onset": "Instant du changement",
}
"""The statistic in a chart's title, short enough for a phone ("Effet de pilon [N], ordre 2";
a time: "Période de : Angle … [s]")."""

TIMES = frozenset({"period", "onset"})
"""Statistics that are times [s], whatever the readout's unit."""


class StudyChart:
    """A study's chart in ``folder`` of ``gui``, for the scene of ``sim``."""

    def __init__(
        self, gui: viser.GuiApi, folder: viser.GuiFolderHandle, sim: ReadOnlySimulation
    ) -> None:
        self.gui = gui
        self.folder = folder
        scene = sim.scene
        self.params: dict[str, Param] = {p.name: p for p in (scene.params if scene else ())}
        self.infos = {i.name: i for i in sim.readout_infos()}
        self._y_range: tuple[float, float] | None = None
        self._labels: object = None
        with folder:
            self.chart = self._new_chart(("", ""), [("dots", "")], (0.0, 1.0), (0.0, 1.0))

    def x_of(self, job: StudyJob) -> XAxis:
        """(axis title, X of a run's values): the study's own when it names one (a
        preset's R/L), else its first parameter."""
        first = job.study.varies[0].name
        if job.x is not None:
            return job.x
        p = self.params[first]
        return param_label(p), lambda v: float(v[first])

    def draw(self, job: StudyJob) -> None:
        """The study's dots and closed form as they are now."""
        study = job.study
        x_title, x_of = self.x_of(job)
        fixed = {n: float(v) for n, v in study.fixed}
        second = study.varies[1] if len(study.varies) > 1 else None
        families = second.values if second is not None else [None]
        points = study.points()  # the first parameter varies slowest
        xs = [
            x_of({**fixed, **points[i * len(families)]}) for i in range(len(study.varies[0].values))
        ]
        order = np.argsort(xs)
        x = np.asarray(xs, dtype=float)[order]
        columns_: list[np.ndarray] = []
        labels: list[tuple[str, str]] = []
        found: list[float] = []
        n = len(study.varies[0].values)
        for f, family_value in enumerate(families):
            rows = job.rows[f :: len(families)] if second is not None else job.rows
            rows = [rows[k] for k in order] if len(rows) == n else rows
            measure = np.array([r["measure"] if r else math.nan for r in rows], dtype=float)
            course = np.array([r["closed_form"] if r else math.nan for r in rows], dtype=float)
            name = (
                self._family_words(second.name, family_value)
                if second and family_value is not None
                else ""
            )
            columns_.append(measure)
            labels.append(("dots", name))
            found += [v for v in measure if math.isfinite(v)]
            if np.isfinite(course).any():
                columns_.append(course)
                labels.append(("course", name))
                found += [v for v in course if math.isfinite(v)]
        y_range = nice_range(found or [0.0], 0.08)  # a few rebuilds a study
        info = self.infos[study.measure.readout]
        axis = Axis.of(info.name, info.label or info.name, info.unit)
        statistic = study.measure.statistic
        y_title = f"{axis.title}{TITLE_WORDS[statistic]}"
        scale = axis.scale
        if statistic in TIMES:  # a time [s], whatever the readout's unit
            y_title, scale = f"{TITLE_WORDS[statistic]} de : {axis.words} [s]", 1.0
        data = (x, *(c * scale for c in columns_))
        x_range = (float(np.nanmin(x)), float(np.nanmax(x)))
        if x_range[0] == x_range[1]:
            x_range = (x_range[0] - 1.0, x_range[1] + 1.0)
        if self._y_range != y_range or self._labels != (labels, x_title):
            self._y_range = y_range
            self._labels = (labels, x_title)
            scaled = (y_range[0] * scale, y_range[1] * scale)
            self._replace_chart((x_title, y_title), labels, x_range, scaled, data)
        else:
            self.chart.data = data

    def _family_words(self, name: str, value: float) -> str:
        p = self.params[name]
        return f"{p.label or p.name} = {with_unit(number(value, 4), param_unit(p))}"

    def _replace_chart(
        self,
        titles: tuple[str, str],
        labels: Sequence[tuple[str, str]],
        x_range: tuple[float, float],
        y_range: tuple[float, float],
        data: tuple[np.ndarray, ...],
    ) -> None:
        self.chart = replace_chart(
            self.folder,
            self.chart,
            lambda order: self._new_chart(titles, labels, x_range, y_range, data, order),
        )

    def _new_chart(
        self,
        titles: tuple[str, str],
        labels: Sequence[tuple[str, str]],
        x_range: tuple[float, float],
        y_range: tuple[float, float],
        data: tuple[np.ndarray, ...] | None = None,
        order: float | None = None,
    ) -> viser.GuiUplotHandle:
        """A chart with fixed ranges on both axes: dots of runs not yet done are NaN,
        which viser's uPlot draws only with fixed ranges (an automatic range with a NaN
        first value loses its y axis)."""
        series: list[uplot.Series] = [{"label": titles[0]}]
        curve = -1
        for kind, name in labels:
            if kind == "dots":
                curve += 1
            r, g, b = PALETTE[max(curve, 0) % len(PALETTE)]
            color = f"rgb({r},{g},{b})"
            if kind == "dots":
                series.append(dots(name or "Simulations", color, 8.0))
            else:
                series.append(dashed(f"Cours{', ' + name if name else ''}", color, 1.5, (6.0, 4.0)))
        if data is None:
            data = (np.array([0.0, 1.0]), *(np.full(2, math.nan) for _ in labels))
        return self.gui.add_uplot(
            data=data,
            series=tuple(series),
            title=titles[1] or "Lancez une étude : un point par simulation",
            scales={
                "x": {"time": False, "auto": False, "range": x_range},
                "y": {"auto": False, "range": y_range},
            },
            axes=({"label": titles[0]}, {"size": 60}),
            legend={"live": False},
            padding=(12, 24, 0, 0),
            aspect=1.3,
            order=order,
        )

    # -- files ---------------------------------------------------------------------------
    @staticmethod
    def download(client: viser.ClientHandle, kind: str, job: StudyJob) -> None:
        """The study's rows as CSV (``sandbox sweep --out``'s columns) or PNG."""
        rows = [r for r in job.rows if r is not None]
        stamp = time.strftime("%Y%m%d-%H%M%S")
        name = f"etude_{job.study.target}_{stamp}"
        buffer = io.BytesIO()
        if kind == "csv":
            text = io.StringIO()
            write_csv(text, job.study, rows)
            client.send_file_download(f"{name}.csv", text.getvalue().encode("utf-8"))
            return
        plot(buffer, job.study, rows)
        client.send_file_download(f"{name}.png", buffer.getvalue())
