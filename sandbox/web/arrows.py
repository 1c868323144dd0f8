"""Force arrows of the scene (e.g. bearing forces) drawn in the 3D view every frame."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from sandbox.physics.snapshot import Snapshot
from sandbox.scenes.base import Arrow

if TYPE_CHECKING:
    import viser

MIN_LENGTH = 1e-4
"""Arrows shorter than this [m] are hidden (a cone alone would mislead)."""


def arrow_points(arrow: Arrow, snapshot: Snapshot) -> tuple[np.ndarray, np.ndarray, float]:
    """Start and end [m] of an arrow in world coordinates, and the magnitude of its vector."""
    origin, vector = arrow.fn(snapshot)
    origin = np.asarray(origin, dtype=float)
    vector = np.asarray(vector, dtype=float)
    return origin, origin + arrow.scale * vector, float(np.linalg.norm(vector))


class ArrowLayer:
    """One arrow node and one label per scene arrow, in a client's scene.

    Args:
        scene: A viser ``SceneApi``.
        arrows: The scene's arrows.
        extent: Size of the model [m], sets the shaft thickness.
        units: Unit of each arrow's vector, shown in its label.
        prefix: Scene-tree folder above ``/arrows`` and ``/arrow_labels``.
    """

    def __init__(
        self,
        scene: viser.SceneApi,
        arrows: Sequence[Arrow],
        *,
        extent: float,
        units: Sequence[str] = (),
        prefix: str = "",
    ) -> None:
        self.arrows = tuple(arrows)
        self.units = tuple(units) + ("",) * (len(self.arrows) - len(units))
        self.nodes: list[tuple[viser.ArrowsHandle, viser.LabelHandle]] = []
        shaft = 0.01 * extent
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

    def update(self, snapshot: Snapshot) -> None:
        """Move every arrow to its current origin and vector (hidden if not finite)."""
        for k, (arrow, (node, label)) in enumerate(zip(self.arrows, self.nodes, strict=True)):
            start, end, magnitude = arrow_points(arrow, snapshot)
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
                self.origins[k] = start

    def relabel(self) -> None:
        """Write the current magnitudes in the labels (called at the panel rate)."""
        for arrow, (_, label), magnitude, unit in zip(
            self.arrows, self.nodes, self.magnitudes, self.units, strict=True
        ):
            label.text = f"{arrow.label} : {magnitude:.3g} {unit}".rstrip()

    def only(self, names: Sequence[str] | None) -> None:
        """Show only the arrows called ``names`` (None: all), from the next update on."""
        self.enabled = None if names is None else set(names)

    def hide(self) -> None:
        """Hide every arrow (e.g. after a divergence)."""
        for k, (node, label) in enumerate(self.nodes):
            if self.shown[k]:
                node.visible = label.visible = self.shown[k] = False
