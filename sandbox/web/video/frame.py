"""What a video frame shows over the mechanism: the scene's arrows as MuJoCo arrows,
their labels and the key readouts in large French text (Pillow, with matplotlib's
DejaVu Sans, shipped with it).
"""

from __future__ import annotations

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
from sandbox.web.view3d.label_layout import DISTANCES, GAP, Block, Placement, Rect, place


# -- the frame's text -----------------------------------------------------------------------
def _font(px: int) -> Any:
    from matplotlib import get_data_path  # matplotlib takes 0.6 s: only once a video is drawn

    return ImageFont.truetype(str(Path(get_data_path()) / "fonts/ttf/DejaVuSans.ttf"), px)


class Text:
    """Boxes of French text drawn on a frame (Pillow), sized to the frame's height."""

    def __init__(self, height: int) -> None:
        self.big = _font(max(12, round(height * 0.042)))
        self.small = _font(max(10, round(height * 0.026)))
        self._measure = ImageDraw.Draw(Image.new("RGB", (1, 1)))  # made once: every frame measures

    def extent(self, lines: Sequence[str], font: Any) -> tuple[float, float]:
        """Width and height [px] of :meth:`box` around ``lines``, padding included."""
        x0, y0, x1, y1 = self._measure.multiline_textbbox(
            (0, 0), "\n".join(lines), font=font, spacing=4
        )
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


class ArrowLabels:
    """The arrows' labels of a video ("Palier A : 54,4 N") placed as the page places its
    3D labels (:func:`sandbox.web.view3d.label_layout.place`): the labels of one point
    stacked in a block, each block beside its point on the free side away from the
    view's centre, clear of the other blocks and of the readouts' box, a leader line when
    it had to go further; a block keeps its place from frame to frame while it is free
    (labels do not hop). Sizes are the drawn text's, measured by Pillow."""

    def __init__(self, text: Text) -> None:
        self.text = text
        self.before: dict[tuple[float, ...], Placement] = {}

    def draw(
        self,
        draw: Any,
        scene: mujoco.MjvScene,
        drawn: Sequence[tuple[Arrow, np.ndarray, float, str]],
        view: tuple[int, int],
        zeros: dict[str, float],
        readouts: Mapping[str, float] | None = None,
        avoid: Sequence[Rect] = (),
    ) -> None:
        """Label the ``drawn`` arrows in the picture of size ``view`` (width, height);
        an arrow that is a readout writes the readout's value in ``readouts`` (the
        overlay's instant), as the page does."""
        width, height = view
        groups: dict[tuple[float, ...], list[tuple[Arrow, str]]] = {}
        points: dict[tuple[float, ...], tuple[float, float]] = {}
        for arrow, origin, magnitude, unit in drawn:
            key = tuple(round(float(c), 6) for c in origin)
            if key not in points:
                ((x, y),) = project(scene, origin[None, :], width, height)
                points[key] = (float(x), float(y))
            reading = readouts.get(arrow.name) if readouts is not None else None
            words = caption(arrow, magnitude, unit, zeros, reading=reading)
            groups.setdefault(key, []).append((arrow, words))
        keys = list(groups)
        font = self.text.small
        blocks = [
            Block(points[k], tuple(self.text.extent([w], font) for _, w in groups[k])) for k in keys
        ]
        places = place(
            blocks,
            view=(0.0, 0.0, float(width), float(height)),
            centre=(width / 2, height / 2),
            avoid=avoid,
            before=[self.before.get(k) for k in keys],
        )
        self.before = {k: p for k, p in zip(keys, places, strict=True) if p is not None}
        pad = max(4, font.size // 4)
        for key, block, where in zip(keys, blocks, places, strict=True):
            if where is None:
                continue
            left, top, right, bottom = where.box
            if not where.free:  # nowhere free: at least whole in the picture
                dx = min(max(left, 0.0), width - (right - left)) - left
                dy = min(max(top, 0.0), height - (bottom - top)) - top
                left, top, right, bottom = left + dx, top + dy, right + dx, bottom + dy
            if where.reach > DISTANCES[0]:  # further out: a line joins it to its point
                px, py = block.point
                nx, ny = min(max(px, left), right), min(max(py, top), bottom)
                draw.line((px, py, nx, ny), fill=(90, 90, 90), width=max(1, font.size // 12))
            y = top
            for (arrow, words), (_, h) in zip(groups[key], block.sizes, strict=True):
                r, g, b = (int(c * 0.6) for c in arrow.color)  # darker: readable on white
                self.text.box(draw, (left + pad, y + pad), [words], font, (r, g, b))
                y += h + GAP
