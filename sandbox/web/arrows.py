"""Force arrows of the scene (e.g. bearing forces) drawn in the 3D view every frame.

Arrows are sized to the mechanism, not to the whole model (a rolling cylinder's 12 m
plane): shafts and heads are a fixed fraction of :func:`mechanism_size`, and lengths are
scaled so that the longest arrow of each unit stays within :data:`MAX_REACH` of that
size (the factor changes only when an arrow would leave the view or shrink to a dot, so
lengths can be compared from one instant to the next). The user multiplies it with
:attr:`ArrowLayer.user_scale` ("Échelle des flèches").
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from sandbox.physics.snapshot import Snapshot
from sandbox.physics.units import display_unit
from sandbox.scenes.base import Arrow
from sandbox.web import wire
from sandbox.web.renderer import mechanism_size
from sandbox.web.text import number, with_unit

if TYPE_CHECKING:
    import viser

MIN_LENGTH = 1e-4
"""Arrows shorter than this [m] are hidden (a cone alone would mislead)."""

SHAFT = 0.01
"""Shaft radius as a fraction of the mechanism's size (heads 2.5 and 6 shafts)."""

MAX_REACH = 0.6
"""Longest arrow of a unit, as a fraction of the mechanism's size, before user scaling."""

MIN_REACH = 0.05
"""Below this fraction the longest arrow of a unit is grown back (a dot says nothing)."""

USER_SCALES = (0.25, 4.0)
"""Range of the user's scale factor on the arrows' lengths."""


def arrow_points(arrow: Arrow, snapshot: Snapshot) -> tuple[np.ndarray, np.ndarray, float]:
    """Start and end [m] of an arrow in world coordinates (at the scene's own scale), and
    the magnitude of its vector."""
    origin, vector = arrow.fn(snapshot)
    origin = np.asarray(origin, dtype=float)
    vector = np.asarray(vector, dtype=float)
    return origin, origin + arrow.scale * vector, float(np.linalg.norm(vector))


def auto_factor(current: float, longest: float, size: float) -> float:
    """The length factor of a unit's arrows: ``current`` unless its longest arrow
    (``longest`` metres at the scene's scale) would reach past :data:`MAX_REACH` or stay
    under :data:`MIN_REACH` of ``size``; then the factor that brings it to 3/4 of the
    reach (long enough to stick out of a body it starts inside, such as a rolling
    cylinder's contact forces)."""
    if not (math.isfinite(longest) and longest > 0):
        return current
    drawn = longest * current
    if MIN_REACH * size <= drawn <= MAX_REACH * size:
        return current
    return 0.75 * MAX_REACH * size / longest


MOVE = 2e-4
"""Smallest move worth a message, as a fraction of the mechanism's size (a fifth of a
pixel when the mechanism spans a 1000-pixel view): a still arrow or label sends nothing."""


class ArrowLayer:
    """The scene's arrows as one viser arrows node, and one label per arrow, in a client's
    (or the broadcast) scene.

    Each drawn frame sends one message for every arrow that moved (the node's points) and
    one per label that moved more than :data:`MOVE`; which arrows show (round-off, a
    lesson's choice) changes the points and colours together.

    Args:
        scene: A viser ``SceneApi``.
        arrows: The scene's arrows.
        extent: Size of the model [m] (used when ``size`` is not given).
        size: Size of the mechanism [m] (:func:`mechanism_size`): thickness and reach;
            None measures it on the first :meth:`update`.
        units: Unit of each arrow's vector (contract form), when the arrows do not say.
        zero: Round-off of the scene by unit (``Scene.zero``): smaller magnitudes read 0.
        prefix: Scene-tree folder above ``/arrows`` and ``/arrow_labels``.
    """

    def __init__(
        self,
        scene: viser.SceneApi,
        arrows: Sequence[Arrow],
        *,
        extent: float,
        size: float | None = None,
        units: Sequence[str] = (),
        zero: Mapping[str, float] | None = None,
        prefix: str = "",
    ) -> None:
        self.zero = dict(zero or {})
        self.arrows = tuple(arrows)
        given = tuple(units) + ("",) * (len(self.arrows) - len(units))
        self.units = tuple(
            getattr(a, "unit", "") or u for a, u in zip(self.arrows, given, strict=True)
        )
        self.size = float(size) if size is not None and size > 0 else float(extent) or 1.0
        self._measured = size is not None and size > 0
        self.user_scale = 1.0
        self.factors: dict[str, float] = {}  # unit -> automatic length factor
        self.colors = np.array([a.color for a in self.arrows], dtype=np.uint8).reshape(-1, 3)
        shaft = SHAFT * self.size
        self.node = scene.add_arrows(
            f"{prefix}/arrows",
            points=np.zeros((1, 2, 3), dtype=np.float32),
            colors=self.colors[:1] if len(self.colors) else (0, 0, 0),
            shaft_radius=shaft,
            head_radius=2.5 * shaft,
            head_length=6 * shaft,
            visible=False,
        )
        self.labels: list[viser.LabelHandle] = [
            scene.add_label(
                f"{prefix}/arrow_labels/{a.name}",
                a.label,
                visible=False,
                anchor="bottom-center",
                font_screen_scale=0.9,
            )
            for a in self.arrows
        ]
        self.enabled: set[str] | None = None  # None: every arrow
        n = len(self.arrows)
        self.magnitudes = [0.0] * n
        self.shown = [False] * n
        self.origins = np.zeros((n, 3))
        self.ends = np.zeros((n, 3))
        self._zero = np.array([self.zero.get(u, 0.0) for u in self.units])
        self._by_unit: dict[str, list[int]] = {}
        for k, unit in enumerate(self.units):
            self._by_unit.setdefault(unit, []).append(k)
        self._sent_points = np.zeros((0, 2, 3), dtype=np.float32)
        self._sent_mask: tuple[bool, ...] = (False,) * n
        self._label_at = np.full((n, 3), np.nan)
        self.messages = 0  # messages queued so far (the counted guard of the tests)
        self.dirty = False  # a setting changed since the last draw: draw again

    def set_scale(self, factor: float) -> None:
        """The user's factor on every arrow's length (clipped to :data:`USER_SCALES`)."""
        low, high = USER_SCALES
        if math.isfinite(factor):
            self.user_scale = min(max(float(factor), low), high)
            self.dirty = True

    def resize(self, size: float) -> None:
        """Size the shafts and heads, and the reach, to a mechanism of ``size`` metres."""
        if not (math.isfinite(size) and size > 0):
            return
        self.size, self._measured = float(size), True
        self.factors.clear()
        shaft = SHAFT * self.size
        wire.set_props(
            self.node, shaft_radius=shaft, head_radius=2.5 * shaft, head_length=6 * shaft
        )
        self.messages += 1

    @property
    def shaft_radius(self) -> float:
        """Radius of the shafts [m] (heads are 2.5 and 6 shafts)."""
        return SHAFT * self.size

    def update(self, snapshot: Snapshot) -> None:
        """Evaluate the arrows on ``snapshot`` and draw them (a replay's export, tests):
        a live view draws the frame's own picture with :meth:`draw`."""
        if not self._measured:
            self.resize(mechanism_size(snapshot.model, snapshot.data))
        ends = np.full((len(self.arrows), 2, 3), np.nan)
        sizes = np.full(len(self.arrows), np.nan)
        for k, arrow in enumerate(self.arrows):
            start, end, magnitude = arrow_points(arrow, snapshot)
            ends[k, 0], ends[k, 1], sizes[k] = start, end, magnitude
        self.draw(ends, sizes)

    def draw(self, ends: np.ndarray, magnitudes: np.ndarray) -> None:
        """Move every arrow to its start and end ``ends`` (A, 2, 3) [m, at the scene's
        scale] with the norms ``magnitudes`` (A,) of their vectors; an arrow whose values
        are not finite is hidden. Vectorised over the arrows (a frame's cost)."""
        self.dirty = False
        starts = np.asarray(ends[:, 0], dtype=float)
        sizes = np.asarray(magnitudes, dtype=float)
        vectors = np.asarray(ends[:, 1], dtype=float) - starts
        with np.errstate(invalid="ignore"):
            vectors[np.abs(sizes) <= self._zero] = 0.0  # round-off: no arrow, not one
            # blown up to a visible length by the automatic scale
            lengths = np.sqrt((vectors * vectors).sum(axis=1))
        wanted = self._wanted()
        scale = np.empty(len(self.arrows))
        for unit, members in self._by_unit.items():
            pick = [k for k in members if wanted[k] and math.isfinite(lengths[k])]
            if pick:
                longest = float(lengths[pick].max())
                self.factors[unit] = auto_factor(self.factors.get(unit, 1.0), longest, self.size)
            scale[members] = self.factors.get(unit, 1.0) * self.user_scale
        tips = starts + scale[:, None] * vectors
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(tips).all(axis=1) & np.isfinite(starts).all(axis=1)
            show = ok & wanted & (scale * lengths > MIN_LENGTH)
        self.magnitudes = [
            float(m) if good else math.nan for m, good in zip(sizes, ok, strict=True)
        ]
        self.origins = np.where(ok[:, None], starts, self.origins)
        self.ends = np.where(ok[:, None], tips, self.ends)
        self.shown = [bool(x) for x in show]
        self._send(np.stack([starts[show], tips[show]], axis=1), show)
        self._place_labels(show)

    def _wanted(self) -> np.ndarray:
        """The arrows a lesson's step asks for (all when it asks for none)."""
        if self.enabled is None:
            return np.ones(len(self.arrows), dtype=bool)
        return np.array([a.name in self.enabled for a in self.arrows], dtype=bool)

    def _send(self, points: np.ndarray, show: np.ndarray) -> None:
        """One message for the node: its points when they moved, with the colours when
        the set of arrows shown changed; its visibility when none or some show."""
        mask = tuple(bool(x) for x in show)
        if not len(points):
            if self.node.visible:
                self.node.visible = False
                self.messages += 1
            self._sent_mask = mask
            return
        points = points.astype(np.float32)
        if mask != self._sent_mask or points.shape != self._sent_points.shape:
            wire.set_props(self.node, points=points, colors=self.colors[show])
            self.messages += 1
        elif np.abs(points - self._sent_points).max() > MOVE * self.size:
            wire.set_props(self.node, points=points)
            self.messages += 1
        else:
            points = self._sent_points  # below what a pixel shows: keep the sent one
        self._sent_points, self._sent_mask = points, mask
        if not self.node.visible:
            self.node.visible = True
            self.messages += 1

    def _place_labels(self, show: np.ndarray) -> None:
        """Each shown arrow's label at its end (sent when it moved), the others hidden."""
        with np.errstate(invalid="ignore"):
            moved = show & ~(np.abs(self.ends - self._label_at) <= MOVE * self.size).all(axis=1)
        for k in np.flatnonzero(moved).tolist():
            wire.set_position(self.labels[k], self.ends[k])
            self._label_at[k] = self.ends[k]
            self.messages += 1
        for label, wanted in zip(self.labels, show.tolist(), strict=True):
            if label.visible != wanted:
                label.visible = wanted
                self.messages += 1

    def caption(self, k: int) -> str:
        """The label of arrow ``k``: its words, magnitude and unit ("Palier A : 0,91 N")."""
        arrow, magnitude, unit = self.arrows[k], self.magnitudes[k], self.units[k]
        if not getattr(arrow, "magnitude", True):
            return arrow.label
        value = number(magnitude, 3, zero=self.zero.get(unit, 0.0))
        return f"{arrow.label} : {with_unit(value, display_unit(unit))}"

    def relabel(self) -> None:
        """Write the current magnitudes in the labels (called at the panel rate)."""
        for k, label in enumerate(self.labels):
            text = self.caption(k)
            if label.text != text:
                label.text = text

    def only(self, names: Sequence[str] | None) -> None:
        """Show only the arrows called ``names`` (None: all), from the next update on."""
        self.enabled = None if names is None else set(names)
        self.dirty = True

    def hide(self) -> None:
        """Hide every arrow (e.g. after a divergence)."""
        if self.node.visible:
            self.node.visible = False
        for k, label in enumerate(self.labels):
            if label.visible:
                label.visible = False
            self.shown[k] = False
        self._sent_mask = tuple(self.shown)
