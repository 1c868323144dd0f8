"""« Pression dans les paliers » (course, appendix B.2: from global to local): for each
pivot the scene models as a plain bearing (:class:`~sandbox.physics.page.Bearing`), the
live radial load F, the contact pressure it spreads around the bore under the chosen
hypothesis, drawn as a polar diagram that turns with the load, its largest value beside
the 200 bar the surfaces must stay under (green, red past it), and the course's formulas
with today's numbers. Under hypothesis 3 also the friction torque, by the derivation,
and where the course's printed line differs from it.

The drawing shows the bore's plane as seen along its axis: the shaft presses on the bore
on the side its load on the bearing points to (−F, F being the frame's force on the
shaft), so the coloured zone of contact is centred there. The numbers are those of the
frame's readouts (``bearing_<name>_pmax``), written as every table writes them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import viser

from sandbox.mechanics import bearing as mech
from sandbox.physics import bearings as bearing_rules
from sandbox.physics.page import Bearing
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.snapshot import Snapshot
from sandbox.web.client.text import html_text, number
from sandbox.web.panels.folder import Folder
from sandbox.web.panels.plots import nice_ceil
from sandbox.web.panels.polar import svg_arrow
from sandbox.web.panels.projector import held_line
from sandbox.written import written

if TYPE_CHECKING:
    from sandbox.web.loop.frame import Frame

FOLDER = "Pression dans les paliers"
GREEN, RED, GREY = "#1e8449", "#c0392b", "#9a9a9a"

SIZE = 200.0
"""Width of one bearing's diagram in the SVG's units (about a pixel in the panel)."""
BORE = 42.0
"""Radius of the drawn bore."""
DEPTH = 30.0
"""Radial thickness of the coloured zone at the diagrams' full scale of pressure."""
LIMIT_ROOM = 56.0
"""Largest distance outside the bore where the dashed 200 bar circle is drawn."""


@dataclass(frozen=True)
class Loaded:
    """One bearing at one instant: its declaration, the shaft's load on the bore in the
    drawing's plane (right, up) [N] and its largest contact pressure [Pa]."""

    bearing: Bearing
    load: tuple[float, float]
    p_max: float

    @property
    def force(self) -> float:
        return math.hypot(*self.load)


def in_plane(b: Bearing, frame_on_shaft: np.ndarray) -> tuple[float, float]:
    """The shaft's load on the bore (−``frame_on_shaft``) as (right, up) components of the
    bore's plane seen along its axis."""
    axis = np.asarray(b.axis, dtype=float)
    right = np.asarray(b.across, dtype=float)
    up = np.cross(axis, right)
    load = -np.asarray(frame_on_shaft, dtype=float)
    return float(load @ right), float(load @ up)


# -- drawing ----------------------------------------------------------------------------------
def _zone(cx: float, cy: float, loaded: Loaded, hypothesis: str, k: float) -> str:
    """The pressure on the loaded half, drawn outside the bore: thickness k·p(φ)."""
    if loaded.force <= 0.0 or loaded.p_max <= 0.0:
        return ""
    psi = math.atan2(loaded.load[1], loaded.load[0])
    outer, inner = [], []
    for i in range(61):
        phi = psi - math.pi / 2 + math.pi * i / 60
        p = loaded.p_max * (1.0 if hypothesis == mech.UNIFORM else max(math.cos(phi - psi), 0.0))
        r = BORE + k * p
        outer.append(f"{cx + r * math.cos(phi):.1f},{cy - r * math.sin(phi):.1f}")
        inner.append(f"{cx + BORE * math.cos(phi):.1f},{cy - BORE * math.sin(phi):.1f}")
    colour = GREEN if loaded.p_max < mech.LIMIT_PA else RED
    return (
        f'<polygon points="{" ".join(outer + inner[::-1])}" fill="{colour}" '
        f'fill-opacity="0.55" stroke="{colour}"/>'
    )


def _arrow(cx: float, cy: float, loaded: Loaded) -> str:
    """The shaft's load on the bearing, from the centre (direction only)."""
    if loaded.force <= 0.0:
        return ""
    ux, uy = loaded.load[0] / loaded.force, -loaded.load[1] / loaded.force
    length = BORE - 8.0
    return svg_arrow(cx, cy, cx + length * ux, cy + length * uy, "#111", 2.5) + (
        f'<text x="{cx + 0.55 * length * ux + 6 * uy:.1f}" '
        f'y="{cy + 0.55 * length * uy - 6 * ux:.1f}" font-style="italic">F</text>'
    )


def _diagram(left: float, loaded: Loaded, hypothesis: str, scale: float, zero: float) -> str:
    cx, cy = left + SIZE / 2, 30.0 + BORE + LIMIT_ROOM
    k = DEPTH / scale
    b = loaded.bearing
    out = [
        f'<text x="{cx:.1f}" y="17" text-anchor="middle" font-weight="600" font-size="15">'
        f"{html_text(b.label)}</text>",
        f'<line x1="{cx - BORE - LIMIT_ROOM:.1f}" y1="{cy:.1f}" '
        f'x2="{cx + BORE + LIMIT_ROOM:.1f}" y2="{cy:.1f}" stroke="{GREY}" '
        'stroke-dasharray="3 3"/>',
        f'<line x1="{cx:.1f}" y1="{cy - BORE - LIMIT_ROOM:.1f}" x2="{cx:.1f}" '
        f'y2="{cy + BORE + LIMIT_ROOM:.1f}" stroke="{GREY}" stroke-dasharray="3 3"/>',
        f'<text x="{cx + BORE + LIMIT_ROOM:.1f}" y="{cy - 5:.1f}" fill="#555" '
        f'text-anchor="end">{html_text(b.words[0])}</text>',
        f'<text x="{cx + 5:.1f}" y="{cy - BORE - LIMIT_ROOM + 10:.1f}" fill="#555">'
        f"{html_text(b.words[1])}</text>",
        _zone(cx, cy, loaded, hypothesis, k),
        f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="{BORE - 3:.1f}" fill="#d9d9d9"/>',
        f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="{BORE:.1f}" fill="none" stroke="#333" '
        'stroke-width="1.5"/>',
    ]
    limit = BORE + k * mech.LIMIT_PA
    if limit <= BORE + LIMIT_ROOM:
        out.append(
            f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="{limit:.1f}" fill="none" stroke="{RED}" '
            'stroke-dasharray="5 4"/>'
        )
    out.append(_arrow(cx, cy, loaded))
    p = written(f"bearing_{b.name}_pmax", loaded.p_max, "Pa", zero=zero)
    colour = GREEN if loaded.p_max < mech.LIMIT_PA else RED
    out.append(
        f'<text x="{cx:.1f}" y="{cy + BORE + LIMIT_ROOM + 22:.1f}" text-anchor="middle" '
        f'fill="{colour}" font-weight="600">pₘₐₓ = {html_text(str(p))}</text>'
    )
    return "".join(out)


def bearings_svg(loaded: Sequence[Loaded], hypothesis: str, zero: float = 0.0) -> str:
    """Every bearing's diagram side by side, on one scale of pressure (the largest
    p_max rounded up): the bore, the shaft, the load's direction, the pressure on the
    loaded half (green under 200 bar, red past it) and, when it fits, 200 bar dashed."""
    largest = max((x.p_max for x in loaded), default=0.0)
    scale = nice_ceil(largest) if largest > 0 else mech.LIMIT_PA
    height = 30.0 + 2 * (BORE + LIMIT_ROOM) + 30
    body = "".join(_diagram(i * SIZE, x, hypothesis, scale, zero) for i, x in enumerate(loaded))
    width = SIZE * max(len(loaded), 1)
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width:.0f} {height:.0f}" '
        'width="100%" role="img" aria-label="Pression de contact dans les paliers" '
        f'font-family="sans-serif" font-size="14" '
        f'style="display:block;max-width:{20 * max(len(loaded), 1)}em">'
        f"{body}</svg>"
    )


# -- the formulas with today's numbers ---------------------------------------------------------
def _mm(metres: float) -> str:
    return f"{number(metres * 1e3, 4)}\u00a0mm"


def formulas_html(loaded: Loaded, values: Mapping[str, float], zeros: Mapping[str, float]) -> str:
    """One bearing's load, pressure (and friction torque under hypothesis 3) with the
    course's formulas and today's numbers, the verdict against 200 bar."""
    b = loaded.bearing
    choice = bearing_rules.hypothesis(values)
    (r, length), f = bearing_rules.bore(values), values["bearing_f"]
    force = written(f"bearing_{b.name}_load", loaded.force, "N", zero=zeros.get("N", 0.0))
    p0 = mech.mean_pressure(loaded.force, r, length)
    p0_text = written(f"bearing_{b.name}_p0", p0, "Pa", zero=zeros.get("Pa", 0.0))
    p_max = written(f"bearing_{b.name}_pmax", loaded.p_max, "Pa", zero=zeros.get("Pa", 0.0))
    lines = [
        f"<b>{html_text(b.label)}</b> : charge radiale F = {html_text(str(force))}",
        f"p₀ = F / (2·R·L) = {html_text(str(force))} / (2 × {_mm(r)} × {_mm(length)}) "
        f"= {html_text(str(p0_text))}",
    ]
    if choice == bearing_rules.COSINE:
        lines.append(f"pₘₐₓ = (4/π)·p₀ = 2·F / (π·R·L) = {html_text(str(p_max))}")
    else:
        lines.append(f"pₘₐₓ = p₀ = {html_text(str(p_max))}")
    if loaded.p_max < mech.LIMIT_PA:
        verdict = f'<span style="color:{GREEN};font-weight:600">sous les 200 bar : tenue</span>'
    else:
        verdict = (
            f'<span style="color:{RED};font-weight:600">au-delà de 200 bar : les surfaces '
            "s'abîment</span>"
        )
    lines.append(verdict)
    if bearing_rules.has_friction(values):
        torque = bearing_rules.friction_torque(loaded.force, values)
        cf = written(f"bearing_{b.name}_Cf", torque, "N·m", zero=zeros.get("N·m", 0.0))
        if choice == bearing_rules.COSINE:
            formula, factor = "Cf = 2·f·R²·L·pₘₐₓ = (4/π)·f·R·F", "(4/π)"
        else:
            formula, factor = "Cf = π·R²·L·f·p₀ = (π/2)·f·R·F", "(π/2)"
        lines.append(
            f"{formula} = {factor} × {number(f, 3)} × {_mm(r)} × "
            f"{html_text(str(force))} = {html_text(str(cf))}"
        )
    return '<p style="margin:0.5em 0 0">' + "<br>".join(lines) + "</p>"


PRINTED_NOTE = (
    "Le cours imprime Cf = 2·π·R²·p₀·f. En intégrant f·p₀ sur la moitié chargée de "
    "l'alésage (un angle de π, pas de 2π) et sur sa longueur L, on trouve π·R²·L·f·p₀ : "
    "la ligne imprimée double le résultat et oublie L (elle donnerait des newtons, pas "
    "des N·m). Les nombres ci-dessus suivent la dérivation."
)


def panel_html(
    loaded: Sequence[Loaded],
    values: Mapping[str, float],
    zeros: Mapping[str, float],
    *,
    held: str = "",
) -> str:
    """The whole folder: the hypothesis, the diagrams, each bearing's formulas, and the
    note on the course's printed line under hypothesis 3 (``held``: the line saying at
    which angle a fast rotation's numbers are read)."""
    choice = bearing_rules.hypothesis(values)
    model = bearing_rules.pressure_model(values)
    radius, length = bearing_rules.bore(values)
    head = (
        f'<p style="margin:0 0 0.3em">{html_text(bearing_rules.HYPOTHESIS_WORDS[choice])}'
        f" ; alésage de rayon R = {_mm(radius)} et de longueur "
        f"L = {_mm(length)} (réglages avancés).</p>"
    )
    legend = (
        '<p style="margin:0.3em 0 0;color:#555">La zone colorée est la moitié chargée de '
        "l'alésage, son épaisseur la pression de contact ; le cercle rouge en tirets "
        "marque 200 bar quand il tient dans le dessin. F : effort de l'arbre sur le "
        "palier.</p>"
    )
    parts = [head, bearings_svg(loaded, model, zeros.get("Pa", 0.0)), legend]
    parts += [formulas_html(x, values, zeros) for x in loaded]
    if bearing_rules.friction_on(values):
        parts.append(
            '<p style="margin:0.5em 0 0">Frottement appliqué dans la simulation : le couple '
            "Cf de chaque palier s'oppose à la rotation, Pᵢₙₜ = −ΣCf·ω (dossier « Énergie "
            "et puissances ») et le moteur fournit ΣCf de plus.</p>"
        )
    if bearing_rules.has_friction(values) and choice != bearing_rules.COSINE:
        note = html_text(PRINTED_NOTE, limit=len(PRINTED_NOTE))
        parts.append(f'<p style="margin:0.5em 0 0;color:#555">{note}</p>')
    if held:
        parts.append(f'<p style="margin:0.4em 0 0;color:#555">{html_text(held)}</p>')
    return f'<div class="sandbox-bearing">{"".join(parts)}</div>'


# -- the panel --------------------------------------------------------------------------------
class BearingPanel:
    """Folder « Pression dans les paliers » of a scene that declares bearings.

    Create it with :meth:`create` (None for scenes without bearings); the view refreshes
    it from each frame that brings readouts, at the panels' rate.
    """

    def __init__(
        self, gui: viser.GuiApi, sim: ReadOnlySimulation, declared: tuple[Bearing, ...]
    ) -> None:
        self.sim = sim
        self.bearings = declared
        self.folder = gui.add_folder(FOLDER, expand_by_default=True)
        with self.folder:
            self.html = gui.add_html("")
        self.names = tuple(f"bearing_{b.name}_pmax" for b in declared)

    @classmethod
    def create(cls, gui: viser.GuiApi, sim: ReadOnlySimulation) -> BearingPanel | None:
        scene = sim.scene
        declared = scene.page.bearings if scene is not None else ()
        return cls(gui, sim, declared) if declared else None

    def pickable(self) -> list[Folder]:
        """Its folder: it reads the state (the instant the tables show), so a challenge
        closes it."""
        return [Folder(FOLDER, self.folder, self._refresh, names=lambda: self.names)]

    def _refresh(self, frame: Frame) -> None:
        self.refresh(frame.state, frame.readouts, held=frame.held is not None)

    def loaded(self, state: Snapshot | None, readouts: Mapping[str, float] | None) -> list[Loaded]:
        """Each bearing's load and largest pressure at ``state`` (its forces prepared;
        None: the physics state), p_max from ``readouts`` when given (the tables' value)."""
        sim = self.sim
        with sim.lock:
            if state is None or state.model is not sim.model:
                state = sim.snapshot((), forces=True)
            out = []
            for b in self.bearings:
                frame_on_shaft = bearing_rules.radial_load(b, state)
                force = float(np.linalg.norm(frame_on_shaft))
                name = f"bearing_{b.name}_pmax"
                p_max = (readouts or {}).get(name)
                if p_max is None or not math.isfinite(p_max):
                    p_max = bearing_rules.max_pressure(force, state.values)
                out.append(Loaded(b, in_plane(b, frame_on_shaft), float(p_max)))
        return out

    def refresh(
        self,
        state: Snapshot | None = None,
        readouts: Mapping[str, float] | None = None,
        *,
        held: bool = False,
    ) -> None:
        """Redraw at ``state`` with ``readouts`` (the frame's)."""
        loaded = self.loaded(state, readouts)
        values = dict(self.sim.values)
        scene = self.sim.scene
        zeros = dict(scene.zero) if scene is not None else {}
        line = held_line(readouts or {}) if held else ""
        self.html.content = panel_html(loaded, values, zeros, held=line)
