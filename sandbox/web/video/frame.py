"""What a video frame shows over the mechanism: the scene's arrows as MuJoCo arrows,
their labels and the key readouts in large French text (Pillow, with matplotlib's
DejaVu Sans, shipped with it).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from PIL import Image, ImageDraw, ImageFont

from sandbox.physics.page import Arrow
from sandbox.physics.snapshot import Snapshot
from sandbox.web.video.offscreen import project
from sandbox.web.view3d.arrow_scale import arrow_points, auto_factor, caption


# -- the frame's text -----------------------------------------------------------------------
def _font(px: int) -> Any:
    from matplotlib import get_data_path  # matplotlib takes 0.6 s: only once a video is drawn

    return ImageFont.truetype(str(Path(get_data_path()) / "fonts/ttf/DejaVuSans.ttf"), px)


class Text:
    """Boxes of French text drawn on a frame (Pillow), sized to the frame's height."""

    def __init__(self, height: int) -> None:
        self.big = _font(max(12, round(height * 0.042)))
        self.small = _font(max(10, round(height * 0.026)))

    def extent(self, lines: Sequence[str], font: Any) -> tuple[float, float]:
        """Width and height [px] of :meth:`box` around ``lines``, padding included."""
        draw = ImageDraw.Draw(Image.new("RGB", (1, 1)))
        x0, y0, x1, y1 = draw.multiline_textbbox((0, 0), "\n".join(lines), font=font, spacing=4)
        pad = max(4, font.size // 4)
        return x1 - x0 + 2 * pad, y1 - y0 + 2 * pad

    def box(
        self,
        draw: Any,
        xy: tuple[float, float],
        lines: Sequence[str],
        font: Any,
        color: tuple[int, int, int] = (0, 0, 0),
    ) -> None:
        """Lines in a white box with its top-left corner at ``xy``."""
        text = "\n".join(lines)
        x0, y0, x1, y1 = draw.multiline_textbbox(xy, text, font=font, spacing=4)
        pad = max(4, font.size // 4)
        draw.rectangle((x0 - pad, y0 - pad, x1 + pad, y1 + pad), fill=(255, 255, 255, 215))
        draw.multiline_text(xy, text, font=font, fill=color, spacing=4)


def add_arrows(
    scene: mujoco.MjvScene,
    arrows: Sequence[Arrow],
    snapshot: Snapshot,
    size: float,
    factors: dict[str, float],
    units: dict[str, str],
) -> list[tuple[Arrow, np.ndarray, float, str]]:
    """The scene's arrows as MuJoCo arrows in ``scene`` (sized as the page sizes them:
    a unit's factor changes only when its longest arrow would leave the view or shrink
    to a dot); returns (arrow, its point, magnitude, unit) of those drawn."""
    ends = []
    for arrow in arrows:
        origin, end, magnitude = arrow_points(arrow, snapshot)
        unit = arrow.unit or units.get(arrow.name, "")
        ends.append((arrow, origin, end, magnitude, unit))
    for unit in {e[4] for e in ends}:
        longest = max(float(np.linalg.norm(e[2] - e[1])) for e in ends if e[4] == unit)
        factors[unit] = auto_factor(factors.get(unit, 1.0), longest, size)
    drawn = []
    shaft = 0.012 * size
    for arrow, origin, end, magnitude, unit in ends:
        tip = origin + factors[unit] * (end - origin)
        if np.linalg.norm(tip - origin) < 1e-4 or scene.ngeom >= scene.maxgeom:
            continue
        geom = scene.geoms[scene.ngeom]
        rgba = np.array([*(c / 255 for c in arrow.color), 1.0], dtype=np.float32)
        mujoco.mjv_initGeom(
            geom, mujoco.mjtGeom.mjGEOM_ARROW, np.zeros(3), np.zeros(3), np.eye(3).ravel(), rgba
        )
        mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_ARROW, shaft, origin, tip)
        scene.ngeom += 1
        drawn.append((arrow, origin, magnitude, unit))
    return drawn


def label_arrows(
    draw: Any,
    text: Text,
    scene: mujoco.MjvScene,
    drawn: Sequence[tuple[Arrow, np.ndarray, float, str]],
    width: int,
    height: int,
    zeros: dict[str, float],
    readouts: Mapping[str, float] | None = None,
) -> None:
    """Each arrow's label ("Palier A : 54,4 N") beside its point of application, the
    labels of one point stacked, in the arrow's colour; an arrow that is a readout writes
    the readout's value in ``readouts`` (the overlay's instant), as the page does."""
    stacks: dict[tuple[int, int], int] = {}
    for arrow, origin, magnitude, unit in drawn:
        ((x, y),) = project(scene, origin[None, :], width, height)
        if not (math.isfinite(x) and math.isfinite(y)):
            continue
        key = (round(x / 40), round(y / 40))
        row = stacks.get(key, 0)
        stacks[key] = row + 1
        reading = readouts.get(arrow.name) if readouts is not None else None
        words = caption(arrow, magnitude, unit, zeros, reading=reading)
        at = (min(x + 12, width - 8 * text.small.size), y + 4 + row * 1.4 * text.small.size)
        r, g, b = (int(c * 0.6) for c in arrow.color)  # darker: readable on white
        color = (r, g, b)
        text.box(draw, at, [words], text.small, color)
