"""Work-precision charts (PNG) of ``sandbox bench``: error against cost, log-log, in
French (they are shown in the web page and on the teachers' slides): words, the scene's
title, the key quantity's label and numbers with a decimal comma.

Charts are matplotlib :class:`~matplotlib.figure.Figure` objects on their own Agg
canvas (no pyplot: no global figure list, no backend switch), and every drawing holds
:data:`LOCK`: matplotlib's text layout and mathtext parser keep module-level state that
two threads drawing at once corrupt (a web server draws from several sessions).
"""

from __future__ import annotations

import math
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from sandbox.bench import Run, SceneResult

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from matplotlib.ticker import Formatter

LOCK = threading.RLock()
"""Held while a chart is drawn or saved (reentrant: a caller may draw then save)."""

COLORS = {
    "euler": "#d62728",
    "implicit": "#9467bd",
    "implicitfast": "#ff7f0e",
    "rk4": "#1f77b4",
    "discrete": "#2ca02c",
}


DRIFT_WORDS = {"energy theorem": "écart au théorème de l'énergie cinétique"}
"""What the drift measures, for the invariants a scene names in words (the others are
symbols: "dérive de T + V")."""


def decimal(value: float) -> str:
    """``value`` with 3 significant digits and a decimal comma ("0,001", "2,5")."""
    return f"{value:.3g}".replace(".", ",").replace("-", "−")


def duration(seconds: float) -> str:
    """A timestep as a reader writes it: "1 ms", "30 µs", "0,01 s"."""
    for factor, unit in ((1.0, "s"), (1e-3, "ms"), (1e-6, "µs")):
        if seconds >= factor or unit == "µs":
            return f"{decimal(seconds / factor)} {unit}"
    return f"{decimal(seconds)} s"


def words(res: SceneResult) -> tuple[str, str, str]:
    """(title, key quantity, invariant) of a scene's chart in French: the scene's title
    and the key readout's label from the registry, the invariant's symbol."""
    title, key = res.scene, res.key
    try:
        from sandbox.scenes import get_scene

        scene = get_scene(res.scene)
    except Exception:  # a result file of a scene this version does not know
        scene = None
    if scene is not None:
        title = scene.title
        for r in scene.readouts:
            if r.name == res.key and r.label:
                key = r.label[0].lower() + r.label[1:] if r.label[1:2].islower() else r.label
    return title, key, drift_words(res.invariant)


def drift_words(invariant: str) -> str:
    """What the drift of a scene's invariant measures, for a French reader: "dérive de "
    and its symbols ("T + V", "|σG|", without the English words in parentheses), or
    French words ("écart au théorème de l'énergie cinétique")."""
    head = invariant.split(" (")[0].strip()
    return DRIFT_WORDS.get(head, f"dérive de {head}")


def _ok(r: Run) -> bool:
    return not r.diverged and math.isfinite(r.error) and r.error > 0


def plot_scene(res: SceneResult, path: Path) -> Path:
    """Write the chart of :func:`draw` as a PNG."""
    with LOCK:
        fig = draw(res)
        fig.savefig(path, dpi=150)
    return path


def new_figure(width: float, height: float) -> Figure:
    """A figure of ``width`` x ``height`` inches on its own Agg canvas (no pyplot)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height))
    FigureCanvasAgg(fig)
    return fig


def draw(res: SceneResult, live: Run | None = None, *, compact: bool = False) -> Figure:
    """Error of the key quantity vs CPU cost: one curve per integrator (small to large
    timestep), the Pareto front as a thick grey band, the default as a star, and the
    live setting of a web session as a black diamond. Returns the matplotlib figure
    (drawn under :data:`LOCK`; hold it too to save or render the figure).

    ``compact``: a smaller figure (5 x 4.4 in) whose words stay readable once the web
    page shrinks it to its panel: no scene title (the panel says it), the legend below."""
    with LOCK:
        return _draw(res, live, compact=compact)


def comma_log_formatter(*, label_only_base: bool = False) -> Formatter:
    """Matplotlib's log tick labels (10⁻³, 2×10⁻³) with a decimal comma in any plain
    number it may write, without touching the process locale."""
    from matplotlib.ticker import LogFormatterSciNotation

    class Comma(LogFormatterSciNotation):
        def __call__(self, x: float, pos: int | None = None) -> str:
            text = str(super().__call__(x, pos))
            return text.replace(".", "{,}") if text.startswith("$") else text.replace(".", ",")

    return Comma(labelOnlyBase=label_only_base)


def _draw(res: SceneResult, live: Run | None, *, compact: bool = False) -> Figure:
    fig = new_figure(5.0, 4.4) if compact else new_figure(8, 5.4)
    ax = fig.add_subplot()
    floor = 1e-16
    by_integrator: dict[str, list[Run]] = {}
    for r in res.runs:
        by_integrator.setdefault(r.integrator, []).append(r)
    for name, runs in by_integrator.items():
        ok = sorted((r for r in runs if _ok(r)), key=lambda r: r.timestep)
        if not ok:
            continue
        color = COLORS.get(name, "black")
        ax.plot(
            [r.cpu_per_sim_s for r in ok],
            [max(r.error, floor) for r in ok],
            "-",
            color=color,
            label=name,
            linewidth=1.4,
        )
        for r in ok:
            good = res.admissible(r)
            ax.plot(
                [r.cpu_per_sim_s],
                [max(r.error, floor)],
                "o",
                color=color,
                markerfacecolor=color if good else "white",
                markersize=5,
            )
    front = sorted((r for r in res.runs if r.pareto and _ok(r)), key=lambda r: r.cpu_per_sim_s)
    if front:
        ax.plot(
            [r.cpu_per_sim_s for r in front],
            [max(r.error, floor) for r in front],
            "-",
            color="grey",
            linewidth=6,
            alpha=0.3,
            label="front de Pareto (les meilleurs compromis)",
            zorder=0,
        )
    default = res.default
    if default is not None and _ok(default):
        ax.plot(
            [default.cpu_per_sim_s],
            [max(default.error, floor)],
            "*",
            color="gold",
            markeredgecolor="black",
            markersize=16,
            label=f"réglage par défaut ({default.integrator}, dt = {duration(default.timestep)})",
        )
    if live is not None and _ok(live) and math.isfinite(live.cpu_per_sim_s):
        ax.plot(
            [live.cpu_per_sim_s],
            [max(live.error, floor)],
            "D",
            color="black",
            markersize=10,
            label=f"réglage actuel ({live.integrator}, dt = {duration(live.timestep)})",
        )
    title, key, invariant = words(res)
    diverged = sum(r.diverged for r in res.runs)
    if any(_ok(r) and not res.admissible(r) for r in res.runs):
        ax.text(
            0.01,
            0.01,
            f"cercle vide : {invariant} au-delà de {decimal(res.drift_tol)} "
            "(réglage non admissible)",
            transform=ax.transAxes,
            fontsize=8,
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("Coût CPU par seconde simulée [s]")
    ax.set_ylabel(
        f"Erreur relative sur {key}\n(par rapport au cours)"
        if compact
        else f"Erreur relative sur {key} (par rapport au cours)"
    )
    heading = "Ce que coûte la précision" if compact else f"Ce que coûte la précision\n{title}"
    if diverged:
        heading += f" ({diverged} calculs divergents non montrés)"
    ax.set_title(heading, fontsize=11)
    ax.axhline(5e-3, color="green", linestyle=":", linewidth=1)
    ax.text(ax.get_xlim()[0], 5e-3, " 0,5 %", color="green", va="bottom", fontsize=8)
    for axis in (ax.xaxis, ax.yaxis):  # 10⁻³ needs no comma; a plain 0.5 would
        axis.set_major_formatter(comma_log_formatter())
        axis.set_minor_formatter(comma_log_formatter(label_only_base=True))
    ax.grid(True, which="both", alpha=0.3)
    if compact:
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2)
    else:
        ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
