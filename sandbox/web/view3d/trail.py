"""A scene's trail: the path of one point drawn as a polyline (e.g. the precession cone
traced by a gyroscope's axis)."""

from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np

MAXLEN = 600
"""Points kept (one per panel refresh: a minute at 10 Hz)."""


class Trail:
    """Polyline of the points a scene's trail follows over time (``Scene.page.trail``, given
    by each frame's picture), in one client's scene.

    Args:
        scene: A viser ``SceneApi``.
        extent: Size of the model [m] (line thickness).
    """

    def __init__(self, scene: Any, *, extent: float) -> None:
        self.points: deque[np.ndarray] = deque(maxlen=MAXLEN)
        self.last_time = -np.inf
        self.node = scene.add_line_segments(
            "/trail",
            points=np.zeros((1, 2, 3), dtype=np.float32),
            colors=(200, 60, 160),
            thickness=0.004 * extent,
            visible=False,
        )

    def add(self, t: float, point: np.ndarray) -> None:
        """Add the point drawn at time ``t`` [s]; time going back (reset) starts a new
        trail."""
        if t < self.last_time:
            self.points.clear()
        self.last_time = t
        p = np.asarray(point, dtype=float)
        if p.shape != (3,) or not np.isfinite(p).all():
            return
        self.points.append(p)
        if len(self.points) >= 2:
            pts = np.array(self.points, dtype=np.float32)
            self.node.points = np.stack([pts[:-1], pts[1:]], axis=1)
            self.node.visible = True
