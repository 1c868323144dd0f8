"""The course's scenes: the frozen :class:`~sandbox.physics.spec.Scene` specs and their registry.

:func:`resolve` turns a name typed by a user (or an MJCF path) into a
:class:`~sandbox.physics.model.Source` against this registry; physics itself takes a spec
(``Simulation(get_scene("rotor"))``).
"""

from __future__ import annotations

from sandbox.physics.model import Source
from sandbox.physics.page import Arrow
from sandbox.physics.spec import Effects, Param, Scene, SceneReadout
from sandbox.scenes.registry import DEFAULT_SCENE, SCENES, get_scene, resolve

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
