"""Live plots: a few readouts against time, kept in a deque and pushed to a uPlot chart."""

from __future__ import annotations

import copy
import math
from collections import deque
from collections.abc import Callable, Mapping, Sequence

import numpy as np
import viser
from numpy.typing import ArrayLike
from viser import uplot

from sandbox.physics.page import Arrow, Components
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import Scene
from sandbox.physics.units import display_unit, shown_scale

PALETTE = ((40, 110, 230), (230, 80, 40), (40, 160, 80), (150, 60, 200), (200, 160, 20))
"""Line colours when a readout has no arrow colour of its own."""


def dots(label: str, color: str, size: float = 4.0) -> uplot.Series:
    """A series drawn as dots only (samples whose order along X means nothing)."""
    return {
        "label": label,
        "stroke": color,
        "width": 0,
        "points": {"show": True, "size": size, "stroke": color, "fill": color},
    }


def dashed(label: str, color: str, width: float, dash: tuple[float, float]) -> uplot.Series:
    """A dashed line without points (the course's curve, a cursor's line)."""
    return {
        "label": label,
        "stroke": color,
        "width": width,
        "dash": dash,
        "points": {"show": False},
    }


def nice_ceil(x: float) -> float:
    """Smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k that is >= ``x`` (``x`` > 0)."""
    if not math.isfinite(x) or x <= 0:
        return 1.0
    k = math.floor(math.log10(x))
    for m in (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0):
        if m * 10.0**k >= x * (1 - 1e-12):
            return m * 10.0**k
    return 10.0 ** (k + 1)


def nice_range(values: ArrayLike, headroom: float = 0.1) -> tuple[float, float]:
    """A vertical range holding 0 and every finite value, with ``headroom`` of the span
    above and below, its bounds rounded up to "nice" numbers (:func:`nice_ceil`)."""
    found = np.asarray(values, dtype=float).ravel()
    found = found[np.isfinite(found)]
    lo = min(0.0, float(found.min())) if found.size else 0.0
    hi = max(0.0, float(found.max())) if found.size else 1.0
    pad = headroom * (hi - lo) or 1.0
    return (-nice_ceil(pad - lo) if lo < 0 else 0.0, nice_ceil(hi + pad))


def replace_chart(
    folder: viser.GuiFolderHandle,
    chart: viser.GuiUplotHandle,
    build: Callable[[float], viser.GuiUplotHandle],
) -> viser.GuiUplotHandle:
    """A new chart in ``chart``'s place (same folder, same order), built by ``build(order)``.

    Used when a chart's scales or series change: viser rebuilds a uPlot whose ``scales``
    change anyway, and a fresh one starts from its own ranges."""
    order = chart.order
    chart.remove()
    with folder:
        return build(order)


SOFT_ZERO = {"pad": 0.0, "soft": 0.0, "mode": 1}
"""uPlot range bound: no padding of its own (the range series carries the headroom), and
0 kept inside the range (soft limit, mode 1)."""

SCALES: dict[str, uplot.Scale] = {
    "x": {"time": False},
    "y": {"auto": True, "range": {"min": SOFT_ZERO, "max": SOFT_ZERO}},
}
"""Scales of every live plot, sent once at creation: x follows the samples, y is ranged
by the browser from the samples and the range series (see :meth:`Plot.arrays`)."""

RANGE_SERIES: uplot.Series = {
    "label": "\u2009",  # a thin space: uPlot writes "Value" for an empty label
    "stroke": "rgba(0,0,0,0)",
    "width": 0,
    "points": {"show": False},
}
"""An invisible last series holding :meth:`Plot.y_range` at its ends: uPlot's own range
pads by a tenth of the spread, so a nearly constant signal sat on the chart's top edge."""


class Plot:
    """One chart of readouts sharing a unit, against simulated time.

    Args:
        names: Readout names on this chart.
        unit: Their common unit (contract form; the axis shows its display form).
        colors: RGB colour of each series.
        labels: What the legend shows for each series (French words; default the names).
        zero: The scene's round-off in ``unit``: smaller samples are drawn as 0 (a range
            of 10⁻⁸ around 0 would fill the chart with noise).
        shown: The unit the chart shows and the factor from ``unit`` to it
            (:func:`~sandbox.physics.units.shown_scale`: ω in tr/min); default
            ``unit`` as the page writes it.
        window: Time span kept [s].
        maxlen: Most points kept per series.
    """

    def __init__(
        self,
        names: Sequence[str],
        unit: str,
        colors: Sequence[tuple[int, int, int]],
        *,
        window: float = 10.0,
        maxlen: int = 1000,
        labels: Sequence[str] | None = None,
        zero: float = 0.0,
        shown: tuple[str, float] | None = None,
    ) -> None:
        self.names = tuple(names)
        self.zero = zero
        self.labels = tuple(labels) if labels is not None else self.names
        self.unit = unit
        self.shown_unit, self.scale = shown if shown is not None else (display_unit(unit), 1.0)
        self.colors = tuple(colors)
        self.window = window
        self.t: deque[float] = deque(maxlen=maxlen)
        self.y: list[deque[float]] = [deque(maxlen=maxlen) for _ in self.names]
        self.handle: viser.GuiUplotHandle | None = None

    def append(self, values: Mapping[str, float]) -> None:
        """Add one sample (needs ``time`` and every name); time going back clears the plot,
        and a sample at the same time (paused) replaces the last one."""
        t = float(values["time"])
        if self.t and t < self.t[-1]:
            self.clear()
        same = bool(self.t) and t == self.t[-1]
        if not same:
            self.t.append(t)
        for series, name in zip(self.y, self.names, strict=True):
            v = float(values.get(name, math.nan))
            shown = math.nan if not math.isfinite(v) else 0.0 if abs(v) <= self.zero else v
            shown *= self.scale
            if same:
                series[-1] = shown
            else:
                series.append(shown)
        while self.t and self.t[0] < t - self.window:
            self.t.popleft()
            for series in self.y:
                series.popleft()

    def clear(self) -> None:
        """Forget every sample."""
        self.t.clear()
        for series in self.y:
            series.clear()

    def arrays(self) -> tuple[np.ndarray, ...]:
        """(t, y_1, ..., y_n, range) as float arrays, at least two points long: the range
        series is NaN (not drawn) but for :meth:`y_range` at its two ends."""
        if not self.t:
            t = np.array([0.0, 1e-3])
            columns = [np.zeros(2) for _ in self.names]
        elif len(self.t) == 1:
            t = np.array([self.t[0], self.t[0] + 1e-3])
            columns = [np.array([s[0], s[0]]) for s in self.y]
        else:
            t = np.array(self.t)
            columns = [np.array(s) for s in self.y]
        bounds = np.full(len(t), np.nan)
        bounds[0], bounds[-1] = self.y_range()
        return (t, *columns, bounds)

    def series(self) -> tuple[uplot.Series, ...]:
        """uPlot series options: time first, then one coloured line per readout."""
        out: list[uplot.Series] = [uplot.Series(label="t [s]")]
        unit = f" [{self.shown_unit}]" if self.shown_unit else ""
        for label, (r, g, b) in zip(self.labels, self.colors, strict=True):
            out.append(uplot.Series(label=f"{label}{unit}", stroke=f"rgb({r},{g},{b})", width=2))
        out.append(copy.deepcopy(RANGE_SERIES))
        return tuple(out)

    def attach(self, gui: viser.GuiApi, *, title: str, x_label: str = "t [s]") -> None:
        """Create the chart in ``gui`` (a viser ``GuiApi``); its options never change after."""
        self.handle = gui.add_uplot(
            data=self.arrays(),
            series=self.series(),
            title=title,
            scales=self.scales(),
            axes=(uplot.Axis(label=x_label), uplot.Axis(label=self.shown_unit, size=60)),
            legend={"live": False},  # names only: no "--" (English-looking) value cells
            padding=(12, 24, 0, 0),  # room for the top tick's label
            aspect=1.6,
        )

    def y_range(self) -> tuple[float, float]:
        """Vertical range including 0 and every sample, with 10 % headroom, rounded to
        "nice" bounds (the chart's range, sent as the range series)."""
        return nice_range(
            np.concatenate([np.asarray(s, dtype=float) for s in self.y] or [np.zeros(1)])
        )

    def scales(self) -> dict[str, uplot.Scale]:
        """uPlot scales, the same for the chart's whole life (:data:`SCALES`)."""
        return copy.deepcopy(SCALES)

    def push(self) -> None:
        """Send the current samples (only the data: the browser ranges the y axis itself).

        Never send ``scales`` again: any new ``scales`` makes viser's uPlot component
        destroy and rebuild the chart, and the rebuilt chart keeps an x window computed
        from the destroyed one (blank at first, then one second of data lagging ~8 s
        behind, for good: issue 14).
        """
        if self.handle is not None:
            self.handle.data = self.arrays()


def group_by_unit(
    names: Sequence[str],
    units: Mapping[str, str],
    colors: Mapping[str, tuple[int, int, int]],
    labels: Mapping[str, str] | None = None,
    zero: Mapping[str, float] | None = None,
) -> list[Plot]:
    """One :class:`Plot` per unit the page shows (ω in tr/min apart from other rad/s), in
    the order the names first appear; ``units``: contract units; ``labels``: the French
    words of each name (default the name); ``zero``: round-off by contract unit."""
    labels, zero = labels or {}, zero or {}
    groups: dict[tuple[str, tuple[str, float]], list[str]] = {}
    for name in names:
        unit = units.get(name, "")
        groups.setdefault((unit, shown_scale(name, unit)), []).append(name)
    plots = []
    k = 0
    for (unit, shown_as), members in groups.items():
        cols = []
        for name in members:
            cols.append(colors.get(name, PALETTE[k % len(PALETTE)]))
            k += 1
        shown = [labels.get(n) or n for n in members]
        plots.append(
            Plot(members, unit, cols, labels=shown, zero=zero.get(unit, 0.0), shown=shown_as)
        )
    return plots


AXIS_WORDS = {"B0": ("x₀", "y₀", "z₀"), "B1": ("x₁", "y₁", "z₁")}
DASHES: tuple[tuple[float, ...], ...] = ((), (8.0, 4.0), (2.0, 3.0))
"""Solid, dashed, dotted: the components of one arrow share its colour."""


class ComponentPlot(Plot):
    """Components of arrows in a basis against time (one colour per arrow, one dash per
    component), fed with the arrows' vectors rather than readouts.

    Args:
        spec: What to draw.
        arrows: The scene's arrows named in ``spec`` (label, colour, unit).
        zero: The scene's round-off in their unit.
    """

    def __init__(self, spec: Components, arrows: Sequence[Arrow], *, zero: float = 0.0) -> None:
        self.spec = spec
        self.arrows = tuple(arrows)
        names, labels, colors = [], [], []
        for arrow in self.arrows:
            for axis in spec.axes:
                names.append(f"{arrow.name}.{axis}")
                labels.append(f"{arrow.label}, {AXIS_WORDS[spec.basis][axis]}")
                colors.append(arrow.color)
        unit = self.arrows[0].unit if self.arrows else ""
        super().__init__(names, unit, colors, labels=labels, zero=zero)

    def series(self) -> tuple[uplot.Series, ...]:
        out = list(super().series())
        for k, s in enumerate(out[1 : 1 + len(self.names)]):
            dash = DASHES[k % len(self.spec.axes) % len(DASHES)]
            if dash:
                s["dash"] = dash
        return tuple(out)

    def title(self) -> str:
        """French title: the arrows' labels, the basis and the unit."""
        unit = f" [{self.shown_unit}]" if self.shown_unit else ""
        arrows = " et ".join(a.label for a in self.arrows)
        return f"{arrows} : composantes dans {self.spec.words}{unit}"

    def values(self, snapshot: Snapshot, basis: np.ndarray) -> dict[str, float]:
        """The components at ``snapshot``: ``basis`` is 3x3, columns = its unit vectors
        in world."""
        vectors = {arrow.name: arrow.fn(snapshot)[1] for arrow in self.arrows}
        return self.components(float(snapshot.data.time), vectors, basis)

    def components(
        self, time: float, vectors: Mapping[str, ArrayLike], basis: np.ndarray
    ) -> dict[str, float]:
        """The components of the arrows' world ``vectors`` (by arrow name) at ``time`` [s]
        in ``basis`` (3x3, columns = its unit vectors in world): a frame's picture gives
        them, already evaluated."""
        out: dict[str, float] = {"time": float(time)}
        for arrow in self.arrows:
            local = np.asarray(basis, dtype=float).T @ np.asarray(vectors[arrow.name], dtype=float)
            for axis in self.spec.axes:
                out[f"{arrow.name}.{axis}"] = float(local[axis])
        return out


def component_plot(scene: Scene | None) -> ComponentPlot | None:
    """The scene's :class:`ComponentPlot` (None when it has none, or lacks its arrows or
    the body frame its basis needs)."""
    spec = scene.page.components if scene is not None else None
    if scene is None or spec is None or (spec.basis == "B1" and not scene.page.body_frame):
        return None
    by_name = {a.name: a for a in scene.page.arrows}
    arrows = [by_name[n] for n in spec.arrows if n in by_name]
    if not arrows:
        return None
    return ComponentPlot(spec, arrows, zero=scene.zero_for(arrows[0].unit))
