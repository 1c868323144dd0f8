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

from sandbox.bench.results import Run, SceneResult
from sandbox.physics.model import integrator_words
from sandbox.scenes import get_scene

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


DRIFT_WORDS = {
    "energy theorem": "écart au théorème de l'énergie cinétique",
    "kinetic-energy theorem, integrated": "écart au théorème de l'énergie cinétique intégré",
    "T and |σ_G|": "dérive de T et de |σG|",
}
"""What the drift measures, for the invariants a scene names in words (the others are
symbols: "dérive de T + V")."""


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def decimal(value: float) -> str:
    """``value`` with 3 significant digits and a decimal comma ("0,001", "2,5"), powers of
    ten as a reader writes them ("2×10⁻⁷", never "2e-07")."""
    text = f"{value:.3g}"
    if "e" in text:
        mantissa, power = text.split("e")
        text = f"{mantissa}×10{str(int(power)).translate(_SUPERSCRIPT)}"
        text = text.removeprefix("1×")
    return text.replace(".", ",").replace("-", "−")


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
    # matplotlib on the first chart only: its import takes 0.5-1 s of every start-up
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height))
    FigureCanvasAgg(fig)
    return fig


def draw(res: SceneResult, live: Run | None = None, *, compact: bool = False) -> Figure:
    """Error of the key quantity vs CPU cost: one curve per integrator (small to large
    timestep), the Pareto front as a thick grey band, the benchmark's default as a star,
    and ``live`` (a web session's setting) as a black diamond. Returns the matplotlib
    figure (drawn under :data:`LOCK`; hold it too to save or render the figure).

    ``compact``: the web panel's chart (4.2 x 5 in at 100 dpi, shown about 390 px wide:
    every text at least 12 px there), without the star and the diamond, which the panel
    puts where the settings in force are (:data:`STAR`, :data:`DIAMOND`); their legend entries
    name their roles, the panel's table the settings."""
    with LOCK:
        return _draw(res, live, compact=compact)


def comma_log_formatter(*, label_only_base: bool = False) -> Formatter:
    """Matplotlib's log tick labels (10⁻³, 2×10⁻³) with a decimal comma in any plain
    number it may write, without touching the process locale."""
    # matplotlib on the first chart only: its import takes 0.5-1 s of every start-up
    from matplotlib.ticker import LogFormatterSciNotation

    class Comma(LogFormatterSciNotation):
        def __call__(self, x: float, pos: int | None = None) -> str:
            text = str(super().__call__(x, pos))
            return text.replace(".", "{,}") if text.startswith("$") else text.replace(".", ",")

    return Comma(labelOnlyBase=label_only_base)


def comma_formatter() -> Formatter:
    """Linear tick labels as a French reader writes them: "0,5", "−2", "1,5e+03" stays
    Matplotlib's short form with a comma."""
    # matplotlib on the first chart only: its import takes 0.5-1 s of every start-up
    from matplotlib.ticker import FuncFormatter

    return FuncFormatter(lambda v, _: f"{v:g}".replace(".", ",").replace("-", "−"))


STAR = "réglage par défaut"
DIAMOND = "votre réglage"
"""The compact chart's legend entries for the marks the web panel draws itself."""


def _draw(res: SceneResult, live: Run | None, *, compact: bool = False) -> Figure:
    fig = new_figure(4.2, 5.0) if compact else new_figure(8, 5.4)
    size = 10 if compact else 8  # points: 13 px at 100 dpi, the web chart's
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
            label=integrator_words(name),
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
            label="front de Pareto" if compact else "front de Pareto (les meilleurs compromis)",
            zorder=0,
        )
    star = {"color": "gold", "markeredgecolor": "black", "markersize": 14 if compact else 16}
    default = res.default
    if compact:  # legend entries only: the panel draws the marks where they belong
        ax.plot([], [], "*", label=STAR, **star)  # type: ignore[arg-type]
        ax.plot([], [], "D", color="black", markersize=8, label=DIAMOND)
    elif default is not None and _ok(default):
        ax.plot(
            [default.cpu_per_sim_s],
            [max(default.error, floor)],
            "*",
            label=f"réglage par défaut ({setting_words(default)})",
            **star,  # type: ignore[arg-type]
        )
    if not compact and live is not None and _ok(live) and math.isfinite(live.cpu_per_sim_s):
        ax.plot(
            [live.cpu_per_sim_s],
            [max(live.error, floor)],
            "D",
            color="black",
            markersize=10,
            label=f"réglage actuel ({setting_words(live)})",
        )
    title, key, invariant = words(res)
    diverged = sum(r.diverged for r in res.runs)
    if not compact and any(_ok(r) and not res.admissible(r) for r in res.runs):
        ax.text(
            0.01,
            0.01,
            f"cercle vide : {invariant} au-delà de {decimal(res.drift_tol)} "
            "(réglage non admissible)",
            transform=ax.transAxes,
            fontsize=size,
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("Coût CPU par seconde simulée [s]", fontsize=size)
    ax.set_ylabel(  # the panel's text names the key quantity: a long one would not fit
        "Erreur relative\n(par rapport au cours)"
        if compact
        else f"Erreur relative sur {key} (par rapport au cours)",
        fontsize=size,
    )
    ax.tick_params(labelsize=size)
    if not compact:
        heading = f"Ce que coûte la précision\n{title}"
        if diverged:
            heading += f" ({diverged} calculs divergents non montrés)"
        ax.set_title(heading, fontsize=11)
    ax.axhline(5e-3, color="green", linestyle=":", linewidth=1)
    ax.text(ax.get_xlim()[1], 5e-3, "0,5 % ", color="green", va="bottom", ha="right", fontsize=size)
    for axis in (ax.xaxis, ax.yaxis):  # 10⁻³ needs no comma; a plain 0.5 would
        axis.set_major_formatter(comma_log_formatter())
        axis.set_minor_formatter(comma_log_formatter(label_only_base=True))
    ax.grid(True, which="both", alpha=0.3)
    if compact:  # below the chart, as wide as the figure: every word inside the image
        fig.subplots_adjust(left=0.22, right=0.96, top=0.96, bottom=0.35)
        fig.legend(
            loc="lower center",
            ncol=2,
            fontsize=size,
            frameon=False,
            handlelength=1.4,
            columnspacing=0.8,
            borderaxespad=0.2,
        )
    else:
        ax.legend(fontsize=8)
        fig.tight_layout()
    return fig


def setting_words(run: Run) -> str:
    """A run's setting in words: "Runge-Kutta 4, dt = 1 ms"."""
    return f"{integrator_words(run.integrator)}, dt = {duration(run.timestep)}"
