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


class ArrowLayer:
    """One arrow node and one label per scene arrow, in a client's scene.

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
        self.nodes: list[tuple[viser.ArrowsHandle, viser.LabelHandle]] = []
        shaft = SHAFT * self.size
        for a in self.arrows:
            node = scene.add_arrows(
                f"{prefix}/arrows/{a.name}",
                points=np.zeros((1, 2, 3), dtype=np.float32),
                colors=a.color,
                shaft_radius=shaft,
                head_radius=2.5 * shaft,
                head_length=6 * shaft,
                visible=False,
            )
            label = scene.add_label(
                f"{prefix}/arrow_labels/{a.name}",
                a.label,
                visible=False,
                anchor="bottom-center",
                font_screen_scale=0.9,
            )
            self.nodes.append((node, label))
        self.enabled: set[str] | None = None  # None: every arrow
        self.magnitudes = [0.0] * len(self.arrows)
        self.shown = [False] * len(self.arrows)
        self.origins = [np.zeros(3) for _ in self.arrows]
        self.ends = [np.zeros(3) for _ in self.arrows]

    def set_scale(self, factor: float) -> None:
        """The user's factor on every arrow's length (clipped to :data:`USER_SCALES`)."""
        low, high = USER_SCALES
        if math.isfinite(factor):
            self.user_scale = min(max(float(factor), low), high)

    def resize(self, size: float) -> None:
        """Size the shafts and heads, and the reach, to a mechanism of ``size`` metres."""
        if not (math.isfinite(size) and size > 0):
            return
        self.size, self._measured = float(size), True
        self.factors.clear()
        shaft = SHAFT * self.size
        for node, _ in self.nodes:
            node.shaft_radius = shaft
            node.head_radius = 2.5 * shaft
            node.head_length = 6 * shaft

    def update(self, snapshot: Snapshot) -> None:
        """Move every arrow to its current origin and vector (hidden if not finite)."""
        if not self._measured:
            self.resize(mechanism_size(snapshot.model, snapshot.data))
        points = []
        longest: dict[str, float] = {}
        for arrow, unit in zip(self.arrows, self.units, strict=True):
            start, end, magnitude = arrow_points(arrow, snapshot)
            if abs(magnitude) <= self.zero.get(unit, 0.0):  # round-off: no arrow, not
                end = start  # one blown up to a visible length by the automatic scale
            points.append((start, end, magnitude))
            length = float(np.linalg.norm(end - start))
            wanted = self.enabled is None or arrow.name in self.enabled
            if wanted and math.isfinite(length):
                longest[unit] = max(longest.get(unit, 0.0), length)
        for unit, length in longest.items():
            self.factors[unit] = auto_factor(self.factors.get(unit, 1.0), length, self.size)
        for k, (arrow, (node, label)) in enumerate(zip(self.arrows, self.nodes, strict=True)):
            start, end, magnitude = points[k]
            factor = self.factors.get(self.units[k], 1.0) * self.user_scale
            end = start + factor * (end - start)
            ok = bool(np.isfinite(end).all() and np.isfinite(start).all())
            wanted = self.enabled is None or arrow.name in self.enabled
            show = ok and wanted and float(np.linalg.norm(end - start)) > MIN_LENGTH
            if show:
                node.points = np.stack([start, end])[None].astype(np.float32)
                label.position = end
            if show != self.shown[k]:
                node.visible = label.visible = self.shown[k] = show
            self.magnitudes[k] = magnitude if ok else float("nan")
            if ok:
                self.origins[k], self.ends[k] = start, end

    def caption(self, k: int) -> str:
        """The label of arrow ``k``: its words, magnitude and unit ("Palier A : 0,91 N")."""
        arrow, magnitude, unit = self.arrows[k], self.magnitudes[k], self.units[k]
        if not getattr(arrow, "magnitude", True):
            return arrow.label
        value = number(magnitude, 3, zero=self.zero.get(unit, 0.0))
        return f"{arrow.label} : {with_unit(value, display_unit(unit))}"

    def relabel(self) -> None:
        """Write the current magnitudes in the labels (called at the panel rate)."""
        for k, (_, label) in enumerate(self.nodes):
            text = self.caption(k)
            if label.text != text:
                label.text = text

    def only(self, names: Sequence[str] | None) -> None:
        """Show only the arrows called ``names`` (None: all), from the next update on."""
        self.enabled = None if names is None else set(names)

    def hide(self) -> None:
        """Hide every arrow (e.g. after a divergence)."""
        for k, (node, label) in enumerate(self.nodes):
            if self.shown[k]:
                node.visible = label.visible = self.shown[k] = False
