"""Where the 3D labels go on the screen: beside the point they name, never over one
another, nor over the readouts written over the view.

viser draws a label as a billboard of constant pixel size (12 px per unit of
``font_screen_scale``) anchored at a 3D point, with no offset of its own; overlapping
labels and labels at the tip of a force that turns 50 times a second were unreadable on
a projector. Here labels sharing a point (the forces at a bearing, the moments at G) are
stacked in one block, and each block is put beside its point, on the free side facing
away from the mechanism's centre, a few pixels from it, then further out (a leader line
then joins them), in the camera's view at the time. The pixel offsets are turned back
into metres in the plane of the point facing the camera, so the browser draws the labels
exactly there, without any message while the camera stays.

Everything here is pure (no viser): the text's width is estimated from the characters
(an upper bound of the usual sans-serif fonts), and the tests check the result against
the widths a browser measures.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

PX_PER_SCALE = 12.0
"""Height of a label's em [CSS px] per unit of viser's ``font_screen_scale``."""

LABEL_EM = 0.8
"""A 3D label's em as a fraction of the page's text size ("Taille du texte")."""

LINE = 1.2
"""Height of a label's line in em (the font's ascent plus descent)."""

PADDING = 0.2
"""viser's background padding, a fraction of the line's height (half on each side)."""

GAP = 3.0
"""Pixels kept free between two labels, and between a block and its point."""

DISTANCES = (6.0, 30.0, 60.0, 100.0)
"""Pixels from the point to its block tried in turn: beyond the first one, a leader
line joins them."""

REACH = DISTANCES[-1] + 10.0
"""Farthest a label's box may be from its point [px] (the tests' bound)."""

_NARROW = set("iljI.,:;'|!ıft ·()[]-rJ")
_WIDE = set("mwMWæœ%@∈")
_SMALL = set("⁰¹²³⁴⁵⁶⁷⁸⁹⁻₀₁₂₃₄₅₆₇₈₉ₜₐₘₚ°")


def text_width(text: str, em: float) -> float:
    """Width [px] of ``text`` written with an em of ``em`` px: an upper bound of the
    sans-serif fonts a browser picks for viser's labels (DejaVu Sans, the widest usual
    one, is 10 % wider than Arial)."""
    total = 0.0
    for char in text:
        if char in _NARROW:
            total += 0.34
        elif char in _WIDE:
            total += 0.95
        elif char in _SMALL:
            total += 0.42
        elif char.isupper():
            total += 0.78
        else:
            total += 0.66
    return total * em


def label_size(text: str, em: float) -> tuple[float, float]:
    """(width, height) [px] of a label's box, background included."""
    line = LINE * em
    pad = PADDING * line
    return text_width(text, em) + pad, line + pad


@dataclass(frozen=True)
class Camera:
    """A perspective camera as the browser draws it.

    Attributes:
        position: Eye [m].
        look_at: Point looked at [m].
        up: Up direction.
        fov: Vertical field of view [rad].
        width: Canvas width [px].
        height: Canvas height [px].
    """

    position: tuple[float, float, float]
    look_at: tuple[float, float, float]
    up: tuple[float, float, float]
    fov: float
    width: float
    height: float

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(right, up, forward) unit vectors of the image."""
        return self._axes

    @functools.cached_property
    def _axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The axes, computed once for this camera (a layout projects every point)."""
        forward = np.asarray(self.look_at, float) - np.asarray(self.position, float)
        forward /= max(float(np.linalg.norm(forward)), 1e-12)
        right = np.cross(forward, np.asarray(self.up, float))
        norm = float(np.linalg.norm(right))
        if norm < 1e-9:  # looking along "up": any right angle will do
            right = np.cross(forward, np.array([1.0, 0.0, 0.0]))
            norm = float(np.linalg.norm(right)) or 1.0
        right /= norm
        out = (right, np.cross(right, forward), forward)
        for a in out:
            a.flags.writeable = False  # shared by every call on this camera
        return out

    @property
    def focal(self) -> float:
        """Pixels per unit of tangent (the projection's focal length) [px]."""
        return 0.5 * self.height / math.tan(0.5 * self.fov)

    def project(self, point: np.ndarray) -> tuple[float, float, float]:
        """(x, y) [px, y down, from the canvas' top left] of a point [m], and its depth
        [m] along the view (≤ 0: behind the camera)."""
        right, up, forward = self.axes()
        d = np.asarray(point, float) - np.asarray(self.position, float)
        z = float(d @ forward)
        if z <= 1e-9:
            return math.nan, math.nan, z
        f = self.focal / z
        return 0.5 * self.width + f * float(d @ right), 0.5 * self.height - f * float(d @ up), z

    def offset(self, dx: float, dy: float, depth: float) -> np.ndarray:
        """The move [m] in the plane facing the camera at ``depth`` that moves a point's
        image by (dx, dy) [px, y down]."""
        right, up, _ = self.axes()
        scale = depth / self.focal
        return scale * (dx * right - dy * up)


Rect = tuple[float, float, float, float]
"""(left, top, right, bottom) [px]."""


def overlaps(a: Rect, b: Rect, margin: float = 0.0) -> bool:
    """True when the two boxes, ``a`` grown by ``margin``, share some area."""
    return (
        a[0] - margin < b[2]
        and b[0] < a[2] + margin
        and a[1] - margin < b[3]
        and b[1] < a[3] + margin
    )


def distance(point: tuple[float, float], box: Rect) -> float:
    """Distance [px] from a point to a box (0 inside it)."""
    dx = max(box[0] - point[0], 0.0, point[0] - box[2])
    dy = max(box[1] - point[1], 0.0, point[1] - box[3])
    return math.hypot(dx, dy)


DIRECTIONS = tuple(
    (round(math.cos(a), 9), round(-math.sin(a), 9)) for a in (k * math.pi / 4 for k in range(8))
)
"""Sides of a point a block may take (x right, y down): east, then counter-clockwise."""


def _sign(u: float) -> float:
    return 0.0 if abs(u) < 1e-6 else math.copysign(1.0, u)


@dataclass(frozen=True)
class Block:
    """Labels sharing a point, stacked in a column.

    Attributes:
        point: Image of the point [px].
        sizes: (width, height) [px] of each label, top to bottom.
    """

    point: tuple[float, float]
    sizes: tuple[tuple[float, float], ...]

    @property
    def size(self) -> tuple[float, float]:
        """(width, height) [px] of the column."""
        if not self.sizes:
            return 0.0, 0.0
        width = max(w for w, _ in self.sizes)
        return width, sum(h for _, h in self.sizes) + GAP * (len(self.sizes) - 1)

    def box(self, side: int, reach: float) -> Rect:
        """The column's box when it sits on ``side`` (index in :data:`DIRECTIONS`),
        ``reach`` px from the point."""
        ux, uy = DIRECTIONS[side]
        width, height = self.size
        x = self.point[0] + reach * ux + _sign(ux) * width / 2
        y = self.point[1] + reach * uy + _sign(uy) * height / 2
        return x - width / 2, y - height / 2, x + width / 2, y + height / 2


@dataclass(frozen=True)
class Placement:
    """Where a block went.

    Attributes:
        side: Index in :data:`DIRECTIONS`.
        reach: Distance [px] from the point (an index of :data:`DISTANCES`' values).
        box: The column's box [px].
        free: False when no place was free (the least crowded one was taken).
    """

    side: int
    reach: float
    box: Rect
    free: bool = True

    def rows(self, block: Block) -> list[tuple[float, float, str]]:
        """Anchor of each label of ``block``: (x, y) [px] and viser's anchor name, the
        text hugging the side of the point."""
        ux = DIRECTIONS[self.side][0]
        left, top, right, _ = self.box
        if ux > 1e-6:
            x, where = left, "top-left"
        elif ux < -1e-6:
            x, where = right, "top-right"
        else:
            x, where = 0.5 * (left + right), "top-center"
        rows = []
        y = top
        for _, h in block.sizes:
            rows.append((x, y, where))
            y += h + GAP
        return rows


def preferred_sides(point: tuple[float, float], centre: tuple[float, float]) -> list[int]:
    """Sides ordered from the one facing away from ``centre`` (the mechanism's image)."""
    away = (point[0] - centre[0], point[1] - centre[1])
    if math.hypot(*away) < 1e-6:
        away = (1.0, -1.0)  # the upper right of a point in the middle
    heading = math.atan2(away[1], away[0])

    def turn(k: int) -> float:
        ux, uy = DIRECTIONS[k]
        gap = abs(math.atan2(uy, ux) - heading) % (2 * math.pi)
        return min(gap, 2 * math.pi - gap) + 1e-3 * k  # ties: the first side

    return sorted(range(len(DIRECTIONS)), key=turn)


def _fits(box: Rect, view: Rect, taken: Sequence[Rect], points: Sequence[Rect]) -> bool:
    """``box`` lies inside ``view``, clear of the boxes ``taken`` and of other ``points``."""
    inside = view[0] <= box[0] and box[2] <= view[2] and view[1] <= box[1] and box[3] <= view[3]
    return (
        inside
        and not any(overlaps(box, t, GAP) for t in taken)
        and not any(overlaps(box, p) for p in points)
    )


def place(
    blocks: Sequence[Block],
    *,
    view: Rect,
    centre: tuple[float, float],
    avoid: Sequence[Rect] = (),
    before: Sequence[Placement | None] = (),
) -> list[Placement | None]:
    """A place for every block: inside ``view``, clear of the boxes ``avoid`` (e.g. the
    readouts written over the view, a label riding on a rotor) and of the blocks placed
    before it, nearest to its point first, on the side away from ``centre``.

    A block keeps its place from ``before`` while it is still free (labels do not hop
    between equally good places). A block whose point is off the view gets None.
    """
    taken: list[Rect] = list(avoid)
    points = [b.point for b in blocks]
    result: list[Placement | None] = [None] * len(blocks)
    order = sorted(range(len(blocks)), key=lambda k: -len(blocks[k].sizes))
    for k in order:
        block = blocks[k]
        px, py = block.point
        if not (math.isfinite(px) and math.isfinite(py)) or not block.sizes:
            continue
        if not (view[0] <= px <= view[2] and view[1] <= py <= view[3]):
            continue
        others = [(x - GAP, y - GAP, x + GAP, y + GAP) for j, (x, y) in enumerate(points) if j != k]

        old = before[k] if k < len(before) else None
        chosen: Placement | None = None
        if old is not None:
            box = block.box(old.side, old.reach)
            if _fits(box, view, taken, others):
                chosen = Placement(old.side, old.reach, box)
        sides = preferred_sides(block.point, centre)
        if chosen is None:
            chosen = next(
                (
                    Placement(side, reach, block.box(side, reach))
                    for reach in DISTANCES
                    for side in sides
                    if _fits(block.box(side, reach), view, taken, others)
                ),
                None,
            )
        if chosen is None:  # nowhere free: the nearest place crossing the fewest boxes
            side = sides[0]
            chosen = min(
                (Placement(s, DISTANCES[0], block.box(s, DISTANCES[0]), free=False) for s in sides),
                key=lambda p: sum(overlaps(p.box, t, GAP) for t in taken),
                default=Placement(side, DISTANCES[0], block.box(side, DISTANCES[0]), free=False),
            )
        taken.append(chosen.box)
        result[k] = chosen
    return result
