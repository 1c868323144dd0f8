"""The camera a browser looks through: where the page points it at a scene, and what
the browser says it sees (for placing labels in its view).

A scene may prefer a side (its ``camera``) and a framing (its ``look_at``); without
them the view is three-quarter from the front, above, z up. The videos
(:mod:`sandbox.web.video.render`) frame a scene as the page does. The key readouts written over
the bottom left of the view (projector mode) keep labels out of that corner
(:func:`overlay_box`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from sandbox.web.view3d.label_layout import Camera, Rect

if TYPE_CHECKING:
    import viser

    from sandbox.physics.simulation import Simulation

Vec3 = tuple[float, float, float]


def camera_pose(
    center: ArrayLike, extent: float, direction: ArrayLike = (0.45, -1.0, 0.55)
) -> tuple[np.ndarray, np.ndarray]:
    """A view along ``direction`` (default: three-quarter from the front, above).

    Returns:
        Camera position and look-at point, world coordinates [m].
    """
    look_at = np.asarray(center, dtype=float)
    axis = np.asarray(direction, dtype=float)
    axis /= np.linalg.norm(axis)
    return look_at + 0.9 * max(extent, 1e-3) * axis, look_at


def scene_view(sim: Simulation) -> tuple[Vec3, Vec3]:
    """(direction towards the camera, up vector): the scene's own, else z up."""
    spec = sim.scene
    if spec is not None and spec.page.camera:
        return spec.page.camera
    return (0.45, -1.0, 0.55), (0.0, 0.0, 1.0)


def page_pose(
    sim: Simulation, direction: ArrayLike | None = None, *, narrow: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """The page's camera (position, look-at point): the scene's own framing
    (``page.look_at``), else MuJoCo's centre and extent, along ``direction`` (the
    scene's side when None; ``narrow``: from further back)."""
    model = sim.model
    center, extent = np.asarray(model.stat.center, dtype=float), float(model.stat.extent)
    spec = sim.scene
    if spec is not None and spec.page.look_at is not None:
        center, extent = np.asarray(spec.page.look_at[0], dtype=float), spec.page.look_at[1]
    if direction is None:
        direction = scene_view(sim)[0]
    return camera_pose(center, extent * (1.5 if narrow else 1.0), direction)


def point_camera(client: viser.ClientHandle, sim: Simulation, *, narrow: bool = False) -> None:
    """Aim a browser's camera at the scene, from the scene's preferred side (``narrow``:
    from further back, for a 3D view between two docked columns)."""
    direction, up = scene_view(sim)
    position, look_at = page_pose(sim, direction, narrow=narrow)
    client.camera.up_direction = up
    client.camera.position = position
    client.camera.look_at = look_at


def read_camera(handle: Any) -> Camera | None:
    """The camera a browser draws with (a viser ``CameraHandle``), None until the browser
    has told its canvas' size; a :class:`Camera` is returned as is."""
    if handle is None or isinstance(handle, Camera):
        return handle
    try:
        width, height = int(handle.image_width), int(handle.image_height)
        if width <= 0 or height <= 0:
            return None
        position = tuple(float(x) for x in handle.position)
        look_at = tuple(float(x) for x in handle.look_at)
        up = tuple(float(x) for x in handle.up_direction)
        fov = float(handle.fov)
    except (AssertionError, AttributeError, TypeError, ValueError):
        return None
    values = (*position, *look_at, *up, fov)
    if not all(math.isfinite(v) for v in values) or not 0 < fov < math.pi:
        return None
    return Camera(position, look_at, up, fov, float(width), float(height))  # type: ignore[arg-type]


OVERLAY_LINES = 4
"""Lines of the key readouts written over the bottom left of the view (projector mode):
the labels keep out of that corner."""


def overlay_box(camera: Camera, font_px: float) -> Rect:
    """Where the key readouts are written over the view [px]: the bottom left corner."""
    height = 24 + OVERLAY_LINES * 1.3 * 1.3 * font_px
    return 0.0, camera.height - height, 0.62 * camera.width, camera.height
