"""Folder "Précision et coût": live cost, error against the course, invariant drift, and
where the current integrator and timestep sit on the scene's work-precision chart."""

from __future__ import annotations

import logging
import math
import threading
from collections import deque
from collections.abc import Mapping
from concurrent.futures import Future

import numpy as np
import viser

from sandbox.bench import Run, SceneResult, load_results
from sandbox.bench_plot import drift_words
from sandbox.physics.simulation import Simulation
from sandbox.scenes.base import as_scene
from sandbox.web import charts
from sandbox.web.tables import cell, fmt, integrator_words
from sandbox.web.text import html_text

log = logging.getLogger(__name__)

CHART_PERIOD = 30.0
"""Seconds between two redraws of the chart while the setting stays the same (a redraw
costs the session loop a few tenths of a second; a new integrator or dt redraws at once)."""

WINDOW = 300
"""Samples kept for the live error and drift (30 s at the panel rate)."""


_BASES: dict[tuple[str, int], tuple[np.ndarray, tuple[float, ...]]] = {}
_BASES_LOCK = threading.Lock()
CHART_DPI = 100
"""Pixels per inch of the web chart (5 x 4.4 in: 500 x 440 px, shown about 390 px wide)."""


def chart_base(res: SceneResult) -> tuple[np.ndarray, tuple[float, ...]]:
    """The scene's chart without the live point, drawn once per process, and the map
    from (log10 cost, log10 error) to pixels: ``(ax, bx, ay, by, x0, x1, y0, y1)``."""
    with charts.LOCK, _BASES_LOCK:  # this order only: charts.submit holds LOCK first
        key = (res.scene, len(res.runs))  # every session loads its own copy
        cached = _BASES.get(key)
        if cached is not None:
            return cached
        from sandbox.bench_plot import draw

        fig = draw(res, None, compact=True)  # a Figure on its own Agg canvas: no pyplot
        fig.set_dpi(CHART_DPI)
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        canvas = fig.canvas
        assert isinstance(canvas, FigureCanvasAgg)
        canvas.draw()
        rgba = np.asarray(canvas.buffer_rgba())
        image = np.ascontiguousarray(rgba[..., :3])
        axes = fig.axes[0]
        height = fig.bbox.height
        (px0, py0), (px1, py1) = axes.transData.transform([(1.0, 1.0), (10.0, 10.0)])
        box = axes.get_window_extent()
        mapping = (
            float(px0),
            float(px1 - px0),
            float(height - py0),
            float(py0 - py1),
            float(box.x0),
            float(box.x1),
            float(height - box.y1),
            float(height - box.y0),
        )
        _BASES[key] = (image, mapping)
        return image, mapping


def chart_image(res: SceneResult, live: Run | None) -> np.ndarray:
    """The work-precision chart as an RGB array, with the live point (a black diamond)
    when its cost and error are known: the base is drawn once, the point in numpy."""
    base, (ax, bx, ay, by, x0, x1, y0, y1) = chart_base(res)
    image = base.copy()
    if live is None or not (live.cpu_per_sim_s > 0 and live.error > 0):
        return image
    if not (math.isfinite(live.cpu_per_sim_s) and math.isfinite(live.error)):
        return image
    px = ax + bx * math.log10(live.cpu_per_sim_s)
    py = ay + by * math.log10(max(live.error, 1e-16))
    px, py = min(max(px, x0), x1), min(max(py, y0), y1)  # off the chart: on its edge
    size = 7
    rows, cols = np.ogrid[: image.shape[0], : image.shape[1]]
    diamond = np.abs(rows - py) + np.abs(cols - px) <= size
    image[diamond] = 0
    return image


class AccuracyPanel:
    """Live accuracy and cost of one session.

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation.
    """

    def __init__(self, gui: viser.GuiApi, sim: Simulation) -> None:
        scene = as_scene(sim.scene)
        self.acc = scene.accuracy if scene is not None else None
        self.results = load_results(scene.name) if scene is not None else None
        self.samples: deque[dict[str, float]] = deque(maxlen=WINDOW)
        self._key: tuple | None = None
        self._chart_at = -math.inf
        self._charted: tuple | None = None
        self._drawing: Future[np.ndarray] | None = None
        self.key_words = self.invariant_words = ""
        if self.acc is not None:
            labels = {i.name: i.label for i in sim.readout_infos()}
            self.key_words = labels.get(self.acc.key) or self.acc.key
            self.invariant_words = drift_words(self.acc.invariant)
        with gui.add_folder("Précision et coût") as self.folder:
            self.text = gui.add_markdown("")
            self.image = None
            if self.results is not None:
                blank = np.full((8, 12, 3), 255, dtype=np.uint8)  # drawn at the first refresh
                self.image = gui.add_image(blank, label="Erreur relative et coût CPU", format="png")

    def names(self) -> tuple[str, ...]:
        """Readouts the live error and drift need (sampled whether shown or not)."""
        return ("time", *self.acc.readouts) if self.acc is not None else ()

    def _settings(self, sim: Simulation, generation: int) -> tuple:
        return (sim.integrator, sim.timestep, tuple(sorted(sim.values.items())), generation)

    def sample(self, sim: Simulation, values: Mapping[str, float], generation: int) -> None:
        """Add the readouts shown now; a new setting starts a new series."""
        key = self._settings(sim, generation)
        if key != self._key:
            self._key = key
            self.samples.clear()
        if self.acc is not None:
            self.samples.append({n: values[n] for n in ("time", *self.acc.readouts) if n in values})

    def measures(self, sim: Simulation) -> tuple[float, float]:
        """Error of the key quantity and drift of the invariant over the samples kept."""
        if self.acc is None or len(self.samples) < 3:
            return math.nan, math.nan
        names = self.samples[0].keys()
        series = {n: np.array([s[n] for s in self.samples]) for n in names}
        try:
            return float(self.acc.error(series, sim.values)), float(
                self.acc.drift(series, sim.values)
            )
        except (KeyError, ValueError, ZeroDivisionError, FloatingPointError):
            return math.nan, math.nan

    def refresh(self, sim: Simulation, cost: float, now: float) -> None:
        """Rewrite the table; redraw the chart now and then."""
        error, drift = self.measures(sim)
        text = accuracy_markdown(
            sim.integrator,
            sim.timestep,
            cost,
            error=error if self.acc is not None else None,
            drift=drift if self.acc is not None else None,
            key=self.key_words,
            invariant=self.invariant_words,
            chart=self.image is not None,
        )
        if self.text.content != text:
            self.text.content = text
        if self.image is None:
            return
        if self._drawing is not None and self._drawing.done():
            drawing, self._drawing = self._drawing, None
            try:
                self.image.image = drawing.result()
            except Exception:  # a chart is a bonus: the table stays
                log.exception("work-precision chart failed")
        if self._drawing is not None or not math.isfinite(cost) or self.results is None:
            return
        point = (sim.integrator, sim.timestep, _round(cost), _round(error))
        changed = self._charted is None or point[:2] != self._charted[:2]
        if point != self._charted and (changed or now - self._chart_at >= CHART_PERIOD):
            self._chart_at, self._charted = now, point
            live = Run(
                sim.label, sim.integrator, sim.timestep, 0.0, error=error, cpu_per_sim_s=cost
            )
            # Drawn by the chart thread: the frames of every session go on meanwhile.
            self._drawing = charts.submit(chart_image, self.results, live)


def accuracy_markdown(
    integrator: str,
    timestep: float,
    cost: float,
    *,
    error: float | None = None,
    drift: float | None = None,
    key: str = "",
    invariant: str = "",
    chart: bool = False,
) -> str:
    """The live table of "Précision et coût", in French with decimal commas.

    Args:
        integrator: Contract name of the integrator (shown with its words).
        timestep: Timestep [s].
        cost: CPU seconds per simulated second.
        error: Relative error of the key quantity against the course (None: no course).
        drift: Relative drift of the invariant (None: no course).
        key: The key quantity in words (its label).
        invariant: What the drift measures (:func:`~sandbox.bench_plot.drift_words`).
        chart: Add the sentence that explains the chart's marks.
    """
    rtf = 1.0 / cost if cost > 0 else math.nan
    factor = fmt(round(rtf)) if rtf >= 10 else fmt(rtf, digits=2)
    lines = [
        "| | |",
        "|:--|--:|",
        f"| Intégrateur | {html_text(integrator_words(integrator))} |",
        f"| Pas de temps dt | {fmt(timestep * 1e3)} ms |",
        f"| Coût CPU par seconde simulée | {fmt(cost, digits=3)} s |",
        f"| Facteur temps réel possible | ×{factor} |",
    ]
    if error is not None:
        lines.append(f"| Erreur relative sur {cell(key)} (cours) | {fmt(error, digits=2)} |")
    if drift is not None:
        what = cell(invariant[:1].upper() + invariant[1:])
        lines.append(f"| {what} (relatif) | {fmt(drift, digits=2)} |")
    text = "\n".join(lines)
    if chart:
        text += (
            "\n\nSur le graphique, l'étoile marque le réglage par défaut de la scène et le "
            "losange noir votre réglage actuel (mesuré ici)."
        )
    return text


def _round(x: float) -> float:
    """Two significant digits (the chart is redrawn only when the point really moved)."""
    if not math.isfinite(x) or x == 0:
        return x
    return float(f"{x:.2g}")
