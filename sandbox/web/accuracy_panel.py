"""Folder "Précision et coût": live cost, error against the course, invariant drift, and
where the current integrator and timestep sit on the scene's work-precision chart."""

from __future__ import annotations

import json
import math
from collections import deque
from collections.abc import Mapping
from typing import Any

import numpy as np

from sandbox.bench import Run, SceneResult, mark_pareto
from sandbox.data import data_dir
from sandbox.physics.simulation import Simulation
from sandbox.web.tables import fmt

CHART_PERIOD = 30.0
"""Seconds between two redraws of the chart while the setting stays the same (a redraw
costs the session loop a few tenths of a second; a new integrator or dt redraws at once)."""

WINDOW = 300
"""Samples kept for the live error and drift (30 s at the panel rate)."""


def load_results(scene: str) -> SceneResult | None:
    """The shipped benchmark of ``scene`` (bench/results.json), if any."""
    path = data_dir("bench") / "results.json"
    try:
        doc = json.loads(path.read_text())
        entry = doc["scenes"][scene]
    except (OSError, ValueError, KeyError):
        return None
    runs = []
    for r in entry["runs"]:
        fields = {
            k: (math.inf if v == "inf" else math.nan if v == "nan" else v) for k, v in r.items()
        }
        runs.append(Run(**fields))
    res = SceneResult(
        scene,
        entry["key"],
        entry["invariant"],
        entry["default"]["integrator"],
        entry["default"]["timestep"],
        runs,
        drift_tol=float(entry.get("drift_tol", math.inf)),
        constraint_tol=float(entry.get("constraint_tol", math.inf)),
    )
    from sandbox.scenes import SCENES

    scene_spec = SCENES.get(scene)
    mark_pareto(res.runs, scene_spec.accuracy if scene_spec else None)
    return res


def chart_image(res: SceneResult, live: Run | None) -> np.ndarray:
    """The work-precision chart as an RGB array, with the live point if known."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image
    import matplotlib.pyplot as plt

    from sandbox.bench_plot import draw

    buffer = io.BytesIO()
    fig = draw(res, live)
    fig.savefig(buffer, format="png", dpi=60)
    plt.close(fig)
    buffer.seek(0)
    image = matplotlib.image.imread(buffer, format="png")
    return (image[..., :3] * 255).astype(np.uint8)


class AccuracyPanel:
    """Live accuracy and cost of one session.

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation.
    """

    def __init__(self, gui: Any, sim: Simulation) -> None:
        scene = sim.scene
        self.acc = scene.accuracy if scene is not None else None
        self.results = load_results(scene.name) if scene is not None else None
        self.samples: deque[dict[str, float]] = deque(maxlen=WINDOW)
        self._key: tuple | None = None
        self._chart_at = -math.inf
        self._charted: tuple | None = None
        with gui.add_folder("Précision et coût"):
            self.text = gui.add_markdown("")
            self.image = None
            if self.results is not None:
                blank = np.full((8, 12, 3), 255, dtype=np.uint8)  # drawn at the first refresh
                self.image = gui.add_image(blank, label="Erreur / coût", format="png")

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
        rtf = 1.0 / cost if cost > 0 else math.nan
        lines = [
            "| | |",
            "|:--|--:|",
            f"| Intégrateur, dt | {sim.integrator}, {fmt(sim.timestep * 1e3)} ms |",
            f"| Coût : s CPU par s simulée | {fmt(cost, digits=3)} |",
            f"| Facteur temps réel possible | ×{rtf:.0f} |"
            if rtf >= 10
            else f"| Facteur temps réel possible | ×{fmt(rtf, digits=2)} |",
        ]
        if self.acc is not None:
            lines += [
                f"| Erreur de {self.acc.key} / cours | {fmt(error, digits=2)} |",
                f"| Dérive de {self.acc.invariant.replace('|', '')} | {fmt(drift, digits=2)} |",
            ]
        text = "\n".join(lines) + (
            "\n\nL'étoile du graphique est le réglage par défaut de la scène, le losange noir "
            "votre réglage actuel (mesuré ici)."
            if self.image is not None
            else ""
        )
        if self.text.content != text:
            self.text.content = text
        if self.image is None or not math.isfinite(cost):
            return
        point = (sim.integrator, sim.timestep, _round(cost), _round(error))
        changed = self._charted is None or point[:2] != self._charted[:2]
        if point != self._charted and (changed or now - self._chart_at >= CHART_PERIOD):
            self._chart_at, self._charted = now, point
            live = Run(
                sim.label, sim.integrator, sim.timestep, 0.0, error=error, cpu_per_sim_s=cost
            )
            self.image.image = chart_image(self.results, live)


def _round(x: float) -> float:
    """Two significant digits (the chart is redrawn only when the point really moved)."""
    if not math.isfinite(x) or x == 0:
        return x
    return float(f"{x:.2g}")
