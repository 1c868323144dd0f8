"""Registry of the course's scenes (frozen :class:`~sandbox.scenes.base.Scene` specs).

Importing it passes the registry down to physics (:func:`sandbox.physics.model.register_scenes`),
so that ``Simulation("rotor")`` and :func:`resolve` know the scene names.
"""

from __future__ import annotations

from sandbox.errors import UnknownScene, choices
from sandbox.physics.model import Source, register_scenes, resolve
from sandbox.scenes.base import Arrow, Effects, Param, Scene, SceneReadout
from sandbox.scenes.compressor import SCENE as COMPRESSOR
from sandbox.scenes.engine import SCENE as ENGINE
from sandbox.scenes.gyroscope import SCENE as GYROSCOPE
from sandbox.scenes.heavy_gyroscope import SCENE as HEAVY_GYROSCOPE
from sandbox.scenes.inertia import SCENE as INERTIA
from sandbox.scenes.robot_axis import SCENE as ROBOT_AXIS
from sandbox.scenes.rolling_cylinder import SCENE as ROLLING_CYLINDER
from sandbox.scenes.rotor import SCENE as ROTOR
from sandbox.scenes.wheel_balancer import SCENE as WHEEL_BALANCER

SCENES: dict[str, Scene] = {
    s.name: s
    for s in (
        ROTOR,
        COMPRESSOR,
        ROLLING_CYLINDER,
        GYROSCOPE,
        HEAVY_GYROSCOPE,
        ENGINE,
        ROBOT_AXIS,
        INERTIA,
        WHEEL_BALANCER,
    )
}
"""Every registered scene by name."""

DEFAULT_SCENE = "rotor"

register_scenes(SCENES)


def get_scene(name: str) -> Scene:
    """The scene called ``name`` (UnknownScene listing the valid names)."""
    try:
        return SCENES[name]
    except KeyError:
        raise UnknownScene(f"unknown scene {name!r}; choose one of: {choices(SCENES)}") from None


__all__ = [
    "SCENES",
    "DEFAULT_SCENE",
    "get_scene",
    "resolve",
    "Source",
    "Scene",
    "Param",
    "Effects",
    "SceneReadout",
    "Arrow",
]
