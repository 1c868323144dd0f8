"""Registry of the course's scenes (frozen :class:`~sandbox.scenes.base.Scene` specs)."""

from __future__ import annotations

from sandbox.errors import UnknownScene, choices
from sandbox.scenes.base import Arrow, Effects, Param, Scene, SceneReadout
from sandbox.scenes.compressor import SCENE as COMPRESSOR
from sandbox.scenes.gyroscope import SCENE as GYROSCOPE
from sandbox.scenes.heavy_gyroscope import SCENE as HEAVY_GYROSCOPE
from sandbox.scenes.rolling_cylinder import SCENE as ROLLING_CYLINDER
from sandbox.scenes.rotor import SCENE as ROTOR

SCENES: dict[str, Scene] = {
    s.name: s for s in (ROTOR, COMPRESSOR, ROLLING_CYLINDER, GYROSCOPE, HEAVY_GYROSCOPE)
}
"""Every registered scene by name."""

DEFAULT_SCENE = "rotor"


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
    "Scene",
    "Param",
    "Effects",
    "SceneReadout",
    "Arrow",
]
