"""MuJoCo's own offscreen renderer for the videos, on any laptop without a GPU or a
display (EGL, else OSMesa, on a Linux machine without a display; CGL on macOS; a hidden
window on Windows), with the camera the page uses (the scene's side, any up direction)
and a white wall behind the mechanism.
"""

from __future__ import annotations

import os
import platform

import mujoco
import numpy as np

from sandbox.web.video.options import VideoError

# -- offscreen OpenGL -----------------------------------------------------------------------
HEADLIGHT = (0.35, 0.45, 0.1)
"""Ambient, diffuse and specular grey of the light that follows the camera in a video:
the page lights its solids from every side (viser's environment map); with MuJoCo's
default headlight (0.1 ambient) a disc seen from its unlit side was black."""


def light_as_the_page(model: mujoco.MjModel) -> None:
    """Light ``model``'s videos as the page lights the scene: a face turned away from the
    lights is shaded, never black."""
    ambient, diffuse, specular = HEADLIGHT
    light = model.vis.headlight
    light.active = 1
    light.ambient[:] = ambient
    light.diffuse[:] = diffuse
    light.specular[:] = specular


def offscreen_renderer(model: mujoco.MjModel, height: int, width: int) -> mujoco.Renderer:
    """MuJoCo's renderer on a headless context: ``MUJOCO_GL`` when the user set it; on a
    Linux machine without a display, EGL, else OSMesa.

    Raises:
        VideoError: no OpenGL this machine can draw with (naming what to install).
    """
    # where Renderer finds its context; imported here, as it picks a backend on import
    from mujoco.rendering.classic import gl_context

    headless = platform.system() == "Linux" and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    )
    if headless and not os.environ.get("MUJOCO_GL"):
        for backend in ("egl", "osmesa"):
            try:
                module = __import__(f"mujoco.{backend}", fromlist=["GLContext"])
                module.GLContext(1, 1).free()
            except Exception:  # missing library or driver: try the next one
                continue
            gl_context.GLContext = module.GLContext
            break
    light_as_the_page(model)
    model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
    model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
    try:
        return mujoco.Renderer(model, height, width)
    except Exception as exc:
        raise VideoError(
            "vidéo : pas d'OpenGL pour dessiner hors écran / no OpenGL to draw the video "
            f"offscreen ({type(exc).__name__}: {exc}); Linux: apt install libegl1 (or "
            "libosmesa6 and MUJOCO_GL=osmesa); macOS and Windows: update the graphics driver"
        ) from None


def aim(scene: mujoco.MjvScene, position: np.ndarray, look_at: np.ndarray, up: np.ndarray) -> None:
    """Point the scene's cameras from ``position`` at ``look_at``, ``up`` up (any up:
    MuJoCo's free camera only knows z)."""
    forward = look_at - position
    forward /= max(float(np.linalg.norm(forward)), 1e-12)
    up = up - np.dot(up, forward) * forward
    up /= max(float(np.linalg.norm(up)), 1e-12)
    for cam in scene.camera:
        cam.pos[:] = position
        cam.forward[:] = forward
        cam.up[:] = up


def backdrop(scene: mujoco.MjvScene, look_at: np.ndarray, extent: float) -> None:
    """A white wall behind the mechanism, facing the camera and lit by nothing (MuJoCo
    clears to black where a scene has no skybox; the page is white)."""
    if scene.ngeom >= scene.maxgeom:
        return
    cam = scene.camera[0]
    forward, up = np.asarray(cam.forward, float), np.asarray(cam.up, float)
    right = np.cross(forward, up)
    rot = np.column_stack([right, up, forward])  # the wall's z along the sight
    geom = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(
        geom,
        mujoco.mjtGeom.mjGEOM_BOX,
        np.array([40.0, 40.0, 0.001]) * extent,
        look_at + 6.0 * extent * forward,
        rot.ravel(),
        np.array([1.0, 1.0, 1.0, 1.0], dtype=np.float32),
    )
    geom.emission = 1.0
    scene.ngeom += 1


def project(scene: mujoco.MjvScene, points: np.ndarray, width: int, height: int) -> np.ndarray:
    """Pixel coordinates (x right, y down) of world ``points`` (n×3) in the view of
    ``scene``'s camera (NaN behind it)."""
    cam = scene.camera[0]
    forward, up = np.asarray(cam.forward), np.asarray(cam.up)
    right = np.cross(forward, up)
    rel = np.asarray(points, dtype=float) - np.asarray(cam.pos)
    z = rel @ forward
    near, top = float(cam.frustum_near), float(cam.frustum_top)
    half_h = top / near
    half_w = half_h * width / height
    with np.errstate(divide="ignore", invalid="ignore"):
        x = (rel @ right) / z / half_w
        y = (rel @ up) / z / half_h
    out = np.stack([(x + 1) * width / 2, (1 - y) * height / 2], axis=1)
    out[z <= 0] = np.nan
    return out
