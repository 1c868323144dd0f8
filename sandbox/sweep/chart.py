"""A parameter study as a chart for a slide, in French: the measure against the first
varied parameter, beside the course's closed form.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

from sandbox.bench.plot import LOCK, comma_formatter, new_figure
from sandbox.physics.simulation import Simulation
from sandbox.physics.units import display_unit
from sandbox.sweep.study import Study

STAT_WORDS = {
    "final": "",
    "mean": "moyenne de ",
    "max": "maximum de ",
    "amplitude": "amplitude de ",
    "order1": "ordre 1 de ",
    "order2": "ordre 2 de ",
    "period": "période de ",
    "onset": "instant où change ",
}
"""The statistic in French, before the readout's words on a chart's axis."""


def _words(label: str, unit: str) -> str:
    shown = display_unit(unit)
    return f"{label} [{shown}]" if shown else label


def plot(out: Path | IO[bytes], study: Study, rows: Sequence[Mapping[str, Any]]) -> None:
    """The study as a PNG for a slide, in French: the measure against the first varied
    parameter (one curve per value of the second), dots for the runs, the course's
    closed form dashed through them where the scene has one; decimal commas."""
    sim = Simulation(study.source, values=dict(study.fixed))
    scene = sim.scene
    params = {p.name: p for p in (scene.params if scene is not None else ())}
    infos = {i.name: i for i in sim.readout_infos()}
    first = study.varies[0].name
    p = params.get(first)
    x_words = _words(p.label or p.name, p.unit) if p is not None else first
    info = infos[study.measure.readout]
    y_words = STAT_WORDS[study.measure.statistic] + _words(info.label or info.name, info.unit)
    comma = comma_formatter()
    with LOCK:
        fig = new_figure(7.0, 4.5)
        ax = fig.add_subplot()
        groups: dict[float | None, list[Mapping[str, Any]]] = {}
        second = study.varies[1].name if len(study.varies) > 1 else None
        for r in rows:
            groups.setdefault(r[second] if second else None, []).append(r)
        q = params.get(second) if second else None

        dashed = False
        for key, members in groups.items():
            xs = [r[first] for r in members]
            name = "simulation"
            if second and key is not None:
                words = (q.label or q.name) if q is not None else second
                unit = display_unit(q.unit) if q is not None else ""
                value = f"{key:g}".replace(".", ",").replace("-", "−")
                name = f"{words} = {value}{'' if unit == '°' else ' '}{unit}".rstrip()
            (line,) = ax.plot(xs, [r["measure"] for r in members], "o-", label=name)
            course = [r["closed_form"] for r in members]
            if any(math.isfinite(c) for c in course):
                label = None if dashed else "cours (tirets)"
                ax.plot(xs, course, "--", color=line.get_color(), label=label)
                dashed = True
        ax.set_xlabel(x_words)
        ax.set_ylabel(y_words)
        ax.xaxis.set_major_formatter(comma)
        ax.yaxis.set_major_formatter(comma)
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(out, dpi=150, format="png")
