"""The recorded motion between a recording's frames, and the video's strip of readouts
against time (drawn once by matplotlib, its cursor per frame).

A frame shows the recorded state carried forward to its instant: a recording keeps
frames at the page's rate, and re-simulating from a recorded state is exact.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from PIL import Image

from sandbox.bench.plot import LOCK, comma_formatter, new_figure
from sandbox.physics.units import shown_scale
from sandbox.recording import Recording
from sandbox.written import flat_limits


# -- the recorded motion, between its frames --------------------------------------------------
class Follow:
    """Moves a simulation to any instant of a recording's clock
    (:attr:`~sandbox.recording.Recording.timeline`, from 0 at its first frame, whatever
    the simulated time then): from the recorded frame at or before it, stepped on (a
    recording keeps frames at the page's rate, 10 to 60 a second; the compressor's crank
    turns 50 times a second). Re-simulating from a recorded state is exact (``sandbox
    replay --verify``)."""

    def __init__(self, rec: Recording, sim: Any) -> None:
        self.rec, self.sim = rec, sim
        self.clock = rec.timeline  # built once: a property that sums every frame
        self.index = -1

    def to(self, clock: float) -> float:
        """The physics state at the last whole timestep at or before ``clock`` [s];
        returns the simulated time of that instant (what the display draws, a fraction
        of a timestep past the physics state)."""
        rec, sim = self.rec, self.sim
        i = max(0, int(np.searchsorted(self.clock, clock + 1e-12, side="right")) - 1)
        wanted = clock - float(self.clock[i])  # time past frame i
        if i != self.index or float(sim.data.time) - float(rec.times[i]) > wanted + 1e-12:
            for name, value in rec.values_at(i).items():
                # a recording whose scene is gone replays its MJCF: no parameters
                if name in sim.values and sim.values[name] != value:
                    sim.set_value(name, value)
            sim.restore(rec.states[i])
            self.index = i
        elapsed = float(sim.data.time) - float(rec.times[i])
        steps = math.floor((wanted - elapsed) / sim.timestep + 1e-9)
        if steps > 0:
            sim.step(steps)
        return float(rec.times[i]) + wanted


MAX_STRIP_SAMPLES = 20_000
"""Readout evaluations for the strip at most (every timestep of a short clip)."""


def sampled(
    rec: Recording, sim: Any, names: Sequence[str], start: float, stop: float
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The strip's readouts over [start, stop] of the recording's clock on the
    re-simulated motion, at every
    timestep (thinned to :data:`MAX_STRIP_SAMPLES`): the recorded readouts, taken at the
    page's rate, would alias a crank turning 50 times a second."""
    follow = Follow(rec, sim)
    follow.to(start)
    dt = sim.timestep
    count = int((stop - start) / dt) + 1
    stride = max(1, math.ceil(count / MAX_STRIP_SAMPLES))
    times = start + np.arange(0, count, stride) * dt
    columns: dict[str, list[float]] = {n: [] for n in names}
    for t in times:
        follow.to(float(t))
        values = sim.readouts(list(names))
        for n in names:
            columns[n].append(values[n])
    return times, {n: np.asarray(v, dtype=float) for n, v in columns.items()}


# -- the plot strip -------------------------------------------------------------------------
class Strip:
    """Readouts against time over the clip, drawn once (:meth:`draw`); a cursor per
    frame (:meth:`x_of`)."""

    def __init__(
        self,
        rec: Recording,
        names: Sequence[str],
        labels: dict[str, str],
        span: tuple[float, float],
        width: int,
        height: int,
    ) -> None:
        self.units = dict(zip(rec.names, rec.header.get("units", []), strict=False))
        self.names, self.labels, self.span = tuple(names), labels, span
        self.width, self.height = width, height
        self.image: Any = None
        self.left = self.right = self.top = self.bottom = 0.0

    def draw(self, times: np.ndarray, columns: dict[str, np.ndarray]) -> None:
        """The curves, French axis and legend (decimal comma), once for the clip."""
        with LOCK:
            fig = new_figure(self.width / 100, self.height / 100)
            ax = fig.add_axes((0.08, 0.22, 0.9, 0.56))  # the legend above: a narrow video
            shown = []
            for k, name in enumerate(self.names):
                unit, factor = shown_scale(name, self.units.get(name, ""))
                words = f"{self.labels.get(name) or name}" + (f" [{unit}]" if unit else "")
                values = columns[name] * factor
                shown.append(values[np.isfinite(values)])
                ax.plot(times, values, lw=2, label=words, color=f"C{k}")
            ax.set_xlim(*self.span)
            limits = flat_limits(np.concatenate(shown) if shown else ())
            if limits is not None:
                ax.set_ylim(*limits)
            ax.set_xlabel("Temps de l'enregistrement [s]")  # t is the simulated time
            ax.xaxis.set_major_formatter(comma_formatter())
            ax.yaxis.set_major_formatter(comma_formatter())
            ax.grid(True, alpha=0.3)
            ax.legend(
                loc="lower left",
                bbox_to_anchor=(0.0, 1.0),
                ncol=max(1, len(self.names)),
                fontsize=8,
                frameon=False,
            )
            fig.canvas.draw()
            rgba = np.asarray(fig.canvas.buffer_rgba())  # type: ignore[attr-defined]
            box = ax.get_window_extent()
        self.image = Image.fromarray(rgba[..., :3].copy())
        self.left, self.right = float(box.x0), float(box.x1)
        self.top, self.bottom = self.height - float(box.y1), self.height - float(box.y0)

    def x_of(self, time: float) -> float:
        """Pixel column of ``time`` in the strip."""
        a, b = self.span
        return self.left + (time - a) / (b - a) * (self.right - self.left)
