"""The data of a "Tracé X–Y": readouts against another readout (or time), as a class
reads them: the course's value dashed beside each, a cursor that reads X, Y and the slope,
and the same curves as a CSV file (contract names and units) or a PNG for a slide
(French, decimal comma).

No viser here (see :mod:`sandbox.web.panels.xy`): samples come from the session's
:class:`~sandbox.web.loop.probe.Probe`; this module keeps, folds, sorts and reads them.
"""

from __future__ import annotations

import csv
import io
import math
import threading
from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sandbox.bench.plot import LOCK, comma_formatter, new_figure
from sandbox.physics.presets import TIME
from sandbox.physics.units import TURN_ANGLES, shown_scale
from sandbox.runner import csv_cell
from sandbox.web.client.text import number, with_unit
from sandbox.written import Written, flat_limits, time_words, written

WINDOW = 10.0
"""Seconds of simulated time kept when X is time."""

FOLD_SECONDS = 2.0
"""Seconds of simulated time kept when X is a folded angle (many revolutions overlaid in
a steady motion; a change of parameters fades out within this time), and always the last
revolution however slow."""

MAX_KEPT = 2000
"""Samples kept (the oldest go first)."""

MAX_SENT = 720
"""Points sent to a browser per series (evenly thinned past that): a phone on the class's
Wi-Fi receives the chart several times a second."""

SLOPE_SPAN = 0.03
"""Half-width of the neighbourhood the cursor's slope is fitted on, as a fraction of the
X range (a least-squares line through the samples there)."""


@dataclass(frozen=True)
class Axis:
    """A readout as the chart shows it.

    Attributes:
        name: Readout name (a contract: CSV column), or :data:`TIME`.
        words: French words (the readout's label).
        unit: Contract unit (files).
        shown: Unit the page shows, and ``scale`` the factor to it (ω in tr/min).
    """

    name: str
    words: str
    unit: str
    shown: str
    scale: float

    @classmethod
    def of(cls, name: str, words: str, unit: str) -> Axis:
        """The axis of readout ``name`` in the unit the page shows it in."""
        shown, scale = shown_scale(name, unit)
        return cls(name, words, unit, shown, scale)

    @property
    def title(self) -> str:
        """ "Effort du palier A [N]"."""
        return f"{self.words} [{self.shown}]" if self.shown else self.words

    @property
    def folds(self) -> bool:
        """True for a turn counter (the crank angle): drawn over one revolution."""
        return self.name in TURN_ANGLES and self.unit == "rad"


TIME_AXIS = Axis(TIME, "Temps t", "s", "s", 1.0)


def finite_ends(column: np.ndarray) -> np.ndarray:
    """``column`` with finite first and last values (the nearest finite ones; 0 when none
    is): a series that starts or ends with NaN leaves viser's uPlot chart without a y
    axis for good (NaN inside is skipped, and the line joins across it)."""
    ok = np.flatnonzero(np.isfinite(column))
    if len(ok) == len(column):
        return column
    out = column.copy()
    out[0] = column[ok[0]] if len(ok) else 0.0
    out[-1] = column[ok[-1]] if len(ok) else 0.0
    return out


def slope_unit(y: str, x: str) -> str:
    """The unit of dY/dX ("N/(tr/min)", "N/°", "N/s"); "" when both are bare."""
    if not x:
        return y
    bottom = f"({x})" if "/" in x or "·" in x else x
    return f"{y or '1'}/{bottom}"


class XYData:
    """Samples of ``ys`` (and their course values ``refs``) against ``x``.

    Args:
        x: Horizontal axis (a readout or :data:`TIME_AXIS`).
        ys: Vertical axes (one to three readouts).
        refs: Readout holding the course's value of each Y that has one, by Y name.
    """

    def __init__(self, x: Axis, ys: Sequence[Axis], refs: Mapping[str, str]) -> None:
        self.x = x
        self.ys = tuple(ys)
        self.refs = {y.name: refs[y.name] for y in self.ys if y.name in refs}
        self._t: deque[float] = deque(maxlen=MAX_KEPT)
        self._x: deque[float] = deque(maxlen=MAX_KEPT)  # contract unit (unwrapped turns)
        self._y: dict[str, deque[float]] = {
            n: deque(maxlen=MAX_KEPT) for n in (*(y.name for y in self.ys), *self.refs.values())
        }
        self._lock = threading.Lock()  # downloads read from viser's thread

    @property
    def names(self) -> tuple[str, ...]:
        """Readouts to sample (X, Ys, their course values)."""
        x = () if self.x.name == TIME else (self.x.name,)
        return tuple(dict.fromkeys((*x, *self._y)))

    def __len__(self) -> int:
        return len(self._t)

    def clear(self) -> None:
        """Forget every sample."""
        with self._lock:
            self._t.clear()
            self._x.clear()
            for series in self._y.values():
                series.clear()

    def add(self, samples: Iterable[tuple[float, Mapping[str, float]]]) -> None:
        """Keep new samples; time going back (a reset) starts the plot again; what falls
        out of view goes (older than :data:`WINDOW` against time, more than one
        revolution behind for a folded angle)."""
        with self._lock:
            for t, values in samples:
                if self._t and t < self._t[-1]:
                    self._t.clear()
                    self._x.clear()
                    for series in self._y.values():
                        series.clear()
                self._t.append(t)
                self._x.append(
                    t if self.x.name == TIME else float(values.get(self.x.name, math.nan))
                )
                for name, series in self._y.items():
                    series.append(float(values.get(name, math.nan)))
            self._trim()

    def _trim(self) -> None:
        if not self._t:
            return
        if self.x.name == TIME:
            keep = lambda k: self._t[k] >= self._t[-1] - WINDOW  # noqa: E731
        elif self.x.folds:
            last, now = self._x[-1], self._t[-1]
            keep = lambda k: (  # noqa: E731
                now - self._t[k] <= FOLD_SECONDS or abs(self._x[k] - last) < 2 * math.pi
            )
        else:
            return
        while self._t and not keep(0):
            self._t.popleft()
            self._x.popleft()
            for series in self._y.values():
                series.popleft()

    # -- what the chart shows ------------------------------------------------------------
    def shown(self) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """X in the page's unit (an angle folded on [0, 360°)), sorted, and each Y and
        course value in the page's unit, in the same order."""
        with self._lock:
            x = np.asarray(self._x, dtype=float) * self.x.scale
            ys = {n: np.asarray(s, dtype=float) for n, s in self._y.items()}
        if self.x.folds:
            x = np.mod(x, 360.0)
        order = np.argsort(x, kind="stable")
        scale = {y.name: y.scale for y in self.ys}
        for y in self.ys:
            if y.name in self.refs:
                scale[self.refs[y.name]] = y.scale
        return x[order], {n: v[order] * scale.get(n, 1.0) for n, v in ys.items()}

    def arrays(self, cursor: float | None = None) -> tuple[np.ndarray, ...]:
        """The chart's data (see :meth:`layout`): X, then for each Y its samples, its
        course value when it has one, and the cursor's line (the cursor's Y value at both
        ends and at the cursor, NaN between: uPlot joins them into a horizontal line);
        at most :data:`MAX_SENT` points, two at least (uPlot draws nothing from one)."""
        x, values = self.shown()
        if len(x) > MAX_SENT:
            pick = np.linspace(0, len(x) - 1, MAX_SENT).round().astype(int)
            x, values = x[pick], {n: v[pick] for n, v in values.items()}
        if len(x) < 2:
            x = np.array([0.0, 1.0]) if len(x) == 0 else np.array([x[0], x[0] + 1e-9])
            values = {n: np.full(2, np.nan) for n in values}
        at = self.cursor_index(x, cursor)
        out: list[np.ndarray] = [x]
        for y in self.ys:
            out.append(values[y.name])
            ref = self.refs.get(y.name)
            if ref is not None:
                out.append(values[ref])
            mark = np.full(len(x), np.nan)
            if at is not None and math.isfinite(values[y.name][at]):
                mark[[0, at, -1]] = values[y.name][at]
            out.append(mark)
        # the vertical range, held at its ends by an invisible last column: a nearly flat
        # curve gets room around it (uPlot zoomed into round-off: every tick read « 30 »)
        every = np.concatenate(out[1:]) if len(out) > 1 else np.zeros(0)
        span = flat_limits(every)
        finite = every[np.isfinite(every)]
        if span is None and len(finite):  # wide enough: the data's own, changing nothing
            span = float(finite.min()), float(finite.max())
        bounds = np.full(len(x), np.nan)
        if span is not None:
            bounds[0], bounds[-1] = span
        out.append(bounds)
        return (x, *(finite_ends(c) for c in out[1:]))

    def layout(self) -> list[tuple[str, Axis]]:
        """What each column of :meth:`arrays` after X is: ("y" | "ref" | "mark" | "range",
        its Y; the last, "range", holds the vertical range)."""
        out = []
        for y in self.ys:
            out.append(("y", y))
            if y.name in self.refs:
                out.append(("ref", y))
            out.append(("mark", y))
        if self.ys:
            out.append(("range", self.ys[0]))  # the vertical range's ends (:meth:`arrays`)
        return out

    @staticmethod
    def cursor_index(x: np.ndarray, cursor: float | None) -> int | None:
        """The sample nearest to ``cursor`` (a fraction 0..1 of the X range), or None."""
        if cursor is None or len(x) == 0 or not np.isfinite(x).any():
            return None
        lo, hi = float(np.nanmin(x)), float(np.nanmax(x))
        target = lo + min(max(cursor, 0.0), 1.0) * (hi - lo)
        return int(np.nanargmin(np.abs(x - target)))

    def read(
        self,
        cursor: float,
        shown: tuple[np.ndarray, dict[str, np.ndarray]] | None = None,
    ) -> tuple[float, list[tuple[Axis, float, float]]] | None:
        """At the cursor (a fraction 0..1 of the X range): X, and for each Y its value
        and slope dY/dX in the page's units (a least-squares line over
        :data:`SLOPE_SPAN` of the range either side); None before any sample.
        ``shown``: what :meth:`shown` returned, when the caller has it already."""
        x, values = shown if shown is not None else self.shown()
        at = self.cursor_index(x, cursor)
        if at is None:
            return None
        span = SLOPE_SPAN * float(np.nanmax(x) - np.nanmin(x))
        near = np.abs(x - x[at]) <= span
        out = []
        for y in self.ys:
            v = values[y.name]
            ok = near & np.isfinite(v) & np.isfinite(x)
            slope = math.nan
            if ok.sum() >= 3 and np.ptp(x[ok]) > 0:
                slope = float(np.polyfit(x[ok], v[ok], 1)[0])
            out.append((y, float(v[at]), slope))
        return float(x[at]), out

    def reading(self, cursor: float, zero: Mapping[str, float] | None = None) -> str:
        """The cursor's reading as French markdown lines (no sample: what to do)."""
        xs, values = shown = self.shown()
        found = self.read(cursor, shown)
        if found is None:
            return "Pas encore de points : lancez la simulation (▶ Lecture)."
        x, ys = found
        at = self._written(self.x, x)
        if len(xs) > 1 and np.nanmax(xs) == np.nanmin(xs):
            return (
                f"X ne varie pas ({self.x.words} = {at}) : "
                "aucune courbe à tracer. Choisissez une autre grandeur en X, ou un "
                "préréglage qui la fait varier."
            )
        zero = zero or {}
        lines = [f"**{self.x.words}** = {at}"]
        span = float(np.nanmax(xs) - np.nanmin(xs)) if len(xs) else 0.0
        for y, value, slope in ys:
            z = zero.get(y.unit, 0.0) * y.scale
            # a slope that moves Y over the whole range by less than Y's own written digits
            # show (half its fourth significant digit), or than its round-off, reads 0: the
            # heavy top's steady nutation drifting 3×10⁻⁶° in 10 s read « pente 3,35×10⁻⁷ °/s »
            size = float(np.nanmax(np.abs(values[y.name]))) if len(xs) else 0.0
            digit = 10.0 ** (math.floor(math.log10(size)) - 3) if size > 0 else 0.0
            flat = max(z, 0.5 * digit) / span if span > 0 else 0.0
            lines.append(
                f"**{y.words}** = {self._written(y, value, zero.get(y.unit, 0.0))} ; "
                f"pente {with_unit(number(slope, 3, zero=flat), slope_unit(y.shown, self.x.shown))}"
            )
        return "  \n".join(lines)

    @staticmethod
    def _written(axis: Axis, shown: float, zero: float = 0.0) -> Written:
        """A value the chart shows (in the page's unit) as every view writes it."""
        if axis.name == TIME:
            return Written(time_words(shown), "s", shown)
        return written(axis.name, shown / axis.scale, axis.unit, zero=zero)

    # -- files ---------------------------------------------------------------------------
    def csv_text(self) -> str:
        """The samples kept, in time order: ``time``, X, the Ys and their course values,
        named and in units as in every file of the sandbox (contracts)."""
        with self._lock:
            t = list(self._t)
            x = list(self._x)
            ys = {n: list(s) for n, s in self._y.items()}
        names = ["time"] + ([] if self.x.name == TIME else [self.x.name]) + list(ys)
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(names)
        for k in range(len(t)):
            row = [t[k]] + ([] if self.x.name == TIME else [x[k]]) + [ys[n][k] for n in ys]
            writer.writerow([csv_cell(float(v)) for v in row])
        return out.getvalue()

    def png(self, title: str, colors: Sequence[str]) -> bytes:
        """The chart as a PNG for a slide: French axes with units, decimal commas, the
        course's values dashed."""
        x, values = self.shown()
        with LOCK:
            fig = new_figure(7.0, 4.5)
            ax = fig.add_subplot()
            line = "-" if self.x.name == TIME or self.x.folds else "."
            for y, color in zip(self.ys, colors, strict=False):
                ax.plot(x, values[y.name], line, color=color, label=y.title, markersize=3)
                ref = self.refs.get(y.name)
                if ref is not None:
                    ax.plot(x, values[ref], "--", color=color, label=f"{y.words}, cours")
            ax.set_xlabel(self.x.title)
            units = {y.shown for y in self.ys}
            ax.set_ylabel(f"[{units.pop()}]" if len(units) == 1 else "")
            ax.set_title(title)
            ax.xaxis.set_major_formatter(comma_formatter())
            ax.yaxis.set_major_formatter(comma_formatter())
            ax.grid(True, alpha=0.3)
            ax.legend()
            fig.tight_layout()
            buffer = io.BytesIO()
            fig.savefig(buffer, format="png", dpi=150)
        return buffer.getvalue()
