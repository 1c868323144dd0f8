"""The course's scenes: the frozen :class:`~sandbox.physics.spec.Scene` specs and their registry.

Importing it loads :mod:`sandbox.scenes.registry`, which passes the registry down to physics
(:func:`sandbox.physics.model.register_scenes`), so that ``Simulation("rotor")`` and
:func:`resolve` know the scene names.
"""

from __future__ import annotations

from sandbox.physics.model import Source, resolve
from sandbox.physics.page import Arrow
from sandbox.physics.spec import Effects, Param, Scene, SceneReadout
from sandbox.scenes.registry import DEFAULT_SCENE, SCENES, get_scene

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
