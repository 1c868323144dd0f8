"""Work-precision charts (PNG) of ``sandbox bench``: error against cost, log-log.

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

LOCK = threading.RLock()
"""Held while a chart is drawn or saved (reentrant: a caller may draw then save)."""

COLORS = {
    "euler": "#d62728",
    "implicit": "#9467bd",
    "implicitfast": "#ff7f0e",
    "rk4": "#1f77b4",
    "discrete": "#2ca02c",
}


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


def draw(res: SceneResult, live: Run | None = None) -> Figure:
    """Error of the key quantity vs CPU cost: one curve per integrator (small to large
    timestep), the Pareto front as a thick grey band, the default as a star, and the
    live setting of a web session as a black diamond. Returns the matplotlib figure
    (drawn under :data:`LOCK`; hold it too to save or render the figure)."""
    with LOCK:
        return _draw(res, live)


def _draw(res: SceneResult, live: Run | None) -> Figure:
    fig = new_figure(8, 5.4)
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
            label="Pareto front",
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
            label=f"default ({default.integrator}, dt = {default.timestep:g} s)",
        )
    if live is not None and _ok(live) and math.isfinite(live.cpu_per_sim_s):
        ax.plot(
            [live.cpu_per_sim_s],
            [max(live.error, floor)],
            "D",
            color="black",
            markersize=10,
            label=f"now ({live.integrator}, dt = {live.timestep:g} s)",
        )
    diverged = sum(r.diverged for r in res.runs)
    if any(_ok(r) and not res.admissible(r) for r in res.runs):
        ax.text(
            0.01,
            0.01,
            f"hollow: {res.invariant} above {res.drift_tol:g} (not admissible)",
            transform=ax.transAxes,
            fontsize=8,
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("cost: CPU seconds per simulated second")
    ax.set_ylabel(f"relative error of {res.key} vs the course")
    title = f"{res.scene}: what accuracy costs"
    if diverged:
        title += f" ({diverged} diverged runs not shown)"
    ax.set_title(title)
    ax.axhline(5e-3, color="green", linestyle=":", linewidth=1)
    ax.text(ax.get_xlim()[0], 5e-3, " 0.5 %", color="green", va="bottom", fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
