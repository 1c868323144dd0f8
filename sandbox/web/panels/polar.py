"""Polar diagram of the rotor's unbalance (course 7.2), drawn live as an inline SVG.

Two diagrams in the rotor frame (y₁ to the right, z₁ up, angles in degrees from y₁ towards
z₁, as the correction masses' angles): the static unbalance m·OG⊥ [kg·m] and the couple
unbalance (F, E) [kg·m²]. In each, the rotor without correction masses (defect mass and
skewed disk), then correction mass 1, then correction mass 2 are drawn head to tail, and
the resultant from the centre: the rotor is balanced dynamically when both chains close
at the centre, and then the bearings carry no rotating force.

The vectors come from the scene, which declares its diagram
(:class:`~sandbox.physics.spec.UnbalanceDiagram`: the rotor's comes from its defect, disk and
planes, :mod:`sandbox.scenes.rotor.diagram`); the panel redraws only when a parameter the
diagram depends on changes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import viser

from sandbox.mechanics.unbalance import Unbalance, polar
from sandbox.physics.page import UnbalanceDiagram
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.web.client.text import html_text, number
from sandbox.web.panels.folder import Folder

if TYPE_CHECKING:
    from sandbox.web.loop.frame import Frame
from sandbox.web.panels.plots import nice_ceil

FOLDER = "Diagramme des balourds"
COLOURS = {"rotor": "#c0392b", "m1": "#1e8449", "m2": "#7d3c98", "total": "#111111"}
NAMES = {"rotor": "Rotor seul", "m1": "m₁ (plan 1)", "m2": "m₂ (plan 2)", "total": "Résultante"}
TIPS = {"rotor": "rotor", "m1": "m₁", "m2": "m₂", "total": "Σ"}
ROUND_OFF = 1e-9
"""Relative size under which a vector is shown as 0 (the round-off of the sums)."""


# -- drawing ----------------------------------------------------------------------------------
SIZE = 200.0
"""Width of one diagram in the SVG's units (two side by side: about one unit per pixel in
the control panel, so that 14-unit text reads as 14 px)."""
RADIUS = 66.0


def _fmt(norm: float, unit: str, zero: float) -> str:
    return f"{number(norm, 3, zero=zero)} {unit}"


def svg_arrow(x0: float, y0: float, x1: float, y1: float, colour: str, width: float) -> str:
    """An SVG arrow from (x0, y0) to (x1, y1) with a filled head (no marker ids)."""
    length = math.hypot(x1 - x0, y1 - y0)
    if length < 0.5:
        return ""
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    head = min(10.0, 0.5 * length)
    bx, by = x1 - head * ux, y1 - head * uy
    px, py = -uy * head * 0.45, ux * head * 0.45
    return (
        f'<line x1="{x0:.1f}" y1="{y0:.1f}" x2="{bx:.1f}" y2="{by:.1f}" stroke="{colour}" '
        f'stroke-width="{width}" stroke-linecap="round"/>'
        f'<polygon points="{x1:.1f},{y1:.1f} {bx + px:.1f},{by + py:.1f} '
        f'{bx - px:.1f},{by - py:.1f}" fill="{colour}"/>'
    )


def _diagram(
    left: float, title: str, parts: Mapping[str, np.ndarray], total: np.ndarray, unit: str
) -> str:
    """One polar diagram at x offset ``left``: axes, scale circle, chain and resultant."""
    cx, cy = left + SIZE / 2, 44.0 + RADIUS
    chain = [np.zeros(2)]
    for vector in parts.values():
        chain.append(chain[-1] + vector)
    reach = max(
        [float(np.linalg.norm(p)) for p in chain]
        + [float(np.linalg.norm(v)) for v in parts.values()]
    )
    scale = nice_ceil(reach) if reach > 0 else 1.0
    k = RADIUS / scale

    def at(p: np.ndarray) -> tuple[float, float]:
        return cx + k * float(p[0]), cy - k * float(p[1])  # z₁ up

    grey = "#9a9a9a"
    out = [
        f'<text x="{cx:.1f}" y="17" text-anchor="middle" font-weight="600" font-size="15">'
        f"{title}</text>",
        f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="{RADIUS}" fill="none" stroke="{grey}"/>',
        f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="{RADIUS / 2}" fill="none" stroke="#d0d0d0"/>',
        f'<line x1="{cx - RADIUS - 6:.1f}" y1="{cy:.1f}" x2="{cx + RADIUS + 6:.1f}" '
        f'y2="{cy:.1f}" stroke="{grey}" stroke-dasharray="3 3"/>',
        f'<line x1="{cx:.1f}" y1="{cy - RADIUS - 6:.1f}" x2="{cx:.1f}" '
        f'y2="{cy + RADIUS + 6:.1f}" stroke="{grey}" stroke-dasharray="3 3"/>',
        f'<text x="{cx + RADIUS:.1f}" y="{cy + 17:.1f}" fill="#555" text-anchor="end">'
        "0° (y₁)</text>",
        f'<text x="{cx - RADIUS:.1f}" y="{cy + 17:.1f}" fill="#555">180°</text>',
        f'<text x="{cx + 4:.1f}" y="{cy - RADIUS - 8:.1f}" fill="#555">90° (z₁)</text>',
        f'<text x="{cx + 4:.1f}" y="{cy + RADIUS + 18:.1f}" fill="#555">−90°</text>',
        f'<text x="{cx:.1f}" y="{cy + RADIUS + 38:.1f}" text-anchor="middle" '
        f'fill="#555">cercle : {html_text(_fmt(scale, unit, 0.0))}</text>',
    ]
    for name, start, end in zip(parts, chain[:-1], chain[1:], strict=True):
        (x0, y0), (x1, y1) = at(start), at(end)
        out.append(svg_arrow(x0, y0, x1, y1, COLOURS[name], 3.0))
    x1, y1 = at(total)
    out.append(svg_arrow(cx, cy, x1, y1, COLOURS["total"], 4.5))
    out.append(f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="3" fill="#111"/>')
    return "".join(out)


def polar_svg(unbalance: Unbalance) -> str:
    """Both diagrams side by side as one inline SVG (scales with the panel's width)."""
    height = 44.0 + 2 * RADIUS + 46
    body = _diagram(
        0.0, "Balourd statique m·OG⊥", unbalance.static, unbalance.static_total, "kg·m"
    ) + _diagram(
        SIZE, "Balourd de couple (F, E)", unbalance.couple, unbalance.couple_total, "kg·m²"
    )
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {2 * SIZE:.0f} {height:.0f}" '
        'width="100%" role="img" aria-label="Diagramme polaire des balourds" '
        'font-family="sans-serif" font-size="14" style="display:block;max-width:40em">'
        f"{body}</svg>"
    )


def _cell(vector: np.ndarray, zero: float) -> str:
    norm, angle = polar(vector)
    if norm <= zero:
        return "0"
    if angle <= -179.95:
        angle = 180.0  # -0.0 below the axis: the same direction
    degrees = number(angle, 3, zero=0.05).replace("-", "−")
    return f"{number(norm, 3, zero=zero)} à {degrees}°"


def legend_html(unbalance: Unbalance) -> str:
    """The table under the diagrams: colour, part, static and couple unbalance, angle."""
    static_zero = ROUND_OFF * max(float(np.linalg.norm(v)) for v in unbalance.static.values())
    couple_zero = ROUND_OFF * max(float(np.linalg.norm(v)) for v in unbalance.couple.values())
    rows = []
    cell = '<td style="text-align:right;white-space:nowrap;padding-left:0.5em">'
    parts = [
        *((n, unbalance.static[n], unbalance.couple[n]) for n in ("rotor", "m1", "m2")),
        ("total", unbalance.static_total, unbalance.couple_total),
    ]
    for name, static, couple in parts:
        swatch = (
            f'<svg width="14" height="14" viewBox="0 0 14 14" aria-hidden="true">'
            f'<rect width="14" height="14" rx="2" fill="{COLOURS[name]}"/></svg>'
        )
        weight = ' style="font-weight:600"' if name == "total" else ""
        rows.append(
            f"<tr{weight}><td>{swatch}</td><td>{html_text(NAMES[name])}</td>"
            f"{cell}{html_text(_cell(static, static_zero))}</td>"
            f"{cell}{html_text(_cell(couple, couple_zero))}</td>"
            "</tr>"
        )
    head = (
        '<tr style="color:#555"><th></th><th style="text-align:left">Vecteur</th>'
        '<th style="text-align:right">Statique [kg·m]</th>'
        '<th style="text-align:right">Couple [kg·m²]</th></tr>'
    )
    note = (
        '<p style="margin:0.4em 0 0">Balourds statique et de couple, dans le repère du '
        "rotor (angles depuis y₁ vers z₁). Rotor seul : masselotte et disque de travers ; "
        "plan 1 à x = −120 mm, plan 2 à x = +120 mm. Le rotor est équilibré quand les deux "
        "résultantes sont nulles : les paliers ne transmettent plus d'effort tournant.</p>"
    )
    return (
        '<table style="width:100%;border-collapse:collapse;font-size:0.9em">'
        f"{head}{''.join(rows)}</table>{note}"
    )


def panel_html(unbalance: Unbalance) -> str:
    """The whole panel for a rotor's ``unbalance``: diagrams and legend."""
    return f'<div class="sandbox-polar">{polar_svg(unbalance)}{legend_html(unbalance)}</div>'


# -- the panel --------------------------------------------------------------------------------
class PolarPanel:
    """Folder "Diagramme des balourds" of the rotor scene, redrawn when a value changes.

    Create it with :meth:`create` (None for scenes without such a diagram) and call
    :meth:`refresh` at the panel rate (10 Hz) from the session's loop thread.

    Args:
        gui: A viser ``GuiApi``.
        sim: The simulation shown (live or replayed): its ``values`` are the parameters.
        diagram: The scene's diagram.
    """

    def __init__(
        self, gui: viser.GuiApi, sim: ReadOnlySimulation, diagram: UnbalanceDiagram
    ) -> None:
        self.sim = sim
        self.diagram = diagram
        self._key: tuple[float, ...] | None = None
        self.folder = gui.add_folder(FOLDER, expand_by_default=True)
        with self.folder:
            self.html = gui.add_html("")
        self.refresh()

    @classmethod
    def create(cls, gui: viser.GuiApi, sim: ReadOnlySimulation) -> PolarPanel | None:
        """The panel when ``sim`` is of a scene that declares an unbalance diagram (the
        rotor), else None."""
        scene = sim.scene
        diagram = scene.page.unbalance_diagram if scene is not None else None
        if diagram is None:
            return None
        return cls(gui, sim, diagram)

    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché »: drawn from the parameters (closed during a
        challenge: it would show a hidden unbalance), refreshed even while diverged."""
        return [Folder(FOLDER, self.folder, self._redraw, needs_readouts=False)]

    def _redraw(self, _: Frame) -> None:
        self.refresh()

    def refresh(self) -> bool:
        """Redraw when a parameter the diagram depends on changed; True when redrawn."""
        values: Mapping[str, float] = self.sim.values
        try:
            key = tuple(float(values[k]) for k in self.diagram.depends_on)
        except (KeyError, TypeError, ValueError):
            return False
        if key == self._key:
            return False
        self._key = key
        self.html.content = panel_html(self.diagram.unbalance(values))
        return True
