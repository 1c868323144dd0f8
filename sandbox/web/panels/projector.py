"""Projector mode: text large enough for the back row, and the scene's key readouts in
large print over the 3D view.

viser has no font-size setting: the page's size comes from a ``<style>`` element sent
with ``gui.add_html`` (the browser applies a style element wherever it sits), which sets
Mantine's size variables, so every label, box, button and slider bound follows. The
overlay is a fixed ``<div>`` sent the same way, drawn over the canvas, left of the
control panel.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.strobe import HELD_ANGLE
from sandbox.web.client.fields import on_user, set_value
from sandbox.web.client.text import html_text
from sandbox.web.panels.folder import Folder
from sandbox.written import written

if TYPE_CHECKING:
    import viser


FALLBACK_READOUTS = ("T", "V")
"""Overlay of a scene without key readouts: kinetic and potential energy."""

FONT_SIZES = (16, 18, 20, 24)
"""Text sizes offered [px] (the smallest is the default: 16 px is read from the back of
a classroom on a 1280×720 projector)."""

DISPLAY_FOLDER = "Projecteur"
FONT_LABEL = "Taille du texte"
OVERLAY_LABEL = "Mesures dans la vue 3D"
OVERLAY_ID = "sandbox-overlay"


def font_option(px: int) -> str:
    return f"{px} px"


def style_html(font_px: int, *, left: int = 16, right: int = 16) -> str:
    """The page's style: Mantine's text sizes from ``font_px`` up, slider bounds and
    folder titles readable, and the overlay's place (``left`` [px] from the window's
    left edge, past a panel docked there; at most up to ``right`` [px] from its right
    edge, before the control panel)."""
    f = font_px
    return (
        "<style>"
        f":root{{--mantine-font-size-xs:{f}px;--mantine-font-size-sm:{f}px;"
        f"--mantine-font-size-md:{f + 1}px;--mantine-font-size-lg:{f + 2}px;"
        f"--mantine-font-size-xl:{f + 4}px;}}"
        f".mantine-Slider-markLabel{{font-size:{max(f - 4, 12)}px !important}}"
        f".mantine-Input-input,.mantine-InputWrapper-label,.mantine-Button-label,"
        f".mantine-Text-root,.mantine-Tooltip-tooltip{{font-size:{f}px !important}}"
        # viser gives a control's label a fixed 6.6 em column: three lines for "Masse de
        # correction m₁ [g]"; 40 % of the row keeps it on one or two.
        '.mantine-Flex-root>div[style*="width: 6.6125em"]{width:40% !important}'
        ".mantine-Flex-root>div>p.mantine-Text-root{letter-spacing:0 !important}"
        # a slider's number box is 3 rem wide: "0.015" and "3000" were cut
        '.mantine-NumberInput-root[style*="width: 3rem"]{width:4.4em !important}'
        # markdown tables have no cell padding: "0,12130,1213+0,00 %" read as one number
        "td,th{padding:2px 0 2px 0.6em !important}td:first-child,th:first-child"
        "{padding-left:0 !important}"
        f"#{OVERLAY_ID}{{position:fixed;left:{left + 64}px;bottom:12px;z-index:5;"
        f"max-width:calc(100vw - {left + 64 + right}px);"
        "pointer-events:none;background:rgba(255,255,255,0.82);border-radius:8px;"
        f"padding:6px 14px;font-size:{round(1.3 * f)}px;line-height:1.3;"
        "font-variant-numeric:tabular-nums;color:#111;box-shadow:0 1px 6px rgba(0,0,0,.2)}"
        f"#{OVERLAY_ID}:empty{{display:none}}"
        "</style>"
    )


def key_readouts(sim: ReadOnlySimulation) -> dict[str, str]:
    """The overlay's readouts for ``sim`` (those it has) with their short words ("": the
    readout's label): the scene's ``overlay``, else its energies."""
    known = set(sim.readout_names())
    spec = sim.scene
    names = dict(spec.page.overlay) if spec is not None and spec.page.overlay else {}
    names = names or dict.fromkeys(FALLBACK_READOUTS, "")
    return {n: short for n, short in names.items() if n in known}


def overlay_labels(sim: ReadOnlySimulation) -> dict[str, str]:
    """The overlay's words for each of its readouts (:func:`key_readouts`), in the way
    the motion is computed now (« Couple nécessaire » while it is imposed): the scene's
    short words, else the readout's label. Every view that writes the overlay (the page,
    the class board, a video, a static export) takes them from here."""
    infos = {i.name: i for i in sim.readout_infos()}
    short = key_readouts(sim)
    spec = sim.scene
    imposed = spec is not None and sim.motion == "imposed"
    changed = dict(spec.page.imposed_overlay) if spec is not None and imposed else {}
    return {n: changed.get(n) or w or infos[n].label or n for n, w in short.items()}


def held_line(values: Mapping[str, float]) -> str:
    """The overlay's last line while a fast rotation's numbers are held at one angle
    (:mod:`sandbox.physics.strobe`): which angle, written as the tables write θ."""
    theta = values.get(HELD_ANGLE)
    if theta is None or not math.isfinite(theta):
        return "(relevé au même angle, à chaque tour)"
    return f"(relevé à θ = {written(HELD_ANGLE, theta, 'rad')}, à chaque tour)"


def overlay_lines(
    names: Sequence[str],
    values: Mapping[str, float],
    labels: Mapping[str, str],
    units: Mapping[str, str],
    zeros: Mapping[str, float] | None = None,
) -> list[str]:
    """One line per readout: "label = value unit", written as every view writes it
    (:func:`sandbox.written.written`: the tables' digits, θ modulo 360°, a flag in words,
    "—" when missing)."""
    lines = []
    for name in names:
        value = values.get(name, math.nan)
        text = written(name, value, units.get(name, ""), zero=(zeros or {}).get(name, 0.0))
        lines.append(f"{labels.get(name) or name} = {text}")
    return lines


def overlay_html(lines: Sequence[str]) -> str:
    """The overlay's HTML: every line escaped (labels may come from a file)."""
    body = "<br>".join(html_text(line) for line in lines)
    return f"<div id='{OVERLAY_ID}'>{body}</div>"


class Projector:
    """Folder "Projecteur" (text size, overlay on or off), the page's style and the key
    readouts over the 3D view.

    Args:
        gui: A viser ``GuiApi`` (``client.gui``).
        sim: The session's simulation (only read).
        left: Distance [px] of the 3D view from the window's left edge.
        right: Distance [px] of the 3D view from the window's right edge.
    """

    def __init__(
        self, gui: viser.GuiApi, sim: ReadOnlySimulation, *, left: int = 16, right: int = 16
    ) -> None:
        self.left, self.right = left, right
        self.font = FONT_SIZES[0]
        infos = {i.name: i for i in sim.readout_infos()}
        self.names = list(key_readouts(sim))
        self.sim = sim
        self.units = {n: infos[n].unit for n in self.names}
        spec = sim.scene  # the scene's round-off: 5e-15 W is written 0
        self.zeros = {n: spec.zero_for(self.units[n]) if spec else 0.0 for n in self.names}
        self.style = gui.add_html(style_html(self.font, left=left, right=right), order=-1000.0)
        self.overlay = gui.add_html(overlay_html([]), order=-999.0)
        with gui.add_folder(DISPLAY_FOLDER) as self.folder:
            options = tuple(font_option(px) for px in FONT_SIZES)
            self.size = gui.add_dropdown(
                FONT_LABEL,
                options,
                initial_value=font_option(self.font),
                hint="Taille des textes du panneau (plus grand pour le fond de la salle)",
            )
            self.show = gui.add_checkbox(
                OVERLAY_LABEL,
                True,
                hint="Les grandeurs clés de la scène en grand, sur la vue 3D",
            )
        self._pending_font: int | None = None
        on_user(self.size, self._ask_font)
        self._lines: list[str] = []

    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché » (text size, overlay), which a challenge
        keeps; the overlay itself is refreshed at every panel tick, whatever is shown."""
        return [Folder(self.folder.label or DISPLAY_FOLDER, self.folder, secret_safe=True)]

    def _ask_font(self, option: object) -> None:
        for px in FONT_SIZES:
            if option == font_option(px):
                self._pending_font = px
                return
        set_value(self.size, font_option(self.font))  # a crafted option: put back

    def refresh(self, values: Mapping[str, float] | None, *, held: bool = False) -> None:
        """Apply a new text size; show the key readouts of ``values`` (None: keep);
        ``held``: they are a fast rotation's, read at one angle every turn (said on a
        last line, :func:`held_line`)."""
        if self._pending_font is not None:
            self.font, self._pending_font = self._pending_font, None
            self.style.content = style_html(self.font, left=self.left, right=self.right)
        if not self.show.value:
            lines: list[str] = []
        elif values is None:
            return
        else:
            labels = overlay_labels(self.sim)  # the motion may have changed since
            lines = overlay_lines(self.names, values, labels, self.units, self.zeros)
            if held and lines:
                lines.append(held_line(values))
        if lines != self._lines:
            self._lines = lines
            self.overlay.content = overlay_html(lines)
